//! Tests of the contact search: against brute force on flat, warped,
//! triangulated and curved masters, determinism, bad input, cost.

use super::facets::{boundary_distance, facet_size};
use super::*;
use crate::contact::projection::project;
use crate::fem::test_util::Lcg;
use crate::vec3::distance;

pub(super) type Mesh = (Vec<[f64; 3]>, Vec<[u32; MAX_FACET_NODES]>);

/// A first-order facet's nodes in a contact facet row.
pub(super) fn pad(f: [u32; 4]) -> [u32; MAX_FACET_NODES] {
    let mut row = [0; MAX_FACET_NODES];
    row[..4].copy_from_slice(&f);
    row
}

pub(super) fn surface<'a>(facet_type: FacetType, mesh: &'a Mesh) -> SearchSurface<'a> {
    SearchSurface {
        facet_type,
        positions: &mesh.0,
        facets: &mesh.1,
    }
}

/// Uniform in [0, 1).
pub(super) fn unit(rng: &mut Lcg) -> f64 {
    0.5 * (rng.next() + 1.0)
}

/// `nx × ny` cells of size `h` in the xy plane, node (i, j) at
/// `(i h, j h, z(i h, j h))` plus in-plane jitter; quads counter-clockwise
/// seen from +z, or each quad split into two triangles (alternating
/// diagonals).
pub(super) fn plane_grid(
    nx: usize,
    ny: usize,
    h: f64,
    jitter: f64,
    z: impl Fn(f64, f64) -> f64,
    tri: bool,
    rng: &mut Lcg,
) -> Mesh {
    let mut pos = Vec::new();
    for j in 0..=ny {
        for i in 0..=nx {
            let on_rim = i == 0 || j == 0 || i == nx || j == ny;
            let (dx, dy) = if on_rim {
                (0.0, 0.0)
            } else {
                (jitter * h * rng.next(), jitter * h * rng.next())
            };
            let (x, y) = (i as f64 * h + dx, j as f64 * h + dy);
            pos.push([x, y, z(x, y)]);
        }
    }
    let node = |i: usize, j: usize| (j * (nx + 1) + i) as u32;
    let mut facets = Vec::new();
    for j in 0..ny {
        for i in 0..nx {
            let (a, b, c, d) = (
                node(i, j),
                node(i + 1, j),
                node(i + 1, j + 1),
                node(i, j + 1),
            );
            if !tri {
                facets.push(pad([a, b, c, d]));
            } else if (i + j) % 2 == 0 {
                facets.push(pad([a, b, c, 0]));
                facets.push(pad([a, c, d, 0]));
            } else {
                facets.push(pad([a, b, d, 0]));
                facets.push(pad([b, c, d, 0]));
            }
        }
    }
    (pos, facets)
}

/// Open cylinder of radius `r` around the z axis, outward normals.
pub(super) fn cylinder(n_theta: usize, n_z: usize, r: f64, length: f64) -> Mesh {
    let mut pos = Vec::new();
    for j in 0..=n_z {
        for i in 0..n_theta {
            let t = 2.0 * std::f64::consts::PI * i as f64 / n_theta as f64;
            pos.push([r * t.cos(), r * t.sin(), length * j as f64 / n_z as f64]);
        }
    }
    let node = |i: usize, j: usize| (j * n_theta + i % n_theta) as u32;
    let mut facets = Vec::new();
    for j in 0..n_z {
        for i in 0..n_theta {
            facets.push(pad([
                node(i, j),
                node(i + 1, j),
                node(i + 1, j + 1),
                node(i, j + 1),
            ]));
        }
    }
    (pos, facets)
}

pub(super) struct Brute {
    pub(super) facet: u32,
    pub(super) distance: f64,
    pub(super) valid: bool,
}

/// Reference inner search: every facet of the surface projected, then the
/// selection rule of the module doc written out directly.
pub(super) fn brute_force(s: &SearchSurface, facets: &[u32], x: [f64; 3]) -> Option<Brute> {
    let mut all = Vec::new();
    for &f in facets {
        let Some(conn) = s.facets.get(f as usize) else {
            continue;
        };
        let k = s.facet_type.nodes();
        let Some(nodes) = conn[..k]
            .iter()
            .map(|&n| s.positions.get(n as usize).copied())
            .collect::<Option<Vec<_>>>()
        else {
            continue;
        };
        let p = project(s.facet_type, &nodes, x, None);
        let valid = p.converged && p.outside <= INSIDE_TOL;
        let d = if valid {
            distance(x, p.point)
        } else {
            boundary_distance(s.facet_type, &nodes, x)
        };
        all.push((f, d, valid, facet_size(s.facet_type, &nodes)));
    }
    let dmin = all.iter().map(|a| a.1).fold(f64::INFINITY, f64::min);
    all.iter()
        .filter(|a| a.1 <= dmin + TIE_REL * a.3)
        .min_by_key(|a| (!a.2, a.0))
        .map(|a| Brute {
            facet: a.0,
            distance: a.1,
            valid: a.2,
        })
}

pub(super) fn all_facets(s: &SearchSurface) -> Vec<u32> {
    (0..s.facets.len() as u32).collect()
}

pub(super) fn ring_of(s: &SearchSurface, node: u32) -> Vec<u32> {
    let k = s.facet_type.nodes();
    (0..s.facets.len() as u32)
        .filter(|&f| s.facets[f as usize][..k].contains(&node))
        .collect()
}

pub(super) fn closest_node_brute(s: &SearchSurface, x: [f64; 3]) -> Option<(u32, f64)> {
    let k = s.facet_type.nodes();
    let mut best: Option<(u32, f64)> = None;
    for (n, p) in s.positions.iter().enumerate() {
        let on_facet = s.facets.iter().any(|f| f[..k].contains(&(n as u32)));
        if !on_facet {
            continue;
        }
        let d = distance(*p, x);
        if best.is_none_or(|(_, bd)| d < bd) {
            best = Some((n as u32, d));
        }
    }
    best
}

/// Runs `find` against the brute force for `n` random points from
/// `sample`; returns how often the winner was not around the closest
/// node (so a test can insist the exactness sweep was exercised).
pub(super) fn check_find_against_brute(
    s: &SearchSurface,
    n: usize,
    rng: &mut Lcg,
    mut sample: impl FnMut(&mut Lcg) -> [f64; 3],
) -> usize {
    let index = SearchIndex::build(s);
    let facets = all_facets(s);
    let mut outside_ring = 0;
    for q in 0..n {
        let x = sample(rng);
        let found = index.find(s, x, f64::INFINITY).expect("non-empty surface");
        let brute = brute_force(s, &facets, x).unwrap();
        assert_eq!(
            found.facet, brute.facet,
            "query {q} x={x:?}: find {found:?}, brute facet {} d {} valid {}",
            brute.facet, brute.distance, brute.valid
        );
        let (node, _) = closest_node_brute(s, x).unwrap();
        assert_eq!(found.closest_node, node, "query {q}");
        if !ring_of(s, node).contains(&found.facet) {
            outside_ring += 1;
        }
        check_patch(s, &found);
    }
    outside_ring
}

/// The patch is sorted, unique, holds the facet and every facet sharing
/// a node with it, and is exactly the 2-ring of the closest node plus the
/// chosen facet's neighbours.
pub(super) fn check_patch(s: &SearchSurface, found: &Found) {
    let k = s.facet_type.nodes();
    let p = &found.patch;
    assert!(p.windows(2).all(|w| w[0] < w[1]), "patch not sorted/unique");
    assert!(p.contains(&found.facet));
    let mut expect = Vec::new();
    let mut seeds = ring_of(s, found.closest_node);
    seeds.push(found.facet);
    for f in seeds {
        for &n in &s.facets[f as usize][..k] {
            expect.extend(ring_of(s, n));
        }
    }
    expect.sort_unstable();
    expect.dedup();
    assert_eq!(p, &expect);
    for &n in &s.facets[found.facet as usize][..k] {
        for f in ring_of(s, n) {
            assert!(p.contains(&f), "neighbour {f} missing");
        }
    }
}

#[test]
fn closest_node_equals_brute_force_on_random_clouds() {
    let mut rng = Lcg::new(11);
    // Uniform cloud of triangles, one stray node on no facet.
    let mut pos: Vec<[f64; 3]> = (0..600)
        .map(|_| {
            [
                10.0 * unit(&mut rng),
                10.0 * unit(&mut rng),
                10.0 * unit(&mut rng),
            ]
        })
        .collect();
    let facets: Vec<[u32; MAX_FACET_NODES]> = (0..200)
        .map(|i| pad([3 * i, 3 * i + 1, 3 * i + 2, 0]))
        .collect();
    pos.push([5.0, 5.0, 5.0]);
    let uniform = (pos, facets);
    // Strongly clustered cloud: most nodes in a tiny ball, a few spread
    // wide, so the grid is capped and cells are very uneven.
    let mut pos: Vec<[f64; 3]> = (0..450)
        .map(|_| {
            [
                1.0 + 0.01 * rng.next(),
                1.0 + 0.01 * rng.next(),
                1.0 + 0.01 * rng.next(),
            ]
        })
        .collect();
    pos.extend((0..150).map(|_| {
        [
            100.0 * unit(&mut rng),
            100.0 * unit(&mut rng),
            100.0 * unit(&mut rng),
        ]
    }));
    let facets: Vec<[u32; MAX_FACET_NODES]> =
        (0..200).map(|i| pad([i, i + 200, i + 400, 0])).collect();
    let clustered = (pos, facets);
    for (mesh, scale) in [(&uniform, 10.0), (&clustered, 100.0)] {
        let s = surface(FacetType::Tri3, mesh);
        let index = SearchIndex::build(&s);
        for q in 0..1000 {
            let x = match q % 10 {
                // Far outside, including along one axis only.
                0 => rng.vec3(1e4),
                1 => [0.5 * scale, 0.5 * scale, 1e3 * scale * rng.next()],
                // Exactly on a node.
                2 => mesh.0[q % 600],
                _ => [
                    scale * (1.5 * rng.next() + 0.5),
                    scale * (1.5 * rng.next() + 0.5),
                    scale * (1.5 * rng.next() + 0.5),
                ],
            };
            let got = index.closest_node(&s, x);
            let want = closest_node_brute(&s, x);
            assert_eq!(got.map(|g| g.0), want.map(|w| w.0), "query {q} x={x:?}");
            assert_eq!(got.unwrap().1, want.unwrap().1);
        }
    }
}

#[test]
fn closest_node_ties_go_to_smaller_id() {
    // Node 4 sits on node 1; a query midway between nodes 0 and 1.
    let mesh: Mesh = (
        vec![
            [0.0, 0.0, 0.0],
            [1.0, 0.0, 0.0],
            [0.0, 1.0, 0.0],
            [1.0, 1.0, 0.0],
            [1.0, 0.0, 0.0],
        ],
        vec![pad([4, 3, 2, 0]), pad([0, 1, 2, 0])],
    );
    let s = surface(FacetType::Tri3, &mesh);
    let index = SearchIndex::build(&s);
    assert_eq!(index.closest_node(&s, [1.0, 0.0, 0.3]).unwrap().0, 1);
    assert_eq!(index.closest_node(&s, [0.5, -0.2, 0.0]).unwrap().0, 0);
    // Equidistant from all four corners.
    assert_eq!(index.closest_node(&s, [0.5, 0.5, 0.0]).unwrap().0, 0);
}

#[test]
fn find_equals_brute_force_flat_quad_grid() {
    let mut rng = Lcg::new(21);
    let mesh = plane_grid(16, 12, 1.0, 0.0, |_, _| 0.0, false, &mut rng);
    let s = surface(FacetType::Quad4, &mesh);
    check_find_against_brute(&s, 1000, &mut rng, |r| {
        [17.0 * unit(r) - 0.5, 13.0 * unit(r) - 0.5, 0.6 * r.next()]
    });
}

#[test]
fn find_equals_brute_force_warped_quad_grid() {
    let mut rng = Lcg::new(22);
    let z = |x: f64, y: f64| 0.8 * (0.5 * x).sin() * (0.4 * y).cos();
    let mesh = plane_grid(14, 14, 1.0, 0.3, z, false, &mut rng);
    // Graded (neighbouring columns and rows differ in width by up to a
    // factor 3) and non-planar quads.
    let mut mesh = mesh;
    let grade = |v: f64| v + 0.3 * (std::f64::consts::PI * v).sin();
    for p in mesh.0.iter_mut() {
        let (x, y) = (grade(p[0]), grade(p[1]));
        *p = [x, y, z(x, y) + 0.1 * rng.next()];
    }
    let s = surface(FacetType::Quad4, &mesh);
    let outside_ring = check_find_against_brute(&s, 1000, &mut rng, |r| {
        let (x, y) = (15.0 * unit(r) - 0.5, 15.0 * unit(r) - 0.5);
        [x, y, z(x, y) + 0.6 * r.next()]
    });
    // The distorted mesh must produce winners away from the closest
    // node, or this test would not exercise the exactness sweep.
    eprintln!("warped quads: {outside_ring} winners away from the closest node");
    assert!(outside_ring > 0, "sweep never needed");
}

#[test]
fn find_equals_brute_force_triangulated_grid() {
    let mut rng = Lcg::new(23);
    let z = |x: f64, y: f64| 0.3 * (0.7 * x + 0.2 * y).sin();
    let mesh = plane_grid(12, 12, 1.0, 0.25, z, true, &mut rng);
    let s = surface(FacetType::Tri3, &mesh);
    let outside_ring = check_find_against_brute(&s, 1000, &mut rng, |r| {
        let (x, y) = (13.0 * unit(r) - 0.5, 13.0 * unit(r) - 0.5);
        [x, y, z(x, y) + 0.6 * r.next()]
    });
    assert!(outside_ring > 0, "sweep never needed");
}

#[test]
fn find_equals_brute_force_cylinder() {
    let mut rng = Lcg::new(24);
    let mesh = cylinder(24, 10, 10.0, 20.0);
    let s = surface(FacetType::Quad4, &mesh);
    check_find_against_brute(&s, 1000, &mut rng, |r| {
        let t = std::f64::consts::PI * r.next();
        let rad = 10.0 + 5.0 * r.next();
        [rad * t.cos(), rad * t.sin(), 22.0 * unit(r) - 1.0]
    });
}

#[test]
fn find_many_equals_find() {
    let mut rng = Lcg::new(26);
    let z = |x: f64, y: f64| 0.4 * (0.5 * x).sin() * (0.4 * y).cos();
    let mesh = plane_grid(12, 9, 1.0, 0.3, z, true, &mut rng);
    let s = surface(FacetType::Tri3, &mesh);
    let index = SearchIndex::build(&s);
    let mut points: Vec<[f64; 3]> = (0..500)
        .map(|_| {
            let (x, y) = (14.0 * unit(&mut rng) - 1.0, 11.0 * unit(&mut rng) - 1.0);
            [x, y, z(x, y) + 0.8 * rng.next()]
        })
        .collect();
    points.push([f64::NAN, 0.0, 0.0]);
    points.push([1e5, -1e5, 3.0]);
    let many = index.find_many(&s, &points, 1.0);
    assert_eq!(many.len(), points.len());
    for (p, m) in points.iter().zip(&many) {
        let one = index.find(&s, *p, 1.0);
        assert_eq!(
            one.as_ref().map(|f| (f.facet, f.closest_node, &f.patch)),
            m.as_ref().map(|f| (f.facet, f.closest_node, &f.patch))
        );
        assert_eq!(
            one.map(|f| f.projection.xi),
            m.as_ref().map(|f| f.projection.xi)
        );
    }
    assert!(many[500].is_none() && many[501].is_none());
    assert!(many.iter().filter(|m| m.is_some()).count() > 400);
}

#[test]
fn large_ring_fan() {
    // 40 triangles around node 0 (more than the stack buffers hold),
    // a cone so the facets are not coplanar.
    let n = 40;
    let mut pos = vec![[0.0, 0.0, 1.0]];
    for i in 0..n {
        let t = 2.0 * std::f64::consts::PI * i as f64 / n as f64;
        pos.push([3.0 * t.cos(), 3.0 * t.sin(), 0.0]);
    }
    let facets: Vec<[u32; MAX_FACET_NODES]> = (0..n as u32)
        .map(|i| pad([0, 1 + i, 1 + (i + 1) % n as u32, 0]))
        .collect();
    let mesh = (pos, facets);
    let s = surface(FacetType::Tri3, &mesh);
    let mut rng = Lcg::new(27);
    check_find_against_brute(&s, 300, &mut rng, |r| {
        [1.5 * r.next(), 1.5 * r.next(), 0.8 + 0.5 * r.next()]
    });
    let index = SearchIndex::build(&s);
    let f = index.find(&s, [0.0, 0.0, 1.2], 10.0).unwrap();
    assert_eq!((f.facet, f.closest_node, f.patch.len()), (0, 0, n));
    // Every facet holds the apex: the inner search alone agrees.
    let all: Vec<u32> = (0..n as u32).rev().collect();
    assert_eq!(
        select_facet(&s, &all, [0.0, 0.0, 1.0], Some((39, [0.0, 0.0])))
            .unwrap()
            .0,
        0
    );
}

#[test]
fn cylinder_concave_side_picks_nearest_of_two_valid() {
    let mesh = cylinder(24, 4, 10.0, 8.0);
    let s = surface(FacetType::Quad4, &mesh);
    let index = SearchIndex::build(&s);
    let dt = 2.0 * std::f64::consts::PI / 24.0;
    // Facets 2 and 3 (first row) share the node line at angle 3 dt.
    let at = |t: f64, r: f64| [r * t.cos(), r * t.sin(), 1.0];
    for (t, want) in [(3.0 * dt, 2), (3.0 * dt - 0.01, 2), (3.0 * dt + 0.01, 3)] {
        let x = at(t, 9.0);
        // Both project validly: the situation under test.
        for f in [2u32, 3] {
            let nodes: Vec<_> = mesh.1[f as usize][..4]
                .iter()
                .map(|&n| mesh.0[n as usize])
                .collect();
            let p = project(FacetType::Quad4, &nodes, x, None);
            assert!(p.converged && p.outside <= INSIDE_TOL, "facet {f} at t={t}");
        }
        let found = index.find(&s, x, 100.0).unwrap();
        assert_eq!(found.facet, want, "t={t}");
        assert!(found.projection.outside <= INSIDE_TOL);
        assert!(found.projection.gap < 0.0, "inside the body");
    }
    // Outside over the convex edge: no facet holds the projection; the
    // edge is equally near both, so the smaller id.
    let found = index.find(&s, at(3.0 * dt, 11.0), 100.0).unwrap();
    assert_eq!(found.facet, 2);
    assert!(found.projection.outside > INSIDE_TOL);
    // Near the axis every facet of the row holds a valid projection, the
    // nearest is the one facing the point.
    let found = index.find(&s, at(5.5 * dt, 0.5), 100.0).unwrap();
    assert_eq!(found.facet, 5);
}

#[test]
fn flat_master_points_across_whole_plane() {
    let mut rng = Lcg::new(25);
    let mesh = plane_grid(40, 40, 0.5, 0.0, |_, _| 2.0, false, &mut rng);
    let s = surface(FacetType::Quad4, &mesh);
    let index = SearchIndex::build(&s);
    for _ in 0..2000 {
        let (x, y, dz) = (
            20.0 * unit(&mut rng),
            20.0 * unit(&mut rng),
            0.4 * rng.next(),
        );
        let found = index.find(&s, [x, y, 2.0 + dz], 1.0).unwrap();
        let (i, j) = ((x / 0.5).floor(), (y / 0.5).floor());
        assert_eq!(found.facet, (j * 40.0 + i) as u32);
        let p = &found.projection;
        assert!(p.outside <= INSIDE_TOL);
        assert!((p.gap - dz).abs() < 1e-12);
        assert!((p.xi[0] - (4.0 * (x - 0.5 * i) - 1.0)).abs() < 1e-9);
        assert!((p.xi[1] - (4.0 * (y - 0.5 * j) - 1.0)).abs() < 1e-9);
    }
}

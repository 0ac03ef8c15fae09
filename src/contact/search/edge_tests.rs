//! Search tests at the edges: facet edges, corners and nodes, far points,
//! bad input, grid-layout independence, facet selection and box overlap.

use super::tests::*;
use super::*;
use crate::fem::test_util::Lcg;
/// 4 × 4 unit quads at z = 0: facet (i, j) has id 4 j + i, node (i, j)
/// id 5 j + i.
fn small_flat() -> Mesh {
    plane_grid(4, 4, 1.0, 0.0, |_, _| 0.0, false, &mut Lcg::new(0))
}

#[test]
fn edges_corners_and_nodes() {
    let mesh = small_flat();
    let s = surface(FacetType::Quad4, &mesh);
    let index = SearchIndex::build(&s);
    let find = |x: [f64; 3]| index.find(&s, x, 10.0).unwrap();
    // Exactly on interior node 12 = (2, 2): facets 5, 6, 9, 10 all hold
    // it at distance 0; the smallest id wins. Same above it.
    for z in [0.0, 0.5, -0.5] {
        let f = find([2.0, 2.0, z]);
        assert_eq!((f.facet, f.closest_node), (5, 12), "z={z}");
        assert!(f.projection.outside <= INSIDE_TOL);
        assert!((f.projection.gap - z).abs() < 1e-12);
    }
    // On the edge between facets 5 and 9 (y = 2), and above it.
    assert_eq!(find([1.5, 2.0, 0.0]).facet, 5);
    assert_eq!(find([1.5, 2.0, 0.3]).facet, 5);
    // Just off it on either side.
    assert_eq!(find([1.5, 2.0 + 1e-3, 0.3]).facet, 9);
    assert_eq!(find([1.5, 2.0 - 1e-3, 0.3]).facet, 5);
    // Inside a facet.
    let f = find([1.3, 1.6, 0.2]);
    assert_eq!(f.facet, 5);
    assert!((f.projection.xi[0] + 0.4).abs() < 1e-12 && (f.projection.xi[1] - 0.2).abs() < 1e-12);
    // Beyond the outer corner and beyond the border: only clamped
    // projections exist.
    let f = find([-0.5, -0.5, 0.3]);
    assert_eq!((f.facet, f.closest_node), (0, 0));
    assert!(f.projection.outside > INSIDE_TOL);
    let f = find([-0.5, 2.0, 0.1]);
    assert_eq!(f.facet, 4, "edge shared by facets 4 and 8 at the border");
    assert!(f.projection.outside > INSIDE_TOL);
    // Corner node of the master exactly.
    assert_eq!(find([4.0, 4.0, 0.0]).facet, 15);
    // The inner search alone keeps the same ties even when it starts on
    // the larger id (the previous facet is projected first).
    let ring = [5, 6, 9, 10];
    for x in [[2.0, 2.0, 0.0], [2.0, 2.0, 0.4], [1.5, 2.0, 0.3]] {
        let (f, _) = select_facet(&s, &ring, x, Some((10, [-1.0, -1.0]))).unwrap();
        assert_eq!(f, 5, "x={x:?}");
    }
}

#[test]
fn far_points_and_max_distance() {
    let mesh = small_flat();
    let s = surface(FacetType::Quad4, &mesh);
    let index = SearchIndex::build(&s);
    let far = [1e3, 2e3, 5e2];
    assert!(index.find(&s, far, 10.0).is_none());
    let f = index.find(&s, far, f64::INFINITY).unwrap();
    assert_eq!((f.facet, f.closest_node), (15, 24));
    assert!(index.find(&s, far, f64::NAN).is_none());
    // Straight above the middle of the grid, far up.
    let f = index.find(&s, [2.2, 1.7, 1e3], f64::INFINITY).unwrap();
    assert_eq!(f.closest_node, 12);
    assert_eq!(f.facet, 6);
    // max_distance limits the closest NODE: above a facet centre the
    // nodes are 0.707 away.
    assert!(index.find(&s, [1.5, 1.5, 0.0], 0.7).is_none());
    assert!(index.find(&s, [1.5, 1.5, 0.0], 0.71).is_some());
}

#[test]
fn bad_input_finds_nothing_and_never_panics() {
    let mesh = small_flat();
    let s = surface(FacetType::Quad4, &mesh);
    let index = SearchIndex::build(&s);
    for x in [[f64::NAN, 0.0, 0.0], [0.0, f64::INFINITY, 0.0]] {
        assert!(index.closest_node(&s, x).is_none());
        assert!(index.find(&s, x, 1.0).is_none());
        assert!(select_facet(&s, &[0, 1], x, None).is_none());
    }
    // A surface that is not the one indexed.
    let other = small_flat();
    let short = SearchSurface {
        facets: &other.1[..3],
        ..surface(FacetType::Quad4, &other)
    };
    assert!(index.find(&short, [1.0, 1.0, 0.0], 1.0).is_none());
    let tri = surface(FacetType::Tri3, &other);
    assert!(index.find(&tri, [1.0, 1.0, 0.0], 1.0).is_none());

    // Empty surface.
    let empty: Mesh = (vec![], vec![]);
    let e = surface(FacetType::Quad4, &empty);
    let index = SearchIndex::build(&e);
    assert!(index.closest_node(&e, [0.0; 3]).is_none());
    assert!(index.find(&e, [0.0; 3], 1.0).is_none());
    assert!(!boxes_overlap(
        index.bounding_box(),
        ([-1.0; 3], [1.0; 3]),
        10.0
    ));

    // Broken facets are ignored, the good one still works.
    let mut mesh = small_flat();
    mesh.1[0] = pad([0, 1, 999, 5]);
    mesh.1[1][2] = u32::MAX;
    mesh.0[20] = [f64::NAN, 0.0, 0.0]; // node of facet 12
    let s = surface(FacetType::Quad4, &mesh);
    let index = SearchIndex::build(&s);
    let f = index.find(&s, [0.5, 0.5, 0.1], 10.0).unwrap();
    assert!(![0, 1, 12].contains(&f.facet));
    assert!(![0, 1, 12].iter().any(|b| f.patch.contains(b)));
    assert!(index.find(&s, [0.5, 3.5, 0.1], 10.0).is_some());
    assert!(select_facet(&s, &[0, 1, 12, 77], [0.5, 0.5, 0.1], None).is_none());
    // Degenerate facet (all nodes equal) and a collapsed quad.
    let mesh: Mesh = (
        vec![[0.0; 3], [0.0; 3], [1.0, 0.0, 0.0], [1.0, 1.0, 0.0]],
        vec![pad([0, 1, 0, 1]), pad([0, 2, 3, 3])],
    );
    let s = surface(FacetType::Quad4, &mesh);
    let index = SearchIndex::build(&s);
    let f = index.find(&s, [0.7, 0.2, 0.1], 10.0).unwrap();
    assert_eq!(f.facet, 1);
}

#[test]
fn result_does_not_depend_on_grid_layout() {
    // The same surface with a far-away extra facet appended: different
    // bounding box and (capped) cell size, identical answers.
    let mut rng = Lcg::new(31);
    let z = |x: f64, y: f64| 0.5 * (0.6 * x).sin() * (0.3 * y).sin();
    let mesh = plane_grid(10, 10, 1.0, 0.3, z, false, &mut rng);
    let mut wide = mesh.clone();
    let base = wide.0.len() as u32;
    wide.0.extend([
        [500.0, 0.0, 300.0],
        [501.0, 0.0, 300.0],
        [501.0, 1.0, 300.0],
        [500.0, 1.0, 300.0],
    ]);
    wide.1.push(pad([base, base + 1, base + 2, base + 3]));
    let (a, b) = (
        surface(FacetType::Quad4, &mesh),
        surface(FacetType::Quad4, &wide),
    );
    let (ia, ib) = (SearchIndex::build(&a), SearchIndex::build(&b));
    assert_ne!(ia.grid.cell, ib.grid.cell);
    for _ in 0..500 {
        let (x, y) = (11.0 * unit(&mut rng) - 0.5, 11.0 * unit(&mut rng) - 0.5);
        let p = [x, y, z(x, y) + 0.4 * rng.next()];
        let (fa, fb) = (ia.find(&a, p, 5.0).unwrap(), ib.find(&b, p, 5.0).unwrap());
        assert_eq!(
            (fa.facet, fa.closest_node, &fa.patch),
            (fb.facet, fb.closest_node, &fb.patch)
        );
        assert_eq!(fa.projection.xi, fb.projection.xi);
    }
}

#[test]
fn select_facet_matches_brute_force_on_candidates() {
    let mut rng = Lcg::new(41);
    let z = |x: f64, y: f64| 0.6 * (0.5 * x).sin() * (0.5 * y).cos();
    let mesh = plane_grid(12, 12, 1.0, 0.25, z, false, &mut rng);
    let s = surface(FacetType::Quad4, &mesh);
    let index = SearchIndex::build(&s);
    for q in 0..500 {
        let (x, y) = (2.0 + 8.0 * unit(&mut rng), 2.0 + 8.0 * unit(&mut rng));
        let x0 = [x, y, z(x, y) + 0.3 * rng.next()];
        let found = index.find(&s, x0, 5.0).unwrap();
        // Newton moves the slave point (large sliding) within the patch.
        let x1 = [
            x0[0] + 1.2 * rng.next(),
            x0[1] + 1.2 * rng.next(),
            x0[2] + 0.2 * rng.next(),
        ];
        let previous = Some((found.facet, found.projection.xi));
        let (f, p) = select_facet(&s, &found.patch, x1, previous).unwrap();
        let brute = brute_force(&s, &found.patch, x1).unwrap();
        assert_eq!(f, brute.facet, "query {q}");
        assert_eq!(p.outside <= INSIDE_TOL, brute.valid);
        let (g, _) = select_facet(&s, &found.patch, x1, None).unwrap();
        assert_eq!(g, f, "start must not change the choice");
        // When the patch holds the global winner, it agrees with find.
        let global = index.find(&s, x1, 5.0).unwrap();
        if found.patch.contains(&global.facet) {
            assert_eq!(f, global.facet);
        }
    }
    assert!(select_facet(&s, &[], [1.0, 1.0, 0.0], None).is_none());
    assert!(select_facet(&s, &[9999], [1.0, 1.0, 0.0], None).is_none());
    // A previous facet that is not a candidate is ignored.
    let (f, _) = select_facet(&s, &[0, 1], [0.5, 0.5, 0.0], Some((50, [0.0, 0.0]))).unwrap();
    assert_eq!(f, 0);
    // Non-finite previous ξ falls back to the default start.
    let (f, _) = select_facet(&s, &[0, 1], [0.5, 0.5, 0.0], Some((0, [f64::NAN, 0.0]))).unwrap();
    assert_eq!(f, 0);
}

#[test]
fn boxes_overlap_cases() {
    let unit_box = ([0.0; 3], [1.0; 3]);
    let shifted = |d: [f64; 3]| (d, [d[0] + 1.0, d[1] + 1.0, d[2] + 1.0]);
    assert!(boxes_overlap(unit_box, shifted([0.5, 0.5, 0.5]), 0.0));
    assert!(
        boxes_overlap(unit_box, shifted([1.0, 0.0, 0.0]), 0.0),
        "touching"
    );
    assert!(!boxes_overlap(unit_box, shifted([1.2, 0.0, 0.0]), 0.1));
    assert!(boxes_overlap(unit_box, shifted([1.2, 0.0, 0.0]), 0.2));
    assert!(
        !boxes_overlap(unit_box, shifted([-1.3, 0.0, 0.0]), 0.2),
        "other side"
    );
    assert!(
        !boxes_overlap(unit_box, shifted([0.0, 0.0, 1.5]), 0.2),
        "z only"
    );
    assert!(!boxes_overlap(unit_box, shifted([1.5, 1.5, 1.5]), 0.4));
    // Each axis within the margin: overlap, though the corners are
    // farther apart than the margin (boxes, not balls).
    assert!(boxes_overlap(unit_box, shifted([1.3, 1.3, 1.3]), 0.3));
    assert!(
        boxes_overlap(shifted([5.0, 5.0, 5.0]), shifted([5.0, 5.0, 5.0]), 0.0),
        "same box"
    );
    assert!(!boxes_overlap(unit_box, EMPTY_BOX, 1e9), "empty box");
    assert!(
        boxes_overlap(unit_box, shifted([9.0, 9.0, 9.0]), f64::NAN),
        "NaN: search anyway"
    );
    assert_eq!(points_bounding_box(&[]), None);
    assert_eq!(points_bounding_box(&[[f64::NAN, 0.0, 0.0]]), None);
    assert_eq!(
        points_bounding_box(&[[1.0, 2.0, 3.0], [f64::NAN, 9.0, 9.0], [-1.0, 5.0, 0.0]]),
        Some(([-1.0, 2.0, 0.0], [1.0, 5.0, 3.0]))
    );
    let mesh = small_flat();
    let index = SearchIndex::build(&surface(FacetType::Quad4, &mesh));
    assert_eq!(index.bounding_box(), ([0.0; 3], [4.0, 4.0, 0.0]));
}

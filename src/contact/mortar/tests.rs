//! Geometry, dual basis and the consistency of the mortar tangent.
use super::geometry::{
    boxes_apart, clip, inverse_map, overlap, shape_values, Plane, Polygon, BOX_MARGIN, GEOMETRY_TOL,
};
use super::segment::{dual_coefficients, dual_values, segment_terms, MortarRules};
use super::system::{
    covered_facets, for_each_segment, node_states, residual, segments, slave_nodal_areas, tangent,
    weighted_gaps, Interface, NodalData, Segment,
};
use crate::contact::autodiff::Dual;
use crate::fem::test_util::Lcg;
use crate::fem::FacetType::{self, Quad4, Tri3};

fn square(x0: f64, y0: f64, s: f64, z: f64) -> Vec<[f64; 3]> {
    vec![
        [x0, y0, z],
        [x0 + s, y0, z],
        [x0 + s, y0 + s, z],
        [x0, y0 + s, z],
    ]
}

/// The same square seen from the other side (a master facet's orientation).
fn flipped(mut x: Vec<[f64; 3]>) -> Vec<[f64; 3]> {
    x.reverse();
    x
}

fn area(slave: FacetType, xs: &[[f64; 3]], master: FacetType, xm: &[[f64; 3]]) -> f64 {
    overlap::<f64>(slave, xs, master, xm).map_or(0.0, |o| o.polygon.signed_area())
}

#[test]
fn overlap_of_shifted_squares() {
    let xs = square(0.0, 0.0, 1.0, 0.0);
    let xm = flipped(square(0.5, 0.25, 1.0, 0.1));
    assert!((area(Quad4, &xs, Quad4, &xm) - 0.375).abs() < 1e-14);
    // Disjoint and edge-touching facets do not overlap.
    assert_eq!(
        area(Quad4, &xs, Quad4, &flipped(square(2.0, 0.0, 1.0, 0.0))),
        0.0
    );
    assert_eq!(
        area(Quad4, &xs, Quad4, &flipped(square(1.0, 0.0, 1.0, 0.0))),
        0.0
    );
}

#[test]
fn overlap_of_square_and_rotated_square_is_an_octagon() {
    let xs = square(-0.5, -0.5, 1.0, 0.0);
    let (c, s) = (
        std::f64::consts::FRAC_PI_4.cos(),
        std::f64::consts::FRAC_PI_4.sin(),
    );
    let xm: Vec<[f64; 3]> = flipped(square(-0.5, -0.5, 1.0, -0.2))
        .iter()
        .map(|p| [c * p[0] - s * p[1], s * p[0] + c * p[1], p[2]])
        .collect();
    let ov = overlap::<f64>(Quad4, &xs, Quad4, &xm).unwrap();
    assert_eq!(ov.polygon.len, 8);
    let exact = 2.0 * (2f64.sqrt() - 1.0);
    assert!((ov.polygon.signed_area() - exact).abs() < 1e-14);
}

#[test]
fn triangle_and_quad_overlaps() {
    let tri = vec![[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]];
    let xm = flipped(square(0.0, 0.0, 1.0, 0.0));
    assert!((area(Tri3, &tri, Quad4, &xm) - 0.5).abs() < 1e-14);
    let xs = square(0.0, 0.0, 1.0, 0.0);
    let tri_m = vec![[0.0, 0.0, 0.0], [0.0, 1.0, 0.0], [1.0, 0.0, 0.0]];
    assert!((area(Quad4, &xs, Tri3, &tri_m) - 0.5).abs() < 1e-14);
    let shifted = vec![[0.5, 0.5, 0.0], [0.5, 1.5, 0.0], [1.5, 0.5, 0.0]];
    // Its long edge passes through the square's corner (1, 1).
    assert!((area(Quad4, &xs, Tri3, &shifted) - 0.25).abs() < 1e-14);
    let cutting = vec![[0.0, 0.5, 0.0], [0.0, 1.5, 0.0], [1.0, 0.5, 0.0]];
    assert!((area(Quad4, &xs, Tri3, &cutting) - 0.375).abs() < 1e-14);
}

/// A master `n × n` grid over `[x0, x0 + size]²`, perturbed in plane and
/// height, oriented as a master (normal down).
fn master_grid(
    n: usize,
    x0: f64,
    size: f64,
    z: f64,
    rng: &mut Lcg,
    amp: f64,
) -> Vec<Vec<[f64; 3]>> {
    let h = size / n as f64;
    let node = |i: usize, j: usize, rng: &mut Lcg| {
        let interior = i > 0 && j > 0 && i < n && j < n;
        let d = if interior { amp * h } else { 0.0 };
        [
            x0 + i as f64 * h + d * rng.next(),
            x0 + j as f64 * h + d * rng.next(),
            z + 0.01 * rng.next(),
        ]
    };
    let mut grid = vec![vec![[0.0; 3]; n + 1]; n + 1];
    for (i, col) in grid.iter_mut().enumerate() {
        for (j, p) in col.iter_mut().enumerate() {
            *p = node(i, j, rng);
        }
    }
    let mut facets = Vec::new();
    for i in 0..n {
        for j in 0..n {
            facets.push(flipped(vec![
                grid[i][j],
                grid[i + 1][j],
                grid[i + 1][j + 1],
                grid[i][j + 1],
            ]));
        }
    }
    facets
}

#[test]
fn overlaps_with_a_covering_master_partition_the_projected_slave() {
    let mut rng = Lcg::new(7);
    let xs = vec![
        [0.1, 0.2, 0.0],
        [0.9, 0.15, 0.02],
        [0.8, 0.85, -0.01],
        [0.2, 0.7, 0.0],
    ];
    let plane = Plane::<f64>::of_facet(Quad4, &xs).unwrap();
    let projected: Vec<[f64; 2]> = xs.iter().map(|x| plane.coordinates(x)).collect();
    let slave_area = Polygon::from_points(&projected).signed_area();
    for (n, amp) in [(3, 0.0), (5, 0.25), (7, 0.3)] {
        let total: f64 = master_grid(n, -0.05, 1.1, 0.05, &mut rng, amp)
            .iter()
            .map(|xm| area(Quad4, &xs, Quad4, xm))
            .sum();
        assert!(
            (total - slave_area).abs() < 1e-12,
            "{n}x{n}: {total} vs {slave_area}"
        );
    }
}

#[test]
fn clipping_a_polygon_by_itself_returns_it() {
    let p = Polygon::from_points(&[[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]]);
    let c = clip(&p, &p, 1e-12);
    assert_eq!(c.len, 4);
    assert!((c.signed_area() - 1.0).abs() < 1e-15);
}

#[test]
fn quadrature_points_map_back_onto_both_facets() {
    let xs = vec![
        [0.0, 0.0, 0.0],
        [1.1, 0.1, 0.05],
        [1.0, 0.9, 0.0],
        [-0.1, 1.0, -0.05],
    ];
    let xm = flipped(vec![
        [0.3, 0.2, 0.2],
        [1.4, 0.3, 0.1],
        [1.3, 1.2, 0.2],
        [0.2, 1.1, 0.1],
    ]);
    let ov = overlap::<f64>(Quad4, &xs, Quad4, &xm).unwrap();
    let rules = MortarRules::default();
    let mut sum = 0.0;
    assert!(ov.for_each_point(Quad4, Quad4, &rules.triangle, |q| {
        sum += q.weight;
        for (facet_x, zeta) in [(&xs, q.zeta), (&xm, q.xi)] {
            let n = shape_values(Quad4, &zeta);
            let x: [f64; 3] = [0, 1, 2].map(|i| (0..4).map(|a| n[a] * facet_x[a][i]).sum());
            // Both facet points project onto the same point of the plane.
            let p = ov.plane.coordinates(&x);
            let slave_p = {
                let ns = shape_values(Quad4, &q.zeta);
                let xs_p: [f64; 3] = [0, 1, 2].map(|i| (0..4).map(|a| ns[a] * xs[a][i]).sum());
                ov.plane.coordinates(&xs_p)
            };
            assert!((p[0] - slave_p[0]).abs() < 1e-12 && (p[1] - slave_p[1]).abs() < 1e-12);
        }
    }));
    assert!((sum - ov.polygon.signed_area()).abs() < 1e-14);
    // The inverse map of a vertex of the slave is its reference corner.
    let z = inverse_map(Quad4, &ov.slave_nodes, &ov.slave_nodes[2]).unwrap();
    assert!((z[0] - 1.0).abs() < 1e-12 && (z[1] - 1.0).abs() < 1e-12);
}

fn distorted_quad() -> Vec<[f64; 3]> {
    vec![
        [0.0, 0.0, 0.0],
        [1.2, 0.1, 0.1],
        [1.0, 0.8, 0.0],
        [0.1, 1.1, -0.1],
    ]
}

#[test]
fn dual_basis_is_biorthogonal_and_sums_to_one() {
    let rules = MortarRules::default();
    for (facet, x) in [
        (Quad4, distorted_quad()),
        (
            Tri3,
            vec![[0.0, 0.0, 0.0], [1.3, 0.2, 0.1], [0.2, 0.9, 0.0]],
        ),
    ] {
        let a = dual_coefficients::<f64>(facet, &x, &rules).unwrap();
        let n = facet.nodes();
        let (mut dm, mut d) = ([[0.0; 4]; 4], [0.0; 4]);
        for (zeta, w) in rules.facet(facet) {
            let s = super::facet_shape(facet, *zeta);
            let t = |c: usize| -> [f64; 3] {
                [0, 1, 2].map(|i| (0..n).map(|k| s.dn[k][c] * x[k][i]).sum())
            };
            let jw =
                crate::contact::autodiff::norm(&crate::contact::autodiff::cross(&t(0), &t(1))) * w;
            let phi = dual_values(&a, &s.n, n);
            assert!((phi[..n].iter().sum::<f64>() - 1.0).abs() < 1e-13);
            for j in 0..n {
                d[j] += s.n[j] * jw;
                for (dmk, nk) in dm[j].iter_mut().zip(&s.n).take(n) {
                    *dmk += phi[j] * nk * jw;
                }
            }
        }
        for (j, row) in dm.iter().enumerate().take(n) {
            for (k, v) in row.iter().enumerate().take(n) {
                let expected = if j == k { d[j] } else { 0.0 };
                assert!((v - expected).abs() < 1e-13, "{facet:?} {j} {k}");
            }
        }
    }
}

#[test]
fn parallel_facets_give_gap_times_nodal_area_and_consistent_forces() {
    let rules = MortarRules::default();
    let xs = square(0.0, 0.0, 1.0, 0.0);
    let a = dual_coefficients::<f64>(Quad4, &xs, &rules).unwrap();
    let mut rng = Lcg::new(3);
    let (mut gap, mut d, mut m_sum) = ([0.0; 4], [0.0; 4], [0.0; 4]);
    for xm in master_grid(3, -0.2, 1.5, 0.0, &mut rng, 0.2) {
        let xm: Vec<[f64; 3]> = xm.iter().map(|p| [p[0], p[1], 0.25]).collect();
        if let Some(t) = segment_terms(Quad4, &xs, &xs, Quad4, &xm, &a, &rules, None) {
            for j in 0..4 {
                gap[j] += t.weighted_gap[j];
                d[j] += (0..4).map(|k| t.d[j][k]).sum::<f64>();
                m_sum[j] += (0..4).map(|l| t.m[j][l]).sum::<f64>();
            }
        }
    }
    for j in 0..4 {
        assert!((d[j] - 0.25).abs() < 1e-13);
        assert!((m_sum[j] - 0.25).abs() < 1e-13);
        assert!((gap[j] - 0.25 * 0.25).abs() < 1e-13);
    }
}

/// A random interface: a 2×2 slave patch (quads or triangles) under a
/// perturbed, rotated, slightly penetrating master patch.
pub(super) struct Case {
    pub(super) slave_type: FacetType,
    pub(super) master_type: FacetType,
    pub(super) positions: Vec<[f64; 3]>,
    pub(super) slave_facets: Vec<[u32; 4]>,
    pub(super) master_facets: Vec<[u32; 4]>,
    pub(super) candidates: Vec<(u32, u32)>,
    pub(super) assembled: Vec<bool>,
    pub(super) nodal: NodalData,
}

/// Where a test patch sits: facets per side, side length, height, rotation
/// about the vertical axis, and whether it is a master (normal down).
struct PatchSpec {
    n: usize,
    size: f64,
    z: f64,
    angle: f64,
    master: bool,
    /// Node perturbations (in-plane, out of plane) relative to the facet
    /// size; zero leaves parallelograms, whose maps onto the plane are
    /// affine.
    jitter: [f64; 2],
}

fn patch(
    facet: FacetType,
    spec: PatchSpec,
    rng: &mut Lcg,
    positions: &mut Vec<[f64; 3]>,
) -> Vec<[u32; 4]> {
    let PatchSpec {
        n,
        size,
        z,
        angle,
        master,
        jitter,
    } = spec;
    let base = positions.len() as u32;
    let h = size / n as f64;
    let (c, s) = (angle.cos(), angle.sin());
    for j in 0..=n {
        for i in 0..=n {
            let (x, y) = (i as f64 * h - size / 2.0, j as f64 * h - size / 2.0);
            let (x, y) = (
                x + jitter[0] * h * rng.next(),
                y + jitter[0] * h * rng.next(),
            );
            positions.push([c * x - s * y, s * x + c * y, z + jitter[1] * h * rng.next()]);
        }
    }
    let id = |i: usize, j: usize| base + (j * (n + 1) + i) as u32;
    let mut facets = Vec::new();
    for j in 0..n {
        for i in 0..n {
            let q = [id(i, j), id(i + 1, j), id(i + 1, j + 1), id(i, j + 1)];
            let mut list = match facet {
                Quad4 => vec![q],
                _ => vec![[q[0], q[1], q[2], 0], [q[0], q[2], q[3], 0]],
            };
            if master {
                for f in &mut list {
                    f[..facet.nodes()].reverse();
                }
            }
            facets.extend(list);
        }
    }
    facets
}

pub(super) fn random_case(seed: u64, slave_type: FacetType, master_type: FacetType) -> Case {
    case_with(seed, slave_type, master_type, [0.15, 0.05])
}

/// [`random_case`] with the master patch moved by `shift` along x: it then
/// covers the slave facets on one side whole and those on the other in part
/// (`coverage`: integrated `D` there, the exact diagonal on the others).
pub(super) fn shifted_case(seed: u64, slave_type: FacetType, shift: f64) -> Case {
    let mut case = random_case(seed, slave_type, Quad4);
    let n_slave = case.nodal.nodes.len();
    for p in &mut case.positions[n_slave..] {
        p[0] += shift;
    }
    case
}

/// [`random_case`] with unperturbed nodes: a square slave grid under a
/// rotated square master grid, every facet mapping affinely onto the plane
/// (the block slide's facets, where the inverse maps take their affine
/// path).
pub(super) fn parallelogram_case(seed: u64) -> Case {
    case_with(seed, Quad4, Quad4, [0.0, 0.0])
}

pub(super) fn case_with(
    seed: u64,
    slave_type: FacetType,
    master_type: FacetType,
    jitter: [f64; 2],
) -> Case {
    let mut rng = Lcg::new(seed);
    let mut positions = Vec::new();
    let slave = PatchSpec {
        n: 2,
        size: 2.0,
        z: 0.0,
        angle: 0.0,
        master: false,
        jitter,
    };
    let slave_facets = patch(slave_type, slave, &mut rng, &mut positions);
    let n_slave = positions.len();
    let angle = 0.3 * rng.next();
    let master = PatchSpec {
        n: 3,
        size: 2.6,
        z: -0.02,
        angle,
        master: true,
        jitter,
    };
    let master_facets = patch(master_type, master, &mut rng, &mut positions);
    let mut candidates = Vec::new();
    for s in 0..slave_facets.len() as u32 {
        for m in 0..master_facets.len() as u32 {
            candidates.push((s, m));
        }
    }
    let nodes: Vec<u32> = (0..n_slave as u32).collect();
    let lambda = (0..n_slave).map(|_| 0.5 + 0.4 * rng.next()).collect();
    let penalty = (0..n_slave).map(|_| 50.0 * (1.5 + rng.next())).collect();
    let area = (0..n_slave).map(|_| 0.25 + 0.05 * rng.next()).collect();
    Case {
        slave_type,
        master_type,
        positions,
        assembled: vec![true; slave_facets.len()],
        slave_facets,
        master_facets,
        candidates,
        nodal: NodalData::new(nodes, lambda, penalty, area),
    }
}

impl Case {
    pub(super) fn interface<'a>(&'a self, positions: &'a [[f64; 3]]) -> Interface<'a> {
        Interface {
            slave_type: self.slave_type,
            master_type: self.master_type,
            positions,
            reference: &self.positions,
            slave_facets: &self.slave_facets,
            master_facets: &self.master_facets,
            candidates: &self.candidates,
            assembled: &self.assembled,
        }
    }

    fn residual(&self, positions: &[[f64; 3]]) -> Vec<f64> {
        let interface = self.interface(positions);
        let rules = MortarRules::default();
        let segs: Vec<Segment<f64>> = segments(&interface, &rules);
        let (gap, covered) = weighted_gaps(&interface, &self.nodal, &segs);
        let states = node_states(&self.nodal, &gap, &covered);
        let mut r = vec![0.0; 3 * positions.len()];
        residual(&interface, &self.nodal, &segs, &states, |n, i, v| {
            r[3 * n as usize + i] += v;
        });
        r
    }

    fn tangent(&self) -> (Vec<f64>, usize) {
        let interface = self.interface(&self.positions);
        let rules = MortarRules::default();
        let segs: Vec<Segment<Dual<24>>> = segments(&interface, &rules);
        let (gap, covered) = weighted_gaps(&interface, &self.nodal, &segs);
        let states = node_states(&self.nodal, &gap, &covered);
        let n = 3 * self.positions.len();
        let mut k = vec![0.0; n * n];
        tangent(&interface, &self.nodal, &segs, &states, |r, c, v| {
            k[(3 * r.0 as usize + r.1) * n + 3 * c.0 as usize + c.1] += v;
        });
        (k, states.iter().filter(|s| s.closed).count())
    }
}

#[test]
fn tangent_matches_finite_differences_of_the_residual() {
    let cases = [
        (11, Quad4, Quad4),
        (12, Quad4, Quad4),
        (13, Tri3, Quad4),
        (14, Quad4, Tri3),
        (15, Tri3, Tri3),
    ]
    .map(|(seed, s, m)| (seed, random_case(seed, s, m)))
    .into_iter()
    .chain([
        (16, parallelogram_case(16)),
        (17, shifted_case(17, Quad4, 0.7)),
        (18, shifted_case(18, Tri3, 0.7)),
    ]);
    for (seed, case) in cases {
        let (s, m) = (case.slave_type, case.master_type);
        let (k, closed) = case.tangent();
        assert!(closed >= 4, "seed {seed}: only {closed} closed nodes");
        let n = 3 * case.positions.len();
        let h = 1e-6;
        let mut fd = vec![0.0; n * n];
        for col in 0..n {
            let mut plus = case.positions.clone();
            let mut minus = case.positions.clone();
            plus[col / 3][col % 3] += h;
            minus[col / 3][col % 3] -= h;
            let (rp, rm) = (case.residual(&plus), case.residual(&minus));
            for row in 0..n {
                fd[row * n + col] = (rp[row] - rm[row]) / (2.0 * h);
            }
        }
        let scale = fd.iter().fold(0.0f64, |a, v| a.max(v.abs()));
        let err = k
            .iter()
            .zip(&fd)
            .fold(0.0f64, |a, (x, y)| a.max((x - y).abs()));
        assert!(scale > 1.0, "seed {seed}: tangent vanishes");
        assert!(
            err < 1e-6 * scale,
            "seed {seed} {s:?}/{m:?}: {err:e} vs {scale:e}"
        );
    }
}

/// On a flat slave, moving a master node along the slave's normal moves
/// neither the overlaps nor `D`, `M`, `ν`: there the consistent tangent is
/// its main part, `(ε_j/A_j) f_j ⊗ f_j`. The main part is symmetric.
#[test]
fn main_part_is_the_tangent_along_the_normal_of_master_nodes() {
    for (seed, s, m) in [(21, Quad4, Quad4), (22, Tri3, Quad4), (23, Quad4, Tri3)] {
        let mut case = random_case(seed, s, m);
        let n_slave = case.nodal.nodes.len();
        for p in &mut case.positions[..n_slave] {
            p[2] = 0.0;
        }
        let (k, closed) = case.tangent();
        assert!(closed >= 4, "seed {seed}: only {closed} closed nodes");
        let interface = case.interface(&case.positions);
        let rules = MortarRules::default();
        let segs: Vec<Segment<f64>> = segments(&interface, &rules);
        let (gap, covered) = weighted_gaps(&interface, &case.nodal, &segs);
        let states = node_states(&case.nodal, &gap, &covered);
        let n = 3 * case.positions.len();
        let mut main = vec![0.0; n * n];
        super::main_part::tangent(&interface, &case.nodal, &segs, &states, |r, c, v| {
            main[(3 * r.0 as usize + r.1) * n + 3 * c.0 as usize + c.1] += v;
        });
        let scale = main.iter().fold(0.0f64, |a, v| a.max(v.abs()));
        assert!(scale > 1.0, "seed {seed}: main part vanishes");
        for row in 0..n {
            for col in 0..n {
                let (a, b) = (main[row * n + col], main[col * n + row]);
                assert!((a - b).abs() < 1e-12 * scale, "seed {seed}: not symmetric");
            }
            for node in n_slave..case.positions.len() {
                let col = 3 * node + 2;
                let (a, b) = (main[row * n + col], k[row * n + col]);
                assert!(
                    (a - b).abs() < 1e-9 * scale,
                    "seed {seed} row {row} col {col}: {a:e} vs {b:e}"
                );
            }
        }
    }
}

/// The bounding-box early-out of `overlap` drops only pairs whose clip is
/// empty: a unit square against a sharp (20°) triangle and a square slid
/// past each of its sides and corners, down to a tenth of the clipping
/// tolerance apart and overlapping by as little.
#[test]
fn box_early_out_skips_only_empty_clips() {
    let slave = Polygon::from_points(&[[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]]);
    let tol = GEOMETRY_TOL;
    let sharp = |x: f64, y: f64| {
        let (c, s) = (20f64.to_radians().cos(), 20f64.to_radians().sin());
        vec![
            [x, y],
            [x + 0.5 * c, y + 0.5 * s],
            [x + 0.5 * c, y - 0.5 * s],
        ]
    };
    let square = |x: f64, y: f64| vec![[x, y], [x + 0.4, y], [x + 0.4, y + 0.4], [x, y + 0.4]];
    let gaps = [-1e-10, 1e-10, 1e-9, 3e-9, 1e-8, 1e-7, 1e-6, 1e-3, 0.1];
    let (mut skipped, mut kept) = (0, 0);
    for &g in &gaps {
        for corners in [
            sharp(1.0 + g, 0.5),
            sharp(1.0 + g, 1.0 + g),
            square(1.0 + g, 0.3),
            square(-0.4 - g, -0.4 - g),
            square(0.3, 1.0 + g),
        ] {
            let master = Polygon::from_points(&corners).counter_clockwise();
            if !boxes_apart(slave.points(), master.points(), BOX_MARGIN * tol) {
                kept += 1;
                continue;
            }
            skipped += 1;
            let clipped = clip(&slave, &master, tol);
            assert!(
                clipped.len < 3 || clipped.signed_area() <= tol,
                "gap {g:e}: skipped a clip of area {}",
                clipped.signed_area()
            );
        }
    }
    assert!(skipped > 0 && kept > 0, "skipped {skipped}, kept {kept}");
}

/// A slave facet the master covers whole carries the exact diagonal
/// `∫ N_j dA₀` as its `D`, which the segments' integrals give to their
/// quadrature error; a facet covered in part keeps the integrals; and the
/// tangent's streamed segments, told the coverage, are the same terms as
/// the integrated ones set afterwards, values and derivatives.
#[test]
fn covered_facets_carry_their_exact_diagonal() {
    let rules = MortarRules::default();
    for (seed, case) in [
        (31, random_case(31, Quad4, Quad4)),
        (32, shifted_case(32, Quad4, 0.7)),
        (33, shifted_case(33, Tri3, 0.7)),
    ] {
        let interface = case.interface(&case.positions);
        let mut integrated: Vec<Segment<f64>> = Vec::new();
        for_each_segment(&interface, &rules, &[], |s| integrated.push(s));
        let covered = covered_facets(&interface, &rules, &integrated);
        let set: Vec<Segment<f64>> = segments(&interface, &rules);
        let ns = case.slave_type.nodes();
        let mut worst = 0.0f64;
        for f in 0..case.slave_facets.len() as u32 {
            let sum = |segs: &[Segment<f64>]| {
                let mut d = [[0.0; 4]; 4];
                for seg in segs.iter().filter(|s| s.slave == f) {
                    for (dj, sj) in d.iter_mut().zip(&seg.terms.d) {
                        for (x, y) in dj.iter_mut().zip(sj) {
                            *x += y;
                        }
                    }
                }
                d
            };
            let (raw, exact) = (sum(&integrated), sum(&set));
            let areas = slave_nodal_areas(&interface, f, &rules);
            for j in 0..ns {
                for k in 0..ns {
                    if !covered[f as usize] {
                        assert_eq!(raw[j][k], exact[j][k], "seed {seed} facet {f}");
                        continue;
                    }
                    let diagonal = if j == k { areas[j] } else { 0.0 };
                    assert_eq!(exact[j][k], diagonal, "seed {seed} facet {f}");
                    let err = (raw[j][k] - diagonal).abs();
                    worst = worst.max(err / areas[j]);
                }
            }
        }
        // The quadrature error of the segments' integrals on these bent,
        // jittered facets (nodes moved by up to 15 % of the facet in the
        // plane, 5 % out of it): 5.5e-7, 3.4e-8 and 8e-16 (triangles).
        eprintln!("seed {seed}: segments' D off the exact diagonal by {worst:.1e}");
        assert!(worst < 1e-6, "seed {seed}: {worst:e}");
        let (n_covered, n_facets) = (covered.iter().filter(|c| **c).count(), covered.len());
        assert!(n_covered > 0, "seed {seed}: no covered facet");
        if seed != 31 {
            assert!(n_covered < n_facets, "seed {seed}: every facet covered");
        }
        let set: Vec<Segment<Dual<24>>> = segments(&interface, &rules);
        let mut streamed: Vec<Segment<Dual<24>>> = Vec::new();
        for_each_segment(&interface, &rules, &covered, |s| streamed.push(s));
        assert_eq!(set.len(), streamed.len());
        for (a, b) in set.iter().zip(&streamed) {
            let (a, b) = (&a.terms, &b.terms);
            let rows = a.d.iter().chain(&a.m).zip(b.d.iter().chain(&b.m));
            for (x, y) in rows
                .flat_map(|(x, y)| x.iter().zip(y))
                .chain(a.weighted_gap.iter().zip(&b.weighted_gap))
            {
                assert!(
                    x.re == y.re && x.eps == y.eps,
                    "seed {seed}: streamed terms differ"
                );
            }
        }
    }
}

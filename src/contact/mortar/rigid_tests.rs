//! Mortar against rigid masters: the integrals on a flat patch, and the
//! tangent (normal and frictional, stick and slip, quasi-static and
//! dynamic increments) against finite differences of the residual on a
//! perturbed slave patch pressed into a rigid plane, sphere and cylinder.
use super::friction::{Increment, NodalFriction, NodeFriction};
use super::rigid::{self, RigidFacet, RigidInterface, RD};
use super::rigid_friction;
use super::segment::MortarRules;
use super::system::{node_states, NodalData};
use crate::fem::test_util::Lcg;
use crate::fem::FacetType::{self, Quad4, Tri3};
use crate::model::RigidSurface;

struct Case {
    facet_type: FacetType,
    positions: Vec<[f64; 3]>,
    facets: Vec<[u32; 4]>,
    candidates: Vec<(u32, u32)>,
    assembled: Vec<bool>,
    expected: Vec<u32>,
    nodal: NodalData,
    surface: RigidSurface,
    friction: Option<NodalFriction>,
    /// Slave increments at `positions` (affine with `slope`) and the master's.
    base: Vec<[f64; 3]>,
    slope: f64,
    master: [f64; 3],
}

/// A 3×3 patch of `facet_type` over `[-1, 1]²` at height `z(x, y)`,
/// perturbed by `amp` in all directions.
fn patch(
    facet_type: FacetType,
    z: impl Fn(f64, f64) -> f64,
    rng: &mut Lcg,
    amp: f64,
) -> (Vec<[f64; 3]>, Vec<[u32; 4]>) {
    let n = 3;
    let h = 2.0 / n as f64;
    let mut positions = Vec::new();
    for j in 0..=n {
        for i in 0..=n {
            let (x, y) = (-1.0 + i as f64 * h, -1.0 + j as f64 * h);
            let (x, y) = (x + amp * h * rng.next(), y + amp * h * rng.next());
            positions.push([x, y, z(x, y) + 0.3 * amp * h * rng.next()]);
        }
    }
    let id = |i: usize, j: usize| (j * (n + 1) + i) as u32;
    let mut facets = Vec::new();
    for j in 0..n {
        for i in 0..n {
            // Counter-clockwise seen from +z: the slave's outward normal is −z.
            let q = [id(i, j), id(i, j + 1), id(i + 1, j + 1), id(i + 1, j)];
            match facet_type {
                Quad4 => facets.push(q),
                _ => facets.extend([[q[0], q[1], q[2], 0], [q[0], q[2], q[3], 0]]),
            }
        }
    }
    (positions, facets)
}

fn case(seed: u64, facet_type: FacetType, surface: RigidSurface, mu: Option<f64>) -> Case {
    let mut rng = Lcg::new(seed);
    // The surface's top near z = 0; the patch dips 0.06 into it at the
    // centre, so the outer nodes of the curved cases open.
    let (positions, facets) = patch(facet_type, |_, _| -0.06, &mut rng, 0.15);
    let n = positions.len();
    let nf = facet_type.nodes();
    let mut expected = vec![0u32; n];
    for f in &facets {
        for &a in &f[..nf] {
            expected[a as usize] += 1;
        }
    }
    let nodal = NodalData::new(
        (0..n as u32).collect(),
        (0..n).map(|_| 0.5 + 0.4 * rng.next()).collect(),
        (0..n).map(|_| 50.0 * (1.5 + rng.next())).collect(),
        (0..n).map(|_| 0.45 + 0.05 * rng.next()).collect(),
    );
    let friction = mu.map(|mu| NodalFriction {
        mu,
        penalty: (0..n).map(|_| 40.0 * (1.5 + rng.next())).collect(),
        lambda: (0..n)
            .map(|_| [0.2 * rng.next(), 0.2 * rng.next(), 0.05 * rng.next()])
            .collect(),
    });
    let base = (0..n)
        .map(|_| {
            [
                0.02 + 0.01 * rng.next(),
                0.01 * rng.next(),
                0.005 * rng.next(),
            ]
        })
        .collect();
    Case {
        facet_type,
        positions,
        candidates: (0..facets.len() as u32).map(|f| (f, 0)).collect(),
        assembled: vec![true; facets.len()],
        facets,
        expected,
        nodal,
        surface: surface.moved([0.0; 3], 0.0),
        friction,
        base,
        slope: 1.0,
        master: [-0.01, 0.004, 0.0],
    }
}

fn plane() -> RigidSurface {
    RigidSurface::Plane {
        point: [0.0, 0.0, 0.0],
        normal: [0.1, -0.05, 1.0],
    }
}

fn sphere() -> RigidSurface {
    RigidSurface::Sphere {
        centre: [0.1, -0.1, -8.0],
        radius: 8.0,
    }
}

fn cylinder() -> RigidSurface {
    RigidSurface::Cylinder {
        point: [0.0, 0.1, -6.0],
        axis: [1.0, 0.2, 0.05],
        radius: 6.0,
    }
}

impl Case {
    fn interface<'a>(&'a self, positions: &'a [[f64; 3]]) -> RigidInterface<'a> {
        RigidInterface {
            facet_type: self.facet_type,
            positions,
            reference: &self.positions,
            facets: &self.facets,
            candidates: &self.candidates,
            assembled: &self.assembled,
            surface: self.surface,
        }
    }

    fn increments(&self, positions: &[[f64; 3]]) -> Vec<[f64; 3]> {
        positions
            .iter()
            .zip(&self.positions)
            .zip(&self.base)
            .map(|((x, x0), b)| [0, 1, 2].map(|i| b[i] + self.slope * (x[i] - x0[i])))
            .collect()
    }

    fn residual(&self, positions: &[[f64; 3]]) -> (Vec<f64>, usize, Vec<NodeFriction>) {
        let interface = self.interface(positions);
        let facets: Vec<RigidFacet<f64>> = rigid::facets(&interface, &MortarRules::default());
        let (gap, covered) = rigid::weighted_gaps(&interface, &self.nodal, &facets, &self.expected);
        let states = node_states(&self.nodal, &gap, &covered);
        let mut r = vec![0.0; 3 * positions.len()];
        let mut add = |n: u32, i: usize, v: f64| r[3 * n as usize + i] += v;
        rigid::residual(&interface, &self.nodal, &facets, &states, &mut add);
        let mut nf = Vec::new();
        if let Some(f) = &self.friction {
            let value = self.increments(positions);
            let inc = Increment {
                value: &value,
                slope: self.slope,
            };
            let slips = rigid_friction::facet_slips(&interface, &facets, &inc, self.master);
            nf = rigid_friction::node_frictions(
                &interface,
                &self.nodal,
                f,
                &states,
                &facets,
                &slips,
            );
            rigid_friction::residual(&interface, &self.nodal, &facets, &nf, &mut add);
        }
        (r, states.iter().filter(|s| s.closed).count(), nf)
    }

    fn tangent(&self) -> Vec<f64> {
        let positions = &self.positions;
        let interface = self.interface(positions);
        let facets: Vec<RigidFacet<RD>> = rigid::facets(&interface, &MortarRules::default());
        let (gap, covered) = rigid::weighted_gaps(&interface, &self.nodal, &facets, &self.expected);
        let states = node_states(&self.nodal, &gap, &covered);
        let n = 3 * positions.len();
        let mut k = vec![0.0; n * n];
        let mut add = |r: (u32, usize), c: (u32, usize), v: f64| {
            k[(3 * r.0 as usize + r.1) * n + 3 * c.0 as usize + c.1] += v
        };
        rigid::tangent(&interface, &self.nodal, &facets, &states, &mut add);
        if let Some(f) = &self.friction {
            let value = self.increments(positions);
            let inc = Increment {
                value: &value,
                slope: self.slope,
            };
            let slips = rigid_friction::facet_slips(&interface, &facets, &inc, self.master);
            let nf = rigid_friction::node_frictions(
                &interface,
                &self.nodal,
                f,
                &states,
                &facets,
                &slips,
            );
            rigid_friction::tangent(&interface, &self.nodal, &facets, &slips, &nf, &mut add);
        }
        k
    }

    /// max |K − K_fd| / max |K_fd|, and the number of closed nodes.
    fn tangent_error(&self) -> (f64, usize) {
        let k = self.tangent();
        let n = 3 * self.positions.len();
        let h = 1e-6;
        let mut fd = vec![0.0; n * n];
        for col in 0..n {
            let mut plus = self.positions.clone();
            let mut minus = self.positions.clone();
            plus[col / 3][col % 3] += h;
            minus[col / 3][col % 3] -= h;
            let (rp, rm) = (self.residual(&plus).0, self.residual(&minus).0);
            for row in 0..n {
                fd[row * n + col] = (rp[row] - rm[row]) / (2.0 * h);
            }
        }
        let scale = fd.iter().fold(0.0f64, |a, v| a.max(v.abs()));
        assert!(scale > 1.0, "tangent vanishes");
        let err = k
            .iter()
            .zip(&fd)
            .fold(0.0f64, |a, (x, y)| a.max((x - y).abs()));
        (err / scale, self.residual(&self.positions).1)
    }
}

#[test]
fn flat_patch_on_a_plane_gives_gap_times_area_and_consistent_forces() {
    // A flat, undistorted patch 0.01 inside the plane z = 0: g̃_j = −0.01 A_j
    // and, for a uniform p, the forces are p times the nodal areas along +z.
    let mut rng = Lcg::new(1);
    for ft in [Quad4, Tri3] {
        let (positions, facets) = patch(ft, |_, _| -0.01, &mut rng, 0.0);
        let n = positions.len();
        let mut c = case(1, ft, plane(), None);
        c.surface = RigidSurface::Plane {
            point: [0.0; 3],
            normal: [0.0, 0.0, 1.0],
        };
        c.positions = positions;
        c.candidates = (0..facets.len() as u32).map(|f| (f, 0)).collect();
        c.assembled = vec![true; facets.len()];
        c.facets = facets;
        let interface = c.interface(&c.positions);
        let f: Vec<RigidFacet<f64>> = rigid::facets(&interface, &MortarRules::default());
        let mut gap = vec![0.0; n];
        let mut area = vec![0.0; n];
        let mut force = vec![[0.0; 3]; n];
        let nf = ft.nodes();
        for t in &f {
            for (a, &j) in c.facets[t.facet as usize][..nf].iter().enumerate() {
                gap[j as usize] += t.weighted_gap[a];
                area[j as usize] += t.d[a][..nf].iter().sum::<f64>();
                for (k, &m) in c.facets[t.facet as usize][..nf].iter().enumerate() {
                    for (sum, v) in force[m as usize].iter_mut().zip(&t.force[a][k]) {
                        *sum += v;
                    }
                }
            }
        }
        let total: f64 = area.iter().sum();
        assert!((total - 4.0).abs() < 1e-13, "{ft:?}: area {total}");
        for j in 0..n {
            assert!((gap[j] + 0.01 * area[j]).abs() < 1e-15, "{ft:?} node {j}");
            // Σ_j c_jk = −∫ N_k n dA: the consistent nodal force of a unit
            // pressure (the slave is pushed up, the residual points down).
            assert!((force[j][2] + area[j]).abs() < 1e-14 && force[j][0].abs() < 1e-15);
        }
    }
}

#[test]
fn rigid_tangent_matches_finite_differences() {
    let mut worst = 0.0f64;
    for (seed, ft) in [(41, Quad4), (42, Tri3)] {
        for (name, surface) in [
            ("plane", plane()),
            ("sphere", sphere()),
            ("cylinder", cylinder()),
        ] {
            // Frictionless; μ = 10 (stick) and μ = 0.05 (slip), each with the
            // quasi-static (slope 1) and a dynamic (0.37) increment.
            let mut cases = vec![case(seed, ft, surface, None)];
            for (mu, slope) in [(10.0, 1.0), (0.05, 1.0), (0.05, 0.37), (10.0, 0.37)] {
                let mut c = case(seed, ft, surface, Some(mu));
                c.slope = slope;
                cases.push(c);
            }
            for c in &cases {
                let (err, closed) = c.tangent_error();
                let (_, _, nf) = c.residual(&c.positions);
                let sliding = nf.iter().filter(|f| f.sliding).count();
                let mu = c.friction.as_ref().map(|f| f.mu);
                assert!(closed >= 4, "{name} {ft:?}: {closed} closed nodes");
                match mu {
                    Some(m) if m > 1.0 => assert!(3 * sliding <= closed, "{name}: slides"),
                    Some(_) => assert!(3 * sliding >= 2 * closed, "{name}: sticks"),
                    None => {}
                }
                assert!(
                    err < 1e-6,
                    "{name} {ft:?} μ {mu:?} slope {}: {err:e}",
                    c.slope
                );
                worst = worst.max(err);
            }
            if name != "plane" {
                // The curved cases leave the patch's rim open.
                let (_, closed, _) = cases[0].residual(&cases[0].positions);
                assert!(closed < cases[0].positions.len(), "{name}: all closed");
            }
        }
    }
    println!("rigid mortar tangent vs finite differences: worst {worst:.1e} relative");
}

#[test]
fn frictionless_rigid_tangent_is_symmetric() {
    for surface in [plane(), sphere(), cylinder()] {
        let c = case(43, Quad4, surface, None);
        let k = c.tangent();
        let n = 3 * c.positions.len();
        let scale = k.iter().fold(0.0f64, |a, v| a.max(v.abs()));
        for r in 0..n {
            for col in 0..r {
                let d = (k[r * n + col] - k[col * n + r]).abs();
                assert!(
                    d <= 1e-12 * scale,
                    "{surface:?}: K[{r},{col}] asymmetric by {d:e}"
                );
            }
        }
    }
}

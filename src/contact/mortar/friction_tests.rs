//! The frictional mortar residual against the return map, and its tangent
//! against finite differences of the residual (stick, slip, quasi-static
//! and dynamic increments) on random overlapping facet patches.
use super::friction::{
    self, node_frictions, segment_slips, Increment, NodalFriction, NodeFriction,
};
use super::segment::MortarRules;
use super::system::{self, node_states, segments, weighted_gaps, Segment};
use super::tests::{parallelogram_case, random_case, Case};
use crate::contact::autodiff::Dual;
use crate::fem::test_util::Lcg;
use crate::fem::FacetType::{Quad4, Tri3};

/// A frictional case: the normal case, λT, εT, μ and the increments at the
/// case's positions (`base`), affine in the positions with `slope`.
struct Frictional {
    case: Case,
    friction: NodalFriction,
    base: Vec<[f64; 3]>,
    slope: f64,
}

fn frictional(
    seed: u64,
    s: crate::fem::FacetType,
    m: crate::fem::FacetType,
    mu: f64,
    slope: f64,
) -> Frictional {
    with_friction(random_case(seed, s, m), seed, mu, slope)
}

fn with_friction(case: Case, seed: u64, mu: f64, slope: f64) -> Frictional {
    let mut rng = Lcg::new(seed + 100);
    let n = case.nodal.nodes.len();
    let friction = NodalFriction {
        mu,
        penalty: (0..n).map(|_| 40.0 * (1.5 + rng.next())).collect(),
        lambda: (0..n)
            .map(|_| [0.2 * rng.next(), 0.2 * rng.next(), 0.05 * rng.next()])
            .collect(),
    };
    // Slave and master moved against each other along x, plus noise.
    let n_slave = n;
    let base = (0..case.positions.len())
        .map(|i| {
            let drift = if i < n_slave { 0.02 } else { -0.01 };
            [
                drift + 0.01 * rng.next(),
                0.01 * rng.next(),
                0.005 * rng.next(),
            ]
        })
        .collect();
    Frictional {
        case,
        friction,
        base,
        slope,
    }
}

impl Frictional {
    fn increments(&self, positions: &[[f64; 3]]) -> Vec<[f64; 3]> {
        positions
            .iter()
            .zip(&self.case.positions)
            .zip(&self.base)
            .map(|((x, x0), b)| [0, 1, 2].map(|i| b[i] + self.slope * (x[i] - x0[i])))
            .collect()
    }

    fn residual(&self, positions: &[[f64; 3]]) -> (Vec<f64>, Vec<NodeFriction>) {
        let interface = self.case.interface(positions);
        let nodal = &self.case.nodal;
        let segs: Vec<Segment<f64>> = segments(&interface, &MortarRules::default());
        let (gap, covered) = weighted_gaps(&interface, nodal, &segs);
        let states = node_states(nodal, &gap, &covered);
        let value = self.increments(positions);
        let inc = Increment {
            value: &value,
            slope: self.slope,
        };
        let slips = segment_slips(&interface, &segs, &inc);
        let nf = node_frictions(&interface, nodal, &self.friction, &states, &segs, &slips);
        let mut r = vec![0.0; 3 * positions.len()];
        let mut add = |n: u32, i: usize, v: f64| r[3 * n as usize + i] += v;
        system::residual(&interface, nodal, &segs, &states, &mut add);
        friction::residual(&interface, nodal, &segs, &nf, &mut add);
        (r, nf)
    }

    fn tangent(&self) -> Vec<f64> {
        let positions = &self.case.positions;
        let interface = self.case.interface(positions);
        let nodal = &self.case.nodal;
        let segs: Vec<Segment<Dual<24>>> = segments(&interface, &MortarRules::default());
        let (gap, covered) = weighted_gaps(&interface, nodal, &segs);
        let states = node_states(nodal, &gap, &covered);
        let value = self.increments(positions);
        let inc = Increment {
            value: &value,
            slope: self.slope,
        };
        let slips = segment_slips(&interface, &segs, &inc);
        let nf = node_frictions(&interface, nodal, &self.friction, &states, &segs, &slips);
        let n = 3 * positions.len();
        let mut k = vec![0.0; n * n];
        let mut add = |r: (u32, usize), c: (u32, usize), v: f64| {
            k[(3 * r.0 as usize + r.1) * n + 3 * c.0 as usize + c.1] += v
        };
        friction::tangent(&interface, nodal, &segs, &slips, &states, &nf, &mut add);
        k
    }
}

#[test]
fn frictional_tangent_matches_finite_differences_in_stick_and_slip() {
    let mut worst = 0.0f64;
    // Seed 26: the parallelogram patches (affine maps).
    for (seed, s, m) in [
        (21, Quad4, Quad4),
        (22, Quad4, Quad4),
        (23, Tri3, Quad4),
        (24, Quad4, Tri3),
        (25, Tri3, Tri3),
        (26, Quad4, Quad4),
    ] {
        // μ = 10: the nodes stick; μ = 0.05: they slide. Slope 1 is
        // the quasi-static increment x − xₙ, 0.37 a dynamic Δt ∂v/∂x.
        for (mu, slope) in [(10.0, 1.0), (0.05, 1.0), (0.05, 0.37), (10.0, 0.37)] {
            let f = if seed == 26 {
                with_friction(parallelogram_case(seed), seed, mu, slope)
            } else {
                frictional(seed, s, m, mu, slope)
            };
            let positions = &f.case.positions;
            let (_, nf) = f.residual(positions);
            let active = nf.iter().filter(|n| n.active).count();
            let sliding = nf.iter().filter(|n| n.sliding).count();
            assert!(active >= 4, "seed {seed}: {active} active nodes");
            // (A node at the rim of the overlap may have almost no pressure:
            // it slides whatever μ.)
            if mu > 1.0 {
                assert!(
                    3 * sliding <= active,
                    "seed {seed}: {sliding} of {active} sliding at μ = {mu}"
                );
            } else {
                assert!(
                    3 * sliding >= 2 * active,
                    "seed {seed}: {sliding} of {active} sliding at μ = {mu}"
                );
                for n in nf.iter().filter(|n| n.active) {
                    let t = crate::contact::autodiff::norm(&n.traction);
                    assert!(t > 0.0);
                }
            }
            let k = f.tangent();
            let n = 3 * positions.len();
            let h = 1e-6;
            let mut fd = vec![0.0; n * n];
            for col in 0..n {
                let mut plus = positions.clone();
                let mut minus = positions.clone();
                plus[col / 3][col % 3] += h;
                minus[col / 3][col % 3] -= h;
                let (rp, rm) = (f.residual(&plus).0, f.residual(&minus).0);
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
                "seed {seed} {s:?}/{m:?} μ {mu} slope {slope}: {err:e} vs {scale:e}"
            );
            worst = worst.max(err / scale);
        }
    }
    println!("frictional mortar tangent vs finite differences: worst {worst:.1e} relative");
}

#[test]
fn sliding_nodes_carry_mu_times_their_pressure_and_mu_zero_is_frictionless() {
    let f = frictional(31, Quad4, Quad4, 0.2, 1.0);
    let positions = &f.case.positions;
    let interface = f.case.interface(positions);
    let nodal = &f.case.nodal;
    let segs: Vec<Segment<f64>> = segments(&interface, &MortarRules::default());
    let (gap, covered) = weighted_gaps(&interface, nodal, &segs);
    let states = node_states(nodal, &gap, &covered);
    let (_, nf) = f.residual(positions);
    for (s, n) in states.iter().zip(&nf).filter(|(_, n)| n.sliding) {
        let t = crate::contact::autodiff::norm(&n.traction);
        assert!(
            (t - 0.2 * s.pressure).abs() <= 1e-14 * t,
            "{t} vs {}",
            s.pressure
        );
    }
    let mut zero = frictional(31, Quad4, Quad4, 0.0, 1.0);
    zero.friction.lambda.iter_mut().for_each(|l| *l = [0.0; 3]);
    let (r0, nf0) = zero.residual(positions);
    assert!(nf0.iter().all(|n| n.traction == [0.0; 3]));
    let mut frictionless = vec![0.0; r0.len()];
    system::residual(&interface, nodal, &segs, &states, |n, i, v| {
        frictionless[3 * n as usize + i] += v
    });
    assert_eq!(r0, frictionless);
}

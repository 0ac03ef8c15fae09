//! Second-order facets: residual and tangent against finite differences on
//! curved slave and master facets (tri6, quad8, quad9, and mixed pairs),
//! frictionless and with friction in stick and slip, and against a rigid
//! sphere.
//!
//! Bounds: central differences with h = 1e-6 have a truncation error
//! ~h² |r'''| ≈ 1e-12 and a round-off error ~ε |r| / h ≈ 1e-10 relative to
//! the largest entry; the kernel's own f64 projection is converged to
//! ~1e-13 in ξ. Measured errors are ~1e-9; 1e-6 leaves margin while still
//! failing on any dropped curvature term (those are O(gap · curvature) or
//! O(pN · curvature), ~1e-2 relative on these facets).

use super::*;
use crate::fem::shape::facet_reference_nodes;

/// The nodes of a `facet` whose corners are `corners` (2-D, in facet
/// order), mid-side and centre nodes at the means of their corners, every
/// node moved by up to `amp` in-plane, and lifted to `z(x, y)`.
fn curved_nodes(
    facet: FacetType,
    corners: &[[f64; 2]],
    amp: f64,
    z: impl Fn(f64, f64) -> f64,
    rng: &mut Lcg,
) -> Vec<[f64; 3]> {
    let mut xy: Vec<[f64; 2]> = corners[..facet.corners()].to_vec();
    for of in facet.higher_nodes() {
        let n = of.len() as f64;
        let mut m = [0.0; 2];
        for &a in *of {
            m[0] += corners[a][0] / n;
            m[1] += corners[a][1] / n;
        }
        xy.push(m);
    }
    xy.iter()
        .map(|p| {
            let d = rng.vec3(amp);
            let (x, y) = (p[0] + d[0], p[1] + d[1]);
            [x, y, z(x, y)]
        })
        .collect()
}

/// Master facet around the origin, outward normal +z, on a sphere of radius
/// 1.5 bulging towards the slave (strongly curved: the facet spans about
/// 2, so its mid-side nodes stand ~0.1–0.3 off its chords); a first-order
/// master lies in z = 0.
fn curved_master(facet: FacetType, rng: &mut Lcg) -> Vec<[f64; 3]> {
    let corners: &[[f64; 2]] = match facet.linear() {
        FacetType::Quad4 => &[[-1.0, -1.0], [1.0, -1.0], [1.0, 1.0], [-1.0, 1.0]],
        _ => &[[-1.0, -1.0], [1.6, -0.8], [-0.6, 1.6]],
    };
    let r = 1.5f64;
    curved_nodes(
        facet,
        corners,
        0.05,
        |x, y| {
            if facet.is_linear() {
                0.0
            } else {
                (r * r - x * x - y * y).max(0.0).sqrt() - r
            }
        },
        rng,
    )
}

/// Slave facet around z = z0, outward normal −z, curved the other way (its
/// body above is convex too) when it is second order.
fn curved_slave(facet: FacetType, z0: f64, rng: &mut Lcg) -> Vec<[f64; 3]> {
    let corners: &[[f64; 2]] = match facet.linear() {
        FacetType::Quad4 => &[[-0.4, -0.4], [-0.4, 0.4], [0.4, 0.4], [0.4, -0.4]],
        _ => &[[-0.4, -0.4], [-0.2, 0.4], [0.4, -0.1]],
    };
    let k = if facet.is_linear() { 0.0 } else { 0.6 };
    curved_nodes(
        facet,
        corners,
        0.04,
        |x, y| z0 + k * (x * x + y * y - 0.16),
        rng,
    )
}

fn closed(case: Case) -> Option<Case> {
    let s = evaluate(&case.input());
    (s.projection_converged && s.pressure > 0.05 && s.outside < 0.5).then_some(case)
}

/// A random closed link between curved facets (`master` None: the rigid
/// sphere of [`rigid_masters`]).
fn curved_case(slave: FacetType, master: Option<FacetType>, rng: &mut Lcg) -> Case {
    for _ in 0..10_000 {
        let master = match master {
            Some(f) => OwnedMaster::Facet(f, curved_master(f, rng)),
            None => OwnedMaster::Rigid(rigid_masters()[1]),
        };
        let case = Case {
            slave_facet: slave,
            slave_x: curved_slave(slave, 0.05 * rng.next() - 0.03, rng),
            zeta: random_zeta(slave, rng),
            weight: 0.3 + 0.2 * rng.next(),
            master,
            lambda_n: 0.5 * (rng.next() + 1.0),
            penalty: 20.0,
            friction: None,
        };
        if let Some(c) = closed(case) {
            return c;
        }
    }
    panic!("no closed curved case for {}", pair_name(slave, master));
}

const PAIRS: [(FacetType, Option<FacetType>); 9] = [
    (FacetType::Tri6, Some(FacetType::Tri6)),
    (FacetType::Quad8, Some(FacetType::Quad8)),
    (FacetType::Quad9, Some(FacetType::Quad9)),
    (FacetType::Tri6, Some(FacetType::Quad8)),
    (FacetType::Quad4, Some(FacetType::Quad9)),
    (FacetType::Quad9, Some(FacetType::Tri3)),
    (FacetType::Tri6, None),
    (FacetType::Quad8, None),
    (FacetType::Quad9, None),
];

fn pair_name(slave: FacetType, master: Option<FacetType>) -> String {
    format!(
        "{}-{}",
        slave.name(),
        master.map_or("sphere", FacetType::name)
    )
}

/// Every curved pairing, a few random cases each, plus one whose slave
/// point projects into the interior of the master (ξ̄ well inside, where
/// the facet is most curved between its nodes).
fn curved_cases() -> Vec<(String, Case)> {
    let mut rng = Lcg::new(4343);
    let mut out = Vec::new();
    for (slave, master) in PAIRS {
        for _ in 0..3 {
            out.push((
                pair_name(slave, master),
                curved_case(slave, master, &mut rng),
            ));
        }
        if let Some(m) = master {
            let centre = projection::reference_centre(m);
            let interior = (0..1000)
                .map(|_| curved_case(slave, master, &mut rng))
                .find(|c| {
                    let xi = evaluate(&c.input()).xi;
                    let far = (xi[0] - centre[0]).abs().max((xi[1] - centre[1]).abs());
                    projection::outside_distance(m, xi) == 0.0 && far < 0.3 && far > 0.05
                })
                .expect("an interior case");
            out.push((format!("{} interior", pair_name(slave, master)), interior));
        }
    }
    out
}

fn check_curved(what: &str, limit: f64, cases: &[(String, Case)], measure: impl Fn(&Case) -> f64) {
    let mut worst = std::collections::BTreeMap::<String, f64>::new();
    for (name, case) in cases {
        let err = measure(case);
        assert!(err < limit, "{name}: {what} = {err:e}");
        let w = worst.entry(name.clone()).or_insert(0.0);
        *w = w.max(err);
    }
    for (name, err) in worst {
        println!("{what:>22} {name:>28}: {err:.1e}");
    }
}

#[test]
fn curved_cases_are_curved_and_second_order() {
    for (name, case) in curved_cases() {
        // The master's mid-side nodes stand off its chords.
        if let OwnedMaster::Facet(f, x) = &case.master {
            if !f.is_linear() {
                let (a, b, m) = (x[0], x[1], x[f.corners()]);
                let chord = autodiff::scale_f64(&autodiff::add(&a, &b), 0.5);
                assert!(autodiff::norm(&autodiff::sub(&m, &chord)) > 0.05, "{name}");
            }
        }
        assert_eq!(case.n(), 3 * case.nodes().len(), "{name}");
    }
    let _ = facet_reference_nodes(FacetType::Quad9);
}

#[test]
fn curved_residual_is_gradient_of_potential() {
    let cases = curved_cases();
    check_curved("r vs FD(potential)", 1e-6, &cases, |case| {
        let (r, _, state) = case.residual_and_tangent();
        assert!(state.pressure > 0.0);
        rel_err(&r, &fd_gradient_of_potential(case))
    });
}

#[test]
fn curved_tangent_matches_finite_differences_of_residual() {
    let cases = curved_cases();
    check_curved("k vs FD(r)", 1e-6, &cases, |case| {
        let (_, k, _) = case.residual_and_tangent();
        rel_err(&k, &fd_tangent(case))
    });
    check_curved("asymmetry of k", 1e-10, &cases, |case| {
        let (_, k, _) = case.residual_and_tangent();
        asymmetry(&k, case.n())
    });
}

#[test]
fn curved_friction_tangent_matches_finite_differences() {
    let mut rng = Lcg::new(99);
    let mut cases = Vec::new();
    for (name, case) in curved_cases() {
        for (ratio, branch) in [(0.5, "stick"), (2.0, "slip")] {
            for dynamic in [false, true] {
                let c = super::friction::with_friction(&case, ratio, dynamic, &mut rng);
                let s = evaluate(&c.input());
                assert_eq!(s.friction.unwrap().sliding, ratio > 1.0, "{name} {branch}");
                let kind = if dynamic { "dyn" } else { "static" };
                cases.push((format!("{name} {branch} {kind}"), c));
            }
        }
    }
    check_curved("friction k vs FD(r)", 1e-6, &cases, |case| {
        let (r, k, _) = case.residual_and_tangent();
        assert!(rel_err(&case.residual(), &r) < 1e-14);
        rel_err(&k, &fd_tangent(case))
    });
}

/// Forces balance (Σ r = 0 over slave and master) on curved facet pairs.
#[test]
fn curved_forces_balance() {
    for (name, case) in curved_cases() {
        if matches!(case.master, OwnedMaster::Rigid(_)) {
            continue;
        }
        let r = case.residual();
        let scale = r.iter().fold(0.0f64, |m, v| m.max(v.abs()));
        for i in 0..3 {
            let sum: f64 = r.iter().skip(i).step_by(3).sum();
            assert!(sum.abs() < 1e-12 * scale, "{name}: Σ r_{i} = {sum:e}");
        }
    }
}

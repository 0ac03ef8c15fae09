//! Frictionless links: residual, tangent, balance, closed forms, bad input.

use super::*;
use crate::contact::surfaces::reference_weights;

#[test]
fn cases_cover_penetration_and_separation() {
    let gaps: Vec<f64> = all_cases()
        .iter()
        .map(|(_, c)| evaluate(&c.input()).gap)
        .collect();
    let penetrating = gaps.iter().filter(|g| **g < 0.0).count();
    assert!(penetrating >= gaps.len() / 2, "{gaps:?}");
    assert!(penetrating < gaps.len(), "no case closed by λN alone");
}

#[test]
fn residual_is_gradient_of_potential() {
    check_all("r vs FD(potential)", 1e-6, |case| {
        let (r, _, state) = case.residual_and_tangent();
        assert!(state.pressure > 0.0);
        rel_err(&r, &fd_gradient_of_potential(case))
    });
}

#[test]
fn tangent_matches_finite_differences_of_residual() {
    check_all("k vs FD(r)", 1e-6, |case| {
        let (_, k, _) = case.residual_and_tangent();
        rel_err(&k, &fd_tangent(case))
    });
}

#[test]
fn frictionless_tangent_is_symmetric() {
    check_all("asymmetry of k", 1e-10, |case| {
        let (_, k, _) = case.residual_and_tangent();
        asymmetry(&k, case.n())
    });
}

#[test]
fn main_part_tangent_is_the_pressure_derivative_alone() {
    // r = −pN w c with c = ∂gN/∂u, so the main part εN w c cᵀ is
    // εN / (pN² w) r rᵀ; the residual itself does not change.
    let mut geometric = 0.0f64;
    for (name, case) in all_cases() {
        let full = case.input();
        let main = LinkInput {
            main_part_tangent: true,
            ..case.input()
        };
        let n = case.n();
        let (mut r, mut k) = (vec![0.0; n], vec![0.0; n * n]);
        let state = residual_tangent(&main, &mut r, Some(&mut k));
        let (mut r_full, mut k_full) = (vec![0.0; n], vec![0.0; n * n]);
        residual_tangent(&full, &mut r_full, Some(&mut k_full));
        assert!(rel_err(&r, &r_full) < 1e-14, "{name}: residual changed");
        let scale = full.penalty / (state.pressure * state.pressure * full.weight);
        let outer: Vec<f64> = (0..n * n).map(|ij| scale * r[ij / n] * r[ij % n]).collect();
        let err = rel_err(&k, &outer);
        assert!(err < 1e-10, "{name}: main part vs εN c cᵀ = {err:e}");
        geometric = geometric.max(rel_err(&k_full, &k));
    }
    assert!(geometric > 1e-3, "no case has geometric terms to drop");
}

#[test]
fn residual_only_path_matches_dual_path() {
    for (name, case) in all_cases() {
        let (r, _, _) = case.residual_and_tangent();
        let err = rel_err(&case.residual(), &r);
        assert!(err < 1e-14, "{name}: {err:e}");
    }
}

#[test]
fn forces_and_moments_balance_for_facet_masters() {
    for (name, case) in all_cases() {
        if matches!(case.master, OwnedMaster::Rigid(_)) {
            continue;
        }
        let (r, k, _) = case.residual_and_tangent();
        let n = case.n();
        let scale = r.iter().fold(0.0f64, |m, v| m.max(v.abs()));
        let mut force = [0.0; 3];
        let mut moment = [0.0; 3];
        for (x, f) in case.nodes().iter().zip(r.chunks_exact(3)) {
            let f = [f[0], f[1], f[2]];
            force = autodiff::add(&force, &f);
            moment = autodiff::add(&moment, &autodiff::cross(x, &f));
        }
        let size = case
            .nodes()
            .iter()
            .fold(0.0f64, |m, x| m.max(autodiff::norm(x)));
        assert!(
            autodiff::norm(&force) < 1e-14 * scale,
            "{name}: force {force:?}"
        );
        assert!(
            autodiff::norm(&moment) < 1e-14 * scale * size,
            "{name}: moment {moment:?}"
        );
        // Balance holds for every u, so its derivative does too: the
        // rows of k summed over nodes vanish, and a rigid translation
        // (the same column block summed) changes nothing.
        let kscale = k.iter().fold(0.0f64, |m, v| m.max(v.abs()));
        for i in 0..3 {
            for col in 0..n {
                let sum: f64 = (0..n / 3).map(|a| k[(3 * a + i) * n + col]).sum();
                assert!(sum.abs() < 1e-13 * kscale, "{name}: row sum {sum:e}");
            }
            for row in 0..n {
                let sum: f64 = (0..n / 3).map(|b| k[row * n + 3 * b + i]).sum();
                assert!(sum.abs() < 1e-13 * kscale, "{name}: translation {sum:e}");
            }
        }
    }
}

#[test]
fn translation_does_not_change_facet_link() {
    for (name, case) in all_cases() {
        if matches!(case.master, OwnedMaster::Rigid(_)) {
            continue;
        }
        let (r, k, _) = case.residual_and_tangent();
        let (r2, k2, _) = case.translated([3.0, -2.0, 1.5]).residual_and_tangent();
        assert!(
            rel_err(&r2, &r) < 1e-12 && rel_err(&k2, &k) < 1e-11,
            "{name}"
        );
    }
}

#[test]
fn open_link_is_exactly_zero() {
    for (name, case) in all_cases() {
        // Lift the slave well clear: gN > λN/εN.
        let mut open = case.clone();
        for p in &mut open.slave_x {
            p[2] += 0.5;
        }
        let n = open.n();
        let (mut r, mut k) = (vec![7.0; n], vec![7.0; n * n]);
        let state = residual_tangent(&open.input(), &mut r, Some(&mut k));
        assert!(state.gap > open.lambda_n / open.penalty, "{name}");
        assert_eq!(state.pressure, 0.0);
        assert!(r.iter().chain(&k).all(|v| *v == 0.0), "{name}");
        assert!(state.projection_converged);
    }
}

#[test]
fn apart_but_closed_by_multiplier() {
    // 0 < gN < λN/εN: the augmented pressure still pushes.
    let master = vec![
        [-1.0, -1.0, 0.0],
        [1.0, -1.0, 0.0],
        [1.0, 1.0, 0.0],
        [-1.0, 1.0, 0.0],
    ];
    let case = Case {
        slave_facet: FacetType::Tri3,
        slave_x: vec![[0.0, 0.0, 0.02], [0.0, 0.5, 0.02], [0.5, 0.0, 0.02]],
        zeta: [0.2, 0.2],
        weight: 1.0,
        master: OwnedMaster::Facet(FacetType::Quad4, master),
        lambda_n: 1.0,
        penalty: 10.0,
        friction: None,
    };
    let (r, _, s) = case.residual_and_tangent();
    assert!((s.gap - 0.02).abs() < 1e-15);
    assert!((s.pressure - 0.8).abs() < 1e-14);
    let fz: f64 = r[..9].chunks_exact(3).map(|f| f[2]).sum();
    assert!((fz + 0.8).abs() < 1e-14);
}

/// Σ over the facet's quadrature points of the slave forces, and of the
/// master forces.
fn pressed_totals(
    slave: FacetType,
    x_ref: &[[f64; 3]],
    x: &[[f64; 3]],
    master: LinkMaster,
) -> ([f64; 3], [f64; 3]) {
    let rule = QuadRule::default_for_facet(slave);
    let (mut fs, mut fm) = ([0.0; 3], [0.0; 3]);
    for (zeta, weight) in reference_weights(slave, x_ref, &rule) {
        let input = LinkInput {
            slave_facet: slave,
            slave_x: x,
            zeta,
            weight,
            master,
            xi_start: [0.0; 2],
            lambda_n: 0.7,
            penalty: 50.0,
            friction: None,
            main_part_tangent: false,
        };
        let mut r = vec![0.0; dof_count(&input)];
        let s = residual_tangent(&input, &mut r, None);
        assert!(s.projection_converged && s.pressure > 0.0);
        let ns = slave.nodes();
        for (a, f) in r.chunks_exact(3).enumerate() {
            let target = if a < ns { &mut fs } else { &mut fm };
            *target = autodiff::add(target, &[f[0], f[1], f[2]]);
        }
    }
    (fs, fm)
}

#[test]
fn flat_facet_pressed_uniformly() {
    let depth = 0.01;
    let p_n = 0.7 + 50.0 * depth;
    let table = [-5.0, 5.0];
    let master_x = [
        [table[0], table[0], 0.0],
        [table[1], table[0], 0.0],
        [table[1], table[1], 0.0],
        [table[0], table[1], 0.0],
    ];
    let masters = [
        LinkMaster::Facet {
            facet: FacetType::Quad4,
            x: &master_x,
        },
        LinkMaster::Plane {
            point: [0.0; 3],
            normal: [0.0, 0.0, 3.0],
        },
    ];
    // Parallelogram (area 1.5) and triangle (area 0.585) in z = 0.
    let quad: Vec<[f64; 3]> = vec![
        [0.0, 0.0, 0.0],
        [0.2, 1.0, 0.0],
        [1.7, 1.0, 0.0],
        [1.5, 0.0, 0.0],
    ];
    let tri: Vec<[f64; 3]> = vec![[0.0, 0.0, 0.0], [0.3, 1.2, 0.0], [1.0, 0.1, 0.0]];
    for (facet, x_ref, area) in [(FacetType::Quad4, quad, 1.5), (FacetType::Tri3, tri, 0.585)] {
        // Current configuration: in-plane stretch by 1.3 and a shift that
        // presses it `depth` into the master. The force must use the
        // reference area (nominal pressure), not the stretched one.
        let x: Vec<[f64; 3]> = x_ref
            .iter()
            .map(|p| [1.3 * p[0] - 0.4, 1.3 * p[1] - 0.3, -depth])
            .collect();
        for master in masters {
            let (fs, fm) = pressed_totals(facet, &x_ref, &x, master);
            let expect = [0.0, 0.0, -p_n * area];
            assert!(
                rel_err(&fs, &expect) < 1e-13,
                "{} {fs:?} vs {expect:?}",
                facet.name()
            );
            if matches!(master, LinkMaster::Facet { .. }) {
                assert!(rel_err(&fm, &[0.0, 0.0, p_n * area]) < 1e-13);
            }
        }
    }
}

#[test]
fn reference_weights_sum_to_area() {
    let quad = [
        [0.0, 0.0, 1.0],
        [2.0, 0.0, 1.0],
        [2.5, 1.0, 1.0],
        [0.5, 1.0, 1.0],
    ];
    let w = reference_weights(FacetType::Quad4, &quad, &QuadRule::quad_2x2());
    assert_eq!(w.len(), 4);
    let total: f64 = w.iter().map(|(_, wi)| wi).sum();
    assert!((total - 2.0).abs() < 1e-14);
    let tri = [[0.0, 0.0, 0.0], [0.0, 2.0, 0.0], [0.0, 0.0, 3.0]];
    let w = reference_weights(FacetType::Tri3, &tri, &QuadRule::tri_3());
    let total: f64 = w.iter().map(|(_, wi)| wi).sum();
    assert!((total - 3.0).abs() < 1e-14);
    assert!((w[1].0[0] - 2.0 / 3.0).abs() < 1e-15);
    assert!(reference_weights(FacetType::Quad4, &tri, &QuadRule::quad_2x2()).is_empty());
    let bad = QuadRule {
        points: vec![],
        weights: vec![],
    };
    assert!(reference_weights(FacetType::Tri3, &tri, &bad).is_empty());
}

#[test]
fn bad_input_is_reported_not_panicked() {
    let mut rng = Lcg::new(3);
    let good = random_case(FacetType::Quad4, Some(FacetType::Quad4), 0, &mut rng);
    let n = good.n();
    let run = |c: &Case, r_len: usize, k_len: usize| {
        let (mut r, mut k) = (vec![1.0; r_len], vec![1.0; k_len]);
        let s = residual_tangent(&c.input(), &mut r, Some(&mut k));
        if !s.projection_converged {
            assert!(r.iter().chain(&k).all(|v| *v == 0.0));
        }
        assert!(!s.gap.is_nan() && !s.pressure.is_nan());
        s
    };
    assert!(run(&good, n, n * n).projection_converged);
    assert!(!run(&good, n - 1, n * n).projection_converged);
    assert!(!run(&good, n, 3).projection_converged);
    assert!(matches!(
        check_buffers(&good.input(), n, Some(3)),
        Err(LinkError::BufferLength { .. })
    ));

    let mut c = good.clone();
    c.slave_x.pop();
    assert!(!run(&c, n - 3, (n - 3) * (n - 3)).projection_converged);
    assert!(matches!(
        check_input(&c.input()),
        Err(LinkError::NodeCount { .. })
    ));
    let mut c = good.clone();
    c.slave_x[1][2] = f64::NAN;
    assert!(matches!(
        check_input(&c.input()),
        Err(LinkError::NonFinite { .. })
    ));
    assert!(!run(&c, n, n * n).projection_converged);
    for (field, value) in [("penalty", 0.0), ("lambda", -1.0), ("weight", f64::NAN)] {
        let mut c = good.clone();
        match field {
            "penalty" => c.penalty = value,
            "lambda" => c.lambda_n = value,
            _ => c.weight = value,
        }
        assert!(check_input(&c.input()).is_err(), "{field}");
        assert!(!evaluate(&c.input()).projection_converged);
        assert_eq!(potential(&c.input()), 0.0);
    }

    // Overflow-sized slave positions: whatever comes out is not NaN.
    let mut c = good.clone();
    c.slave_x.iter_mut().for_each(|p| p[0] *= 1e300);
    let (mut r, mut k) = (vec![0.0; n], vec![0.0; n * n]);
    let s = residual_tangent(&c.input(), &mut r, Some(&mut k));
    assert!(!s.gap.is_nan() && !s.pressure.is_nan());
    assert!(r.iter().chain(&k).all(|v| !v.is_nan()));

    // Degenerate master facet (all nodes at one point).
    let mut c = good.clone();
    c.master = OwnedMaster::Facet(FacetType::Quad4, vec![[0.0, 0.0, 0.0]; 4]);
    assert!(!run(&c, n, n * n).projection_converged);

    // Rigid masters: zero normal, zero radius, slave point at the
    // centre / on the axis (no normal there).
    let sq = [
        [-0.5, -0.5, 0.0],
        [0.5, -0.5, 0.0],
        [0.5, 0.5, 0.0],
        [-0.5, 0.5, 0.0],
    ];
    let rigid = [
        LinkMaster::Plane {
            point: [0.0; 3],
            normal: [0.0; 3],
        },
        LinkMaster::Sphere {
            centre: [0.0; 3],
            radius: 0.0,
        },
        LinkMaster::Sphere {
            centre: [0.0; 3],
            radius: 1.0,
        },
        LinkMaster::Cylinder {
            point: [0.0; 3],
            axis: [0.0, 1.0, 0.0],
            radius: 1.0,
        },
        LinkMaster::Cylinder {
            point: [0.0; 3],
            axis: [0.0; 3],
            radius: 1.0,
        },
    ];
    for m in rigid {
        let c = Case {
            slave_facet: FacetType::Quad4,
            slave_x: sq.to_vec(),
            zeta: [0.0; 2],
            weight: 1.0,
            master: OwnedMaster::Rigid(m),
            lambda_n: 1.0,
            penalty: 1.0,
            friction: None,
        };
        let s = run(&c, 12, 144);
        assert!(!s.projection_converged && s.pressure == 0.0, "{m:?}");
    }
}

#[test]
fn rigid_sphere_values() {
    // Slave point straight above the centre, 0.1 inside the ball.
    let x = [[0.0, 0.0, 0.9], [1.0, 0.0, 0.9], [0.0, 1.0, 0.9]];
    let input = LinkInput {
        slave_facet: FacetType::Tri3,
        slave_x: &x,
        zeta: [0.0, 0.0],
        weight: 2.0,
        master: LinkMaster::Sphere {
            centre: [0.0; 3],
            radius: 1.0,
        },
        xi_start: [0.0; 2],
        lambda_n: 0.0,
        penalty: 10.0,
        friction: None,
        main_part_tangent: false,
    };
    let s = evaluate(&input);
    assert!((s.gap + 0.1).abs() < 1e-15);
    assert!((s.pressure - 1.0).abs() < 1e-14);
    assert_eq!(s.master_point, [0.0, 0.0, 1.0]);
    assert!((potential(&input) - 1.0 / 20.0 * 2.0).abs() < 1e-15);
}

//! Coulomb friction: stick and slip, tangent, damping, balance, bad input.

use super::*;

/// Adds friction to a closed case: a slip history a little away from the
/// current master point, a λT, and μ chosen so that `|tT*| = ratio · μ pN`
/// (ratio < 1 sticks, > 1 slips; far from the kink either way).
pub(super) fn with_friction(case: &Case, ratio: f64, dynamic: bool, rng: &mut Lcg) -> Case {
    let mut c = case.clone();
    let s = evaluate(&c.input());
    let history = match &c.master {
        OwnedMaster::Facet(..) => SlipHistory::Convected {
            xi_n: [s.xi[0] - 0.05 * rng.next(), s.xi[1] + 0.05 * rng.next()],
            lambda: [0.1 * rng.next(), 0.1 * rng.next()],
        },
        OwnedMaster::Rigid(_) => SlipHistory::Spatial {
            point_n: autodiff::add(&s.master_point, &rng.vec3(0.05)),
            lambda: rng.vec3(0.1),
        },
    };
    let rate = dynamic.then(|| {
        let nm = match &c.master {
            OwnedMaster::Facet(_, x) => x.len(),
            OwnedMaster::Rigid(_) => 1,
        };
        (
            (0..c.slave_x.len()).map(|_| rng.vec3(0.5)).collect(),
            (0..nm).map(|_| rng.vec3(0.5)).collect(),
            0.1,
            3.0,
        )
    });
    c.friction = Some(CaseFriction {
        mu: 1e6,
        penalty: 15.0,
        history,
        rate,
    });
    // With μ huge the link sticks and |traction| = |tT*|.
    let trial = autodiff::norm(&evaluate(&c.input()).friction.unwrap().traction);
    if let Some(f) = &mut c.friction {
        f.mu = trial / (ratio * s.pressure);
    }
    c
}

/// Every pairing with friction: stick and slip, static and dynamic.
fn friction_cases() -> Vec<(String, Case)> {
    let mut rng = Lcg::new(7);
    let mut out = Vec::new();
    for (name, case) in all_cases() {
        for (ratio, branch) in [(0.5, "stick"), (2.0, "slip")] {
            for dynamic in [false, true] {
                let c = with_friction(&case, ratio, dynamic, &mut rng);
                let kind = if dynamic { "dyn" } else { "static" };
                out.push((format!("{name} {branch} {kind}"), c));
            }
        }
    }
    out
}

#[test]
fn friction_cases_stick_and_slip_as_intended() {
    for (name, case) in friction_cases() {
        let s = evaluate(&case.input());
        let f = s.friction.expect("closed link with friction");
        assert_eq!(f.sliding, name.contains("slip"), "{name}");
        let limit = case.friction.as_ref().unwrap().mu * s.pressure;
        let t = autodiff::norm(&f.traction);
        if f.sliding {
            assert!((t - limit).abs() < 1e-12 * limit, "{name}: {t} vs {limit}");
        } else {
            assert!(t < limit, "{name}");
        }
    }
}

#[test]
fn friction_tangent_matches_finite_differences() {
    let mut worst = std::collections::BTreeMap::<String, f64>::new();
    for (name, case) in friction_cases() {
        let (_, k, _) = case.residual_and_tangent();
        let err = rel_err(&k, &fd_tangent(&case));
        assert!(err < 1e-6, "{name}: {err:e}");
        let key = name.split(' ').skip(1).collect::<Vec<_>>().join(" ");
        let w = worst.entry(key).or_insert(0.0);
        *w = w.max(err);
    }
    for (branch, err) in worst {
        println!("friction k vs FD(r) {branch:>12}: {err:.1e}");
    }
}

#[test]
fn friction_residual_only_path_matches_dual_path() {
    for (name, case) in friction_cases() {
        let (r, _, _) = case.residual_and_tangent();
        assert!(rel_err(&case.residual(), &r) < 1e-14, "{name}");
    }
}

#[test]
fn damping_matrix_is_the_velocity_derivative() {
    // k(dv/dx = c) − k(dv/dx = 0) = c ∂r/∂v: the friction damping matrix (docs/formulation.md §8)
    // enters through the integrator's coefficient and nothing else.
    const HV: f64 = 1e-6;
    for (name, case) in friction_cases() {
        if !name.ends_with("dyn") {
            continue;
        }
        let n = case.n();
        let c = case.friction.as_ref().unwrap().rate.as_ref().unwrap().3;
        let (_, k, _) = case.residual_and_tangent();
        let mut still = case.clone();
        still.friction.as_mut().unwrap().rate.as_mut().unwrap().3 = 0.0;
        let (_, k0, _) = still.residual_and_tangent();
        let ns = case.slave_x.len();
        let facet_master = matches!(case.master, OwnedMaster::Facet(..));
        let mut damping = vec![0.0; n * n];
        for j in 0..n {
            let (node, i) = (j / 3, j % 3);
            if node >= ns && !facet_master {
                continue;
            }
            let shifted = |h: f64| {
                let mut s = still.clone();
                let rate = s.friction.as_mut().unwrap().rate.as_mut().unwrap();
                if node < ns {
                    rate.0[node][i] += h;
                } else {
                    rate.1[node - ns][i] += h;
                }
                s.residual()
            };
            let (p, m) = (shifted(HV), shifted(-HV));
            for row in 0..n {
                damping[row * n + j] = c * (p[row] - m[row]) / (2.0 * HV);
            }
        }
        let diff: Vec<f64> = k.iter().zip(&k0).map(|(a, b)| a - b).collect();
        let err = rel_err(&diff, &damping);
        assert!(err < 1e-6, "{name}: {err:e}");
    }
}

#[test]
fn friction_forces_balance_for_facet_masters() {
    for (name, case) in friction_cases() {
        if matches!(case.master, OwnedMaster::Rigid(_)) {
            continue;
        }
        let (r, k, _) = case.residual_and_tangent();
        let n = case.n();
        let scale = r.iter().fold(0.0f64, |m, v| m.max(v.abs()));
        let force = r
            .chunks_exact(3)
            .fold([0.0; 3], |f, v| autodiff::add(&f, &[v[0], v[1], v[2]]));
        assert!(autodiff::norm(&force) < 1e-13 * scale, "{name}: {force:?}");
        let kscale = k.iter().fold(0.0f64, |m, v| m.max(v.abs()));
        for i in 0..3 {
            for col in 0..n {
                let sum: f64 = (0..n / 3).map(|a| k[(3 * a + i) * n + col]).sum();
                assert!(sum.abs() < 1e-12 * kscale, "{name}: row sum {sum:e}");
            }
        }
    }
}

#[test]
fn zero_friction_coefficient_is_frictionless() {
    for (name, case) in friction_cases() {
        let mut c = case.clone();
        c.friction.as_mut().unwrap().mu = 0.0;
        let mut plain = case.clone();
        plain.friction = None;
        let (r, k, _) = c.residual_and_tangent();
        let (r0, k0, _) = plain.residual_and_tangent();
        assert!(
            rel_err(&r, &r0) < 1e-14 && rel_err(&k, &k0) < 1e-14,
            "{name}"
        );
    }
}

#[test]
fn convected_multiplier_turns_with_the_master() {
    // Rotate the whole link: the covariant λT, the slip and the forces
    // rotate with it (frame indifference).
    let (c, s) = (0.6f64, 0.8f64);
    let rot = |p: &[f64; 3]| [c * p[0] - s * p[1], s * p[0] + c * p[1], p[2]];
    for (name, case) in friction_cases() {
        let OwnedMaster::Facet(facet, x) = &case.master else {
            continue;
        };
        if name.ends_with("dyn") {
            continue;
        }
        let mut turned = case.clone();
        turned.slave_x = case.slave_x.iter().map(rot).collect();
        turned.master = OwnedMaster::Facet(*facet, x.iter().map(rot).collect());
        let (r, _, st) = case.residual_and_tangent();
        let (r2, _, st2) = turned.residual_and_tangent();
        let r_rot: Vec<f64> = r
            .chunks_exact(3)
            .flat_map(|f| rot(&[f[0], f[1], f[2]]))
            .collect();
        assert!(rel_err(&r2, &r_rot) < 1e-11, "{name}");
        let (f, f2) = (st.friction.unwrap(), st2.friction.unwrap());
        assert!(rel_err(&f2.traction, &rot(&f.traction)) < 1e-11, "{name}");
    }
}

#[test]
fn sliding_block_transmits_mu_times_pressure() {
    // A flat slave facet pressed into a flat master, then moved +x: the
    // traction on the slave is exactly −μ pN x̂ once sliding, and
    // λT + εT·slip opposing the slip while sticking.
    let master_x = [
        [-5.0, -5.0, 0.0],
        [5.0, -5.0, 0.0],
        [5.0, 5.0, 0.0],
        [-5.0, 5.0, 0.0],
    ];
    let slave_x = [
        [0.3, 0.0, -0.01],
        [0.3, 1.0, -0.01],
        [1.3, 1.0, -0.01],
        [1.3, 0.0, -0.01],
    ];
    let masters = [
        (
            LinkMaster::Facet {
                facet: FacetType::Quad4,
                x: &master_x,
            },
            SlipHistory::Convected {
                // Master point before the move: (0.5, 0.5), ξ = x/5.
                xi_n: [0.1, 0.1],
                lambda: [0.0, 0.0],
            },
        ),
        (
            LinkMaster::Plane {
                point: [0.0; 3],
                normal: [0.0, 0.0, 1.0],
            },
            SlipHistory::Spatial {
                point_n: [0.5, 0.5, 0.0],
                lambda: [0.0; 3],
            },
        ),
    ];
    let p_n = 2.0 + 100.0 * 0.01;
    for (master, history) in masters {
        for (mu, sliding) in [(0.3, true), (10.0, false)] {
            let input = LinkInput {
                slave_facet: FacetType::Quad4,
                slave_x: &slave_x,
                zeta: [0.0, 0.0],
                weight: 1.0,
                master,
                xi_start: [0.0; 2],
                lambda_n: 2.0,
                penalty: 100.0,
                friction: Some(Friction {
                    mu,
                    penalty: 50.0,
                    history,
                    rate: None,
                }),
                main_part_tangent: false,
            };
            let s = evaluate(&input);
            let f = s.friction.unwrap();
            assert_eq!(f.sliding, sliding);
            assert!(rel_err(&f.slip, &[0.3, 0.0, 0.0]) < 1e-12, "{:?}", f.slip);
            let expect = if sliding { -mu * p_n } else { -50.0 * 0.3 };
            assert!(rel_err(&f.traction, &[expect, 0.0, 0.0]) < 1e-12, "{f:?}");
            let mut r = vec![0.0; dof_count(&input)];
            residual_tangent(&input, &mut r, None);
            let fx: f64 = r[..12].chunks_exact(3).map(|v| v[0]).sum();
            assert!((fx + expect).abs() < 1e-12, "slave residual x {fx}");
        }
    }
}

#[test]
fn bad_friction_input_is_rejected() {
    let mut rng = Lcg::new(5);
    let base = random_case(FacetType::Quad4, Some(FacetType::Quad4), 0, &mut rng);
    let good = with_friction(&base, 0.5, true, &mut rng);
    assert!(check_input(&good.input()).is_ok());
    type Edit = (&'static str, fn(&mut CaseFriction));
    let edits: [Edit; 5] = [
        ("mu < 0", |f| f.mu = -0.1),
        ("εT = 0", |f| f.penalty = 0.0),
        ("εT NaN", |f| f.penalty = f64::NAN),
        ("spatial history on a facet", |f| {
            f.history = SlipHistory::Spatial {
                point_n: [0.0; 3],
                lambda: [0.0; 3],
            }
        }),
        ("dt = 0", |f| f.rate.as_mut().unwrap().2 = 0.0),
    ];
    for (what, edit) in edits {
        let mut c = good.clone();
        edit(c.friction.as_mut().unwrap());
        assert!(check_input(&c.input()).is_err(), "{what}");
        let s = evaluate(&c.input());
        assert!(!s.projection_converged && s.pressure == 0.0, "{what}");
    }
    let mut c = good.clone();
    c.friction.as_mut().unwrap().rate.as_mut().unwrap().1.pop();
    assert!(matches!(
        check_input(&c.input()),
        Err(LinkError::NodeCount { .. })
    ));
}

#[test]
#[ignore = "timing, run with --ignored --nocapture"]
fn timing_quad_quad() {
    let mut rng = Lcg::new(1);
    let case = random_case(FacetType::Quad4, Some(FacetType::Quad4), 0, &mut rng);
    let input = case.input();
    let (mut r, mut k) = ([0.0; 24], [0.0; 576]);
    let calls = 20_000;
    let start = std::time::Instant::now();
    for _ in 0..calls {
        residual_tangent(std::hint::black_box(&input), &mut r, Some(&mut k));
    }
    let dt = start.elapsed().as_secs_f64() / calls as f64;
    let start = std::time::Instant::now();
    for _ in 0..calls {
        residual_tangent(std::hint::black_box(&input), &mut r, None);
    }
    let dt_r = start.elapsed().as_secs_f64() / calls as f64;
    let start = std::time::Instant::now();
    for _ in 0..calls {
        std::hint::black_box(evaluate(std::hint::black_box(&input)));
    }
    let dt_e = start.elapsed().as_secs_f64() / calls as f64;
    println!(
        "quad4-quad4: residual_tangent {:.2} µs, residual only {:.2} µs, evaluate {:.2} µs per call",
        dt * 1e6,
        dt_r * 1e6,
        dt_e * 1e6
    );
}

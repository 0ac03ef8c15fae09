//! Closest-point projection tests: exact cases, brute-force minima,
//! convergence, degenerate and far-away input.

use super::*;
use crate::fem::test_util::Lcg;

fn flat_quad() -> [[f64; 3]; 4] {
    // A parallelogram in z = 0.3 (affine map, so ξ is known in closed
    // form): x = c + ξ₁ a + ξ₂ b.
    [
        [-1.0 - 0.2, -0.5, 0.3],
        [1.0 - 0.2, -0.5, 0.3],
        [1.0 + 0.2, 0.5, 0.3],
        [-1.0 + 0.2, 0.5, 0.3],
    ]
}

fn warped_quad() -> [[f64; 3]; 4] {
    [
        [-1.0, -1.0, 0.25],
        [1.1, -0.9, -0.2],
        [0.9, 1.2, 0.3],
        [-1.05, 0.95, -0.25],
    ]
}

fn tri() -> [[f64; 3]; 3] {
    [[0.1, 0.2, 0.5], [2.1, 0.4, 0.7], [0.3, 1.9, 0.2]]
}

fn surface_point(facet: FacetType, x: &[[f64; 3]], xi: [f64; 2]) -> [f64; 3] {
    let s = facet_shape::<MAX_FACET_NODES>(facet, xi);
    let mut p = [0.0; 3];
    for (b, xb) in x.iter().enumerate() {
        for i in 0..3 {
            p[i] += s.n[b] * xb[i];
        }
    }
    p
}

fn assert_finite(p: &Projection) {
    let vals = p.xi.iter().chain(&p.point).chain(&p.normal);
    assert!(vals.clone().all(|v| v.is_finite()), "{p:?}");
    assert!(!p.gap.is_nan() && !p.outside.is_nan(), "{p:?}");
}

#[test]
fn point_above_flat_quad_interior_is_exact() {
    let m = flat_quad();
    // x = c + 0.3 a + (−0.6) b + 0.7 ẑ with a = (1, 0, 0), b = (0.2, 0.5, 0).
    let xi_exact = [0.3, -0.6];
    let on = surface_point(FacetType::Quad4, &m, xi_exact);
    let x = [on[0], on[1], on[2] + 0.7];
    let p = project(FacetType::Quad4, &m, x, None);
    assert!(p.converged);
    assert!((p.xi[0] - 0.3).abs() < 1e-14 && (p.xi[1] + 0.6).abs() < 1e-14);
    assert!((p.gap - 0.7).abs() < 1e-14);
    assert!((p.normal[2] - 1.0).abs() < 1e-15);
    assert_eq!(p.outside, 0.0);
    // Below the facet: penetration.
    let below = project(FacetType::Quad4, &m, [on[0], on[1], on[2] - 0.2], None);
    assert!((below.gap + 0.2).abs() < 1e-14);
}

#[test]
fn tri_exact_and_oriented() {
    let m = tri();
    let xi_exact = [0.2, 0.5];
    let on = surface_point(FacetType::Tri3, &m, xi_exact);
    let n = {
        let v = cross(sub(m[1], m[0]), sub(m[2], m[0]));
        v.map(|c| c / norm(v))
    };
    let x = add(on, n.map(|c| -0.4 * c));
    let (p, its) = project_counted(FacetType::Tri3, &m, x, None);
    assert!(p.converged);
    assert!((p.xi[0] - 0.2).abs() < 1e-13 && (p.xi[1] - 0.5).abs() < 1e-13);
    assert!((p.gap + 0.4).abs() < 1e-13);
    assert!(dot(p.normal, n) > 1.0 - 1e-14);
    // A plane: Newton is exact after one step, the second confirms it.
    assert!(its <= 2, "{its} iterations");
}

#[test]
fn warped_quad_satisfies_orthogonality_and_converges_quadratically() {
    let m = warped_quad();
    let mut rng = Lcg::new(11);
    for _ in 0..50 {
        let xi = [0.8 * rng.next(), 0.8 * rng.next()];
        let on = surface_point(FacetType::Quad4, &m, xi);
        let x = add(on, rng.vec3(0.4));
        let (p, its) = project_counted(FacetType::Quad4, &m, x, None);
        assert!(p.converged, "{p:?}");
        // Gauss–Newton (no curvature term) needs far more iterations here.
        assert!(its <= 7, "{its} iterations");
        let s = facet_shape::<MAX_FACET_NODES>(FacetType::Quad4, p.xi);
        let d = sub(x, p.point);
        for alpha in 0..2 {
            let mut t = [0.0; 3];
            for (b, xb) in m.iter().enumerate() {
                for i in 0..3 {
                    t[i] += s.dn[b][alpha] * xb[i];
                }
            }
            assert!(dot(d, t).abs() < 1e-13, "F_{alpha} = {}", dot(d, t));
        }
        // x − x² is along the normal at the closest point.
        assert!((p.gap.abs() - norm(d)).abs() < 1e-13);
    }
}

/// Dense sampling over the reference square, refined around the best
/// sample, as an independent minimiser of |x − x²(ξ)|.
fn brute_force(m: &[[f64; 3]], x: [f64; 3]) -> ([f64; 2], f64) {
    let dist = |xi: [f64; 2]| norm(sub(x, surface_point(FacetType::Quad4, m, xi)));
    let mut best = ([0.0, 0.0], f64::INFINITY);
    let n = 200;
    for i in 0..=n {
        for j in 0..=n {
            let xi = [
                -1.0 + 2.0 * i as f64 / n as f64,
                -1.0 + 2.0 * j as f64 / n as f64,
            ];
            let d = dist(xi);
            if d < best.1 {
                best = (xi, d);
            }
        }
    }
    let mut h = 2.0 / n as f64;
    for _ in 0..30 {
        let c = best.0;
        for i in -4..=4 {
            for j in -4..=4 {
                let xi = [c[0] + h * i as f64 / 4.0, c[1] + h * j as f64 / 4.0];
                let d = dist(xi);
                if d < best.1 {
                    best = (xi, d);
                }
            }
        }
        h *= 0.5;
    }
    best
}

#[test]
fn random_points_match_brute_force_minimum() {
    let m = warped_quad();
    let mut rng = Lcg::new(5);
    let mut checked = 0;
    for _ in 0..40 {
        let x = add([1.2 * rng.next(), 1.2 * rng.next(), 0.0], rng.vec3(0.6));
        let (xi_b, d_b) = brute_force(&m, x);
        if xi_b.iter().any(|v| v.abs() > 0.98) {
            continue; // minimiser on the boundary of the sampled square
        }
        let p = project(FacetType::Quad4, &m, x, None);
        assert!(p.converged);
        assert!(
            (p.gap.abs() - d_b).abs() < 1e-10,
            "{} vs {d_b}",
            p.gap.abs()
        );
        assert!((p.xi[0] - xi_b[0]).abs() < 1e-6 && (p.xi[1] - xi_b[1]).abs() < 1e-6);
        checked += 1;
    }
    assert!(checked >= 20, "only {checked} interior cases");
}

#[test]
fn off_edge_and_corner_report_outside() {
    let m = flat_quad();
    // Beyond the edge ξ₁ = 1 by 0.3 in ξ₁, inside in ξ₂.
    let on = surface_point(FacetType::Quad4, &m, [1.3, 0.2]);
    let p = project(FacetType::Quad4, &m, [on[0], on[1], on[2] + 0.1], None);
    assert!(p.converged);
    assert!((p.outside - 0.3).abs() < 1e-13, "{}", p.outside);
    // Off the corner (1, 1).
    let on = surface_point(FacetType::Quad4, &m, [1.2, 1.5]);
    let p = project(FacetType::Quad4, &m, [on[0], on[1], on[2] - 0.1], None);
    assert!(p.converged);
    assert!((p.outside - 0.5).abs() < 1e-13);
    assert!((p.gap + 0.1).abs() < 1e-13);
    // Tri: beyond the hypotenuse.
    let t = tri();
    let on = surface_point(FacetType::Tri3, &t, [0.7, 0.6]);
    let p = project(FacetType::Tri3, &t, on, Some([0.0, 0.0]));
    assert!(p.converged);
    assert!((p.outside - 0.3).abs() < 1e-12);
    // Off the tri corner at node 0.
    let on = surface_point(FacetType::Tri3, &t, [-0.2, -0.4]);
    let p = project(FacetType::Tri3, &t, on, None);
    assert!((p.outside - 0.4).abs() < 1e-12);
}

#[test]
fn far_points_are_clamped_not_divergent() {
    let mut rng = Lcg::new(9);
    for facet_x in [warped_quad().to_vec(), flat_quad().to_vec()] {
        for scale in [10.0, 1e3, 1e6] {
            for _ in 0..20 {
                let x = rng.vec3(scale);
                let start = [3.0 * rng.next(), 3.0 * rng.next()];
                let p = project(FacetType::Quad4, &facet_x, x, Some(start));
                assert_finite(&p);
                let bounds = search_box(FacetType::Quad4);
                assert!(p.xi.iter().all(|v| (bounds.0..=bounds.1).contains(v)));
                // Descent: never further away than the (clamped) start.
                let d = norm(sub(x, p.point));
                let s0 = clamp_box(start, bounds);
                let d0 = norm(sub(x, surface_point(FacetType::Quad4, &facet_x, s0)));
                assert!(d <= d0 * (1.0 + 1e-9), "{d} > {d0}");
            }
        }
    }
}

#[test]
fn far_above_flat_facet_still_converges() {
    let m = flat_quad();
    let on = surface_point(FacetType::Quad4, &m, [0.4, 0.1]);
    let p = project(FacetType::Quad4, &m, [on[0], on[1], on[2] + 1e4], None);
    assert!(p.converged);
    assert!((p.xi[0] - 0.4).abs() < 1e-12 && (p.xi[1] - 0.1).abs() < 1e-12);
}

#[test]
fn degenerate_facets_do_not_panic() {
    let collapsed = [
        [0.0, 0.0, 0.0],
        [1.0, 0.0, 0.0],
        [1.0, 0.0, 0.0],
        [0.0, 1.0, 0.0],
    ];
    let p = project(FacetType::Quad4, &collapsed, [0.5, 0.3, 0.2], None);
    assert_finite(&p);
    // Triangle-shaped quad still has a normal away from the collapsed edge.
    assert!(p.converged && (p.gap - 0.2).abs() < 1e-12, "{p:?}");

    let point = [[1.0, 2.0, 3.0]; 4];
    let p = project(FacetType::Quad4, &point, [0.0, 0.0, 0.0], None);
    assert_finite(&p);
    assert!(!p.converged && p.gap == f64::INFINITY);

    let line = [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [2.0, 0.0, 0.0]];
    let p = project(FacetType::Tri3, &line, [0.5, 1.0, 0.0], None);
    assert_finite(&p);
    assert!(!p.converged);

    let sliver = [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.5, 1e-9, 0.0]];
    let p = project(FacetType::Tri3, &sliver, [0.5, 0.0, 0.3], None);
    assert_finite(&p);

    let nan = [[f64::NAN, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]];
    let p = project(FacetType::Tri3, &nan, [0.0; 3], None);
    assert!(!p.converged && p.gap == f64::INFINITY);
    let p = project(FacetType::Tri3, &tri(), [f64::INFINITY, 0.0, 0.0], None);
    assert!(!p.converged);
    let p = project(FacetType::Quad4, &tri(), [0.0; 3], None);
    assert!(!p.converged, "wrong node count must be rejected");
    // Overflow-sized coordinates: no NaN anywhere.
    for x in [[1e200, -1e200, 3e199], [1e-300, 0.0, 1e-310]] {
        assert_finite(&project(FacetType::Quad4, &warped_quad(), x, None));
    }
    let huge = warped_quad().map(|p| p.map(|c| c * 1e300));
    assert_finite(&project(FacetType::Quad4, &huge, [1.0, 2.0, 3.0], None));
    let tiny = warped_quad().map(|p| p.map(|c| c * 1e-300));
    assert_finite(&project(
        FacetType::Quad4,
        &tiny,
        [1e-300, 0.0, 2e-300],
        None,
    ));
    let p = project(
        FacetType::Tri3,
        &tri(),
        [0.3, 0.3, 1.0],
        Some([f64::NAN, 0.0]),
    );
    assert!(p.converged, "a NaN start falls back to the centre");
}

#[test]
fn start_value_is_used() {
    let m = warped_quad();
    let on = surface_point(FacetType::Quad4, &m, [0.9, -0.9]);
    let x = add(on, [0.0, 0.0, 0.05]);
    let (far, n_far) = project_counted(FacetType::Quad4, &m, x, None);
    let (near, n_near) = project_counted(FacetType::Quad4, &m, x, Some(far.xi));
    assert!(far.converged && near.converged);
    assert!(n_near < n_far, "{n_near} vs {n_far}");
    assert!((near.xi[0] - far.xi[0]).abs() < 1e-13);
}

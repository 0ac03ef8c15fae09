//! Projection onto curved second-order facets (tri6, quad8, quad9): the
//! brute-force minimum on a fine grid, orthogonality, and the quadratic
//! rate of the full-Hessian Newton iteration.

use super::*;
use crate::fem::test_util::Lcg;

/// A facet bulging out of z = 0 towards +z: the nodes of `facet` on the
/// reference facet (scaled to about 2 across) lifted onto a sphere of
/// radius 1.5, mid-side nodes moved in-plane a little.
fn bulging(facet: FacetType, rng: &mut Lcg) -> Vec<[f64; 3]> {
    let r = 1.5f64;
    crate::fem::shape::facet_reference_nodes(facet)
        .iter()
        .enumerate()
        .map(|(a, p)| {
            let (mut x, mut y) = match facet.linear() {
                FacetType::Tri3 => (2.0 * p[0] - 0.7, 2.0 * p[1] - 0.7),
                _ => (p[0], p[1]),
            };
            if a >= facet.corners() {
                x += 0.08 * rng.next();
                y += 0.08 * rng.next();
            }
            [x, y, (r * r - x * x - y * y).sqrt() - r]
        })
        .collect()
}

fn point_on(facet: FacetType, x: &[[f64; 3]], xi: [f64; 2]) -> [f64; 3] {
    let s = facet_shape::<MAX_FACET_NODES>(facet, xi);
    let mut p = [0.0; 3];
    for (b, xb) in x.iter().enumerate() {
        for i in 0..3 {
            p[i] += s.n[b] * xb[i];
        }
    }
    p
}

/// Grid minimum over the reference facet, refined around the best sample.
fn brute_force(facet: FacetType, m: &[[f64; 3]], x: [f64; 3]) -> ([f64; 2], f64) {
    let tri = facet.linear() == FacetType::Tri3;
    let dist = |xi: [f64; 2]| norm(sub(x, point_on(facet, m, xi)));
    let mut best = ([0.0, 0.0], f64::INFINITY);
    let n = 200;
    for i in 0..=n {
        for j in 0..=n {
            let xi = if tri {
                if i + j > n {
                    continue;
                }
                [i as f64 / n as f64, j as f64 / n as f64]
            } else {
                [
                    -1.0 + 2.0 * i as f64 / n as f64,
                    -1.0 + 2.0 * j as f64 / n as f64,
                ]
            };
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

const CURVED: [FacetType; 3] = [FacetType::Tri6, FacetType::Quad8, FacetType::Quad9];

#[test]
fn curved_facets_match_brute_force_minimum() {
    let mut rng = Lcg::new(31);
    for facet in CURVED {
        let m = bulging(facet, &mut rng);
        let mut checked = 0;
        let spread = if facet.linear() == FacetType::Tri3 {
            0.25
        } else {
            0.5
        };
        for _ in 0..40 {
            let centre = reference_centre(facet);
            let xi0 = [
                centre[0] + spread * rng.next(),
                centre[1] + spread * rng.next(),
            ];
            // Off the bulge on either side, up to half its radius of curvature.
            let x = add(point_on(facet, &m, xi0), rng.vec3(0.4));
            let (xi_b, d_b) = brute_force(facet, &m, x);
            if outside_distance(facet, xi_b) > 0.0
                || (0..2).any(|i| {
                    let edge = match facet.linear() {
                        FacetType::Tri3 => xi_b[i].min(1.0 - xi_b[0] - xi_b[1]),
                        _ => 1.0 - xi_b[i].abs(),
                    };
                    edge < 0.02
                })
            {
                continue; // minimiser on the facet's border
            }
            let p = project(facet, &m, x, None);
            assert!(p.converged, "{}: {p:?}", facet.name());
            assert!(
                (p.gap.abs() - d_b).abs() < 1e-10,
                "{}: {} vs {d_b}",
                facet.name(),
                p.gap.abs()
            );
            assert!(
                (p.xi[0] - xi_b[0]).abs() < 1e-6 && (p.xi[1] - xi_b[1]).abs() < 1e-6,
                "{}: {:?} vs {xi_b:?}",
                facet.name(),
                p.xi
            );
            // x − x² is normal to both tangents.
            let s = Frame::<MAX_FACET_NODES>::new(facet, &m).unwrap();
            let surf = s.surface(p.xi);
            let d = sub(sub(x, s.centre), surf.x);
            for t in [surf.t1, surf.t2] {
                assert!(dot(d, t).abs() < 1e-12, "{}", facet.name());
            }
            checked += 1;
        }
        assert!(
            checked >= 10,
            "{}: only {checked} interior cases",
            facet.name()
        );
    }
}

/// The Newton iterates from the facet centre towards a point 0.4 off a
/// strongly curved facet: once near, each error is bounded by a constant
/// times the square of the previous one. (Without the `τ_11`, `τ_22`
/// curvature terms the Hessian is wrong by `g τ_αα·ν` and the rate is
/// linear: `e_{k+1}/e_k` stays near a constant and `e_{k+1}/e_k²` grows
/// without bound.)
#[test]
fn newton_converges_quadratically_on_curved_facets() {
    let mut rng = Lcg::new(32);
    for facet in CURVED {
        let m = bulging(facet, &mut rng);
        let frame = Frame::<MAX_FACET_NODES>::new(facet, &m).unwrap();
        for k in 0..10 {
            let c = reference_centre(facet);
            let xi_star = [c[0] + 0.3 * rng.next(), c[1] + 0.3 * rng.next()];
            let s = frame.surface(xi_star);
            let normal = cross(s.t1, s.t2);
            let sign = if k % 2 == 0 { 0.4 } else { -0.3 };
            let y = add(s.x, normal.map(|v| sign * v / norm(normal)));
            let (mut xi, mut errors) = (c, Vec::new());
            for _ in 0..8 {
                let e = (xi[0] - xi_star[0]).abs().max((xi[1] - xi_star[1]).abs());
                errors.push(e);
                let s = frame.surface(xi);
                let d = sub(y, s.x);
                let f = [dot(d, s.t1), dot(d, s.t2)];
                let dir = direction(&s, d, f, [true, true]).unwrap();
                xi = [xi[0] + dir[0], xi[1] + dir[1]];
            }
            assert!(errors[7] < 1e-12, "{} {errors:?}", facet.name());
            for w in errors.windows(2) {
                if w[0] < 0.1 && w[0] > 1e-6 {
                    assert!(
                        w[1] < 5.0 * w[0] * w[0],
                        "{}: not quadratic {errors:?}",
                        facet.name()
                    );
                }
            }
        }
    }
}

#[test]
fn curved_facet_box_holds_the_facet() {
    let mut rng = Lcg::new(33);
    for facet in CURVED {
        // Mid-side nodes pushed well off-centre, so the edges overshoot
        // their end nodes.
        let mut m = bulging(facet, &mut rng);
        for p in &mut m[facet.corners()..] {
            p[0] *= 1.6;
            p[2] += 0.3;
        }
        let (lo, hi) = crate::contact::search::facet_box(facet, &m);
        let nodes = crate::contact::search::points_bounding_box(&m).unwrap();
        let mut beyond_nodes = false;
        for i in 0..=40 {
            for j in 0..=40 {
                let xi = match facet.linear() {
                    FacetType::Tri3 if i + j > 40 => continue,
                    FacetType::Tri3 => [i as f64 / 40.0, j as f64 / 40.0],
                    _ => [-1.0 + i as f64 / 20.0, -1.0 + j as f64 / 20.0],
                };
                let p = point_on(facet, &m, xi);
                for c in 0..3 {
                    assert!(
                        p[c] >= lo[c] - 1e-12 && p[c] <= hi[c] + 1e-12,
                        "{}",
                        facet.name()
                    );
                    beyond_nodes |= p[c] > nodes.1[c] + 1e-9 || p[c] < nodes.0[c] - 1e-9;
                }
            }
        }
        assert!(
            beyond_nodes,
            "{}: the case does not bulge past its nodes",
            facet.name()
        );
    }
}

//! Facet loads on boundary facets of every type (quad4, tri3, and the
//! curved tri6, quad8, quad9).
//!
//! Facet node order fixes the orientation: the right-hand normal
//! `∂x/∂ξ₁ × ∂x/∂ξ₂` must point OUT of the body (take faces from
//! [`CellType::local_faces`](super::CellType::local_faces)).
//!
//! Sign convention. Every function here returns an EXTERNAL force `f_ext`
//! (node-major, `3n` entries, overwritten) and, for the follower load, its
//! derivative `k_ext = ∂f_ext/∂u` (row-major `(3n) × (3n)`, overwritten).
//! The solver's residual is `R = f_int − f_ext` and Newton solves
//! `K Δu = −R` with `K = ∂R/∂u`, so the solver SUBTRACTS `f` from `R` and
//! SUBTRACTS `k` from `K`. The follower `k` is not symmetric per facet (it is
//! only on a closed or fully clamped surface).

use nalgebra::{Matrix3, Vector3};

use super::shape::FacetShape;
use super::{check_finite_points, check_len, FacetType, FemError, QuadRule, MAX_FACET_NODES};

/// Runs `$body` with `$n` a const buffer size that holds the facet's nodes:
/// 4 for the first-order facets, so they never zero-fill more than they
/// use, [`MAX_FACET_NODES`] for the second-order ones.
macro_rules! by_size {
    ($facet:expr, $f:ident ( $($arg:expr),* )) => {
        if $facet.nodes() <= 4 {
            $f::<4>($($arg),*)
        } else {
            $f::<MAX_FACET_NODES>($($arg),*)
        }
    };
}

/// The facet's shape at a quadrature point, in a holder of `N`.
fn shape_at<const N: usize>(facet: FacetType, p: &[f64; 3]) -> Result<FacetShape<N>, FemError> {
    FacetShape::of(facet, surface_point(p)).ok_or(FemError::LengthMismatch {
        what: "facet shape buffer",
        expected: facet.nodes(),
        got: N,
    })
}

/// The surface coordinates of a quadrature point (facet rules keep the third
/// coordinate at zero).
fn surface_point(p: &[f64; 3]) -> [f64; 2] {
    [p[0], p[1]]
}

/// Tangents `(∂x/∂ξ₁, ∂x/∂ξ₂)` of the facet through the points `x`.
fn tangents<const N: usize>(s: &FacetShape<N>, x: &[[f64; 3]]) -> (Vector3<f64>, Vector3<f64>) {
    let mut t1 = Vector3::zeros();
    let mut t2 = Vector3::zeros();
    for (xa, da) in x.iter().zip(&s.dn[..s.nodes]) {
        let xa = Vector3::from(*xa);
        t1 += da[0] * xa;
        t2 += da[1] * xa;
    }
    (t1, t2)
}

fn check_facet(facet: FacetType, what: &'static str, x: &[[f64; 3]]) -> Result<(), FemError> {
    check_len(what, facet.nodes(), x.len())?;
    check_finite_points(what, x)
}

fn check_finite_value(what: &'static str, v: f64) -> Result<(), FemError> {
    if v.is_finite() {
        Ok(())
    } else {
        Err(FemError::NonFinite { what })
    }
}

/// `[v]×`, the matrix of `w ↦ v × w`.
fn skew(v: &Vector3<f64>) -> Matrix3<f64> {
    Matrix3::new(0.0, -v.z, v.y, v.z, 0.0, -v.x, -v.y, v.x, 0.0)
}

/// Dead load: `f_{ai} = ∫ N_a t_i dA` over the reference facet (`t` is a
/// force per reference area, fixed in direction).
pub fn dead_traction(
    facet: FacetType,
    x_ref: &[[f64; 3]],
    t: [f64; 3],
    f: &mut [f64],
) -> Result<(), FemError> {
    check_facet(facet, "x_ref", x_ref)?;
    check_finite_points("t", &[t])?;
    check_len("f", 3 * facet.nodes(), f.len())?;
    f.fill(0.0);
    by_size!(facet, add_dead_traction(facet, x_ref, t, f))
}

fn add_dead_traction<const N: usize>(
    facet: FacetType,
    x_ref: &[[f64; 3]],
    t: [f64; 3],
    f: &mut [f64],
) -> Result<(), FemError> {
    // The area element of a curved facet is not a polynomial: one degree
    // beyond the pressure's rule keeps the totals to 1e-6 on strongly curved
    // facets (the first-order facets' rules are exact as they are).
    let rule = match facet {
        FacetType::Tri6 => QuadRule::composite_for_facet(facet, 2),
        FacetType::Quad8 | FacetType::Quad9 => QuadRule::quad_4x4(),
        _ => QuadRule::default_for_facet(facet),
    };
    for (p, w) in rule.points.iter().zip(&rule.weights) {
        let s = shape_at::<N>(facet, p)?;
        let (t1, t2) = tangents(&s, x_ref);
        let da = t1.cross(&t2).norm() * w;
        for (fa, na) in f.chunks_exact_mut(3).zip(&s.n[..s.nodes]) {
            for (fi, ti) in fa.iter_mut().zip(t) {
                *fi += na * ti * da;
            }
        }
    }
    Ok(())
}

/// Follower pressure on the current facet `x = X + u`; `p > 0` pushes into
/// the body: `f = −p ∫ N (∂x/∂ξ₁ × ∂x/∂ξ₂) dξ`. With `k` given, also writes
/// the exact `k = ∂f/∂u`. The default rules (2×2, 3-point) integrate both
/// exactly, since the integrands are polynomial.
pub fn follower_pressure(
    facet: FacetType,
    x_ref: &[[f64; 3]],
    u: &[[f64; 3]],
    p: f64,
    f: &mut [f64],
    mut k: Option<&mut [f64]>,
) -> Result<(), FemError> {
    check_facet(facet, "x_ref", x_ref)?;
    check_facet(facet, "u", u)?;
    check_finite_value("pressure", p)?;
    let nodes = facet.nodes();
    let ndof = 3 * nodes;
    check_len("f", ndof, f.len())?;
    f.fill(0.0);
    if let Some(k) = k.as_deref_mut() {
        check_len("k", ndof * ndof, k.len())?;
        k.fill(0.0);
    }
    by_size!(facet, add_follower_pressure(facet, x_ref, u, p, f, k))
}

fn add_follower_pressure<const N: usize>(
    facet: FacetType,
    x_ref: &[[f64; 3]],
    u: &[[f64; 3]],
    p: f64,
    f: &mut [f64],
    mut k: Option<&mut [f64]>,
) -> Result<(), FemError> {
    let mut x = [[0.0; 3]; N];
    for ((xa, xr), ua) in x.iter_mut().zip(x_ref).zip(u) {
        *xa = [xr[0] + ua[0], xr[1] + ua[1], xr[2] + ua[2]];
    }
    let x = &x[..facet.nodes()];
    let rule = QuadRule::default_for_facet(facet);
    for (pt, w) in rule.points.iter().zip(&rule.weights) {
        let s = shape_at::<N>(facet, pt)?;
        let (t1, t2) = tangents(&s, x);
        let scale = -p * w;
        add_pressure_force(&s, &t1.cross(&t2), scale, f);
        if let Some(k) = k.as_deref_mut() {
            add_pressure_tangent(&s, &t1, &t2, scale, k);
        }
    }
    Ok(())
}

fn add_pressure_force<const N: usize>(
    s: &FacetShape<N>,
    normal: &Vector3<f64>,
    scale: f64,
    f: &mut [f64],
) {
    for (fa, na) in f.chunks_exact_mut(3).zip(&s.n[..s.nodes]) {
        for (fi, ni) in fa.iter_mut().zip(normal.iter()) {
            *fi += scale * na * ni;
        }
    }
}

/// `∂(t₁ × t₂)/∂x_b = ∂N_b/∂ξ₂ [t₁]× − ∂N_b/∂ξ₁ [t₂]×`, since
/// `δt₁ × t₂ = −[t₂]× δt₁` and `t₁ × δt₂ = [t₁]× δt₂`.
fn add_pressure_tangent<const N: usize>(
    s: &FacetShape<N>,
    t1: &Vector3<f64>,
    t2: &Vector3<f64>,
    scale: f64,
    k: &mut [f64],
) {
    let ndof = 3 * s.nodes;
    let (s1, s2) = (skew(t1), skew(t2));
    for (node_b, db) in s.dn[..s.nodes].iter().enumerate() {
        let dn_db = db[1] * s1 - db[0] * s2;
        for (node_a, na) in s.n[..s.nodes].iter().enumerate() {
            for i in 0..3 {
                let row = (3 * node_a + i) * ndof + 3 * node_b;
                for (kk, kv) in k[row..row + 3].iter_mut().enumerate() {
                    *kv += scale * na * dn_db[(i, kk)];
                }
            }
        }
    }
}

/// Area of the facet through the points `x` (reference or current).
pub fn facet_area(facet: FacetType, x: &[[f64; 3]]) -> Result<f64, FemError> {
    check_facet(facet, "x", x)?;
    by_size!(facet, area(facet, x))
}

fn area<const N: usize>(facet: FacetType, x: &[[f64; 3]]) -> Result<f64, FemError> {
    // |t₁ × t₂| of a warped or curved facet is not polynomial: 4×4 on a
    // quad4, composite rules on the curved second-order facets (relative
    // error below 1e-8 on a strongly curved one); for planar first-order
    // facets any rule is already exact.
    let rule = match facet {
        FacetType::Tri3 => QuadRule::tri_1(),
        FacetType::Quad4 => QuadRule::quad_4x4(),
        FacetType::Tri6 => QuadRule::composite_for_facet(facet, 8),
        FacetType::Quad8 | FacetType::Quad9 => QuadRule::composite_for_facet(facet, 4),
    };
    let mut sum = 0.0;
    for (p, w) in rule.points.iter().zip(&rule.weights) {
        let (t1, t2) = tangents(&shape_at::<N>(facet, p)?, x);
        sum += t1.cross(&t2).norm() * w;
    }
    Ok(sum)
}

/// Vector area `∫ (∂x/∂ξ₁ × ∂x/∂ξ₂) dξ` of the facet through `x`:
/// direction the (mean) outward normal, length the area of a planar facet.
/// Exact for every facet type (the integrand is a polynomial the default
/// rule integrates).
pub fn facet_vector_area(facet: FacetType, x: &[[f64; 3]]) -> Result<[f64; 3], FemError> {
    check_facet(facet, "x", x)?;
    by_size!(facet, vector_area(facet, x))
}

fn vector_area<const N: usize>(facet: FacetType, x: &[[f64; 3]]) -> Result<[f64; 3], FemError> {
    let rule = QuadRule::default_for_facet(facet);
    let mut sum = Vector3::zeros();
    for (p, w) in rule.points.iter().zip(&rule.weights) {
        let (t1, t2) = tangents(&shape_at::<N>(facet, p)?, x);
        sum += t1.cross(&t2) * *w;
    }
    Ok([sum.x, sum.y, sum.z])
}

/// Samples of each node's shape function over the facet through `x`:
/// (node, point, N_node · dA) at every point of `rule`.
pub fn shape_samples(
    facet: FacetType,
    x: &[[f64; 3]],
    rule: &QuadRule,
) -> Result<Vec<(usize, [f64; 3], f64)>, FemError> {
    check_facet(facet, "x", x)?;
    by_size!(facet, samples(facet, x, rule))
}

fn samples<const N: usize>(
    facet: FacetType,
    x: &[[f64; 3]],
    rule: &QuadRule,
) -> Result<Vec<(usize, [f64; 3], f64)>, FemError> {
    let mut out = Vec::with_capacity(rule.len() * x.len());
    for (p, w) in rule.points.iter().zip(&rule.weights) {
        let s = shape_at::<N>(facet, p)?;
        let (t1, t2) = tangents(&s, x);
        let da = t1.cross(&t2).norm() * w;
        let mut at = [0.0; 3];
        for (na, xa) in s.n.iter().zip(x) {
            for k in 0..3 {
                at[k] += na * xa[k];
            }
        }
        out.extend((0..x.len()).map(|a| (a, at, s.n[a] * da)));
    }
    Ok(out)
}

/// Unit outward normal at the facet centre (`ξ = (0,0)` for
/// quadrilaterals, `(⅓,⅓)` for triangles).
pub fn facet_normal_at_centre(facet: FacetType, x: &[[f64; 3]]) -> Result<[f64; 3], FemError> {
    check_facet(facet, "x", x)?;
    by_size!(facet, normal_at_centre(facet, x))
}

fn normal_at_centre<const N: usize>(
    facet: FacetType,
    x: &[[f64; 3]],
) -> Result<[f64; 3], FemError> {
    let centre = match facet.linear() {
        FacetType::Tri3 => [1.0 / 3.0, 1.0 / 3.0, 0.0],
        _ => [0.0, 0.0, 0.0],
    };
    let (t1, t2) = tangents(&shape_at::<N>(facet, &centre)?, x);
    let n = t1.cross(&t2);
    let area = n.norm();
    // Relative to the tangent lengths, so the test does not depend on units.
    let scale = t1.norm() * t2.norm();
    if area.is_nan() || area <= 1e-14 * scale || scale == 0.0 {
        return Err(FemError::DegenerateFacet {
            facet: facet.name(),
            area,
        });
    }
    let n = n / area;
    Ok([n.x, n.y, n.z])
}

#[cfg(test)]
mod tests {
    use super::super::shape::{self, facet_reference_nodes};
    use super::super::test_util::{distorted_cell, hex8_unit, perturb, rel_err, unit_cell, Lcg};
    use super::super::CellType;
    use super::*;

    const H: f64 = 1e-6;

    /// The unit square or triangle, every node moved by up to 0.2 (0.08 for
    /// the second-order facets, whose nodes are closer: curved, not folded).
    fn warped(facet: FacetType, seed: u64) -> Vec<[f64; 3]> {
        let mut x: Vec<[f64; 3]> = facet_reference_nodes(facet)
            .iter()
            .map(|p| match facet.linear() {
                FacetType::Tri3 => [p[0], p[1], 0.0],
                _ => [0.5 * (p[0] + 1.0), 0.5 * (p[1] + 1.0), 0.0],
            })
            .collect();
        let amp = if facet.is_linear() { 0.2 } else { 0.08 };
        perturb(&mut x, &mut Lcg::new(seed), amp);
        x
    }

    fn pressure_force(facet: FacetType, x: &[[f64; 3]], u: &[[f64; 3]], p: f64) -> Vec<f64> {
        let mut f = vec![0.0; 3 * facet.nodes()];
        follower_pressure(facet, x, u, p, &mut f, None).unwrap();
        f
    }

    #[test]
    fn follower_tangent_matches_finite_differences() {
        for facet in FacetType::ALL {
            let x = warped(facet, 21);
            let mut rng = Lcg::new(22);
            let u: Vec<[f64; 3]> = (0..facet.nodes()).map(|_| rng.vec3(0.2)).collect();
            let p = 3.7;
            let ndof = 3 * facet.nodes();
            let mut f = vec![0.0; ndof];
            let mut k = vec![0.0; ndof * ndof];
            follower_pressure(facet, &x, &u, p, &mut f, Some(&mut k)).unwrap();
            assert_eq!(f, pressure_force(facet, &x, &u, p));
            let mut fd = vec![0.0; ndof * ndof];
            for col in 0..ndof {
                let mut up = u.clone();
                let mut um = u.clone();
                up[col / 3][col % 3] += H;
                um[col / 3][col % 3] -= H;
                let fp = pressure_force(facet, &x, &up, p);
                let fm = pressure_force(facet, &x, &um, p);
                for row in 0..ndof {
                    fd[row * ndof + col] = (fp[row] - fm[row]) / (2.0 * H);
                }
            }
            let err = rel_err(&k, &fd);
            println!("follower k vs FD {}: {err:.2e}", facet.name());
            assert!(err < 1e-6, "{}: {err:e}", facet.name());
            // Not symmetric per facet: a symmetric bug would hide here.
            let asym = (0..ndof * ndof)
                .map(|e| (k[e] - k[(e % ndof) * ndof + e / ndof]).abs())
                .fold(0.0f64, f64::max);
            assert!(asym > 1e-3);
        }
    }

    fn total(f: &[f64]) -> [f64; 3] {
        let mut t = [0.0; 3];
        for fa in f.chunks_exact(3) {
            for i in 0..3 {
                t[i] += fa[i];
            }
        }
        t
    }

    /// Sum of the follower forces over all faces of a deformed cell: the
    /// vector area of a closed surface vanishes.
    fn closed_surface_total(cell: CellType, x: &[[f64; 3]], u: &[[f64; 3]]) -> [f64; 3] {
        let mut sum = [0.0; 3];
        for (f, face) in cell.local_faces().iter().enumerate() {
            let xf: Vec<[f64; 3]> = face.iter().map(|&a| x[a]).collect();
            let uf: Vec<[f64; 3]> = face.iter().map(|&a| u[a]).collect();
            let t = total(&pressure_force(cell.face_type(f), &xf, &uf, 2.5));
            for i in 0..3 {
                sum[i] += t[i];
            }
        }
        sum
    }

    #[test]
    fn pressure_on_closed_surface_sums_to_zero() {
        let mut rng = Lcg::new(23);
        for cell in CellType::ALL {
            // Curved faces close too: neighbouring faces share their edge
            // nodes, so the surface is watertight.
            let x = distorted_cell(cell, 30, 0.1);
            let u: Vec<[f64; 3]> = (0..cell.nodes()).map(|_| rng.vec3(0.2)).collect();
            let sum = closed_surface_total(cell, &x, &u);
            assert!(
                sum.iter().all(|v| v.abs() < 1e-13),
                "{}: {sum:?}",
                cell.name()
            );
            // One face alone must not vanish, or the sum proves nothing.
            let face = cell.local_faces()[0];
            let xf: Vec<[f64; 3]> = face.iter().map(|&a| x[a]).collect();
            let uf: Vec<[f64; 3]> = face.iter().map(|&a| u[a]).collect();
            let single = total(&pressure_force(cell.face_type(0), &xf, &uf, 2.5));
            assert!(single.iter().any(|v| v.abs() > 0.1));
        }
    }

    #[test]
    fn pressure_on_one_face_is_minus_p_area_normal() {
        let p = 4.0;
        for cell in CellType::ALL {
            let x = unit_cell(cell);
            for (f, face) in cell.local_faces().iter().enumerate() {
                let facet = cell.face_type(f);
                let xf: Vec<[f64; 3]> = face.iter().map(|&a| x[a]).collect();
                let area = facet_area(facet, &xf).unwrap();
                let n = facet_normal_at_centre(facet, &xf).unwrap();
                let zero = vec![[0.0; 3]; face.len()];
                let t = total(&pressure_force(facet, &xf, &zero, p));
                for i in 0..3 {
                    assert!(
                        (t[i] + p * area * n[i]).abs() < 1e-13,
                        "{} {face:?}",
                        cell.name()
                    );
                }
            }
            // The slanted tet face: area √3/2, normal (1,1,1)/√3.
            if cell == CellType::Tet4 {
                let facet = FacetType::Tri3;
                let xf: Vec<[f64; 3]> = [1, 2, 3].iter().map(|&a| x[a]).collect();
                let area = facet_area(facet, &xf).unwrap();
                assert!((area - 3f64.sqrt() / 2.0).abs() < 1e-15);
                let n = facet_normal_at_centre(facet, &xf).unwrap();
                assert!(n.iter().all(|v| (v - 1.0 / 3f64.sqrt()).abs() < 1e-15));
            }
        }
        // Bottom face of the unit cube: pressure pushes up (+z, into the body).
        let bottom: Vec<[f64; 3]> = [0, 3, 2, 1].iter().map(|&a| hex8_unit()[a]).collect();
        let t = total(&pressure_force(
            FacetType::Quad4,
            &bottom,
            &[[0.0; 3]; 4],
            p,
        ));
        assert!((t[2] - p).abs() < 1e-14 && t[0].abs() < 1e-14 && t[1].abs() < 1e-14);
    }

    #[test]
    fn dead_traction_distributes_total_force() {
        let t = [1.0, -2.0, 0.5];
        for facet in [FacetType::Quad4, FacetType::Tri3] {
            let x: Vec<[f64; 3]> = match facet {
                FacetType::Quad4 => vec![
                    [0.0, 0.0, 0.0],
                    [2.0, 0.0, 0.0],
                    [2.5, 1.0, 0.0],
                    [0.0, 1.0, 0.0],
                ],
                _ => vec![[0.0, 0.0, 1.0], [2.0, 0.0, 1.0], [0.0, 3.0, 1.0]],
            };
            let area = if facet == FacetType::Quad4 { 2.25 } else { 3.0 };
            assert!((facet_area(facet, &x).unwrap() - area).abs() < 1e-14);
            let mut f = vec![0.0; 3 * facet.nodes()];
            dead_traction(facet, &x, t, &mut f).unwrap();
            let tot = total(&f);
            for i in 0..3 {
                assert!((tot[i] - t[i] * area).abs() < 1e-14);
            }
            if facet == FacetType::Tri3 {
                // Linear triangle: each node carries a third.
                for fa in f.chunks_exact(3) {
                    assert!((fa[0] - t[0] * area / 3.0).abs() < 1e-14);
                }
            }
        }
    }

    #[test]
    fn shape_samples_split_the_area_and_the_first_moment_among_the_corners() {
        for facet in FacetType::ALL {
            let x = warped(facet, 7);
            let cells = if facet.is_linear() { 3 } else { 8 };
            let rule = QuadRule::composite_for_facet(facet, cells);
            let samples = shape_samples(facet, &x, &rule).unwrap();
            assert_eq!(samples.len(), rule.len() * x.len());
            let area: f64 = samples.iter().map(|s| s.2).sum();
            let exact = facet_area(facet, &x).unwrap();
            assert!(
                rel_err(&[area], &[exact]) < 1e-6,
                "{facet:?}: {area} vs {exact}"
            );
            // Σ_a N_a x_a = x at every sample: the corners' weighted positions
            // add up to the facet's first moment.
            let moment = |k: usize| -> (f64, f64) {
                let by_corner: f64 = samples.iter().map(|s| s.2 * x[s.0][k]).sum();
                let by_point: f64 = samples.iter().map(|s| s.2 * s.1[k]).sum();
                (by_corner, by_point)
            };
            for k in 0..3 {
                let (c, p) = moment(k);
                assert!(
                    (c - p).abs() < 1e-12 * (1.0 + p.abs()),
                    "{facet:?} {k}: {c} vs {p}"
                );
            }
        }
        assert!(shape_samples(FacetType::Quad4, &[[0.0; 3]; 3], &QuadRule::quad_2x2()).is_err());
    }

    #[test]
    fn warped_quad_area_converges() {
        let x = warped(FacetType::Quad4, 24);
        let reference: f64 = {
            // 16×16 sub-quads of the 4×4 rule as an independent reference.
            let m = 16;
            let rule = QuadRule::quad_4x4();
            let mut a = 0.0;
            for i in 0..m {
                for j in 0..m {
                    for (p, w) in rule.points.iter().zip(&rule.weights) {
                        let h = 2.0 / m as f64;
                        let xi = [
                            -1.0 + h * (i as f64 + 0.5 * (p[0] + 1.0)),
                            -1.0 + h * (j as f64 + 0.5 * (p[1] + 1.0)),
                        ];
                        let (t1, t2) = tangents(&shape::quad4(xi), &x);
                        a += t1.cross(&t2).norm() * w * h * h / 4.0;
                    }
                }
            }
            a
        };
        let area = facet_area(FacetType::Quad4, &x).unwrap();
        assert!(
            (area - reference).abs() < 1e-6 * reference,
            "{area} vs {reference}"
        );
    }

    /// The parabolic sheet z = c x² over the unit square (quad8, quad9) or
    /// the unit triangle (tri6), which the quadratic facets represent
    /// exactly: the pressure's total is −p times the vector area
    /// ∫ (−2cx, 0, 1) dA, exact with the default rules, and the area is
    /// ∫ √(1 + 4c²x²) dA in closed form.
    #[test]
    fn pressure_and_area_of_curved_facets_match_closed_forms() {
        let c: f64 = 0.7;
        let p = 3.0;
        let sheet = |x: f64, y: f64| [x, y, c * x * x];
        // ∫₀¹ √(1 + 4c²x²) dx and ∫₀¹ (1 − x) √(1 + 4c²x²) dx.
        let g = |x: f64| (1.0 + 4.0 * c * c * x * x).sqrt();
        let prim = |x: f64| 0.5 * x * g(x) + (2.0 * c * x).asinh() / (4.0 * c);
        let square_area = prim(1.0) - prim(0.0);
        let moment = (g(1.0).powi(3) - 1.0) / (12.0 * c * c);
        let triangle_area = square_area - moment;
        for facet in [FacetType::Quad8, FacetType::Quad9, FacetType::Tri6] {
            let x: Vec<[f64; 3]> = facet_reference_nodes(facet)
                .iter()
                .map(|q| match facet.linear() {
                    FacetType::Tri3 => sheet(q[0], q[1]),
                    _ => sheet(0.5 * (q[0] + 1.0), 0.5 * (q[1] + 1.0)),
                })
                .collect();
            let (vector_area, area) = match facet.linear() {
                FacetType::Tri3 => ([-c / 3.0, 0.0, 0.5], triangle_area),
                _ => ([-c, 0.0, 1.0], square_area),
            };
            let zero = vec![[0.0; 3]; facet.nodes()];
            let t = total(&pressure_force(facet, &x, &zero, p));
            for i in 0..3 {
                assert!(
                    (t[i] + p * vector_area[i]).abs() < 1e-14,
                    "{} {t:?}",
                    facet.name()
                );
            }
            let a = facet_area(facet, &x).unwrap();
            println!("{} area {a} vs {area}", facet.name());
            assert!(
                (a - area).abs() < 1e-6 * area,
                "{}: {a} vs {area}",
                facet.name()
            );
            // A dead traction's total is t times the area it acts on; its
            // integrand ∝ |t₁ × t₂| is not a polynomial on a curved facet,
            // so the load rule is close, not exact.
            let mut f = vec![0.0; 3 * facet.nodes()];
            dead_traction(facet, &x, [0.0, 0.0, -2.0], &mut f).unwrap();
            let tot = total(&f);
            let err = (tot[2] + 2.0 * area).abs() / area;
            println!(
                "{} dead traction total: relative error {err:.1e}",
                facet.name()
            );
            assert!(err < 1e-5, "{}: {err:e}", facet.name());
            let n = facet_normal_at_centre(facet, &x).unwrap();
            assert!(n[2] > 0.0 && n[0] < 0.0, "{} {n:?}", facet.name());
        }
    }

    /// On a flat tri6 the corner nodes carry nothing of a uniform load and
    /// the mid-edge nodes a third each; on a flat quad8 the corners carry
    /// −1/12 and the mid-edges 1/3 (the serendipity element's well-known
    /// consistent loads).
    #[test]
    fn flat_second_order_facets_distribute_uniform_loads_consistently() {
        let flat = |facet: FacetType| -> Vec<[f64; 3]> {
            facet_reference_nodes(facet)
                .iter()
                .map(|q| [q[0], q[1], 0.0])
                .collect()
        };
        let mut f = vec![0.0; 18];
        dead_traction(
            FacetType::Tri6,
            &flat(FacetType::Tri6),
            [0.0, 0.0, 1.0],
            &mut f,
        )
        .unwrap();
        for (a, fa) in f.chunks_exact(3).enumerate() {
            let expect = if a < 3 { 0.0 } else { 0.5 / 3.0 };
            assert!((fa[2] - expect).abs() < 1e-15, "tri6 node {a}: {}", fa[2]);
        }
        let mut f = vec![0.0; 24];
        dead_traction(
            FacetType::Quad8,
            &flat(FacetType::Quad8),
            [0.0, 0.0, 1.0],
            &mut f,
        )
        .unwrap();
        for (a, fa) in f.chunks_exact(3).enumerate() {
            let expect = if a < 4 { -4.0 / 12.0 } else { 4.0 / 3.0 };
            assert!((fa[2] - expect).abs() < 1e-14, "quad8 node {a}: {}", fa[2]);
        }
    }

    #[test]
    fn bad_input_is_an_error() {
        let x = warped(FacetType::Tri3, 25);
        let mut f = vec![0.0; 9];
        let u = [[0.0; 3]; 3];
        assert!(follower_pressure(FacetType::Tri3, &x, &u, f64::NAN, &mut f, None).is_err());
        assert!(follower_pressure(FacetType::Quad4, &x, &u, 1.0, &mut f, None).is_err());
        let mut short = vec![0.0; 8];
        assert!(follower_pressure(FacetType::Tri3, &x, &u, 1.0, &mut f, Some(&mut short)).is_err());
        assert!(dead_traction(FacetType::Tri3, &x, [f64::INFINITY, 0.0, 0.0], &mut f).is_err());
        let line = [[0.0; 3], [1.0, 0.0, 0.0], [2.0, 0.0, 0.0]];
        assert!(matches!(
            facet_normal_at_centre(FacetType::Tri3, &line),
            Err(FemError::DegenerateFacet { .. })
        ));
        assert!(facet_area(FacetType::Tri3, &x[..2]).is_err());
    }
}

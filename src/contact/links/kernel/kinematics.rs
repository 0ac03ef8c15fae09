//! Kinematics of a link in scalar type `T` (f64, or dual for the tangent):
//! the slave point, the closest master point, gap, normal and the frame in
//! which the master point moves (convected on a facet, rigid otherwise).

use super::input::{LinkInput, LinkMaster};
use crate::contact::autodiff::{self, Scalar, Vec3};
use crate::contact::{facet_second, facet_shape, facet_third};
use crate::fem::FacetType;

/// `x¹ = Σ N¹_a(ζ) x¹_a` (`M`: the node capacity of the kernel instance).
pub(super) fn slave_point<T: Scalar, const M: usize>(
    facet: FacetType,
    zeta: [f64; 2],
    x: &[Vec3<T>],
) -> Vec3<T> {
    let s = facet_shape::<M>(facet, zeta);
    let mut p = autodiff::constant3([0.0; 3]);
    for (xa, na) in x.iter().zip(s.n) {
        p = autodiff::axpy(&p, na, xa);
    }
    p
}

/// Gap, normal, master shape values and the convected frame at the closest
/// point, in scalar type `T` (f64 or dual), for facets of up to `M` nodes.
pub(super) struct Kinematics<T, const M: usize> {
    /// `x¹ − x²(ξ̄)` (= gN ν at the closest point).
    pub(super) separation: Vec3<T>,
    pub(super) gap: T,
    pub(super) normal: Vec3<T>,
    pub(super) master_point: Vec3<T>,
    /// `N²_b(ξ̄)` for a facet master (first `n_m` entries).
    pub(super) master_n: [T; M],
    pub(super) frame: Frame<T, M>,
}

/// How the master point moves along the surface (what friction needs).
pub(super) enum Frame<T, const M: usize> {
    /// Master facet: ξ̄ (dual-valued, so it carries ∂ξ̄/∂u), tangents τ_α,
    /// the projection Hessian `H = [h11, h12, h22]` and `N²_b,α(ξ̄)`.
    Facet {
        xi: [T; 2],
        tangents: [Vec3<T>; 2],
        hessian: [T; 3],
        master_dn: [[T; 2]; M],
    },
    /// Rigid master: the contact point's derivative with respect to x¹ is
    /// `J = a⊗a + s (I − a⊗a − ν⊗ν)` (plane: s = 1 and no axis; sphere:
    /// s = R/|x¹ − c|; cylinder: s = R/(distance to the axis), a the axis).
    Rigid { scale: T, axis: Option<[f64; 3]> },
}

/// Relative threshold for a singular projection Hessian or a vanishing
/// normal, matching the projection's own test.
pub(super) const SINGULAR: f64 = 1e-12;

/// Kinematics on a master facet at the converged ξ̄ (f64), with one Newton
/// step in `T` to carry the derivative of ξ̄. `None` if the projection
/// Hessian is singular or the facet has no normal (no tangent exists then).
///
/// The step Δ has zero value at a converged ξ̄, so what is evaluated at
/// ξ̄ + Δ needs the Taylor terms that carry a first derivative: `N_b` and
/// `x²` to first order in Δ, the tangents `τ_α` and `N_b,α` to first order
/// too, which brings in the second derivatives `N_b,αβ` (the curvature), and
/// the projection Hessian `H_αβ = τ_α·τ_β − (x¹ − x²)·τ_αβ` (friction's
/// `H⁻¹`) with `τ_αβ` to first order, which brings in the third
/// derivatives (quad8, quad9 only). On a first-order facet the only
/// non-zero second derivative is the bilinear quad's mixed one, and the
/// expansion (with its `Δ₁Δ₂` term) is exact.
fn facet_kinematics<T: Scalar, const M: usize>(
    x1: &Vec3<T>,
    facet: FacetType,
    xm: &[Vec3<T>],
    xi_bar: [f64; 2],
) -> Option<Kinematics<T, M>> {
    let s = facet_shape::<M>(facet, xi_bar);
    let dd = facet_second::<M>(facet, xi_bar);
    let curved = !facet.is_linear();
    let zero = autodiff::constant3::<T>([0.0; 3]);
    let (mut x2, mut t1, mut t2, mut t12) = (zero, zero, zero, zero);
    let (mut t11, mut t22) = (zero, zero);
    for (b, xb) in xm.iter().enumerate() {
        x2 = autodiff::axpy(&x2, s.n[b], xb);
        t1 = autodiff::axpy(&t1, s.dn[b][0], xb);
        t2 = autodiff::axpy(&t2, s.dn[b][1], xb);
        t12 = autodiff::axpy(&t12, dd[b][1], xb);
        if curved {
            t11 = autodiff::axpy(&t11, dd[b][0], xb);
            t22 = autodiff::axpy(&t22, dd[b][2], xb);
        }
    }
    // Newton step Δ = H⁻¹ F on F_α = (x¹ − x²)·τ_α.
    let d = autodiff::sub(x1, &x2);
    let f = [autodiff::dot(&d, &t1), autodiff::dot(&d, &t2)];
    let mut h11 = autodiff::dot(&t1, &t1);
    let mut h22 = autodiff::dot(&t2, &t2);
    let h12 = autodiff::dot(&t1, &t2) - autodiff::dot(&d, &t12);
    if curved {
        h11 = h11 - autodiff::dot(&d, &t11);
        h22 = h22 - autodiff::dot(&d, &t22);
    }
    let det = h11 * h22 - h12 * h12;
    if !(h11.re() > 0.0 && det.re() > SINGULAR * h11.re() * h22.re()) {
        return None;
    }
    let d1 = (h22 * f[0] - h12 * f[1]) / det;
    let d2 = (h11 * f[1] - h12 * f[0]) / det;
    let d12 = d1 * d2;
    let x2 = autodiff::add(
        &autodiff::add(&x2, &autodiff::scale(&t1, d1)),
        &autodiff::add(&autodiff::scale(&t2, d2), &autodiff::scale(&t12, d12)),
    );
    let mut t1 = autodiff::add(&t1, &autodiff::scale(&t12, d2));
    let mut t2 = autodiff::add(&t2, &autodiff::scale(&t12, d1));
    let mut master_n = [T::from_f64(0.0); M];
    let mut master_dn = [[T::from_f64(0.0); 2]; M];
    for b in 0..xm.len() {
        let m = dd[b][1];
        master_n[b] = d1 * s.dn[b][0] + d2 * s.dn[b][1] + d12 * m + s.n[b];
        master_dn[b] = [d2 * m + s.dn[b][0], d1 * m + s.dn[b][1]];
    }
    // τ_αβ at ξ̄ + Δ for the Hessian: constant (t12) on a first-order facet.
    let (mut t11_at, mut t12_at, mut t22_at) = (t11, t12, t22);
    if curved {
        t1 = autodiff::add(&t1, &autodiff::scale(&t11, d1));
        t2 = autodiff::add(&t2, &autodiff::scale(&t22, d2));
        let ddd = facet_third::<M>(facet, xi_bar);
        let (mut t112, mut t122) = (zero, zero);
        for (b, xb) in xm.iter().enumerate() {
            t112 = autodiff::axpy(&t112, ddd[b][0], xb);
            t122 = autodiff::axpy(&t122, ddd[b][1], xb);
            master_dn[b][0] = master_dn[b][0] + d1 * dd[b][0];
            master_dn[b][1] = master_dn[b][1] + d2 * dd[b][2];
        }
        // τ_111 = τ_222 = 0 (see `contact::facet_third`).
        t11_at = autodiff::add(&t11, &autodiff::scale(&t112, d2));
        t12_at = autodiff::add(
            &t12,
            &autodiff::add(&autodiff::scale(&t112, d1), &autodiff::scale(&t122, d2)),
        );
        t22_at = autodiff::add(&t22, &autodiff::scale(&t122, d1));
    }
    let normal = unit(
        &autodiff::cross(&t1, &t2),
        autodiff::norm(&t1).re() * autodiff::norm(&t2).re(),
    )?;
    let separation = autodiff::sub(x1, &x2);
    // The Hessian at ξ̄ + Δ (not ξ̄), so its derivative includes the move of ξ̄.
    let mut hessian = [
        autodiff::dot(&t1, &t1),
        autodiff::dot(&t1, &t2) - autodiff::dot(&separation, &t12_at),
        autodiff::dot(&t2, &t2),
    ];
    if curved {
        hessian[0] = hessian[0] - autodiff::dot(&separation, &t11_at);
        hessian[2] = hessian[2] - autodiff::dot(&separation, &t22_at);
    }
    Some(Kinematics {
        gap: autodiff::dot(&separation, &normal),
        separation,
        normal,
        master_point: x2,
        master_n,
        frame: Frame::Facet {
            xi: [d1 + xi_bar[0], d2 + xi_bar[1]],
            tangents: [t1, t2],
            hessian,
            master_dn,
        },
    })
}

/// `v/|v|`, or `None` if `|v| ≤ SINGULAR · scale` (no direction).
fn unit<T: Scalar>(v: &Vec3<T>, scale: f64) -> Option<Vec3<T>> {
    let len = autodiff::norm(v);
    (len.re() > SINGULAR * scale && len.re() > 0.0).then(|| autodiff::scale(v, len.recip()))
}

fn unit_f64(v: [f64; 3]) -> [f64; 3] {
    let len = autodiff::norm(&v);
    v.map(|c| c / len)
}

/// Closest point on a rigid master, in `T`. `None` where the normal is
/// undefined (slave point at the sphere centre / on the cylinder axis).
pub(super) fn rigid_kinematics<T: Scalar, const M: usize>(
    x1: &Vec3<T>,
    master: &LinkMaster,
) -> Option<Kinematics<T, M>> {
    let no_nodes = [T::from_f64(0.0); M];
    let one = T::from_f64(1.0);
    let (normal, gap, master_point, scale, axis) = match *master {
        LinkMaster::Plane { point, normal } => {
            let n = autodiff::constant3::<T>(unit_f64(normal));
            let gap = autodiff::dot(&autodiff::sub(x1, &autodiff::constant3(point)), &n);
            let foot = autodiff::sub(x1, &autodiff::scale(&n, gap));
            (n, gap, foot, one, None)
        }
        LinkMaster::Sphere { centre, radius } => {
            let c = autodiff::constant3::<T>(centre);
            let n = unit(&autodiff::sub(x1, &c), radius)?;
            let dist = autodiff::dot(&autodiff::sub(x1, &c), &n);
            let foot = autodiff::add(&c, &autodiff::scale_f64(&n, radius));
            (n, dist - radius, foot, dist.recip() * radius, None)
        }
        LinkMaster::Cylinder {
            point,
            axis,
            radius,
        } => {
            let a_f = unit_f64(axis);
            let a = autodiff::constant3::<T>(a_f);
            let d = autodiff::sub(x1, &autodiff::constant3(point));
            let along = autodiff::scale(&a, autodiff::dot(&d, &a));
            let n = unit(&autodiff::sub(&d, &along), radius)?;
            let dist = autodiff::dot(&autodiff::sub(&d, &along), &n);
            let base = autodiff::add(&autodiff::constant3(point), &along);
            let foot = autodiff::add(&base, &autodiff::scale_f64(&n, radius));
            (n, dist - radius, foot, dist.recip() * radius, Some(a_f))
        }
        LinkMaster::Facet { .. } => return None,
    };
    Some(Kinematics {
        separation: autodiff::sub(x1, &master_point),
        gap,
        normal,
        master_point,
        master_n: no_nodes,
        frame: Frame::Rigid { scale, axis },
    })
}

/// `v − ν (ν·v)`.
pub(super) fn tangential<T: Scalar>(v: &Vec3<T>, normal: &Vec3<T>) -> Vec3<T> {
    autodiff::sub(v, &autodiff::scale(normal, autodiff::dot(normal, v)))
}

/// Kinematics for either master kind, with slave and master nodal
/// positions already in `T`.
pub(super) fn kinematics<T: Scalar, const M: usize>(
    input: &LinkInput,
    slave: &[Vec3<T>],
    master: &[Vec3<T>],
    xi_bar: [f64; 2],
) -> Option<Kinematics<T, M>> {
    let x1 = slave_point::<T, M>(input.slave_facet, input.zeta, slave);
    match input.master {
        LinkMaster::Facet { facet, .. } => facet_kinematics(&x1, facet, master, xi_bar),
        _ => rigid_kinematics(&x1, &input.master),
    }
}

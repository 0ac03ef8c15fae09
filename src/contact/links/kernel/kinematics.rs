//! Kinematics of a link in scalar type `T` (f64, or dual for the tangent):
//! the slave point, the closest master point, gap, normal and the frame in
//! which the master point moves (convected on a facet, rigid otherwise).

use super::input::{LinkInput, LinkMaster};
use crate::contact::autodiff::{self, Scalar, Vec3};
use crate::contact::facet_shape;
use crate::contact::projection::mixed_second_derivative;
use crate::contact::MAX_FACET_NODES;
use crate::fem::FacetType;

/// `x¹ = Σ N¹_a(ζ) x¹_a`.
pub(super) fn slave_point<T: Scalar>(facet: FacetType, zeta: [f64; 2], x: &[Vec3<T>]) -> Vec3<T> {
    let s = facet_shape(facet, zeta);
    let mut p = autodiff::constant3([0.0; 3]);
    for (xa, na) in x.iter().zip(s.n) {
        p = autodiff::axpy(&p, na, xa);
    }
    p
}

/// Gap, normal, master shape values and the convected frame at the closest
/// point, in scalar type `T` (f64 or dual).
pub(super) struct Kinematics<T> {
    /// `x¹ − x²(ξ̄)` (= gN ν at the closest point).
    pub(super) separation: Vec3<T>,
    pub(super) gap: T,
    pub(super) normal: Vec3<T>,
    pub(super) master_point: Vec3<T>,
    /// `N²_b(ξ̄)` for a facet master (first `n_m` entries).
    pub(super) master_n: [T; MAX_FACET_NODES],
    pub(super) frame: Frame<T>,
}

/// How the master point moves along the surface (what friction needs).
pub(super) enum Frame<T> {
    /// Master facet: ξ̄ (dual-valued, so it carries ∂ξ̄/∂u), tangents τ_α,
    /// the projection Hessian `H = [h11, h12, h22]` and `N²_b,α(ξ̄)`.
    Facet {
        xi: [T; 2],
        tangents: [Vec3<T>; 2],
        hessian: [T; 3],
        master_dn: [[T; 2]; MAX_FACET_NODES],
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
fn facet_kinematics<T: Scalar>(
    x1: &Vec3<T>,
    facet: FacetType,
    xm: &[Vec3<T>],
    xi_bar: [f64; 2],
) -> Option<Kinematics<T>> {
    let s = facet_shape(facet, xi_bar);
    let m = mixed_second_derivative(facet);
    let zero = autodiff::constant3::<T>([0.0; 3]);
    let (mut x2, mut t1, mut t2, mut t12) = (zero, zero, zero, zero);
    for (b, xb) in xm.iter().enumerate() {
        x2 = autodiff::axpy(&x2, s.n[b], xb);
        t1 = autodiff::axpy(&t1, s.dn[b][0], xb);
        t2 = autodiff::axpy(&t2, s.dn[b][1], xb);
        t12 = autodiff::axpy(&t12, m[b], xb);
    }
    // Newton step Δ = H⁻¹ F on F_α = (x¹ − x²)·τ_α.
    let d = autodiff::sub(x1, &x2);
    let f = [autodiff::dot(&d, &t1), autodiff::dot(&d, &t2)];
    let h11 = autodiff::dot(&t1, &t1);
    let h22 = autodiff::dot(&t2, &t2);
    let h12 = autodiff::dot(&t1, &t2) - autodiff::dot(&d, &t12);
    let det = h11 * h22 - h12 * h12;
    if !(h11.re() > 0.0 && det.re() > SINGULAR * h11.re() * h22.re()) {
        return None;
    }
    let d1 = (h22 * f[0] - h12 * f[1]) / det;
    let d2 = (h11 * f[1] - h12 * f[0]) / det;
    // N is at most bilinear, so its second-order Taylor expansion about ξ̄ is
    // exact: evaluate everything at ξ̄ + Δ without generic shape functions.
    let d12 = d1 * d2;
    let x2 = autodiff::add(
        &autodiff::add(&x2, &autodiff::scale(&t1, d1)),
        &autodiff::add(&autodiff::scale(&t2, d2), &autodiff::scale(&t12, d12)),
    );
    let t1 = autodiff::add(&t1, &autodiff::scale(&t12, d2));
    let t2 = autodiff::add(&t2, &autodiff::scale(&t12, d1));
    let mut master_n = [T::from_f64(0.0); MAX_FACET_NODES];
    let mut master_dn = [[T::from_f64(0.0); 2]; MAX_FACET_NODES];
    for b in 0..xm.len() {
        master_n[b] = d1 * s.dn[b][0] + d2 * s.dn[b][1] + d12 * m[b] + s.n[b];
        master_dn[b] = [d2 * m[b] + s.dn[b][0], d1 * m[b] + s.dn[b][1]];
    }
    let normal = unit(
        &autodiff::cross(&t1, &t2),
        autodiff::norm(&t1).re() * autodiff::norm(&t2).re(),
    )?;
    let separation = autodiff::sub(x1, &x2);
    // The Hessian at ξ̄ + Δ (not ξ̄), so its derivative includes the move of ξ̄.
    let hessian = [
        autodiff::dot(&t1, &t1),
        autodiff::dot(&t1, &t2) - autodiff::dot(&separation, &t12),
        autodiff::dot(&t2, &t2),
    ];
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
pub(super) fn rigid_kinematics<T: Scalar>(
    x1: &Vec3<T>,
    master: &LinkMaster,
) -> Option<Kinematics<T>> {
    let no_nodes = [T::from_f64(0.0); MAX_FACET_NODES];
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
pub(super) fn kinematics<T: Scalar>(
    input: &LinkInput,
    slave: &[Vec3<T>],
    master: &[Vec3<T>],
    xi_bar: [f64; 2],
) -> Option<Kinematics<T>> {
    let x1 = slave_point(input.slave_facet, input.zeta, slave);
    match input.master {
        LinkMaster::Facet { facet, .. } => facet_kinematics(&x1, facet, master, xi_bar),
        _ => rigid_kinematics(&x1, &input.master),
    }
}

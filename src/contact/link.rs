//! ContactLink3D kernel: one slave quadrature point against one master
//! (deformable facet or rigid analytic surface), frictionless normal part of
//! the augmented-Lagrangian formulation of docs/formulation.md §3–§4.
//!
//! Conventions.
//! - DOFs: slave facet nodes first, then master facet nodes (none for rigid
//!   masters), node-major (`3a + i`); `n = 3 (n_s + n_m)`. `k` is row-major
//!   `n × n`, entry `row * n + col` = `∂r_row/∂u_col`.
//! - Sign: the solver's residual is `R = f_int − f_ext + r`, with
//!   `r = ∂Πc/∂u`, `Πc = (⟨λN − εN gN⟩² − λN²) / (2 εN) · w`, hence
//!   `r = −pN ∂gN/∂u · w`: slave node `a` gets `−pN N¹_a ν w`, master node
//!   `b` gets `+pN N²_b(ξ̄) ν w`. `k = ∂r/∂u` is added to the solver's `K`.
//! - `w` is a REFERENCE area weight (Gauss weight × reference Jacobian). The
//!   potential is an integral over the reference slave surface, so `w` does
//!   not depend on `u`: `r` is then exactly `∂Πc/∂u` and `k = ∂²Πc/∂u²` is
//!   symmetric. (With the current area the residual would need the
//!   derivative of the area too, and dropping it makes the tangent
//!   inconsistent and non-symmetric.) Consequently `λN` and `pN` are forces
//!   per reference area (nominal pressures).
//! - The tangent is exact: after the f64 projection, ONE Newton step on ξ is
//!   taken in dual arithmetic from the converged ξ̄; at `F(ξ̄) = 0` that step
//!   has value ξ̄ and derivative `H⁻¹ ∂F/∂u`, which is the implicit-function
//!   derivative of ξ̄. Gap, normal and forces are then evaluated in duals, so
//!   the change of ξ̄ and ν (curvature terms) is included.
//!
//! Coulomb friction (docs/formulation.md §5), when the input carries a [`Friction`]:
//! - slip increment ΔgT in the master's convected frame: `(ξ̄ − ξ̄ₙ)^α τ_α`
//!   on a facet, the tangential move of the contact point on a rigid master,
//!   or `Δt · vT` (relative tangential velocity) in dynamics;
//! - λT held fixed during Newton (covariant components `λ_α = λT·τ_α` on a
//!   facet, so a rigid rotation of the master carries it along), trial
//!   `tT* = λT + εT ΔgT`, stick if `|tT*| ≤ μ pN`, else the return map
//!   `tT = μ pN tT*/|tT*|`;
//! - virtual work `∫ tT·τ_α δξ̄^α w` (the master point's convected
//!   variation), `r_slave = N¹_a τ_β c^β w`, `r_master = (−N²_b τ_β +
//!   (x¹ − x²) N²_b,β) c^β w` with `c = H⁻¹ [tT·τ_α]`, written explicitly in
//!   the scalar type so the dual pass differentiates it exactly: the slip
//!   branch, the coupling to pN and (in dynamics) the damping term
//!   `∂r/∂v · ∂v/∂x` all land in `k`, which is then non-symmetric.
//!
//! `r` and `k` include the friction only when the link is closed.

use thiserror::Error;

use super::dual::{self, Dual, Scalar, Vec3};
use super::projection::{self, mixed_second_derivative};
use crate::fem::shape::facet_shape;
use crate::fem::{FacetType, QuadRule, MAX_FACET_NODES};

/// The master side of a link.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Master<'a> {
    /// Deformable master facet, CURRENT nodal positions (these are DOFs).
    Facet { facet: FacetType, x: &'a [[f64; 3]] },
    /// Rigid half-space, no DOFs; `normal` (any length) points out of the
    /// rigid body.
    Plane { point: [f64; 3], normal: [f64; 3] },
    /// Rigid ball; the slave is outside it.
    Sphere { centre: [f64; 3], radius: f64 },
    /// Rigid infinite cylinder (`axis` any length); the slave is outside it.
    Cylinder {
        point: [f64; 3],
        axis: [f64; 3],
        radius: f64,
    },
}

/// Where slip is measured from, and the tangential multiplier λT (held
/// fixed during Newton). The variant must match the master kind.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum SlipHistory {
    /// Deformable master: `ξ̄ₙ` on the link's facet (the master point of the
    /// last converged step) and λT's covariant components `λT·τ_α` there.
    Convected { xi_n: [f64; 2], lambda: [f64; 2] },
    /// Rigid master: the last converged contact point, moved with the
    /// master to its current placement, and λT as a vector (a rigid master
    /// only translates, so a fixed frame is its convected frame).
    Spatial { point_n: [f64; 3], lambda: [f64; 3] },
}

/// Nodal velocities for the dynamic slip rate `ΔgT = Δt · vT`. The time
/// integrator makes the velocity affine in the displacement, `v = v̄ +
/// dv_dx · (x − x̄)` about the current state, which is how the damping
/// contribution `∂r/∂v` enters the tangent.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SlipRate<'a> {
    pub slave_v: &'a [[f64; 3]],
    /// Master facet node velocities (one per master node), or one entry: the
    /// velocity of a rigid master.
    pub master_v: &'a [[f64; 3]],
    pub dt: f64,
    /// `∂v/∂u` of the integrator (`γ/(βΔt)` for Newmark).
    pub dv_dx: f64,
}

/// Coulomb friction of one link.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Friction<'a> {
    pub mu: f64,
    /// Tangential penalty εT > 0.
    pub penalty: f64,
    pub history: SlipHistory,
    /// Dynamics: slip from the relative velocity instead of `ξ̄ − ξ̄ₙ`.
    pub rate: Option<SlipRate<'a>>,
}

/// Friction values of a closed link (f64).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct FrictionState {
    /// Tangential traction on the slave per reference area (`−tT`).
    pub traction: [f64; 3],
    /// Slip increment ΔgT of the step (slave relative to master, in space).
    pub slip: [f64; 3],
    pub sliding: bool,
    /// What the Uzawa update stores: λT ← tT (same variant as the input)
    /// with the current master point as the next `ξ̄ₙ` / `point_n`.
    pub updated: SlipHistory,
}

/// Everything one link evaluation needs.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LinkInput<'a> {
    pub slave_facet: FacetType,
    /// CURRENT slave facet positions (DOFs).
    pub slave_x: &'a [[f64; 3]],
    /// Slave quadrature point in facet coordinates.
    pub zeta: [f64; 2],
    /// Reference area weight of that point (see [`reference_weights`]).
    pub weight: f64,
    pub master: Master<'a>,
    /// Start for the projection (the last ξ̄).
    pub xi_start: [f64; 2],
    /// Uzawa multiplier, fixed during Newton (≥ 0).
    pub lambda_n: f64,
    /// Penalty εN > 0.
    pub penalty: f64,
    /// Coulomb friction; `None` is frictionless (no tangential work at all).
    pub friction: Option<Friction<'a>>,
}

/// What a link evaluation reports (f64 values, no derivatives).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LinkState {
    /// `gN = (x¹ − x²)·ν`, > 0 apart. `f64::INFINITY` when there is no
    /// closest point at all (bad input, degenerate geometry); finite but
    /// not to be used when only the projection failed to converge.
    pub gap: f64,
    pub normal: [f64; 3],
    /// ξ̄ on a master facet; `[0, 0]` for rigid masters.
    pub xi: [f64; 2],
    /// `pN = ⟨λN − εN gN⟩`; 0 when the link is open or invalid. This is the
    /// value the Uzawa update stores as the new λN.
    pub pressure: f64,
    /// `λN − εN gN ≥ 0`: the link is in contact and contributes its tangent.
    /// Closed with `pN = 0` is exact touching (gN = λN/εN): no force yet,
    /// but the penalty stiffness, so a body held only by contact is not
    /// singular at first touch.
    pub closed: bool,
    pub slave_point: [f64; 3],
    pub master_point: [f64; 3],
    /// False when no valid closest point exists; `r`, `k` and `pressure` are
    /// then zero and the caller should drop the link.
    pub projection_converged: bool,
    /// How far ξ̄ lies outside the master facet (see
    /// [`projection::Projection::outside`]); 0 for rigid masters.
    pub outside: f64,
    /// Present when the input has friction and the link is closed.
    pub friction: Option<FrictionState>,
}

impl LinkState {
    /// The link without force: no usable closest point after all.
    fn dropped(self) -> Self {
        LinkState {
            projection_converged: false,
            closed: false,
            pressure: 0.0,
            friction: None,
            ..self
        }
    }

    /// "No link": far apart, no force. Finite where possible so output stays
    /// readable.
    fn invalid() -> Self {
        LinkState {
            gap: f64::INFINITY,
            normal: [0.0; 3],
            xi: [0.0; 2],
            pressure: 0.0,
            closed: false,
            slave_point: [0.0; 3],
            master_point: [0.0; 3],
            projection_converged: false,
            outside: f64::INFINITY,
            friction: None,
        }
    }
}

/// Why a [`LinkInput`] or an output buffer is unusable.
#[derive(Debug, Clone, PartialEq, Error)]
pub enum LinkError {
    #[error("{what}: expected {expected} nodes, got {got}")]
    NodeCount {
        what: &'static str,
        expected: usize,
        got: usize,
    },
    #[error("{what} contains a non-finite value")]
    NonFinite { what: &'static str },
    #[error("{what} = {value:e} out of range: must be {must}")]
    OutOfRange {
        what: &'static str,
        value: f64,
        must: &'static str,
    },
    #[error("{what}: expected length {expected}, got {got}")]
    BufferLength {
        what: &'static str,
        expected: usize,
        got: usize,
    },
}

/// Number of link DOFs `n = 3 (n_s + n_m)`.
pub fn dof_count(input: &LinkInput) -> usize {
    3 * (input.slave_facet.nodes() + master_nodes(&input.master))
}

fn master_nodes(master: &Master) -> usize {
    match master {
        Master::Facet { facet, .. } => facet.nodes(),
        _ => 0,
    }
}

fn finite(what: &'static str, v: &[f64]) -> Result<(), LinkError> {
    if v.iter().all(|c| c.is_finite()) {
        Ok(())
    } else {
        Err(LinkError::NonFinite { what })
    }
}

/// `value > 0` (`strict`) or `value >= 0`, and finite.
fn non_negative(what: &'static str, value: f64, strict: bool) -> Result<(), LinkError> {
    finite(what, &[value])?;
    let ok = if strict { value > 0.0 } else { value >= 0.0 };
    if ok {
        Ok(())
    } else {
        let must = if strict { "> 0" } else { ">= 0" };
        Err(LinkError::OutOfRange { what, value, must })
    }
}

fn facet_nodes(what: &'static str, facet: FacetType, x: &[[f64; 3]]) -> Result<(), LinkError> {
    if x.len() != facet.nodes() {
        return Err(LinkError::NodeCount {
            what,
            expected: facet.nodes(),
            got: x.len(),
        });
    }
    finite(what, x.as_flattened())
}

fn nonzero(what: &'static str, v: [f64; 3]) -> Result<(), LinkError> {
    finite(what, &v)?;
    non_negative(what, dual::norm(&v), true)
}

/// Checks everything [`evaluate`] relies on. The kernels call it themselves
/// and answer bad input with an invalid [`LinkState`]; call it directly to
/// learn what was wrong.
pub fn check_input(input: &LinkInput) -> Result<(), LinkError> {
    facet_nodes("slave_x", input.slave_facet, input.slave_x)?;
    finite("zeta", &input.zeta)?;
    non_negative("weight", input.weight, false)?;
    non_negative("lambda_n", input.lambda_n, false)?;
    non_negative("penalty", input.penalty, true)?;
    if let Some(f) = &input.friction {
        check_friction(input, f)?;
    }
    match input.master {
        Master::Facet { facet, x } => facet_nodes("master x", facet, x),
        Master::Plane { point, normal } => {
            finite("plane point", &point)?;
            nonzero("plane normal", normal)
        }
        Master::Sphere { centre, radius } => {
            finite("sphere centre", &centre)?;
            non_negative("sphere radius", radius, true)
        }
        Master::Cylinder {
            point,
            axis,
            radius,
        } => {
            finite("cylinder point", &point)?;
            nonzero("cylinder axis", axis)?;
            non_negative("cylinder radius", radius, true)
        }
    }
}

fn check_friction(input: &LinkInput, f: &Friction) -> Result<(), LinkError> {
    non_negative("friction coefficient", f.mu, false)?;
    non_negative("tangential penalty", f.penalty, true)?;
    let rigid = !matches!(input.master, Master::Facet { .. });
    match f.history {
        SlipHistory::Convected { xi_n, lambda } if !rigid => {
            finite("xi_n", &xi_n)?;
            finite("lambda_t", &lambda)?;
        }
        SlipHistory::Spatial { point_n, lambda } if rigid => {
            finite("point_n", &point_n)?;
            finite("lambda_t", &lambda)?;
        }
        _ => {
            return Err(LinkError::OutOfRange {
                what: "slip history",
                value: f64::NAN,
                must: "convected for facet masters, spatial for rigid ones",
            })
        }
    }
    if let Some(rate) = &f.rate {
        non_negative("time step", rate.dt, true)?;
        non_negative("dv_dx", rate.dv_dx, false)?;
        let expected_master = if rigid {
            1
        } else {
            master_nodes(&input.master)
        };
        for (what, v, n) in [
            ("slave velocities", rate.slave_v, input.slave_facet.nodes()),
            ("master velocities", rate.master_v, expected_master),
        ] {
            if v.len() != n {
                return Err(LinkError::NodeCount {
                    what,
                    expected: n,
                    got: v.len(),
                });
            }
            finite(what, v.as_flattened())?;
        }
    }
    Ok(())
}

/// Checks the lengths of the output buffers of [`residual_tangent`].
pub fn check_buffers(
    input: &LinkInput,
    r_len: usize,
    k_len: Option<usize>,
) -> Result<(), LinkError> {
    let n = dof_count(input);
    let length = |what, expected, got| {
        if expected == got {
            Ok(())
        } else {
            Err(LinkError::BufferLength {
                what,
                expected,
                got,
            })
        }
    };
    length("r", n, r_len)?;
    k_len.map_or(Ok(()), |len| length("k", n * n, len))
}

/// Slave quadrature points and their reference weights: Gauss weight ×
/// `|∂X/∂ζ₁ × ∂X/∂ζ₂|` on the reference (undeformed) slave facet `x_ref`.
/// Empty for bad input (wrong node count, non-finite values, malformed rule).
pub fn reference_weights(
    facet: FacetType,
    x_ref: &[[f64; 3]],
    rule: &QuadRule,
) -> Vec<([f64; 2], f64)> {
    if facet_nodes("x_ref", facet, x_ref).is_err() || rule.check().is_err() {
        return Vec::new();
    }
    rule.points
        .iter()
        .zip(&rule.weights)
        .map(|(p, w)| {
            let zeta = [p[0], p[1]];
            let s = facet_shape(facet, zeta);
            let mut t = [[0.0; 3]; 2];
            for (xa, da) in x_ref.iter().zip(&s.dn) {
                t[0] = dual::axpy(&t[0], da[0], xa);
                t[1] = dual::axpy(&t[1], da[1], xa);
            }
            (zeta, w * dual::norm(&dual::cross(&t[0], &t[1])))
        })
        .collect()
}

/// `x¹ = Σ N¹_a(ζ) x¹_a`.
fn slave_point<T: Scalar>(facet: FacetType, zeta: [f64; 2], x: &[Vec3<T>]) -> Vec3<T> {
    let s = facet_shape(facet, zeta);
    let mut p = dual::constant3([0.0; 3]);
    for (xa, na) in x.iter().zip(s.n) {
        p = dual::axpy(&p, na, xa);
    }
    p
}

/// Gap, normal, master shape values and the convected frame at the closest
/// point, in scalar type `T` (f64 or dual).
struct Kinematics<T> {
    /// `x¹ − x²(ξ̄)` (= gN ν at the closest point).
    separation: Vec3<T>,
    gap: T,
    normal: Vec3<T>,
    master_point: Vec3<T>,
    /// `N²_b(ξ̄)` for a facet master (first `n_m` entries).
    master_n: [T; MAX_FACET_NODES],
    frame: Frame<T>,
}

/// How the master point moves along the surface (what friction needs).
enum Frame<T> {
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
const SINGULAR: f64 = 1e-12;

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
    let zero = dual::constant3::<T>([0.0; 3]);
    let (mut x2, mut t1, mut t2, mut t12) = (zero, zero, zero, zero);
    for (b, xb) in xm.iter().enumerate() {
        x2 = dual::axpy(&x2, s.n[b], xb);
        t1 = dual::axpy(&t1, s.dn[b][0], xb);
        t2 = dual::axpy(&t2, s.dn[b][1], xb);
        t12 = dual::axpy(&t12, m[b], xb);
    }
    // Newton step Δ = H⁻¹ F on F_α = (x¹ − x²)·τ_α.
    let d = dual::sub(x1, &x2);
    let f = [dual::dot(&d, &t1), dual::dot(&d, &t2)];
    let h11 = dual::dot(&t1, &t1);
    let h22 = dual::dot(&t2, &t2);
    let h12 = dual::dot(&t1, &t2) - dual::dot(&d, &t12);
    let det = h11 * h22 - h12 * h12;
    if !(h11.re() > 0.0 && det.re() > SINGULAR * h11.re() * h22.re()) {
        return None;
    }
    let d1 = (h22 * f[0] - h12 * f[1]) / det;
    let d2 = (h11 * f[1] - h12 * f[0]) / det;
    // N is at most bilinear, so its second-order Taylor expansion about ξ̄ is
    // exact: evaluate everything at ξ̄ + Δ without generic shape functions.
    let d12 = d1 * d2;
    let x2 = dual::add(
        &dual::add(&x2, &dual::scale(&t1, d1)),
        &dual::add(&dual::scale(&t2, d2), &dual::scale(&t12, d12)),
    );
    let t1 = dual::add(&t1, &dual::scale(&t12, d2));
    let t2 = dual::add(&t2, &dual::scale(&t12, d1));
    let mut master_n = [T::from_f64(0.0); MAX_FACET_NODES];
    let mut master_dn = [[T::from_f64(0.0); 2]; MAX_FACET_NODES];
    for b in 0..xm.len() {
        master_n[b] = d1 * s.dn[b][0] + d2 * s.dn[b][1] + d12 * m[b] + s.n[b];
        master_dn[b] = [d2 * m[b] + s.dn[b][0], d1 * m[b] + s.dn[b][1]];
    }
    let normal = unit(
        &dual::cross(&t1, &t2),
        dual::norm(&t1).re() * dual::norm(&t2).re(),
    )?;
    let separation = dual::sub(x1, &x2);
    // The Hessian at ξ̄ + Δ (not ξ̄), so its derivative includes the move of ξ̄.
    let hessian = [
        dual::dot(&t1, &t1),
        dual::dot(&t1, &t2) - dual::dot(&separation, &t12),
        dual::dot(&t2, &t2),
    ];
    Some(Kinematics {
        gap: dual::dot(&separation, &normal),
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
    let len = dual::norm(v);
    (len.re() > SINGULAR * scale && len.re() > 0.0).then(|| dual::scale(v, len.recip()))
}

fn unit_f64(v: [f64; 3]) -> [f64; 3] {
    let len = dual::norm(&v);
    v.map(|c| c / len)
}

/// Closest point on a rigid master, in `T`. `None` where the normal is
/// undefined (slave point at the sphere centre / on the cylinder axis).
fn rigid_kinematics<T: Scalar>(x1: &Vec3<T>, master: &Master) -> Option<Kinematics<T>> {
    let no_nodes = [T::from_f64(0.0); MAX_FACET_NODES];
    let one = T::from_f64(1.0);
    let (normal, gap, master_point, scale, axis) = match *master {
        Master::Plane { point, normal } => {
            let n = dual::constant3::<T>(unit_f64(normal));
            let gap = dual::dot(&dual::sub(x1, &dual::constant3(point)), &n);
            let foot = dual::sub(x1, &dual::scale(&n, gap));
            (n, gap, foot, one, None)
        }
        Master::Sphere { centre, radius } => {
            let c = dual::constant3::<T>(centre);
            let n = unit(&dual::sub(x1, &c), radius)?;
            let dist = dual::dot(&dual::sub(x1, &c), &n);
            let foot = dual::add(&c, &dual::scale_f64(&n, radius));
            (n, dist - radius, foot, dist.recip() * radius, None)
        }
        Master::Cylinder {
            point,
            axis,
            radius,
        } => {
            let a_f = unit_f64(axis);
            let a = dual::constant3::<T>(a_f);
            let d = dual::sub(x1, &dual::constant3(point));
            let along = dual::scale(&a, dual::dot(&d, &a));
            let n = unit(&dual::sub(&d, &along), radius)?;
            let dist = dual::dot(&dual::sub(&d, &along), &n);
            let base = dual::add(&dual::constant3(point), &along);
            let foot = dual::add(&base, &dual::scale_f64(&n, radius));
            (n, dist - radius, foot, dist.recip() * radius, Some(a_f))
        }
        Master::Facet { .. } => return None,
    };
    Some(Kinematics {
        separation: dual::sub(x1, &master_point),
        gap,
        normal,
        master_point,
        master_n: no_nodes,
        frame: Frame::Rigid { scale, axis },
    })
}

/// `pN = λN − εN gN` on the closed branch (the caller has decided it is
/// closed from the f64 gap).
fn closed_pressure<T: Scalar>(input: &LinkInput, gap: T) -> T {
    -(gap * input.penalty) + input.lambda_n
}

/// `v − ν (ν·v)`.
fn tangential<T: Scalar>(v: &Vec3<T>, normal: &Vec3<T>) -> Vec3<T> {
    dual::sub(v, &dual::scale(normal, dual::dot(normal, v)))
}

/// `Σ N_a (v̄_a + dv_dx (x_a − x̄_a))`: the integrator's velocity, affine in
/// the positions, interpolated with shape values `n`.
fn interpolated_velocity<T: Scalar>(n: &[T], x: &[Vec3<T>], v: &[[f64; 3]], dv_dx: f64) -> Vec3<T> {
    let mut out = dual::constant3::<T>([0.0; 3]);
    for ((na, xa), va) in n.iter().zip(x).zip(v) {
        for i in 0..3 {
            out[i] = out[i] + *na * ((xa[i] - xa[i].re()) * dv_dx + va[i]);
        }
    }
    out
}

/// Slip increment ΔgT of the slave relative to the master.
fn slip_increment<T: Scalar>(
    input: &LinkInput,
    friction: &Friction,
    kin: &Kinematics<T>,
    slave: &[Vec3<T>],
    master: &[Vec3<T>],
) -> Vec3<T> {
    if let Some(rate) = &friction.rate {
        let s = facet_shape(input.slave_facet, input.zeta);
        let n_slave = s.n.map(T::from_f64);
        let v1 = interpolated_velocity(&n_slave[..slave.len()], slave, rate.slave_v, rate.dv_dx);
        let v2 = match kin.frame {
            Frame::Facet { .. } => interpolated_velocity(
                &kin.master_n[..master.len()],
                master,
                rate.master_v,
                rate.dv_dx,
            ),
            Frame::Rigid { .. } => dual::constant3(rate.master_v[0]),
        };
        return dual::scale_f64(&tangential(&dual::sub(&v1, &v2), &kin.normal), rate.dt);
    }
    match (&kin.frame, friction.history) {
        (Frame::Facet { xi, tangents, .. }, SlipHistory::Convected { xi_n, .. }) => dual::add(
            &dual::scale(&tangents[0], xi[0] - xi_n[0]),
            &dual::scale(&tangents[1], xi[1] - xi_n[1]),
        ),
        (Frame::Rigid { .. }, SlipHistory::Spatial { point_n, .. }) => tangential(
            &dual::sub(&kin.master_point, &dual::constant3(point_n)),
            &kin.normal,
        ),
        // `check_input` rejects a history that does not match the master.
        _ => dual::constant3([0.0; 3]),
    }
}

/// λT as a vector in the current tangent plane.
fn multiplier_vector<T: Scalar>(history: SlipHistory, kin: &Kinematics<T>) -> Vec3<T> {
    match (&kin.frame, history) {
        (
            Frame::Facet {
                tangents: [t1, t2], ..
            },
            SlipHistory::Convected { lambda, .. },
        ) => {
            // Contravariant basis m^α = M^{αβ} τ_β, so that λT·τ_α = λ_α.
            let (m11, m12, m22) = (dual::dot(t1, t1), dual::dot(t1, t2), dual::dot(t2, t2));
            let det = m11 * m22 - m12 * m12;
            let c1 = (m22 * lambda[0] - m12 * lambda[1]) / det;
            let c2 = (m11 * lambda[1] - m12 * lambda[0]) / det;
            dual::add(&dual::scale(t1, c1), &dual::scale(t2, c2))
        }
        (_, SlipHistory::Spatial { lambda, .. }) => {
            tangential(&dual::constant3(lambda), &kin.normal)
        }
        _ => dual::constant3([0.0; 3]),
    }
}

/// The friction law at one link: trial, stick/slip decision (on the f64
/// value) and return map. Returns `tT` (the traction resisting the slip).
fn friction_traction<T: Scalar>(
    friction: &Friction,
    kin: &Kinematics<T>,
    pressure: T,
    slip: &Vec3<T>,
) -> (Vec3<T>, bool) {
    let lambda = multiplier_vector(friction.history, kin);
    let trial = dual::add(&lambda, &dual::scale_f64(slip, friction.penalty));
    let size = dual::norm(&trial);
    let limit = pressure * friction.mu;
    if size.re() > limit.re() && size.re() > 0.0 {
        (dual::scale(&trial, limit / size), true)
    } else {
        (trial, false)
    }
}

/// The contact forces of one link (normal, plus friction when the input has
/// it), handed to `emit(dof, value)` once per DOF. Slave node `a` gets
/// `N¹_a (g − pN ν) w`; master node `b` gets `(pN ν − g) N²_b w + (x¹ − x²)
/// c^α N²_b,α w`, where `g = τ_α c^α` (facet) or `Jᵀ tT` (rigid) is the
/// friction's generalized force and `c = H⁻¹ [tT·τ_α]`.
fn link_forces<T: Scalar>(
    input: &LinkInput,
    kin: &Kinematics<T>,
    slave: &[Vec3<T>],
    master: &[Vec3<T>],
    mut emit: impl FnMut(usize, T),
) -> Option<FrictionState> {
    let s = facet_shape(input.slave_facet, input.zeta);
    let ns = input.slave_facet.nodes();
    let n_master = master.len();
    let pressure = closed_pressure(input, kin.gap);
    let mut common = dual::scale(&kin.normal, -pressure);
    let mut master_extra = [T::from_f64(0.0); MAX_FACET_NODES];
    let mut state = None;
    if let Some(friction) = &input.friction {
        let slip = slip_increment(input, friction, kin, slave, master);
        let (traction, sliding) = friction_traction(friction, kin, pressure, &slip);
        let (g, updated) = match &kin.frame {
            Frame::Facet {
                xi,
                tangents: [t1, t2],
                hessian: [h11, h12, h22],
                master_dn,
            } => {
                let t = [dual::dot(&traction, t1), dual::dot(&traction, t2)];
                let det = *h11 * *h22 - *h12 * *h12;
                let c1 = (*h22 * t[0] - *h12 * t[1]) / det;
                let c2 = (*h11 * t[1] - *h12 * t[0]) / det;
                for (extra, dn) in master_extra.iter_mut().zip(master_dn).take(n_master) {
                    *extra = c1 * dn[0] + c2 * dn[1];
                }
                let g = dual::add(&dual::scale(t1, c1), &dual::scale(t2, c2));
                let updated = SlipHistory::Convected {
                    xi_n: [xi[0].re(), xi[1].re()],
                    lambda: [t[0].re(), t[1].re()],
                };
                (g, updated)
            }
            Frame::Rigid { scale, axis } => {
                let along = match axis {
                    Some(a) => {
                        let a = dual::constant3::<T>(*a);
                        dual::scale(&a, dual::dot(&a, &traction))
                    }
                    None => dual::constant3([0.0; 3]),
                };
                let across = tangential(&dual::sub(&traction, &along), &kin.normal);
                let g = dual::add(&along, &dual::scale(&across, *scale));
                let updated = SlipHistory::Spatial {
                    point_n: dual::re3(&kin.master_point),
                    lambda: dual::re3(&traction),
                };
                (g, updated)
            }
        };
        common = dual::add(&common, &g);
        state = Some(FrictionState {
            traction: dual::re3(&traction).map(|v| -v),
            slip: dual::re3(&slip),
            sliding,
            updated,
        });
    }
    let common = dual::scale_f64(&common, input.weight);
    for a in 0..ns {
        for (i, ci) in common.iter().enumerate() {
            emit(3 * a + i, *ci * s.n[a]);
        }
    }
    for (b, (extra_b, n_b)) in master_extra
        .iter()
        .zip(&kin.master_n)
        .take(n_master)
        .enumerate()
    {
        for (i, (sep, c)) in kin.separation.iter().zip(&common).enumerate() {
            let extra = *sep * *extra_b * input.weight;
            emit(3 * (ns + b) + i, extra - *c * *n_b);
        }
    }
    state
}

/// Kinematics for either master kind, with slave and master nodal
/// positions already in `T`.
fn kinematics<T: Scalar>(
    input: &LinkInput,
    slave: &[Vec3<T>],
    master: &[Vec3<T>],
    xi_bar: [f64; 2],
) -> Option<Kinematics<T>> {
    let x1 = slave_point(input.slave_facet, input.zeta, slave);
    match input.master {
        Master::Facet { facet, .. } => facet_kinematics(&x1, facet, master, xi_bar),
        _ => rigid_kinematics(&x1, &input.master),
    }
}

fn nodes_as<T: Scalar>(x: &[[f64; 3]]) -> [Vec3<T>; MAX_FACET_NODES] {
    let mut out = [dual::constant3([0.0; 3]); MAX_FACET_NODES];
    for (o, p) in out.iter_mut().zip(x) {
        *o = dual::constant3(*p);
    }
    out
}

/// Nodal positions as dual variables, variable index `offset + 3a + i`.
fn seed<const N: usize>(x: &[[f64; 3]], offset: usize) -> [Vec3<Dual<N>>; MAX_FACET_NODES] {
    let mut out = [[Dual::constant(0.0); 3]; MAX_FACET_NODES];
    for (a, (o, p)) in out.iter_mut().zip(x).enumerate() {
        for (i, (oi, pi)) in o.iter_mut().zip(p).enumerate() {
            *oi = Dual::variable(*pi, offset + 3 * a + i);
        }
    }
    out
}

fn master_x<'a>(input: &LinkInput<'a>) -> &'a [[f64; 3]] {
    match input.master {
        Master::Facet { x, .. } => x,
        _ => &[],
    }
}

/// Residual only (f64 path; the Newton step is then a harmless polish).
/// `None` where the kernel has no usable closest point.
fn residual_f64(
    input: &LinkInput,
    xi_bar: [f64; 2],
    r: &mut [f64],
) -> Option<Option<FrictionState>> {
    let ns = input.slave_facet.nodes();
    let xm = master_x(input);
    let slave = nodes_as::<f64>(input.slave_x);
    let master = nodes_as::<f64>(xm);
    let kin = kinematics(input, &slave[..ns], &master[..xm.len()], xi_bar)?;
    Some(link_forces(
        input,
        &kin,
        &slave[..ns],
        &master[..xm.len()],
        |dof, v| {
            if let Some(ri) = r.get_mut(dof) {
                *ri = v;
            }
        },
    ))
}

/// Residual and tangent with `N` = number of link DOFs.
fn residual_dual<const N: usize>(
    input: &LinkInput,
    xi_bar: [f64; 2],
    r: &mut [f64],
    k: &mut [f64],
) -> Option<Option<FrictionState>> {
    let ns = input.slave_facet.nodes();
    let xm = master_x(input);
    let slave = seed::<N>(input.slave_x, 0);
    let master = seed::<N>(xm, 3 * ns);
    let kin = kinematics(input, &slave[..ns], &master[..xm.len()], xi_bar)?;
    Some(link_forces(
        input,
        &kin,
        &slave[..ns],
        &master[..xm.len()],
        |dof, v: Dual<N>| {
            if let Some(ri) = r.get_mut(dof) {
                *ri = v.re;
            }
            if let Some(row) = k.get_mut(dof * N..(dof + 1) * N) {
                row.copy_from_slice(&v.eps);
            }
        },
    ))
}
/// Monomorphised for the possible link sizes so the dual arrays are exactly
/// as long as needed: quad–quad 24, quad–tri 21, tri–tri 18, rigid 12 / 9.
fn residual_tangent_sized(
    input: &LinkInput,
    xi_bar: [f64; 2],
    r: &mut [f64],
    k: &mut [f64],
) -> Option<Option<FrictionState>> {
    match dof_count(input) {
        24 => residual_dual::<24>(input, xi_bar, r, k),
        21 => residual_dual::<21>(input, xi_bar, r, k),
        18 => residual_dual::<18>(input, xi_bar, r, k),
        12 => residual_dual::<12>(input, xi_bar, r, k),
        9 => residual_dual::<9>(input, xi_bar, r, k),
        _ => None,
    }
}

/// Gap, normal, pressure and closest point in f64, without derivatives (for
/// the Uzawa update and output). Bad input or a failed projection gives
/// `projection_converged = false`, `pressure = 0`.
pub fn evaluate(input: &LinkInput) -> LinkState {
    let mut state = evaluate_normal(input);
    if state.closed && input.friction.is_some() {
        // The friction state comes from the kernel's own kinematics, so the
        // stick/slip decision here is the one the residual makes.
        match residual_f64(input, state.xi, &mut []) {
            Some(friction) => state.friction = friction,
            None => state = state.dropped(),
        }
    }
    state
}

/// Gap, normal, pressure and open/closed, without the friction state.
fn evaluate_normal(input: &LinkInput) -> LinkState {
    if check_input(input).is_err() {
        return LinkState::invalid();
    }
    let slave = nodes_as::<f64>(input.slave_x);
    let x1 = slave_point(
        input.slave_facet,
        input.zeta,
        &slave[..input.slave_facet.nodes()],
    );
    let mut state = match input.master {
        Master::Facet { facet, x } => {
            let p = projection::project(facet, x, x1, Some(input.xi_start));
            LinkState {
                gap: p.gap,
                normal: p.normal,
                xi: p.xi,
                pressure: 0.0,
                closed: false,
                slave_point: x1,
                master_point: p.point,
                projection_converged: p.converged,
                outside: p.outside,
                friction: None,
            }
        }
        _ => match rigid_kinematics::<f64>(&x1, &input.master) {
            Some(kin) => LinkState {
                gap: kin.gap,
                normal: kin.normal,
                xi: [0.0; 2],
                pressure: 0.0,
                closed: false,
                slave_point: x1,
                master_point: kin.master_point,
                projection_converged: true,
                outside: 0.0,
                friction: None,
            },
            None => LinkState {
                slave_point: x1,
                ..LinkState::invalid()
            },
        },
    };
    if state.projection_converged {
        let p = input.lambda_n - input.penalty * state.gap;
        state.closed = p >= 0.0;
        state.pressure = p.max(0.0);
    }
    state
}

/// The link potential `Πc = (pN² − λN²)/(2 εN) · w` (0 for bad input). Not
/// needed by Newton; it is what `r` is the gradient of, for line searches
/// and consistency checks.
pub fn potential(input: &LinkInput) -> f64 {
    if check_input(input).is_err() {
        return 0.0;
    }
    let p = evaluate(input).pressure;
    (p * p - input.lambda_n * input.lambda_n) / (2.0 * input.penalty) * input.weight
}

/// Contact residual `r` (length `n`, overwritten) and, if `k` is given, its
/// exact derivative `k = ∂r/∂u` (length `n²`, row-major, overwritten). Open
/// or invalid links (and wrong buffer lengths) leave both exactly zero.
/// Never allocates.
pub fn residual_tangent(input: &LinkInput, r: &mut [f64], mut k: Option<&mut [f64]>) -> LinkState {
    r.fill(0.0);
    if let Some(k) = k.as_deref_mut() {
        k.fill(0.0);
    }
    let k_len = k.as_deref().map(<[f64]>::len);
    if check_input(input).is_err() || check_buffers(input, r.len(), k_len).is_err() {
        return LinkState::invalid();
    }
    let state = evaluate_normal(input);
    // Cheap exit: the f64 gap decides open/closed before any dual work.
    if !state.closed {
        return state;
    }
    let forces = match k.as_deref_mut() {
        Some(k) => residual_tangent_sized(input, state.xi, r, k),
        None => residual_f64(input, state.xi, r),
    };
    match forces {
        // The friction state of the same pass that formed the forces.
        Some(friction) => LinkState { friction, ..state },
        None => {
            // The closest point has no usable Hessian or normal in the
            // kernel's own evaluation: drop the link rather than return a
            // wrong tangent.
            r.fill(0.0);
            if let Some(k) = k {
                k.fill(0.0);
            }
            state.dropped()
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::fem::test_util::{rel_err, Lcg};

    /// Owned counterpart of [`Master`], so test cases can be perturbed.
    #[derive(Clone)]
    enum OwnedMaster {
        Facet(FacetType, Vec<[f64; 3]>),
        Rigid(Master<'static>),
    }

    #[derive(Clone)]
    struct Case {
        slave_facet: FacetType,
        slave_x: Vec<[f64; 3]>,
        zeta: [f64; 2],
        weight: f64,
        master: OwnedMaster,
        lambda_n: f64,
        penalty: f64,
        friction: Option<CaseFriction>,
    }

    /// (slave v, master v, Δt, dv/dx).
    type CaseRate = (Vec<[f64; 3]>, Vec<[f64; 3]>, f64, f64);

    /// Owned counterpart of [`Friction`].
    #[derive(Clone)]
    struct CaseFriction {
        mu: f64,
        penalty: f64,
        history: SlipHistory,
        rate: Option<CaseRate>,
    }

    impl Case {
        fn input(&self) -> LinkInput<'_> {
            let master = match &self.master {
                OwnedMaster::Facet(facet, x) => Master::Facet { facet: *facet, x },
                OwnedMaster::Rigid(m) => *m,
            };
            let xi_start = match &self.master {
                OwnedMaster::Facet(f, _) => projection::reference_centre(*f),
                OwnedMaster::Rigid(_) => [0.0; 2],
            };
            LinkInput {
                slave_facet: self.slave_facet,
                slave_x: &self.slave_x,
                zeta: self.zeta,
                weight: self.weight,
                master,
                xi_start,
                lambda_n: self.lambda_n,
                penalty: self.penalty,
                friction: self.friction.as_ref().map(|f| Friction {
                    mu: f.mu,
                    penalty: f.penalty,
                    history: f.history,
                    rate: f.rate.as_ref().map(|(vs, vm, dt, c)| SlipRate {
                        slave_v: vs,
                        master_v: vm,
                        dt: *dt,
                        dv_dx: *c,
                    }),
                }),
            }
        }

        fn n(&self) -> usize {
            dof_count(&self.input())
        }

        /// All nodal positions in DOF order (slave, then master).
        fn nodes(&self) -> Vec<[f64; 3]> {
            let mut v = self.slave_x.clone();
            if let OwnedMaster::Facet(_, x) = &self.master {
                v.extend_from_slice(x);
            }
            v
        }

        fn shifted(&self, dof: usize, h: f64) -> Case {
            let mut c = self.clone();
            let (node, i) = (dof / 3, dof % 3);
            let ns = c.slave_x.len();
            if node < ns {
                c.slave_x[node][i] += h;
            } else if let OwnedMaster::Facet(_, x) = &mut c.master {
                x[node - ns][i] += h;
            }
            // The integrator's velocity moves with the position.
            if let Some((vs, vm, _, dv_dx)) = c.friction.as_mut().and_then(|f| f.rate.as_mut()) {
                if node < ns {
                    vs[node][i] += *dv_dx * h;
                } else if let Some(v) = vm.get_mut(node - ns) {
                    if matches!(self.master, OwnedMaster::Facet(..)) {
                        v[i] += *dv_dx * h;
                    }
                }
            }
            c
        }

        fn translated(&self, t: [f64; 3]) -> Case {
            let mut c = self.clone();
            let shift = |p: &mut [f64; 3]| *p = dual::add(p, &t);
            c.slave_x.iter_mut().for_each(shift);
            if let OwnedMaster::Facet(_, x) = &mut c.master {
                x.iter_mut().for_each(shift);
            }
            c
        }

        fn residual(&self) -> Vec<f64> {
            let mut r = vec![0.0; self.n()];
            residual_tangent(&self.input(), &mut r, None);
            r
        }

        fn residual_and_tangent(&self) -> (Vec<f64>, Vec<f64>, LinkState) {
            let n = self.n();
            let (mut r, mut k) = (vec![0.0; n], vec![0.0; n * n]);
            let state = residual_tangent(&self.input(), &mut r, Some(&mut k));
            (r, k, state)
        }
    }

    const H: f64 = 1e-6;

    fn fd_gradient_of_potential(c: &Case) -> Vec<f64> {
        (0..c.n())
            .map(|j| {
                let p = potential(&c.shifted(j, H).input());
                let m = potential(&c.shifted(j, -H).input());
                (p - m) / (2.0 * H)
            })
            .collect()
    }

    /// Row-major n×n with column j = central difference of r along DOF j.
    fn fd_tangent(c: &Case) -> Vec<f64> {
        let n = c.n();
        let mut k = vec![0.0; n * n];
        for j in 0..n {
            let (p, m) = (c.shifted(j, H).residual(), c.shifted(j, -H).residual());
            for i in 0..n {
                k[i * n + j] = (p[i] - m[i]) / (2.0 * H);
            }
        }
        k
    }

    fn asymmetry(k: &[f64], n: usize) -> f64 {
        let scale = k.iter().fold(0.0f64, |m, v| m.max(v.abs()));
        let mut worst = 0.0f64;
        for i in 0..n {
            for j in 0..n {
                worst = worst.max((k[i * n + j] - k[j * n + i]).abs());
            }
        }
        worst / scale
    }

    fn random_zeta(facet: FacetType, rng: &mut Lcg) -> [f64; 2] {
        match facet {
            FacetType::Quad4 => [0.9 * rng.next(), 0.9 * rng.next()],
            FacetType::Tri3 => {
                let (a, b) = (0.5 * (rng.next() + 1.0), 0.5 * (rng.next() + 1.0));
                if a + b < 1.0 {
                    [a, b]
                } else {
                    [1.0 - a, 1.0 - b]
                }
            }
        }
    }

    fn perturbed(base: &[[f64; 2]], z: f64, amp: f64, rng: &mut Lcg) -> Vec<[f64; 3]> {
        base.iter()
            .map(|p| dual::add(&[p[0], p[1], z], &rng.vec3(amp)))
            .collect()
    }

    /// Slave facet around z = z0, oriented with its outward normal −z (its
    /// body is above), arbitrarily deformed.
    fn slave_nodes(facet: FacetType, z0: f64, rng: &mut Lcg) -> Vec<[f64; 3]> {
        let base: &[[f64; 2]] = match facet {
            FacetType::Quad4 => &[[-0.4, -0.4], [-0.4, 0.4], [0.4, 0.4], [0.4, -0.4]],
            FacetType::Tri3 => &[[-0.4, -0.4], [-0.2, 0.4], [0.4, -0.1]],
        };
        perturbed(base, z0, 0.08, rng)
    }

    /// Warped master facet around z = 0, outward normal +z.
    fn master_nodes(facet: FacetType, rng: &mut Lcg) -> Vec<[f64; 3]> {
        let base: &[[f64; 2]] = match facet {
            FacetType::Quad4 => &[[-1.0, -1.0], [1.0, -1.0], [1.0, 1.0], [-1.0, 1.0]],
            FacetType::Tri3 => &[[-1.0, -1.0], [1.6, -0.8], [-0.6, 1.6]],
        };
        let mut x = perturbed(base, 0.0, 0.1, rng);
        for p in &mut x {
            p[2] += 0.1 * rng.next();
        }
        x
    }

    fn rigid_masters() -> [Master<'static>; 3] {
        [
            Master::Plane {
                point: [0.05, -0.02, 0.01],
                normal: [0.1, -0.15, 2.0],
            },
            Master::Sphere {
                centre: [0.1, 0.05, -1.3],
                radius: 1.3,
            },
            Master::Cylinder {
                point: [0.0, 0.0, -1.3],
                axis: [1.0, 0.2, 0.1],
                radius: 1.3,
            },
        ]
    }

    /// A random closed link (pN ≥ 0.05, away from the kink at pN = 0): the
    /// slave point penetrates or lies slightly apart with λN large enough.
    fn random_case(
        slave: FacetType,
        master: Option<FacetType>,
        rigid: usize,
        rng: &mut Lcg,
    ) -> Case {
        loop {
            let master = match master {
                Some(f) => OwnedMaster::Facet(f, master_nodes(f, rng)),
                None => OwnedMaster::Rigid(rigid_masters()[rigid]),
            };
            let case = Case {
                slave_facet: slave,
                slave_x: slave_nodes(slave, 0.05 * rng.next() - 0.03, rng),
                zeta: random_zeta(slave, rng),
                weight: 0.3 + 0.2 * rng.next(),
                master,
                lambda_n: 0.5 * (rng.next() + 1.0),
                penalty: 20.0,
                friction: None,
            };
            let s = evaluate(&case.input());
            if s.projection_converged && s.pressure > 0.05 && s.outside < 0.5 {
                return case;
            }
        }
    }

    /// Every facet pairing and every rigid master, a few random cases each.
    fn all_cases() -> Vec<(String, Case)> {
        let mut rng = Lcg::new(42);
        let facets = [FacetType::Quad4, FacetType::Tri3];
        let mut out = Vec::new();
        for _ in 0..4 {
            for s in facets {
                for m in facets {
                    let name = format!("{}-{}", s.name(), m.name());
                    out.push((name, random_case(s, Some(m), 0, &mut rng)));
                }
                for (i, kind) in ["plane", "sphere", "cylinder"].iter().enumerate() {
                    let name = format!("{}-{kind}", s.name());
                    out.push((name, random_case(s, None, i, &mut rng)));
                }
            }
        }
        out
    }

    /// Runs `measure` on every case, asserts `< limit`, and prints the
    /// worst value per pairing (run with --nocapture to see them).
    fn check_all(what: &str, limit: f64, measure: impl Fn(&Case) -> f64) {
        let mut worst = std::collections::BTreeMap::<String, f64>::new();
        for (name, case) in all_cases() {
            let err = measure(&case);
            assert!(err < limit, "{name}: {what} = {err:e}");
            let w = worst.entry(name).or_insert(0.0);
            *w = w.max(err);
        }
        for (name, err) in worst {
            println!("{what:>22} {name:>15}: {err:.1e}");
        }
    }

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
                force = dual::add(&force, &f);
                moment = dual::add(&moment, &dual::cross(x, &f));
            }
            let size = case
                .nodes()
                .iter()
                .fold(0.0f64, |m, x| m.max(dual::norm(x)));
            assert!(
                dual::norm(&force) < 1e-14 * scale,
                "{name}: force {force:?}"
            );
            assert!(
                dual::norm(&moment) < 1e-14 * scale * size,
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
        master: Master,
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
            };
            let mut r = vec![0.0; dof_count(&input)];
            let s = residual_tangent(&input, &mut r, None);
            assert!(s.projection_converged && s.pressure > 0.0);
            let ns = slave.nodes();
            for (a, f) in r.chunks_exact(3).enumerate() {
                let target = if a < ns { &mut fs } else { &mut fm };
                *target = dual::add(target, &[f[0], f[1], f[2]]);
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
            Master::Facet {
                facet: FacetType::Quad4,
                x: &master_x,
            },
            Master::Plane {
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
                if matches!(master, Master::Facet { .. }) {
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
            Master::Plane {
                point: [0.0; 3],
                normal: [0.0; 3],
            },
            Master::Sphere {
                centre: [0.0; 3],
                radius: 0.0,
            },
            Master::Sphere {
                centre: [0.0; 3],
                radius: 1.0,
            },
            Master::Cylinder {
                point: [0.0; 3],
                axis: [0.0, 1.0, 0.0],
                radius: 1.0,
            },
            Master::Cylinder {
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
            master: Master::Sphere {
                centre: [0.0; 3],
                radius: 1.0,
            },
            xi_start: [0.0; 2],
            lambda_n: 0.0,
            penalty: 10.0,
            friction: None,
        };
        let s = evaluate(&input);
        assert!((s.gap + 0.1).abs() < 1e-15);
        assert!((s.pressure - 1.0).abs() < 1e-14);
        assert_eq!(s.master_point, [0.0, 0.0, 1.0]);
        assert!((potential(&input) - 1.0 / 20.0 * 2.0).abs() < 1e-15);
    }

    /// Adds friction to a closed case: a slip history a little away from the
    /// current master point, a λT, and μ chosen so that `|tT*| = ratio · μ pN`
    /// (ratio < 1 sticks, > 1 slips; far from the kink either way).
    fn with_friction(case: &Case, ratio: f64, dynamic: bool, rng: &mut Lcg) -> Case {
        let mut c = case.clone();
        let s = evaluate(&c.input());
        let history = match &c.master {
            OwnedMaster::Facet(..) => SlipHistory::Convected {
                xi_n: [s.xi[0] - 0.05 * rng.next(), s.xi[1] + 0.05 * rng.next()],
                lambda: [0.1 * rng.next(), 0.1 * rng.next()],
            },
            OwnedMaster::Rigid(_) => SlipHistory::Spatial {
                point_n: dual::add(&s.master_point, &rng.vec3(0.05)),
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
        let trial = dual::norm(&evaluate(&c.input()).friction.unwrap().traction);
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
            let t = dual::norm(&f.traction);
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
                .fold([0.0; 3], |f, v| dual::add(&f, &[v[0], v[1], v[2]]));
            assert!(dual::norm(&force) < 1e-13 * scale, "{name}: {force:?}");
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
                Master::Facet {
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
                Master::Plane {
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
}

//! ContactLink3D kernel: one slave quadrature point against one master
//! (deformable facet or rigid analytic surface), frictionless normal part of
//! the augmented-Lagrangian formulation of DESIGN.md §3.
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
//! Friction (DESIGN.md §4) will add a tangential traction to the same force
//! loop (`normal_forces` is the only place forces are formed) and needs the
//! dual-valued ξ and tangents that `facet_kinematics` already computes.

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
    pub slave_point: [f64; 3],
    pub master_point: [f64; 3],
    /// False when no valid closest point exists; `r`, `k` and `pressure` are
    /// then zero and the caller should drop the link.
    pub projection_converged: bool,
    /// How far ξ̄ lies outside the master facet (see
    /// [`projection::Projection::outside`]); 0 for rigid masters.
    pub outside: f64,
}

impl LinkState {
    /// "No link": far apart, no force. Finite where possible so output stays
    /// readable.
    fn invalid() -> Self {
        LinkState {
            gap: f64::INFINITY,
            normal: [0.0; 3],
            xi: [0.0; 2],
            pressure: 0.0,
            slave_point: [0.0; 3],
            master_point: [0.0; 3],
            projection_converged: false,
            outside: f64::INFINITY,
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

/// Normal gap, normal and master shape values at the closest point, in
/// scalar type `T` (f64 or dual).
struct Kinematics<T> {
    gap: T,
    normal: Vec3<T>,
    master_point: Vec3<T>,
    /// `N²_b(ξ̄)` for a facet master (first `n_m` entries).
    master_n: [T; MAX_FACET_NODES],
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
    for (b, nb) in master_n.iter_mut().enumerate().take(xm.len()) {
        *nb = d1 * s.dn[b][0] + d2 * s.dn[b][1] + d12 * m[b] + s.n[b];
    }
    let normal = unit(
        &dual::cross(&t1, &t2),
        dual::norm(&t1).re() * dual::norm(&t2).re(),
    )?;
    Some(Kinematics {
        gap: dual::dot(&dual::sub(x1, &x2), &normal),
        normal,
        master_point: x2,
        master_n,
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
    let (normal, gap, master_point) = match *master {
        Master::Plane { point, normal } => {
            let n = dual::constant3::<T>(unit_f64(normal));
            let gap = dual::dot(&dual::sub(x1, &dual::constant3(point)), &n);
            let foot = dual::sub(x1, &dual::scale(&n, gap));
            (n, gap, foot)
        }
        Master::Sphere { centre, radius } => {
            let c = dual::constant3::<T>(centre);
            let n = unit(&dual::sub(x1, &c), radius)?;
            let gap = dual::dot(&dual::sub(x1, &c), &n) - radius;
            (n, gap, dual::add(&c, &dual::scale_f64(&n, radius)))
        }
        Master::Cylinder {
            point,
            axis,
            radius,
        } => {
            let a = dual::constant3::<T>(unit_f64(axis));
            let d = dual::sub(x1, &dual::constant3(point));
            let along = dual::scale(&a, dual::dot(&d, &a));
            let n = unit(&dual::sub(&d, &along), radius)?;
            let gap = dual::dot(&dual::sub(&d, &along), &n) - radius;
            let base = dual::add(&dual::constant3(point), &along);
            (n, gap, dual::add(&base, &dual::scale_f64(&n, radius)))
        }
        Master::Facet { .. } => return None,
    };
    Some(Kinematics {
        gap,
        normal,
        master_point,
        master_n: no_nodes,
    })
}

/// `pN = λN − εN gN` on the closed branch (the caller has decided it is
/// closed from the f64 gap).
fn closed_pressure<T: Scalar>(input: &LinkInput, gap: T) -> T {
    -(gap * input.penalty) + input.lambda_n
}

/// The normal contact forces `r = −pN ∂gN/∂u · w`, handed to `emit(dof,
/// value)`: slave `−pN N¹_a ν w`, master `+pN N²_b ν w`.
fn normal_forces<T: Scalar>(
    input: &LinkInput,
    kin: &Kinematics<T>,
    n_master: usize,
    mut emit: impl FnMut(usize, T),
) {
    let s = facet_shape(input.slave_facet, input.zeta);
    let ns = input.slave_facet.nodes();
    let force = dual::scale(&kin.normal, closed_pressure(input, kin.gap) * input.weight);
    for a in 0..ns {
        for (i, fi) in force.iter().enumerate() {
            emit(3 * a + i, -(*fi * s.n[a]));
        }
    }
    for b in 0..n_master {
        for (i, fi) in force.iter().enumerate() {
            emit(3 * (ns + b) + i, *fi * kin.master_n[b]);
        }
    }
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
fn residual_f64(input: &LinkInput, xi_bar: [f64; 2], r: &mut [f64]) -> bool {
    let ns = input.slave_facet.nodes();
    let xm = master_x(input);
    let slave = nodes_as::<f64>(input.slave_x);
    let master = nodes_as::<f64>(xm);
    let Some(kin) = kinematics(input, &slave[..ns], &master[..xm.len()], xi_bar) else {
        return false;
    };
    normal_forces(input, &kin, xm.len(), |dof, v| {
        if let Some(ri) = r.get_mut(dof) {
            *ri = v;
        }
    });
    true
}

/// Residual and tangent with `N` = number of link DOFs.
fn residual_dual<const N: usize>(
    input: &LinkInput,
    xi_bar: [f64; 2],
    r: &mut [f64],
    k: &mut [f64],
) -> bool {
    let ns = input.slave_facet.nodes();
    let xm = master_x(input);
    let slave = seed::<N>(input.slave_x, 0);
    let master = seed::<N>(xm, 3 * ns);
    let Some(kin) = kinematics(input, &slave[..ns], &master[..xm.len()], xi_bar) else {
        return false;
    };
    normal_forces(input, &kin, xm.len(), |dof, v: Dual<N>| {
        if let Some(ri) = r.get_mut(dof) {
            *ri = v.re;
        }
        if let Some(row) = k.get_mut(dof * N..(dof + 1) * N) {
            row.copy_from_slice(&v.eps);
        }
    });
    true
}

/// Monomorphised for the possible link sizes so the dual arrays are exactly
/// as long as needed: quad–quad 24, quad–tri 21, tri–tri 18, rigid 12 / 9.
fn residual_tangent_sized(
    input: &LinkInput,
    xi_bar: [f64; 2],
    r: &mut [f64],
    k: &mut [f64],
) -> bool {
    match dof_count(input) {
        24 => residual_dual::<24>(input, xi_bar, r, k),
        21 => residual_dual::<21>(input, xi_bar, r, k),
        18 => residual_dual::<18>(input, xi_bar, r, k),
        12 => residual_dual::<12>(input, xi_bar, r, k),
        9 => residual_dual::<9>(input, xi_bar, r, k),
        _ => false,
    }
}

/// Gap, normal, pressure and closest point in f64, without derivatives (for
/// the Uzawa update and output). Bad input or a failed projection gives
/// `projection_converged = false`, `pressure = 0`.
pub fn evaluate(input: &LinkInput) -> LinkState {
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
                slave_point: x1,
                master_point: p.point,
                projection_converged: p.converged,
                outside: p.outside,
            }
        }
        _ => match rigid_kinematics::<f64>(&x1, &input.master) {
            Some(kin) => LinkState {
                gap: kin.gap,
                normal: kin.normal,
                xi: [0.0; 2],
                pressure: 0.0,
                slave_point: x1,
                master_point: kin.master_point,
                projection_converged: true,
                outside: 0.0,
            },
            None => LinkState {
                slave_point: x1,
                ..LinkState::invalid()
            },
        },
    };
    if state.projection_converged {
        state.pressure = (input.lambda_n - input.penalty * state.gap).max(0.0);
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
    let mut state = evaluate(input);
    // Cheap exit: the f64 gap decides open/closed before any dual work.
    if state.pressure <= 0.0 {
        return state;
    }
    let ok = match k.as_deref_mut() {
        Some(k) => residual_tangent_sized(input, state.xi, r, k),
        None => residual_f64(input, state.xi, r),
    };
    if !ok {
        // The closest point has no usable Hessian or normal in the kernel's
        // own evaluation: drop the link rather than return a wrong tangent.
        r.fill(0.0);
        if let Some(k) = k {
            k.fill(0.0);
        }
        state = LinkState {
            projection_converged: false,
            pressure: 0.0,
            ..state
        };
    }
    state
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
        };
        let s = evaluate(&input);
        assert!((s.gap + 0.1).abs() < 1e-15);
        assert!((s.pressure - 1.0).abs() < 1e-14);
        assert_eq!(s.master_point, [0.0, 0.0, 1.0]);
        assert!((potential(&input) - 1.0 / 20.0 * 2.0).abs() < 1e-15);
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

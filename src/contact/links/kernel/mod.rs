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
//!
//! Files: `input` (what a link evaluation takes and reports, input checks,
//! reference weights, nodal positions as f64 or dual variables),
//! `kinematics` (slave point, closest point, gap, normal, convected frame),
//! `normal` (the contact pressure pN and the frictionless state), `friction`
//! (slip increment, trial traction, return map), `forces` (nodal forces of a
//! link and the f64 / dual passes that form `r` and `k`).

mod forces;
mod friction;
mod input;
mod kinematics;
mod normal;
#[cfg(test)]
mod tests;

pub use input::{
    check_buffers, check_input, dof_count, Friction, FrictionState, LinkError, LinkInput,
    LinkMaster, LinkState, SlipHistory, SlipRate,
};
pub use normal::potential;

use forces::{residual_f64, residual_tangent_sized};
use normal::evaluate_normal;

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

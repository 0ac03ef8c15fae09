//! The linear solves' floor of a Newton solve (`Snes::set_linear_floor`):
//! a KSP convergence test that wraps the KSP's own and stops a linear solve
//! once it has removed what the Newton solve still needs.
use super::sys;
use std::ffi::c_void;

/// A KSP convergence test and the destructor of its context.
pub(super) type ConvergenceTest = Option<
    unsafe extern "C" fn(
        sys::KSP,
        sys::PetscInt,
        f64,
        *mut sys::KSPConvergedReason,
        *mut c_void,
    ) -> sys::PetscErrorCode,
>;
pub(super) type ConvergenceDestroy =
    Option<unsafe extern "C" fn(*mut c_void) -> sys::PetscErrorCode>;

/// The state of the convergence test `set_linear_floor` installs: the
/// KSP's own test it wraps and the solve's first residual norm.
pub(super) struct LinearFloor {
    pub(super) snes: sys::SNES,
    pub(super) fraction: f64,
    pub(super) inner: ConvergenceTest,
    pub(super) inner_ctx: *mut c_void,
    pub(super) inner_destroy: ConvergenceDestroy,
    pub(super) rnorm0: f64,
}

/// The convergence test of `Snes::set_linear_floor`: the KSP's own test,
/// then convergence once the residual is below the floor.
pub(super) unsafe extern "C" fn floor_test(
    ksp: sys::KSP,
    n: sys::PetscInt,
    rnorm: f64,
    reason: *mut sys::KSPConvergedReason,
    ctx: *mut c_void,
) -> sys::PetscErrorCode {
    // SAFETY: ctx is the boxed `LinearFloor` of a live Snes (set in
    // `set_linear_floor`); PETSc passes a valid reason pointer.
    let f = unsafe { &mut *(ctx as *mut LinearFloor) };
    if let Some(inner) = f.inner {
        // SAFETY: the KSP's own test with its own context.
        let code = unsafe { inner(ksp, n, rnorm, reason, f.inner_ctx) };
        if code != 0 {
            return code;
        }
    }
    if n == 0 {
        f.rnorm0 = rnorm;
        return 0;
    }
    if f.fraction <= 0.0 {
        return 0;
    }
    // SAFETY: reason is valid for the call.
    if unsafe { *reason } != 0 {
        return 0;
    }
    let (mut atol, mut rtol, mut stol) = (0.0, 0.0, 0.0);
    let (mut max_it, mut max_f): (sys::PetscInt, sys::PetscInt) = (0, 0);
    let mut fnorm = 0.0;
    let mut hist: *mut f64 = std::ptr::null_mut();
    let mut hist_its: *mut sys::PetscInt = std::ptr::null_mut();
    let mut nhist: sys::PetscInt = 0;
    // SAFETY: valid snes (it owns this KSP); out-pointers are locals.
    let got = unsafe {
        sys::SNESGetTolerances(
            f.snes,
            &mut atol,
            &mut rtol,
            &mut stol,
            &mut max_it,
            &mut max_f,
        ) == 0
            && sys::SNESGetFunctionNorm(f.snes, &mut fnorm) == 0
            && sys::SNESGetConvergenceHistory(f.snes, &mut hist, &mut hist_its, &mut nhist) == 0
    };
    if !got || hist.is_null() || nhist < 1 || fnorm.is_nan() || fnorm <= 0.0 {
        return 0;
    }
    // SAFETY: the history holds nhist >= 1 entries; the first is |R0|.
    let first = unsafe { *hist };
    let target = atol.max(rtol * first);
    if rnorm <= f.fraction * (target / fnorm) * f.rnorm0 {
        // SAFETY: reason is valid for the call.
        unsafe { *reason = sys::KSPConvergedReason_KSP_CONVERGED_ATOL };
    }
    0
}

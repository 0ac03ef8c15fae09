//! A convergence test of Newton's linear solves from Rust
//! ([`Snes::add_linear_test`](super::Snes::add_linear_test)): it runs after
//! the KSP's own test, which it keeps, and may end a solve as converged,
//! knowing where the Newton solve stands.
use super::sys;
use std::ffi::c_void;

/// What a linear solve's convergence test adds to the KSP's own.
pub trait LinearTest: 'static {
    /// At iteration `iteration` of a linear solve with residual norm
    /// `rnorm`, after the KSP's own test (`decided`: it ended the solve):
    /// true to end the solve as converged.
    fn converged(&mut self, iteration: usize, rnorm: f64, decided: bool, newton: &Newton) -> bool;
}

/// Where the Newton solve around a linear solve stands, read on request.
pub struct Newton {
    snes: sys::SNES,
}

/// The Newton solve's tolerances and residual norms.
#[derive(Debug, Clone, Copy)]
pub struct NewtonProgress {
    pub atol: f64,
    pub rtol: f64,
    /// |R| at the current iterate.
    pub function_norm: f64,
    /// |R| at the solve's start (the first entry of its history).
    pub first_norm: f64,
}

impl Newton {
    /// The solve's tolerances and norms; None when PETSc cannot give them
    /// (no convergence history kept, say).
    pub fn progress(&self) -> Option<NewtonProgress> {
        let (mut atol, mut rtol, mut stol) = (0.0, 0.0, 0.0);
        let (mut max_it, mut max_f): (sys::PetscInt, sys::PetscInt) = (0, 0);
        let mut fnorm = 0.0;
        let mut hist: *mut f64 = std::ptr::null_mut();
        let mut hist_its: *mut sys::PetscInt = std::ptr::null_mut();
        let mut nhist: sys::PetscInt = 0;
        // SAFETY: a valid snes (it owns the KSP under test); out-pointers
        // are locals.
        let got = unsafe {
            sys::SNESGetTolerances(
                self.snes,
                &mut atol,
                &mut rtol,
                &mut stol,
                &mut max_it,
                &mut max_f,
            ) == 0
                && sys::SNESGetFunctionNorm(self.snes, &mut fnorm) == 0
                && sys::SNESGetConvergenceHistory(self.snes, &mut hist, &mut hist_its, &mut nhist)
                    == 0
        };
        if !got || hist.is_null() || nhist < 1 {
            return None;
        }
        // SAFETY: the history holds nhist >= 1 entries; the first is |R0|.
        let first_norm = unsafe { *hist };
        Some(NewtonProgress {
            atol,
            rtol,
            function_norm: fnorm,
            first_norm,
        })
    }
}

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

/// The installed test: the KSP's own test it wraps (its context destroyed
/// with this), the SNES, and the Rust test.
pub(super) struct Hook<T> {
    pub(super) snes: sys::SNES,
    pub(super) inner: ConvergenceTest,
    pub(super) inner_ctx: *mut c_void,
    pub(super) inner_destroy: ConvergenceDestroy,
    pub(super) test: T,
}

impl<T> Drop for Hook<T> {
    fn drop(&mut self) {
        if let Some(destroy) = self.inner_destroy {
            // SAFETY: the context taken over from the KSP, destroyed once,
            // by the function it came with, after the SNES (the owner drops
            // the hook after destroying it).
            unsafe {
                destroy(self.inner_ctx);
            }
        }
    }
}

/// The KSP's convergence test: the KSP's own test, then the Rust one.
pub(super) unsafe extern "C" fn trampoline<T: LinearTest>(
    ksp: sys::KSP,
    n: sys::PetscInt,
    rnorm: f64,
    reason: *mut sys::KSPConvergedReason,
    ctx: *mut c_void,
) -> sys::PetscErrorCode {
    // SAFETY: ctx is the boxed `Hook<T>` of a live Snes (set in
    // `add_linear_test`); PETSc passes a valid reason pointer.
    let h = unsafe { &mut *(ctx as *mut Hook<T>) };
    if let Some(inner) = h.inner {
        // SAFETY: the KSP's own test with its own context.
        let code = unsafe { inner(ksp, n, rnorm, reason, h.inner_ctx) };
        if code != 0 {
            return code;
        }
    }
    // SAFETY: reason is valid for the call.
    let decided = unsafe { *reason } != 0;
    let newton = Newton { snes: h.snes };
    if h.test.converged(n.max(0) as usize, rnorm, decided, &newton) {
        // SAFETY: reason is valid for the call.
        unsafe { *reason = sys::KSPConvergedReason_KSP_CONVERGED_ATOL };
    }
    0
}

//! The PETSc shell preconditioner around one of the contact Schur paths'
//! states ([`super::schur::SchurPreconditioner`] on one rank,
//! [`super::low_rank::LowRankPreconditioner`] on several): the callbacks
//! PETSc runs at each set-up and application, written once for both.
use super::{petsc_call, sys, Matrix, PetscError, Result, Vector};
use std::ffi::c_void;
use std::panic::{catch_unwind, AssertUnwindSafe};

/// What a shell preconditioner's state does at PETSc's callbacks.
pub(super) trait ShellState {
    /// The name PETSc prints for the PC (`-ksp_view`).
    const NAME: &'static std::ffi::CStr;
    /// Set-up for the Jacobian K + `kc` from the contact tangent `kc` alone.
    fn set_up(&mut self, kc: &Matrix) -> Result<()>;
    fn apply(&mut self, b: &Vector, x: &mut Vector) -> Result<()>;
    /// Some(failed) when the state reports an agreed numeric failure through
    /// the PC's failed reason (so the KSP reports a failed preconditioner);
    /// None when it never does.
    fn failed(&self) -> Option<bool>;
    /// Keeps the message of a callback's error for the caller to report.
    fn record_error(&mut self, message: String);
}

pub(super) fn error(call: &'static str, message: String) -> PetscError {
    PetscError {
        call,
        code: -1,
        message,
    }
}

/// Makes `pc` a shell preconditioner backed by `state`.
///
/// # Safety
/// `pc` must be a valid PC and `state` must stay at its address, alive,
/// until the PC is destroyed or given another type.
pub(super) unsafe fn install<T: ShellState>(pc: sys::PC, state: *mut T) -> Result<()> {
    // SAFETY: as the caller promises; the callbacks below read the context
    // only while PETSc runs them on this PC.
    unsafe {
        petsc_call!(PCSetType(pc, c"shell".as_ptr()))?;
        petsc_call!(PCShellSetContext(pc, state as *mut c_void))?;
        petsc_call!(PCShellSetSetUp(pc, Some(set_up_trampoline::<T>)))?;
        petsc_call!(PCShellSetApply(pc, Some(apply_trampoline::<T>)))?;
        petsc_call!(PCShellSetName(pc, T::NAME.as_ptr()))
    }
}

/// The shell's context.
///
/// # Safety
/// `pc` is a shell PC set up by [`install`] with a `T`.
unsafe fn context<'a, T: ShellState>(pc: sys::PC) -> Result<&'a mut T> {
    let mut ctx: *mut c_void = std::ptr::null_mut();
    // SAFETY: valid shell PC; PCShellGetContext writes the stored pointer
    // into the out-pointer (passed as void*, as PETSc 3.18 declares it).
    unsafe {
        petsc_call!(PCShellGetContext(
            pc,
            &mut ctx as *mut *mut c_void as *mut c_void
        ))?;
        (ctx as *mut T)
            .as_mut()
            .ok_or_else(|| error("PCShellGetContext", "no context".into()))
    }
}

/// The callback's code. A state that reports failures through the PC has
/// its reason set on every successful callback (cleared once a set-up
/// succeeds: the reason stays on the PC until set again).
fn code_of<T: ShellState>(pc: sys::PC, r: std::thread::Result<Result<()>>, state: &mut T) -> i32 {
    let message = match r {
        Ok(Ok(())) => {
            let Some(failed) = state.failed() else {
                return 0;
            };
            let reason = if failed {
                sys::PCFailedReason_PC_FACTOR_OTHER
            } else {
                sys::PCFailedReason_PC_NOERROR
            };
            // SAFETY: valid PC for the callback's duration.
            match unsafe { petsc_call!(PCSetFailedReason(pc, reason)) } {
                Ok(()) => return 0,
                Err(e) => e.to_string(),
            }
        }
        Ok(Err(e)) => e.to_string(),
        Err(_) => format!(
            "panic in the preconditioner '{}'",
            T::NAME.to_string_lossy()
        ),
    };
    state.record_error(message);
    sys::PETSC_ERR_LIB
}

unsafe extern "C" fn set_up_trampoline<T: ShellState>(pc: sys::PC) -> sys::PetscErrorCode {
    // SAFETY: PETSc calls this on the shell PC `install` set up with a `T`.
    let Ok(state) = (unsafe { context::<T>(pc) }) else {
        return sys::PETSC_ERR_LIB;
    };
    let mut a: sys::Mat = std::ptr::null_mut();
    let mut p: sys::Mat = std::ptr::null_mut();
    // SAFETY: valid PC; the operators are borrowed for this call only.
    let got = unsafe { petsc_call!(PCGetOperators(pc, &mut a, &mut p)) };
    let r = catch_unwind(AssertUnwindSafe(|| {
        got?;
        // SAFETY: the preconditioning matrix is valid during the set-up.
        // On these paths it holds the contact tangent alone (see
        // `solve::mechanics`).
        let kc = unsafe { Matrix::borrowed(p) };
        state.set_up(&kc)
    }));
    code_of(pc, r, state)
}

unsafe extern "C" fn apply_trampoline<T: ShellState>(
    pc: sys::PC,
    b: sys::Vec,
    x: sys::Vec,
) -> sys::PetscErrorCode {
    // SAFETY: PETSc calls this on the shell PC `install` set up with a `T`.
    let Ok(state) = (unsafe { context::<T>(pc) }) else {
        return sys::PETSC_ERR_LIB;
    };
    // SAFETY: PETSc passes valid vectors for the call's duration.
    let (bv, mut xv) = unsafe { (Vector::borrowed(b), Vector::borrowed(x)) };
    let r = catch_unwind(AssertUnwindSafe(|| state.apply(&bv, &mut xv)));
    code_of(pc, r, state)
}

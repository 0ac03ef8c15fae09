//! The PETSc shell preconditioner around [`LowRankPreconditioner`].
use super::super::{petsc_call, sys, Matrix, Result, Vector};
use super::{error, LowRankPreconditioner};
use std::ffi::c_void;
use std::panic::{catch_unwind, AssertUnwindSafe};

/// Makes `pc` a shell preconditioner backed by `state`.
///
/// # Safety
/// `pc` must be a valid PC and `state` must stay at its address, alive,
/// until the PC is destroyed or given another type.
pub(in crate::petsc) unsafe fn install(
    pc: sys::PC,
    state: *mut LowRankPreconditioner,
) -> Result<()> {
    // SAFETY: as the caller promises; the callbacks below read the context
    // only while PETSc runs them on this PC.
    unsafe {
        petsc_call!(PCSetType(pc, c"shell".as_ptr()))?;
        petsc_call!(PCShellSetContext(pc, state as *mut c_void))?;
        petsc_call!(PCShellSetSetUp(pc, Some(set_up_trampoline)))?;
        petsc_call!(PCShellSetApply(pc, Some(apply_trampoline)))?;
        petsc_call!(PCShellSetName(
            pc,
            c"MUMPS factor of the bulk stiffness with a low-rank contact update".as_ptr()
        ))
    }
}

/// The shell's context.
///
/// # Safety
/// `pc` is a shell PC set up by [`install`].
unsafe fn context<'a>(pc: sys::PC) -> Result<&'a mut LowRankPreconditioner> {
    let mut ctx: *mut c_void = std::ptr::null_mut();
    // SAFETY: valid shell PC; PCShellGetContext writes the stored pointer
    // into the out-pointer (passed as void*, as PETSc 3.18 declares it).
    unsafe {
        petsc_call!(PCShellGetContext(
            pc,
            &mut ctx as *mut *mut c_void as *mut c_void
        ))?;
        (ctx as *mut LowRankPreconditioner)
            .as_mut()
            .ok_or_else(|| error("PCShellGetContext", "no context".into()))
    }
}

/// The callback's code; an agreed numeric failure marks the PC failed
/// (every rank alike) instead, so the KSP reports a failed preconditioner.
fn code_of(
    pc: sys::PC,
    r: std::thread::Result<Result<()>>,
    state: &mut LowRankPreconditioner,
) -> i32 {
    let message = match r {
        Ok(Ok(())) => {
            // The reason stays on the PC until set again: cleared once a
            // set-up succeeds.
            let reason = if state.failed.is_some() {
                sys::PCFailedReason_PC_FACTOR_OTHER
            } else {
                sys::PCFailedReason_PC_NOERROR
            };
            // SAFETY: valid PC for the callback's duration.
            let set = unsafe { petsc_call!(PCSetFailedReason(pc, reason)) };
            match set {
                Ok(()) => return 0,
                Err(e) => e.to_string(),
            }
        }
        Ok(Err(e)) => e.to_string(),
        Err(_) => "panic in the low-rank contact preconditioner".into(),
    };
    state.last_error = Some(message);
    sys::PETSC_ERR_LIB
}

unsafe extern "C" fn set_up_trampoline(pc: sys::PC) -> sys::PetscErrorCode {
    // SAFETY: PETSc calls this on the shell PC `install` set up.
    let Ok(state) = (unsafe { context(pc) }) else {
        return sys::PETSC_ERR_LIB;
    };
    let mut a: sys::Mat = std::ptr::null_mut();
    let mut p: sys::Mat = std::ptr::null_mut();
    // SAFETY: valid PC; the operators are borrowed for this call only.
    let got = unsafe { petsc_call!(PCGetOperators(pc, &mut a, &mut p)) };
    let r = catch_unwind(AssertUnwindSafe(|| {
        got?;
        // SAFETY: the preconditioning matrix is valid during the set-up;
        // on this path it holds the contact tangent alone.
        let kc = unsafe { Matrix::borrowed(p) };
        state.set_up(&kc)
    }));
    code_of(pc, r, state)
}

unsafe extern "C" fn apply_trampoline(
    pc: sys::PC,
    b: sys::Vec,
    x: sys::Vec,
) -> sys::PetscErrorCode {
    // SAFETY: PETSc calls this on the shell PC `install` set up.
    let Ok(state) = (unsafe { context(pc) }) else {
        return sys::PETSC_ERR_LIB;
    };
    // SAFETY: PETSc passes valid vectors for the call's duration.
    let (bv, mut xv) = unsafe { (Vector::borrowed(b), Vector::borrowed(x)) };
    let r = catch_unwind(AssertUnwindSafe(|| state.apply(&bv, &mut xv)));
    code_of(pc, r, state)
}

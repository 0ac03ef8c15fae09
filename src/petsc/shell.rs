//! PETSc shells around Rust state: a shell preconditioner
//! ([`ShellPreconditioner`]: PETSc's set-up and application call it), and
//! a shell Jacobian operator ([`ShellOperator`]: its products, with the
//! Jacobian matrix at hand, and each linear solve's right-hand side and
//! solution reported to it). [`super::Snes`] installs them.
use super::{comm_world, petsc_call, sys, Matrix, PetscError, Result, Vector};
use std::ffi::c_void;
use std::panic::{catch_unwind, AssertUnwindSafe};

/// What a shell preconditioner's state does at PETSc's callbacks.
pub trait ShellPreconditioner: 'static {
    /// The name PETSc prints for the PC (`-ksp_view`).
    const NAME: &'static std::ffi::CStr;
    /// Set-up from the preconditioning matrix `p` (SNES's Jacobian matrix).
    fn set_up(&mut self, p: &Matrix) -> Result<()>;
    fn apply(&mut self, b: &Vector, x: &mut Vector) -> Result<()>;
    /// Some(failed) when the state reports an agreed numeric failure through
    /// the PC's failed reason (so the KSP reports a failed preconditioner);
    /// None when it never does.
    fn failed(&self) -> Option<bool>;
    /// Keeps the message of a callback's error for the caller to report.
    fn record_error(&mut self, message: String);
}

/// Makes `pc` a shell preconditioner backed by `state`.
///
/// # Safety
/// `pc` must be a valid PC and `state` must stay at its address, alive,
/// until the PC is destroyed or given another type.
pub(super) unsafe fn install<T: ShellPreconditioner>(pc: sys::PC, state: *mut T) -> Result<()> {
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
unsafe fn context<'a, T: ShellPreconditioner>(pc: sys::PC) -> Result<&'a mut T> {
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
            .ok_or_else(|| PetscError::new("PCShellGetContext", "no context".into()))
    }
}

/// The callback's code. A state that reports failures through the PC has
/// its reason set on every successful callback (cleared once a set-up
/// succeeds: the reason stays on the PC until set again).
fn code_of<T: ShellPreconditioner>(
    pc: sys::PC,
    r: std::thread::Result<Result<()>>,
    state: &mut T,
) -> i32 {
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

unsafe extern "C" fn set_up_trampoline<T: ShellPreconditioner>(pc: sys::PC) -> sys::PetscErrorCode {
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
        let pm = unsafe { Matrix::borrowed(p) };
        state.set_up(&pm)
    }));
    code_of(pc, r, state)
}

unsafe extern "C" fn apply_trampoline<T: ShellPreconditioner>(
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

/// What a shell Jacobian operator A does: its products, given the Jacobian
/// (preconditioning) matrix of the solve, and what it learns of each linear
/// solve of the KSP it watches.
pub trait ShellOperator: 'static {
    /// y = A x.
    fn mult(&mut self, jacobian: &Matrix, x: &Vector, y: &mut Vector) -> Result<()>;
    /// y = Aᵀ x.
    fn mult_transpose(&mut self, jacobian: &Matrix, x: &Vector, y: &mut Vector) -> Result<()>;
    /// A linear solve ended with the right-hand side `b` and solution `x`.
    fn solved(&mut self, b: &Vector, x: &Vector) -> Result<()>;
}

/// A shell matrix's product y = op(A) x.
type MatVecOp = unsafe extern "C" fn(sys::Mat, sys::Vec, sys::Vec) -> sys::PetscErrorCode;

/// A [`ShellOperator`] as PETSc sees it: the shell matrix (made at the
/// first [`Self::operator`], with the Jacobian's sizes) and the Jacobian
/// matrix of the current solve. Its address is the shell's and the KSP
/// hook's context: it stays fixed while either lives.
pub(super) struct OperatorShell {
    shell: sys::Mat,
    jacobian: sys::Mat,
    state: Box<dyn ShellOperator>,
}

impl OperatorShell {
    pub(super) fn new(state: Box<dyn ShellOperator>) -> Self {
        OperatorShell {
            shell: std::ptr::null_mut(),
            jacobian: std::ptr::null_mut(),
            state,
        }
    }

    /// The shell operator for a solve whose Jacobian matrix is `jacobian`
    /// (created at the first call, with its sizes; `self` must stay at one
    /// address while the shell lives: it is the shell's context).
    pub(super) fn operator(&mut self, jacobian: sys::Mat) -> Result<sys::Mat> {
        self.jacobian = jacobian;
        if !self.shell.is_null() {
            return Ok(self.shell);
        }
        let (mut m, mut n, mut gm, mut gn) = (0, 0, 0, 0);
        let ctx = self as *mut OperatorShell as *mut c_void;
        // SAFETY: `jacobian` is a valid matrix; the shell is owned by `self`
        // (destroyed in Drop) and its context is `self`, whose address the
        // caller keeps fixed while the shell lives; the operations are
        // functions of the signature PETSc calls them with (cast to the
        // generic pointer type MatShellSetOperation takes).
        unsafe {
            petsc_call!(MatGetLocalSize(jacobian, &mut m, &mut n))?;
            petsc_call!(MatGetSize(jacobian, &mut gm, &mut gn))?;
            petsc_call!(MatCreateShell(
                comm_world(),
                m,
                n,
                gm,
                gn,
                ctx,
                &mut self.shell
            ))?;
            let (mult, mult_t): (MatVecOp, MatVecOp) = (shell_mult, shell_mult_transpose);
            petsc_call!(MatShellSetOperation(
                self.shell,
                sys::MatOperation_MATOP_MULT,
                Some(std::mem::transmute::<MatVecOp, unsafe extern "C" fn()>(
                    mult
                ))
            ))?;
            petsc_call!(MatShellSetOperation(
                self.shell,
                sys::MatOperation_MATOP_MULT_TRANSPOSE,
                Some(std::mem::transmute::<MatVecOp, unsafe extern "C" fn()>(
                    mult_t
                ))
            ))?;
        }
        Ok(self.shell)
    }

    /// Makes every linear solve of `ksp` report its right-hand side and
    /// solution to the state (`self` at a fixed address while the KSP
    /// lives).
    pub(super) fn watch(&mut self, ksp: sys::KSP) -> Result<()> {
        let ctx = self as *mut OperatorShell as *mut c_void;
        // SAFETY: valid KSP; the context outlives it (the caller's promise).
        unsafe { petsc_call!(KSPSetPostSolve(ksp, Some(post_solve), ctx)) }
    }
}

impl Drop for OperatorShell {
    fn drop(&mut self) {
        // SAFETY: owned and destroyed once (null is skipped by PETSc).
        unsafe {
            sys::MatDestroy(&mut self.shell);
        }
    }
}

/// The `OperatorShell` behind a context pointer.
///
/// # Safety
/// `ctx` must be the `OperatorShell` the shell or hook was created with, alive.
unsafe fn shell_at<'a>(ctx: *mut c_void) -> &'a mut OperatorShell {
    // SAFETY: the caller's promise.
    unsafe { &mut *(ctx as *mut OperatorShell) }
}

fn code(r: Result<()>) -> sys::PetscErrorCode {
    match r {
        Ok(()) => 0,
        Err(_) => sys::PETSC_ERR_LIB,
    }
}

unsafe extern "C" fn post_solve(
    _ksp: sys::KSP,
    b: sys::Vec,
    x: sys::Vec,
    ctx: *mut c_void,
) -> sys::PetscErrorCode {
    // SAFETY: PETSc passes the KSP's valid vectors for the call and the
    // context set in `watch`.
    let (bv, xv, s) = unsafe { (Vector::borrowed(b), Vector::borrowed(x), shell_at(ctx)) };
    code(s.state.solved(&bv, &xv))
}

/// The `OperatorShell` behind the shell `a` (None if PETSc cannot give it).
///
/// # Safety
/// `a` must be a shell made by [`OperatorShell::operator`], its state alive.
unsafe fn shell_of<'a>(a: sys::Mat) -> Option<&'a mut OperatorShell> {
    let mut ctx: *mut c_void = std::ptr::null_mut();
    // SAFETY: `a` is a valid shell (the caller's promise); the out-pointer
    // is a local.
    let got = unsafe { sys::MatShellGetContext(a, &mut ctx as *mut *mut c_void as *mut c_void) };
    // SAFETY: its context is the state (the caller's promise).
    (got == 0).then(|| unsafe { shell_at(ctx) })
}

unsafe extern "C" fn shell_mult(a: sys::Mat, x: sys::Vec, y: sys::Vec) -> sys::PetscErrorCode {
    // SAFETY: PETSc calls this on the shell made in `operator`.
    let Some(s) = (unsafe { shell_of(a) }) else {
        return sys::PETSC_ERR_LIB;
    };
    // SAFETY: PETSc passes valid vectors for the call; the Jacobian matrix
    // is the solve's, assembled.
    let (j, xv, mut yv) = unsafe {
        (
            Matrix::borrowed(s.jacobian),
            Vector::borrowed(x),
            Vector::borrowed(y),
        )
    };
    code(s.state.mult(&j, &xv, &mut yv))
}

unsafe extern "C" fn shell_mult_transpose(
    a: sys::Mat,
    x: sys::Vec,
    y: sys::Vec,
) -> sys::PetscErrorCode {
    // SAFETY: as in `shell_mult`.
    let Some(s) = (unsafe { shell_of(a) }) else {
        return sys::PETSC_ERR_LIB;
    };
    // SAFETY: as in `shell_mult`.
    let (j, xv, mut yv) = unsafe {
        (
            Matrix::borrowed(s.jacobian),
            Vector::borrowed(x),
            Vector::borrowed(y),
        )
    };
    code(s.state.mult_transpose(&j, &xv, &mut yv))
}

//! The Newton line search's slope on the contact paths whose Jacobian
//! matrix holds the contact tangent alone (the Schur and low-rank paths:
//! K lives in the preconditioner's factor).
//!
//! PETSc's backtracking line search takes its initial slope as F · (A y),
//! A the SNES's operator and y the step the linear solve returned; with A
//! the contact tangent alone that is not the whole system's slope, and a
//! step the search cuts gets another length than on the full
//! factorisation. The operator is therefore a shell: its product with the
//! step the last linear solve returned is that solve's right-hand side (A y
//! = F for the exact solves these paths make, so the slope is −|F|²; a
//! Krylov method a user puts around them leaves the residual of its
//! tolerance), and any other product is the contact tangent's, as before.
use super::{comm_world, petsc_call, sys, Result, Vector};
use std::os::raw::c_void;

/// A shell matrix's product y = op(A) x.
type MatVecOp = unsafe extern "C" fn(sys::Mat, sys::Vec, sys::Vec) -> sys::PetscErrorCode;

/// The shell operator's state: the last linear solve's right-hand side
/// and solution, and the contact tangent for any other product.
pub struct LastSolve {
    shell: sys::Mat,
    tangent: sys::Mat,
    rhs: Option<Vector>,
    sol: Option<Vector>,
}

impl LastSolve {
    pub(super) fn new() -> Self {
        LastSolve {
            shell: std::ptr::null_mut(),
            tangent: std::ptr::null_mut(),
            rhs: None,
            sol: None,
        }
    }

    /// The shell operator for a solve whose Jacobian matrix is `tangent`
    /// (created at the first call, with its sizes; `self` must stay at one
    /// address while the shell lives: it is the shell's context).
    pub(super) fn operator(&mut self, tangent: sys::Mat) -> Result<sys::Mat> {
        self.tangent = tangent;
        if !self.shell.is_null() {
            return Ok(self.shell);
        }
        let (mut m, mut n, mut gm, mut gn) = (0, 0, 0, 0);
        let ctx = self as *mut LastSolve as *mut c_void;
        // SAFETY: `tangent` is a valid matrix; the shell is owned by `self`
        // (destroyed in Drop) and its context is `self`, whose address the
        // caller keeps fixed while the shell lives; the operations are
        // functions of the signature PETSc calls them with (cast to the
        // generic pointer type MatShellSetOperation takes).
        unsafe {
            petsc_call!(MatGetLocalSize(tangent, &mut m, &mut n))?;
            petsc_call!(MatGetSize(tangent, &mut gm, &mut gn))?;
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

    /// Makes every linear solve of `ksp` record its right-hand side and
    /// solution here (`self` at a fixed address while the KSP lives).
    pub(super) fn watch(&mut self, ksp: sys::KSP) -> Result<()> {
        let ctx = self as *mut LastSolve as *mut c_void;
        // SAFETY: valid KSP; the context outlives it (the caller's promise).
        unsafe { petsc_call!(KSPSetPostSolve(ksp, Some(post_solve), ctx)) }
    }

    fn record(&mut self, b: &Vector, x: &Vector) -> Result<()> {
        for (kept, v) in [(&mut self.rhs, b), (&mut self.sol, x)] {
            if kept.is_none() {
                *kept = Some(v.duplicate()?);
            }
            if let Some(k) = kept.as_mut() {
                k.copy_from(v)?;
            }
        }
        Ok(())
    }

    /// y = A x: the last right-hand side when x is the last solution.
    fn mult(&self, x: sys::Vec, y: sys::Vec) -> Result<()> {
        if let (Some(sol), Some(rhs)) = (&self.sol, &self.rhs) {
            let mut same = sys::PetscBool_PETSC_FALSE;
            // SAFETY: valid vectors of the operator's layout (PETSc checks).
            unsafe { petsc_call!(VecEqual(x, sol.raw(), &mut same))? };
            if same == sys::PetscBool_PETSC_TRUE {
                // SAFETY: as above.
                return unsafe { petsc_call!(VecCopy(rhs.raw(), y)) };
            }
        }
        // SAFETY: the tangent is the solve's Jacobian matrix, assembled.
        unsafe { petsc_call!(MatMult(self.tangent, x, y)) }
    }
}

impl Drop for LastSolve {
    fn drop(&mut self) {
        // SAFETY: owned and destroyed once (null is skipped by PETSc).
        unsafe {
            sys::MatDestroy(&mut self.shell);
        }
    }
}

/// The context of the shell `a` (or of the KSP's post-solve hook).
///
/// # Safety
/// `ctx` must be the `LastSolve` the shell or hook was created with, alive.
unsafe fn state<'a>(ctx: *mut c_void) -> &'a mut LastSolve {
    // SAFETY: the caller's promise.
    unsafe { &mut *(ctx as *mut LastSolve) }
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
    let (bv, xv, s) = unsafe { (Vector::borrowed(b), Vector::borrowed(x), state(ctx)) };
    code(s.record(&bv, &xv))
}

/// The state behind the shell `a` (None if PETSc cannot give it).
///
/// # Safety
/// `a` must be a shell made by [`LastSolve::operator`], its state alive.
unsafe fn shell_state<'a>(a: sys::Mat) -> Option<&'a mut LastSolve> {
    let mut ctx: *mut c_void = std::ptr::null_mut();
    // SAFETY: `a` is a valid shell (the caller's promise); the out-pointer
    // is a local.
    let got = unsafe { sys::MatShellGetContext(a, &mut ctx as *mut *mut c_void as *mut c_void) };
    // SAFETY: its context is the state (the caller's promise).
    (got == 0).then(|| unsafe { state(ctx) })
}

unsafe extern "C" fn shell_mult(a: sys::Mat, x: sys::Vec, y: sys::Vec) -> sys::PetscErrorCode {
    // SAFETY: PETSc calls this on the shell made in `operator`.
    match unsafe { shell_state(a) } {
        Some(s) => code(s.mult(x, y)),
        None => sys::PETSC_ERR_LIB,
    }
}

/// Aᵀ x with the contact tangent (what SNES asks when its line search has
/// failed, to tell a local minimum).
unsafe extern "C" fn shell_mult_transpose(
    a: sys::Mat,
    x: sys::Vec,
    y: sys::Vec,
) -> sys::PetscErrorCode {
    // SAFETY: as in `shell_mult`.
    let Some(s) = (unsafe { shell_state(a) }) else {
        return sys::PETSC_ERR_LIB;
    };
    // SAFETY: the tangent is the solve's Jacobian matrix, assembled.
    code(unsafe { petsc_call!(MatMultTranspose(s.tangent, x, y)) })
}

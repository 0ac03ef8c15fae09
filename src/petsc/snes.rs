//! Newton's method through PETSc SNES, with residual and Jacobian computed by
//! Rust code behind the [`NonlinearProblem`] trait.
use super::linear_test::{self, Hook, LinearTest};
use super::reason::{KspReason, SnesReason};
use super::shell::{self, OperatorShell, ShellOperator, ShellPreconditioner};
use super::{comm_world, petsc_call, sys, Matrix, PetscError, Result, Vector};
use std::any::Any;
use std::ffi::c_void;
use std::panic::{catch_unwind, AssertUnwindSafe};

/// What a callback can report besides success.
#[derive(Debug)]
pub enum CallbackError {
    /// The state is outside the problem's domain (e.g. an inverted element): SNES
    /// treats the step as failed and the caller can cut the load step back.
    /// Must be returned on every rank alike (the problem agrees it first).
    Domain(String),
    /// Anything else: the solve stops and the error is reported; also on
    /// every rank alike.
    Fatal(String),
}

/// The residual R(x) and its Jacobian, evaluated by the application.
///
/// Both are collective: an implementation finishes its collective work
/// (ghost updates, assembly) even when its local part failed, and returns
/// the same outcome on every rank.
pub trait NonlinearProblem {
    fn residual(&mut self, x: &Vector, r: &mut Vector) -> std::result::Result<(), CallbackError>;
    fn jacobian(&mut self, x: &Vector, j: &mut Matrix) -> std::result::Result<(), CallbackError>;

    /// Called after each Jacobian evaluation with the iteration count of the
    /// last linear solve: Some(true) to rebuild the preconditioner from this
    /// Jacobian, Some(false) to keep the last one, None to leave SNES's own
    /// lag setting alone. Must give the same answer on every rank.
    fn rebuild_preconditioner(&mut self, _last_linear_iterations: usize) -> Option<bool> {
        None
    }

    /// Called before each backtracking line search (not before the other
    /// kinds) with the iterate `x` and the Newton step `y` (the full step
    /// goes to `x − y`): a fraction in (0, 1) to shorten the step to, or
    /// None to keep it. Collective; must give the same answer on every
    /// rank.
    fn step_fraction(
        &mut self,
        _x: &Vector,
        _y: &Vector,
    ) -> std::result::Result<Option<f64>, CallbackError> {
        Ok(None)
    }
}

/// The result of one SNES solve.
#[derive(Debug, Clone)]
pub struct SnesOutcome {
    /// SNES converged and no callback reported a domain error.
    pub converged: bool,
    pub reason: SnesReason,
    pub iterations: usize,
    pub linear_iterations: usize,
    /// The last linear solve: why it stopped and after how many iterations.
    pub ksp_reason: KspReason,
    pub ksp_iterations: usize,
    pub residual_norm: f64,
    /// Residual norm after each Newton iteration (index 0: initial).
    pub history: Vec<f64>,
    /// Set when a callback hit a domain error (inverted element, ...); the
    /// callbacks agree it over all ranks, so it is the same everywhere.
    pub domain_error: Option<String>,
}

struct Context<'a> {
    problem: &'a mut dyn NonlinearProblem,
    fatal: Option<String>,
    domain: Option<String>,
    /// The Jacobian callback ended the solve with a domain error.
    jacobian_stopped: bool,
}

pub struct Snes {
    raw: sys::SNES,
    /// The linear solves' own convergence test (`add_linear_test`, a
    /// `linear_test::Hook`): boxed so that its address, which the KSP
    /// holds, stays fixed; dropped after the SNES (fields go after
    /// `Drop::drop`), which its drop needs.
    linear_test: Option<Box<dyn Any>>,
    /// The shell preconditioner's state, when there is one
    /// (`install_shell_preconditioner`): boxed and dropped after the SNES,
    /// as above.
    preconditioner: Option<Box<dyn Any>>,
    /// The shell Jacobian operator, when there is one (`set_operator`):
    /// boxed and dropped after the SNES, as above.
    operator: Option<Box<OperatorShell>>,
    /// The line search is PETSc's backtracking one (read after the options
    /// are applied): the problem's `step_fraction` is asked before it.
    backtracking: bool,
}

/// A line search's pre-check (`SNESLineSearchSetPreCheck`).
type PreCheck = unsafe extern "C" fn(
    sys::SNESLineSearch,
    sys::Vec,
    sys::Vec,
    *mut sys::PetscBool,
    *mut c_void,
) -> sys::PetscErrorCode;

impl Snes {
    /// A Newton solver that reads its settings from the options database under
    /// `prefix` (e.g. "" or "contact_").
    pub fn new() -> Result<Self> {
        let mut raw: sys::SNES = std::ptr::null_mut();
        // SAFETY: PETSc is initialised; out-pointer valid.
        unsafe { petsc_call!(SNESCreate(comm_world(), &mut raw))? };
        let snes = Snes {
            raw,
            linear_test: None,
            preconditioner: None,
            operator: None,
            backtracking: false,
        };
        Ok(snes)
    }

    pub fn set_tolerances(&mut self, atol: f64, rtol: f64, stol: f64, max_it: usize) -> Result<()> {
        // SAFETY: valid snes.
        unsafe {
            petsc_call!(SNESSetTolerances(
                self.raw,
                atol,
                rtol,
                stol,
                max_it as sys::PetscInt,
                -1
            ))
        }
    }

    /// The current (atol, rtol, stol, max_it), as the options left them.
    pub fn tolerances(&self) -> Result<(f64, f64, f64, usize)> {
        let (mut atol, mut rtol, mut stol) = (0.0, 0.0, 0.0);
        let (mut max_it, mut max_f): (sys::PetscInt, sys::PetscInt) = (0, 0);
        // SAFETY: valid snes; every out-pointer is a live local.
        unsafe {
            petsc_call!(SNESGetTolerances(
                self.raw,
                &mut atol,
                &mut rtol,
                &mut stol,
                &mut max_it,
                &mut max_f
            ))?
        };
        Ok((atol, rtol, stol, max_it.max(0) as usize))
    }

    /// How often the preconditioner is rebuilt within this and later solves:
    /// 1 every Newton iteration, -1 never (reuse the last one). The Jacobian
    /// itself is still evaluated every iteration.
    pub fn set_lag_preconditioner(&mut self, lag: i32) -> Result<()> {
        // SAFETY: valid snes.
        unsafe {
            petsc_call!(SNESSetLagPreconditionerPersists(
                self.raw,
                sys::PetscBool_PETSC_TRUE
            ))?;
            petsc_call!(SNESSetLagPreconditioner(self.raw, lag))
        }
    }

    /// Drops the preconditioner's factors, symbolic ones included: after a
    /// failed factorisation (MUMPS keeps a failed analysis and skips every
    /// later numeric factorisation of the same pattern) the next solve
    /// starts afresh. Collective.
    pub fn reset_preconditioner(&mut self) -> Result<()> {
        let mut ksp: sys::KSP = std::ptr::null_mut();
        let mut pc: sys::PC = std::ptr::null_mut();
        // SAFETY: valid snes; the KSP and PC handles are borrowed from it.
        unsafe {
            petsc_call!(SNESGetKSP(self.raw, &mut ksp))?;
            petsc_call!(KSPGetPC(ksp, &mut pc))?;
            petsc_call!(PCReset(pc))
        }
    }

    /// Makes the linear solver's preconditioner a shell backed by `state`
    /// (after [`Self::set_from_options`], which would reset it).
    pub fn install_shell_preconditioner<T: ShellPreconditioner>(&mut self, state: T) -> Result<()> {
        let mut ksp: sys::KSP = std::ptr::null_mut();
        let mut pc: sys::PC = std::ptr::null_mut();
        let mut boxed = Box::new(state);
        let ptr: *mut T = &mut *boxed;
        self.preconditioner = Some(boxed);
        // SAFETY: valid snes; the KSP and PC are borrowed from it; the box
        // is kept in `self` until after the SNES (and so the PC) is destroyed,
        // and never moved out while the SNES lives.
        unsafe {
            petsc_call!(SNESGetKSP(self.raw, &mut ksp))?;
            petsc_call!(KSPGetPC(ksp, &mut pc))?;
            shell::install(pc, ptr)
        }
    }

    /// The shell preconditioner's state, if one of type `T` is installed.
    pub fn preconditioner<T: ShellPreconditioner>(&self) -> Option<&T> {
        self.preconditioner.as_ref()?.downcast_ref()
    }

    pub fn preconditioner_mut<T: ShellPreconditioner>(&mut self) -> Option<&mut T> {
        self.preconditioner.as_mut()?.downcast_mut()
    }

    /// Makes the Jacobian operator of every later solve a shell backed by
    /// `state` (over the Jacobian matrix, which stays the preconditioning
    /// matrix), and reports each linear solve of this SNES to it.
    pub fn set_operator(&mut self, state: impl ShellOperator) -> Result<()> {
        let mut ksp: sys::KSP = std::ptr::null_mut();
        let operator = self
            .operator
            .insert(Box::new(OperatorShell::new(Box::new(state))));
        // SAFETY: valid snes; the KSP is borrowed from it; the box lives in
        // `self` until after the SNES is destroyed and is never moved out
        // while it lives.
        unsafe { petsc_call!(SNESGetKSP(self.raw, &mut ksp))? };
        operator.watch(ksp)
    }

    /// The linear solver applies its preconditioner once (KSP "preonly"),
    /// unless the user chose a `-ksp_type`: for a preconditioner that
    /// solves exactly.
    pub fn apply_preconditioner_only(&mut self) -> Result<()> {
        let mut ksp: sys::KSP = std::ptr::null_mut();
        // SAFETY: valid snes; the KSP is borrowed from it.
        unsafe {
            petsc_call!(SNESGetKSP(self.raw, &mut ksp))?;
            if !super::options::user_set("-ksp_type")? {
                petsc_call!(KSPSetType(ksp, c"preonly".as_ptr()))?;
            }
        }
        Ok(())
    }

    /// Adds `test` after the KSP's own convergence test (which it keeps,
    /// with the Eisenstat–Walker tolerances it is given) for every linear
    /// solve of this SNES. Collective; after [`Self::set_from_options`].
    pub fn add_linear_test<T: LinearTest>(&mut self, test: T) -> Result<()> {
        let mut ksp: sys::KSP = std::ptr::null_mut();
        let mut hook = Box::new(Hook {
            snes: self.raw,
            inner: None,
            inner_ctx: std::ptr::null_mut(),
            inner_destroy: None,
            test,
        });
        let ptr: *mut Hook<T> = &mut *hook;
        // SAFETY: valid snes; the KSP is borrowed from it. The KSP's own
        // test is taken over (not destroyed) and called from the hook's
        // trampoline; the box lives in `self` until after the SNES is
        // destroyed and is never moved out while it lives; its drop then
        // destroys the inner context.
        unsafe {
            petsc_call!(SNESGetKSP(self.raw, &mut ksp))?;
            petsc_call!(KSPGetAndClearConvergenceTest(
                ksp,
                &mut hook.inner,
                &mut hook.inner_ctx,
                &mut hook.inner_destroy
            ))?;
            self.linear_test = Some(hook);
            petsc_call!(KSPSetConvergenceTest(
                ksp,
                Some(linear_test::trampoline::<T>),
                ptr as *mut c_void,
                None
            ))
        }
    }

    /// The linear test added, if it is of type `T`.
    pub fn linear_test_mut<T: LinearTest>(&mut self) -> Option<&mut T> {
        let hook = self.linear_test.as_mut()?.downcast_mut::<Hook<T>>()?;
        Some(&mut hook.test)
    }

    /// Applies the options database (after the program's defaults are set).
    pub fn set_from_options(&mut self) -> Result<()> {
        let mut kind: sys::SNESLineSearchType = std::ptr::null();
        // SAFETY: valid snes; the line search is borrowed from it and its
        // type name, a static string of PETSc's, is only read here.
        unsafe {
            petsc_call!(SNESSetFromOptions(self.raw))?;
            let mut ksp: sys::KSP = std::ptr::null_mut();
            petsc_call!(SNESGetKSP(self.raw, &mut ksp))?;
            petsc_call!(KSPSetFromOptions(ksp))?;
            let mut search: sys::SNESLineSearch = std::ptr::null_mut();
            petsc_call!(SNESGetLineSearch(self.raw, &mut search))?;
            petsc_call!(SNESLineSearchGetType(search, &mut kind))?;
            self.backtracking =
                !kind.is_null() && std::ffi::CStr::from_ptr(kind).to_bytes() == b"bt";
        }
        Ok(())
    }

    /// Solves R(x) = 0 starting from `x`, overwriting it. `r` and `j` are the
    /// work residual and Jacobian storage.
    pub fn solve(
        &mut self,
        problem: &mut dyn NonlinearProblem,
        x: &mut Vector,
        r: &mut Vector,
        j: &mut Matrix,
    ) -> Result<SnesOutcome> {
        let mut ctx = Context {
            problem,
            fatal: None,
            domain: None,
            jacobian_stopped: false,
        };
        let ctx_ptr = &mut ctx as *mut Context as *mut c_void;
        // The operator is the Jacobian matrix itself, or the shell of
        // `set_operator` over it.
        let operator = match self.operator.as_mut() {
            Some(s) => s.operator(j.raw())?,
            None => j.raw(),
        };
        const HIST: usize = 200;
        let mut hist = [0.0f64; HIST];
        let mut hist_its = [0 as sys::PetscInt; HIST];
        // SAFETY: the context lives on this stack frame and SNES calls back into it
        // only during SNESSolve below; callbacks are reset to this context before
        // every solve. The history arrays outlive the solve and are detached
        // after it, whatever the solve returned.
        let solved = unsafe {
            petsc_call!(SNESSetFunction(
                self.raw,
                r.raw(),
                Some(residual_trampoline),
                ctx_ptr
            ))?;
            petsc_call!(SNESSetJacobian(
                self.raw,
                operator,
                j.raw(),
                Some(jacobian_trampoline),
                ctx_ptr
            ))?;
            let mut search: sys::SNESLineSearch = std::ptr::null_mut();
            petsc_call!(SNESGetLineSearch(self.raw, &mut search))?;
            let precheck = if self.backtracking {
                Some(precheck_trampoline as PreCheck)
            } else {
                None
            };
            petsc_call!(SNESLineSearchSetPreCheck(search, precheck, ctx_ptr))?;
            petsc_call!(SNESSetConvergenceHistory(
                self.raw,
                hist.as_mut_ptr(),
                hist_its.as_mut_ptr(),
                HIST as sys::PetscInt,
                sys::PetscBool_PETSC_TRUE
            ))?;
            petsc_call!(SNESSolve(self.raw, std::ptr::null_mut(), x.raw()))
        };
        let read = self.read_outcome(&hist);
        // SAFETY: valid snes; detaching the stack arrays before they go away.
        let detached = unsafe {
            petsc_call!(SNESSetConvergenceHistory(
                self.raw,
                std::ptr::null_mut(),
                std::ptr::null_mut(),
                0,
                sys::PetscBool_PETSC_TRUE
            ))
        };
        if let Some(msg) = ctx.fatal.take() {
            return Err(PetscError {
                call: "SNESSolve callback",
                code: -1,
                message: msg,
            });
        }
        detached?;
        let mut outcome = read?;
        if ctx.jacobian_stopped {
            outcome.reason = SnesReason::JacobianDomain;
        } else {
            solved?;
        }
        outcome.domain_error = ctx.domain.take();
        outcome.converged = outcome.reason.converged() && outcome.domain_error.is_none();
        Ok(outcome)
    }

    /// Reason, counts and history after a solve (every call checked).
    fn read_outcome(&self, hist: &[f64]) -> Result<SnesOutcome> {
        let mut reason: sys::SNESConvergedReason = 0;
        let mut its: sys::PetscInt = 0;
        let mut lits: sys::PetscInt = 0;
        let mut norm = 0.0;
        let mut nhist: sys::PetscInt = 0;
        let mut hptr: *mut f64 = std::ptr::null_mut();
        let mut iptr: *mut sys::PetscInt = std::ptr::null_mut();
        let mut ksp: sys::KSP = std::ptr::null_mut();
        let mut ksp_reason: sys::KSPConvergedReason = 0;
        let mut ksp_its: sys::PetscInt = 0;
        // SAFETY: valid snes; out-pointers valid for the calls.
        unsafe {
            petsc_call!(SNESGetConvergedReason(self.raw, &mut reason))?;
            petsc_call!(SNESGetIterationNumber(self.raw, &mut its))?;
            petsc_call!(SNESGetLinearSolveIterations(self.raw, &mut lits))?;
            petsc_call!(SNESGetFunctionNorm(self.raw, &mut norm))?;
            petsc_call!(SNESGetConvergenceHistory(
                self.raw, &mut hptr, &mut iptr, &mut nhist
            ))?;
            petsc_call!(SNESGetKSP(self.raw, &mut ksp))?;
            petsc_call!(KSPGetConvergedReason(ksp, &mut ksp_reason))?;
            petsc_call!(KSPGetIterationNumber(ksp, &mut ksp_its))?;
        }
        let reason = SnesReason::from_raw(reason);
        Ok(SnesOutcome {
            converged: reason.converged(),
            reason,
            iterations: its.max(0) as usize,
            linear_iterations: lits.max(0) as usize,
            ksp_reason: KspReason::from_raw(ksp_reason),
            ksp_iterations: ksp_its.max(0) as usize,
            residual_norm: norm,
            history: hist[..(nhist.max(0) as usize).min(hist.len())].to_vec(),
            domain_error: None,
        })
    }
}

impl Drop for Snes {
    fn drop(&mut self) {
        // SAFETY: owned and destroyed once.
        unsafe {
            sys::SNESDestroy(&mut self.raw);
        }
        // The boxed hooks drop after this, the linear test's first: it
        // destroys the KSP test context it took over.
    }
}

/// Which callback is running: a domain error is flagged on its own kind.
#[derive(Clone, Copy)]
enum Kind {
    Residual,
    Jacobian,
}

fn run_callback(
    ctx: *mut c_void,
    snes: sys::SNES,
    kind: Kind,
    f: impl FnOnce(&mut dyn NonlinearProblem) -> std::result::Result<(), CallbackError>,
) -> sys::PetscErrorCode {
    // SAFETY: ctx is the `Context` set in `solve`, alive for the whole SNESSolve.
    let ctx = unsafe { &mut *(ctx as *mut Context) };
    let result = catch_unwind(AssertUnwindSafe(|| f(&mut *ctx.problem)));
    match result {
        Ok(Ok(())) => 0,
        Ok(Err(CallbackError::Domain(msg))) => {
            // The problem agreed the failure over all ranks before returning
            // it, so every rank flags the same domain error here.
            ctx.domain = Some(msg);
            match kind {
                Kind::Residual => {
                    // SAFETY: valid snes handed to the callback by PETSc.
                    match unsafe { petsc_call!(SNESSetFunctionDomainError(snes)) } {
                        Ok(()) => 0,
                        Err(e) => {
                            ctx.fatal = Some(e.to_string());
                            sys::PETSC_ERR_USER
                        }
                    }
                }
                // PETSc 3.18 keeps a Jacobian domain flag set into the next
                // solve (and checks it only on request), so the Jacobian
                // stops the solve with an error code instead, on every
                // rank alike; `solve` reads it back as this domain error.
                Kind::Jacobian => {
                    ctx.jacobian_stopped = true;
                    sys::PETSC_ERR_NOT_CONVERGED
                }
            }
        }
        Ok(Err(CallbackError::Fatal(msg))) => {
            ctx.fatal = Some(msg);
            sys::PETSC_ERR_USER
        }
        Err(_) => {
            ctx.fatal = Some("panic inside a SNES callback".into());
            sys::PETSC_ERR_USER
        }
    }
}

unsafe extern "C" fn residual_trampoline(
    snes: sys::SNES,
    x: sys::Vec,
    r: sys::Vec,
    ctx: *mut c_void,
) -> sys::PetscErrorCode {
    // SAFETY: PETSc passes valid vectors owned by the SNES for the call's duration.
    let (xv, mut rv) = unsafe { (Vector::borrowed(x), Vector::borrowed(r)) };
    run_callback(ctx, snes, Kind::Residual, |p| p.residual(&xv, &mut rv))
}

/// The backtracking line search's pre-check: the problem's step fraction
/// scales the step in place. A domain error there stops the solve as a
/// residual's does (the step is then cut back).
unsafe extern "C" fn precheck_trampoline(
    search: sys::SNESLineSearch,
    x: sys::Vec,
    y: sys::Vec,
    changed: *mut sys::PetscBool,
    ctx: *mut c_void,
) -> sys::PetscErrorCode {
    let mut snes: sys::SNES = std::ptr::null_mut();
    // SAFETY: PETSc passes the line search of the SNES being solved.
    if unsafe { sys::SNESLineSearchGetSNES(search, &mut snes) } != 0 {
        return sys::PETSC_ERR_USER;
    }
    // SAFETY: PETSc passes valid vectors for the call's duration.
    let (xv, mut yv) = unsafe { (Vector::borrowed(x), Vector::borrowed(y)) };
    let mut fraction = None;
    let code = run_callback(ctx, snes, Kind::Residual, |p| {
        fraction = p.step_fraction(&xv, &yv)?;
        Ok(())
    });
    if code != 0 {
        return code;
    }
    if let Some(f) = fraction.filter(|f| *f > 0.0 && *f < 1.0) {
        if yv.scale(f).is_err() {
            return sys::PETSC_ERR_USER;
        }
        // SAFETY: PETSc passes a valid flag pointer.
        unsafe { *changed = sys::PetscBool_PETSC_TRUE };
    }
    0
}

unsafe extern "C" fn jacobian_trampoline(
    snes: sys::SNES,
    x: sys::Vec,
    _a: sys::Mat,
    p: sys::Mat,
    ctx: *mut c_void,
) -> sys::PetscErrorCode {
    // SAFETY: PETSc passes valid objects for the call's duration; P is the
    // Jacobian matrix set in `solve` (A is P or the shell over it).
    let (xv, mut am) = unsafe { (Vector::borrowed(x), Matrix::borrowed(p)) };
    let code = run_callback(ctx, snes, Kind::Jacobian, |p| p.jacobian(&xv, &mut am));
    // SNES reads its preconditioner lag after this callback returns, so a
    // lag set here decides this iteration: -2 rebuilds once, -1 reuses.
    // The decision is collective, so it is asked for on every rank even
    // when the Jacobian failed (the failure was agreed by every rank, so
    // all of them return it below).
    let mut its: sys::PetscInt = 0;
    let mut ksp: sys::KSP = std::ptr::null_mut();
    // SAFETY: valid snes handed to the callback; out-pointers are locals.
    let got = unsafe {
        sys::SNESGetKSP(snes, &mut ksp) == 0 && sys::KSPGetIterationNumber(ksp, &mut its) == 0
    };
    // SAFETY: ctx is the `Context` set in `solve`, alive for the whole SNESSolve.
    let context = unsafe { &mut *(ctx as *mut Context) };
    let last = if got { its.max(0) as usize } else { usize::MAX };
    let decision = catch_unwind(AssertUnwindSafe(|| {
        context.problem.rebuild_preconditioner(last)
    }));
    if code != 0 {
        return code;
    }
    match decision {
        Ok(Some(rebuild)) => {
            let lag = if rebuild { -2 } else { -1 };
            // SAFETY: valid snes handed to the callback by PETSc.
            let set = unsafe {
                petsc_call!(SNESSetLagPreconditionerPersists(
                    snes,
                    sys::PetscBool_PETSC_TRUE
                ))
                .and_then(|()| petsc_call!(SNESSetLagPreconditioner(snes, lag)))
            };
            match set {
                Ok(()) => 0,
                Err(e) => {
                    context.fatal = Some(e.to_string());
                    sys::PETSC_ERR_USER
                }
            }
        }
        Ok(None) => 0,
        Err(_) => {
            context.fatal = Some("panic while deciding the preconditioner lag".into());
            sys::PETSC_ERR_USER
        }
    }
}

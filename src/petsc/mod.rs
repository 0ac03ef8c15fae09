//! The PETSc binding layer: raw bindings (`sys`) and the safe RAII wrappers
//! the rest of the program uses, over PETSc and the few LAPACK routines it
//! calls (`lapack`): vectors, sparse and dense matrices, MUMPS factors with
//! their Schur complement and selected inverse entries (`factor`),
//! scatters, index sets, Newton (SNES) with Rust callbacks and the shells
//! and hooks that put Rust state into its linear solves (`shell`,
//! `linear_test`), options and log stages. Algorithms built on them live
//! outside (`linsolve`, `solve`).
//!
//! With `runtime/` (process signals and malloc) the only place with
//! `unsafe`; every PETSc error code becomes a [`PetscError`] naming the
//! call.
pub mod dense;
pub mod factor;
pub mod index_set;
pub mod lapack;
pub mod linear_test;
pub mod log;
pub mod matrix;
pub mod options;
pub mod reason;
pub mod scatter;
pub mod shell;
pub mod snes;
pub mod sys;
pub mod vector;

pub use dense::DenseMatrix;
pub use factor::Factor;
pub use linear_test::{LinearTest, Newton, NewtonProgress};
pub use log::LogStage;
pub use matrix::Matrix;
pub use reason::{KspReason, SnesReason};
pub use scatter::Scatter;
pub use shell::{ShellOperator, ShellPreconditioner};
pub use snes::{NonlinearProblem, Snes, SnesOutcome};
pub use vector::{GhostedVector, Vector};

use std::ffi::{CStr, CString};

/// PETSc's integer type (32-bit in Debian's build).
pub type PetscInt = sys::PetscInt;

/// A PETSc call that returned a non-zero error code.
#[derive(Debug, Clone, thiserror::Error)]
#[error("PETSc call {call} failed with error {code}: {message}")]
pub struct PetscError {
    pub call: &'static str,
    pub code: i32,
    pub message: String,
}

impl PetscError {
    /// An error of the Rust side around `call` (no PETSc code).
    pub fn new(call: &'static str, message: String) -> Self {
        PetscError {
            call,
            code: -1,
            message,
        }
    }
}

pub type Result<T> = std::result::Result<T, PetscError>;

/// Converts a PETSc error code into a `Result`, keeping the call's name.
pub(crate) fn check(call: &'static str, code: sys::PetscErrorCode) -> Result<()> {
    if code == 0 {
        return Ok(());
    }
    let mut text: *const std::os::raw::c_char = std::ptr::null();
    // SAFETY: PetscErrorMessage only writes a pointer to a static string table
    // entry (or leaves it null) for any integer code.
    unsafe {
        sys::PetscErrorMessage(code, &mut text, std::ptr::null_mut());
    }
    let class = if text.is_null() {
        "unknown error".to_owned()
    } else {
        // SAFETY: non-null pointers from PetscErrorMessage are NUL-terminated statics.
        unsafe { CStr::from_ptr(text) }
            .to_string_lossy()
            .into_owned()
    };
    // PETSc's own text says which value it refused; with it, the option.
    let message = match options::take_error_text(code) {
        Some(detail) => match options::option_named_by(&detail) {
            Some((key, value)) => format!("option {key} {value}: {detail} ({class})"),
            None => format!("{class}: {detail}"),
        },
        None => class,
    };
    Err(PetscError {
        call,
        code,
        message,
    })
}

/// Calls a raw PETSc function and turns its error code into a `PetscError`
/// that carries the function's name.
macro_rules! petsc_call {
    ($f:ident ( $($arg:expr),* $(,)? )) => {
        $crate::petsc::check(stringify!($f), $crate::petsc::sys::$f($($arg),*))
    };
}
pub(crate) use petsc_call;

/// Converts a count or index to PETSc's 32-bit integer, refusing overflow
/// (Debian's PETSc is built with 32-bit indices).
pub fn to_petsc_int(n: usize) -> Result<PetscInt> {
    PetscInt::try_from(n).map_err(|_| PetscError {
        call: "to_petsc_int",
        code: -1,
        message: format!("{n} does not fit PETSc's 32-bit PetscInt"),
    })
}

/// PETSc initialised on an MPI communicator; finalised on drop.
///
/// Must be dropped before rsmpi's `Universe` (which calls MPI_Finalize):
/// [`crate::runtime::Runtime`] holds both in that order.
pub struct PetscGuard {
    // PETSc keeps pointers into argv for its whole life.
    _args: Vec<CString>,
    _argv: Vec<*mut std::os::raw::c_char>,
}

impl PetscGuard {
    /// Initialises PETSc on `comm` with the given command-line style options
    /// (the program name first). PETSC_OPTIONS in the environment is read too.
    pub fn initialize(
        comm: &impl mpi::raw::AsRaw<Raw = mpi::ffi::MPI_Comm>,
        args: &[String],
    ) -> Result<Self> {
        let c_args: Vec<CString> = args
            .iter()
            .map(|a| {
                CString::new(a.as_str()).unwrap_or_else(|_| CString::new("?").expect("literal"))
            })
            .collect();
        let mut argv: Vec<*mut std::os::raw::c_char> =
            c_args.iter().map(|a| a.as_ptr() as *mut _).collect();
        argv.push(std::ptr::null_mut());
        let mut argc = (argv.len() - 1) as std::os::raw::c_int;
        let mut argv_ptr = argv.as_mut_ptr();
        // SAFETY: MPI is initialised (the communicator exists); PETSC_COMM_WORLD is
        // set before PetscInitialize as PETSc requires; argv outlives PETSc because
        // it is stored in the guard, and PETSc never writes through the strings.
        unsafe {
            sys::PETSC_COMM_WORLD = comm.as_raw();
            petsc_call!(PetscInitialize(
                &mut argc,
                &mut argv_ptr,
                std::ptr::null(),
                std::ptr::null()
            ))?;
            // Errors come back as codes to Rust instead of PETSc printing a
            // traceback: the Rust side reports them with context, and with
            // the message PETSc gave (kept by the handler).
            petsc_call!(PetscPushErrorHandler(
                Some(options::keep_error_text),
                std::ptr::null_mut()
            ))?;
        }
        Ok(PetscGuard {
            _args: c_args,
            _argv: argv,
        })
    }
}

impl Drop for PetscGuard {
    fn drop(&mut self) {
        // SAFETY: PETSc was initialised by `initialize`; all PETSc objects are owned
        // by values that borrow nothing from the guard but are dropped before it by
        // the runtime's field order.
        unsafe {
            sys::PetscFinalize();
        }
    }
}

/// The PETSc world communicator as a raw handle.
pub(crate) fn comm_world() -> sys::MPI_Comm {
    // SAFETY: PETSC_COMM_WORLD is written once before PetscInitialize and only read after.
    unsafe { sys::PETSC_COMM_WORLD }
}

/// This process's rank in PETSc's world communicator.
pub fn world_rank() -> Result<i32> {
    let mut r = 0;
    // SAFETY: valid communicator; out-pointer is a local.
    let code = unsafe { sys::MPI_Comm_rank(comm_world(), &mut r) };
    if code != 0 {
        return Err(PetscError::new("MPI_Comm_rank", format!("error {code}")));
    }
    Ok(r)
}

//! Named PETSc log stages, so `-log_view` tells where the time went.
use super::{petsc_call, PetscError, Result};
use std::ffi::CString;

#[derive(Debug, Clone, Copy)]
pub struct LogStage(super::sys::PetscLogStage);

impl LogStage {
    pub fn register(name: &str) -> Result<Self> {
        let n = CString::new(name).map_err(|_| PetscError {
            call: "PetscLogStageRegister",
            code: -1,
            message: "stage name contains NUL".into(),
        })?;
        let mut stage = -1;
        // SAFETY: valid C string and out-pointers; PETSc copies the name. A name
        // registered before (a second run in one process) is looked up, not
        // registered again, which PETSc rejects.
        unsafe {
            petsc_call!(PetscLogStageGetId(n.as_ptr(), &mut stage))?;
            if stage < 0 {
                petsc_call!(PetscLogStageRegister(n.as_ptr(), &mut stage))?;
            }
        }
        Ok(LogStage(stage))
    }

    /// Runs `f` inside this stage.
    pub fn scope<T>(self, f: impl FnOnce() -> T) -> T {
        // SAFETY: the stage was registered; push/pop are balanced around `f`.
        unsafe {
            super::sys::PetscLogStagePush(self.0);
        }
        let out = f();
        // SAFETY: balanced with the push above.
        unsafe {
            super::sys::PetscLogStagePop();
        }
        out
    }
}

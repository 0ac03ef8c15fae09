//! Process start-up and shut-down: MPI first, then PETSc on the same
//! communicator; PETSc finalised before MPI.
use crate::error::{Error, Result};
use crate::petsc::PetscGuard;
use mpi::topology::{Communicator, SimpleCommunicator};

/// Owns MPI and PETSc for the life of the program.
///
/// Field order matters: Rust drops fields in declaration order, and
/// PetscFinalize must run before rsmpi's Universe calls MPI_Finalize.
pub struct Runtime {
    _petsc: PetscGuard,
    universe: mpi::environment::Universe,
}

impl Runtime {
    /// `petsc_args` are PETSc options in command-line form (program name not
    /// included), e.g. `["-ksp_type", "cg"]`.
    pub fn start(petsc_args: &[String]) -> Result<Self> {
        // Before MPI and PETSc allocate (see `petsc::heap`).
        crate::petsc::heap::restore_malloc_defaults();
        let universe =
            mpi::initialize().ok_or_else(|| Error::Mpi("MPI was already initialised".into()))?;
        let world = universe.world();
        let mut args = vec!["contactlink".to_owned()];
        args.extend(petsc_args.iter().cloned());
        let petsc = PetscGuard::initialize(&world, &args)?;
        // After PETSc's start-up, which installs its own handlers: a
        // termination signal then ends the run at a step boundary.
        crate::petsc::signals::defer_termination(world.rank() == 0).map_err(|e| {
            let why = format!("cannot install the SIGTERM/SIGINT handler: {e}");
            Error::Io(std::io::Error::new(e.kind(), why))
        })?;
        // Set-up time counts from here: the scene, the mesh, the partition
        // and the matrix, not MPI's and PETSc's own start-up.
        crate::footprint::setup_started();
        crate::footprint::checkpoint("MPI and PETSc start-up");
        Ok(Runtime {
            _petsc: petsc,
            universe,
        })
    }

    pub fn world(&self) -> SimpleCommunicator {
        self.universe.world()
    }

    pub fn rank(&self) -> usize {
        self.universe.world().rank() as usize
    }

    pub fn size(&self) -> usize {
        self.universe.world().size() as usize
    }
}

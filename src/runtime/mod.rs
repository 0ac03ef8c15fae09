//! The process around a run: start-up and shut-down (MPI first, then
//! PETSc on the same communicator; PETSc finalised before MPI), the C heap's
//! settings (`heap`), the termination signals (`signals`) and the CPU clock
//! (`clock`).
//!
//! `runtime/` (process signals, malloc and the clock, through libc) and
//! `petsc/` (the PETSc and LAPACK bindings) are the only places with
//! `unsafe` code; each block says why it holds.
mod clock;
pub mod heap;
pub mod signals;

pub use clock::cpu_seconds;

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
        run_alone_without_a_daemon();
        // Before MPI and PETSc allocate (see `heap`).
        heap::restore_malloc_defaults();
        let universe =
            mpi::initialize().ok_or_else(|| Error::Mpi("MPI was already initialised".into()))?;
        let world = universe.world();
        let mut args = vec!["contactlink".to_owned()];
        args.extend(petsc_args.iter().cloned());
        let petsc = PetscGuard::initialize(&world, &args)?;
        // After PETSc's start-up, which installs its own handlers: a
        // termination signal then ends the run at a step boundary.
        signals::defer_termination(world.rank() == 0).map_err(|e| {
            let why = format!("cannot install the SIGTERM/SIGINT handler: {e}");
            Error::Io(std::io::Error::new(e.kind(), why))
        })?;
        // Set-up time counts from here: the scene, the mesh, the partition
        // and the matrix, not MPI's and PETSc's own start-up.
        crate::memory::setup_started();
        crate::memory::checkpoint("MPI and PETSc start-up");
        Ok(Runtime {
            _petsc: petsc,
            universe,
        })
    }

    /// The options given to this run (command line, PETSC_OPTIONS, a
    /// scene's `petsc_options`) that neither this program nor PETSc read on
    /// any rank (`petsc::options::unread`), as (name, value): rank 0's
    /// list, each kept if no rank read it. Collective; at the end of a run.
    pub fn unread_options(&self) -> Result<Vec<(String, String)>> {
        let world = self.world();
        let local = crate::petsc::options::unread().map_err(Error::from);
        let rank0 = crate::parallel::agree(&world, local)?;
        let text: String = rank0
            .iter()
            .map(|(k, v)| format!("{k}{FIELD}{v}{RECORD}"))
            .collect();
        let text = crate::parallel::broadcast_text(&world, 0, &text);
        let mut unread = Vec::new();
        for entry in text.split(RECORD).filter(|e| !e.is_empty()) {
            let (key, value) = entry.split_once(FIELD).unwrap_or((entry, ""));
            let here = crate::petsc::options::was_read(key).map_err(Error::from);
            let read_here = crate::parallel::agree(&world, here)?;
            if !crate::parallel::any_rank(&world, read_here) {
                unread.push((key.to_owned(), value.to_owned()));
            }
        }
        Ok(unread)
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

/// The separators of [`Runtime::unread_options`]'s broadcast: between an
/// option's name and value, and after each option (no option holds them).
const FIELD: char = '\u{1f}';
const RECORD: char = '\u{1e}';

/// A process started without a launcher (`contactlink run scene.toml`) is an
/// MPI singleton. Open MPI then forks a daemon (`orted`) for it, and its
/// message layer opens every network transport it has, two of which (the
/// PSM and PSM2 transports of Intel's InfiniBand and Omni-Path cards) spend
/// 0.1 s each timing the clock even where no such card exists: 0.12 s and
/// 0.2 s of a 0.54 s graded line run (b/5) on this machine kind. One process
/// talks to no one, so unless the user chose otherwise, Open MPI is told not
/// to start the daemon and to use its shared-memory/self layer (`ob1`).
/// Under mpirun, srun or any PMI launcher these settings are left unset.
fn run_alone_without_a_daemon() {
    const SETTINGS: [(&str, &str); 2] = [
        ("OMPI_MCA_ess_singleton_isolated", "1"),
        ("OMPI_MCA_pml", "ob1"),
    ];
    let launched = ["OMPI_COMM_WORLD_SIZE", "PMIX_RANK", "PMI_RANK"]
        .iter()
        .any(|v| std::env::var_os(v).is_some());
    if launched {
        return;
    }
    for (key, value) in SETTINGS {
        if std::env::var_os(key).is_none() {
            // Before MPI_Init and before any other thread exists.
            std::env::set_var(key, value);
        }
    }
}

//! One error type for the program. Every variant says what went wrong and
//! where (file, set, cell, step), so a user can act on it.
use crate::fem::FemError;
use crate::mesh::MeshError;
use crate::petsc::PetscError;

#[derive(Debug, thiserror::Error)]
pub enum Error {
    #[error(transparent)]
    Petsc(#[from] PetscError),
    #[error("mesh: {0}")]
    Mesh(#[from] MeshError),
    #[error("cell {cell}: {source}")]
    Element { cell: usize, source: FemError },
    #[error(
        "cell {cell} is inverted in the reference configuration (det J = {det_j:.3e} at quadrature point {qp}); check the mesh and its node order"
    )]
    InvertedCell { cell: usize, qp: usize, det_j: f64 },
    /// A result file could not be written or read. The cause is the output
    /// module's own error (it converts itself into this variant, so this
    /// module need not know its type).
    #[error("output: {0}")]
    Output(#[source] Box<dyn std::error::Error + Send + Sync + 'static>),
    #[error("scene {origin}: {message}")]
    Scene { origin: String, message: String },
    #[error("partition: {0}")]
    Partition(String),
    #[error("MPI: {0}")]
    Mpi(String),
    #[error(
        "load step {step} (load factor {load_factor:.6}): Newton did not converge after {cutbacks} cutbacks; last attempt: {reason}"
    )]
    NoConvergence {
        step: usize,
        load_factor: f64,
        cutbacks: usize,
        reason: String,
    },
    /// A result file that cannot be continued from (`run --restart`).
    #[error("restart: {0}")]
    Restart(String),
    #[error("{0}")]
    Io(#[from] std::io::Error),
    /// A failure one rank had, agreed by all ranks: every rank returns this,
    /// with the lowest failing rank's message.
    #[error("rank {rank}: {message}")]
    OnRank { rank: usize, message: String },
    /// A failure of work only rank 0 does (reading the mesh, resolving the
    /// scene against it), as every other rank holds it: rank 0's text.
    #[error("{0}")]
    Relayed(String),
    /// NaN or infinite values where a finite result was expected.
    #[error("non-finite values in the {0}")]
    NonFinite(String),
    /// SIGTERM or SIGINT reached a rank; all ranks stopped together at the
    /// end of a load step (every converged step is written).
    #[error(
        "stopped by {name} after load step {step} (load factor {load_factor:.6}); every converged step is written"
    )]
    Stopped {
        signal: i32,
        /// The signal's conventional name (`runtime::signals::name`).
        name: &'static str,
        step: usize,
        load_factor: f64,
    },
    /// A fault injected by `CONTACTLINK_FAULT` (tests only).
    #[error("injected fault at {0} (CONTACTLINK_FAULT)")]
    Fault(&'static str),
    /// A broken internal invariant (a bug, not bad input).
    #[error("internal error: {0}")]
    Internal(String),
}

pub type Result<T> = std::result::Result<T, Error>;

impl Error {
    pub fn scene(origin: impl Into<String>, message: impl Into<String>) -> Self {
        Error::Scene {
            origin: origin.into(),
            message: message.into(),
        }
    }
}

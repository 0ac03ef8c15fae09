//! contactlink: a parallel, PETSc-backed solver for 3D frictional contact
//! between deformable bodies (the ContactLink3D condition: surface-to-surface
//! augmented Lagrangian with Uzawa updates, finite deformation).
//!
//! The modules follow the data flow of a run:
//!
//! ```text
//! scene (TOML) ──► mesh (generators, sets) ──► distribution (METIS on rank 0, one piece per rank)
//!      ──► dofs (owned/ghost, PETSc numbering)
//!      ──► fem (element kernels) ──► assembly (into PETSc Mat/Vec) ──► solve (load steps → SNES Newton)
//!      ──► output (parallel HDF5 + XDMF)
//! ```
//!
//! `model` is the problem as plain data between `scene` and `solve` (a program
//! may build it in code instead of reading a scene).
//! `parallel` is where rank-local outcomes become one decision of all ranks.
//! `linsolve` holds the linear solves `solve` adds to PETSc's own (the
//! contact Schur path, condensed Newton).
//! `pipeline` strings these together for one run; `petsc` and `runtime` are
//! the only places that touch C libraries directly.
pub mod amplitude;
pub mod assembly;
pub mod check;
pub mod contact;
pub mod distribution;
pub mod dofs;
pub mod error;
pub mod exchange;
pub mod fem;
pub mod hertz;
pub mod linsolve;
pub mod memory;
pub mod mesh;
pub mod model;
pub mod output;
pub mod parallel;
pub mod partition;
pub mod petsc;
pub mod pipeline;
pub mod restart;
pub mod results;
pub mod runtime;
pub mod scene;
pub mod setup_only;
pub mod solve;
pub mod vec3;

pub use error::{Error, Result};

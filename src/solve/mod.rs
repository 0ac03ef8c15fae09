//! The solution procedure. A run is a sequence of load steps
//! (`driver.rs`); in each, the contact search finds every slave point's
//! master facet, then the Uzawa loop (`uzawa.rs`) alternates Newton (PETSc
//! SNES, on the residual and Jacobian of `mechanics.rs`) with the contact
//! multipliers fixed and a multiplier update, until every pair meets its
//! tolerances. A step whose Newton or Uzawa loop fails is cut back and
//! retried; converged steps go to a `StepSink` (`report.rs`).
//!
//! This module sits above `assembly` and `contact`: they know nothing of
//! SNES, and only this module calls the solver.
mod anderson;
pub mod boundary;
mod driver;
pub mod dynamics;
mod failure;
pub mod lagging;
mod master_tail;
pub mod mechanics;
pub mod natural;
pub mod newmark;
pub mod phases;
mod predictor;
mod reactions;
mod report;
mod restart_state;
mod setup;
mod start;
mod state_change;
pub mod stiffness;
pub mod tolerance;
mod uzawa;

pub use crate::linsolve::SchurSummary;
pub use boundary::Dirichlet;
pub use driver::Simulation;
pub use dynamics::DynamicsReport;
pub use mechanics::Mechanics;
pub use natural::NaturalOrder;
pub use report::{ContactReport, PairFields, RunReport, StepReport, StepSink};
pub use restart_state::RestartState;

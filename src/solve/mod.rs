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
pub mod boundary;
mod driver;
pub mod dynamics;
mod failure;
pub mod lagging;
pub mod mechanics;
pub mod natural;
pub mod newmark;
pub mod phases;
mod predictor;
mod reactions;
mod report;
mod restart_state;
mod setup;
pub mod tolerance;
mod uzawa;

pub use boundary::{Dirichlet, DirichletSpec};
pub use driver::Simulation;
pub use dynamics::{DynamicsReport, DynamicsSpec};
pub use mechanics::Mechanics;
pub use natural::NaturalOrder;
pub use report::{ContactReport, PairFields, RunReport, StepReport, StepSink};
pub use restart_state::RestartState;

use crate::assembly::FacetLoad;
use crate::contact::PairSpec;
use crate::fem::Material;
use crate::mesh::Mesh;

/// Newton and load-stepping settings.
#[derive(Debug, Clone)]
pub struct SolverSettings {
    pub max_newton: usize,
    pub rtol: f64,
    /// Absolute residual tolerance; None: rtol × the residual at the start of
    /// each load step (the step's own force scale), so small loads and large
    /// ones converge alike, and Uzawa's follow-up solves stay as tight.
    pub atol: Option<f64>,
    /// Models with at most this many DOFs default to a parallel direct solver
    /// (MUMPS LU), robust for stiff contact penalties; larger ones to
    /// Krylov + algebraic multigrid.
    pub direct_max_dofs: usize,
    pub max_cutbacks: usize,
    /// PETSc options (defaults that the command line and PETSC_OPTIONS override).
    pub petsc_options: String,
    /// What is computed once and reused (all on by default; switches exist
    /// to measure each saving).
    pub reuse: Reuse,
    /// Start each load step from the last two converged steps extrapolated
    /// to the new load, instead of from the last one. Off by default: it
    /// saves Newton iterations on smooth load paths (block-slide 60 → 51)
    /// but costs them where the contact set changes between steps
    /// (hertz-cylinder 23 → 24, and a cutback with the l2 line search).
    pub extrapolate: bool,
    /// Newton inside a non-final Uzawa iteration stops once its residual
    /// fell by this factor (see `tolerance`); 0: every solve to the final
    /// tolerance.
    pub uzawa_forcing: f64,
}

/// Work a run reuses instead of redoing.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Reuse {
    /// Linear-elastic bulk stiffness assembled once (residual = K u − f).
    pub linear_stiffness: bool,
    /// Jacobian sparsity pattern kept while the contact couplings are unchanged.
    pub pattern: bool,
    /// Preconditioner (LU factors) of an Uzawa iteration's first solve kept
    /// for the following ones.
    pub preconditioner: bool,
    /// Preconditioner rebuilt only when the contact active set changed
    /// (within Newton too), see `lagging`; off: rebuilt every Newton
    /// iteration of a step's first Uzawa iteration.
    pub active_set: bool,
}

impl Default for Reuse {
    fn default() -> Self {
        Reuse {
            linear_stiffness: true,
            pattern: true,
            preconditioner: true,
            active_set: true,
        }
    }
}

impl Default for SolverSettings {
    fn default() -> Self {
        SolverSettings {
            max_newton: 30,
            rtol: 1e-9,
            atol: None,
            direct_max_dofs: 20_000,
            max_cutbacks: 8,
            petsc_options: String::new(),
            reuse: Reuse::default(),
            extrapolate: false,
            uzawa_forcing: tolerance::DEFAULT_FORCING,
        }
    }
}

/// A vector field of the reference position, b(X).
pub type VectorField = Box<dyn Fn([f64; 3]) -> [f64; 3]>;

/// A fully resolved problem: mesh, materials per body, conditions, contact, steps.
pub struct Model {
    pub name: String,
    pub mesh: Mesh,
    /// Material of each body, indexed like `mesh.bodies`.
    pub materials: Vec<Material>,
    pub dirichlet: Vec<DirichletSpec>,
    /// (facet set name, load at full amplitude, amplitude).
    pub facet_loads: Vec<(String, FacetLoad, crate::amplitude::Amplitude)>,
    /// Body force per body (per unit reference volume) at full load.
    pub body_force: Vec<[f64; 3]>,
    /// A spatially varying body force b(X) at full load (manufactured solutions).
    pub body_force_fn: Option<VectorField>,
    pub contact: Vec<PairSpec>,
    /// Compare a pair against Hertz after each step.
    pub hertz: Option<crate::verify::HertzCheck>,
    pub steps: usize,
    pub solver: SolverSettings,
    /// Implicit dynamics (None: quasi-static load stepping).
    pub dynamics: Option<DynamicsSpec>,
}

impl Model {
    /// Legal but risky choices, for the user to see before a long run.
    pub fn warnings(&self) -> Vec<String> {
        let mut w = Vec::new();
        if let Some(d) = &self.dynamics {
            if !self.contact.is_empty() && d.newmark.gamma <= 0.5 + 1e-12 {
                w.push(format!(
                    "[dynamics] γ = {} with contact: the trapezoidal rule has no numerical damping and its acceleration memory can create energy whenever contact opens (measured: +186 % on the impact scene); beta = 0.5, gamma = 1.0 never creates energy there",
                    d.newmark.gamma
                ));
            }
        }
        w
    }
}

//! The plain problem data a run solves: mesh, materials, conditions, contact
//! pairs, dynamics and solver settings, as `scene` builds them (or a program
//! sets them up directly). Nothing here knows how the problem is solved; the
//! solver, assembly and contact modules read these types.
//!
//! - `conditions`: Dirichlet conditions and facet loads;
//! - `contact`: what a pair states (surfaces, rigid masters, friction, tolerances);
//! - `dynamics`: implicit dynamics and the Newmark parameters;
//! - `solver`: Newton, load-stepping and reuse settings;
//! - `wire`: a model without its mesh as words for one broadcast.
pub mod conditions;
pub mod contact;
pub mod dynamics;
pub mod solver;
pub mod wire;

pub use conditions::{DirichletSpec, FacetLoad};
pub use contact::{Formulation, FrictionSpec, MasterSpec, PairSpec, RigidSurface, SlaveQuadrature};
pub use dynamics::{DynamicsSpec, Newmark};
pub use solver::{Reuse, SolverSettings, DEFAULT_ACCELERATION, DEFAULT_FORCING, MAX_ACCELERATION};

use crate::amplitude::Amplitude;
use crate::fem::{Integration, Material};
use crate::hertz::HertzCheck;
use crate::mesh::Mesh;

/// A vector field of the reference position, b(X).
pub type VectorField = Box<dyn Fn([f64; 3]) -> [f64; 3]>;

/// A fully resolved problem: mesh, materials per body, conditions, contact, steps.
pub struct Model {
    pub name: String,
    /// The global mesh. A scene's run holds it on rank 0 only, and only
    /// until the set-up has cut it into pieces: on the other ranks, and
    /// after [`Model::take_mesh`], it is empty (its cell type kept).
    pub mesh: Mesh,
    /// Material of each body, indexed like `mesh.bodies`.
    pub materials: Vec<Material>,
    /// Stiffness integration of each body, indexed like `mesh.bodies`.
    pub integration: Vec<Integration>,
    pub dirichlet: Vec<DirichletSpec>,
    /// (facet set name, load at full amplitude, amplitude).
    pub facet_loads: Vec<(String, FacetLoad, Amplitude)>,
    /// Body force per body (per unit reference volume) at full load.
    pub body_force: Vec<[f64; 3]>,
    /// A spatially varying body force b(X) at full load (manufactured solutions).
    pub body_force_fn: Option<VectorField>,
    pub contact: Vec<PairSpec>,
    /// Compare a pair against Hertz after each step.
    pub hertz: Option<HertzCheck>,
    pub steps: usize,
    pub solver: SolverSettings,
    /// Implicit dynamics (None: quasi-static load stepping).
    pub dynamics: Option<DynamicsSpec>,
}

impl Model {
    /// Moves the mesh out, leaving an empty mesh of the same cell type: a run
    /// hands the mesh to the set-up, which frees it once the pieces are cut.
    pub fn take_mesh(&mut self) -> Mesh {
        let empty = Mesh::empty(self.mesh.cell_type);
        std::mem::replace(&mut self.mesh, empty)
    }

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

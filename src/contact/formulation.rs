//! The seam between the solver and a contact formulation: every duty the
//! solver asks of a pair, whatever the formulation. A formulation is one
//! module implementing [`Formulation`] (`links`: one link per slave
//! quadrature point; `mortar`: dual multipliers at the slave nodes) plus
//! one arm in `ContactPair::new`; the solver talks to
//! [`super::pair::ContactPair`] only and names no formulation.
//!
//! The duties, in the order a load step meets them: the master exchange
//! and the search (start of a step); the Jacobian pattern, residual and
//! tangent (each Newton iteration); the Uzawa update and what the Uzawa
//! loop reads of it (after each Newton solve); commit, snapshot and
//! restore (end of a step, cutbacks); restart rows and output fields
//! (result file). Everything is this rank's part; the caller reduces over
//! ranks.
use super::fields::{PairOutput, RestartRequest, RestartRows};
use super::outcome::UzawaStats;
use super::surfaces::SlaveSurface;
use crate::assembly::{HaloFactory, MatrixSink, PatternSink, RankExchange};
use crate::distribution::{LocalMesh, SlaveSetPiece};
use crate::dofs::{DofMap, GlobalDof};
use crate::error::Result;
use crate::model::PairSpec;
use std::any::Any;

/// What a formulation is built from on one rank.
pub struct PairSetup<'a> {
    pub mesh: &'a LocalMesh,
    pub dofs: &'a DofMap,
    pub spec: &'a PairSpec,
    /// The slave set beyond this rank's facets (owners, ghost facets).
    pub slave_piece: &'a SlaveSetPiece,
    /// Young's modulus of the softest body (the default penalty's scale).
    pub softest_youngs: f64,
    pub search_distance: f64,
    pub halos: &'a dyn HaloFactory,
    pub ranks: &'a dyn RankExchange,
}

/// Dynamics: the time integrator's velocity, affine in the displacement,
/// `v = dv_du · u + offset` (local form, per DOF), for the slip rate.
#[derive(Debug, Clone)]
pub struct SlipRate {
    pub dt: f64,
    pub dv_du: f64,
    pub offset: Vec<f64>,
    /// Velocity of a rigid master (its motion per unit time).
    pub rigid_velocity: [f64; 3],
}

/// The state a pair is evaluated at: the extended local displacement
/// (local nodes, then the tail of held nodes), the load factor, and in
/// dynamics the slip rate.
#[derive(Clone, Copy)]
pub struct At<'a> {
    pub u: &'a [f64],
    pub factor: f64,
    pub rate: Option<&'a SlipRate>,
}

/// What the solver's choices depend on, per formulation.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Traits {
    /// The tangent is symmetric (the Hessian of a potential).
    pub symmetric_tangent: bool,
    /// Newton converges in one or two iterations per Uzawa iteration only
    /// when the linear solves are accurate: a Krylov path keeps a fixed,
    /// tight linear tolerance instead of Eisenstat–Walker's.
    pub accurate_linear_solves: bool,
    /// Newton steps may end where a constraint changes between open and
    /// closed (`state_change_fraction`).
    pub state_change_steps: bool,
    /// What the Uzawa statistics count ("points", "nodes").
    pub unit: &'static str,
}

/// A pair's constraints at an iterate, for a failed solve's report.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct Census {
    pub pressed: usize,
    pub sliding: usize,
    pub max_penetration: f64,
}

/// The held master facets of a deformable master, for the step report.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct HeldFacets {
    /// Held now on this rank ...
    pub held: usize,
    /// ... of the whole master set ...
    pub whole: usize,
    /// ... of them received at the last exchange.
    pub received: usize,
}

/// A pair's multipliers and history as they were, for a cutback to go
/// back to; only the formulation that took it can read it.
pub struct PairSnapshot(pub Box<dyn Any>);

/// One contact formulation at run time, as one rank holds it.
pub trait Formulation {
    /// The slave surface's facets and points of this rank.
    fn slave(&self) -> &SlaveSurface;
    fn traits(&self) -> Traits;
    fn has_friction(&self) -> bool;

    /// Before the step's search: the exchange that decides which master
    /// facets (and nodes other ranks own) this rank holds; `tail_base` is
    /// the first tail slot the pair may use; returns how many it uses.
    /// Collective.
    fn exchange_master(
        &mut self,
        u_local: &[f64],
        dofs: &DofMap,
        tail_base: usize,
        ranks: &dyn RankExchange,
    ) -> usize;
    /// Global DOFs of the tail's nodes, node-major.
    fn master_tail(&self) -> &[GlobalDof];
    /// Held facets of a deformable master (None: rigid master).
    fn held_facets(&self) -> Option<HeldFacets>;
    /// The search that starts a load step (`motion`: the step's largest
    /// prescribed displacement); true when the couplings changed.
    fn search(&mut self, at: &At, motion: f64) -> bool;
    /// Whether the step's search still covers the state `at`.
    fn covers(&self, at: &At) -> bool;
    /// DOFs to keep among the contact DOFs beyond the pattern's.
    fn reserve_dofs(&self) -> Vec<GlobalDof>;
    /// Whether the step's slip is measured from the committed state given
    /// to `start_slip_from` (with the restart's `committed_origins`).
    fn measures_slip_from_committed(&self) -> bool;
    fn committed_origins(&self) -> Vec<(u32, [f64; 3])>;
    fn start_slip_from(&mut self, u_committed: &[f64]);

    fn add_pattern(&self, pattern: &mut dyn PatternSink) -> Result<()>;
    /// Adds the contact residual into the local-form array.
    fn add_residual(&mut self, at: &At, r_local: &mut [f64]) -> Result<()>;
    /// Adds the tangent into `k` (not assembled).
    fn add_tangent(&mut self, at: &At, k: &mut dyn MatrixSink) -> Result<()>;
    /// A hash of the active set the last tangent was assembled with: equal
    /// values mean the same tangent structure.
    fn tangent_signature(&self) -> u64;
    /// Whether the tangent keeps only its main part (the residual is the
    /// same); a step's first contact from none uses it.
    fn set_main_part_tangent(&mut self, on: bool);

    /// The Uzawa update of the multipliers at the solved state.
    fn uzawa_update(&mut self, at: &At) -> Result<UzawaStats>;
    /// The constraints at `at` as the update would find them, nothing changed.
    fn census(&mut self, at: &At) -> Result<Census>;
    /// One clause of a failure message about the census (over all ranks).
    fn describe_census(&self, pair: &str, c: &Census) -> String;
    /// The fraction of the way from `u0` to `at` at which the last
    /// constraint changing between open and closed changes (None: none).
    fn state_change_fraction(&self, u0: &[f64], at: &At) -> Option<f64>;
    /// Multiplies every penalty the formulation stores by `factor` (the
    /// tangential one when it follows the normal one).
    fn scale_penalty(&mut self, factor: f64);
    /// The normal multipliers an accelerated Uzawa update works on and
    /// whether each is counted here (None: not accelerated, friction).
    fn normal_multipliers(&self) -> Option<(Vec<f64>, Vec<bool>)>;
    fn set_normal_multipliers(&mut self, lambda: &[f64]) -> Result<()>;
    /// This rank's constraints in contact and, of those, sliding.
    fn multiplier_states(&self) -> (usize, usize);

    /// A converged step is final: the next one measures slip from here.
    fn commit(&mut self) -> Result<()>;
    fn snapshot(&self) -> PairSnapshot;
    fn restore(&mut self, snap: PairSnapshot) -> Result<()>;

    /// The fields and rows a restart reads for this rank.
    fn restart_request(&self) -> RestartRequest;
    /// Takes a step over from the rows `restart_request` asked for, then
    /// commits it.
    fn restart_from(&mut self, rows: &RestartRows) -> Result<()>;

    /// The fields of a converged step (the multipliers after a converged
    /// Uzawa loop are the pressures).
    fn output(&mut self, at: &At) -> Result<PairOutput>;
    /// Adds the nodal contact pressure of the owned nodes (indexed by owned
    /// local node; the denominator counts the pairs).
    fn add_nodal_pressure(&self, numerator: &mut [f64], denominator: &mut [f64]) -> Result<()>;
    /// Halo exchanges of the multipliers: seconds spent, and ghost values.
    fn multiplier_halo(&self) -> (f64, usize);
}

/// The error of a snapshot given to a formulation that did not take it.
pub fn foreign_snapshot() -> crate::error::Error {
    crate::error::Error::Internal("a contact snapshot restored into another formulation".into())
}

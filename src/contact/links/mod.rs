//! The links formulation (ContactLink3D, docs/formulation.md §2–§6): one
//! link per slave quadrature point, each a slave point and its closest
//! point on the master, with a multiplier λN (and with friction λT and a
//! slip history) per point. Its duties, by concept:
//! - `link`: the links of a load step ([`Link`]), the master exchange, the
//!   step's search and the following of sliding;
//! - `assemble`: the Jacobian pattern, residual and tangent of the links;
//! - `kernel`: one link's gap, pressure, friction, residual and exact tangent;
//! - `multipliers`: λN and the friction state per point, and their halo;
//! - `slip_history`: each point's friction history on its current master
//!   facet (carried over when a link changes facet);
//! - `uzawa`: the multiplier update;
//! - `restart`: cutback snapshots, step commit, restart rows;
//! - `output`: the point and nodal fields of the result file.
mod assemble;
pub mod kernel;
mod link;
pub mod multipliers;
mod output;
mod restart;
mod slip_history;
mod uzawa;

pub use link::Link;

use super::fields::{PairOutput, RestartRequest, RestartRows};
use super::formulation::{At, Census, Formulation, HeldFacets, PairSetup, PairSnapshot, Traits};
use super::master::MasterSide;
use super::outcome::UzawaStats;
use super::penalty;
use super::surfaces::SlaveSurface;
use crate::assembly::{MatrixSink, PatternSink, RankExchange};
use crate::dofs::{DofMap, GlobalDof};
use crate::error::Result;
use multipliers::Multipliers;

/// Friction of a links pair: μ and εT per slave facet, and whether εT
/// follows εN (no `tangential_penalty` given: raised with it).
struct PairFriction {
    mu: f64,
    penalty: Vec<f64>,
    follows: bool,
}

/// A links pair at run time, as one rank holds it.
pub struct LinksPair {
    name: String,
    slave: SlaveSurface,
    master: MasterSide,
    multipliers: Multipliers,
    /// εN per slave facet: the user's, or the default for the facet's own
    /// element size (a graded mesh gets a local penalty).
    facet_penalty: Vec<f64>,
    friction: Option<PairFriction>,
    search_distance: f64,
    links: Vec<Link>,
    pattern_key: u64,
    /// Master node positions of the last evaluation (deformable masters).
    positions: Vec<[f64; 3]>,
    /// See `tangent_signature`.
    tangent_signature: u64,
    /// See `set_main_part_tangent`.
    main_part_tangent: bool,
}

impl LinksPair {
    /// Collective (the multipliers' halos).
    pub fn new(s: &PairSetup, slave: SlaveSurface, master: MasterSide) -> Result<Self> {
        let spec = s.spec;
        let rule = spec.quadrature.rule(slave.facet_type);
        let friction_spec = spec.active_friction();
        let multipliers = Multipliers::new(
            s.dofs,
            s.slave_piece,
            &slave,
            &rule,
            friction_spec.is_some(),
            s.halos,
        )?;
        let facet_penalty: Vec<f64> = slave
            .facets
            .iter()
            .map(|f| penalty::default_normal(spec.penalty, s.softest_youngs, f.h))
            .collect();
        let friction = friction_spec.map(|f| PairFriction {
            mu: f.mu,
            penalty: match f.penalty {
                Some(p) => vec![p; slave.facets.len()],
                None => facet_penalty.clone(),
            },
            follows: f.penalty.is_none(),
        });
        Ok(LinksPair {
            name: spec.name.clone(),
            slave,
            master,
            multipliers,
            facet_penalty,
            friction,
            search_distance: s.search_distance,
            links: Vec::new(),
            pattern_key: 0,
            positions: Vec::new(),
            tangent_signature: 0,
            main_part_tangent: false,
        })
    }

    pub fn links(&self) -> &[Link] {
        &self.links
    }
}

impl Formulation for LinksPair {
    fn slave(&self) -> &SlaveSurface {
        &self.slave
    }

    /// Frictionless links are the Hessian of a potential: symmetric.
    fn traits(&self) -> Traits {
        Traits {
            symmetric_tangent: self.friction.is_none(),
            accurate_linear_solves: false,
            state_change_steps: false,
            unit: "points",
        }
    }

    fn has_friction(&self) -> bool {
        self.friction.is_some()
    }

    fn exchange_master(
        &mut self,
        u_local: &[f64],
        dofs: &DofMap,
        tail_base: usize,
        ranks: &dyn RankExchange,
    ) -> usize {
        self.exchange(u_local, dofs, tail_base, ranks)
    }

    fn master_tail(&self) -> &[GlobalDof] {
        match &self.master {
            MasterSide::Facets(m) => &m.tail_dofs,
            MasterSide::Rigid(_) => &[],
        }
    }

    fn held_facets(&self) -> Option<HeldFacets> {
        match &self.master {
            MasterSide::Facets(m) => Some(HeldFacets {
                held: m.set_index.len(),
                whole: m.whole,
                received: m.received,
            }),
            MasterSide::Rigid(_) => None,
        }
    }

    fn search(&mut self, at: &At, _motion: f64) -> bool {
        self.search_links(at.u, at.factor)
    }

    /// The links' search distance (ten element sizes, at least a tenth of
    /// the master's extent) is their margin: they are taken as covered.
    fn covers(&self, _at: &At) -> bool {
        true
    }

    /// None: the pattern already spans the search distance.
    fn reserve_dofs(&self) -> Vec<GlobalDof> {
        Vec::new()
    }

    /// The links measure slip from their own history.
    fn measures_slip_from_committed(&self) -> bool {
        false
    }

    fn committed_origins(&self) -> Vec<(u32, [f64; 3])> {
        Vec::new()
    }

    fn start_slip_from(&mut self, _u_committed: &[f64]) {}

    fn add_pattern(&self, pattern: &mut dyn PatternSink) -> Result<()> {
        self.pattern(pattern)
    }

    fn add_residual(&mut self, at: &At, r_local: &mut [f64]) -> Result<()> {
        self.residual(at, r_local)
    }

    fn add_tangent(&mut self, at: &At, k: &mut dyn MatrixSink) -> Result<()> {
        self.tangent(at, k)
    }

    fn tangent_signature(&self) -> u64 {
        self.tangent_signature
    }

    /// The frictionless links' tangent keeps only its main part (see
    /// `kernel::LinkInput::main_part_tangent`); friction ignores it.
    fn set_main_part_tangent(&mut self, on: bool) {
        self.main_part_tangent = on;
    }

    fn uzawa_update(&mut self, at: &At) -> Result<UzawaStats> {
        self.update(at)
    }

    fn census(&mut self, at: &At) -> Result<Census> {
        Ok(self.link_census(at))
    }

    fn describe_census(&self, pair: &str, c: &Census) -> String {
        let sticking = c.pressed - c.sliding.min(c.pressed);
        format!(
            "links of pair '{pair}' at the failing iterate: {} pressed together (gap < 0 or λN > 0), {} sliding, {sticking} sticking, max penetration {:.3e}",
            c.pressed, c.sliding, c.max_penetration
        )
    }

    fn state_change_fraction(&self, _u0: &[f64], _at: &At) -> Option<f64> {
        None
    }

    fn scale_penalty(&mut self, factor: f64) {
        self.facet_penalty.iter_mut().for_each(|p| *p *= factor);
        if let Some(f) = self.friction.as_mut().filter(|f| f.follows) {
            f.penalty.iter_mut().for_each(|p| *p *= factor);
        }
    }

    /// λN of every owned point (all counted); None with friction, whose
    /// update also classifies stick and slip from the solved state.
    fn normal_multipliers(&self) -> Option<(Vec<f64>, Vec<bool>)> {
        if self.friction.is_some() {
            return None;
        }
        let lambda = self.multipliers.lambda.clone();
        let owned = vec![true; lambda.len()];
        Some((lambda, owned))
    }

    fn set_normal_multipliers(&mut self, lambda: &[f64]) -> Result<()> {
        self.set_lambda(lambda)
    }

    fn multiplier_states(&self) -> (usize, usize) {
        self.states()
    }

    fn commit(&mut self) -> Result<()> {
        self.commit_step()
    }

    fn snapshot(&self) -> PairSnapshot {
        PairSnapshot(Box::new(self.take_snapshot()))
    }

    fn restore(&mut self, snap: PairSnapshot) -> Result<()> {
        let snap = snap
            .0
            .downcast()
            .map_err(|_| super::formulation::foreign_snapshot())?;
        self.restore_snapshot(*snap)
    }

    fn restart_request(&self) -> RestartRequest {
        self.request()
    }

    fn restart_from(&mut self, rows: &RestartRows) -> Result<()> {
        self.take_over(rows)
    }

    fn output(&mut self, at: &At) -> Result<PairOutput> {
        self.fields(at)
    }

    fn add_nodal_pressure(&self, numerator: &mut [f64], denominator: &mut [f64]) -> Result<()> {
        self.multipliers.add_nodal_pressure(numerator, denominator)
    }

    fn multiplier_halo(&self) -> (f64, usize) {
        (
            self.multipliers.exchange_seconds,
            self.multipliers.ghost_values(),
        )
    }
}

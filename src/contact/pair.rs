//! A contact pair at run time ([`ContactPair`]): what the solver holds of a
//! pair on one rank. It keeps what every formulation shares (the pair's
//! specification, its penalty as reported and the force floor of its Uzawa
//! test, the slip rate in dynamics) and hands every duty to its
//! formulation (see [`super::formulation`]).
use super::fields::{PairOutput, RestartRequest, RestartRows};
use super::formulation::{
    At, Census, Formulation, HeldFacets, PairSetup, PairSnapshot, SlipRate, Traits,
};
use super::links::LinksPair;
use super::master::MasterSide;
use super::mortar::MortarPair;
use super::outcome::UzawaStats;
use super::penalty;
use super::surfaces::{self, SlaveSurface};
use crate::assembly::{HaloFactory, MatrixSink, PatternSink, RankExchange};
use crate::distribution::{LocalMesh, SlaveSetPiece};
use crate::dofs::{DofMap, GlobalDof};
use crate::error::{Error, Result};
use crate::hertz::{facet_samples, NodalSample};
use crate::model::{self, PairSpec};

pub struct ContactPair {
    pub spec: PairSpec,
    /// The pair's penalty as reported: the user's εN, or the default for
    /// the slave surface's mean element size (each facet or node uses its
    /// own size), times every raise so far.
    penalty: f64,
    /// The smallest nodal force the Uzawa test resolves (see
    /// [`ContactPair::force_floor`]), measured with the penalty the pair
    /// was built with, so that raising or softening the penalty does not
    /// move the test's resolution.
    force_floor: f64,
    /// Dynamics: the slip rate of the current time step (None: quasi-static).
    rate: Option<SlipRate>,
    formulation: Box<dyn Formulation>,
}

impl ContactPair {
    /// Resolves a pair on this rank. `slave_piece` is what the rank holds of
    /// the slave set beyond its own facets (every facet's owner, the mean
    /// edge, ghost facets); `softest_youngs` sets the default penalty.
    /// Collective.
    pub fn new(
        mesh: &LocalMesh,
        dofs: &DofMap,
        slave_piece: &SlaveSetPiece,
        spec: &PairSpec,
        softest_youngs: f64,
        halos: &dyn HaloFactory,
        ranks: &dyn RankExchange,
    ) -> Result<Self> {
        let rule = spec
            .quadrature
            .rule(surfaces::contact_facet_type(mesh, &spec.slave)?);
        let slave = SlaveSurface::new(mesh, dofs, &spec.slave, slave_piece, &rule)?;
        let master = MasterSide::new(mesh, dofs, spec, ranks)?;
        let penalty = penalty::default_normal(spec.penalty, softest_youngs, slave.h);
        if !(penalty.is_finite() && penalty > 0.0) {
            return Err(Error::scene(
                "contact",
                format!(
                    "pair '{}': penalty must be positive (got {penalty})",
                    spec.name
                ),
            ));
        }
        let h = slave.h;
        let search_distance = spec
            .search_distance
            .unwrap_or_else(|| master.default_search_distance(mesh, h));
        let setup = PairSetup {
            mesh,
            dofs,
            spec,
            slave_piece,
            softest_youngs,
            search_distance,
            halos,
            ranks,
        };
        let formulation: Box<dyn Formulation> = match spec.formulation {
            model::Formulation::Links => Box::new(LinksPair::new(&setup, slave, master)?),
            model::Formulation::Mortar => Box::new(MortarPair::new(&setup, slave, master)?),
        };
        Ok(ContactPair {
            spec: spec.clone(),
            penalty,
            force_floor: penalty * spec.penetration_tol * h * h * h,
            rate: None,
            formulation,
        })
    }

    fn at<'a>(&'a self, u: &'a [f64], factor: f64) -> At<'a> {
        At {
            u,
            factor,
            rate: self.rate.as_ref(),
        }
    }

    pub fn name(&self) -> &str {
        &self.spec.name
    }

    pub fn traits(&self) -> Traits {
        self.formulation.traits()
    }

    pub fn has_friction(&self) -> bool {
        self.formulation.has_friction()
    }

    pub fn tangent_is_symmetric(&self) -> bool {
        self.traits().symmetric_tangent
    }

    /// The slave surface's facets and points of this rank.
    pub fn slave(&self) -> &SlaveSurface {
        self.formulation.slave()
    }

    /// The penalty as reported (see the field).
    pub fn penalty(&self) -> f64 {
        self.penalty
    }

    /// The smallest nodal force the Uzawa test resolves: the force of a
    /// penetration at the tolerance on one facet (εN · tol·h · h²). Below it
    /// a change in the multipliers cannot move the solution by more than the
    /// penetration tolerance already allows, so a near-empty contact (a
    /// grazing touch) is not iterated to relative precision.
    pub fn force_floor(&self) -> f64 {
        self.force_floor
    }

    /// The pair's Uzawa test: penetration and multiplier change within its
    /// tolerances.
    pub fn uzawa_converged(&self, s: &UzawaStats) -> bool {
        s.max_penetration <= self.spec.penetration_tol
            && s.max_change <= self.spec.multiplier_tol * s.max_force.max(self.force_floor)
    }

    /// What the penalty policy reads of one Uzawa update (see
    /// `penalty::StepPenalties`).
    pub fn progress(&self, s: &UzawaStats) -> penalty::PairProgress {
        penalty::PairProgress {
            converged: self.uzawa_converged(s),
            relative_change: s.max_change / s.max_force.max(self.force_floor),
            tolerance: self.spec.multiplier_tol,
            frictional: self.has_friction(),
        }
    }

    /// Multiplies the penalty by `factor` (the tangential one too when it
    /// follows the normal one); the multipliers are kept.
    pub fn raise_penalty(&mut self, factor: f64) {
        self.penalty *= factor;
        self.formulation.scale_penalty(factor);
    }

    /// The prescribed translation of a rigid master at load factor
    /// `factor` (its `motion` times its amplitude).
    pub fn rigid_shift(&self, factor: f64) -> [f64; 3] {
        let a = self.spec.motion_amplitude.at(factor);
        self.spec.motion.map(|c| c * a)
    }

    /// Dynamics: the slip rate of the time step (None quasi-static).
    pub fn set_slip_rate(&mut self, rate: Option<SlipRate>) {
        self.rate = rate;
    }

    pub fn slip_rate_mut(&mut self) -> Option<&mut SlipRate> {
        self.rate.as_mut()
    }

    pub fn exchange_master(
        &mut self,
        u_local: &[f64],
        dofs: &DofMap,
        tail_base: usize,
        ranks: &dyn RankExchange,
    ) -> usize {
        self.formulation
            .exchange_master(u_local, dofs, tail_base, ranks)
    }

    pub fn master_tail(&self) -> &[GlobalDof] {
        self.formulation.master_tail()
    }

    pub fn held_facets(&self) -> Option<HeldFacets> {
        self.formulation.held_facets()
    }

    pub fn search(&mut self, u_local: &[f64], factor: f64, motion: f64) -> bool {
        let at = At {
            u: u_local,
            factor,
            rate: self.rate.as_ref(),
        };
        self.formulation.search(&at, motion)
    }

    pub fn covers(&self, u_local: &[f64], factor: f64) -> bool {
        self.formulation.covers(&self.at(u_local, factor))
    }

    pub fn reserve_dofs(&self) -> Vec<GlobalDof> {
        self.formulation.reserve_dofs()
    }

    pub fn measures_slip_from_committed(&self) -> bool {
        self.formulation.measures_slip_from_committed()
    }

    pub fn committed_origins(&self) -> Vec<(u32, [f64; 3])> {
        self.formulation.committed_origins()
    }

    pub fn start_slip_from(&mut self, u_committed: &[f64]) {
        self.formulation.start_slip_from(u_committed)
    }

    pub fn add_pattern(&self, pattern: &mut dyn PatternSink) -> Result<()> {
        self.formulation.add_pattern(pattern)
    }

    pub fn add_residual(
        &mut self,
        u_local: &[f64],
        factor: f64,
        r_local: &mut [f64],
    ) -> Result<()> {
        let at = At {
            u: u_local,
            factor,
            rate: self.rate.as_ref(),
        };
        self.formulation.add_residual(&at, r_local)
    }

    pub fn add_tangent(
        &mut self,
        u_local: &[f64],
        factor: f64,
        k: &mut dyn MatrixSink,
    ) -> Result<()> {
        let at = At {
            u: u_local,
            factor,
            rate: self.rate.as_ref(),
        };
        self.formulation.add_tangent(&at, k)
    }

    pub fn tangent_signature(&self) -> u64 {
        self.formulation.tangent_signature()
    }

    pub fn set_main_part_tangent(&mut self, on: bool) {
        self.formulation.set_main_part_tangent(on)
    }

    pub fn uzawa_update(&mut self, u_local: &[f64], factor: f64) -> Result<UzawaStats> {
        let at = At {
            u: u_local,
            factor,
            rate: self.rate.as_ref(),
        };
        self.formulation.uzawa_update(&at)
    }

    pub fn census(&mut self, u_local: &[f64], factor: f64) -> Result<Census> {
        let at = At {
            u: u_local,
            factor,
            rate: self.rate.as_ref(),
        };
        self.formulation.census(&at)
    }

    pub fn describe_census(&self, c: &Census) -> String {
        self.formulation.describe_census(&self.spec.name, c)
    }

    pub fn state_change_fraction(&self, u0: &[f64], u1: &[f64], factor: f64) -> Option<f64> {
        self.formulation
            .state_change_fraction(u0, &self.at(u1, factor))
    }

    pub fn normal_multipliers(&self) -> Option<(Vec<f64>, Vec<bool>)> {
        self.formulation.normal_multipliers()
    }

    pub fn set_normal_multipliers(&mut self, lambda: &[f64]) -> Result<()> {
        self.formulation.set_normal_multipliers(lambda)
    }

    pub fn multiplier_states(&self) -> (usize, usize) {
        self.formulation.multiplier_states()
    }

    pub fn commit(&mut self) -> Result<()> {
        self.formulation.commit()
    }

    pub fn snapshot(&self) -> PairSnapshot {
        self.formulation.snapshot()
    }

    pub fn restore(&mut self, snap: PairSnapshot) -> Result<()> {
        self.formulation.restore(snap)
    }

    pub fn restart_request(&self) -> RestartRequest {
        self.formulation.restart_request()
    }

    /// Takes over a converged step from a result file (this rank's rows of
    /// what `restart_request` asked for): the penalty the first run had
    /// raised to, then the formulation's multipliers and history.
    pub fn restart_from(&mut self, rows: &RestartRows) -> Result<()> {
        if let Some(p) = rows.penalty.filter(|p| p.is_finite() && *p > 0.0) {
            self.raise_penalty(p / self.penalty);
        }
        self.formulation.restart_from(rows)
    }

    pub fn output(&mut self, u_local: &[f64], factor: f64) -> Result<PairOutput> {
        let at = At {
            u: u_local,
            factor,
            rate: self.rate.as_ref(),
        };
        self.formulation.output(&at)
    }

    pub fn add_nodal_pressure(&self, numerator: &mut [f64], denominator: &mut [f64]) -> Result<()> {
        self.formulation.add_nodal_pressure(numerator, denominator)
    }

    /// Samples of the shape functions of the slave nodes `wanted` picks, over
    /// every facet of this rank that has one of them as a corner (reference
    /// configuration), so that a reader can form ∫N_j p dA / ∫N_j dA of a
    /// closed-form pressure p: what the nodal pressure of the output
    /// approximates (hertz::fit_nodal_averages). Each facet is on one rank
    /// only, so the samples of all ranks together cover each node's support
    /// once. (The facets were checked when the surface was built, so none
    /// fails here.)
    pub fn nodal_samples(&self, wanted: &dyn Fn(&[f64; 3]) -> bool) -> Vec<NodalSample> {
        let slave = self.slave();
        let facets = slave.facets.iter().map(|f| f.x_ref.as_slice());
        facet_samples(slave.facet_type, facets, wanted).unwrap_or_default()
    }

    /// Seconds spent in multiplier halo exchanges, and ghost values held.
    pub fn multiplier_halo(&self) -> (f64, usize) {
        self.formulation.multiplier_halo()
    }
}

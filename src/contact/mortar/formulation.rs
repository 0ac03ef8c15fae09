//! The mortar pair as the solver sees it: its set-up from the shared pair
//! data and its duties as a [`Formulation`].
use super::friction::Rate;
use super::master::Master;
use super::pair::MortarPair;
use crate::assembly::{MatrixSink, PatternSink, RankExchange};
use crate::contact::fields::{PairOutput, RestartRequest, RestartRows};
use crate::contact::formulation::{
    foreign_snapshot, At, Census, Formulation, HeldFacets, PairSetup, PairSnapshot, SlipRate,
    Traits,
};
use crate::contact::master::MasterSide;
use crate::contact::outcome::UzawaStats;
use crate::contact::penalty;
use crate::contact::surfaces::SlaveSurface;
use crate::dofs::{DofMap, GlobalDof};
use crate::error::{Error, Result};

/// The slip rate in the mortar pair's terms.
fn rate(r: &SlipRate) -> Rate<'_> {
    Rate {
        dt: r.dt,
        dv_du: r.dv_du,
        offset: &r.offset,
        master_velocity: r.rigid_velocity,
    }
}

impl MortarPair {
    /// The mortar pair on this rank. Collective (the slave share and the
    /// master are exchanged).
    pub fn new(s: &PairSetup, slave: SlaveSurface, master: MasterSide) -> Result<Self> {
        let spec = s.spec;
        let h = slave.h;
        MortarPair::build(
            s.mesh,
            s.dofs,
            spec,
            (slave, master, s.ranks),
            |h| penalty::default_normal(spec.penalty, s.softest_youngs, h),
            // Candidates are fixed for a step and every one widens the
            // Jacobian pattern: one element size of margin, not the links'
            // search distance, which only reserves contact DOFs.
            (s.search_distance.min(h), s.search_distance),
            spec.active_friction(),
        )
    }
}

impl Formulation for MortarPair {
    fn slave(&self) -> &SlaveSurface {
        &self.slave
    }

    /// The mortar residual is not a gradient (the forces hold D, M and ν
    /// fixed), so its exact tangent is not symmetric; against a rigid
    /// master it is (−p_j ∂g̃_j/∂x exactly, nothing held fixed:
    /// docs/formulation.md §13.5), symmetric to rounding.
    fn traits(&self) -> Traits {
        Traits {
            symmetric_tangent: self.friction.is_none() && matches!(self.master, Master::Rigid(_)),
            accurate_linear_solves: true,
            state_change_steps: true,
            unit: "nodes",
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
        self.tail_dofs()
    }

    fn held_facets(&self) -> Option<HeldFacets> {
        match &self.master {
            Master::Facets(m) => Some(HeldFacets {
                held: m.held.set_index.len(),
                whole: m.held.whole,
                received: m.held.received,
            }),
            Master::Rigid(_) => None,
        }
    }

    fn search(&mut self, at: &At, motion: f64) -> bool {
        self.search_candidates(at.u, at.factor, motion)
    }

    fn covers(&self, at: &At) -> bool {
        self.candidates_cover(at.u, at.factor)
    }

    fn reserve_dofs(&self) -> Vec<GlobalDof> {
        self.reserved_dofs()
    }

    /// A frictional pair measures the step's slip from the committed state.
    fn measures_slip_from_committed(&self) -> bool {
        self.friction.is_some()
    }

    fn committed_origins(&self) -> Vec<(u32, [f64; 3])> {
        MortarPair::committed_origins(self)
    }

    fn start_slip_from(&mut self, u_committed: &[f64]) {
        MortarPair::start_slip_from(self, u_committed)
    }

    fn add_pattern(&self, pattern: &mut dyn PatternSink) -> Result<()> {
        self.pattern(pattern)
    }

    fn add_residual(&mut self, at: &At, r_local: &mut [f64]) -> Result<()> {
        self.residual(at.u, at.rate.map(rate).as_ref(), at.factor, r_local);
        Ok(())
    }

    fn add_tangent(&mut self, at: &At, k: &mut dyn MatrixSink) -> Result<()> {
        let r = at.rate.map(rate);
        self.tangent_signature =
            self.tangent(at.u, r.as_ref(), (at.factor, self.main_part_tangent), k)?;
        Ok(())
    }

    fn tangent_signature(&self) -> u64 {
        self.tangent_signature
    }

    /// A frictionless pair on master facets then assembles its tangent
    /// without the derivatives of D, M and ν (see `main_part`).
    fn set_main_part_tangent(&mut self, on: bool) {
        self.main_part_tangent = on;
    }

    fn uzawa_update(&mut self, at: &At) -> Result<UzawaStats> {
        Ok(self.update(at.u, at.rate.map(rate).as_ref(), at.factor))
    }

    fn census(&mut self, at: &At) -> Result<Census> {
        let s = self.node_census(at.u, at.rate.map(rate).as_ref(), at.factor);
        Ok(Census {
            pressed: s.active,
            sliding: s.sliding,
            max_penetration: s.max_penetration,
        })
    }

    fn describe_census(&self, pair: &str, c: &Census) -> String {
        let sticking = c.pressed - c.sliding.min(c.pressed);
        format!(
            "slave nodes of mortar pair '{pair}' at the failing iterate: {} pressed together (p > 0), {} sliding, {sticking} sticking, max mean penetration {:.3e} of the element size",
            c.pressed, c.sliding, c.max_penetration
        )
    }

    fn state_change_fraction(&self, u0: &[f64], at: &At) -> Option<f64> {
        self.change_fraction(u0, at.u, at.rate.map(rate).as_ref(), at.factor)
    }

    fn scale_penalty(&mut self, factor: f64) {
        self.raise_penalty(factor);
    }

    fn normal_multipliers(&self) -> Option<(Vec<f64>, Vec<bool>)> {
        if self.friction.is_some() {
            return None;
        }
        Some(self.nodal_multipliers())
    }

    fn set_normal_multipliers(&mut self, lambda: &[f64]) -> Result<()> {
        self.set_nodal_multipliers(lambda);
        Ok(())
    }

    fn multiplier_states(&self) -> (usize, usize) {
        (self.active_nodes(), self.sliding_nodes())
    }

    fn commit(&mut self) -> Result<()> {
        self.commit_step();
        Ok(())
    }

    fn snapshot(&self) -> PairSnapshot {
        PairSnapshot(Box::new(self.take_snapshot()))
    }

    fn restore(&mut self, snap: PairSnapshot) -> Result<()> {
        let snap = snap.0.downcast().map_err(|_| foreign_snapshot())?;
        self.restore_snapshot(*snap);
        Ok(())
    }

    fn restart_request(&self) -> RestartRequest {
        self.request()
    }

    fn restart_from(&mut self, rows: &RestartRows) -> Result<()> {
        let name = self.name.clone();
        self.restart(rows).map_err(|what| {
            Error::Restart(format!(
                "contact pair '{name}': the file's {what} does not fit this mortar pair (another scene, or a file written before mortar restarts existed?)"
            ))
        })
    }

    fn output(&mut self, at: &At) -> Result<PairOutput> {
        Ok(self.fields(at.u, at.rate.map(rate).as_ref(), at.factor))
    }

    fn add_nodal_pressure(&self, numerator: &mut [f64], denominator: &mut [f64]) -> Result<()> {
        MortarPair::add_nodal_pressure(self, numerator, denominator);
        Ok(())
    }

    /// Every rank holding a node computes its multiplier itself: there is
    /// no halo exchange.
    fn multiplier_halo(&self) -> (f64, usize) {
        (0.0, 0)
    }
}

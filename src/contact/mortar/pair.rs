//! A mortar contact pair at run time: candidate segments per load step,
//! residual and tangent contributions, the nodal Uzawa update.
//!
//! Parallel layout: see `share`. A rank holds the slave facets of its own
//! cells (assembled here) and the other ranks' facets around their nodes
//! (evaluated only, so each node's weighted gap is complete), and the
//! master facets near its slave nodes. Segments are integrated in a fixed
//! order (slave facet, then master facet, by set index), so every rank
//! that holds node `j` computes the same `g̃_j` and the same update of
//! `λ_j` bit for bit; the owner of the node is the one that counts it in
//! the Uzawa statistics and writes it out.
use super::friction::{NodeFriction, Rate};
use super::holding::Holding;
use super::master::Master;
use super::segment::MortarRules;
use super::system::{NodalData, NodeState};
use super::tangential::PairFriction;
use super::MAX_FACET_NODES;
use crate::assembly::{MatrixSink, PatternSink};
use crate::contact::outcome::UzawaStats;
use crate::contact::surfaces::SlaveSurface;
use crate::dofs::{GlobalDof, DIM};
use crate::error::Result;
use crate::fem::FacetType;

/// What a cut-back step restores: λ_j and λT_j of the last converged step.
#[derive(Debug, Clone)]
pub struct MortarSnapshot {
    lambda: Vec<f64>,
    lambda_t: Option<Vec<[f64; 3]>>,
}

pub struct MortarPair {
    pub(super) name: String,
    /// This rank's slave facets and points: the output's point rows.
    pub(super) slave: SlaveSurface,
    pub(super) master: Master,
    /// See `Formulation::tangent_signature`.
    pub(super) tangent_signature: u64,
    /// See `Formulation::set_main_part_tangent`.
    pub(super) main_part_tangent: bool,
    pub(super) facet_type: FacetType,
    /// Slave nodes are ids `0..n_slave`, held master nodes follow.
    pub(super) n_slave: usize,
    /// Per node id: its slot in the extended local array (a local node,
    /// or past them a tail slot), global DOFs and reference position.
    pub(super) node_local: Vec<u32>,
    pub(super) node_dofs: Vec<[GlobalDof; DIM]>,
    pub(super) x_ref: Vec<[f64; 3]>,
    pub(super) slave_facets: Vec<[u32; MAX_FACET_NODES]>,
    /// Per slave facet: its position in the slave set.
    pub(super) slave_set_index: Vec<u32>,
    pub(super) assembled: Vec<bool>,
    /// Slave facets this rank evaluates (ascending): all it holds.
    pub(super) evaluated: Vec<u32>,
    pub nodal: NodalData,
    /// Per slot: all of the node's facets are evaluated here ...
    pub(super) complete: Vec<bool>,
    /// ... and this rank owns the node.
    pub(super) owned: Vec<bool>,
    /// Per slot: the node's element size (mean shortest edge of its facets).
    pub(super) h: Vec<f64>,
    /// The step's candidates: (evaluated slave facet, held master facet)
    /// pairs whose bounding boxes meet, or against a rigid master
    /// (evaluated slave facet near the surface, 0); by slave, then master.
    pub(super) candidates: Vec<(u32, u32)>,
    /// The last search's candidates by set indices (the held master's
    /// numbering changes with each exchange).
    pub(super) candidate_key: Vec<(u32, u32)>,
    pub(super) search_distance: f64,
    /// The links' search distance: nodes of facets within it of the other
    /// surface at the last search (`reserve`, node ids) are held in the
    /// contact DOFs though no candidate couples them yet.
    pub(super) reach: f64,
    pub(super) reserve: Vec<u32>,
    pub(super) rules: MortarRules,
    /// Owned mesh nodes of this rank (the length of the output fields).
    pub(super) owned_mesh_nodes: usize,
    /// Owned nodes on either surface (local index, reference position).
    pub(super) owned_pair_nodes: Vec<(u32, [f64; 3])>,
    pub(super) friction: Option<PairFriction>,
    /// Every pair node's natural (file) number, for restarts.
    pub(super) natural: Vec<usize>,
    /// The tail of nodes this rank does not see (see `holding`).
    pub(super) holding: Holding,
    /// The rows of [`MortarPair::restart_nodes`].
    pub(super) restart_rows: Vec<usize>,
    /// A restart's slip origins of the owned pair nodes, until the first
    /// step after it has converged.
    pub(super) pending_origins: Option<Vec<[f64; 3]>>,
}

impl MortarPair {
    /// Current position of node `id` (its slot must be in `u_local`).
    pub(super) fn position(&self, id: u32, u_local: &[f64]) -> [f64; 3] {
        let (x, b) = (
            self.x_ref[id as usize],
            DIM * self.node_local[id as usize] as usize,
        );
        [
            x[0] + u_local[b],
            x[1] + u_local[b + 1],
            x[2] + u_local[b + 2],
        ]
    }

    pub(super) fn positions(&self, u_local: &[f64]) -> Vec<[f64; 3]> {
        self.node_local
            .iter()
            .zip(&self.x_ref)
            .map(|(&l, x)| {
                let b = DIM * l as usize;
                [
                    x[0] + u_local[b],
                    x[1] + u_local[b + 1],
                    x[2] + u_local[b + 2],
                ]
            })
            .collect()
    }

    /// The search of a load step: every (evaluated slave, master) facet pair
    /// whose bounding boxes, grown by the search distance, meet. Returns
    /// whether the candidates changed.
    ///
    /// `motion` is the step's largest prescribed displacement (agreed over
    /// the ranks): the bodies may approach by as much within the step while
    /// the predicted state has not moved them yet, so the margin is at least
    /// that (within the links' search distance). With one element size
    /// alone the graded Hertz line at h_c = b/40 (one cell thick, so its
    /// facets' shortest edge is the thickness) found the outer third of its
    /// contact zone only after Uzawa had converged, and solved again.
    pub(super) fn search_candidates(&mut self, u_local: &[f64], factor: f64, motion: f64) -> bool {
        let x = self.positions(u_local);
        let margin = self.search_distance.max(motion.min(self.reach));
        let (reserve, candidates) = match &self.master {
            Master::Facets(m) => (
                self.nodes_within(m, &x, self.reach),
                self.facet_pairs(m, &x, margin),
            ),
            Master::Rigid(r) => {
                let near = self.facets_near_rigid(r, &x, factor, self.reach);
                let candidates = self.facets_near_rigid(r, &x, factor, margin);
                (
                    self.facet_nodes(&near),
                    candidates.into_iter().map(|f| (f, 0)).collect(),
                )
            }
        };
        let key: Vec<(u32, u32)> = candidates
            .iter()
            .map(|&(s, m)| (self.slave_set_index[s as usize], self.master.set_index(m)))
            .collect();
        let changed = key != self.candidate_key;
        self.reserve = reserve;
        self.candidate_key = key;
        self.candidates = candidates;
        changed
    }

    /// The nodes (ids, ascending) of slave facets `facets`.
    fn facet_nodes(&self, facets: &[u32]) -> Vec<u32> {
        let nf = self.facet_type.nodes();
        let mut nodes: Vec<u32> = facets
            .iter()
            .flat_map(|&f| self.slave_facets[f as usize][..nf].to_vec())
            .collect();
        nodes.sort_unstable();
        nodes.dedup();
        nodes
    }

    /// Whether the step's candidates still hold every pair that may touch
    /// at `u_local`: each (evaluated slave, held master) facet pair whose
    /// bounding boxes meet, or for a rigid master each facet with a node on
    /// or behind the surface placed at `factor`. The candidates are fixed
    /// for a solve, searched at the step's predicted state with one element
    /// size of margin; a step that moves the bodies further (one load step
    /// of a Hertz contact whose zone grows past that margin) leaves facets
    /// without segments, unconstrained, and only a search from the solved
    /// state finds them.
    pub(super) fn candidates_cover(&self, u_local: &[f64], factor: f64) -> bool {
        let x = self.positions(u_local);
        // Both lists are ordered by slave, then master.
        let now: Vec<(u32, u32)> = match &self.master {
            Master::Facets(m) => self.facet_pairs(m, &x, 0.0),
            Master::Rigid(r) => self
                .facets_near_rigid(r, &x, factor, 0.0)
                .into_iter()
                .map(|f| (f, 0))
                .collect(),
        };
        now.iter()
            .all(|pair| self.candidates.binary_search(pair).is_ok())
    }

    /// The global DOFs of the nodes reserved at the last search: a search
    /// that adds candidates among them does not grow the contact DOFs, so a
    /// contact Schur complement keeps its factor of the bulk stiffness (a
    /// contact zone that grows past the candidates' margin within one step
    /// costs a second search, not a second factorisation).
    pub(super) fn reserved_dofs(&self) -> Vec<GlobalDof> {
        self.reserve
            .iter()
            .flat_map(|&n| self.node_dofs[n as usize])
            .collect()
    }

    pub(super) fn local_dof(&self, id: u32, c: usize) -> usize {
        DIM * self.node_local[id as usize] as usize + c
    }

    pub(super) fn global_dof(&self, id: u32, c: usize) -> GlobalDof {
        self.node_dofs[id as usize][c]
    }

    /// For each node of an assembled facet: the DOFs its tangent may couple
    /// (all nodes of its candidate segments: the slave facet's and the
    /// master facet's), squared into the pattern.
    pub(super) fn pattern(&self, pattern: &mut dyn PatternSink) -> Result<()> {
        let nf = self.facet_type.nodes();
        let mut support: Vec<Vec<u32>> = vec![Vec::new(); self.nodal.nodes.len()];
        for &(s, m) in &self.candidates {
            let master: &[u32] = match &self.master {
                Master::Facets(f) => &f.facets[m as usize][..nf],
                Master::Rigid(_) => &[],
            };
            let ids: Vec<u32> = self.slave_facets[s as usize][..nf]
                .iter()
                .chain(master)
                .copied()
                .collect();
            for &n in &self.slave_facets[s as usize][..nf] {
                if let Some(j) = self.nodal.slot_of(n) {
                    support[j].extend(&ids);
                }
            }
        }
        let mut d: Vec<GlobalDof> = Vec::new();
        for (j, mut nodes) in support.into_iter().enumerate() {
            if !self.complete[j] || nodes.is_empty() {
                continue;
            }
            nodes.sort_unstable();
            nodes.dedup();
            d.clear();
            for n in nodes {
                d.extend((0..DIM).map(|c| self.global_dof(n, c)));
            }
            pattern.add_square(&d)?;
        }
        Ok(())
    }

    pub(super) fn residual(
        &self,
        u_local: &[f64],
        rate: Option<&Rate>,
        factor: f64,
        r_local: &mut [f64],
    ) {
        let x = self.positions(u_local);
        match &self.master {
            Master::Facets(m) => self.facet_residual(m, (&x, u_local), rate, r_local),
            Master::Rigid(r) => self.rigid_residual(r, (&x, u_local), (rate, factor), r_local),
        }
    }

    /// Adds the tangent; returns its active-set signature: equal values mean
    /// the same segments, the same closed nodes and the same sliding nodes
    /// on this rank (what the tangent's structure depends on, so the
    /// solver may keep the preconditioner of an earlier one). With
    /// `main_part` a frictionless pair on master facets adds only the main
    /// part (see `main_part`).
    pub(super) fn tangent(
        &self,
        u_local: &[f64],
        rate: Option<&Rate>,
        (factor, main_part): (f64, bool),
        k: &mut dyn MatrixSink,
    ) -> Result<u64> {
        let x = self.positions(u_local);
        match &self.master {
            Master::Facets(m) => self.facet_tangent(m, (&x, u_local), (rate, main_part), k),
            Master::Rigid(r) => self.rigid_tangent(r, (&x, u_local), (rate, factor), k),
        }
    }

    /// λ_j ← ⟨λ_j − ε_j ḡ_j⟩ (and λT_j ← tT_j) at every node whose
    /// weighted gap is complete on this rank; statistics over the nodes this
    /// rank owns.
    pub(super) fn update(
        &mut self,
        u_local: &[f64],
        rate: Option<&Rate>,
        factor: f64,
    ) -> UzawaStats {
        let x = self.positions(u_local);
        let (states, frictions) = self.trial(&x, u_local, rate, factor);
        let mut stats = self.census_of(&states, &frictions);
        for (j, s) in states.iter().enumerate() {
            if !self.complete[j] {
                continue;
            }
            let old = self.nodal.lambda[j];
            self.nodal.lambda[j] = s.pressure;
            let area = self.nodal.area[j];
            if let Some(f) = &mut self.friction {
                let n = &frictions[j];
                let change = crate::contact::autodiff::norm(&crate::contact::autodiff::sub(
                    &n.traction,
                    &f.nodal.lambda[j],
                ));
                f.nodal.lambda[j] = n.traction;
                f.sliding[j] = n.sliding;
                f.slip[j] = n.slip;
                if self.owned[j] {
                    stats.max_change = stats.max_change.max(change * area);
                }
            }
            if !self.owned[j] {
                continue;
            }
            stats.max_multiplier = stats.max_multiplier.max(s.pressure);
            stats.max_change = stats.max_change.max((s.pressure - old).abs() * area);
            stats.max_force = stats.max_force.max(s.pressure * area);
        }
        if let Some(f) = &mut self.friction {
            f.last = x;
        }
        if let Master::Rigid(r) = &mut self.master {
            r.last_factor = factor;
        }
        stats
    }

    /// The nodes' states at `u_local` as the Uzawa update would find
    /// them, nothing changed: its statistics without the multiplier
    /// changes (a failed Newton solve's report).
    pub(super) fn node_census(
        &self,
        u_local: &[f64],
        rate: Option<&Rate>,
        factor: f64,
    ) -> UzawaStats {
        let x = self.positions(u_local);
        let (states, frictions) = self.trial(&x, u_local, rate, factor);
        self.census_of(&states, &frictions)
    }

    /// Over the owned nodes whose weighted gap is complete here that are
    /// open at `u0` and closed at `u1`, or closed and open, their trial
    /// pressure `λ_j − ε_j g̃_j / A_j` crossing zero: the largest fraction
    /// of the way from `u0` to `u1` at which one of them changes state
    /// (the trial pressure interpolated linearly); None if none changes.
    pub(super) fn change_fraction(
        &self,
        u0: &[f64],
        u1: &[f64],
        rate: Option<&Rate>,
        factor: f64,
    ) -> Option<f64> {
        let (s0, _) = self.trial(&self.positions(u0), u0, rate, factor);
        let (s1, _) = self.trial(&self.positions(u1), u1, rate, factor);
        let nodal = &self.nodal;
        let trial = |s: &NodeState, j: usize| {
            nodal.lambda[j] - nodal.penalty[j] * s.weighted_gap / nodal.area[j]
        };
        let mut out: Option<f64> = None;
        for (j, (a, b)) in s0.iter().zip(&s1).enumerate() {
            if !(self.complete[j] && self.owned[j]) || a.closed == b.closed {
                continue;
            }
            // A node that leaves or enters the master's cover changes state
            // without its trial pressure crossing zero: no kink to step to
            // (a fraction of 0 there would shorten every step to 5 %).
            let (t0, t1) = (trial(a, j), trial(b, j));
            if (t0 < 0.0) == (t1 < 0.0) {
                continue;
            }
            let f = (t0 / (t0 - t1)).clamp(0.0, 1.0);
            out = Some(out.map_or(f, |o| o.max(f)));
        }
        out
    }

    /// Node states and friction outcomes at the positions `x`.
    fn trial(
        &self,
        x: &[[f64; 3]],
        u_local: &[f64],
        rate: Option<&Rate>,
        factor: f64,
    ) -> (Vec<NodeState>, Vec<NodeFriction>) {
        match &self.master {
            Master::Facets(m) => {
                let e = self.facet_evaluate(m, x, u_local, rate);
                (e.states, e.frictions)
            }
            Master::Rigid(r) => self.rigid_outcome(r, (x, u_local), rate, factor),
        }
    }

    /// Over the owned nodes whose weighted gap is complete here: pressed
    /// (p_j > 0), sliding, and the deepest mean penetration g̃_j / A_j
    /// relative to the node's element size.
    fn census_of(&self, states: &[NodeState], frictions: &[NodeFriction]) -> UzawaStats {
        let mut stats = UzawaStats::default();
        for (j, s) in states.iter().enumerate() {
            if !(self.complete[j] && self.owned[j]) {
                continue;
            }
            if s.pressure > 0.0 || s.closed {
                let mean = -s.weighted_gap / self.nodal.area[j];
                stats.max_penetration = stats.max_penetration.max(mean / self.h[j]);
            }
            stats.active += usize::from(s.pressure > 0.0);
            let slides = self.friction.is_some() && frictions.get(j).is_some_and(|n| n.sliding);
            stats.sliding += usize::from(slides);
        }
        stats
    }

    /// λ of the nodes this rank updates (complete here; the others are
    /// kept at 0 by the setter) and whether this rank owns them.
    pub(super) fn nodal_multipliers(&self) -> (Vec<f64>, Vec<bool>) {
        let counted = self
            .complete
            .iter()
            .zip(&self.owned)
            .map(|(c, o)| *c && *o)
            .collect();
        (self.nodal.lambda.clone(), counted)
    }

    /// Sets λ at the nodes this rank updates (the others keep theirs).
    pub(super) fn set_nodal_multipliers(&mut self, lambda: &[f64]) {
        for (j, l) in lambda.iter().enumerate().take(self.complete.len()) {
            if self.complete[j] {
                self.nodal.lambda[j] = *l;
            }
        }
    }

    /// A converged step is final: the next one measures slip from here.
    pub(super) fn commit_step(&mut self) {
        self.pending_origins = None;
        if let Some(f) = &mut self.friction {
            f.start.clone_from(&f.last);
        }
        if let Master::Rigid(r) = &mut self.master {
            r.start_factor = r.last_factor;
        }
    }

    pub(super) fn take_snapshot(&self) -> MortarSnapshot {
        MortarSnapshot {
            lambda: self.nodal.lambda.clone(),
            lambda_t: self.friction.as_ref().map(|f| f.nodal.lambda.clone()),
        }
    }

    pub(super) fn restore_snapshot(&mut self, snap: MortarSnapshot) {
        if snap.lambda.len() == self.nodal.lambda.len() {
            self.nodal.lambda = snap.lambda;
        }
        if let (Some(f), Some(l)) = (&mut self.friction, snap.lambda_t) {
            f.nodal.lambda = l;
        }
    }

    /// Multiplies εN by `factor`, and εT when it follows εN.
    pub fn raise_penalty(&mut self, factor: f64) {
        self.nodal.penalty.iter_mut().for_each(|p| *p *= factor);
        if let Some(f) = self.friction.as_mut().filter(|f| f.follows) {
            f.nodal.penalty.iter_mut().for_each(|p| *p *= factor);
        }
    }

    /// Owned nodes sliding at the last Uzawa update.
    pub fn sliding_nodes(&self) -> usize {
        self.friction.as_ref().map_or(0, |f| {
            (0..self.owned.len())
                .filter(|&j| self.owned[j] && f.sliding[j])
                .count()
        })
    }

    /// Owned nodes in contact.
    pub fn active_nodes(&self) -> usize {
        (0..self.owned.len())
            .filter(|&j| self.owned[j] && self.nodal.lambda[j] > 0.0)
            .count()
    }
}

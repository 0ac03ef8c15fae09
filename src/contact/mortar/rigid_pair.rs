//! A mortar pair against a rigid analytic master at run time: the step's
//! candidate facets, residual, tangent, node states and output rows (the
//! integrals are `rigid`'s, the friction `rigid_friction`'s; everything
//! per node, the Uzawa update and the output fields are `pair`'s).
//!
//! Parallel layout as for deformable masters: a rank integrates every slave
//! facet it evaluates (its own and those sharing a node with them) from the
//! same ghosted positions and the same placed surface, so every rank that
//! holds node `j` computes the same `g̃_j`, `λ_j` and `λT_j`.
use super::friction::{Increment, NodeFriction, Rate};
use super::pair::MortarPair;
use super::pair_output::OutputRows;
use super::rigid::{self, RigidFacet, RigidInterface, RD};
use super::rigid_friction::{self, RigidSlip};
use super::rigid_master::RigidMaster;
use super::rows::Rows;
use super::system::{self, NodeState};
use crate::assembly::{MatrixSink, PatternSink};
use crate::contact::autodiff::Seed;
use crate::dofs::{GlobalDof, DIM};
use crate::error::Result;

/// One evaluation against the rigid master.
struct RigidEvaluation<T> {
    facets: Vec<RigidFacet<T>>,
    states: Vec<NodeState>,
    slips: Vec<RigidSlip<T>>,
    frictions: Vec<NodeFriction>,
}

impl MortarPair {
    /// Whether the master is a rigid analytic surface.
    pub fn is_rigid(&self) -> bool {
        self.rigid.is_some()
    }

    fn rigid_master(&self) -> &RigidMaster {
        match &self.rigid {
            Some(r) => r,
            None => unreachable!("rigid mortar call on a pair with master facets"),
        }
    }

    fn rigid_interface<'a>(&'a self, positions: &'a [[f64; 3]], factor: f64) -> RigidInterface<'a> {
        let r = self.rigid_master();
        RigidInterface {
            facet_type: self.facet_type,
            positions,
            reference: &self.x_ref,
            facets: &self.slave_facets,
            candidates: &r.candidates,
            assembled: &self.assembled,
            surface: r.placed(factor),
        }
    }

    /// The search of a load step: the evaluated facets with a node within
    /// the margin (as `search`'s: at least the step's prescribed `motion`)
    /// of the surface placed at `factor`. Returns whether the candidates
    /// changed.
    pub(super) fn rigid_search(&mut self, u_local: &[f64], factor: f64, motion: f64) -> bool {
        let margin = self.search_distance.max(motion.min(self.reach));
        let candidates = self.facets_near_rigid(u_local, factor, margin);
        let nf = self.facet_type.nodes();
        let mut reserve: Vec<u32> = self
            .facets_near_rigid(u_local, factor, self.reach)
            .iter()
            .flat_map(|&f| self.slave_facets[f as usize][..nf].to_vec())
            .collect();
        reserve.sort_unstable();
        reserve.dedup();
        self.reserve = reserve;
        match &mut self.rigid {
            Some(r) => {
                let changed = candidates != r.candidates;
                r.candidates = candidates;
                changed
            }
            None => false,
        }
    }

    /// Whether the step's candidates hold every evaluated facet with a node
    /// on or behind the surface placed at `factor` (see `MortarPair::covers`).
    pub(super) fn rigid_covers(&self, u_local: &[f64], factor: f64) -> bool {
        let candidates = &self.rigid_master().candidates;
        self.facets_near_rigid(u_local, factor, 0.0)
            .iter()
            .all(|f| candidates.binary_search(f).is_ok())
    }

    /// The evaluated facets (ascending) with a node within `distance` of
    /// the surface placed at `factor`.
    fn facets_near_rigid(&self, u_local: &[f64], factor: f64, distance: f64) -> Vec<u32> {
        let x = self.positions(u_local);
        let surface = self.rigid_master().placed(factor);
        let near: Vec<bool> = x
            .iter()
            .map(|p| rigid::distance(&surface, p).is_some_and(|(g, _)| g <= distance))
            .collect();
        let nf = self.facet_type.nodes();
        self.evaluated
            .iter()
            .copied()
            .filter(|&f| {
                self.slave_facets[f as usize][..nf]
                    .iter()
                    .any(|&n| near[n as usize])
            })
            .collect()
    }

    /// For each complete node: the nodes of its candidate facets, squared
    /// into the pattern (slave–slave couplings only).
    pub(super) fn rigid_pattern(&self, pattern: &mut dyn PatternSink) -> Result<()> {
        let nf = self.facet_type.nodes();
        let mut support: Vec<Vec<u32>> = vec![Vec::new(); self.nodal.nodes.len()];
        for &f in &self.rigid_master().candidates {
            let ids = &self.slave_facets[f as usize][..nf];
            for &n in ids {
                if let Some(j) = self.nodal.slot_of(n) {
                    support[j].extend(ids);
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

    /// The master's increment of the step: its translation since the last
    /// converged step (quasi-static) or `Δt` times its velocity (dynamics).
    fn master_increment(&self, rate: Option<&Rate>, factor: f64) -> [f64; 3] {
        let r = self.rigid_master();
        match rate {
            None => {
                let (now, then) = (r.shift(factor), r.shift(r.start_factor));
                [0, 1, 2].map(|i| now[i] - then[i])
            }
            Some(rate) => rate.master_velocity.map(|v| rate.dt * v),
        }
    }

    fn rigid_evaluate<T: Seed>(
        &self,
        x: &[[f64; 3]],
        u_local: &[f64],
        rate: Option<&Rate>,
        factor: f64,
    ) -> RigidEvaluation<T> {
        let interface = self.rigid_interface(x, factor);
        let facets = rigid::facets::<T>(&interface, &self.rules);
        let (gap, covered) = rigid::weighted_gaps(
            &interface,
            &self.nodal,
            &facets,
            &self.rigid_master().expected,
        );
        let states = system::node_states(&self.nodal, &gap, &covered);
        let (slips, frictions) = match &self.friction {
            Some(f) => {
                let (value, slope) = f.increments(&self.node_local, x, u_local, rate);
                let inc = Increment {
                    value: &value,
                    slope,
                };
                let master = self.master_increment(rate, factor);
                let slips = rigid_friction::facet_slips(&interface, &facets, &inc, master);
                let frictions = rigid_friction::node_frictions(
                    &interface,
                    &self.nodal,
                    &f.nodal,
                    &states,
                    &facets,
                    &slips,
                );
                (slips, frictions)
            }
            None => (Vec::new(), Vec::new()),
        };
        RigidEvaluation {
            facets,
            states,
            slips,
            frictions,
        }
    }

    pub(super) fn rigid_residual(
        &self,
        u_local: &[f64],
        rate: Option<&Rate>,
        factor: f64,
        r_local: &mut [f64],
    ) {
        let x = self.positions(u_local);
        let e = self.rigid_evaluate::<f64>(&x, u_local, rate, factor);
        let interface = self.rigid_interface(&x, factor);
        let mut add = |n: u32, c: usize, v: f64| {
            r_local[self.local_dof(n, c)] += v;
        };
        rigid::residual(&interface, &self.nodal, &e.facets, &e.states, &mut add);
        if self.friction.is_some() {
            rigid_friction::residual(&interface, &self.nodal, &e.facets, &e.frictions, &mut add);
        }
    }

    /// See [`MortarPair::add_tangent`].
    pub(super) fn rigid_tangent(
        &self,
        u_local: &[f64],
        rate: Option<&Rate>,
        factor: f64,
        k: &mut dyn MatrixSink,
    ) -> Result<u64> {
        let x = self.positions(u_local);
        let e = self.rigid_evaluate::<RD>(&x, u_local, rate, factor);
        let interface = self.rigid_interface(&x, factor);
        let mut rows = Rows::new(self.node_local.len());
        let mut add = |r, c, v| rows.add(r, c, v);
        rigid::tangent(&interface, &self.nodal, &e.facets, &e.states, &mut add);
        if self.friction.is_some() {
            rigid_friction::tangent(
                &interface,
                &self.nodal,
                &e.facets,
                &e.slips,
                &e.frictions,
                &mut add,
            );
        }
        rows.add_to(|id, c| self.global_dof(id, c), k)?;
        use std::hash::{Hash, Hasher};
        let mut h = std::collections::hash_map::DefaultHasher::new();
        for f in &e.facets {
            f.facet.hash(&mut h);
        }
        for s in &e.states {
            s.closed.hash(&mut h);
        }
        for f in &e.frictions {
            f.sliding.hash(&mut h);
        }
        Ok(h.finish())
    }

    /// Node states and frictions for the Uzawa update.
    pub(super) fn rigid_outcome(
        &self,
        x: &[[f64; 3]],
        u_local: &[f64],
        rate: Option<&Rate>,
        factor: f64,
    ) -> (Vec<NodeState>, Vec<NodeFriction>) {
        let e = self.rigid_evaluate::<f64>(x, u_local, rate, factor);
        (e.states, e.frictions)
    }

    /// Node states and, per assembled facet row, `(slot, Σ_k D_jk, Σ_k c_jk)`
    /// (the output's weights and force directions).
    pub(super) fn rigid_output_rows(
        &self,
        x: &[[f64; 3]],
        factor: f64,
    ) -> (Vec<NodeState>, OutputRows) {
        let interface = self.rigid_interface(x, factor);
        let facets = rigid::facets::<f64>(&interface, &self.rules);
        let (gap, covered) = rigid::weighted_gaps(
            &interface,
            &self.nodal,
            &facets,
            &self.rigid_master().expected,
        );
        let states = system::node_states(&self.nodal, &gap, &covered);
        let nf = self.facet_type.nodes();
        let mut rows = Vec::new();
        rigid::for_each_node(&interface, &self.nodal, &facets, true, |_, f, a, j| {
            let d: f64 = f.d[a][..nf].iter().sum();
            let mut c = [0.0; 3];
            for ck in &f.force[a][..nf] {
                for i in 0..3 {
                    c[i] += ck[i];
                }
            }
            rows.push((j, d, c));
        });
        (states, rows)
    }
}

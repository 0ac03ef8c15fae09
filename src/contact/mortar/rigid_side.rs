//! A mortar pair's rigid analytic master at run time: the surface and its
//! prescribed motion, the step's candidate slave facets (those with a node
//! near the surface), and the evaluation, residual and tangent over them
//! (the integrals are `rigid`'s, the friction `rigid_friction`'s). The
//! other variant of the master side is `facet_side`; everything per node
//! (the Uzawa update, the output fields) is `pair`'s.
//!
//! Parallel layout as for deformable masters: a rank integrates every slave
//! facet it evaluates (its own and those sharing a node with them) from the
//! same ghosted positions and the same placed surface, so every rank that
//! holds node `j` computes the same `g̃_j`, `λ_j` and `λT_j`.
use super::friction::{Increment, NodeFriction, Rate};
use super::master::RigidSide;
use super::output::OutputRows;
use super::pair::MortarPair;
use super::rigid::{self, RigidFacet, RigidInterface, RD};
use super::rigid_friction::{self, RigidSlip};
use super::rows::Rows;
use super::system::{self, NodeState};
use crate::assembly::MatrixSink;
use crate::contact::autodiff::Seed;
use crate::error::Result;

/// One evaluation against the rigid master.
struct RigidEvaluation<T> {
    facets: Vec<RigidFacet<T>>,
    states: Vec<NodeState>,
    slips: Vec<RigidSlip<T>>,
    frictions: Vec<NodeFriction>,
}

impl MortarPair {
    fn rigid_interface<'a>(
        &'a self,
        positions: &'a [[f64; 3]],
        r: &RigidSide,
        factor: f64,
    ) -> RigidInterface<'a> {
        RigidInterface {
            facet_type: self.facet_type,
            positions,
            reference: &self.x_ref,
            facets: &self.slave_facets,
            candidates: &self.candidates,
            assembled: &self.assembled,
            surface: r.master.placed(factor),
        }
    }

    /// The evaluated facets (ascending) with a node within `distance` of
    /// the surface placed at `factor`, at positions `x`.
    pub(super) fn facets_near_rigid(
        &self,
        r: &RigidSide,
        x: &[[f64; 3]],
        factor: f64,
        distance: f64,
    ) -> Vec<u32> {
        let surface = r.master.placed(factor);
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

    /// The master's increment of the step: its translation since the last
    /// converged step (quasi-static) or `Δt` times its velocity (dynamics).
    fn master_increment(r: &RigidSide, rate: Option<&Rate>, factor: f64) -> [f64; 3] {
        match rate {
            None => {
                let (now, then) = (r.master.shift(factor), r.master.shift(r.start_factor));
                [0, 1, 2].map(|i| now[i] - then[i])
            }
            Some(rate) => rate.master_velocity.map(|v| rate.dt * v),
        }
    }

    fn rigid_evaluate<T: Seed>(
        &self,
        r: &RigidSide,
        (x, u_local): (&[[f64; 3]], &[f64]),
        rate: Option<&Rate>,
        factor: f64,
    ) -> RigidEvaluation<T> {
        let interface = self.rigid_interface(x, r, factor);
        let facets = rigid::facets::<T>(&interface, &self.rules);
        let (gap, covered) = rigid::weighted_gaps(&interface, &self.nodal, &facets, &r.expected);
        let states = system::node_states(&self.nodal, &gap, &covered);
        let (slips, frictions) = match &self.friction {
            Some(f) => {
                let (value, slope) = f.increments(&self.node_local, x, u_local, rate);
                let inc = Increment {
                    value: &value,
                    slope,
                };
                let master = Self::master_increment(r, rate, factor);
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
        r: &RigidSide,
        (x, u_local): (&[[f64; 3]], &[f64]),
        (rate, factor): (Option<&Rate>, f64),
        r_local: &mut [f64],
    ) {
        let e = self.rigid_evaluate::<f64>(r, (x, u_local), rate, factor);
        let interface = self.rigid_interface(x, r, factor);
        let mut add = |n: u32, c: usize, v: f64| {
            r_local[self.local_dof(n, c)] += v;
        };
        rigid::residual(&interface, &self.nodal, &e.facets, &e.states, &mut add);
        if self.friction.is_some() {
            rigid_friction::residual(&interface, &self.nodal, &e.facets, &e.frictions, &mut add);
        }
    }

    /// See `MortarPair::tangent` (the main part is the whole tangent here).
    pub(super) fn rigid_tangent(
        &self,
        r: &RigidSide,
        (x, u_local): (&[[f64; 3]], &[f64]),
        (rate, factor): (Option<&Rate>, f64),
        k: &mut dyn MatrixSink,
    ) -> Result<u64> {
        let e = self.rigid_evaluate::<RD>(r, (x, u_local), rate, factor);
        let interface = self.rigid_interface(x, r, factor);
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
        r: &RigidSide,
        (x, u_local): (&[[f64; 3]], &[f64]),
        rate: Option<&Rate>,
        factor: f64,
    ) -> (Vec<NodeState>, Vec<NodeFriction>) {
        let e = self.rigid_evaluate::<f64>(r, (x, u_local), rate, factor);
        (e.states, e.frictions)
    }

    /// Node states and, per assembled facet row, `(slot, Σ_k D_jk, Σ_k c_jk)`
    /// (the output's weights and force directions).
    pub(super) fn rigid_output_rows(
        &self,
        r: &RigidSide,
        x: &[[f64; 3]],
        factor: f64,
    ) -> (Vec<NodeState>, OutputRows) {
        let interface = self.rigid_interface(x, r, factor);
        let facets = rigid::facets::<f64>(&interface, &self.rules);
        let (gap, covered) = rigid::weighted_gaps(&interface, &self.nodal, &facets, &r.expected);
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

//! What a mortar pair hands the result file: nodal fields of the owned
//! slave nodes, the pair's force, and point values interpolated from the
//! nodes.
use super::facet_shape;
use super::friction::Rate;
use super::master::Master;
use super::pair::MortarPair;
use super::system::NodeState;
use crate::contact::fields::{self, Field, PairOutput};
use crate::contact::outcome::PairForce;

/// Per assembled facet row: `(slot, Σ_k D_jk, Σ_k D_jk ν)` (a rigid
/// master: `Σ_k c_jk` for the last), the weights and force directions the
/// output sums.
pub(super) type OutputRows = Vec<(usize, f64, [f64; 3])>;

impl MortarPair {
    /// Owned slave nodes: reference position and λ_j.
    fn node_values(&self) -> Vec<([f64; 3], f64)> {
        (0..self.owned.len())
            .filter(|&j| self.owned[j])
            .map(|j| {
                (
                    self.x_ref[self.nodal.nodes[j] as usize],
                    self.nodal.lambda[j],
                )
            })
            .collect()
    }

    /// The pair's fields: per slave point its position, the pressure
    /// interpolated from the nodes with the standard shape functions
    /// (Σ N_a λ_a, the smooth nodal traction; the mortar field Σ Φ_a λ_a
    /// itself oscillates inside a facet) and its area weight; per owned
    /// mesh node λ_j, the weighted gap, the nodal area, the traction and,
    /// with friction, the stick/slip state, the step's slip and the history
    /// a restart reads; and this rank's part of the force.
    pub(super) fn fields(&self, u_local: &[f64], rate: Option<&Rate>, factor: f64) -> PairOutput {
        let slave = &self.slave;
        let lambda = self.lambda_by_local_node();
        let nq = slave.num_qps();
        let mut pressure = vec![0.0; nq];
        for (q, p) in pressure.iter_mut().enumerate() {
            let facet = &slave.facets[q / slave.nqp];
            let s = facet_shape(slave.facet_type, slave.qp_zeta[q]);
            *p = facet
                .nodes
                .iter()
                .zip(s.n)
                .map(|(n, na)| na * lambda.get(&n.to_u32()).copied().unwrap_or(0.0))
                .sum();
        }
        let points: Vec<[f64; 3]> = (0..nq).map(|q| slave.qp_position(q, u_local)).collect();
        let (node_fields, force) = self.node_fields(u_local, rate, factor);
        PairOutput {
            point_fields: vec![
                Field::vector(fields::PAIR_POINTS, &points),
                Field::scalar(fields::PAIR_PRESSURE, pressure),
                Field::scalar(fields::PAIR_WEIGHT, slave.qp_weight.clone()),
            ],
            node_fields,
            force,
            nodes: self.node_values(),
        }
    }

    /// Nodal fields of the owned nodes and this rank's part of the pair's
    /// force on the slave: `Σ_j λ_j D_jk ν` summed over `k` (`D` of the
    /// current segments), or `Σ_j λ_j c_jk` against a rigid master, so the
    /// force is the one the residual applied.
    fn node_fields(
        &self,
        u_local: &[f64],
        rate: Option<&Rate>,
        factor: f64,
    ) -> (Vec<Field>, PairForce) {
        let x = self.positions(u_local);
        // Per assembled facet row: (slot, Σ_k D_jk, its force direction Σ_k D_jk ν).
        let (states, rows): (Vec<NodeState>, OutputRows) = match &self.master {
            Master::Facets(m) => self.facet_output_rows(m, &x, u_local, rate),
            Master::Rigid(r) => self.rigid_output_rows(r, &x, factor),
        };
        let zero = [0.0; 3];
        let lambda_t = |j: usize| self.friction.as_ref().map_or(&zero, |f| &f.nodal.lambda[j]);
        let mut normal_sum = vec![[0.0; 3]; self.nodal.nodes.len()];
        let mut force = PairForce::default();
        for (j, d, dn) in rows {
            let lambda = self.nodal.lambda[j];
            for ((sum, f), nc) in normal_sum[j].iter_mut().zip(force.force.iter_mut()).zip(dn) {
                *sum += nc;
                *f -= lambda * nc;
            }
            force.normal += lambda * d;
            let t = lambda_t(j);
            for (f, tc) in force.force.iter_mut().zip(t) {
                *f -= tc * d;
            }
            force.tangential += crate::contact::autodiff::norm(t) * d;
        }
        let n = self.owned_mesh_nodes;
        let friction = self.friction.as_ref();
        let (mut lambda, mut weighted_gap, mut area) = (vec![0.0; n], vec![0.0; n], vec![0.0; n]);
        let mut traction = vec![[0.0; 3]; n];
        let (mut state, mut slip, mut lambda_tf) =
            (vec![0.0; n], vec![[0.0; 3]; n], vec![[0.0; 3]; n]);
        for j in (0..self.owned.len()).filter(|&j| self.owned[j]) {
            let l = self.node_local[self.nodal.nodes[j] as usize] as usize;
            if l >= n {
                continue;
            }
            lambda[l] = self.nodal.lambda[j];
            weighted_gap[l] = states[j].weighted_gap;
            area[l] = self.nodal.area[j];
            if let Some(f) = friction {
                lambda_tf[l] = f.nodal.lambda[j];
                slip[l] = f.slip[j];
                state[l] = match (self.nodal.lambda[j] > 0.0, f.sliding[j]) {
                    (false, _) => fields::OPEN,
                    (true, false) => fields::STICK,
                    (true, true) => fields::SLIP,
                };
            }
            let len = crate::contact::autodiff::norm(&normal_sum[j]);
            if len > 0.0 {
                let t = lambda_t(j);
                traction[l] =
                    [0, 1, 2].map(|i| -self.nodal.lambda[j] * normal_sum[j][i] / len - t[i]);
            }
        }
        let mut out = vec![
            Field::scalar(fields::PAIR_NODE_LAMBDA, lambda),
            Field::scalar(fields::PAIR_NODE_WEIGHTED_GAP, weighted_gap),
            Field::scalar(fields::PAIR_NODE_AREA, area),
            Field::vector(fields::PAIR_NODE_TRACTION, &traction),
        ];
        if friction.is_some() {
            // Every owned node of either surface (held here or not): where
            // it was at the last Uzawa update, the state written.
            let mut origin = vec![[0.0; 3]; n];
            for &(l, x) in &self.owned_pair_nodes {
                if let Some(o) = origin.get_mut(l as usize) {
                    let u = crate::dofs::LocalNode::from_u32(l).value(u_local);
                    *o = [x[0] + u[0], x[1] + u[1], x[2] + u[2]];
                }
            }
            out.extend([
                Field::scalar(fields::PAIR_NODE_STATE, state),
                Field::vector(fields::PAIR_NODE_SLIP, &slip),
                Field::vector(fields::PAIR_NODE_LAMBDA_T, &lambda_tf),
                Field::vector(fields::PAIR_NODE_SLIP_ORIGIN, &origin),
            ]);
        }
        (out, force)
    }

    /// Adds λ_j of every owned node into the nodal contact-pressure field
    /// (indexed by owned local node; the denominator counts the pairs).
    pub(super) fn add_nodal_pressure(&self, numerator: &mut [f64], denominator: &mut [f64]) {
        for j in (0..self.owned.len()).filter(|&j| self.owned[j]) {
            let l = self.node_local[self.nodal.nodes[j] as usize] as usize;
            if let (Some(n), Some(d)) = (numerator.get_mut(l), denominator.get_mut(l)) {
                *n += self.nodal.lambda[j];
                *d += 1.0;
            }
        }
    }

    /// λ_j by the slave node's local index, for the nodes this rank holds
    /// (the point output interpolates them with the standard shape functions).
    fn lambda_by_local_node(&self) -> std::collections::HashMap<u32, f64> {
        self.nodal
            .nodes
            .iter()
            .zip(&self.nodal.lambda)
            .map(|(&id, &l)| (self.node_local[id as usize], l))
            .collect()
    }
}

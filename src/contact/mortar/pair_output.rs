//! What a mortar pair hands the result file: nodal fields of the owned
//! slave nodes, the pair's force, and point values interpolated from the
//! nodes.
use super::friction::Rate;
use super::pair::{Evaluation, MortarPair, NodeFields};
use super::system::NodeState;
use crate::contact::outcome::PairForce;
use crate::fem::shape::facet_shape;

/// Per assembled facet row: `(slot, Σ_k D_jk, Σ_k D_jk ν)` (a rigid
/// master: `Σ_k c_jk` for the last), the weights and force directions the
/// output sums.
pub(super) type OutputRows = Vec<(usize, f64, [f64; 3])>;

impl MortarPair {
    /// Owned slave nodes: reference position and λ_j.
    pub fn node_values(&self) -> Vec<([f64; 3], f64)> {
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

    /// Nodal output of the owned nodes and this rank's part of the pair's
    /// force on the slave: `Σ_j λ_j D_jk ν` summed over `k` (`D` of the
    /// current segments), or `Σ_j λ_j c_jk` against a rigid master, so the
    /// force is the one the residual applied.
    pub fn output(
        &self,
        u_local: &[f64],
        rate: Option<&Rate>,
        factor: f64,
    ) -> (NodeFields, PairForce) {
        let x = self.positions(u_local);
        // Per assembled facet row: (slot, Σ_k D_jk, its force direction Σ_k D_jk ν).
        let (states, rows): (Vec<NodeState>, OutputRows) = match &self.rigid {
            Some(_) => self.rigid_output_rows(&x, factor),
            None => {
                let Evaluation {
                    segments, states, ..
                } = self.evaluate(&x, u_local, rate);
                let nf = self.facet_type.nodes();
                let mut rows = Vec::new();
                for seg in segments.iter().filter(|s| self.assembled[s.slave as usize]) {
                    for (a, &n) in self.slave_facets[seg.slave as usize][..nf]
                        .iter()
                        .enumerate()
                    {
                        if let Some(j) = self.nodal.slot_of(n) {
                            let d: f64 = seg.terms.d[a][..nf].iter().sum();
                            rows.push((j, d, seg.terms.normal.map(|c| d * c)));
                        }
                    }
                }
                (states, rows)
            }
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
        let mut out = NodeFields {
            lambda: vec![0.0; n],
            weighted_gap: vec![0.0; n],
            area: vec![0.0; n],
            traction: vec![[0.0; 3]; n],
            lambda_t: self.friction.as_ref().map(|_| vec![[0.0; 3]; n]),
            // Every owned node of either surface (held here or not): where
            // it was at the last Uzawa update, the state written.
            slip_origin: self.friction.as_ref().map(|_| {
                let mut origin = vec![[0.0; 3]; n];
                for &(l, x) in &self.owned_pair_nodes {
                    if let Some(o) = origin.get_mut(l as usize) {
                        let u = crate::dofs::LocalNode::from_u32(l).value(u_local);
                        *o = [x[0] + u[0], x[1] + u[1], x[2] + u[2]];
                    }
                }
                origin
            }),
        };
        for j in (0..self.owned.len()).filter(|&j| self.owned[j]) {
            let l = self.node_local[self.nodal.nodes[j] as usize] as usize;
            if l >= n {
                continue;
            }
            out.lambda[l] = self.nodal.lambda[j];
            out.weighted_gap[l] = states[j].weighted_gap;
            out.area[l] = self.nodal.area[j];
            if let Some(lt) = &mut out.lambda_t {
                lt[l] = *lambda_t(j);
            }
            let len = crate::contact::autodiff::norm(&normal_sum[j]);
            if len > 0.0 {
                let t = lambda_t(j);
                out.traction[l] =
                    [0, 1, 2].map(|i| -self.nodal.lambda[j] * normal_sum[j][i] / len - t[i]);
            }
        }
        (out, force)
    }

    /// Adds λ_j of every owned node into the nodal contact-pressure field
    /// (indexed by owned local node; the denominator counts the pairs).
    pub fn add_nodal_pressure(&self, numerator: &mut [f64], denominator: &mut [f64]) {
        for j in (0..self.owned.len()).filter(|&j| self.owned[j]) {
            let l = self.node_local[self.nodal.nodes[j] as usize] as usize;
            if let (Some(n), Some(d)) = (numerator.get_mut(l), denominator.get_mut(l)) {
                *n += self.nodal.lambda[j];
                *d += 1.0;
            }
        }
    }

    /// Friction at the slave points of `slave` (output): the nodal traction
    /// on the slave (−λT_j) and slip interpolated like the pressure, and the
    /// state (0 open where `pressure` is 0, else 2 if a node of the facet
    /// slides, else 1). Empty for a frictionless pair.
    pub fn point_friction(
        &self,
        slave: &crate::contact::surfaces::SlaveSurface,
        pressure: &[f64],
    ) -> (Vec<[f64; 3]>, Vec<[f64; 3]>, Vec<i8>) {
        use crate::contact::multipliers::PointState;
        let Some(f) = &self.friction else {
            return Default::default();
        };
        let by_node: std::collections::HashMap<u32, usize> = (0..self.nodal.nodes.len())
            .map(|j| (self.node_local[self.nodal.nodes[j] as usize], j))
            .collect();
        let mut out: (Vec<[f64; 3]>, Vec<[f64; 3]>, Vec<i8>) = Default::default();
        for (q, p) in pressure.iter().enumerate() {
            let s = facet_shape(slave.facet_type, slave.qp_zeta[q]);
            let (mut t, mut slip, mut sliding) = ([0.0; 3], [0.0; 3], false);
            for (n, na) in slave.facets[q / slave.nqp].nodes.iter().zip(s.n) {
                if let Some(&j) = by_node.get(&n.to_u32()) {
                    for c in 0..3 {
                        t[c] -= na * f.nodal.lambda[j][c];
                        slip[c] += na * f.slip[j][c];
                    }
                    sliding |= f.sliding[j];
                }
            }
            let state = match (*p > 0.0, sliding) {
                (false, _) => PointState::Open,
                (true, false) => PointState::Stick,
                (true, true) => PointState::Slip,
            };
            out.0.push(t);
            out.1.push(slip);
            out.2.push(state as i8);
        }
        out
    }

    /// λ_j by the slave node's local index, for the nodes this rank holds
    /// (the point output interpolates them with the standard shape functions).
    pub fn lambda_by_local_node(&self) -> std::collections::HashMap<u32, f64> {
        self.nodal
            .nodes
            .iter()
            .zip(&self.nodal.lambda)
            .map(|(&id, &l)| (self.node_local[id as usize], l))
            .collect()
    }
}

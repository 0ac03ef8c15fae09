//! Coulomb friction of a mortar pair against a rigid master: the law of
//! `friction` (the same return map on the nodal multipliers) with slave-only
//! aggregates.
//!
//! Per slave node `j`, over its facets:
//! - weighted slip `ũ_j = Σ_k D_jk Δ_k − d_j Δc` with `d_j = Σ_k D_jk`, `Δ`
//!   the slave nodes' increment of the step (`x − xₙ` quasi-static, `Δt v(x)`
//!   in dynamics) and `Δc` the rigid master's (its prescribed translation
//!   since the last converged step, or `Δt` times its velocity): the slip of
//!   the slave's material points relative to the rigid body, weighted with
//!   `Φ_j`;
//! - node normal from `a_j = Σ ∫ N_j n dA₀`;
//! - residual `+D_jk tT_j` on slave node `k` (the rigid master takes the
//!   reaction). `D` is constant, so the tangent is `D_jk ⊗ ∂tT_j/∂x` alone,
//!   through the aggregates' derivatives (slip branch, coupling to `p_j`
//!   and, in dynamics, the damping `Δt ∂v/∂x`).
use super::friction::{emit_outer, node_law, Increment, NodalFriction, NodeFriction};
use super::rigid::{for_each_node, RigidFacet, RigidInterface, RD};
use super::system::{NodalData, NodeDof, NodeState};
use super::MAX_FACET_NODES;
use crate::contact::autodiff::{self, Scalar, Seed, Vec3};

/// One facet's weighted slip per row, `Σ_k D_ak Δ_k − d_a Δc`.
#[derive(Debug, Clone, Copy)]
pub struct RigidSlip<T> {
    pub slip: [Vec3<T>; MAX_FACET_NODES],
}

/// Every facet's slip terms (same order as `facets`); `master`: the rigid
/// master's increment `Δc` (independent of the slave positions).
pub fn facet_slips<T: Seed>(
    interface: &RigidInterface,
    facets: &[RigidFacet<T>],
    inc: &Increment,
    master: [f64; 3],
) -> Vec<RigidSlip<T>> {
    let ns = interface.facet_type.nodes();
    facets
        .iter()
        .map(|f| {
            let nodes = &interface.facets[f.facet as usize][..ns];
            let mut delta = [autodiff::constant3::<T>([0.0; 3]); MAX_FACET_NODES];
            for (a, (o, &n)) in delta.iter_mut().zip(nodes).enumerate() {
                let v = inc.value[n as usize];
                *o = [0, 1, 2].map(|i| T::seed_scaled(v[i], 3 * a + i, inc.slope));
            }
            let mut slip = [autodiff::constant3::<T>([0.0; 3]); MAX_FACET_NODES];
            for (a, s) in slip.iter_mut().enumerate().take(ns) {
                let row: f64 = f.d[a][..ns].iter().sum();
                *s = autodiff::constant3(master.map(|c| -row * c));
                for (dak, x) in f.d[a].iter().zip(&delta).take(ns) {
                    *s = autodiff::add(s, &autodiff::scale_f64(x, *dak));
                }
            }
            RigidSlip { slip }
        })
        .collect()
}

/// The law at every closed node, from the facets' terms.
pub fn node_frictions<T: Scalar>(
    interface: &RigidInterface,
    nodal: &NodalData,
    friction: &NodalFriction,
    states: &[NodeState],
    facets: &[RigidFacet<T>],
    slips: &[RigidSlip<T>],
) -> Vec<NodeFriction> {
    let nn = nodal.nodes.len();
    let (mut normal, mut slip) = (vec![[0.0; 3]; nn], vec![[0.0; 3]; nn]);
    for_each_node(interface, nodal, facets, false, |index, f, a, j| {
        let s = &slips[index];
        for i in 0..3 {
            normal[j][i] += f.normal[a][i].re();
            slip[j][i] += s.slip[a][i].re();
        }
    });
    (0..nn)
        .map(|j| node_law(nodal, friction, states, j, &normal[j], &slip[j]))
        .collect()
}

/// Adds the tangential residual `+D_jk tT_j` of the assembled facets.
pub fn residual<T: Scalar>(
    interface: &RigidInterface,
    nodal: &NodalData,
    facets: &[RigidFacet<T>],
    frictions: &[NodeFriction],
    mut emit: impl FnMut(u32, usize, f64),
) {
    let ns = interface.facet_type.nodes();
    for_each_node(interface, nodal, facets, true, |_, f, a, j| {
        let fr = &frictions[j];
        if !fr.active || fr.traction == [0.0; 3] {
            return;
        }
        for (k, &node) in interface.facets[f.facet as usize][..ns].iter().enumerate() {
            for (i, t) in fr.traction.iter().enumerate() {
                emit(node, i, f.d[a][k] * t);
            }
        }
    });
}

/// Adds the exact tangent of the tangential residual. `facets` and `slips`
/// must hold every integrated facet of every node of an assembled facet.
pub fn tangent(
    interface: &RigidInterface,
    nodal: &NodalData,
    facets: &[RigidFacet<RD>],
    slips: &[RigidSlip<RD>],
    frictions: &[NodeFriction],
    emit: impl FnMut(NodeDof, NodeDof, f64),
) {
    let ns = interface.facet_type.nodes();
    let nn = nodal.nodes.len();
    let mut grad: Vec<[Vec<(NodeDof, f64)>; 3]> = vec![Default::default(); nn];
    let mut coef: Vec<Vec<(NodeDof, f64)>> = vec![Vec::new(); nn];
    for (f, s) in facets.iter().zip(slips) {
        let ids = &interface.facets[f.facet as usize][..ns];
        let assembled = interface.assembled[f.facet as usize];
        for (a, &node) in ids.iter().enumerate() {
            let Some(j) = nodal.slot_of(node) else {
                continue;
            };
            let fr = &frictions[j];
            if !fr.active {
                continue;
            }
            let aggregates: [&RD; 7] = [
                &f.weighted_gap[a],
                &f.normal[a][0],
                &f.normal[a][1],
                &f.normal[a][2],
                &s.slip[a][0],
                &s.slip[a][1],
                &s.slip[a][2],
            ];
            for v in 0..3 * ns {
                for (g, row) in grad[j].iter_mut().zip(&fr.derivative) {
                    let d: f64 = row.iter().zip(&aggregates).map(|(r, x)| r * x.eps[v]).sum();
                    if d != 0.0 {
                        g.push(((ids[v / 3], v % 3), d));
                    }
                }
            }
            if assembled {
                for (k, &id) in ids.iter().enumerate() {
                    coef[j].push(((id, 0), f.d[a][k]));
                }
            }
        }
    }
    // D ⊗ ∂tT_j/∂x.
    emit_outer(coef, grad, emit);
}

//! The main part of the mortar normal tangent: the analogue of the links'
//! `εN (N ν)(N ν)ᵀ` (`[solver] first_contact_main_tangent`).
//!
//! With `f_j` the force coefficients of node `j` (`+D_jk ν` on slave node
//! `k`, `−M_jl ν` on master node `l`, see `system`), `g̃_j = −f_j·x` at fixed
//! `D`, `M` and `ν`, so dropping the derivatives of `D`, `M`, `ν` and of the
//! clipped polygon leaves `(ε_j/A_j) f_j ⊗ f_j` per closed node: symmetric,
//! positive semi-definite, and computed from the segments' values alone (no
//! dual numbers). The solver uses it in the first Uzawa iteration of a step
//! that starts without contact, where the trial pressures are far above
//! the final ones and the consistent tangent's terms in `p_j` open and
//! close nodes inside the zone; the residual is unchanged, so the answer is.
use super::system::{
    emit_scaled_outer, force_coefficient, segment_nodes, Interface, NodalData, NodeDof, NodeState,
    Segment, SEGMENT_DOFS,
};

/// Adds the main-part tangent: `emit(row, col, value)`. `segments` must hold
/// every segment of every closed node of an assembled facet.
pub(super) fn tangent(
    interface: &Interface,
    nodal: &NodalData,
    segments: &[Segment<f64>],
    states: &[NodeState],
    emit: impl FnMut(NodeDof, NodeDof, f64),
) {
    let ns = interface.slave_type.nodes();
    let nn = nodal.nodes.len();
    // Per closed node: f_j over all its segments (the gradient of g̃_j), and
    // over the assembled ones (the rows this rank adds).
    let mut all: Vec<Vec<(NodeDof, f64)>> = vec![Vec::new(); nn];
    let mut rows: Vec<Vec<(NodeDof, f64)>> = vec![Vec::new(); nn];
    for seg in segments {
        let ids = segment_nodes(interface, seg.slave, seg.master);
        let assembled = interface.assembled[seg.slave as usize];
        for (a, &node) in interface.slave_facets[seg.slave as usize][..ns]
            .iter()
            .enumerate()
        {
            let Some(j) = nodal.slot_of(node).filter(|&j| states[j].closed) else {
                continue;
            };
            for v in 0..SEGMENT_DOFS {
                let id = ids[v / 3];
                if id == u32::MAX {
                    continue;
                }
                let c = force_coefficient(&seg.terms, a, v);
                all[j].push(((id, v % 3), c));
                if assembled {
                    rows[j].push(((id, v % 3), c));
                }
            }
        }
    }
    emit_scaled_outer(nodal, 1.0, rows, all, emit);
}

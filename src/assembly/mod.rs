//! Assembly: element and facet kernels (from `fem`) gathered from this rank's
//! local arrays and added into a matrix or pattern through the traits of
//! `sink` (which the PETSc matrix and `pattern`'s builder implement); the
//! sparsity pattern (symbolic) is recorded apart from the values (numeric).
//!
//! Local arrays are PETSc ghosted-vector local forms: entry 3·l + c is
//! component c of local node l (owned nodes first, then ghosts). Residuals are
//! accumulated there and summed into owners by a reverse ghost update, so only
//! the matrix goes through PETSc's off-rank stash.
pub mod bulk;
pub mod halo;
pub mod loads;
pub mod pattern;
pub mod sink;

pub use bulk::BulkAssembler;
pub use halo::{Halo, HaloFactory, MpiRanks, PetscHalos, RankExchange, SingleRank};
pub use loads::SurfaceLoads;
pub use pattern::PatternBuilder;
pub use sink::{MatrixSink, PatternSink};

use crate::dofs::{DofMap, GlobalDof, LocalNode, DIM};

/// The displacement of `nodes` (local indices) read out of a local-form array.
pub(crate) fn gather_nodal(local: &[f64], nodes: &[LocalNode], out: &mut [[f64; 3]]) {
    for (o, &l) in out.iter_mut().zip(nodes) {
        *o = l.value(local);
    }
}

/// Adds an element vector (node-major, 3 per node) into a local-form array.
pub(crate) fn scatter_add(local: &mut [f64], nodes: &[LocalNode], values: &[f64], sign: f64) {
    for (a, &l) in nodes.iter().enumerate() {
        for c in 0..DIM {
            local[l.vec_index(c)] += sign * values[DIM * a + c];
        }
    }
}

/// Global DOFs of `nodes` (local indices), node-major.
pub(crate) fn element_dofs(dofs: &DofMap, nodes: &[LocalNode], out: &mut Vec<GlobalDof>) {
    out.clear();
    for &l in nodes {
        out.extend(dofs.node_dofs(l));
    }
}

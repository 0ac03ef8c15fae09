//! What a run continues from: the state a restart hands the solver. The
//! reading of a result file into it lives in `crate::restart`, above the
//! solver, so the solver never depends on the file format.
use crate::contact::pair_state::RestartRows;
use crate::contact::ContactPair;
use crate::dofs::{DofMap, LocalNode, DIM};
use crate::error::Result;
use crate::petsc::Vector;
use std::path::PathBuf;

/// What a run continues from.
#[derive(Debug, Clone)]
pub struct RestartState {
    pub path: PathBuf,
    /// Index of the step continued from; the next one written is `step + 1`.
    pub step: usize,
    pub load_factor: f64,
    /// Natural node order, 3 per node.
    pub displacement: Vec<f64>,
    /// Per contact pair of the model, in the model's order.
    pub pairs: Vec<RestartRows>,
}

impl RestartState {
    /// Sets the displacement and every pair's multipliers and friction
    /// history to this state's step (each rank its own rows).
    pub(super) fn take_over(
        &self,
        dofs: &DofMap,
        x: &mut Vector,
        pairs: &mut [ContactPair],
    ) -> Result<()> {
        let start = dofs.owned_dof_start();
        x.with_array_mut(|xa| {
            for l in (0..dofs.num_local_nodes()).map(LocalNode::from_index) {
                if !dofs.is_owned(l) {
                    continue;
                }
                let n = dofs.natural(l).0;
                for c in 0..DIM {
                    let row = dofs.dof(l, c).0 as usize - start;
                    xa[row] = self.displacement[DIM * n + c];
                }
            }
        })?;
        for (pair, rows) in pairs.iter_mut().zip(&self.pairs) {
            pair.restart_from(rows)?;
        }
        Ok(())
    }
}

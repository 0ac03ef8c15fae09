//! What a run continues from: the state a restart hands the solver. The
//! reading of a result file into it lives in `crate::restart`, above the
//! solver, so the solver never depends on the file format.
use crate::contact::fields::RestartRows;
use crate::contact::ContactPair;
use crate::dofs::DofMap;
use crate::error::{Error, Result};
use crate::petsc::Vector;
use std::path::PathBuf;

/// What a run continues from: this rank's share of it only (read after
/// set-up, for the rank's own DOFs and contact points).
#[derive(Debug, Clone)]
pub struct RestartState {
    pub path: PathBuf,
    /// Index of the step continued from; the next one written is `step + 1`.
    pub step: usize,
    pub load_factor: f64,
    /// The displacement of this rank's owned DOFs, in PETSc order (the
    /// owned rows of the solution vector).
    pub displacement: Vec<f64>,
    /// Per contact pair of the model, in the model's order: this rank's rows.
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
        if self.displacement.len() != dofs.num_owned_dofs() {
            return Err(Error::Internal(format!(
                "restart state holds {} displacement rows for {} owned DOFs",
                self.displacement.len(),
                dofs.num_owned_dofs()
            )));
        }
        x.with_array_mut(|xa| xa.copy_from_slice(&self.displacement))?;
        for (pair, rows) in pairs.iter_mut().zip(&self.pairs) {
            pair.restart_from(rows)?;
        }
        Ok(())
    }
}

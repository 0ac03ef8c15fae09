//! What a run continues from: the state a restart hands the solver. The
//! reading of a result file into it lives in `crate::restart`, above the
//! solver, so the solver never depends on the file format.
use crate::contact::pair_state::RestartRows;
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

//! What a rank holds of a mortar pair's node tail between two master
//! exchanges (filled by [`super::share`], read by the pair).
use crate::dofs::GlobalDof;

/// The tail as it stands after the last exchange.
#[derive(Debug, Clone, Default)]
pub(super) struct Holding {
    /// Slave node ids this rank does not see (slots in the tail).
    pub slave_tail: Vec<u32>,
    /// The first tail slot the pair used at the last exchange.
    pub tail_base: Option<usize>,
    /// Global DOFs of the pair's tail, node-major: slave, then master.
    pub tail_dofs: Vec<GlobalDof>,
    /// Per owned pair node: its displacement at the last master exchange.
    pub u_at_exchange: Vec<[f64; 3]>,
}

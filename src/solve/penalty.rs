//! The penalty policy's limits, shared by the Uzawa loop that applies them
//! and the failure report that quotes them.

/// How often, and by how much, a step may raise a slow pair's penalty
/// before the Uzawa loop gives up (the raised penalty stays for the run).
pub(super) const PENALTY_RAISES: usize = 2;
pub(super) const PENALTY_RAISE: f64 = 10.0;

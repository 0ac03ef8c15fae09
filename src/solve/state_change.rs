//! Newton steps that end where the last contact constraint changing
//! between open and closed along them changes (for the pairs whose
//! formulation asks for it, `contact::Traits::state_change_steps`).
//!
//! A backtracking line search shortens a step that crosses a kink of ‖R‖
//! by a tenth at most per Newton iteration. Where a Uzawa update opened
//! constraints (their multipliers had held an open gap), the open
//! tangent's direction (free flight) overshoots into the penalty, and
//! Newton crawls at λ = 0.1 along the same direction until they close; a
//! constraint that opens along a step is the same kink the other way.
//! Before a backtracking line search (`Snes`'s pre-check) the step ends a
//! little past where the last constraint that changes state along it
//! changes, its trial pressure interpolated linearly, so the next direction
//! has its stiffness or is free of it. Not on the l2 line search, nor with
//! linear bodies on the direct path (`Mechanics::state_change_steps`),
//! where friction takes the contact Schur path, whose condensed Newton has
//! no step end positions and must match the whole-vector Newton.
use crate::contact::ContactPair;

/// How far past the last constraint's change a shortened step goes, as a
/// fraction of the rest of the step: it must have changed at the
/// new iterate (its trial pressure a little past zero), or the next
/// direction is the same one again.
const MARGIN: f64 = 0.05;

/// The fraction of the step from `u0` to `u1` at which the last of this
/// rank's constraints that change state on the way changes; None if none
/// does.
pub(super) fn fraction(pairs: &[ContactPair], u0: &[f64], u1: &[f64], factor: f64) -> Option<f64> {
    pairs
        .iter()
        .filter_map(|p| p.state_change_fraction(u0, u1, factor))
        .reduce(f64::max)
}

/// The step fraction a little past `fraction` (agreed over the ranks).
pub(super) fn past(fraction: f64) -> f64 {
    fraction + MARGIN * (1.0 - fraction)
}

//! Newton steps that end where the last mortar node changing between open
//! and closed along them changes.
//!
//! A backtracking line search shortens a step that crosses a kink of ‖R‖
//! by a tenth at most per Newton iteration. Where a Uzawa update opened
//! mortar nodes (their multipliers had held an open gap), the open
//! tangent's direction (free flight) overshoots into the penalty, and
//! Newton crawled at λ = 0.1 along the same direction until the nodes
//! closed (`impact`, step 17: 14 such steps before the full step was
//! taken); a node that opens along a step is the same kink the other way.
//! Before a backtracking line search (`Snes`'s pre-check) the step now ends
//! a little past where the last node that changes state along it changes,
//! its trial pressure interpolated linearly, so the next direction has the
//! node's stiffness or is free of it. Measured (`contactlink run SCENE`,
//! without / closing nodes only / both directions): `impact` 164 / 143 /
//! 143 Newton iterations; ironing 588 / 605 / 582, the same forces;
//! frictional hertz-sphere h = 0.35 on 2 ranks (GMRES + GAMG) 15 / 11 / 11
//! Newton, 337 / 225 / 225 GMRES. Not on the l2 line search (linear
//! frictionless bodies; there it made hertz-sphere h = 0.35 take one more
//! Uzawa iteration), nor with linear bodies on the direct path
//! (`Mechanics::state_change_steps`), where friction takes the contact
//! Schur path, whose condensed Newton has no step end positions and must
//! match the whole-vector Newton.
use crate::contact::ContactPair;

/// How far past the last node's change a shortened step goes, as a
/// fraction of the rest of the step: the node must have changed at the
/// new iterate (its trial pressure a little past zero), or the next
/// direction is the same one again.
const MARGIN: f64 = 0.05;

/// The fraction of the step from `u0` to `u1` at which the last of this
/// rank's mortar nodes that change state on the way changes; None if none
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

//! The penalty policy's limits, shared by the Uzawa loop that applies them
//! and the failure report that quotes them, and the rate rule that raises
//! a slowly converging pair's penalty within a step.

/// How often, and by how much, a step may raise a slow pair's penalty
/// before the Uzawa loop gives up (the raised penalty stays for the run).
pub(super) const PENALTY_RAISES: usize = 2;
pub(super) const PENALTY_RAISE: f64 = 10.0;

/// The rate rule: an Uzawa iteration that leaves a pair's relative
/// multiplier change above `RATE_LIMIT` times the last one's, so far above
/// the tolerance that at that rate it would take more than `RATE_ROUNDS`
/// further iterations to meet it, raises that pair's penalty by
/// `RATE_RAISE`, at most `RATE_RAISES` times a step. A slow rate just above
/// the tolerance is left alone: the raise restarts the contraction (graded
/// line b/10, rate 0.74 at 1.01 × the tolerance: 12 → 17 Newton iterations
/// when raised there).
///
/// Uzawa's multipliers contract by about K / (K + εN) an iteration, K the
/// stiffness the contact zone's edge sees; where that is near 1 (graded
/// Hertz line, h_c = b/5, 10E/h: the relative change 5.3e-3, 4.1e-3, 3.4e-3,
/// 1.6e-3, 2.8e-3, ... for 11 iterations while the zone's edge points open
/// one by one) a larger penalty is what makes it converge, and the
/// augmented Lagrangian's solution does not depend on the penalty. Raising
/// it from the start costs Newton iterations where Uzawa is fast (finer
/// meshes), so the rule raises it only where the loop measurably stalls,
/// and only on the direct path (`tolerance::rate_rule`).
pub(super) const RATE_LIMIT: f64 = 0.5;
pub(super) const RATE_RAISE: f64 = 10.0;
pub(super) const RATE_RAISES: usize = 1;
pub(super) const RATE_ROUNDS: f64 = 3.0;

/// A pair's Uzawa progress over the iterations of one step: its relative
/// multiplier change (change over the largest nodal force or the pair's
/// force floor) of the last iteration, if there was one since the step
/// started, the soft first iteration ended or the penalty was raised.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub(super) struct Progress {
    last: Option<f64>,
}

impl Progress {
    /// Records this iteration's relative change and says whether it shows
    /// a stall: not converged, no better than `RATE_LIMIT` of the last, and
    /// more than `RATE_ROUNDS` iterations from the relative tolerance `tol`
    /// at that rate.
    pub(super) fn stalls(&mut self, relative_change: f64, tol: f64, converged: bool) -> bool {
        let Some(last) = self.last.replace(relative_change) else {
            return false;
        };
        let rate = relative_change / last;
        if converged || rate.is_nan() || rate <= RATE_LIMIT || relative_change <= tol {
            return false;
        }
        rate >= 1.0 || (tol / relative_change).ln() / rate.ln() > RATE_ROUNDS
    }

    /// Forgets the history (a penalty change makes the next rate a new one).
    pub(super) fn forget(&mut self) {
        self.last = None;
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const TOL: f64 = 1e-3;

    #[test]
    fn a_halving_change_is_not_a_stall_a_slower_one_is() {
        let mut p = Progress::default();
        assert!(!p.stalls(1e-2, TOL, false), "no rate from one iteration");
        assert!(!p.stalls(4e-3, TOL, false), "0.4 of the last: contracting");
        // 0.75 of the last at 3 × the tolerance: 3.8 more iterations.
        assert!(p.stalls(3e-3, TOL, false), "0.75 of the last: stalled");
    }

    #[test]
    fn a_slow_rate_next_to_the_tolerance_is_not_a_stall() {
        // Graded line b/10: 1.372e-3 then 1.009e-3, rate 0.74, 0.03 more
        // iterations to go at that rate.
        let mut p = Progress::default();
        p.stalls(1.372e-3, TOL, false);
        assert!(!p.stalls(1.009e-3, TOL, false));
    }

    #[test]
    fn a_growing_change_is_a_stall() {
        let mut p = Progress::default();
        p.stalls(1.1e-3, TOL, false);
        assert!(p.stalls(1.2e-3, TOL, false));
    }

    #[test]
    fn a_converged_pair_never_stalls() {
        let mut p = Progress::default();
        p.stalls(1e-2, TOL, false);
        assert!(!p.stalls(9e-3, TOL, true));
    }

    #[test]
    fn forgetting_starts_the_rate_over() {
        let mut p = Progress::default();
        p.stalls(1e-2, TOL, false);
        p.forget();
        assert!(!p.stalls(1e-2, TOL, false));
        assert!(p.stalls(1e-2, TOL, false));
    }
}

//! The penalty εN of the augmented Lagrangian, in one place for every
//! formulation: the normal law it enters (pN = ⟨λN − εN gN⟩, also the Uzawa
//! update of λN), its default value, and the policy that changes it within
//! a load step (raised where the Uzawa loop is slow, softened for a step's
//! first contact). The policy decides factors; each pair applies them to
//! its own penalties (`ContactPair::raise_penalty`), so a formulation only
//! has to scale what it stores. The augmented Lagrangian converges to the
//! same solution for any penalty, only faster for a larger one: changing
//! it keeps the multipliers.
use super::autodiff::Scalar;

/// `λN − εN gN`, the augmented normal traction: a contact is closed when it
/// is ≥ 0, and it is then the contact pressure. Generic in the scalar type
/// so that the dual pass of a tangent differentiates this same expression.
pub fn trial_pressure<T: Scalar>(lambda_n: f64, penalty: f64, gap: T) -> T {
    -(gap * penalty) + lambda_n
}

/// The contact pressure `pN = ⟨λN − εN gN⟩`, never negative (contact cannot
/// pull). It is also the Uzawa update of the multiplier: λN ← pN.
pub fn contact_pressure(lambda_n: f64, penalty: f64, gap: f64) -> f64 {
    trial_pressure(lambda_n, penalty, gap).max(0.0)
}

/// The default εN of a slave facet or node of element size `h`, against
/// the softest body of the model (Young's modulus `softest_youngs`): stiff
/// enough that a penetration of a small fraction of `h` carries the
/// contact pressure, soft enough to keep Newton's tangent well
/// conditioned. A user value (`penalty` in the scene) replaces it.
pub fn default_normal(user: Option<f64>, softest_youngs: f64, h: f64) -> f64 {
    user.unwrap_or(DEFAULT_RATIO * softest_youngs / h)
}

/// εN = `DEFAULT_RATIO` · E / h.
pub const DEFAULT_RATIO: f64 = 10.0;

/// How often, and by how much, a step may raise a slow pair's penalty
/// before the Uzawa loop gives up (the raised penalty stays for the run).
pub const ROUND_RAISES: usize = 2;
pub const ROUND_RAISE: f64 = 10.0;

/// The rate rule: an Uzawa iteration that leaves a frictionless pair's
/// relative multiplier change above `RATE_LIMIT` times the last one's, so
/// far above the tolerance that at that rate it would take more than
/// `RATE_ROUNDS` further iterations to meet it, raises that pair's penalty
/// by `RATE_RAISE`, at most `RATE_RAISES` times a step. A slow rate just
/// above the tolerance is left alone: the raise restarts the contraction.
///
/// Uzawa's multipliers contract by about K / (K + εN) an iteration, K the
/// stiffness the contact zone's edge sees; where that is near 1 a larger
/// penalty is what makes the loop converge. Raising it from the start
/// costs Newton iterations where Uzawa is fast, so the rule raises it only
/// where the loop measurably stalls, and only where a stiffer contact
/// costs a factorisation rather than Krylov iterations ([`rate_rule`]).
/// Friction keeps its penalty: its stick/slip classification, not the
/// rate, sets its pace.
pub const RATE_LIMIT: f64 = 0.5;
pub const RATE_RAISE: f64 = 10.0;
pub const RATE_RAISES: usize = 1;
pub const RATE_ROUNDS: f64 = 3.0;

/// Whether the rate rule applies: on the direct path only. On the Krylov
/// path a raised penalty meets an AMG hierarchy built for the elastic
/// bodies, and Newton then crawls in one-iteration GMRES steps.
pub fn rate_rule(krylov: bool) -> bool {
    !krylov
}

/// A pair's Uzawa progress over the iterations of one step: its relative
/// multiplier change (change over the largest nodal force or the pair's
/// force floor) of the last iteration, if there was one since the step
/// started, the soft first iteration ended or the penalty was raised.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct Progress {
    last: Option<f64>,
}

impl Progress {
    /// Records this iteration's relative change and says whether it shows
    /// a stall: not converged, no better than `RATE_LIMIT` of the last, and
    /// more than `RATE_ROUNDS` iterations from the relative tolerance `tol`
    /// at that rate.
    pub fn stalls(&mut self, relative_change: f64, tol: f64, converged: bool) -> bool {
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
    pub fn forget(&mut self) {
        self.last = None;
    }
}

/// One pair's figures after an Uzawa update, as the policy reads them.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PairProgress {
    /// Passed the Uzawa test.
    pub converged: bool,
    /// Multiplier change over the largest nodal force (or the force floor).
    pub relative_change: f64,
    /// The pair's relative multiplier tolerance.
    pub tolerance: f64,
    pub frictional: bool,
}

/// The policy's state over the Uzawa iterations of one load step.
#[derive(Debug, Clone)]
pub struct StepPenalties {
    /// The divisor every pair's penalty holds while the step's first,
    /// softened iteration runs (see [`StepPenalties::soften`]).
    softened: Option<f64>,
    /// Rounds ended with a raise, and raises by the rate rule.
    round_raises: usize,
    rate_raises: usize,
    rate_rule: bool,
    progress: Vec<Progress>,
}

impl StepPenalties {
    /// `pairs` contact pairs; `rate_rule`: whether [`rate_rule`] applies.
    pub fn new(pairs: usize, rate_rule: bool) -> Self {
        StepPenalties {
            softened: None,
            round_raises: 0,
            rate_raises: 0,
            rate_rule,
            progress: vec![Progress::default(); pairs],
        }
    }

    /// A step that starts with no multiplier in contact on any rank solves
    /// its first Uzawa iteration as a pure penalty problem from a deeply
    /// penetrating first iterate; a softer penalty (εN / `softening`)
    /// makes that solve smoother, and its multipliers a first estimate of
    /// the pressure. Returns the factor every pair's penalty is to be
    /// scaled by now (None: not softened: `softening` ≤ 1, friction, or
    /// contact already carried by multipliers).
    pub fn soften(&mut self, softening: f64, frictional: bool, no_contact: bool) -> Option<f64> {
        (softening > 1.0 && !frictional && no_contact).then(|| {
            self.softened = Some(softening);
            1.0 / softening
        })
    }

    /// Whether the penalties are softened now.
    pub fn is_softened(&self) -> bool {
        self.softened.is_some()
    }

    /// Ends the softening (once): the factor that gives every pair its own
    /// penalty back. The rates measured so far are forgotten.
    pub fn unsoften(&mut self) -> Option<f64> {
        let s = self.softened.take()?;
        self.forget_progress();
        Some(s)
    }

    pub fn forget_progress(&mut self) {
        self.progress.iter_mut().for_each(Progress::forget);
    }

    /// The rate rule after an Uzawa update that did not converge: per pair,
    /// whether to raise its penalty by [`RATE_RAISE`] now.
    pub fn stalled(&mut self, pairs: &[PairProgress]) -> Vec<bool> {
        let none = vec![false; pairs.len()];
        if !self.rate_rule || self.rate_raises >= RATE_RAISES {
            return none;
        }
        let raise: Vec<bool> = pairs
            .iter()
            .zip(self.progress.iter_mut())
            .map(|(p, pr)| {
                let stalls = pr.stalls(p.relative_change, p.tolerance, p.converged);
                if stalls && !p.frictional {
                    pr.forget();
                    true
                } else {
                    false
                }
            })
            .collect();
        if raise.iter().any(|r| *r) {
            self.rate_raises += 1;
        }
        raise
    }

    /// After a round of Uzawa iterations that ended unconverged: per pair,
    /// whether to raise its penalty by [`ROUND_RAISE`] and start another
    /// round (the pairs still outside their tolerances), or None when the
    /// step has used its [`ROUND_RAISES`] and fails.
    pub fn round_end(&mut self, converged: &[bool]) -> Option<Vec<bool>> {
        if self.round_raises >= ROUND_RAISES {
            return None;
        }
        self.round_raises += 1;
        self.forget_progress();
        Some(converged.iter().map(|c| !c).collect())
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
        // Rate 0.74 at 1.01 × the tolerance: 0.03 more iterations to go.
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

    fn progress(relative_change: f64, frictional: bool) -> PairProgress {
        PairProgress {
            converged: false,
            relative_change,
            tolerance: TOL,
            frictional,
        }
    }

    #[test]
    fn the_rate_rule_raises_a_stalled_frictionless_pair_once_a_step() {
        let mut s = StepPenalties::new(2, true);
        let first = [progress(1e-2, false), progress(1e-2, true)];
        assert_eq!(s.stalled(&first), [false, false]);
        let second = [progress(9e-3, false), progress(9e-3, true)];
        assert_eq!(
            s.stalled(&second),
            [true, false],
            "friction keeps its penalty"
        );
        let third = [progress(9e-3, false), progress(8.9e-3, false)];
        assert_eq!(s.stalled(&third), [false, false], "one raise a step");
        let mut off = StepPenalties::new(1, false);
        off.stalled(&[progress(1e-2, false)]);
        assert_eq!(off.stalled(&[progress(9e-3, false)]), [false]);
    }

    #[test]
    fn rounds_raise_the_unconverged_pairs_until_the_limit() {
        let mut s = StepPenalties::new(2, true);
        for _ in 0..ROUND_RAISES {
            assert_eq!(s.round_end(&[true, false]), Some(vec![false, true]));
        }
        assert_eq!(s.round_end(&[true, false]), None);
    }

    #[test]
    fn softening_is_undone_once() {
        let mut s = StepPenalties::new(1, true);
        assert_eq!(s.soften(1.0, false, true), None, "1: off");
        assert_eq!(s.soften(10.0, true, true), None, "friction");
        assert_eq!(s.soften(10.0, false, false), None, "contact carried");
        assert_eq!(s.soften(10.0, false, true), Some(0.1));
        assert!(s.is_softened());
        assert_eq!(s.unsoften(), Some(10.0));
        assert_eq!(s.unsoften(), None);
    }

    #[test]
    fn the_default_is_ten_youngs_over_h_unless_given() {
        assert_eq!(default_normal(None, 200.0, 0.5), 4000.0);
        assert_eq!(default_normal(Some(7.0), 200.0, 0.5), 7.0);
        assert_eq!(contact_pressure(1.0, 10.0, 0.05), 0.5);
        assert_eq!(contact_pressure(1.0, 10.0, 0.2), 0.0);
    }
}

//! How tightly Newton solves inside the Uzawa loop.
//!
//! Only the last Uzawa iteration's displacement is kept; every earlier one
//! is the start of the next, whose multiplier update moves the residual by
//! the size of the multiplier change anyway. Solving those to the step's
//! final tolerance is oversolving: it costs Newton iterations (and, in the
//! first round, factorisations) per Uzawa iteration.
//!
//! The two tolerances are coupled, not fixed apart: a non-final Newton solve
//! stops once its residual has fallen by `forcing` relative to that solve's
//! own start, i.e. relative to the last multiplier update, so the error it
//! leaves is a fixed fraction of the change the Uzawa test measures and the
//! test can still resolve convergence (a fixed absolute loose tolerance
//! leaves errors above the test's resolution and the loop stalls). When the Uzawa test passes after a loose solve, the multipliers
//! are kept and Newton runs once more to the final tolerance, followed by
//! the usual update and test: the step's answer is as tight as before.

/// The forcing of non-final solves on the Krylov path (GMRES + AMG) when
/// the settings keep the default (`DEFAULT_FORCING`, 1e-3).
///
/// There every decade of residual costs GMRES iterations with the same
/// preconditioner applications a plain solve makes, while on the direct
/// path it costs a Newton iteration around kept factors (one triangular
/// solve). A non-final solve's error is only the start of the next
/// multiplier update, so on the Krylov path one decade less per Uzawa
/// iteration is cheaper than the Uzawa iterations it may add
/// (docs/performance.md, "The solver paths").
pub const KRYLOV_FORCING: f64 = 1e-2;

/// The forcing of non-final solves: the setting, except that the Krylov
/// path takes `KRYLOV_FORCING` where the setting is the default.
pub fn inner_forcing(setting: f64, krylov: bool) -> f64 {
    if krylov && setting == crate::model::DEFAULT_FORCING {
        KRYLOV_FORCING
    } else {
        setting
    }
}

/// The Anderson depth of the Uzawa updates (`solve::anderson`): the
/// setting, or unset `DEFAULT_ACCELERATION` on the Krylov path and 0 on
/// the direct path. On the Krylov path an Uzawa iteration saved is a
/// Newton solve of tens of GMRES iterations; on the direct path Newton
/// iterations around kept factors are cheap, and the extrapolated
/// multipliers' larger residual costs more of them than the Uzawa
/// iterations saved.
pub fn inner_acceleration(setting: Option<usize>, krylov: bool) -> usize {
    match setting {
        Some(depth) => depth,
        None if krylov => crate::model::DEFAULT_ACCELERATION,
        None => 0,
    }
}

/// On the Krylov path with contact, a Newton iteration's GMRES stops once
/// its residual is below this fraction of what the Newton solve still has
/// to remove (`linsolve::set_linear_floor`), however tight the
/// Eisenstat–Walker tolerance: that tolerance follows Newton's last rate
/// and asks the last iteration of a solve for far more than is left.
/// Every solve of a contact step gets it, the last one too, which then
/// ends a tenth below the step's tolerance instead of orders of magnitude
/// further down (the contact force still balances the reactions to the
/// 1e-7 tests/contact.rs asks). At 0.5 Newton stalls on the Hertz sphere.
pub const LINEAR_FLOOR: f64 = 0.1;

/// SNES's stopping rule for one Newton solve: |R| ≤ max(atol, rtol·|R0|).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct NewtonTolerance {
    pub atol: f64,
    pub rtol: f64,
}

/// The final tolerance of a step and the looser one of its non-final Uzawa
/// iterations.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct InnerTolerance {
    /// What the step's last Newton solve must meet (the options' values).
    pub tight: NewtonTolerance,
    /// Relative residual reduction of a non-final solve; 0: every solve tight.
    pub forcing: f64,
}

impl InnerTolerance {
    pub fn new(tight: NewtonTolerance, forcing: f64) -> Self {
        InnerTolerance { tight, forcing }
    }

    /// Whether non-final solves are loosened at all.
    pub fn is_inexact(&self) -> bool {
        self.forcing > self.tight.rtol
    }

    /// The rule for a solve: `tight` for the step's last one (or every one
    /// when there is no contact), else the reduction `forcing` of the
    /// solve's starting residual, never looser than that nor tighter than
    /// the final tolerance.
    pub fn for_solve(&self, tight: bool) -> NewtonTolerance {
        if tight || !self.is_inexact() {
            self.tight
        } else {
            NewtonTolerance {
                atol: self.tight.atol,
                rtol: self.forcing,
            }
        }
    }
}

/// What the Uzawa loop does after a multiplier update.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum RoundEnd {
    /// The Uzawa test passed on a tightly solved state: the step is done.
    Converged,
    /// The test passed, but the state was solved loosely: solve once more
    /// to the final tolerance, then test again.
    Confirm,
    /// The test failed: another Uzawa iteration.
    Continue,
}

/// The outcome of a round from the Uzawa test and how its Newton solve was
/// stopped.
pub fn round_end(uzawa_converged: bool, solved_tight: bool) -> RoundEnd {
    match (uzawa_converged, solved_tight) {
        (true, true) => RoundEnd::Converged,
        (true, false) => RoundEnd::Confirm,
        (false, _) => RoundEnd::Continue,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const TIGHT: NewtonTolerance = NewtonTolerance {
        atol: 1e-10,
        rtol: 1e-9,
    };

    #[test]
    fn a_loose_solve_keeps_the_final_absolute_floor() {
        let t = InnerTolerance::new(TIGHT, 1e-3);
        assert_eq!(t.for_solve(true), TIGHT);
        let loose = t.for_solve(false);
        assert_eq!(loose.rtol, 1e-3);
        assert_eq!(loose.atol, TIGHT.atol);
    }

    #[test]
    fn a_forcing_at_or_below_the_final_rtol_means_every_solve_is_tight() {
        for forcing in [0.0, 1e-9, 1e-12] {
            let t = InnerTolerance::new(TIGHT, forcing);
            assert!(!t.is_inexact());
            assert_eq!(t.for_solve(false), TIGHT);
        }
    }

    #[test]
    fn the_krylov_path_loosens_only_the_default_forcing() {
        let d = crate::model::DEFAULT_FORCING;
        assert_eq!(inner_forcing(d, false), d);
        assert_eq!(inner_forcing(d, true), KRYLOV_FORCING);
        for f in [0.0, 1e-4, 0.1] {
            assert_eq!(inner_forcing(f, true), f, "a user's forcing stands");
        }
    }

    #[test]
    fn the_direct_path_accelerates_only_when_asked() {
        let d = crate::model::DEFAULT_ACCELERATION;
        assert_eq!(inner_acceleration(None, true), d);
        assert_eq!(inner_acceleration(None, false), 0);
        for n in [0, 1, 2, 3] {
            for krylov in [false, true] {
                assert_eq!(
                    inner_acceleration(Some(n), krylov),
                    n,
                    "a user's depth stands"
                );
            }
        }
    }

    #[test]
    fn a_loose_pass_is_confirmed_before_the_step_ends() {
        assert_eq!(round_end(true, true), RoundEnd::Converged);
        assert_eq!(round_end(true, false), RoundEnd::Confirm);
        assert_eq!(round_end(false, false), RoundEnd::Continue);
        assert_eq!(round_end(false, true), RoundEnd::Continue);
    }
}

//! Why a load increment failed, as every rank sees it, and the text the
//! cutback line and the final error print: the contact constraints at the
//! failing iterate, a failed linear solve's KSP reason and the rank whose
//! Jacobian rows are not finite.
use super::mechanics::Mechanics;
use crate::contact::penalty::{ROUND_RAISE, ROUND_RAISES};
use crate::contact::{Census, UzawaStats};
use crate::error::Result;
use crate::parallel;
use crate::petsc::{Matrix, SnesOutcome, SnesReason, Vector};
use mpi::traits::Communicator;

/// Why a load increment failed (the same on every rank).
pub(super) enum StepFailure {
    /// The step's first residual, before Newton, failed on some rank.
    Residual(String),
    /// Newton failed; with each pair's constraints at the failing iterate
    /// (one clause each, over all ranks), and for a failed linear solve the
    /// rank whose Jacobian rows are not finite.
    Newton {
        outcome: SnesOutcome,
        contact: Vec<String>,
        jacobian: Option<String>,
    },
    Uzawa {
        iterations: usize,
        stats: UzawaStats,
    },
    /// A converged Newton solve left the contact candidates of the step's
    /// search: some slave facet now meets a master facet it was not paired
    /// with (see `ContactPair::covers`). The step goes on after a search
    /// from this state (its counts so far); a failure once the searches of
    /// an attempt are used up.
    Uncovered { outcome: SnesOutcome, uzawa: usize },
}

impl StepFailure {
    pub(super) fn linear_solve_failed(&self) -> bool {
        matches!(self, StepFailure::Newton { outcome, .. } if outcome.reason == SnesReason::LinearSolve)
    }
}

/// Collective, on a failed Newton solve (the same on every rank): the link
/// states at the failing iterate, and for a failed linear solve the lowest
/// rank whose Jacobian rows hold non-finite values.
pub(super) fn newton_failure(
    world: &impl Communicator,
    mech: &mut Mechanics,
    x: &Vector,
    jac: &Matrix,
    factor: f64,
    outcome: SnesOutcome,
) -> Result<StepFailure> {
    let jacobian = if outcome.reason == SnesReason::LinearSolve {
        let row = jac.first_nonfinite_owned_row()?;
        let local = row.map(|r| (0, format!("the Jacobian holds NaN or Inf in row {r}")));
        parallel::agree_failure(world, local).map(|f| format!("rank {}: {}", f.rank, f.message))
    } else {
        None
    };
    // A NaN iterate has no meaningful contact states (and no gap to compute).
    let contact = if x.norm2()?.is_finite() {
        censuses(world, mech, x, factor)?
    } else {
        Vec::new()
    };
    Ok(StepFailure::Newton {
        outcome,
        contact,
        jacobian,
    })
}

/// Collective: every pair's constraints at the iterate `x`, summed and
/// maximised over the ranks, as one clause each.
fn censuses(
    world: &impl Communicator,
    mech: &mut Mechanics,
    x: &Vector,
    factor: f64,
) -> Result<Vec<String>> {
    let local = mech.with_state(x, |u, pairs| {
        pairs
            .iter_mut()
            .map(|p| p.census(u, factor))
            .collect::<Result<Vec<Census>>>()
    });
    let local = parallel::agree(world, local)?;
    Ok(mech
        .contact
        .iter()
        .zip(local)
        .map(|(p, c)| {
            let [pressed, sliding] = parallel::sum_usize(world, [c.pressed, c.sliding]);
            let [max_penetration] = parallel::max(world, [c.max_penetration]);
            p.describe_census(&Census {
                pressed,
                sliding,
                max_penetration,
            })
        })
        .collect())
}

pub(super) fn failure_text(f: &StepFailure) -> String {
    match f {
        StepFailure::Residual(why) => format!("the step's first residual failed: {why}"),
        StepFailure::Newton {
            outcome: o,
            contact,
            jacobian,
        } => {
            let mut text = match (&o.domain_error, o.reason) {
                (Some(d), _) => format!("Newton iteration {}: {d}", o.iterations),
                (None, SnesReason::LinearSolve) => format!(
                    "the linear solve failed in Newton iteration {}: {} after {} iterations",
                    o.iterations, o.ksp_reason, o.ksp_iterations
                ),
                (None, reason) => format!(
                    "{reason} after {} iterations, |R| = {:.3e}",
                    o.iterations, o.residual_norm
                ),
            };
            if let Some(j) = jacobian {
                text += &format!(" ({j})");
            }
            for clause in contact {
                text += "; ";
                text += clause;
            }
            text
        }
        StepFailure::Uzawa { iterations, stats } => format!(
            "Uzawa loop did not converge in {iterations} iterations, the last ones with the penalty raised {}× (max penetration {:.3e} of the element size, max nodal contact force change {:.3e} of max {:.3e})",
            ROUND_RAISE.powi(ROUND_RAISES as i32),
            stats.max_penetration, stats.max_change, stats.max_force
        ),
        StepFailure::Uncovered { uzawa, .. } => format!(
            "the contact zone still grew past the contact search's candidates after {uzawa} Uzawa iterations and every search an attempt may make"
        ),
    }
}

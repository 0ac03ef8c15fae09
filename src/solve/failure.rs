//! Why a load increment failed, as every rank sees it, and the text the
//! cutback line and the final error print: the failing iterate's link
//! states, a failed linear solve's KSP reason and the rank whose Jacobian
//! rows are not finite.
use super::mechanics::Mechanics;
use super::penalty::{PENALTY_RAISE, PENALTY_RAISES};
use crate::contact::UzawaStats;
use crate::error::Result;
use crate::parallel;
use crate::petsc::{Matrix, SnesOutcome, SnesReason, Vector};
use mpi::traits::Communicator;

/// Why a load increment failed (the same on every rank).
pub(super) enum StepFailure {
    /// The step's first residual, before Newton, failed on some rank.
    Residual(String),
    /// Newton failed; with the link states at the failing iterate, and for
    /// a failed linear solve the rank whose Jacobian rows are not finite.
    Newton {
        outcome: SnesOutcome,
        links: Vec<(String, LinkSummary)>,
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

/// One pair's links at an iterate: points pressed together (gap < 0 or a
/// positive multiplier), sliding, and the deepest penetration (totals and
/// maxima over ranks). A mortar pair's are its slave nodes (p_j > 0) and
/// their deepest mean penetration g̃_j / A_j relative to the element size.
#[derive(Debug, Clone, Copy, Default)]
pub(super) struct LinkSummary {
    pressed: usize,
    sliding: usize,
    max_penetration: f64,
    mortar: bool,
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
    // A NaN iterate has no meaningful link states (and no gap to compute).
    let links = if x.norm2()?.is_finite() {
        links_at(world, mech, x, factor)?
    } else {
        Vec::new()
    };
    Ok(StepFailure::Newton {
        outcome,
        links,
        jacobian,
    })
}

/// Collective: [`LinkSummary`] of every pair at the iterate `x`.
fn links_at(
    world: &impl Communicator,
    mech: &mut Mechanics,
    x: &Vector,
    factor: f64,
) -> Result<Vec<(String, LinkSummary)>> {
    let local = mech.with_state(x, |u, pairs| {
        pairs
            .iter_mut()
            .map(|p| {
                if let Some(s) = p.mortar_census(u, factor) {
                    return Ok((s.active, s.sliding, s.max_penetration));
                }
                let (v, _) = p.point_values(u, factor)?;
                let pressed = v
                    .gap
                    .iter()
                    .zip(&v.lambda)
                    .filter(|(g, l)| **g < 0.0 || **l > 0.0)
                    .count();
                let sliding = v.state.iter().filter(|s| **s == 2).count();
                let depth = v.gap.iter().fold(0.0f64, |m, g| m.max(-g));
                Ok((pressed, sliding, depth))
            })
            .collect::<Result<Vec<_>>>()
    });
    let local = parallel::agree(world, local)?;
    Ok(mech
        .contact
        .iter()
        .zip(local)
        .map(|(p, (pressed, sliding, depth))| {
            let [pressed, sliding] = parallel::sum_usize(world, [pressed, sliding]);
            let [max_penetration] = parallel::max(world, [depth]);
            let summary = LinkSummary {
                pressed,
                sliding,
                max_penetration,
                mortar: p.is_mortar(),
            };
            (p.spec.name.clone(), summary)
        })
        .collect())
}

pub(super) fn failure_text(f: &StepFailure) -> String {
    match f {
        StepFailure::Residual(why) => format!("the step's first residual failed: {why}"),
        StepFailure::Newton {
            outcome: o,
            links,
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
            for (name, s) in links {
                let sticking = s.pressed - s.sliding.min(s.pressed);
                text += &if s.mortar {
                    format!(
                        "; slave nodes of mortar pair '{name}' at the failing iterate: {} pressed together (p > 0), {} sliding, {sticking} sticking, max mean penetration {:.3e} of the element size",
                        s.pressed, s.sliding, s.max_penetration
                    )
                } else {
                    format!(
                        "; links of pair '{name}' at the failing iterate: {} pressed together (gap < 0 or λN > 0), {} sliding, {sticking} sticking, max penetration {:.3e}",
                        s.pressed, s.sliding, s.max_penetration
                    )
                };
            }
            text
        }
        StepFailure::Uzawa { iterations, stats } => format!(
            "Uzawa loop did not converge in {iterations} iterations, the last ones with the penalty raised {}× (max penetration {:.3e} of the element size, max nodal contact force change {:.3e} of max {:.3e})",
            PENALTY_RAISE.powi(PENALTY_RAISES as i32),
            stats.max_penetration, stats.max_change, stats.max_force
        ),
        StepFailure::Uncovered { uzawa, .. } => format!(
            "the contact zone still grew past the contact search's candidates after {uzawa} Uzawa iterations and every search an attempt may make"
        ),
    }
}

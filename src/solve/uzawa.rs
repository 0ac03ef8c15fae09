//! The Uzawa loop of one load step (docs/formulation.md §6.2): Newton with
//! the multipliers λ fixed, then every pair's multiplier update, until every
//! pair's penetration and multiplier change are within its tolerances on
//! every rank. Where the loop is slow the pairs' penalties are raised, and
//! a step's first contact may be solved with a softer one, as the penalty
//! policy decides (`contact::penalty`).
use super::anderson::Anderson;
use super::failure::{newton_failure, StepFailure};
use super::mechanics::Mechanics;
use super::phases::{Phase, PhaseMark, PhaseTimes, Stages};
use super::tolerance;
use crate::contact::penalty::{PairProgress, StepPenalties, RATE_RAISE, ROUND_RAISE};
use crate::contact::{ContactPair, UzawaStats};
use crate::error::Result;
use crate::linsolve;
use crate::parallel::{self, fault, fault::FaultPhase};
use crate::petsc::{Matrix, Snes, SnesOutcome, Vector};
use mpi::traits::*;

/// A step's converged Newton outcome (iterations summed over the Uzawa
/// iterations), its Uzawa iteration count and each pair's figures, or why
/// it failed.
pub(super) type StepResult =
    std::result::Result<(SnesOutcome, usize, Vec<UzawaStats>), StepFailure>;

/// The solver state one Uzawa loop works on.
pub(super) struct StepContext<'s> {
    pub(super) snes: &'s mut Snes,
    pub(super) x: &'s mut Vector,
    pub(super) r: &'s mut Vector,
    pub(super) jac: &'s mut Matrix,
    pub(super) stages: &'s Stages,
    pub(super) times: &'s mut PhaseTimes,
    pub(super) reuse_preconditioner: bool,
    /// Newton's relative forcing in non-final Uzawa iterations.
    pub(super) forcing: f64,
    /// The GMRES floor of a contact step's solves (`tolerance::LINEAR_FLOOR`;
    /// 0: none).
    pub(super) linear_floor: f64,
    /// Penalty divisor of a contact-free step's first Uzawa iteration
    /// (1: off; see `StepPenalties::soften`).
    pub(super) softening: f64,
    /// Whether a contact-free step's first Uzawa iteration assembles the
    /// pairs' main-part tangent (see `main_part_tangent`).
    pub(super) main_part_tangent: bool,
    /// Anderson depth of the frictionless pairs' multiplier updates (0:
    /// off; see `anderson`).
    pub(super) acceleration: usize,
    /// Whether the penalty policy's rate rule applies
    /// (`contact::penalty::rate_rule`).
    pub(super) rate_rule: bool,
}

/// The Uzawa loop of one load step (docs/formulation.md §6.2): Newton with λ fixed, then
/// λ ← ⟨λ − εN gN⟩ at every link, until the penetration and the multiplier
/// change meet the tolerances on every rank (or there is no contact).
/// Newton iterations are summed over the Uzawa iterations.
pub(super) fn uzawa_loop(
    world: &impl Communicator,
    ctx: &mut StepContext,
    mech: &mut Mechanics,
    factor: f64,
) -> Result<StepResult> {
    // The options' tolerances are the final ones; non-final solves loosen
    // them, and every way out restores them for the next step.
    let (atol, rtol, stol, max_it) = ctx.snes.tolerances()?;
    let tight = tolerance::NewtonTolerance { atol, rtol };
    // Friction keeps every solve tight: its Uzawa update classifies stick
    // and slip from the solved state, and loose states misclassify points
    // (block-slide: 60 -> 74 Newton, 43 -> 63 Uzawa iterations when loose).
    let frictional = mech.contact.iter().any(ContactPair::has_friction);
    let forcing = if mech.contact.is_empty() || frictional {
        0.0
    } else {
        ctx.forcing
    };
    let inner = tolerance::InnerTolerance::new(tight, forcing);
    let mut penalties = StepPenalties::new(mech.contact.len(), ctx.rate_rule);
    let softening = ctx.softening;
    let no_contact =
        softening > 1.0 && !frictional && no_multiplier_in_contact(world, mech.contact);
    if let Some(f) = penalties.soften(softening, frictional, no_contact) {
        raise_all(mech.contact, f);
    }
    let mut main_part =
        ctx.main_part_tangent && !frictional && main_part_tangent(world, mech.contact, true);
    // The condensed Newton iterates are the whole vector's only with no
    // step-length test (stol compares norms of the whole x and step).
    let condensed = stol == 0.0 && linsolve::condenses(ctx.snes);
    if condensed {
        linsolve::arm(ctx.snes, ctx.x)?;
    }
    let mut result = uzawa_rounds(
        world,
        ctx,
        mech,
        factor,
        &inner,
        (stol, max_it, condensed),
        (&mut penalties, &mut main_part),
    );
    if linsolve::condenses(ctx.snes) {
        // The converged step's interior, formed once (a failed one is
        // dropped: the step starts again from the last converged state; an
        // uncovered one goes on from this state).
        if matches!(result, Ok(Ok(_) | Err(StepFailure::Uncovered { .. }))) {
            let expanded = linsolve::expand(ctx.snes, ctx.x);
            if let Err(e) = expanded {
                result = Err(e);
            }
        }
        linsolve::disarm(ctx.snes);
    }
    if condensed {
        // The condensed iterates hold the true state on the contact DOFs
        // only, so the candidates are checked here, on the whole state.
        if let Ok(Ok((outcome, uzawa, _))) = &result {
            if !contact_covers(world, mech, ctx.x, factor)? {
                result = Ok(Err(StepFailure::Uncovered {
                    outcome: outcome.clone(),
                    uzawa: *uzawa,
                }));
            }
        }
    }
    unsoften(mech, &mut penalties);
    if main_part {
        main_part_tangent(world, mech.contact, false);
    }
    ctx.snes.set_tolerances(atol, rtol, stol, max_it)?;
    result
}

/// A solve the contact search's candidates stopped covering, followed by
/// the solve from its state after a new search (`second`): the second's
/// result gets the Newton and Uzawa counts and the residual history of both.
pub(super) fn chain((first, uzawa): (SnesOutcome, usize), second: &mut StepResult) {
    let (outcome, more) = match second {
        Ok((outcome, more, _)) => (outcome, more),
        Err(StepFailure::Uncovered {
            outcome,
            uzawa: more,
        }) => (outcome, more),
        Err(_) => return,
    };
    outcome.iterations += first.iterations;
    outcome.linear_iterations += first.linear_iterations;
    outcome.history.splice(0..0, first.history);
    *more += uzawa;
}

/// The Newton solves of a step's Uzawa iterations, added up.
#[derive(Default)]
struct Tally {
    newton: usize,
    linear: usize,
    history: Vec<f64>,
    /// Uzawa iterations over every round.
    uzawa: usize,
}

impl Tally {
    fn add(&mut self, o: &SnesOutcome) {
        self.newton += o.iterations;
        self.linear += o.linear_iterations;
        self.history.extend_from_slice(&o.history);
    }

    /// The last solve's outcome with the counts and history of all.
    fn outcome(&self, mut last: SnesOutcome) -> SnesOutcome {
        last.iterations = self.newton;
        last.linear_iterations = self.linear;
        last.history = self.history.clone();
        last
    }
}

/// The Uzawa iterations of one step, in rounds of at most `max_uzawa`; a
/// round that ends unconverged raises the slow pairs' penalties and starts
/// the next, as long as the penalty policy allows.
fn uzawa_rounds(
    world: &impl Communicator,
    ctx: &mut StepContext,
    mech: &mut Mechanics,
    factor: f64,
    inner: &tolerance::InnerTolerance,
    (stol, max_it, condensed): (f64, usize, bool),
    (penalties, main_part): (&mut StepPenalties, &mut bool),
) -> Result<StepResult> {
    let max_uzawa = max_uzawa(mech.contact);
    let mut accel = Anderson::new(ctx.acceleration);
    let mut tally = Tally::default();
    // Uzawa iterations in this round.
    let mut round = 0;
    let mut solve_tight = !inner.is_inexact();
    // A raised penalty changes the tangent: the next solve refactors.
    let mut refactor = false;
    loop {
        round += 1;
        tally.uzawa += 1;
        // Between Uzawa iterations only λ changes, so the tangent barely
        // does: keep the preconditioner (the LU factors) of the first solve.
        let fresh = round == 1
            || std::mem::take(&mut refactor)
            || mech.contact.is_empty()
            || !ctx.reuse_preconditioner;
        let tol = inner.for_solve(solve_tight);
        let outcome = newton(ctx, mech, (tol, stol, max_it), fresh)?;
        tally.add(&outcome);
        if !outcome.converged {
            let (x, jac) = (&*ctx.x, &*ctx.jac);
            return Ok(Err(newton_failure(world, mech, x, jac, factor, outcome)?));
        }
        if mech.contact.is_empty() {
            return Ok(Ok((outcome, 0, Vec::new())));
        }
        let before = accel.is_on().then(|| normal_multipliers(mech.contact));
        // A condensed iterate's off-contact DOFs are not the state yet: the
        // caller checks its candidates once the step has expanded it.
        let (stats, covered) = update_multipliers(
            world,
            (ctx.stages, &mut *ctx.times),
            mech,
            ctx.x,
            (factor, !condensed),
        )?;
        if !covered {
            // No more Uzawa work on a set of segments that misses part of
            // the contact: the caller searches from here and goes on.
            return Ok(Err(StepFailure::Uncovered {
                outcome: tally.outcome(outcome),
                uzawa: tally.uzawa,
            }));
        }
        if std::mem::take(main_part) {
            // The multipliers carry the contact from here: the full tangent.
            main_part_tangent(world, mech.contact, false);
        }
        if penalties.is_softened() {
            // The soft iteration has given the multipliers a first
            // estimate: from here on the pairs' own penalties, and fresh
            // factors (the soft tangent no longer fits); the Uzawa rounds
            // count from here.
            unsoften(mech, penalties);
            round = 0;
            accel.forget();
        }
        let progress: Vec<PairProgress> = mech
            .contact
            .iter()
            .zip(&stats)
            .map(|(p, s)| p.progress(s))
            .collect();
        let converged: Vec<bool> = progress.iter().map(|p| p.converged).collect();
        match tolerance::round_end(converged.iter().all(|c| *c), solve_tight) {
            tolerance::RoundEnd::Converged => {
                return Ok(Ok((tally.outcome(outcome), tally.uzawa, stats)));
            }
            tolerance::RoundEnd::Confirm => {
                solve_tight = true;
                continue;
            }
            tolerance::RoundEnd::Continue => {
                // Only an update that failed the test is extrapolated: a
                // passing one stands, so the step ends on a plain update.
                if let Some(before) = before {
                    accelerate(world, &mut accel, before, mech.contact)?;
                }
            }
        }
        let stalled = penalties.stalled(&progress);
        if stalled.iter().any(|r| *r) {
            raise(mech.contact, &stalled, RATE_RAISE);
            refactor = true;
            accel.forget();
            if let Some(lag) = mech.lag.as_mut() {
                lag.reset();
            }
        }
        if round >= max_uzawa {
            // Converging too slowly (soft bodies, long sliding): a larger
            // penalty for the pairs still outside their tolerances and
            // another round, or the step fails.
            let Some(slow) = penalties.round_end(&converged) else {
                return Ok(Err(StepFailure::Uzawa {
                    iterations: tally.uzawa,
                    stats: worst(&stats),
                }));
            };
            raise(mech.contact, &slow, ROUND_RAISE);
            accel.forget();
            round = 0;
        }
    }
}

/// One Newton solve of the Uzawa loop at the tolerance `tol` (`fresh`:
/// with a new preconditioner), booked as the linear-solve phase.
fn newton(
    ctx: &mut StepContext,
    mech: &mut Mechanics,
    (tol, stol, max_it): (tolerance::NewtonTolerance, f64, usize),
    fresh: bool,
) -> Result<SnesOutcome> {
    let StepContext {
        snes,
        x,
        r,
        jac,
        stages,
        times,
        linear_floor,
        ..
    } = ctx;
    snes.set_tolerances(tol.atol, tol.rtol, stol, max_it)?;
    if *linear_floor > 0.0 {
        let contact = !mech.contact.is_empty();
        linsolve::set_linear_floor(snes, if contact { *linear_floor } else { 0.0 })?;
    }
    snes.set_lag_preconditioner(if fresh { 1 } else { -1 })?;
    let mark = PhaseMark::new(&mech.times, mech.contact);
    let outcome = stages.scope(Phase::LinearSolve, || snes.solve(mech, x, r, jac))?;
    mark.book(Phase::LinearSolve, times, &mech.times, mech.contact);
    Ok(outcome)
}

/// Multiplies the penalty of every pair `which` marks by `factor`.
fn raise(pairs: &mut [ContactPair], which: &[bool], factor: f64) {
    for (p, _) in pairs.iter_mut().zip(which).filter(|(_, r)| **r) {
        p.raise_penalty(factor);
    }
}

/// Multiplies every pair's penalty by `factor`.
fn raise_all(pairs: &mut [ContactPair], factor: f64) {
    for p in pairs.iter_mut() {
        p.raise_penalty(factor);
    }
}

/// Collective: whether no pair has a multiplier in contact on any rank.
fn no_multiplier_in_contact(world: &impl Communicator, pairs: &[ContactPair]) -> bool {
    let local: usize = pairs.iter().map(|p| p.multiplier_states().0).sum();
    let [active] = parallel::sum_usize(world, [local]);
    !pairs.is_empty() && active == 0
}

/// Ends a softened first iteration (once): every pair's own penalty back,
/// and the preconditioner built for the soft tangent forgotten.
fn unsoften(mech: &mut Mechanics, penalties: &mut StepPenalties) {
    if let Some(f) = penalties.unsoften() {
        raise_all(mech.contact, f);
        if let Some(lag) = mech.lag.as_mut() {
            lag.reset();
        }
    }
}

/// Collective: with `on`, switches every pair to the main-part tangent
/// when no pair has a multiplier in contact on any rank, and says whether
/// it did; without, switches them all back (`[solver]
/// first_contact_main_tangent`, on by default).
///
/// A step that starts with no contact solves its first Uzawa iteration as
/// a pure penalty problem from a state where the first iterate penetrates
/// deeply (the bodies move by the whole approach before any link closes),
/// so the trial pressures εN |gN| are far above the contact pressure. The
/// consistent tangent's terms in pN times the derivatives of the normal and
/// of the master shape values are then large and indefinite, and the
/// Newton steps they give open points inside the contact zone and close
/// them again (graded Hertz line, h_c = b/20: holes across the zone at
/// every iteration, the l2 line search cut to λ = 0.05–0.19, 10 Newton
/// iterations in that first Uzawa iteration; b/40: 18). Without them (only
/// εN (N ν)(N ν)ᵀ, symmetric and positive semi-definite) the zone grows
/// monotonically to its final size: 4 iterations at b/20, 3 at b/40. The
/// residual is unchanged, so the solution is too; the later Uzawa
/// iterations, near the solution, use the consistent tangent again.
fn main_part_tangent(world: &impl Communicator, pairs: &mut [ContactPair], on: bool) -> bool {
    let switch = if on {
        let local: usize = pairs.iter().map(|p| p.multiplier_states().0).sum();
        let [active] = parallel::sum_usize(world, [local]);
        !pairs.is_empty() && active == 0
    } else {
        true
    };
    if switch {
        for p in pairs.iter_mut() {
            p.set_main_part_tangent(on);
        }
    }
    switch && on
}

/// Uzawa iterations in one round: the largest any pair allows (at least one).
fn max_uzawa(pairs: &[ContactPair]) -> usize {
    pairs
        .iter()
        .map(|p| p.spec.max_uzawa)
        .max()
        .unwrap_or(1)
        .max(1)
}

/// Collective: the multiplier update of every pair at the solved state `x`,
/// agreed, booked as the Uzawa-update phase, and reduced over the ranks;
/// with `check_cover`, also whether every pair's candidates still cover `x`
/// on every rank (`ContactPair::covers`; true without it).
fn update_multipliers(
    world: &impl Communicator,
    (stages, times): (&Stages, &mut PhaseTimes),
    mech: &mut Mechanics,
    x: &Vector,
    (factor, check_cover): (f64, bool),
) -> Result<(Vec<UzawaStats>, bool)> {
    let mark = PhaseMark::new(&mech.times, mech.contact);
    let updated = stages.scope(Phase::UzawaUpdate, || {
        mech.with_state(x, |u, pairs| {
            let stats = pairs
                .iter_mut()
                .map(|p| p.uzawa_update(u, factor))
                .collect::<Result<Vec<UzawaStats>>>()?;
            fault::check(FaultPhase::UzawaUpdate)?;
            let covered = !check_cover || pairs.iter().all(|p| p.covers(u, factor));
            Ok((stats, covered))
        })
    });
    let (local, covered) = parallel::agree(world, updated)?;
    mark.book(Phase::UzawaUpdate, times, &mech.times, mech.contact);
    let stats = reduce_stats(world, &local);
    Ok((stats, parallel::all_ranks(world, covered)))
}

/// Collective: whether every pair's candidates, on every rank, still
/// cover the state `x` at load `factor` (`ContactPair::covers`).
fn contact_covers(
    world: &impl Communicator,
    mech: &mut Mechanics,
    x: &Vector,
    factor: f64,
) -> Result<bool> {
    let local = mech.with_state(x, |u, pairs| Ok(pairs.iter().all(|p| p.covers(u, factor))));
    let covered = parallel::agree(world, local)?;
    Ok(parallel::all_ranks(world, covered))
}

/// The accelerated pairs' normal multipliers, concatenated, and whether
/// each enters global sums.
fn normal_multipliers(pairs: &[ContactPair]) -> (Vec<f64>, Vec<bool>) {
    let mut values = Vec::new();
    let mut counted = Vec::new();
    for (v, c) in pairs.iter().filter_map(ContactPair::normal_multipliers) {
        values.extend(v);
        counted.extend(c);
    }
    (values, counted)
}

/// Collective: the Anderson step after a multiplier update that failed the
/// test (`before` the multipliers the Newton solve used); the accelerated
/// multipliers replace the plain update's, or it stands.
fn accelerate(
    world: &impl Communicator,
    accel: &mut Anderson,
    (before, counted): (Vec<f64>, Vec<bool>),
    pairs: &mut [ContactPair],
) -> Result<()> {
    let (after, _) = normal_multipliers(pairs);
    let Some(next) = accel.next(&before, &after, &counted, &mut |local| {
        parallel::sum(world, local)
    }) else {
        return Ok(());
    };
    let mut rest = &next[..];
    for p in pairs.iter_mut() {
        if let Some((v, _)) = p.normal_multipliers() {
            let (mine, tail) = rest.split_at(v.len());
            p.set_normal_multipliers(mine)?;
            rest = tail;
        }
    }
    Ok(())
}

/// The figures a failed Uzawa loop reports: maxima and counts over the pairs.
fn worst(stats: &[UzawaStats]) -> UzawaStats {
    stats
        .iter()
        .copied()
        .fold(UzawaStats::default(), |a, s| UzawaStats {
            max_penetration: a.max_penetration.max(s.max_penetration),
            max_change: a.max_change.max(s.max_change),
            max_force: a.max_force.max(s.max_force),
            max_multiplier: a.max_multiplier.max(s.max_multiplier),
            active: a.active + s.active,
            sliding: a.sliding + s.sliding,
        })
}

/// Collective: each pair's Uzawa figures over all ranks.
fn reduce_stats(world: &impl Communicator, local: &[UzawaStats]) -> Vec<UzawaStats> {
    local
        .iter()
        .map(|s| {
            let [max_penetration, max_change, max_force, max_multiplier] = parallel::max(
                world,
                [
                    s.max_penetration,
                    s.max_change,
                    s.max_force,
                    s.max_multiplier,
                ],
            );
            let [active, sliding] = parallel::sum_usize(world, [s.active, s.sliding]);
            UzawaStats {
                max_penetration,
                max_change,
                max_force,
                max_multiplier,
                active,
                sliding,
            }
        })
        .collect()
}

//! A model's run: `Simulation` (set up once, collectively) and its load
//! steps. Each attempt at a step: the predictor, the contact search (and a
//! new Jacobian pattern when the couplings changed), the step's tolerance,
//! the Uzawa loop; a failed attempt is cut back and retried, a converged
//! step is reported to the `StepSink` and committed.
//!
//! Every function here that calls a collective is called by every rank in
//! the same order: the branches depend on agreed values only.
use super::boundary::Dirichlet;
use super::dynamics::{DynamicsReport, TimeStepper};
use super::failure::{failure_text, StepFailure};
use super::mechanics::Mechanics;
use super::natural::NaturalOrder;
use super::newmark::Coefficients;
use super::phases::{Phase, PhaseMark, PhaseTimes, Stages};
use super::predictor::Predictor;
use super::reactions::support_reactions;
use super::report::{
    contact_reports, nodal_pressure, print_step, PairFields, RunReport, StepReport, StepSink,
};
use super::setup::{self, build_jacobian, newton_solver, set_solver_defaults, StepTolerance};
use super::start::{initial_state, mechanics, prepare_time_step, time_stepper, Parts};
use super::uzawa::{chain, uzawa_loop, StepContext, StepResult};
use super::RestartState;
use crate::assembly::{BulkAssembler, SurfaceLoads};
use crate::contact::fields::PairOutput;
use crate::contact::formulation::PairSnapshot;
use crate::contact::{ContactPair, PairForce, UzawaStats};
use crate::distribution::LocalMesh;
use crate::dofs::{DofMap, DIM};
use crate::error::{Error, Result};
use crate::linsolve;
use crate::mesh::Mesh;
use crate::model::Model;
use crate::parallel::{self, fault, fault::FaultPhase};
use crate::petsc::snes::CallbackError;
use crate::petsc::{self, LogStage, Matrix, Snes, SnesOutcome, Vector};
use crate::runtime::Runtime;
use mpi::topology::SimpleCommunicator;
use std::borrow::Cow;
use std::time::Instant;

/// Most contact searches in one attempt at a load step: the step's own and
/// those from a solution the candidates no longer cover (one more is
/// enough unless the zone keeps growing; then the step is cut back).
const SEARCHES: usize = 3;

/// A model set up on this rank: partition, numbering, element data, contact
/// pairs, Jacobian storage. Built collectively by every rank.
pub struct Simulation<'m> {
    pub(super) model: &'m Model,
    /// Owning rank of each cell of this rank's output cell block.
    pub(super) partition_block: Vec<i32>,
    /// This rank's mesh: local nodes and cells, facet-set pieces, output block.
    pub(super) local: LocalMesh,
    pub(super) dofs: DofMap,
    pub(super) bulk: BulkAssembler,
    pub(super) loads: SurfaceLoads,
    pub(super) dirichlet: Dirichlet,
    pub(super) contact: Vec<ContactPair>,
    pub(super) jac: Matrix,
}

impl<'m> Simulation<'m> {
    /// Partitions (METIS on rank 0, each rank sent its piece), numbers the DOFs, precomputes
    /// element data, resolves contact pairs and allocates the Jacobian.
    /// Collective; fails on every rank if it fails on one.
    pub fn setup(rt: &Runtime, model: &'m Model) -> Result<Self> {
        let stage = LogStage::register("Setup")?;
        let parts = stage.scope(|| setup::setup(rt, model, Cow::Borrowed(&model.mesh)))?;
        Ok(Self::from_parts(model, parts))
    }

    /// [`Simulation::setup`] with the mesh moved out of the model: it is
    /// freed as soon as the pieces are cut, so no rank holds the global mesh
    /// past the distribution (`model.mesh` is left as it was handed over,
    /// normally empty, and nothing after set-up reads it).
    pub fn setup_with_mesh(rt: &Runtime, model: &'m Model, mesh: Mesh) -> Result<Self> {
        let stage = LogStage::register("Setup")?;
        let parts = stage.scope(|| setup::setup(rt, model, Cow::Owned(mesh)))?;
        Ok(Self::from_parts(model, parts))
    }

    fn from_parts(model: &'m Model, p: setup::SetUp) -> Self {
        let (partition_block, local, dofs) = (p.partition_block, p.local, p.dofs);
        let (bulk, loads, dirichlet, contact, jac) =
            (p.bulk, p.loads, p.dirichlet, p.contact, p.jac);
        Simulation {
            model,
            partition_block,
            local,
            dofs,
            bulk,
            loads,
            dirichlet,
            contact,
            jac,
        }
    }

    /// Owning rank of each cell of this rank's output cell block
    /// (`even_block(num_cells, rank, nranks)`), natural order.
    pub fn partition_block(&self) -> &[i32] {
        &self.partition_block
    }

    pub fn dofs(&self) -> &DofMap {
        &self.dofs
    }

    /// This rank's share of the mesh.
    pub fn local_mesh(&self) -> &LocalMesh {
        &self.local
    }

    pub fn model(&self) -> &Model {
        self.model
    }

    pub fn contact(&self) -> &[ContactPair] {
        &self.contact
    }

    /// Runs the load steps, from the start or (`restart`) from a converged
    /// step read back from a result file, calling `sink` after every
    /// converged one.
    pub fn run(
        &mut self,
        rt: &Runtime,
        sink: &mut dyn StepSink,
        echo: bool,
        restart: Option<&RestartState>,
    ) -> Result<RunReport> {
        let started = Instant::now();
        let world = rt.world();
        let model = self.model;
        let stage_solve = LogStage::register("Solve")?;
        let stages = Stages::register()?;
        let tangent = setup::tangent_kind(&world, model, &self.loads, &self.contact);
        set_solver_defaults(&model.solver, tangent, DIM * self.dofs.num_global_nodes())?;
        let Simulation {
            local,
            dofs,
            bulk,
            loads,
            dirichlet,
            contact,
            jac,
            ..
        } = self;
        let parts = Parts {
            dofs,
            bulk,
            loads,
            dirichlet,
        };
        let mut mech = mechanics(model, tangent, parts, contact, jac, local)?;
        let stepper = time_stepper(model, &mut mech, local)?;
        let (x, first_step, done) = initial_state(&world, mech.dofs, restart, mech.contact)?;
        let r = x.duplicate()?;
        let x_prev = x.duplicate()?;
        let predictor = Predictor::new(&x, model.solver.extrapolate)?;
        let reaction = x.duplicate()?;
        let (mut snes, tolerance) = newton_solver(model, local)?;
        let global_dofs = DIM * mech.dofs.num_global_nodes();
        let linear_contact = tangent.contact && tangent.linear_bulk;
        if linsolve::applies(model, linear_contact, mech.loads, global_dofs) {
            if let Some(k) = mech.separate_stiffness() {
                let rows = mech.dirichlet.global_rows();
                linsolve::install(&mut snes, k, rows, tangent.symmetric, rt.size())?;
                mech.always_rebuild = true;
                if model.solver.condensed_newton {
                    mech.condensed = linsolve::condensed_state(&mut snes);
                }
            }
        }
        let base = 1.0 / model.steps.max(1) as f64;
        let mut steps = LoadSteps {
            world,
            model,
            local,
            mech,
            jac,
            stepper,
            snes,
            tolerance,
            x,
            r,
            x_prev,
            reaction,
            predictor,
            stage_solve,
            stages,
            times: PhaseTimes::default(),
            pattern_builds: 0,
            reports: Vec::new(),
            first_step,
            done,
            base,
            increment: base,
            cutbacks_here: 0,
            echo: echo && rt.rank() == 0,
        };
        while steps.done < 1.0 - 1e-12 {
            steps.attempt(sink)?;
            steps.stop_if_signalled()?;
        }
        steps.finish(started)
    }
}

/// What an attempt at a step starts from, kept to undo it or report it.
struct StepStart {
    clock: Instant,
    /// Every pair's multipliers and history before the attempt.
    contact: Vec<PairSnapshot>,
    /// The Newmark coefficients of the time step (dynamics only).
    coefficients: Option<Coefficients>,
    /// The phase times before the attempt.
    times: PhaseTimes,
}

/// A converged step's Newton outcome, Uzawa iterations and pair figures.
type Solved = (SnesOutcome, usize, Vec<UzawaStats>);

/// The load-step loop: the solver state, the converged steps so far, and
/// the increment with its cutbacks.
struct LoadSteps<'a> {
    world: SimpleCommunicator,
    model: &'a Model,
    local: &'a LocalMesh,
    mech: Mechanics<'a>,
    jac: &'a mut Matrix,
    stepper: Option<TimeStepper>,
    snes: Snes,
    tolerance: StepTolerance,
    x: Vector,
    r: Vector,
    x_prev: Vector,
    reaction: Vector,
    predictor: Predictor,
    stage_solve: LogStage,
    stages: Stages,
    /// Phases booked here; the callbacks book theirs in `mech.times`.
    times: PhaseTimes,
    pattern_builds: usize,
    reports: Vec<StepReport>,
    /// Index of the step the run started after (a restart's step, or 0).
    first_step: usize,
    /// Load factor of the last converged step.
    done: f64,
    /// The scene's increment, and the current (cut back) one.
    base: f64,
    increment: f64,
    cutbacks_here: usize,
    /// Print step and cutback lines (rank 0 with `-v`).
    echo: bool,
}

impl LoadSteps<'_> {
    /// One attempt at the next load increment: converged, it is reported
    /// and committed; failed, it is cut back (or the run fails).
    fn attempt(&mut self, sink: &mut dyn StepSink) -> Result<()> {
        let target = (self.done + self.increment).min(1.0);
        let start = self.begin(target)?;
        self.search_contact(target)?;
        let first = self.step_tolerance()?;
        // A step (or its retry) starts with fresh factors.
        if let Some(lag) = self.mech.lag.as_mut() {
            lag.reset();
        }
        let attempt = first.map_or_else(|f| Ok(Err(f)), |()| self.solve_searched(target));
        match attempt? {
            Ok(solved) => self.accept(sink, solved, start, target),
            Err(failure) => self.cut_back(failure, start.contact, target),
        }
    }

    /// [`Self::solve`], then while some pair's candidates (searched at the
    /// predicted state) stop covering its solution: a search from that
    /// state and the solve from there, at most `SEARCHES` searches in all.
    fn solve_searched(&mut self, target: f64) -> Result<StepResult> {
        let mut result = self.solve(target)?;
        for _ in 1..SEARCHES {
            let Err(StepFailure::Uncovered { outcome, uzawa }) = result else {
                break;
            };
            self.search_contact(target)?;
            if let Some(lag) = self.mech.lag.as_mut() {
                lag.reset();
            }
            let mut next = self.solve(target)?;
            chain((outcome, uzawa), &mut next);
            result = next;
        }
        Ok(result)
    }

    /// The predictor, the new loads and prescribed displacements at `target`,
    /// and (dynamics) the time step's set-up.
    fn begin(&mut self, target: f64) -> Result<StepStart> {
        let clock = Instant::now();
        self.x_prev.copy_from(&self.x)?;
        let contact = self.mech.contact.iter().map(|p| p.snapshot()).collect();
        self.predictor.extrapolate(&mut self.x, self.done, target)?;
        self.mech.factor = target;
        let coefficients = match &mut self.stepper {
            Some(s) => Some(prepare_time_step(s, &mut self.mech, self.done, target)?),
            None => None,
        };
        let dirichlet = self.mech.dirichlet;
        self.x.with_array_mut(|xa| dirichlet.apply(xa, target))?;
        Ok(StepStart {
            clock,
            contact,
            coefficients,
            times: self.times.plus(&self.mech.times),
        })
    }

    /// Collective: the contact search at the predicted state, and a new
    /// Jacobian pattern when any rank's couplings changed.
    fn search_contact(&mut self, target: f64) -> Result<()> {
        if !self.mech.contact.is_empty() {
            let mark = PhaseMark::new(&self.mech.times, self.mech.contact);
            // The step's prescribed motion: the pairs' search margin.
            let step = self.mech.dirichlet.largest_increment(self.done, target);
            let [motion] = parallel::max(&self.world, [step]);
            let (mech, x, x_prev) = (&mut self.mech, &self.x, &self.x_prev);
            let offset = self.stepper.as_ref().map(|s| s.slip_offset());
            let searched = self.stages.scope(Phase::ContactSearch, || {
                mech.exchange_masters(x)?;
                // The pairs are the same on every rank: so is this choice.
                if mech
                    .contact
                    .iter()
                    .any(|p| p.measures_slip_from_committed())
                {
                    // `x_prev`: the last converged state, with a restart's
                    // slip origins at the owned nodes until its first step
                    // has converged.
                    let mut committed = x_prev.duplicate()?;
                    committed.copy_from(x_prev)?;
                    let dofs = mech.dofs;
                    let start = dofs.owned_dof_start();
                    let origins: Vec<_> = mech
                        .contact
                        .iter()
                        .flat_map(|p| p.committed_origins())
                        .collect();
                    committed.with_array_mut(|a| {
                        for (l, d) in &origins {
                            let l = crate::dofs::LocalNode::from_u32(*l);
                            for (c, v) in d.iter().enumerate() {
                                a[dofs.dof(l, c).0 as usize - start] = *v;
                            }
                        }
                    })?;
                    mech.with_state(&committed, |u, pairs| {
                        pairs.iter_mut().for_each(|p| p.start_slip_from(u));
                        Ok(())
                    })?;
                }
                if let Some(offset) = offset {
                    mech.extend_slip_rates(offset)?;
                }
                mech.with_state(x, |u, pairs| {
                    let changed = pairs
                        .iter_mut()
                        .fold(false, |c, p| p.search(u, target, motion) | c);
                    fault::check(FaultPhase::Search)?;
                    Ok(changed)
                })
            });
            let changed = parallel::agree(&self.world, searched)?;
            mark.book(
                Phase::ContactSearch,
                &mut self.times,
                &self.mech.times,
                self.mech.contact,
            );
            let rebuild = !self.model.solver.reuse.pattern || self.pattern_builds == 0;
            if parallel::any_rank(&self.world, changed) || rebuild {
                let (mech, mesh) = (&self.mech, self.local);
                // On the one-rank Schur path the Jacobian holds the contact
                // tangent alone (K is in the factor): its pattern is the
                // contact couplings', not the bulk's (b/40: 13.6 million
                // entries zeroed per Jacobian, and a matrix of K's size).
                let bulk = (!(mech.always_rebuild && linsolve::schur_installed(&self.snes)))
                    .then_some((mech.bulk, mech.loads));
                *self.jac = self
                    .stages
                    .time(Phase::ContactAssembly, &mut self.times, || {
                        build_jacobian(mech.dofs, bulk, mech.contact, mesh)
                    })?;
                self.pattern_builds += 1;
                linsolve::want(
                    &mut self.snes,
                    self.mech.contact,
                    self.mech.dofs,
                    self.local,
                )?;
            }
        }
        Ok(())
    }

    /// The step's absolute tolerance when no atol is given: rtol times the
    /// step's own force scale, the residual once the new loads and
    /// prescribed displacements are in place. That first residual fails
    /// like any other: into the cutback path.
    fn step_tolerance(&mut self) -> Result<std::result::Result<(), StepFailure>> {
        let solver = &self.model.solver;
        if solver.atol.is_some() || self.tolerance.user_atol {
            return Ok(Ok(()));
        }
        match self.mech.residual_norm(&self.x, &mut self.r) {
            Ok(r0) => self.snes.set_tolerances(
                (solver.rtol * r0).max(self.tolerance.atol_floor),
                solver.rtol,
                0.0,
                solver.max_newton,
            )?,
            Err(CallbackError::Domain(why)) => return Ok(Err(StepFailure::Residual(why))),
            Err(CallbackError::Fatal(why)) => {
                return Err(Error::Petsc(petsc::PetscError {
                    call: "first residual of a step",
                    code: -1,
                    message: why,
                }))
            }
        }
        Ok(Ok(()))
    }

    /// The Uzawa loop at `target`, inside the Solve stage.
    fn solve(&mut self, target: f64) -> Result<StepResult> {
        let solver = &self.model.solver;
        let (world, mech) = (&self.world, &mut self.mech);
        let krylov = DIM * mech.dofs.num_global_nodes() > solver.direct_max_dofs;
        let mut ctx = StepContext {
            snes: &mut self.snes,
            x: &mut self.x,
            r: &mut self.r,
            jac: &mut *self.jac,
            stages: &self.stages,
            times: &mut self.times,
            reuse_preconditioner: solver.reuse.preconditioner,
            forcing: super::tolerance::inner_forcing(solver.uzawa_forcing, krylov),
            linear_floor: if krylov {
                super::tolerance::LINEAR_FLOOR
            } else {
                0.0
            },
            softening: solver.first_contact_softening,
            main_part_tangent: solver.first_contact_main_tangent,
            acceleration: super::tolerance::inner_acceleration(solver.uzawa_acceleration, krylov),
            rate_rule: crate::contact::penalty::rate_rule(krylov),
        };
        self.stage_solve
            .scope(|| uzawa_loop(world, &mut ctx, mech, target))
    }

    /// Collective: a failed attempt goes back to the last converged state
    /// and halves the increment, or fails the run past `max_cutbacks` or
    /// below the smallest increment.
    fn cut_back(
        &mut self,
        failure: StepFailure,
        contact: Vec<PairSnapshot>,
        target: f64,
    ) -> Result<()> {
        if failure.linear_solve_failed() {
            self.snes.reset_preconditioner()?;
        }
        self.x.copy_from(&self.x_prev)?;
        let restored = self
            .mech
            .contact
            .iter_mut()
            .zip(contact)
            .try_for_each(|(p, snap)| p.restore(snap));
        parallel::agree(&self.world, restored)?;
        self.cutbacks_here += 1;
        let max_cutbacks = self.model.solver.max_cutbacks;
        let mut why = failure_text(&failure);
        // The count restarts after every converged step, so a
        // load path stuck at a limit point would creep on with
        // ever smaller increments: they never go below the
        // scene's increment halved max_cutbacks times.
        let smallest = self.base * 0.5f64.powi(max_cutbacks as i32);
        let too_small = self.increment * 0.5 < smallest * (1.0 - 1e-9);
        if too_small && self.cutbacks_here <= max_cutbacks {
            why += &format!(
                "; the next increment would be below the smallest allowed ({smallest:.3e}: the scene's increment halved max_cutbacks = {max_cutbacks} times)"
            );
        }
        if self.cutbacks_here > max_cutbacks || too_small {
            return Err(Error::NoConvergence {
                step: self.first_step + self.reports.len() + 1,
                load_factor: target,
                cutbacks: self.cutbacks_here - 1,
                reason: why,
            });
        }
        self.increment *= 0.5;
        if self.echo {
            let increment = self.increment;
            println!("  cutback: load factor {target:.6} failed ({why}); retrying with increment {increment:.3e}");
        }
        Ok(())
    }

    /// Collective: a converged step advances the predictor and the time
    /// stepper, goes to the sink, and its contact state is committed.
    /// Collective, at a step boundary: if any rank received SIGTERM or
    /// SIGINT, every rank ends the run here (the signal reaches the ranks at
    /// different moments, so each asks all the others).
    fn stop_if_signalled(&self) -> Result<()> {
        let local = crate::runtime::signals::received().unwrap_or(0);
        let [signal] = parallel::max(&self.world, [f64::from(local)]);
        if signal > 0.0 {
            return Err(Error::Stopped {
                signal: signal as i32,
                name: crate::runtime::signals::name(signal as i32),
                step: self.first_step + self.reports.len(),
                load_factor: self.done,
            });
        }
        Ok(())
    }

    fn accept(
        &mut self,
        sink: &mut dyn StepSink,
        solved: Solved,
        start: StepStart,
        target: f64,
    ) -> Result<()> {
        self.predictor.accept(&self.x_prev, self.done)?;
        self.done = target;
        let dynamics = self.dynamics_report(start.coefficients.as_ref())?;
        self.output(sink, solved, dynamics, &start)?;
        let committed = self.mech.contact.iter_mut().try_for_each(|p| p.commit());
        parallel::agree(&self.world, committed)?;
        self.cutbacks_here = 0;
        // Grow back towards the scene's increment after a successful cut step.
        self.increment = (self.increment * 2.0).min(self.base);
        Ok(())
    }

    /// Collective (dynamics): the velocity and acceleration at the converged
    /// step, and its time, energies and momentum.
    fn dynamics_report(
        &mut self,
        coefficients: Option<&Coefficients>,
    ) -> Result<Option<DynamicsReport>> {
        let (Some(s), Some(c)) = (&mut self.stepper, coefficients) else {
            return Ok(None);
        };
        s.advance(&self.x, c)?;
        let bulk = self.mech.bulk;
        let strain = parallel::agree(
            &self.world,
            self.mech.with_state(&self.x, |u, _| bulk.strain_energy(u)),
        )?;
        let time = self.done * s.t_end;
        let inertia = self
            .mech
            .inertia
            .as_mut()
            .ok_or_else(|| Error::Internal("dynamics without inertia".into()))?;
        Ok(Some(s.report(&self.world, inertia, strain, time)?))
    }

    /// Collective: the converged step's reactions, contact values and
    /// report, handed to the sink (booked as the output phase).
    fn output(
        &mut self,
        sink: &mut dyn StepSink,
        (outcome, uzawa_iterations, stats): Solved,
        dynamics: Option<DynamicsReport>,
        start: &StepStart,
    ) -> Result<()> {
        let output_mark = PhaseMark::new(&self.mech.times, self.mech.contact);
        let reactions = self.reactions()?;
        let outputs = self.pair_outputs()?;
        let forces: Vec<PairForce> = outputs.iter().map(|o| o.force).collect();
        let contact = contact_reports(&self.world, self.mech.contact, &forces, &stats);
        let nodal_pressure = parallel::agree(
            &self.world,
            nodal_pressure(self.mech.dofs, self.mech.contact),
        )?;
        let mut report = StepReport {
            index: self.first_step + self.reports.len() + 1,
            load_factor: self.done,
            newton_iterations: outcome.iterations,
            uzawa_iterations,
            linear_iterations: outcome.linear_iterations,
            residual_norm: outcome.residual_norm,
            residual_history: outcome.history.clone(),
            cutbacks: self.cutbacks_here,
            wall_seconds: start.clock.elapsed().as_secs_f64(),
            reactions,
            contact,
            dynamics,
            phases: PhaseTimes::default(),
        };
        if self.echo {
            print_step(&report);
        }
        crate::memory::checkpoint("load step (solver and preconditioner alive)");
        let pair_fields: Vec<PairFields> = self
            .mech
            .contact
            .iter()
            .zip(outputs)
            .map(|(pair, output)| PairFields { pair, output })
            .collect();
        report.phases = self.times.plus(&self.mech.times).since(&start.times);
        let velocity = self.stepper.as_ref().map(|s| s.velocity());
        let (x, reaction) = (&self.x, &self.reaction);
        self.stages.scope(Phase::Output, || {
            sink.step(
                &report,
                x,
                reaction,
                &pair_fields,
                &nodal_pressure,
                velocity,
            )
        })?;
        drop(pair_fields);
        crate::memory::checkpoint("step output");
        output_mark.book(
            Phase::Output,
            &mut self.times,
            &self.mech.times,
            self.mech.contact,
        );
        self.reports.push(report);
        Ok(())
    }

    /// Collective: the total reaction of every Dirichlet set, and the
    /// reaction field (constrained rows only) in `self.reaction`.
    fn reactions(&mut self) -> Result<Vec<(String, [f64; 3])>> {
        // In dynamics the support also carries the inertia of its rows.
        let raw = self.mech.raw_residual(&self.x, &mut self.reaction);
        parallel::agree(&self.world, raw)?;
        let start = self.mech.dofs.owned_dof_start();
        support_reactions(&self.world, self.mech.dirichlet, &mut self.reaction, start)
    }

    /// Collective: every pair's output fields and force.
    fn pair_outputs(&mut self) -> Result<Vec<PairOutput>> {
        let target = self.done;
        let outputs = self.mech.with_state(&self.x, |u, pairs| {
            pairs.iter_mut().map(|p| p.output(u, target)).collect()
        });
        parallel::agree(&self.world, outputs)
    }

    /// Collective: the run's report, with the final displacement on rank 0
    /// and the phase times and halo volumes over the ranks.
    fn finish(self, started: Instant) -> Result<RunReport> {
        let LoadSteps {
            world,
            mech,
            reports,
            times,
            pattern_builds,
            x,
            snes,
            ..
        } = self;
        let dofs = mech.dofs;
        // Freed before the gather's scatter is built: the two never add up.
        let schur = linsolve::summary(&snes);
        drop(snes);
        let displacement = NaturalOrder::nodal(dofs)?.gather_root(&x)?;
        Ok(RunReport {
            steps: reports,
            global_dofs: DIM * dofs.num_global_nodes(),
            wall_seconds: started.elapsed().as_secs_f64(),
            displacement,
            bulk_tangent_assemblies: mech.bulk_tangent_assemblies,
            pattern_builds,
            preconditioner_builds: mech.lag.as_ref().map_or(0, |l| l.rebuilds),
            preconditioner_reuses: mech.lag.as_ref().map_or(0, |l| l.reuses),
            schur,
            phases: times.plus(&mech.times).max_over_ranks(&world),
            halo_displacements: parallel::sum_usize(&world, [dofs.ghost_dofs().len()])[0],
            halo_multipliers: parallel::sum_usize(
                &world,
                [mech.contact.iter().map(|p| p.multiplier_halo().1).sum()],
            )[0],
        })
    }
}

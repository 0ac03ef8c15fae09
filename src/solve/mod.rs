//! The solution procedure: load steps; in each, the contact search, then the
//! Uzawa loop around Newton (PETSc SNES) with the multipliers fixed during
//! Newton; a step whose Newton or Uzawa loop fails is cut back and retried;
//! converged steps go to the output.
//!
//! This module sits above `assembly` and `contact`: they know nothing of
//! SNES, and only this module calls the solver.
pub mod boundary;
pub mod dynamics;
mod failure;
pub mod lagging;
pub mod mechanics;
pub mod natural;
pub mod newmark;
pub mod phases;
mod restart_state;
pub mod tolerance;

pub use boundary::{Dirichlet, DirichletSpec};
pub use dynamics::{DynamicsReport, DynamicsSpec};
pub use mechanics::Mechanics;
pub use natural::NaturalOrder;
pub use restart_state::RestartState;

use crate::assembly::{BulkAssembler, FacetLoad, SurfaceLoads};
use crate::contact::links::PairForce;
use crate::contact::{ContactPair, MasterSpec, PairSpec, UzawaStats};
use crate::dofs::{DofMap, LocalNode, DIM};
use crate::error::{Error, Result};
use crate::fem::Material;
use crate::mesh::Mesh;
use crate::parallel::{self, fault, fault::FaultPhase};
use crate::petsc::snes::CallbackError;
use crate::petsc::{self, LogStage, Matrix, PatternBuilder, Snes, SnesOutcome, Vector};
use crate::runtime::Runtime;
use failure::{failure_text, newton_failure, StepFailure};
use mpi::traits::*;
use phases::{Phase, PhaseTimes};
use std::time::Instant;

/// Newton and load-stepping settings.
#[derive(Debug, Clone)]
pub struct SolverSettings {
    pub max_newton: usize,
    pub rtol: f64,
    /// Absolute residual tolerance; None: rtol × the residual at the start of
    /// each load step (the step's own force scale), so small loads and large
    /// ones converge alike, and Uzawa's follow-up solves stay as tight.
    pub atol: Option<f64>,
    /// Models with at most this many DOFs default to a parallel direct solver
    /// (MUMPS LU), robust for stiff contact penalties; larger ones to
    /// Krylov + algebraic multigrid.
    pub direct_max_dofs: usize,
    pub max_cutbacks: usize,
    /// PETSc options (defaults that the command line and PETSC_OPTIONS override).
    pub petsc_options: String,
    /// What is computed once and reused (all on by default; switches exist
    /// to measure each saving).
    pub reuse: Reuse,
    /// Start each load step from the last two converged steps extrapolated
    /// to the new load, instead of from the last one. Off by default: it
    /// saves Newton iterations on smooth load paths (block-slide 60 → 51)
    /// but costs them where the contact set changes between steps
    /// (hertz-cylinder 23 → 24, and a cutback with the l2 line search).
    pub extrapolate: bool,
    /// Newton inside a non-final Uzawa iteration stops once its residual
    /// fell by this factor (see `tolerance`); 0: every solve to the final
    /// tolerance.
    pub uzawa_forcing: f64,
}

/// Work a run reuses instead of redoing.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Reuse {
    /// Linear-elastic bulk stiffness assembled once (residual = K u − f).
    pub linear_stiffness: bool,
    /// Jacobian sparsity pattern kept while the contact couplings are unchanged.
    pub pattern: bool,
    /// Preconditioner (LU factors) of an Uzawa iteration's first solve kept
    /// for the following ones.
    pub preconditioner: bool,
    /// Preconditioner rebuilt only when the contact active set changed
    /// (within Newton too), see `lagging`; off: rebuilt every Newton
    /// iteration of a step's first Uzawa iteration.
    pub active_set: bool,
}

impl Default for Reuse {
    fn default() -> Self {
        Reuse {
            linear_stiffness: true,
            pattern: true,
            preconditioner: true,
            active_set: true,
        }
    }
}

impl Default for SolverSettings {
    fn default() -> Self {
        SolverSettings {
            max_newton: 30,
            rtol: 1e-9,
            atol: None,
            direct_max_dofs: 20_000,
            max_cutbacks: 8,
            petsc_options: String::new(),
            reuse: Reuse::default(),
            extrapolate: false,
            uzawa_forcing: tolerance::DEFAULT_FORCING,
        }
    }
}

/// A vector field of the reference position, b(X).
pub type VectorField = Box<dyn Fn([f64; 3]) -> [f64; 3]>;

/// A fully resolved problem: mesh, materials per body, conditions, contact, steps.
pub struct Model {
    pub name: String,
    pub mesh: Mesh,
    /// Material of each body, indexed like `mesh.bodies`.
    pub materials: Vec<Material>,
    pub dirichlet: Vec<DirichletSpec>,
    /// (facet set name, load at full amplitude, amplitude).
    pub facet_loads: Vec<(String, FacetLoad, crate::amplitude::Amplitude)>,
    /// Body force per body (per unit reference volume) at full load.
    pub body_force: Vec<[f64; 3]>,
    /// A spatially varying body force b(X) at full load (manufactured solutions).
    pub body_force_fn: Option<VectorField>,
    pub contact: Vec<PairSpec>,
    /// Compare a pair against Hertz after each step.
    pub hertz: Option<crate::verify::HertzCheck>,
    pub steps: usize,
    pub solver: SolverSettings,
    /// Implicit dynamics (None: quasi-static load stepping).
    pub dynamics: Option<DynamicsSpec>,
}

impl Model {
    /// Legal but risky choices, for the user to see before a long run.
    pub fn warnings(&self) -> Vec<String> {
        let mut w = Vec::new();
        if let Some(d) = &self.dynamics {
            if !self.contact.is_empty() && d.newmark.gamma <= 0.5 + 1e-12 {
                w.push(format!(
                    "[dynamics] γ = {} with contact: the trapezoidal rule has no numerical damping and its acceleration memory can create energy whenever contact opens (measured: +186 % on the impact scene); beta = 0.5, gamma = 1.0 never creates energy there",
                    d.newmark.gamma
                ));
            }
        }
        w
    }
}

/// What a contact pair did in one converged step (figures over all ranks).
#[derive(Debug, Clone)]
pub struct ContactReport {
    pub name: String,
    /// Total contact force on the slave surface.
    pub force: [f64; 3],
    /// Normal force Σ pN w and tangential force Σ |tT| w (contact frame).
    pub normal_force: f64,
    pub tangential_force: f64,
    pub max_penetration: f64,
    pub active_points: usize,
    /// Active points that slide (friction).
    pub sliding_points: usize,
    pub penalty: f64,
}

/// What one converged load increment did.
#[derive(Debug, Clone)]
pub struct StepReport {
    pub index: usize,
    pub load_factor: f64,
    pub newton_iterations: usize,
    pub uzawa_iterations: usize,
    pub linear_iterations: usize,
    pub residual_norm: f64,
    /// Residual norms of every Newton iteration of the step's last solve.
    pub residual_history: Vec<f64>,
    pub cutbacks: usize,
    pub wall_seconds: f64,
    /// Total reaction force of each Dirichlet set (summed over ranks).
    pub reactions: Vec<(String, [f64; 3])>,
    pub contact: Vec<ContactReport>,
    /// Time, energy and momentum (dynamics only).
    pub dynamics: Option<DynamicsReport>,
    /// Seconds per phase in this step on this rank (the output phase of
    /// the step itself is booked to the next step's report).
    pub phases: PhaseTimes,
}

/// The result of a run: per-step reports and the final displacement.
pub struct RunReport {
    pub steps: Vec<StepReport>,
    pub global_dofs: usize,
    pub wall_seconds: f64,
    /// Final displacement in natural node order, on every rank (N×3 flat).
    pub displacement: Vec<f64>,
    pub bulk_tangent_assemblies: usize,
    pub pattern_builds: usize,
    /// Preconditioner rebuilds and reuses decided by the active-set watch
    /// (`lagging`; both 0 when it is off).
    pub preconditioner_builds: usize,
    pub preconditioner_reuses: usize,
    /// Seconds per phase over the run, the largest over the ranks.
    pub phases: PhaseTimes,
    /// Halo volume, summed over ranks: ghost displacement values refreshed
    /// before every residual/Jacobian, and ghost multiplier values refreshed
    /// after every Uzawa update.
    pub halo_displacements: usize,
    pub halo_multipliers: usize,
}

/// This rank's contact values of one pair at a converged step, for output.
pub struct PairFields<'a> {
    pub pair: &'a ContactPair,
    pub values: crate::contact::links::PointValues,
}

/// Receives every converged step (the output file, a progress printer, ...).
pub trait StepSink {
    fn step(
        &mut self,
        report: &StepReport,
        displacement: &Vector,
        reaction: &Vector,
        contact: &[PairFields],
        nodal_pressure: &[f64],
        velocity: Option<&Vector>,
    ) -> Result<()>;
}

/// What the default solver choice depends on.
#[derive(Debug, Clone, Copy)]
struct TangentKind {
    /// No friction, no follower load: LDLᵀ / CG.
    symmetric: bool,
    /// Every body linear-elastic: the residual is one matrix-vector product.
    linear_bulk: bool,
    /// The model has contact pairs.
    contact: bool,
}

/// Sets the program's PETSc defaults; the user's options win.
fn set_solver_defaults(settings: &SolverSettings, tangent: TangentKind, dofs: usize) -> Result<()> {
    let TangentKind {
        symmetric,
        linear_bulk,
        contact,
    } = tangent;
    petsc::options::clear_defaults()?;
    petsc::options::insert_string_defaults(&settings.petsc_options)?;
    if linear_bulk {
        // The secant (l2) line search instead of backtracking: a penalty
        // contact residual is piecewise smooth, and backtracking keeps
        // shortening steps that cross a change of the contact set
        // (hertz-cylinder 23 → 18 Newton iterations, hertz-sphere 26 → 25).
        // It costs two extra residuals per iteration, cheap only when the
        // bulk residual is K u − f (ironing, Neo-Hookean: 1479 → 1406
        // iterations but more time), so nonlinear bodies keep backtracking.
        petsc::options::set_default("-snes_linesearch_type", "l2")?;
    }
    if dofs <= settings.direct_max_dofs {
        // GMRES around the LU factors: one iteration with fresh factors, a
        // few with the factors an earlier Uzawa iteration left behind.
        petsc::options::set_default("-ksp_type", "gmres")?;
        petsc::options::set_default("-ksp_rtol", "1e-10")?;
        // A symmetric tangent (no friction, no follower load) factors as
        // LDLᵀ: about 25 % faster than LU on hertz-cylinder, same answer.
        petsc::options::set_default("-pc_type", if symmetric { "cholesky" } else { "lu" })?;
        petsc::options::set_default("-pc_factor_mat_solver_type", "mumps")?;
        return Ok(());
    }
    // CG needs a positive definite matrix. A contact tangent is symmetric
    // without friction but not definite: its geometric terms (pN times the
    // master's curvature) go negative where a trial iterate penetrates deeply
    // (hertz-sphere, 167k DOFs: CG stopped with DIVERGED_INDEFINITE_MAT in
    // the first Newton iterations and the step was cut back twice; GMRES
    // converged in 76–176 iterations without a cutback).
    if symmetric && !contact {
        petsc::options::set_default("-ksp_type", "cg")?;
    } else {
        petsc::options::set_default("-ksp_type", "gmres")?;
        petsc::options::set_default("-ksp_gmres_restart", "100")?;
    }
    petsc::options::set_default("-pc_type", "gamg")?;
    petsc::options::set_default("-ksp_rtol", "1e-10")?;
    if contact {
        // Eisenstat–Walker: each linear solve only as tight as Newton's
        // progress needs (hertz-sphere h = 0.35, 2 ranks: 977 -> 152 GMRES
        // iterations for 12 -> 31 Newton iterations, 241 s -> 100 s on a
        // loaded machine, same Hertz errors). A direct solve gains nothing.
        petsc::options::set_default("-snes_ksp_ew", "true")?;
    }
    petsc::options::set_default("-ksp_max_it", "2000")?;
    Ok(())
}

/// A model set up on this rank: partition, numbering, element data, contact
/// pairs, Jacobian storage. Built collectively by every rank.
pub struct Simulation<'m> {
    model: &'m Model,
    partition: Vec<i32>,
    dofs: DofMap,
    bulk: BulkAssembler,
    loads: SurfaceLoads,
    dirichlet: Dirichlet,
    contact: Vec<ContactPair>,
    jac: Matrix,
}

impl<'m> Simulation<'m> {
    /// Partitions (METIS on rank 0, broadcast), numbers the DOFs, precomputes
    /// element data, resolves contact pairs and allocates the Jacobian.
    /// Collective; fails on every rank if it fails on one.
    pub fn setup(rt: &Runtime, model: &'m Model) -> Result<Self> {
        let stage = LogStage::register("Setup")?;
        stage.scope(|| setup(rt, model))
    }

    /// Owning rank of every cell (global, natural order).
    pub fn partition(&self) -> &[i32] {
        &self.partition
    }

    pub fn dofs(&self) -> &DofMap {
        &self.dofs
    }

    pub fn model(&self) -> &Model {
        self.model
    }

    pub fn contact(&self) -> &[ContactPair] {
        &self.contact
    }

    /// Runs all load steps, calling `sink` after every converged one.
    /// Runs the load steps, from the start or (`restart`) from a converged
    /// step read back from a result file.
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
        let stages = phases::Stages::register()?;
        // Phases booked here; the callbacks book theirs in `mech.times`.
        let mut times = PhaseTimes::default();
        // Frictionless links keep the tangent symmetric (it is the Hessian
        // of a potential); friction, mortar pairs and follower loads do not.
        // A follower load's facets may sit on some ranks only: the choice is
        // agreed, or the ranks would factor one matrix as LU and LDLᵀ at once.
        let unsymmetric = self.contact.iter().any(|p| !p.tangent_is_symmetric());
        let follower = parallel::any_rank(&world, self.loads.has_follower());
        let symmetric =
            !follower && !unsymmetric && model.materials.iter().all(Material::tangent_is_symmetric);
        let tangent = TangentKind {
            symmetric,
            linear_bulk: model.materials.iter().all(Material::is_linear),
            contact: !self.contact.is_empty(),
        };
        set_solver_defaults(&model.solver, tangent, DIM * self.dofs.num_global_nodes())?;
        let Simulation {
            dofs,
            bulk,
            loads,
            dirichlet,
            contact,
            jac,
            ..
        } = self;
        let (dofs, bulk, loads, dirichlet) = (&*dofs, &*bulk, &*loads, &*dirichlet);
        let mut mech = Mechanics::new(
            dofs,
            bulk,
            loads,
            dirichlet,
            contact,
            model.body_force.clone(),
            model.solver.reuse.linear_stiffness,
        )?;
        // Only with linear bodies is the tangent fixed while the active set
        // is (a hyperelastic tangent changes every iteration anyway).
        if !mech.contact.is_empty()
            && tangent.linear_bulk
            && model.solver.reuse.preconditioner
            && model.solver.reuse.active_set
        {
            mech.lag = Some(lagging::PreconditionerLag::default());
        }
        if let Some(b) = &model.body_force_fn {
            let mut f = vec![0.0; DIM * dofs.num_local_nodes()];
            bulk.add_body_force_fn(
                &model.mesh.nodes,
                |l| dofs.natural(LocalNode(l as usize)).0,
                b.as_ref(),
                &mut f,
            )?;
            mech.fixed_external = Some(f);
        }
        let mut stepper = match &model.dynamics {
            Some(spec) => {
                let (stepper, inertia) =
                    dynamics::TimeStepper::new(spec, model.steps, &model.mesh, dofs, bulk)?;
                mech.inertia = Some(inertia);
                Some(stepper)
            }
            None => None,
        };
        let mut x = Vector::new_mpi(dofs.num_owned_dofs())?;
        x.set_block_size(DIM)?;
        x.set_all(0.0)?;
        let (first_step, mut done) = match restart {
            Some(state) => {
                parallel::agree(&world, take_over(state, dofs, &mut x, mech.contact))?;
                (state.step, state.load_factor)
            }
            None => (0, 0.0),
        };
        let mut r = x.duplicate()?;
        let mut x_prev = x.duplicate()?;
        let mut predictor = Predictor::new(&x, model.solver.extrapolate)?;
        let mut reaction = x.duplicate()?;
        let mut snes = Snes::new()?;
        let user_atol = petsc::options::has("-snes_atol")?;
        let atol_floor = 1e-14 * force_scale(model);
        snes.set_tolerances(
            model.solver.atol.unwrap_or(atol_floor),
            model.solver.rtol,
            0.0,
            model.solver.max_newton,
        )?;
        snes.set_from_options()?;

        let mut steps = Vec::new();
        let mut pattern_builds = 0usize;
        let base = 1.0 / model.steps.max(1) as f64;
        let mut increment = base;
        let mut cutbacks_here = 0usize;
        while done < 1.0 - 1e-12 {
            let target = (done + increment).min(1.0);
            let t0 = Instant::now();
            x_prev.copy_from(&x)?;
            let contact_prev: Vec<_> = mech.contact.iter().map(|p| p.snapshot()).collect();
            predictor.extrapolate(&mut x, done, target)?;
            mech.factor = target;
            let coefficients = match &mut stepper {
                Some(s) => Some(prepare_time_step(s, &mut mech, done, target)?),
                None => None,
            };
            x.with_array_mut(|xa| dirichlet.apply(xa, target))?;
            let step_start_times = add_times(&times, &mech.times);
            if !mech.contact.is_empty() {
                let mark = PhaseMark::new(&mech);
                let searched = stages.scope(Phase::ContactSearch, || {
                    mech.with_state(&x, |u, pairs| {
                        let changed = pairs.iter_mut().fold(false, |c, p| p.search(u, target) | c);
                        fault::check(FaultPhase::Search)?;
                        Ok(changed)
                    })
                });
                let changed = parallel::agree(&world, searched)?;
                mark.book(Phase::ContactSearch, &mut times, &mech);
                let rebuild = !model.solver.reuse.pattern || pattern_builds == 0;
                if parallel::any_rank(&world, changed) || rebuild {
                    // A new coupling pattern is contact assembly's cost.
                    *jac = stages.time(Phase::ContactAssembly, &mut times, || {
                        build_jacobian(dofs, bulk, loads, mech.contact, &model.mesh)
                    })?;
                    pattern_builds += 1;
                }
            }
            // The step's first residual (the step's own force scale when no
            // atol is given) fails like any other: into the cutback path.
            let mut first = Ok(());
            if model.solver.atol.is_none() && !user_atol {
                // The step's own force scale: the residual once the new loads
                // and prescribed displacements are in place.
                match mech.residual_norm(&x, &mut r) {
                    Ok(r0) => snes.set_tolerances(
                        (model.solver.rtol * r0).max(atol_floor),
                        model.solver.rtol,
                        0.0,
                        model.solver.max_newton,
                    )?,
                    Err(CallbackError::Domain(why)) => first = Err(StepFailure::Residual(why)),
                    Err(CallbackError::Fatal(why)) => {
                        return Err(Error::Petsc(petsc::PetscError {
                            call: "first residual of a step",
                            code: -1,
                            message: why,
                        }))
                    }
                }
            }
            // A step (or its retry) starts with fresh factors.
            if let Some(lag) = mech.lag.as_mut() {
                lag.reset();
            }
            let attempt = first.map_or_else(
                |f| Ok(Err(f)),
                |()| {
                    stage_solve.scope(|| {
                        let mut ctx = StepContext {
                            snes: &mut snes,
                            x: &mut x,
                            r: &mut r,
                            jac,
                            stages: &stages,
                            times: &mut times,
                            reuse_preconditioner: model.solver.reuse.preconditioner,
                            forcing: model.solver.uzawa_forcing,
                        };
                        uzawa_loop(&world, &mut ctx, &mut mech, target)
                    })
                },
            );
            let (outcome, uzawa_iterations, stats) = match attempt? {
                Ok(done_step) => done_step,
                Err(failure) => {
                    if failure.linear_solve_failed() {
                        snes.reset_preconditioner()?;
                    }
                    x.copy_from(&x_prev)?;
                    let restored = mech
                        .contact
                        .iter_mut()
                        .zip(contact_prev)
                        .try_for_each(|(p, snap)| p.restore(snap));
                    parallel::agree(&world, restored)?;
                    cutbacks_here += 1;
                    let mut why = failure_text(&failure);
                    // The count restarts after every converged step, so a
                    // load path stuck at a limit point would creep on with
                    // ever smaller increments: they never go below the
                    // scene's increment halved max_cutbacks times.
                    let smallest = base * 0.5f64.powi(model.solver.max_cutbacks as i32);
                    let too_small = increment * 0.5 < smallest * (1.0 - 1e-9);
                    if too_small && cutbacks_here <= model.solver.max_cutbacks {
                        why += &format!(
                            "; the next increment would be below the smallest allowed ({smallest:.3e}: the scene's increment halved max_cutbacks = {} times)",
                            model.solver.max_cutbacks
                        );
                    }
                    if cutbacks_here > model.solver.max_cutbacks || too_small {
                        return Err(Error::NoConvergence {
                            step: first_step + steps.len() + 1,
                            load_factor: target,
                            cutbacks: cutbacks_here - 1,
                            reason: why,
                        });
                    }
                    increment *= 0.5;
                    if echo && rt.rank() == 0 {
                        println!("  cutback: load factor {target:.6} failed ({why}); retrying with increment {increment:.3e}");
                    }
                    continue;
                }
            };
            predictor.accept(&x_prev, done)?;
            done = target;
            let dynamics_report = match (&mut stepper, &coefficients) {
                (Some(s), Some(c)) => {
                    s.advance(&x, c)?;
                    let strain =
                        parallel::agree(&world, mech.with_state(&x, |u, _| bulk.strain_energy(u)))?;
                    let time = done * s.t_end;
                    let inertia = mech
                        .inertia
                        .as_mut()
                        .ok_or_else(|| Error::Internal("dynamics without inertia".into()))?;
                    Some(s.report(&world, inertia, strain, time)?)
                }
                _ => None,
            };
            let output_mark = PhaseMark::new(&mech);
            // In dynamics the support also carries the inertia of its rows.
            parallel::agree(&world, mech.raw_residual(&x, &mut reaction))?;
            let reactions = reaction_totals(&world, dirichlet, &reaction, dofs.owned_dof_start())?;
            zero_unconstrained(&mut reaction, dirichlet)?;
            let values = mech.with_state(&x, |u, pairs| {
                let values = pairs
                    .iter_mut()
                    .map(|p| p.point_values(u, target))
                    .collect::<Result<Vec<_>>>()?;
                Ok(values.into_iter().unzip::<_, PairForce, Vec<_>, Vec<_>>())
            });
            let (fields, forces) = parallel::agree(&world, values)?;
            let contact_reports = contact_reports(&world, mech.contact, &forces, &stats);
            let nodal_pressure = parallel::agree(&world, nodal_pressure(dofs, mech.contact))?;
            let report = StepReport {
                index: first_step + steps.len() + 1,
                load_factor: done,
                newton_iterations: outcome.iterations,
                uzawa_iterations,
                linear_iterations: outcome.linear_iterations,
                residual_norm: outcome.residual_norm,
                residual_history: outcome.history.clone(),
                cutbacks: cutbacks_here,
                wall_seconds: t0.elapsed().as_secs_f64(),
                reactions,
                contact: contact_reports,
                dynamics: dynamics_report,
                phases: PhaseTimes::default(),
            };
            if echo && rt.rank() == 0 {
                print_step(&report);
            }
            crate::footprint::checkpoint("load step (solver and preconditioner alive)");
            let pair_fields: Vec<PairFields> = mech
                .contact
                .iter()
                .zip(fields)
                .map(|(pair, values)| PairFields { pair, values })
                .collect();
            let mut report = report;
            report.phases = add_times(&times, &mech.times).since(&step_start_times);
            let velocity = stepper.as_ref().map(|s| s.velocity());
            stages.scope(Phase::Output, || {
                sink.step(
                    &report,
                    &x,
                    &reaction,
                    &pair_fields,
                    &nodal_pressure,
                    velocity,
                )
            })?;
            drop(pair_fields);
            output_mark.book(Phase::Output, &mut times, &mech);
            let committed = mech.contact.iter_mut().try_for_each(|p| p.commit());
            parallel::agree(&world, committed)?;
            steps.push(report);
            cutbacks_here = 0;
            // Grow back towards the scene's increment after a successful cut step.
            increment = (increment * 2.0).min(base);
        }
        let mut natural = NaturalOrder::nodal(dofs)?;
        let displacement = natural.gather_all(&x)?;
        Ok(RunReport {
            steps,
            global_dofs: DIM * dofs.num_global_nodes(),
            wall_seconds: started.elapsed().as_secs_f64(),
            displacement,
            bulk_tangent_assemblies: mech.bulk_tangent_assemblies,
            pattern_builds,
            preconditioner_builds: mech.lag.as_ref().map_or(0, |l| l.rebuilds),
            preconditioner_reuses: mech.lag.as_ref().map_or(0, |l| l.reuses),
            phases: max_over_ranks(&world, add_times(&times, &mech.times)),
            halo_displacements: parallel::sum_usize(&world, [dofs.ghost_dofs().len()])[0],
            halo_multipliers: parallel::sum_usize(
                &world,
                [mech
                    .contact
                    .iter()
                    .map(|p| p.multipliers.ghost_values())
                    .sum()],
            )[0],
        })
    }
}

/// Sets the displacement and every pair's multipliers and friction history
/// to a restart file's step (each rank its own rows).
fn take_over(
    state: &RestartState,
    dofs: &DofMap,
    x: &mut Vector,
    pairs: &mut [ContactPair],
) -> Result<()> {
    let start = dofs.owned_dof_start();
    x.with_array_mut(|xa| {
        for l in (0..dofs.num_local_nodes()).map(LocalNode) {
            if !dofs.is_owned(l) {
                continue;
            }
            let n = dofs.natural(l).0;
            for c in 0..DIM {
                let row = dofs.dof(l, c).0 as usize - start;
                xa[row] = state.displacement[DIM * n + c];
            }
        }
    })?;
    for (pair, rows) in pairs.iter_mut().zip(&state.pairs) {
        pair.restart_from(rows)?;
    }
    Ok(())
}

fn add_times(a: &PhaseTimes, b: &PhaseTimes) -> PhaseTimes {
    let mut t = *a;
    for (x, y) in t.0.iter_mut().zip(b.0) {
        *x += y;
    }
    t
}

fn max_over_ranks(world: &impl Communicator, t: PhaseTimes) -> PhaseTimes {
    PhaseTimes(parallel::max(world, t.0))
}

/// The solver state one Uzawa loop works on.
struct StepContext<'s> {
    snes: &'s mut Snes,
    x: &'s mut Vector,
    r: &'s mut Vector,
    jac: &'s mut Matrix,
    stages: &'s phases::Stages,
    times: &'s mut PhaseTimes,
    reuse_preconditioner: bool,
    /// Newton's relative forcing in non-final Uzawa iterations.
    forcing: f64,
}

/// The initial guess of a load step: the last converged state, or the last
/// two extrapolated linearly in the load factor.
struct Predictor {
    /// The converged state before the last one, and its load factor
    /// (None: no extrapolation).
    older: Option<(Vector, f64)>,
}

impl Predictor {
    fn new(like: &Vector, enabled: bool) -> Result<Self> {
        let older = if enabled {
            Some((like.duplicate()?, f64::NAN))
        } else {
            None
        };
        Ok(Predictor { older })
    }

    /// x ← x + (to − from)/(from − f_older)·(x − x_older), once two converged
    /// states exist (a step cut back retries with a shorter extrapolation).
    fn extrapolate(&self, x: &mut Vector, from: f64, to: f64) -> Result<()> {
        let Some((older, f_older)) = &self.older else {
            return Ok(());
        };
        let span = from - f_older;
        if span.is_nan() || span <= 0.0 {
            return Ok(());
        }
        // x + r (x − x_older) = (1 + r) x − r x_older, without a work vector.
        let ratio = (to - from) / span;
        x.scale(1.0 + ratio)?;
        x.axpy(-ratio, older)?;
        Ok(())
    }

    /// A step from `x_start` (converged at load `f_start`) has converged.
    fn accept(&mut self, x_start: &Vector, f_start: f64) -> Result<()> {
        if let Some((older, f_older)) = self.older.as_mut() {
            older.copy_from(x_start)?;
            *f_older = f_start;
        }
        Ok(())
    }
}

/// The start of a phase measured around work that may call the residual or
/// Jacobian (which book their own phases) or exchange multipliers (halo):
/// `book` charges the phase with the rest only, so nothing counts twice.
struct PhaseMark {
    start: Instant,
    callbacks: f64,
    halo: f64,
}

impl PhaseMark {
    fn new(mech: &Mechanics) -> Self {
        PhaseMark {
            start: Instant::now(),
            callbacks: mech.times.total(),
            halo: multiplier_halo_seconds(mech.contact),
        }
    }

    fn book(self, p: Phase, times: &mut PhaseTimes, mech: &Mechanics) {
        let halo = multiplier_halo_seconds(mech.contact) - self.halo;
        let nested = mech.times.total() - self.callbacks + halo;
        times.add(p, (self.start.elapsed().as_secs_f64() - nested).max(0.0));
        times.add(Phase::HaloExchange, halo);
    }
}

fn multiplier_halo_seconds(pairs: &[ContactPair]) -> f64 {
    pairs.iter().map(|p| p.multipliers.exchange_seconds).sum()
}

/// Sets up one time step from load factor `from` to `to`: the Newmark
/// coefficients for its Δt, the inertia term, and the slip rate of every
/// frictional pair.
fn prepare_time_step(
    stepper: &mut dynamics::TimeStepper,
    mech: &mut Mechanics,
    from: f64,
    to: f64,
) -> Result<newmark::Coefficients> {
    let dt = (to - from) * stepper.t_end;
    let c = stepper.coefficients(to - from);
    let inertia = mech
        .inertia
        .as_mut()
        .ok_or_else(|| Error::Internal("dynamics without inertia".into()))?;
    stepper.prepare(&c, inertia)?;
    for pair in mech.contact.iter_mut().filter(|p| p.has_friction()) {
        let (a, b) = (pair.rigid_shift(from), pair.rigid_shift(to));
        let rigid_velocity = [0, 1, 2].map(|i| (b[i] - a[i]) / dt);
        pair.rate = Some(stepper.slip_rate(&c, dt, rigid_velocity)?);
    }
    Ok(c)
}

type StepResult = std::result::Result<(SnesOutcome, usize, Vec<UzawaStats>), StepFailure>;

/// The Uzawa loop of one load step (docs/formulation.md §6.2): Newton with λ fixed, then
/// λ ← ⟨λ − εN gN⟩ at every link, until the penetration and the multiplier
/// change meet the tolerances on every rank (or there is no contact).
/// Newton iterations are summed over the Uzawa iterations.
fn uzawa_loop(
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
    let result = uzawa_rounds(world, ctx, mech, factor, &inner, (stol, max_it));
    ctx.snes.set_tolerances(atol, rtol, stol, max_it)?;
    result
}

fn uzawa_rounds(
    world: &impl Communicator,
    ctx: &mut StepContext,
    mech: &mut Mechanics,
    factor: f64,
    inner: &tolerance::InnerTolerance,
    (stol, max_it): (f64, usize),
) -> Result<StepResult> {
    let StepContext {
        snes,
        x,
        r,
        jac,
        stages,
        times,
        reuse_preconditioner,
        ..
    } = ctx;
    let reuse_preconditioner = *reuse_preconditioner;
    let max_uzawa = mech
        .contact
        .iter()
        .map(|p| p.spec.max_uzawa)
        .max()
        .unwrap_or(1)
        .max(1);
    let mut newton = 0usize;
    let mut linear = 0usize;
    let mut history = Vec::new();
    let mut k = 0;
    let mut raises = 0;
    // Uzawa iterations over every round (k counts within one).
    let mut total = 0;
    let mut solve_tight = !inner.is_inexact();
    loop {
        k += 1;
        total += 1;
        let tol = inner.for_solve(solve_tight);
        snes.set_tolerances(tol.atol, tol.rtol, stol, max_it)?;
        // Between Uzawa iterations only λ changes, so the tangent barely
        // does: keep the preconditioner (the LU factors) of the first solve.
        snes.set_lag_preconditioner(
            if k == 1 || mech.contact.is_empty() || !reuse_preconditioner {
                1
            } else {
                -1
            },
        )?;
        let mark = PhaseMark::new(mech);
        let mut outcome = stages.scope(Phase::LinearSolve, || snes.solve(mech, x, r, jac))?;
        mark.book(Phase::LinearSolve, times, mech);
        newton += outcome.iterations;
        linear += outcome.linear_iterations;
        history.extend_from_slice(&outcome.history);
        if !outcome.converged {
            return Ok(Err(newton_failure(world, mech, x, jac, factor, outcome)?));
        }
        if mech.contact.is_empty() {
            return Ok(Ok((outcome, 0, Vec::new())));
        }
        let mark = PhaseMark::new(mech);
        let updated = stages.scope(Phase::UzawaUpdate, || {
            mech.with_state(x, |u, pairs| {
                let stats = pairs
                    .iter_mut()
                    .map(|p| p.uzawa_update(u, factor))
                    .collect::<Result<Vec<UzawaStats>>>()?;
                fault::check(FaultPhase::UzawaUpdate)?;
                Ok(stats)
            })
        });
        let local = parallel::agree(world, updated)?;
        mark.book(Phase::UzawaUpdate, times, mech);
        let stats = reduce_stats(world, &local);
        let converged = mech
            .contact
            .iter()
            .zip(&stats)
            .all(|(p, s)| pair_converged(p, s));
        match tolerance::round_end(converged, solve_tight) {
            tolerance::RoundEnd::Converged => {
                outcome.iterations = newton;
                outcome.linear_iterations = linear;
                outcome.history = history;
                return Ok(Ok((outcome, total, stats)));
            }
            tolerance::RoundEnd::Confirm => {
                solve_tight = true;
                continue;
            }
            tolerance::RoundEnd::Continue => {}
        }
        if k >= max_uzawa && raises < PENALTY_RAISES {
            // Converging too slowly (soft bodies, long sliding): the
            // augmented Lagrangian keeps its solution for any penalty and
            // converges faster with a larger one, so raise it for the pairs
            // still outside their tolerances and give Uzawa another round.
            raises += 1;
            for (p, s) in mech.contact.iter_mut().zip(&stats) {
                if !pair_converged(p, s) {
                    p.raise_penalty(PENALTY_RAISE);
                }
            }
            k = 0;
            continue;
        }
        if k >= max_uzawa {
            let worst = stats
                .iter()
                .copied()
                .fold(UzawaStats::default(), |a, s| UzawaStats {
                    max_penetration: a.max_penetration.max(s.max_penetration),
                    max_change: a.max_change.max(s.max_change),
                    max_force: a.max_force.max(s.max_force),
                    max_multiplier: a.max_multiplier.max(s.max_multiplier),
                    active: a.active + s.active,
                    sliding: a.sliding + s.sliding,
                });
            return Ok(Err(StepFailure::Uzawa {
                iterations: total,
                stats: worst,
            }));
        }
    }
}

/// How often, and by how much, a step may raise a slow pair's penalty
/// before the Uzawa loop gives up (the raised penalty stays for the run).
const PENALTY_RAISES: usize = 2;
const PENALTY_RAISE: f64 = 10.0;

/// The Uzawa test of one pair: penetration and multiplier change within the
/// pair's tolerances.
fn pair_converged(p: &ContactPair, s: &UzawaStats) -> bool {
    s.max_penetration <= p.spec.penetration_tol
        && s.max_change <= p.spec.multiplier_tol * s.max_force.max(p.force_floor())
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

fn contact_reports(
    world: &impl Communicator,
    pairs: &[ContactPair],
    forces: &[PairForce],
    stats: &[UzawaStats],
) -> Vec<ContactReport> {
    pairs
        .iter()
        .zip(forces)
        .enumerate()
        .map(|(i, (p, f))| {
            let total = PairForce::from_array(parallel::sum(world, f.to_array()));
            let s = stats.get(i).copied().unwrap_or_default();
            ContactReport {
                name: p.spec.name.clone(),
                force: total.force,
                normal_force: total.normal,
                tangential_force: total.tangential,
                max_penetration: s.max_penetration,
                active_points: s.active,
                sliding_points: s.sliding,
                penalty: p.penalty,
            }
        })
        .collect()
}

/// Nodal contact pressure of the owned nodes (all pairs), PETSc node order.
fn nodal_pressure(dofs: &DofMap, pairs: &[ContactPair]) -> Result<Vec<f64>> {
    let n = dofs.num_owned_nodes();
    let (mut num, mut den) = (vec![0.0; n], vec![0.0; n]);
    for p in pairs {
        p.add_nodal_pressure(&mut num, &mut den)?;
    }
    Ok(num
        .iter()
        .zip(&den)
        .map(|(a, b)| if *b > 0.0 { a / b } else { 0.0 })
        .collect())
}

/// The Jacobian's storage for the current contact couplings: bulk cells,
/// follower loads and every link's candidate master patch.
fn build_jacobian(
    dofs: &DofMap,
    bulk: &BulkAssembler,
    loads: &SurfaceLoads,
    contact: &[ContactPair],
    mesh: &Mesh,
) -> Result<Matrix> {
    let mut pattern = PatternBuilder::new(dofs.num_owned_dofs(), DIM)?;
    bulk.add_pattern(&mut pattern)?;
    loads.add_pattern(&mut pattern)?;
    for pair in contact {
        pair.add_pattern(dofs, &mut pattern)?;
    }
    let mut jac = pattern.build()?;
    let coords = owned_coordinates(mesh, dofs)?;
    jac.set_rigid_body_near_null_space(&coords)?;
    Ok(jac)
}

/// Partition, number, precompute element data, resolve contact, allocate the Jacobian.
fn setup<'m>(rt: &Runtime, model: &'m Model) -> Result<Simulation<'m>> {
    let world = rt.world();
    let (rank, size) = (rt.rank(), rt.size());
    let mesh = &model.mesh;
    crate::footprint::checkpoint("model build");
    let partition = broadcast_partition(&world, mesh, rank, size)?;
    crate::footprint::checkpoint("partition");
    let mut master_nodes = Vec::new();
    for pair in &model.contact {
        if let MasterSpec::Surface { set } = &pair.master {
            master_nodes.extend(crate::contact::surfaces::MasterSurface::natural_nodes(
                mesh, set,
            )?);
        }
        if pair.formulation == crate::contact::Formulation::Mortar {
            master_nodes.extend(crate::contact::surfaces::MasterSurface::natural_nodes(
                mesh,
                &pair.slave,
            )?);
        }
    }
    let dofs = DofMap::new(mesh, &partition, rank, size, &master_nodes);
    crate::footprint::checkpoint("DOF map");
    let bulk = parallel::agree(
        &world,
        BulkAssembler::new(mesh, &dofs, model.materials.clone()),
    )?;
    crate::footprint::checkpoint("bulk assembler (element data)");
    let mut facet_loads = Vec::new();
    for (set, load, amplitude) in &model.facet_loads {
        let facets = mesh.facet_sets.get(set).ok_or_else(|| {
            Error::scene(
                "loads",
                format!("facet set '{set}' does not exist in the mesh"),
            )
        })?;
        facet_loads.push((facets.as_slice(), load.clone(), amplitude.clone()));
    }
    let loads = parallel::agree(&world, SurfaceLoads::new(mesh, &dofs, &facet_loads))?;
    let dirichlet = parallel::agree(&world, Dirichlet::new(&dofs, &model.dirichlet))?;
    let softest = model
        .materials
        .iter()
        .map(Material::youngs)
        .fold(f64::INFINITY, f64::min);
    let contact = parallel::agree(
        &world,
        model
            .contact
            .iter()
            .map(|p| ContactPair::new(mesh, &dofs, &partition, p, softest))
            .collect::<Result<Vec<_>>>(),
    )?;
    crate::footprint::checkpoint("loads, Dirichlet sets, contact pairs");
    let jac = build_jacobian(&dofs, &bulk, &loads, &[], mesh)?;
    crate::footprint::checkpoint("Jacobian allocation");
    crate::footprint::setup_finished();
    Ok(Simulation {
        model,
        partition,
        dofs,
        bulk,
        loads,
        dirichlet,
        contact,
        jac,
    })
}

/// METIS runs on rank 0 only; every rank receives its answer, so all agree
/// on one partition.
fn broadcast_partition(
    world: &impl Communicator,
    mesh: &Mesh,
    rank: usize,
    size: usize,
) -> Result<Vec<i32>> {
    let mine = if rank == 0 {
        crate::partition::partition_cells(mesh, size)
    } else {
        Ok(Vec::new())
    };
    let mut part = parallel::agree(world, mine)?;
    part.resize(mesh.num_cells(), 0);
    world.process_at_rank(0).broadcast_into(&mut part[..]);
    Ok(part)
}

fn owned_coordinates(mesh: &Mesh, dofs: &DofMap) -> Result<Vector> {
    let mut v = Vector::new_mpi(dofs.num_owned_dofs())?;
    v.set_block_size(DIM)?;
    v.with_array_mut(|a| {
        for l in 0..dofs.num_owned_nodes() {
            let p = mesh.nodes[dofs.natural(LocalNode(l)).0];
            a[DIM * l..DIM * l + DIM].copy_from_slice(&p);
        }
    })?;
    Ok(v)
}

/// A force scale for the default absolute tolerance: largest Young's modulus
/// times the squared size of the model.
fn force_scale(model: &Model) -> f64 {
    let e = model
        .materials
        .iter()
        .map(Material::youngs)
        .fold(0.0, f64::max);
    let l = model
        .mesh
        .bounding_box()
        .map_or(1.0, |b| b.size().into_iter().fold(0.0, f64::max));
    (e * l * l).max(f64::MIN_POSITIVE)
}

fn reaction_totals(
    world: &impl Communicator,
    dirichlet: &Dirichlet,
    raw: &Vector,
    start: usize,
) -> Result<Vec<(String, [f64; 3])>> {
    let local = raw.with_array(|a| dirichlet.reaction_sums(a, start))?;
    let total: Vec<f64> = local
        .iter()
        .flat_map(|s| parallel::sum(world, *s))
        .collect();
    Ok(dirichlet
        .set_names
        .iter()
        .enumerate()
        .map(|(i, n)| {
            (
                n.clone(),
                [total[3 * i], total[3 * i + 1], total[3 * i + 2]],
            )
        })
        .collect())
}

fn zero_unconstrained(reaction: &mut Vector, dirichlet: &Dirichlet) -> Result<()> {
    reaction.with_array_mut(|a| {
        let mut keep = vec![false; a.len()];
        for d in &dirichlet.dofs {
            keep[d.owned_index] = true;
        }
        for (v, k) in a.iter_mut().zip(keep) {
            if !k {
                *v = 0.0;
            }
        }
    })?;
    Ok(())
}

fn print_step(s: &StepReport) {
    let hist: Vec<String> = s
        .residual_history
        .iter()
        .map(|r| format!("{r:.2e}"))
        .collect();
    println!(
        "step {:4}  load {:.4}  newton {:2}  uzawa {:2}  ksp {:4}  |R| {:.3e}  {:.2}s  [{}]",
        s.index,
        s.load_factor,
        s.newton_iterations,
        s.uzawa_iterations,
        s.linear_iterations,
        s.residual_norm,
        s.wall_seconds,
        hist.join(" ")
    );
    if let Some(d) = &s.dynamics {
        println!(
            "     t = {:.6e}: kinetic {:.6e}, strain {:.6e}, total {:.6e}, momentum [{:.6e}, {:.6e}, {:.6e}]",
            d.time, d.kinetic, d.strain, d.kinetic + d.strain, d.momentum[0], d.momentum[1], d.momentum[2]
        );
    }
    for c in &s.contact {
        println!(
            "     contact {}: force [{:.6e}, {:.6e}, {:.6e}], normal {:.6e}, tangential {:.6e}, {} active points ({} sliding), max penetration {:.3e} h, penalty {:.3e}",
            c.name, c.force[0], c.force[1], c.force[2], c.normal_force, c.tangential_force, c.active_points, c.sliding_points, c.max_penetration, c.penalty
        );
    }
}

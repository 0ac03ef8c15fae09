//! The solution procedure: load steps, each solved by Newton (PETSc SNES),
//! cut back when Newton fails; converged steps go to the output file.
//!
//! This module sits above `assembly` (and later `contact`): they know nothing
//! of SNES, and only this module calls the solver.
pub mod boundary;
pub mod mechanics;
pub mod natural;

pub use boundary::{Dirichlet, DirichletSpec};
pub use mechanics::Mechanics;
pub use natural::NaturalOrder;

use crate::assembly::{BulkAssembler, FacetLoad, SurfaceLoads};
use crate::dofs::{DofMap, LocalNode, DIM};
use crate::error::{Error, Result};
use crate::fem::Material;
use crate::mesh::Mesh;
use crate::petsc::{self, LogStage, Matrix, Preallocation, Snes, Vector};
use crate::runtime::Runtime;
use mpi::collective::SystemOperation;
use mpi::traits::*;
use std::time::Instant;

/// Newton and load-stepping settings.
#[derive(Debug, Clone)]
pub struct SolverSettings {
    pub max_newton: usize,
    pub rtol: f64,
    /// Absolute residual tolerance; None: 1e-10 × a force scale of the model.
    pub atol: Option<f64>,
    pub max_cutbacks: usize,
    /// PETSc options (defaults that the command line and PETSC_OPTIONS override).
    pub petsc_options: String,
}

impl Default for SolverSettings {
    fn default() -> Self {
        SolverSettings {
            max_newton: 30,
            rtol: 1e-9,
            atol: None,
            max_cutbacks: 8,
            petsc_options: String::new(),
        }
    }
}

/// A vector field of the reference position, b(X).
pub type VectorField = Box<dyn Fn([f64; 3]) -> [f64; 3]>;

/// A fully resolved problem: mesh, materials per body, conditions, steps.
pub struct Model {
    pub name: String,
    pub mesh: Mesh,
    /// Material of each body, indexed like `mesh.bodies`.
    pub materials: Vec<Material>,
    pub dirichlet: Vec<DirichletSpec>,
    /// (facet set name, load at full load factor).
    pub facet_loads: Vec<(String, FacetLoad)>,
    /// Body force per body (per unit reference volume) at full load.
    pub body_force: Vec<[f64; 3]>,
    /// A spatially varying body force b(X) at full load (manufactured solutions).
    pub body_force_fn: Option<VectorField>,
    pub steps: usize,
    pub solver: SolverSettings,
}

/// What one converged load increment did.
#[derive(Debug, Clone)]
pub struct StepReport {
    pub index: usize,
    pub load_factor: f64,
    pub newton_iterations: usize,
    pub linear_iterations: usize,
    pub residual_norm: f64,
    pub residual_history: Vec<f64>,
    pub cutbacks: usize,
    pub wall_seconds: f64,
    /// Total reaction force of each Dirichlet set (summed over ranks).
    pub reactions: Vec<(String, [f64; 3])>,
}

/// The result of a run: per-step reports and the final displacement.
pub struct RunReport {
    pub steps: Vec<StepReport>,
    pub global_dofs: usize,
    pub wall_seconds: f64,
    /// Final displacement in natural node order, on every rank (N×3 flat).
    pub displacement: Vec<f64>,
    pub bulk_tangent_assemblies: usize,
}

/// Receives every converged step (the output file, a progress printer, ...).
pub trait StepSink {
    fn step(&mut self, report: &StepReport, displacement: &Vector, reaction: &Vector)
        -> Result<()>;
}

/// Sets the program's PETSc defaults; the user's options win.
fn set_solver_defaults(settings: &SolverSettings, symmetric: bool) -> Result<()> {
    petsc::options::insert_string_defaults(&settings.petsc_options)?;
    petsc::options::set_default("-ksp_type", if symmetric { "cg" } else { "gmres" })?;
    petsc::options::set_default("-pc_type", "gamg")?;
    petsc::options::set_default("-ksp_rtol", "1e-10")?;
    petsc::options::set_default("-ksp_max_it", "2000")?;
    Ok(())
}

/// A model set up on this rank: partition, numbering, element data, Jacobian
/// storage. Built collectively by every rank.
pub struct Simulation<'m> {
    model: &'m Model,
    partition: Vec<i32>,
    dofs: DofMap,
    bulk: BulkAssembler,
    loads: SurfaceLoads,
    dirichlet: Dirichlet,
    prealloc: Preallocation,
    jac: Matrix,
}

impl<'m> Simulation<'m> {
    /// Partitions (METIS on rank 0, broadcast), numbers the DOFs, precomputes
    /// element data and allocates the Jacobian. Collective; fails on every rank
    /// if it fails on one.
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

    /// Runs all load steps, calling `sink` after every converged one.
    pub fn run(&mut self, rt: &Runtime, sink: &mut dyn StepSink, echo: bool) -> Result<RunReport> {
        let started = Instant::now();
        let world = rt.world();
        let model = self.model;
        let stage_solve = LogStage::register("Solve")?;
        let symmetric = !self.loads.has_follower();
        set_solver_defaults(&model.solver, symmetric)?;
        let (dofs, bulk, loads, dirichlet) = (&self.dofs, &self.bulk, &self.loads, &self.dirichlet);
        let mut mech = Mechanics::new(
            dofs,
            bulk,
            loads,
            dirichlet,
            model.body_force.clone(),
            &self.prealloc,
        )?;
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
        let mut x = Vector::new_mpi(dofs.num_owned_dofs())?;
        x.set_block_size(DIM)?;
        x.set_all(0.0)?;
        let mut r = x.duplicate()?;
        let mut x_prev = x.duplicate()?;
        let mut reaction = x.duplicate()?;
        let mut snes = Snes::new()?;
        let atol = model
            .solver
            .atol
            .unwrap_or_else(|| 1e-10 * force_scale(model));
        snes.set_tolerances(atol, model.solver.rtol, 0.0, model.solver.max_newton)?;
        snes.set_from_options()?;

        let mut steps = Vec::new();
        let base = 1.0 / model.steps.max(1) as f64;
        let mut done = 0.0f64;
        let mut increment = base;
        let mut cutbacks_here = 0usize;
        while done < 1.0 - 1e-12 {
            let target = (done + increment).min(1.0);
            let t0 = Instant::now();
            x_prev.copy_from(&x)?;
            mech.factor = target;
            x.with_array_mut(|xa| dirichlet.apply(xa, target))?;
            let jac = &mut self.jac;
            let outcome = stage_solve.scope(|| snes.solve(&mut mech, &mut x, &mut r, jac))?;
            if !outcome.converged {
                x.copy_from(&x_prev)?;
                cutbacks_here += 1;
                let why = match &outcome.domain_error {
                    Some(d) => format!("{} ({d})", outcome.reason_text),
                    None => format!(
                        "{} after {} iterations, |R| = {:.3e}",
                        outcome.reason_text, outcome.iterations, outcome.residual_norm
                    ),
                };
                if cutbacks_here > model.solver.max_cutbacks {
                    return Err(Error::NoConvergence {
                        step: steps.len() + 1,
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
            done = target;
            mech.raw_residual(&x, &mut reaction)?;
            let reactions = reaction_totals(&world, dirichlet, &reaction, dofs.owned_dof_start())?;
            zero_unconstrained(&mut reaction, dirichlet)?;
            let report = StepReport {
                index: steps.len() + 1,
                load_factor: done,
                newton_iterations: outcome.iterations,
                linear_iterations: outcome.linear_iterations,
                residual_norm: outcome.residual_norm,
                residual_history: outcome.history.clone(),
                cutbacks: cutbacks_here,
                wall_seconds: t0.elapsed().as_secs_f64(),
                reactions,
            };
            if echo && rt.rank() == 0 {
                print_step(&report);
            }
            sink.step(&report, &x, &reaction)?;
            steps.push(report);
            cutbacks_here = 0;
            // Grow back towards the scene's increment after a successful cut step.
            increment = (increment * 2.0).min(base);
        }
        let mut natural = NaturalOrder::new(dofs)?;
        let displacement = natural.gather_all(&x)?;
        Ok(RunReport {
            steps,
            global_dofs: DIM * dofs.num_global_nodes(),
            wall_seconds: started.elapsed().as_secs_f64(),
            displacement,
            bulk_tangent_assemblies: mech.bulk_tangent_assemblies,
        })
    }
}

/// Partition, number, precompute element data and allocate the Jacobian.
fn setup<'m>(rt: &Runtime, model: &'m Model) -> Result<Simulation<'m>> {
    let world = rt.world();
    let (rank, size) = (rt.rank(), rt.size());
    let mesh = &model.mesh;
    let partition = broadcast_partition(&world, mesh, rank, size)?;
    let dofs = DofMap::new(mesh, &partition, rank, size);
    let bulk = collective(
        &world,
        BulkAssembler::new(mesh, &dofs, model.materials.clone()),
    )?;
    let mut facet_loads = Vec::new();
    for (set, load) in &model.facet_loads {
        let facets = mesh.facet_sets.get(set).ok_or_else(|| {
            Error::scene(
                "loads",
                format!("facet set '{set}' does not exist in the mesh"),
            )
        })?;
        facet_loads.push((facets.as_slice(), load.clone()));
    }
    let loads = SurfaceLoads::new(mesh, &dofs, &facet_loads)?;
    let dirichlet = collective(&world, Dirichlet::new(&dofs, &model.dirichlet))?;
    let prealloc = dofs.bulk_preallocation(mesh, &[]);
    let mut jac = Matrix::new_aij(dofs.num_owned_dofs(), &prealloc, DIM)?;
    bulk.add_pattern(&mut jac)?;
    loads.add_pattern(&mut jac)?;
    jac.assemble()?;
    let coords = owned_coordinates(mesh, &dofs)?;
    jac.set_rigid_body_near_null_space(&coords)?;
    Ok(Simulation {
        model,
        partition,
        dofs,
        bulk,
        loads,
        dirichlet,
        prealloc,
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
    let mut ok = i32::from(mine.is_ok());
    world.process_at_rank(0).broadcast_into(&mut ok);
    if ok == 0 {
        return Err(mine
            .err()
            .unwrap_or_else(|| Error::Partition("rank 0 could not partition the mesh".into())));
    }
    let mut part = mine.unwrap_or_else(|_| Vec::new());
    part.resize(mesh.num_cells(), 0);
    world.process_at_rank(0).broadcast_into(&mut part[..]);
    Ok(part)
}

/// Makes a per-rank result collective: if any rank failed, every rank returns
/// an error (the failing rank its own), so no rank waits in a later collective.
pub fn collective<T>(world: &impl Communicator, r: Result<T>) -> Result<T> {
    let mine = r.is_ok() as i32;
    let mut all = 0i32;
    world.all_reduce_into(&mine, &mut all, SystemOperation::min());
    match r {
        Ok(v) if all == 1 => Ok(v),
        Ok(_) => Err(Error::Mpi(
            "another rank failed during set-up (its message is printed by that rank)".into(),
        )),
        Err(e) => Err(e),
    }
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
    let flat: Vec<f64> = local.iter().flat_map(|s| s.iter().copied()).collect();
    let mut total = vec![0.0; flat.len()];
    world.all_reduce_into(&flat[..], &mut total[..], SystemOperation::sum());
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
        "step {:4}  load {:.4}  newton {:2}  ksp {:4}  |R| {:.3e}  {:.2}s  [{}]",
        s.index,
        s.load_factor,
        s.newton_iterations,
        s.linear_iterations,
        s.residual_norm,
        s.wall_seconds,
        hist.join(" ")
    );
}

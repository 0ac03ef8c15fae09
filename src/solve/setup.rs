//! Setting a model up for the solver, collectively on every rank: the
//! distribution (METIS and the numbering on rank 0, each rank sent its
//! piece), DOF numbering, element data,
//! contact pairs and the Jacobian's storage (sparsity pattern and rigid-body
//! near-null space); the PETSc defaults (Newton's line search, the linear
//! solver and preconditioner) chosen from the kind of tangent, and Newton
//! (SNES) with the settings' tolerances.
use super::boundary::Dirichlet;
use crate::assembly::PatternBuilder;
use crate::assembly::{BulkAssembler, SurfaceLoads};
use crate::contact::ContactPair;
use crate::distribution;
use crate::distribution::LocalMesh;
use crate::dofs::{DofMap, DIM};
use crate::error::{Error, Result};
use crate::fem::Material;
use crate::mesh::Mesh;
use crate::model::{Model, SolverSettings};
use crate::parallel;
use crate::petsc::{self, Matrix, Snes, Vector};
use crate::runtime::Runtime;
use mpi::traits::*;
use std::borrow::Cow;

/// What the default solver choice depends on.
#[derive(Debug, Clone, Copy)]
pub(super) struct TangentKind {
    /// No friction, no follower load: LDLᵀ / CG.
    pub(super) symmetric: bool,
    /// Every body linear-elastic: the residual is one matrix-vector product.
    pub(super) linear_bulk: bool,
    /// The model has contact pairs.
    pub(super) contact: bool,
    /// Some contact pair has friction (a nonsmooth stick/slip switch).
    pub(super) frictional: bool,
    /// Some contact pair's Newton wants accurate linear solves
    /// (`contact::Traits::accurate_linear_solves`).
    pub(super) accurate_linear_solves: bool,
    /// Nothing is ever added to the linear stiffness (linear bodies, no
    /// contact, inertia or follower load): the Jacobian never changes, so
    /// the preconditioner is set up once.
    pub(super) constant: bool,
}

/// Collective: the kind of tangent the model has, the same on every rank.
pub(super) fn tangent_kind(
    world: &impl Communicator,
    model: &Model,
    loads: &SurfaceLoads,
    contact: &[ContactPair],
) -> TangentKind {
    // Each pair's formulation says whether its tangent is symmetric (the
    // Hessian of a potential); a follower load's is not.
    // A follower load's facets may sit on some ranks only: the choice is
    // agreed, or the ranks would factor one matrix as LU and LDLᵀ at once.
    let unsymmetric = contact.iter().any(|p| !p.tangent_is_symmetric());
    let follower = parallel::any_rank(world, loads.has_follower());
    let symmetric =
        !follower && !unsymmetric && model.materials.iter().all(Material::tangent_is_symmetric);
    let linear_bulk = model.materials.iter().all(Material::is_linear);
    TangentKind {
        symmetric,
        linear_bulk,
        contact: !contact.is_empty(),
        frictional: contact.iter().any(ContactPair::has_friction),
        accurate_linear_solves: contact.iter().any(|p| p.traits().accurate_linear_solves),
        constant: linear_bulk && contact.is_empty() && !follower && model.dynamics.is_none(),
    }
}

/// Up to this many DOFs a one-rank direct solve factors with PETSc's own
/// LU / Cholesky (nested dissection), above it with MUMPS, whose set-up per
/// factorisation dominates small solves; the two cross near this size
/// (docs/performance.md, "The solver paths"). The contact Schur path keeps
/// MUMPS whatever the size.
const NATIVE_FACTOR_MAX_DOFS: usize = 600;

/// Sets the program's PETSc defaults; the user's options win.
pub(super) fn set_solver_defaults(
    settings: &SolverSettings,
    tangent: TangentKind,
    dofs: usize,
) -> Result<()> {
    let TangentKind {
        symmetric,
        linear_bulk,
        contact,
        frictional,
        accurate_linear_solves,
        constant,
    } = tangent;
    petsc::options::clear_defaults()?;
    petsc::options::insert_string_defaults(&settings.petsc_options)?;
    if linear_bulk {
        // The secant (l2) line search instead of backtracking: a penalty
        // contact residual is piecewise smooth, and backtracking keeps
        // shortening steps that cross a change of the contact set. It costs
        // two extra residuals per iteration, cheap only when the bulk
        // residual is K u − f, so nonlinear bodies keep backtracking (fewer
        // iterations there, but more time).
        //
        // Not with friction: its return map switches between stick and
        // slip along a Newton direction, where ‖R‖ has a kink, and l2's
        // secant step has no decrease test (on a stacked block slide it
        // alternated between two residual levels until a cutback), while
        // backtracking keeps ‖R‖ decreasing.
        let search = if frictional { "bt" } else { "l2" };
        petsc::options::set_default("-snes_linesearch_type", search)?;
    }
    if dofs <= settings.direct_max_dofs {
        // GMRES around the LU factors: one iteration with fresh factors, a
        // few with the factors an earlier Uzawa iteration left behind.
        petsc::options::set_default("-ksp_type", "gmres")?;
        petsc::options::set_default("-ksp_rtol", "1e-10")?;
        // A symmetric tangent (no friction, no follower load) factors as
        // LDLᵀ: about 25 % faster than LU on hertz-cylinder, same answer.
        petsc::options::set_default("-pc_type", if symmetric { "cholesky" } else { "lu" })?;
        let one_rank = mpi::topology::SimpleCommunicator::world().size() == 1;
        if one_rank && dofs <= NATIVE_FACTOR_MAX_DOFS {
            // PETSc's own sparse factorisation with a nested-dissection
            // ordering: MUMPS spends about a millisecond per factorisation
            // on set-up whatever the size.
            petsc::options::set_default("-pc_factor_mat_solver_type", "petsc")?;
            petsc::options::set_default("-pc_factor_mat_ordering_type", "nd")?;
        } else {
            petsc::options::set_default("-pc_factor_mat_solver_type", "mumps")?;
        }
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
    // Unsmoothed aggregation: more Krylov iterations than smoothed, but a
    // sparser prolongator makes each cheaper and the set-up's Galerkin
    // product smaller: about the same time and less peak memory on every
    // rank count (docs/performance.md, "The solver paths").
    petsc::options::set_default("-pc_gamg_agg_nsmooths", "0")?;
    // A pair whose Newton converges in one or two iterations per Uzawa
    // iteration only when its linear solves are accurate gets GMRES to a
    // fixed 1e-4 instead of Eisenstat–Walker (a loose solve makes its
    // Newton crawl); the others keep Eisenstat–Walker, which suits them
    // (below).
    let rtol = if accurate_linear_solves {
        "1e-4"
    } else {
        "1e-10"
    };
    petsc::options::set_default("-ksp_rtol", rtol)?;
    if constant && settings.reuse.linear_stiffness {
        // The Jacobian is set once, so GAMG's set-up runs once: free the
        // Galerkin products' intermediate data (P^T A P keeps A P and the
        // transpose of P for a numeric refresh that never comes): several
        // ranks' peak memory falls, the iterations stay. Where the matrix
        // changes and GAMG reuses its
        // interpolation, the cleared products would be formed again from
        // scratch at every set-up.
        petsc::options::set_default("-mat_product_clear", "true")?;
        // Plain path, several ranks: hypre's Galerkin product instead of
        // PETSc's parallel P^T A P, whose A P and ghost rows of P are the
        // set-up peak that does not split over the ranks (the largest
        // rank's peak falls by a fifth, the iterations and time stay). One rank
        // keeps PETSc's sequential product: hypre's breaks its preconditioner
        // there (DIVERGED_INDEFINITE_PC).
        if mpi::topology::SimpleCommunicator::world().size() > 1 {
            petsc::options::set_default("-matptap_via", "hypre")?;
        }
    }
    if contact && linear_bulk && settings.reuse.preconditioner && settings.reuse.active_set {
        // The contact Jacobian's AMG hierarchy is built once a step and kept
        // while it works (`lagging`), so its Galerkin products' intermediate
        // data waits for a refresh that rarely comes: freed, as on the
        // plain path (less peak memory, the same iterations); a rebuild
        // forms them again from scratch. hypre's product, the plain path's
        // other saving, changes the contact trajectory for the worse, so
        // contact keeps PETSc's.
        petsc::options::set_default("-mat_product_clear", "true")?;
    }
    if contact && !accurate_linear_solves {
        // Eisenstat–Walker: each linear solve only as tight as Newton's
        // progress needs (far fewer GMRES iterations for some more Newton
        // ones, the same answer). A direct solve gains nothing.
        petsc::options::set_default("-snes_ksp_ew", "true")?;
        // ... but never looser than 0.1: PETSc's default ceiling (0.9) lets
        // a slowly converging Newton keep asking for one or two GMRES
        // iterations per step, each step taking only a fraction of the
        // residual off.
        petsc::options::set_default("-snes_ksp_ew_rtolmax", "0.1")?;
    }
    petsc::options::set_default("-ksp_max_it", "2000")?;
    Ok(())
}

/// What set-up hands the driver: every rank's share of the discrete problem.
pub(super) struct SetUp {
    pub(super) partition_block: Vec<i32>,
    pub(super) local: LocalMesh,
    pub(super) dofs: DofMap,
    pub(super) bulk: BulkAssembler,
    pub(super) loads: SurfaceLoads,
    pub(super) dirichlet: Dirichlet,
    pub(super) contact: Vec<ContactPair>,
    pub(super) jac: Matrix,
}

/// Partition, number, precompute element data, resolve contact, allocate the
/// Jacobian. `mesh` is the model's mesh (borrowed, or moved out of the model
/// so that it is freed once the pieces are cut).
pub(super) fn setup(rt: &Runtime, model: &Model, mesh: Cow<'_, Mesh>) -> Result<SetUp> {
    let world = rt.world();
    crate::memory::checkpoint("model build");
    // Contact pairs hold the master facets near their slave side,
    // exchanged at the searches (`contact::held_master`): no node is
    // ghosted beyond the cells' own.
    let slave_sets: Vec<String> = model.contact.iter().map(|p| p.slave.clone()).collect();
    let wanted = distribution::Wanted {
        extra_ghosts: &[],
        slave_sets: &slave_sets,
    };
    let mut piece = distribution::distribute(&world, &mesh, &wanted)?;
    // From here on nothing reads the global mesh: an owned one (a scene's
    // run) is freed before the element data and the Jacobian are allocated.
    let owned = matches!(mesh, Cow::Owned(_));
    drop(mesh);
    if owned {
        crate::memory::checkpoint("pieces cut, global mesh freed");
    }
    let partition_block = std::mem::take(&mut piece.block_partition);
    let (dofs, mut local) = DofMap::from_piece(piece);
    crate::memory::checkpoint("DOF map");
    let bulk = parallel::agree(
        &world,
        BulkAssembler::new(
            &local,
            &dofs,
            model.materials.clone(),
            model.integration.clone(),
        ),
    )?;
    crate::memory::checkpoint("bulk assembler (element data)");
    let mut facet_loads = Vec::new();
    for (set, load, amplitude) in &model.facet_loads {
        let facets = local.facet_set(set).ok_or_else(|| {
            Error::scene(
                "loads",
                format!("facet set '{set}' does not exist in the mesh"),
            )
        })?;
        facet_loads.push((facets, load.clone(), amplitude.clone()));
    }
    let loads = parallel::agree(&world, SurfaceLoads::new(&local, &dofs, &facet_loads))?;
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
            .zip(&local.slaves)
            .map(|(p, slave)| {
                ContactPair::new(
                    &local,
                    &dofs,
                    slave,
                    p,
                    softest,
                    &crate::assembly::PetscHalos,
                    &crate::assembly::MpiRanks(rt.world()),
                )
            })
            .collect::<Result<Vec<_>>>(),
    )?;
    crate::memory::checkpoint("loads, Dirichlet sets, contact pairs");
    // The contact pairs hold what they need of the slave sets; the rest of
    // the local mesh stays for the near-null space, the dynamics and the
    // output.
    local.slaves = Vec::new();
    let jac = build_jacobian(&dofs, Some((&bulk, &loads)), &[], &local)?;
    crate::memory::checkpoint("Jacobian allocation");
    crate::memory::setup_finished();
    Ok(SetUp {
        partition_block,
        local,
        dofs,
        bulk,
        loads,
        dirichlet,
        contact,
        jac,
    })
}

/// The Jacobian's storage for the current contact couplings: bulk cells,
/// follower loads and every link's candidate master patch.
pub(super) fn build_jacobian(
    dofs: &DofMap,
    bulk: Option<(&BulkAssembler, &SurfaceLoads)>,
    contact: &[ContactPair],
    mesh: &LocalMesh,
) -> Result<Matrix> {
    let mut pattern = PatternBuilder::new(dofs.num_owned_dofs(), DIM)?;
    if let Some((bulk, loads)) = bulk {
        bulk.add_pattern(&mut pattern)?;
        loads.add_pattern(&mut pattern)?;
    }
    for pair in contact {
        pair.add_pattern(&mut pattern)?;
    }
    let mut jac = pattern.build()?;
    let coords = owned_coordinates(mesh, dofs)?;
    jac.set_rigid_body_near_null_space(&coords)?;
    Ok(jac)
}

/// This rank's owned node coordinates, blocked like the displacement (for
/// the rigid-body near-null space).
fn owned_coordinates(mesh: &LocalMesh, dofs: &DofMap) -> Result<Vector> {
    let mut v = Vector::new_mpi(dofs.num_owned_dofs())?;
    v.set_block_size(DIM)?;
    v.with_array_mut(|a| {
        for l in 0..dofs.num_owned_nodes() {
            let p = mesh.nodes[l];
            a[DIM * l..DIM * l + DIM].copy_from_slice(&p);
        }
    })?;
    Ok(v)
}

/// How each step's absolute Newton tolerance is found.
pub(super) struct StepTolerance {
    /// The user set `-snes_atol`: it stays for every step.
    pub(super) user_atol: bool,
    /// The smallest absolute tolerance, from the model's force scale.
    pub(super) atol_floor: f64,
}

/// Newton (SNES) with the settings' tolerances, the options applied.
pub(super) fn newton_solver(model: &Model, local: &LocalMesh) -> Result<(Snes, StepTolerance)> {
    let mut snes = Snes::new()?;
    let user_atol = petsc::options::has("-snes_atol")?;
    let atol_floor = 1e-14 * force_scale(model, local);
    snes.set_tolerances(
        model.solver.atol.unwrap_or(atol_floor),
        model.solver.rtol,
        0.0,
        model.solver.max_newton,
    )?;
    snes.set_from_options()?;
    Ok((
        snes,
        StepTolerance {
            user_atol,
            atol_floor,
        },
    ))
}

/// A force scale for the default absolute tolerance: largest Young's modulus
/// times the squared size of the model.
pub(super) fn force_scale(model: &Model, local: &LocalMesh) -> f64 {
    let e = model
        .materials
        .iter()
        .map(Material::youngs)
        .fold(0.0, f64::max);
    let l = local
        .bounding_box
        .map_or(1.0, |b| b.size().into_iter().fold(0.0, f64::max));
    (e * l * l).max(f64::MIN_POSITIVE)
}

//! Newton's linear solves beyond PETSc's own solvers: the contact Schur
//! path (`[solver] contact_schur`), its condensed Newton, the line
//! search's slope on it, and the floor of the linear solves.
//!
//! The contact Schur path solves the direct path of linear bodies as a bulk
//! factorisation once per run plus a small dense one per Jacobian: on one
//! rank the linear bulk stiffness K is factored with a MUMPS Schur
//! complement on the DOFs the contact tangent can touch (`schur/`), and the
//! linear solver's preconditioner becomes that exact solve of
//! (K + Kc) x = b. On several ranks PETSc's MUMPS Schur complement is not
//! available; there K gets an ordinary parallel MUMPS factor, once per run,
//! and each Jacobian a low-rank update of it on C (`low_rank/`). Either
//! may run Newton on the condensed contact system (`condensed.rs`), and
//! either takes the line search's slope from its exact solves
//! (`slope.rs`). `floor.rs` stops any linear solve of a contact Newton
//! step once it has removed what Newton still needs.
//!
//! The path is chosen once per run when it applies: the direct path, every
//! body linear-elastic, contact pairs, no follower load and no inertia
//! (nothing but contact is added to K), K kept assembled, and
//! `[solver] contact_schur` on. C is the union of the DOFs of every contact
//! pattern built in the run; a pattern that reaches outside it makes the
//! next set-up factor K again with the larger C (counted as a growth).
//!
//! Nothing here calls PETSc or LAPACK directly: `petsc/` wraps every call.
mod armed;
mod condensed;
mod floor;
mod low_rank;
mod schur;
mod slope;

pub use condensed::Condensed;
pub use floor::set_linear_floor;
pub use schur::SchurPreconditioner;

use crate::assembly::{PatternSink, SurfaceLoads};
use crate::contact::ContactPair;
use crate::distribution::LocalMesh;
use crate::dofs::{DofMap, GlobalDof, LocalNode, DIM};
use crate::error::Result;
use crate::model::Model;
use crate::parallel;
use crate::petsc::{Matrix, PetscInt, Snes, Vector};
use low_rank::LowRankPreconditioner;
use slope::LastSolve;

/// What the run's report says of the Schur path.
#[derive(Debug, Clone, Copy, Default)]
pub struct SchurSummary {
    /// |C| at the end of the run.
    pub dofs: usize,
    /// Sparse factorisations of K (1 + growths).
    pub bulk_factorisations: usize,
    /// Dense factorisations of the Schur complement.
    pub schur_factorisations: usize,
    pub growths: usize,
    /// Of the dense factorisations: those of the trailing block alone, the
    /// largest such block (DOFs), and the factorisations of S0's leading
    /// block they needed.
    pub trailing_factorisations: usize,
    pub largest_trailing: usize,
    pub leading_factorisations: usize,
    /// Solves with the sparse factor (one rank: condensation and
    /// expansion; several: see `LowRankPreconditioner::sparse_solves`), and
    /// the condensed Newton steps (one rank: with the dense Schur
    /// complement alone; several: dense work on rank 0).
    pub sparse_solves: usize,
    pub dense_solves: usize,
    /// Several ranks: K's factor with a low-rank update (`schur_factorisations`
    /// counts the dense LUs of I + D G; G's columns come in
    /// `inverse_blocks` requests, `inverse_columns` in all).
    pub low_rank: bool,
    pub inverse_blocks: usize,
    pub inverse_columns: usize,
    /// Of them, those from whole solves (every rank's count); whole solves
    /// that probed the selected inverse, and requests redone because its
    /// entries failed the probe.
    pub solved_columns: usize,
    pub probe_solves: usize,
    pub inverse_redone: usize,
    /// Low-rank path, rank 0's CPU seconds: forming G, and the dense
    /// set-ups (D gathered, M formed and factored).
    pub inverse_cpu_seconds: f64,
    pub dense_cpu_seconds: f64,
}

/// Whether the run takes the Schur path; `linear_contact`: the model has
/// contact pairs and every body is linear-elastic. Collective: a follower
/// load's facets may sit on some ranks only, so that is agreed; every other
/// argument is the same on every rank, so is the answer.
pub fn applies(
    model: &Model,
    linear_contact: bool,
    loads: &SurfaceLoads,
    global_dofs: usize,
) -> bool {
    let world = mpi::topology::SimpleCommunicator::world();
    let follower = parallel::any_rank(&world, loads.has_follower());
    let s = &model.solver;
    s.contact_schur
        && linear_contact
        && global_dofs <= s.direct_max_dofs
        && !follower
        && model.dynamics.is_none()
        && s.reuse.linear_stiffness
        && user_kept_direct_defaults()
}

/// The Schur path replaces the program's default preconditioner only: a
/// user's own -pc_type or solver package stands.
fn user_kept_direct_defaults() -> bool {
    !crate::petsc::options::user_set("-pc_type").unwrap_or(true)
        && !crate::petsc::options::user_set("-pc_factor_mat_solver_type").unwrap_or(true)
}

/// Installs the Schur preconditioner (one rank) or the low-rank one
/// (several) on `snes` from the kept bulk stiffness `k` (a second handle,
/// no copy) and the `constrained` rows the Jacobian replaces by the
/// identity; `symmetric`: the contact tangent is. Its exact solves take
/// the line search's slope (`slope`) and need no Krylov iterations around
/// them (GMRES took one each, at twice the solves; a user's -ksp_type
/// stands). Collective.
pub fn install(
    snes: &mut Snes,
    k: &Matrix,
    constrained: Vec<PetscInt>,
    symmetric: bool,
    ranks: usize,
) -> Result<()> {
    if ranks > 1 {
        let world = mpi::topology::SimpleCommunicator::world();
        let any = Box::new(move |flag| parallel::any_rank(&world, flag));
        let pc = LowRankPreconditioner::new(k.share()?, &constrained, any)?;
        snes.install_shell_preconditioner(pc)?;
    } else {
        let pc = SchurPreconditioner::new(k.share()?, constrained, symmetric);
        snes.install_shell_preconditioner(pc)?;
    }
    snes.set_operator(LastSolve::default())?;
    snes.apply_preconditioner_only()?;
    Ok(())
}

/// The one-rank path (the MUMPS Schur complement) is installed.
pub fn schur_installed(snes: &Snes) -> bool {
    snes.preconditioner::<SchurPreconditioner>().is_some()
}

/// Whether Newton may run on the condensed contact system: a Schur path
/// (one rank or several) is installed.
pub fn condenses(snes: &Snes) -> bool {
    schur_installed(snes) || snes.preconditioner::<LowRankPreconditioner>().is_some()
}

/// A load step starts at `x0` (condensed Newton only; see `condensed`).
pub fn arm(snes: &mut Snes, x0: &Vector) -> Result<()> {
    if let Some(s) = snes.preconditioner_mut::<SchurPreconditioner>() {
        s.arm(x0)?;
    }
    if let Some(s) = snes.preconditioner_mut::<LowRankPreconditioner>() {
        s.arm(x0)?;
    }
    Ok(())
}

/// The step converged: its condensed vector `x` becomes the whole state.
/// Collective.
pub fn expand(snes: &mut Snes, x: &mut Vector) -> Result<()> {
    if let Some(s) = snes.preconditioner_mut::<SchurPreconditioner>() {
        s.expand(x)?;
    }
    if let Some(s) = snes.preconditioner_mut::<LowRankPreconditioner>() {
        s.expand(x)?;
    }
    Ok(())
}

/// The step ended: its condensed state is dropped.
pub fn disarm(snes: &mut Snes) {
    if let Some(s) = snes.preconditioner_mut::<SchurPreconditioner>() {
        s.disarm();
    }
    if let Some(s) = snes.preconditioner_mut::<LowRankPreconditioner>() {
        s.disarm();
    }
}

/// The condensed Newton state the residual reads, when the run's Schur
/// path condenses.
pub fn condensed_state(snes: &mut Snes) -> Option<Condensed> {
    if let Some(s) = snes.preconditioner_mut::<SchurPreconditioner>() {
        return Some(Condensed::One(s.condense()));
    }
    snes.preconditioner_mut::<LowRankPreconditioner>()
        .map(|s| Condensed::Several(s.condense()))
}

/// Records the DOFs a square pattern block touches.
#[derive(Default)]
struct Touched(Vec<PetscInt>);

impl PatternSink for Touched {
    fn add_square(&mut self, dofs: &[GlobalDof]) -> Result<()> {
        self.0.extend(dofs.iter().map(|d| d.0).filter(|&d| d >= 0));
        Ok(())
    }
}

/// Every DOF the contact pairs' current pattern couples, with the DOFs of
/// the nodes it names (whole nodes: a node's three DOFs go together).
fn contact_dofs(pairs: &[ContactPair]) -> Result<Vec<PetscInt>> {
    let mut t = Touched::default();
    for p in pairs {
        p.add_pattern(&mut t)?;
    }
    Ok(whole_nodes(&t.0))
}

/// The DOFs the pairs reserve for C beyond their pattern (a pair's
/// nodes within the search distance), whole nodes.
fn reserved_dofs(pairs: &[ContactPair]) -> Vec<PetscInt> {
    let r: Vec<PetscInt> = pairs
        .iter()
        .flat_map(ContactPair::reserve_dofs)
        .map(|d| d.0)
        .filter(|&d| d >= 0)
        .collect();
    whole_nodes(&r)
}

/// The three DOFs of each node some DOF of `dofs` belongs to, sorted.
fn whole_nodes(dofs: &[PetscInt]) -> Vec<PetscInt> {
    let d = DIM as PetscInt;
    let mut out: Vec<PetscInt> = dofs
        .iter()
        .flat_map(|&g| {
            let n = g / d;
            (0..d).map(move |c| n * d + c)
        })
        .collect();
    out.sort_unstable();
    out.dedup();
    out
}

/// After a new Jacobian pattern: the DOFs C must hold from now on, and
/// their order key (see [`distance_to_other_body`]).
pub fn want(snes: &mut Snes, pairs: &[ContactPair], dofs: &DofMap, mesh: &LocalMesh) -> Result<()> {
    if let Some(s) = snes.preconditioner_mut::<SchurPreconditioner>() {
        let c = contact_dofs(pairs)?;
        let reserved = reserved_dofs(pairs);
        let mut all = [c.as_slice(), &reserved].concat();
        all.sort_unstable();
        all.dedup();
        s.order_by(distance_to_other_body(&all, dofs, mesh));
        s.want(c, reserved);
    }
    if let Some(s) = snes.preconditioner_mut::<LowRankPreconditioner>() {
        // Collective: this rank's share, gathered.
        s.want(&contact_dofs(pairs)?)?;
    }
    Ok(())
}

/// Beyond this many nodes in C the order key is not computed (it compares
/// every pair of C's nodes) and C keeps its DOF order.
const MAX_KEYED_NODES: usize = 20_000;

/// For each DOF of C (whole nodes, sorted): the reference distance from its
/// node to the nearest node of C on another body. The nodes nearest the
/// other body are the ones the contact zone takes first, so with C ordered
/// by decreasing distance a contact tangent touches a trailing block of the
/// Schur complement (hertz line b/40: about 330 of 1,626 DOFs), which is
/// all that is factored per Jacobian. One rank (the Schur path's), where
/// every local node is owned.
fn distance_to_other_body(c: &[PetscInt], dofs: &DofMap, mesh: &LocalMesh) -> Vec<(PetscInt, f64)> {
    let d = DIM as PetscInt;
    let mut nodes: Vec<PetscInt> = c.iter().map(|&g| g / d).collect();
    nodes.dedup();
    if nodes.len() > MAX_KEYED_NODES || mesh.owned_body.len() < dofs.num_local_nodes() {
        return Vec::new();
    }
    // The position and body of each node of C.
    let mut at: Vec<Option<([f64; 3], u32)>> = vec![None; nodes.len()];
    for l in 0..dofs.num_local_nodes() {
        let g = dofs.dof(LocalNode::from_index(l), 0).0 / d;
        if let Ok(i) = nodes.binary_search(&g) {
            at[i] = Some((mesh.nodes[l], mesh.owned_body[l]));
        }
    }
    let mut out = Vec::with_capacity(c.len());
    for (i, &n) in nodes.iter().enumerate() {
        let Some((x, body)) = at[i] else { continue };
        let nearest = at
            .iter()
            .flatten()
            .filter(|(_, b)| *b != body)
            .map(|(y, _)| (0..3).map(|k| (x[k] - y[k]).powi(2)).sum::<f64>())
            .fold(f64::INFINITY, f64::min)
            .sqrt();
        out.extend((0..d).map(|k| (n * d + k, nearest)));
    }
    out
}

/// The run's Schur figures (None: not on the Schur path).
pub fn summary(snes: &Snes) -> Option<SchurSummary> {
    let low_rank = snes
        .preconditioner::<LowRankPreconditioner>()
        .map(|s| SchurSummary {
            dofs: s.schur_size(),
            bulk_factorisations: s.bulk_factorisations,
            schur_factorisations: s.dense_factorisations,
            growths: s.growths,
            low_rank: true,
            inverse_blocks: s.inverse_blocks,
            inverse_columns: s.inverse_columns,
            inverse_cpu_seconds: s.inverse_cpu_seconds,
            dense_cpu_seconds: s.dense_cpu_seconds,
            sparse_solves: s.sparse_solves,
            dense_solves: s.dense_steps,
            solved_columns: s.solved_columns,
            probe_solves: s.probe_solves,
            inverse_redone: s.inverse_redone,
            ..SchurSummary::default()
        });
    snes.preconditioner::<SchurPreconditioner>()
        .map(|s| {
            let d = s.dense_counts();
            SchurSummary {
                dofs: s.schur_size(),
                bulk_factorisations: s.bulk_factorisations,
                schur_factorisations: s.schur_factorisations,
                growths: s.growths,
                trailing_factorisations: d.trailing,
                largest_trailing: d.largest_trailing,
                leading_factorisations: d.leading,
                sparse_solves: s.sparse_solves,
                dense_solves: s.dense_solves,
                ..SchurSummary::default()
            }
        })
        .or(low_rank)
}

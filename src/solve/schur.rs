//! The contact solve on the direct path of linear bodies as a bulk
//! factorisation once per run plus a small dense one per Jacobian: the
//! linear bulk stiffness K is factored with a MUMPS Schur complement on the
//! DOFs the contact tangent can touch (`petsc::schur`), and the linear
//! solver's preconditioner becomes that exact solve of (K + Kc) x = b.
//!
//! On several ranks PETSc's MUMPS Schur complement is not available; there
//! K gets an ordinary parallel MUMPS factor, once per run, and each
//! Jacobian a low-rank update of it on C (`petsc::low_rank`).
//!
//! Chosen once per run when it applies: the direct path, every body linear-elastic,
//! contact pairs, no follower load and no inertia (nothing but contact is
//! added to K), K kept assembled, and `[solver] contact_schur` on. C is the
//! union of the DOFs of every contact pattern built in the run; a pattern
//! that reaches outside it makes the next set-up factor K again with the
//! larger C (counted as a growth).
use super::boundary::Dirichlet;
use super::setup::TangentKind;
use crate::assembly::{PatternSink, SurfaceLoads};
use crate::contact::ContactPair;
use crate::distribution::LocalMesh;
use crate::dofs::{DofMap, GlobalDof, LocalNode, DIM};
use crate::error::Result;
use crate::model::Model;
use crate::parallel;
use crate::petsc::condensed_state::Condensed;
use crate::petsc::low_rank::LowRankPreconditioner;
use crate::petsc::schur::SchurPreconditioner;
use crate::petsc::{Matrix, PetscInt, Snes, Vector};

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

/// Whether the run takes the Schur path. Collective: a follower load's
/// facets may sit on some ranks only, so that is agreed; every other
/// argument is the same on every rank, so is the answer.
pub(super) fn applies(
    model: &Model,
    tangent: TangentKind,
    loads: &SurfaceLoads,
    global_dofs: usize,
) -> bool {
    let world = mpi::topology::SimpleCommunicator::world();
    let follower = parallel::any_rank(&world, loads.has_follower());
    let s = &model.solver;
    s.contact_schur
        && tangent.contact
        && tangent.linear_bulk
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
/// no copy) and the Dirichlet rows the Jacobian replaces by the identity.
/// Collective.
pub(super) fn install(
    snes: &mut Snes,
    k: &Matrix,
    dirichlet: &Dirichlet,
    tangent: TangentKind,
    ranks: usize,
) -> Result<()> {
    if ranks > 1 {
        let world = mpi::topology::SimpleCommunicator::world();
        let any = Box::new(move |flag| parallel::any_rank(&world, flag));
        let pc = LowRankPreconditioner::new(k.share()?, &dirichlet.global_rows(), any)?;
        snes.install_low_rank(pc)?;
        return Ok(());
    }
    let pc = SchurPreconditioner::new(k.share()?, dirichlet.global_rows(), tangent.symmetric);
    snes.install_schur(pc)?;
    Ok(())
}

/// Whether Newton may run on the condensed contact system: a Schur path
/// (one rank or several) is installed.
pub(super) fn condenses(snes: &Snes) -> bool {
    snes.schur().is_some() || snes.low_rank().is_some()
}

/// A load step starts at `x0` (condensed Newton only; see
/// `petsc::condensed` and `petsc::low_rank`).
pub(super) fn arm(snes: &mut Snes, x0: &Vector) -> Result<()> {
    if let Some(s) = snes.schur_mut() {
        s.arm(x0)?;
    }
    if let Some(s) = snes.low_rank_mut() {
        s.arm(x0)?;
    }
    Ok(())
}

/// The step converged: its condensed vector `x` becomes the whole state.
/// Collective.
pub(super) fn expand(snes: &mut Snes, x: &mut Vector) -> Result<()> {
    if let Some(s) = snes.schur_mut() {
        s.expand(x)?;
    }
    if let Some(s) = snes.low_rank_mut() {
        s.expand(x)?;
    }
    Ok(())
}

/// The step ended: its condensed state is dropped.
pub(super) fn disarm(snes: &mut Snes) {
    if let Some(s) = snes.schur_mut() {
        s.disarm();
    }
    if let Some(s) = snes.low_rank_mut() {
        s.disarm();
    }
}

/// The condensed Newton state the residual reads, when the run's Schur
/// path condenses.
pub(super) fn condensed_state(snes: &mut Snes) -> Option<Condensed> {
    if let Some(s) = snes.schur_mut() {
        return Some(Condensed::One(s.condense()));
    }
    snes.low_rank_mut()
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
pub(super) fn contact_dofs(pairs: &[ContactPair], _dofs: &DofMap) -> Result<Vec<PetscInt>> {
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
pub(super) fn want(
    snes: &mut Snes,
    pairs: &[ContactPair],
    dofs: &DofMap,
    mesh: &LocalMesh,
) -> Result<()> {
    if let Some(s) = snes.schur_mut() {
        let c = contact_dofs(pairs, dofs)?;
        let reserved = reserved_dofs(pairs);
        let mut all = [c.as_slice(), &reserved].concat();
        all.sort_unstable();
        all.dedup();
        s.order_by(distance_to_other_body(&all, dofs, mesh));
        s.want(c, reserved);
    }
    if let Some(s) = snes.low_rank_mut() {
        // Collective: this rank's share, gathered.
        s.want(&contact_dofs(pairs, dofs)?)?;
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
pub(super) fn summary(snes: &Snes) -> Option<SchurSummary> {
    let low_rank = snes.low_rank().map(|s| SchurSummary {
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
    snes.schur()
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

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
use crate::dofs::{DofMap, GlobalDof, DIM};
use crate::error::Result;
use crate::model::Model;
use crate::parallel;
use crate::petsc::low_rank::LowRankPreconditioner;
use crate::petsc::schur::SchurPreconditioner;
use crate::petsc::{Matrix, PetscInt, Snes};

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
    /// Several ranks: K's factor with a low-rank update (`schur_factorisations`
    /// counts the dense LUs of I + D G; G is formed 1 + growths times).
    pub low_rank: bool,
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
pub(super) fn contact_dofs(pairs: &[ContactPair], dofs: &DofMap) -> Result<Vec<PetscInt>> {
    let mut t = Touched::default();
    for p in pairs {
        p.add_pattern(dofs, &mut t)?;
    }
    let d = DIM as PetscInt;
    let mut out: Vec<PetscInt> =
        t.0.iter()
            .flat_map(|&g| {
                let n = g / d;
                (0..d).map(move |c| n * d + c)
            })
            .collect();
    out.sort_unstable();
    out.dedup();
    Ok(out)
}

/// After a new Jacobian pattern: the DOFs C must hold from now on.
pub(super) fn want(snes: &mut Snes, pairs: &[ContactPair], dofs: &DofMap) -> Result<()> {
    if let Some(s) = snes.schur_mut() {
        s.want(contact_dofs(pairs, dofs)?);
    }
    if let Some(s) = snes.low_rank_mut() {
        // Collective: this rank's share, gathered.
        s.want(&contact_dofs(pairs, dofs)?)?;
    }
    Ok(())
}

/// The run's Schur figures (None: not on the Schur path).
pub(super) fn summary(snes: &Snes) -> Option<SchurSummary> {
    let low_rank = snes.low_rank().map(|s| SchurSummary {
        dofs: s.schur_size(),
        bulk_factorisations: s.bulk_factorisations,
        schur_factorisations: s.dense_factorisations,
        growths: s.growths,
        low_rank: true,
        inverse_cpu_seconds: s.inverse_cpu_seconds,
        dense_cpu_seconds: s.dense_cpu_seconds,
    });
    snes.schur()
        .map(|s| SchurSummary {
            dofs: s.schur_size(),
            bulk_factorisations: s.bulk_factorisations,
            schur_factorisations: s.schur_factorisations,
            growths: s.growths,
            ..SchurSummary::default()
        })
        .or(low_rank)
}

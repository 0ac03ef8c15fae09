//! The contact solve on the direct path of linear bodies as a bulk
//! factorisation once per run plus a small dense one per Jacobian: the
//! linear bulk stiffness K is factored with a MUMPS Schur complement on the
//! DOFs the contact tangent can touch (`petsc::schur`), and the linear
//! solver's preconditioner becomes that exact solve of (K + Kc) x = b.
//!
//! Chosen once per run when it applies: one rank (PETSc's MUMPS Schur
//! complement is sequential), the direct path, every body linear-elastic,
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
}

/// Whether the run takes the Schur path (every argument is the same on every
/// rank, so is the answer).
pub(super) fn applies(
    model: &Model,
    tangent: TangentKind,
    loads: &SurfaceLoads,
    ranks: usize,
    global_dofs: usize,
) -> bool {
    let s = &model.solver;
    s.contact_schur
        && ranks == 1
        && tangent.contact
        && tangent.linear_bulk
        && global_dofs <= s.direct_max_dofs
        && !loads.has_follower()
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

/// Installs the Schur preconditioner on `snes` from the kept bulk
/// stiffness `k` (a second handle, no copy) and the Dirichlet rows the
/// Jacobian replaces by the identity.
pub(super) fn install(
    snes: &mut Snes,
    k: &Matrix,
    dirichlet: &Dirichlet,
    tangent: TangentKind,
) -> Result<()> {
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
    Ok(())
}

/// The run's Schur figures (None: not on the Schur path).
pub(super) fn summary(snes: &Snes) -> Option<SchurSummary> {
    snes.schur().map(|s| SchurSummary {
        dofs: s.schur_size(),
        bulk_factorisations: s.bulk_factorisations,
        schur_factorisations: s.schur_factorisations,
        growths: s.growths,
    })
}

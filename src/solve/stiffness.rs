//! The bulk stiffness K of linear bodies, assembled once: the residual's
//! bulk term is K u, and the Jacobian starts from K.
//!
//! When nothing is ever added to K (no contact pair, no inertia, no
//! follower load) the Jacobian is K with the Dirichlet rows and columns
//! replaced by the identity, and that one matrix serves both: J x gives
//! K_ff x_f on the free rows, and the constrained columns come back as a
//! lift K_{:,c} x_c, an element sum over x masked to the constrained DOFs,
//! formed again only when x_c changes. Otherwise K is a second matrix kept
//! beside the Jacobian (copying it in is cheaper than assembling it).
use super::boundary::Dirichlet;
use crate::assembly::BulkAssembler;
use crate::assembly::PatternBuilder;
use crate::dofs::{DofMap, DIM};
use crate::error::Result;
use crate::petsc::{GhostedVector, Matrix, Vector};

/// Whether and where a run keeps K (linear bodies only).
pub enum KeepStiffness<'j> {
    /// Assembled by elements every time.
    No,
    /// In a matrix of its own.
    Separate,
    /// In this fresh matrix of the bulk pattern (set-up's Jacobian, which
    /// the first contact search replaces before any Jacobian is formed),
    /// which becomes K's own.
    SeparateIn(&'j Matrix),
    /// In this Jacobian matrix, which nothing else is ever added to.
    InJacobian(&'j Matrix),
}

pub(super) enum LinearStiffness {
    /// K in its own matrix, added to the Jacobian each time.
    Separate(Matrix),
    /// K is the Jacobian matrix itself.
    Shared(SharedStiffness),
}

pub(super) struct SharedStiffness {
    /// A second handle on the Jacobian matrix.
    pub j: Matrix,
    /// K is in `j` (with the Dirichlet replacement) and unaltered since.
    pub ready: bool,
    /// x at this rank's constrained DOFs when `lift` was formed.
    lifted_at: Option<Vec<f64>>,
    /// K_{:,c} x_c (owned rows).
    lift: Vector,
}

/// K assembled into its own matrix.
pub(super) fn separate(dofs: &DofMap, bulk: &BulkAssembler) -> Result<Matrix> {
    let mut pattern = PatternBuilder::new(dofs.num_owned_dofs(), DIM)?;
    bulk.add_pattern(&mut pattern)?;
    let mut k = pattern.build()?;
    add_at_rest(dofs, bulk, &mut k)?;
    k.assemble()?;
    Ok(k)
}

/// K assembled into `fresh` (a handle on it is kept): a matrix of the bulk
/// pattern with no values yet and no other user, so no pattern is built.
pub(super) fn separate_in(fresh: &Matrix, dofs: &DofMap, bulk: &BulkAssembler) -> Result<Matrix> {
    let mut k = fresh.share()?;
    add_at_rest(dofs, bulk, &mut k)?;
    k.assemble()?;
    Ok(k)
}

/// K set up to live in the Jacobian `jacobian` (assembled on first use).
pub(super) fn shared(jacobian: &Matrix, like: &Vector) -> Result<SharedStiffness> {
    Ok(SharedStiffness {
        j: jacobian.share()?,
        ready: false,
        lifted_at: None,
        lift: like.duplicate()?,
    })
}

fn add_at_rest(dofs: &DofMap, bulk: &BulkAssembler, k: &mut Matrix) -> Result<()> {
    let zero = vec![0.0; DIM * dofs.num_local_nodes()];
    bulk.add_tangent(&zero, k)
}

impl SharedStiffness {
    /// Collective: K assembled into the Jacobian with the Dirichlet
    /// replacement, unless it is there already.
    pub fn ensure(
        &mut self,
        dofs: &DofMap,
        bulk: &BulkAssembler,
        dirichlet: &Dirichlet,
    ) -> Result<bool> {
        if self.ready {
            return Ok(false);
        }
        self.j.zero_entries()?;
        add_at_rest(dofs, bulk, &mut self.j)?;
        self.j.assemble()?;
        self.j
            .zero_rows_columns_identity(&dirichlet.global_rows())?;
        self.ready = true;
        Ok(true)
    }

    /// Collective: `out += K x` on the free rows (the constrained rows get
    /// x_c plus the lift's, replaced later by the Dirichlet residual).
    /// The lift must be current ([`Self::form_lift`]).
    pub fn add_product(&self, x: &Vector, out: &mut Vector, work: &mut Vector) -> Result<()> {
        self.j.mult(x, work)?;
        out.axpy(1.0, work)?;
        out.axpy(1.0, &self.lift)?;
        Ok(())
    }

    /// Whether this rank's x_c differs from the one the lift was formed at.
    pub fn lift_stale(&self, x: &Vector, dirichlet: &Dirichlet) -> Result<bool> {
        let Some(at) = &self.lifted_at else {
            return Ok(true);
        };
        x.with_array(|xa| {
            dirichlet
                .dofs
                .iter()
                .zip(at)
                .any(|(d, a)| xa[d.owned_index].to_bits() != a.to_bits())
        })
        .map_err(Into::into)
    }

    /// Collective (every rank, once any rank's x_c moved): K_{:,c} x_c.
    /// Returns this rank's assembly failure inside, after the collective
    /// calls.
    pub fn form_lift(&mut self, x: &Vector, w: LiftWork<'_>) -> Result<Result<()>> {
        let LiftWork {
            dirichlet,
            bulk,
            u,
            r,
        } = w;
        let at: Vec<f64> =
            x.with_array(|xa| dirichlet.dofs.iter().map(|d| xa[d.owned_index]).collect())?;
        u.global_mut().set_all(0.0)?;
        u.global_mut().with_array_mut(|ua| {
            for (d, v) in dirichlet.dofs.iter().zip(&at) {
                ua[d.owned_index] = *v;
            }
        })?;
        u.update_ghosts()?;
        // A local failure is returned after the collective calls below.
        let local = r.with_local_mut(|r_local| {
            r_local.fill(0.0);
            u.with_local(|u_local| bulk.add_internal_force(u_local, r_local))
        })??;
        r.accumulate_ghosts()?;
        self.lift.copy_from(r.global())?;
        self.lifted_at = Some(at);
        Ok(local)
    }
}

/// What forming the lift needs: the ghosted pair it may overwrite.
pub(super) struct LiftWork<'a> {
    pub dirichlet: &'a Dirichlet,
    pub bulk: &'a BulkAssembler,
    pub u: &'a mut GhostedVector,
    pub r: &'a mut GhostedVector,
}

//! The displacements of held master nodes this rank does not see (the tail
//! of the extended local array contact reads, `contact::held_master`): a
//! ghosted vector whose ghosts are exactly those nodes' DOFs, so filling it
//! is one PETSc scatter over the tail, rebuilt when the held set changes.
//! Residual entries of tail nodes go to their owners by global DOF.
use crate::contact::ContactPair;
use crate::dofs::GlobalDof;
use crate::error::Result;
use crate::parallel;
use crate::petsc::{GhostedVector, PetscInt, Vector};
use mpi::topology::SimpleCommunicator;

pub struct MasterTail {
    n_owned: usize,
    dofs: Vec<PetscInt>,
    /// None until some rank holds a tail (then on every rank).
    vec: Option<GhostedVector>,
}

impl MasterTail {
    pub fn new(n_owned: usize) -> Self {
        MasterTail {
            n_owned,
            dofs: Vec::new(),
            vec: None,
        }
    }

    /// Takes over the pairs' tails (in pair order, as `exchange_master`
    /// numbered them); rebuilds the scatter when any rank's tail changed.
    /// Collective.
    pub fn refresh(&mut self, world: &SimpleCommunicator, pairs: &[ContactPair]) -> Result<()> {
        let dofs: Vec<PetscInt> = pairs
            .iter()
            .flat_map(ContactPair::master_tail)
            .map(|d: &GlobalDof| d.0)
            .collect();
        let changed = dofs != self.dofs;
        if parallel::any_rank(world, changed) {
            self.vec = Some(GhostedVector::new(self.n_owned, &dofs)?);
            self.dofs = dofs;
        }
        Ok(())
    }

    /// Tail values of `x` (a vector in the DOF layout). Collective when active.
    pub fn values(&mut self, x: &Vector) -> Result<Vec<f64>> {
        let Some(v) = &mut self.vec else {
            return Ok(Vec::new());
        };
        v.global_mut().copy_from(x)?;
        v.update_ghosts()?;
        let n = self.n_owned;
        Ok(v.with_local(|l| l[n..].to_vec())?)
    }

    /// Adds tail residual entries into `out` at their global DOFs.
    /// Collective when active.
    pub fn add_into(&self, tail: &[f64], out: &mut Vector) -> Result<()> {
        if self.vec.is_none() {
            return Ok(());
        }
        out.add_values(&self.dofs, tail)?;
        out.assemble()?;
        Ok(())
    }
}

/// The local form followed by the tail: the array contact reads.
pub fn extended(local: &[f64], tail: &[f64]) -> Vec<f64> {
    let mut out = Vec::with_capacity(local.len() + tail.len());
    out.extend_from_slice(local);
    out.extend_from_slice(tail);
    out
}

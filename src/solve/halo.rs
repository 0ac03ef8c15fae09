//! The halos contact keeps its multipliers in, as PETSc ghosted vectors.
use crate::assembly::{Halo, HaloFactory};
use crate::error::{Error, Result};
use crate::petsc::{GhostedVector, PetscInt};

/// Makes [`Halo`]s backed by PETSc ghosted vectors.
pub struct PetscHalos;

impl HaloFactory for PetscHalos {
    fn halo(&self, n_owned: usize, ghosts: &[usize]) -> Result<Box<dyn Halo>> {
        let ghosts = ghosts
            .iter()
            .map(|&g| {
                PetscInt::try_from(g).map_err(|_| {
                    Error::Partition(format!("halo index {g} exceeds PETSc's index range"))
                })
            })
            .collect::<Result<Vec<_>>>()?;
        let vec = GhostedVector::new(n_owned, &ghosts)?;
        let local = vec.with_local(<[f64]>::to_vec)?;
        Ok(Box::new(GhostedHalo { vec, local }))
    }
}

/// A ghosted vector and a copy of its local form after the last exchange
/// (so readers need no PETSc call).
struct GhostedHalo {
    vec: GhostedVector,
    local: Vec<f64>,
}

impl Halo for GhostedHalo {
    fn exchange(&mut self, owned: &[f64]) -> Result<()> {
        self.vec
            .global_mut()
            .with_array_mut(|a| a.copy_from_slice(owned))?;
        self.vec.update_ghosts()?;
        let local = &mut self.local;
        self.vec.with_local(|l| {
            local.clear();
            local.extend_from_slice(l);
        })?;
        Ok(())
    }

    fn local(&self) -> &[f64] {
        &self.local
    }
}

/// Contact's master exchange over the world communicator.
pub struct MpiRanks(pub mpi::topology::SimpleCommunicator);

impl crate::assembly::RankExchange for MpiRanks {
    fn rank(&self) -> usize {
        mpi::traits::Communicator::rank(&self.0) as usize
    }
    fn size(&self) -> usize {
        mpi::traits::Communicator::size(&self.0) as usize
    }
    fn all_gather(&self, local: &[f64]) -> Vec<f64> {
        crate::parallel::gather_all(&self.0, local)
    }
    fn all_to_all(&self, send: &[Vec<f64>]) -> Vec<f64> {
        crate::parallel::all_to_all(&self.0, send)
    }
}

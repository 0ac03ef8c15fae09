//! Owned values → ghost copies: a rank's values of a distributed array
//! followed by copies of the other ranks' values it reads. `contact` keeps
//! its multipliers in such arrays through the traits here and never names
//! the storage; `solve` hands it the implementations below them (a PETSc
//! ghosted vector, MPI between the ranks).
use crate::error::{Error, Result};
use crate::petsc::{GhostedVector, PetscInt};

/// One distributed array: this rank's owned values and its ghost copies.
pub trait Halo {
    /// Takes this rank's owned values and refreshes every rank's ghost
    /// copies. Collective.
    fn exchange(&mut self, owned: &[f64]) -> Result<()>;
    /// Owned values then ghost copies (in the order the ghosts were given),
    /// as of the last exchange.
    fn local(&self) -> &[f64];
}

/// Makes halos.
pub trait HaloFactory {
    /// A halo of `n_owned` values on this rank, in a numbering contiguous per
    /// rank; `ghosts` are the global indices of the other ranks' values this
    /// rank copies. Collective.
    fn halo(&self, n_owned: usize, ghosts: &[usize]) -> Result<Box<dyn Halo>>;
}

/// The messages between ranks that contact's master side needs: `contact`
/// decides what to send, [`MpiRanks`] moves it (`solve` hands it over), so
/// contact never names the transport.
pub trait RankExchange {
    fn rank(&self) -> usize;
    fn size(&self) -> usize;
    /// Every rank's `local`, concatenated in rank order, on every rank.
    /// Collective.
    fn all_gather(&self, local: &[f64]) -> Vec<f64>;
    /// Sends `send[r]` to rank `r` and returns what every rank sent to this
    /// one, concatenated in rank order. Collective.
    fn all_to_all(&self, send: &[Vec<f64>]) -> Vec<f64>;
}

/// One rank alone: what a serial caller (or a test) hands contact.
pub struct SingleRank;

impl RankExchange for SingleRank {
    fn rank(&self) -> usize {
        0
    }
    fn size(&self) -> usize {
        1
    }
    fn all_gather(&self, local: &[f64]) -> Vec<f64> {
        local.to_vec()
    }
    fn all_to_all(&self, send: &[Vec<f64>]) -> Vec<f64> {
        send.concat()
    }
}

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

impl RankExchange for MpiRanks {
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

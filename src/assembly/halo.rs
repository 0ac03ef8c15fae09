//! Owned values → ghost copies: a rank's values of a distributed array
//! followed by copies of the other ranks' values it reads. `contact` keeps
//! its multipliers in such arrays; `solve` provides them (a PETSc ghosted
//! vector), so contact never names the storage.
use crate::error::Result;

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
/// decides what to send, `solve` moves it (over MPI), so contact never names
/// the transport.
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

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

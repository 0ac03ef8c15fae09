//! Work that one rank does alone, handed to every rank: rank 0 reads the
//! mesh and resolves the scene against it, the others must not hold the
//! mesh, so they wait for its outcome — the result as words, or its error.
use crate::error::{Error, Result};
use mpi::traits::*;

/// Collective: `root`'s outcome on every rank (the others pass `None`).
///
/// On success every rank returns the root's words. On failure the root
/// keeps its own error and every other rank returns [`Error::Relayed`] with
/// the same text, so whichever rank prints prints the line a single-rank
/// run prints (no rank prefix: the failure is not a rank's, it is the
/// input's), and no rank goes on to a collective call the others skip.
pub fn from_root(
    world: &impl Communicator,
    root: usize,
    local: Option<Result<Vec<u64>>>,
) -> Result<Vec<u64>> {
    if world.size() == 1 {
        return local.unwrap_or_else(|| Err(Error::Internal("rank 0 of 1 is not the root".into())));
    }
    let is_root = world.rank() as usize == root;
    let (mut failed, mut words, error) = match local {
        Some(Ok(words)) if is_root => (0u8, words, None),
        Some(Err(e)) if is_root => (1u8, Vec::new(), Some(e)),
        _ => (0u8, Vec::new(), None),
    };
    let at = world.process_at_rank(root as i32);
    at.broadcast_into(&mut failed);
    if failed != 0 {
        let text = error.as_ref().map(ToString::to_string).unwrap_or_default();
        let text = super::broadcast_text(world, root, &text);
        return Err(error.unwrap_or(Error::Relayed(text)));
    }
    let mut len = words.len() as u64;
    at.broadcast_into(&mut len);
    words.resize(len as usize, 0);
    at.broadcast_into(&mut words[..]);
    Ok(words)
}

//! The agreement primitives: one allreduce picks the lowest failing rank,
//! one broadcast hands its message to everybody.
use crate::error::{Error, Result};
use mpi::collective::SystemOperation;
use mpi::traits::*;

/// The failure every rank agreed on: the lowest failing rank, a
/// caller-defined category (e.g. domain error or fatal) and its message.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct RankFailure {
    pub rank: usize,
    pub code: i32,
    pub message: String,
}

/// Collective: the lowest rank whose `flag` is set, the same on every rank.
pub fn lowest_rank(world: &impl Communicator, flag: bool) -> Option<usize> {
    let size = world.size();
    let mine = if flag { world.rank() } else { size };
    let mut lowest = size;
    world.all_reduce_into(&mine, &mut lowest, SystemOperation::min());
    (lowest < size).then_some(lowest as usize)
}

/// Collective: `None` on every rank when no rank failed; otherwise, on
/// every rank, the lowest failing rank's category and message.
pub fn agree_failure(
    world: &impl Communicator,
    local: Option<(i32, String)>,
) -> Option<RankFailure> {
    let rank = lowest_rank(world, local.is_some())?;
    let (mut code, mut bytes) = match local {
        Some((code, message)) if world.rank() as usize == rank => (code, message.into_bytes()),
        _ => (0, Vec::new()),
    };
    world.process_at_rank(rank as i32).broadcast_into(&mut code);
    broadcast_bytes(world, rank, &mut bytes);
    Some(RankFailure {
        rank,
        code,
        message: String::from_utf8_lossy(&bytes).into_owned(),
    })
}

/// Collective: `root`'s text on every rank (the others pass anything).
pub fn broadcast_text(world: &impl Communicator, root: usize, text: &str) -> String {
    let mut bytes = text.as_bytes().to_vec();
    broadcast_bytes(world, root, &mut bytes);
    String::from_utf8_lossy(&bytes).into_owned()
}

fn broadcast_bytes(world: &impl Communicator, root: usize, bytes: &mut Vec<u8>) {
    let root = world.process_at_rank(root as i32);
    let mut len = bytes.len() as u64;
    root.broadcast_into(&mut len);
    bytes.resize(len as usize, 0);
    root.broadcast_into(&mut bytes[..]);
}

/// Collective: a rank-local result made the same on every rank. If any rank
/// failed, every rank returns the lowest failing rank's error naming that
/// rank (one rank alone keeps its error as it is), so no rank goes on to a
/// collective call that the others never reach, and whichever rank prints
/// prints the same line.
pub fn agree<T>(world: &impl Communicator, local: Result<T>) -> Result<T> {
    if world.size() == 1 {
        return local;
    }
    let (value, failure) = match local {
        Ok(v) => (Some(v), None),
        Err(e) => (None, Some((0, e.to_string()))),
    };
    match agree_failure(world, failure) {
        None => value.ok_or_else(|| Error::Internal("agreement lost a value".into())),
        Some(f) => Err(Error::OnRank {
            rank: f.rank,
            message: f.message,
        }),
    }
}

/// Collective: true on every rank if `flag` is true on any.
pub fn any_rank(world: &impl Communicator, flag: bool) -> bool {
    lowest_rank(world, flag).is_some()
}

/// Collective: true on every rank if `flag` is true on all.
pub fn all_ranks(world: &impl Communicator, flag: bool) -> bool {
    !any_rank(world, !flag)
}

/// Collective: element-wise sums over ranks.
pub fn sum<const N: usize>(world: &impl Communicator, local: [f64; N]) -> [f64; N] {
    let mut total = [0.0; N];
    world.all_reduce_into(&local[..], &mut total[..], SystemOperation::sum());
    total
}

/// Collective: element-wise sums of counts over ranks.
pub fn sum_usize<const N: usize>(world: &impl Communicator, local: [usize; N]) -> [usize; N] {
    let mine = local.map(|n| n as u64);
    let mut total = [0u64; N];
    world.all_reduce_into(&mine[..], &mut total[..], SystemOperation::sum());
    total.map(|n| n as usize)
}

/// Collective: element-wise maxima over ranks (NaN-free inputs).
pub fn max<const N: usize>(world: &impl Communicator, local: [f64; N]) -> [f64; N] {
    let mut out = [0.0; N];
    world.all_reduce_into(&local[..], &mut out[..], SystemOperation::max());
    out
}

//! Gathering rank-local arrays onto every rank, or onto rank 0.

use mpi::topology::SimpleCommunicator;
use mpi::traits::{Communicator, CommunicatorCollectives, Root};

/// Concatenates every rank's slice, in rank order, on every rank, when all
/// ranks pass slices of the same length (fingerprints, fixed-width tables).
pub fn gather_equal(world: &impl Communicator, local: &[u64]) -> Vec<u64> {
    let mut all = vec![0_u64; local.len() * world.size() as usize];
    world.all_gather_into(local, &mut all[..]);
    all
}

/// Concatenates every rank's slice, in rank order, on every rank.
pub fn gather_all(world: &SimpleCommunicator, local: &[f64]) -> Vec<f64> {
    use mpi::datatype::PartitionMut;
    let n = local.len() as i32;
    let mut counts = vec![0i32; world.size() as usize];
    world.all_gather_into(&n, &mut counts[..]);
    let displs: Vec<i32> = counts
        .iter()
        .scan(0, |acc, &c| {
            let d = *acc;
            *acc += c;
            Some(d)
        })
        .collect();
    let mut all = vec![0.0; counts.iter().sum::<i32>() as usize];
    let mut partition = PartitionMut::new(&mut all[..], counts, displs);
    world.all_gather_varcount_into(local, &mut partition);
    all
}

/// Concatenates every rank's array, in rank order, on rank 0; the other
/// ranks get an empty array. One rank returns its own array (no copy).
/// Collective.
pub fn gather_root(world: &SimpleCommunicator, local: Vec<f64>) -> Vec<f64> {
    use mpi::datatype::PartitionMut;
    if world.size() == 1 {
        return local;
    }
    let root = world.process_at_rank(0);
    let n = local.len() as i32;
    if world.rank() != 0 {
        root.gather_into(&n);
        root.gather_varcount_into(&local[..]);
        return Vec::new();
    }
    let mut counts = vec![0i32; world.size() as usize];
    root.gather_into_root(&n, &mut counts[..]);
    let displs: Vec<i32> = counts
        .iter()
        .scan(0, |acc, &c| {
            let d = *acc;
            *acc += c;
            Some(d)
        })
        .collect();
    let mut all = vec![0.0; counts.iter().sum::<i32>() as usize];
    let mut partition = PartitionMut::new(&mut all[..], counts, displs);
    root.gather_varcount_into_root(&local[..], &mut partition);
    all
}

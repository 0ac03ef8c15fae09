//! Personalised exchange: every rank sends its own array to every other rank.
//! A leaf: `parallel` re-exports it, and the PETSc layer's pattern builder,
//! which sits below `parallel`, sends rows to their owners with it.

use mpi::datatype::{Equivalence, Partition, PartitionMut};
use mpi::topology::SimpleCommunicator;
use mpi::traits::{Communicator, CommunicatorCollectives};

/// Sends `send[r]` to rank `r` (one array per rank, this rank's own slot
/// included) and returns what every rank sent to this one, concatenated in
/// rank order. Collective.
pub fn all_to_all<T: Equivalence + Copy + Default>(
    world: &SimpleCommunicator,
    send: &[Vec<T>],
) -> Vec<T> {
    let size = world.size() as usize;
    assert_eq!(send.len(), size, "one send array per rank");
    let send_counts: Vec<i32> = send.iter().map(|s| s.len() as i32).collect();
    let mut recv_counts = vec![0i32; size];
    world.all_to_all_into(&send_counts[..], &mut recv_counts[..]);
    let send_flat: Vec<T> = send.concat();
    let mut recv = vec![T::default(); recv_counts.iter().sum::<i32>() as usize];
    let (sd, rd) = (displacements(&send_counts), displacements(&recv_counts));
    let partition = Partition::new(&send_flat[..], send_counts, sd);
    let mut into = PartitionMut::new(&mut recv[..], recv_counts, rd);
    world.all_to_all_varcount_into(&partition, &mut into);
    recv
}

fn displacements(counts: &[i32]) -> Vec<i32> {
    counts
        .iter()
        .scan(0, |acc, &c| {
            let d = *acc;
            *acc += c;
            Some(d)
        })
        .collect()
}

//! Distribution: rank 0 partitions the cells (METIS on the dual graph),
//! numbers the nodes for PETSc and hands every rank its piece — the cells it
//! assembles, the nodes it owns and sees, their PETSc numbers, and the small
//! natural-order blocks it writes — so that no rank below it in the data flow
//! (DOF map, output order, contact multipliers) holds an array of the global
//! node or cell count.
//!
//! The numbering rules live in [`numbering`]: a node belongs to one of the
//! ranks among the cells containing it (the one owning fewer nodes), and
//! PETSc numbers the nodes rank by rank, each rank's in natural order. Pieces travel as flat `u64` words
//! ([`wire`]), one point-to-point message per rank, built and sent one at a
//! time so rank 0 never holds more than one foreign piece.
mod local;
mod numbering;
mod wire;

#[cfg(test)]
mod tests;

pub use local::{
    shortest_edge, GhostFacet, LocalFacet, LocalFacetSet, LocalMesh, OutputBlock, SharedSet,
    SlaveSetPiece,
};
pub use numbering::Numbering;

use crate::error::{Error, Result};
use crate::mesh::Mesh;
use crate::parallel;
use mpi::traits::*;

/// One rank's share of the mesh numbering. Every array is of local size:
/// local cells, local nodes, this rank's output blocks, or a contact surface.
#[derive(Debug, Clone, PartialEq)]
pub struct Piece {
    pub rank: usize,
    pub nranks: usize,
    pub global_nodes: usize,
    pub global_cells: usize,
    /// First PETSc node this rank owns.
    pub owned_node_start: usize,
    /// Number of owned nodes (the first entries of `local_natural`).
    pub n_owned: usize,
    /// Natural ids of the cells this rank assembles, ascending.
    pub local_cells: Vec<usize>,
    /// Natural id of every local node: owned ones first (in PETSc order),
    /// then ghosts (in PETSc order).
    pub local_natural: Vec<usize>,
    /// PETSc node number of every local node.
    pub local_petsc: Vec<u32>,
    /// Local node indices of the local cells, flat, `cell_type.nodes()` per cell.
    pub cell_nodes: Vec<u32>,
    /// PETSc node number of every natural node of this rank's output node
    /// block (`even_block(global_nodes, rank, nranks)`).
    pub block_petsc: Vec<u32>,
    /// Owning rank of every cell of this rank's output cell block.
    pub block_partition: Vec<i32>,
    /// This rank's mesh: local coordinates, cell bodies, facet-set pieces,
    /// the output block's nodes and cells, and the surface-sized sets asked for.
    pub mesh: LocalMesh,
}

/// What, beyond its own cells, each rank's piece must carry.
#[derive(Debug, Clone, Copy, Default)]
pub struct Wanted<'a> {
    /// Natural nodes every rank must see (replicated contact surfaces).
    pub extra_ghosts: &'a [usize],
    /// Contact slave sets: facet owners, mean edge and ghost facets of each.
    pub slave_sets: &'a [String],
}

/// [start, end) of part `rank` when `n` items are split evenly over `nranks`.
pub fn even_block(n: usize, rank: usize, nranks: usize) -> std::ops::Range<usize> {
    let start = n * rank / nranks;
    let end = n * (rank + 1) / nranks;
    start..end
}

/// Collective: partitions `mesh` on rank 0 and returns this rank's piece.
///
/// Only rank 0 reads `mesh` and `wanted`: the other ranks pass an empty
/// mesh in a scene's run (`pipeline::load`), or their own copy.
pub fn distribute(world: &impl Communicator, mesh: &Mesh, wanted: &Wanted) -> Result<Piece> {
    let (rank, size) = (world.rank() as usize, world.size() as usize);
    let part = if rank == 0 {
        // Contact slave facets are balanced over the ranks with the cells.
        let part = crate::partition::partition_cells(mesh, size, wanted.slave_sets);
        if let (Ok(p), true) = (&part, crate::memory::checkpoints_enabled()) {
            let balance = crate::partition::Balance::of(mesh, p, size, wanted.slave_sets);
            eprintln!("{}", balance.line());
        }
        part
    } else {
        Ok(Vec::new())
    };
    let part = parallel::agree(world, part)?;
    crate::memory::checkpoint("partition");
    if size == 1 {
        return Ok(Numbering::new(mesh, &part, 1).piece(mesh, &part, 0, wanted));
    }
    let mine = if rank == 0 {
        let numbering = Numbering::new(mesh, &part, size);
        for r in 1..size {
            let piece = numbering.piece(mesh, &part, r, wanted);
            let words = wire::encode(&piece);
            drop(piece);
            world.process_at_rank(r as i32).send(&words[..]);
        }
        Ok(numbering.piece(mesh, &part, 0, wanted))
    } else {
        let (words, _status) = world.process_at_rank(0).receive_vec::<u64>();
        wire::decode(&words).and_then(|p| check_received(p, rank, size))
    };
    parallel::agree(world, mine)
}

/// A received piece must be addressed to this rank and this rank count.
fn check_received(piece: Piece, rank: usize, size: usize) -> Result<Piece> {
    if piece.rank != rank || piece.nranks != size {
        return Err(Error::Internal(format!(
            "rank {rank} of {size} received the piece of rank {} of {}",
            piece.rank, piece.nranks
        )));
    }
    Ok(piece)
}

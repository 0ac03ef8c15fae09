//! Degrees of freedom: which nodes a rank owns, which it sees as ghosts, and
//! the PETSc (global) number of every DOF.
//!
//! Three numberings meet here, each with its own type so they cannot be mixed:
//! - [`NaturalNode`]: the input (mesh file / generator) node id, used in output;
//! - [`LocalNode`]: index into this rank's owned-then-ghost node arrays;
//! - [`GlobalDof`]: PETSc row/column, 3·(PETSc node) + component, contiguous per rank.
pub use crate::distribution::even_block;
use crate::distribution::{LocalMesh, Numbering, Piece, Wanted};
use crate::mesh::Mesh;
use crate::petsc::PetscInt;
use std::collections::HashMap;

pub const DIM: usize = 3;

#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub struct NaturalNode(pub usize);

#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub struct LocalNode(pub usize);

#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub struct GlobalDof(pub PetscInt);

/// This rank's view of the node and DOF numbering. Every array is of local
/// size (local nodes, local cells, this rank's output block): the global
/// numbering exists only on the rank that cut the pieces
/// (`crate::distribution`).
#[derive(Debug, Clone)]
pub struct DofMap {
    pub rank: usize,
    pub nranks: usize,
    /// Natural ids of the cells this rank assembles, ascending.
    pub local_cells: Vec<usize>,
    /// Natural id of every local node: owned ones first (in PETSc order), then ghosts.
    local_natural: Vec<usize>,
    /// PETSc node number of every local node.
    local_petsc: Vec<u32>,
    n_owned: usize,
    /// Local index of every local node, keyed by natural id.
    local_of_natural: HashMap<usize, u32>,
    /// Local node indices of the local cells, flat, cell_type.nodes() per cell.
    cell_nodes: Vec<u32>,
    owned_node_start: usize,
    global_nodes: usize,
    /// PETSc node number of each natural node of this rank's output block.
    block_petsc: Vec<u32>,
}

impl DofMap {
    /// Builds the numbering from the global mesh and the cell partition, on
    /// one process (tests, benchmarks, code-built models); the parallel set-up
    /// uses [`DofMap::from_piece`] with the piece rank 0 sent. A node belongs
    /// to the lowest rank among the cells that contain it, and PETSc numbers
    /// the nodes rank by rank, each rank's in natural order, so the numbering
    /// is the same whatever the process that computes it.
    ///
    /// `extra_ghosts` are further nodes this rank must see (master contact
    /// surfaces, whose current position every rank's search needs).
    pub fn new(
        mesh: &Mesh,
        partition: &[i32],
        rank: usize,
        nranks: usize,
        extra_ghosts: &[usize],
    ) -> Self {
        let wanted = Wanted {
            extra_ghosts,
            ..Wanted::default()
        };
        Self::with_mesh(mesh, partition, rank, nranks, &wanted).0
    }

    /// [`DofMap::new`] with the rank's local mesh, cut from the global one on
    /// this process (tests, benchmarks, code-built models).
    pub fn with_mesh(
        mesh: &Mesh,
        partition: &[i32],
        rank: usize,
        nranks: usize,
        wanted: &Wanted,
    ) -> (Self, LocalMesh) {
        let numbering = Numbering::new(mesh, partition, nranks);
        Self::from_piece(numbering.piece(mesh, partition, rank, wanted))
    }

    /// This rank's numbering and local mesh from its piece (local-size
    /// arrays only).
    pub fn from_piece(piece: Piece) -> (Self, LocalMesh) {
        let local_of_natural = piece
            .local_natural
            .iter()
            .enumerate()
            .map(|(l, &nat)| (nat, l as u32))
            .collect();
        let dofs = DofMap {
            rank: piece.rank,
            nranks: piece.nranks,
            local_cells: piece.local_cells,
            local_natural: piece.local_natural,
            local_petsc: piece.local_petsc,
            n_owned: piece.n_owned,
            local_of_natural,
            cell_nodes: piece.cell_nodes,
            owned_node_start: piece.owned_node_start,
            global_nodes: piece.global_nodes,
            block_petsc: piece.block_petsc,
        };
        (dofs, piece.mesh)
    }

    pub fn num_owned_nodes(&self) -> usize {
        self.n_owned
    }

    pub fn num_local_nodes(&self) -> usize {
        self.local_natural.len()
    }

    pub fn num_global_nodes(&self) -> usize {
        self.global_nodes
    }

    pub fn num_owned_dofs(&self) -> usize {
        DIM * self.n_owned
    }

    /// First PETSc DOF this rank owns.
    pub fn owned_dof_start(&self) -> usize {
        DIM * self.owned_node_start
    }

    pub fn natural(&self, l: LocalNode) -> NaturalNode {
        NaturalNode(self.local_natural[l.0])
    }

    pub fn local(&self, nat: NaturalNode) -> Option<LocalNode> {
        self.local_of_natural
            .get(&nat.0)
            .map(|&l| LocalNode(l as usize))
    }

    /// Whether this rank assembles natural cell `c` (binary search: the
    /// local cells are ascending).
    pub fn is_local_cell(&self, c: usize) -> bool {
        self.local_cells.binary_search(&c).is_ok()
    }

    pub fn is_owned(&self, l: LocalNode) -> bool {
        l.0 < self.n_owned
    }

    pub fn dof(&self, l: LocalNode, c: usize) -> GlobalDof {
        GlobalDof((DIM * self.local_petsc[l.0] as usize + c) as PetscInt)
    }

    /// Local nodes of the i-th local cell.
    pub fn cell_local_nodes(&self, i: usize, nodes_per_cell: usize) -> &[u32] {
        &self.cell_nodes[i * nodes_per_cell..(i + 1) * nodes_per_cell]
    }

    /// Global DOFs of the ghost entries, in local order (for VecCreateGhost).
    pub fn ghost_dofs(&self) -> Vec<PetscInt> {
        self.local_petsc[self.n_owned..]
            .iter()
            .flat_map(|&p| (0..DIM).map(move |c| (DIM * p as usize + c) as PetscInt))
            .collect()
    }

    /// PETSc node number of each natural node of this rank's output block
    /// ([`DofMap::output_node_block`]), in natural order.
    pub fn output_block_petsc(&self) -> &[u32] {
        &self.block_petsc
    }

    /// The contiguous block of natural node ids this rank writes to the output
    /// file: nodes are split evenly in input order, whatever the partition.
    pub fn output_node_block(&self) -> std::ops::Range<usize> {
        even_block(self.global_nodes, self.rank, self.nranks)
    }
}

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

/// Stored as `u32` (local node counts fit: the numbering stores them so),
/// `repr(transparent)` so that connectivity arrays of it are plain `u32`s.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Hash)]
#[repr(transparent)]
pub struct LocalNode(pub u32);

#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub struct GlobalDof(pub PetscInt);

impl LocalNode {
    /// The node a compact local-node array entry (`u32`) names: element
    /// connectivity, facet nodes and surface node lists store local nodes so.
    pub fn from_u32(l: u32) -> Self {
        LocalNode(l)
    }

    /// The node at position `i` of the rank's local node arrays.
    pub fn from_index(i: usize) -> Self {
        LocalNode(i as u32)
    }

    /// Position in the rank's local node arrays (owned then ghosts).
    pub fn index(self) -> usize {
        self.0 as usize
    }

    /// The compact form stored in local-node arrays.
    pub fn to_u32(self) -> u32 {
        self.0
    }

    /// Index of component `c` of this node in a local-form (ghosted) array,
    /// node-major with [`DIM`] entries per node.
    pub fn vec_index(self, c: usize) -> usize {
        DIM * self.index() + c
    }

    /// This node's [`DIM`] entries of a local-form array.
    pub fn value(self, local: &[f64]) -> [f64; 3] {
        let b = self.vec_index(0);
        [local[b], local[b + 1], local[b + 2]]
    }
}

impl From<u32> for LocalNode {
    fn from(l: u32) -> Self {
        LocalNode::from_u32(l)
    }
}

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
    cell_nodes: Vec<LocalNode>,
    owned_node_start: usize,
    global_nodes: usize,
    /// PETSc node number of each natural node of this rank's output block.
    block_petsc: Vec<u32>,
}

impl DofMap {
    /// Builds the numbering from the global mesh and the cell partition, on
    /// one process (tests, benchmarks, code-built models); the parallel set-up
    /// uses [`DofMap::from_piece`] with the piece rank 0 sent. A node belongs
    /// to one of the ranks among the cells that contain it (the one with
    /// fewer owned nodes, `distribution::numbering`), and PETSc numbers
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
            cell_nodes: piece.cell_nodes.into_iter().map(LocalNode).collect(),
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
        NaturalNode(self.local_natural[l.index()])
    }

    pub fn local(&self, nat: NaturalNode) -> Option<LocalNode> {
        self.local_of_natural
            .get(&nat.0)
            .map(|&l| LocalNode::from_u32(l))
    }

    /// Whether this rank assembles natural cell `c` (binary search: the
    /// local cells are ascending).
    pub fn is_local_cell(&self, c: usize) -> bool {
        self.local_cells.binary_search(&c).is_ok()
    }

    pub fn is_owned(&self, l: LocalNode) -> bool {
        l.index() < self.n_owned
    }

    pub fn dof(&self, l: LocalNode, c: usize) -> GlobalDof {
        GlobalDof(petsc_dof(self.local_petsc[l.index()], c))
    }

    /// The [`DIM`] global DOFs of local node `l`, by component.
    pub fn node_dofs(&self, l: LocalNode) -> [GlobalDof; DIM] {
        std::array::from_fn(|c| self.dof(l, c))
    }

    /// Local nodes of the i-th local cell.
    pub fn cell_local_nodes(&self, i: usize, nodes_per_cell: usize) -> &[LocalNode] {
        &self.cell_nodes[i * nodes_per_cell..(i + 1) * nodes_per_cell]
    }

    /// Global DOFs of the ghost entries, in local order (for VecCreateGhost).
    pub fn ghost_dofs(&self) -> Vec<PetscInt> {
        self.local_petsc[self.n_owned..]
            .iter()
            .flat_map(|&p| (0..DIM).map(move |c| petsc_dof(p, c)))
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

/// PETSc DOF of component `c` of PETSc node `p`.
fn petsc_dof(p: u32, c: usize) -> PetscInt {
    (DIM * p as usize + c) as PetscInt
}

//! Degrees of freedom: which nodes a rank owns, which it sees as ghosts, and
//! the PETSc (global) number of every DOF.
//!
//! Three numberings meet here, each with its own type so they cannot be mixed:
//! - [`NaturalNode`]: the input (mesh file / generator) node id, used in output;
//! - [`LocalNode`]: index into this rank's owned-then-ghost node arrays;
//! - [`GlobalDof`]: PETSc row/column, 3·(PETSc node) + component, contiguous per rank.
use crate::mesh::Mesh;
use crate::petsc::PetscInt;

pub const DIM: usize = 3;

#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub struct NaturalNode(pub usize);

#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub struct LocalNode(pub usize);

#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub struct GlobalDof(pub PetscInt);

const NOT_LOCAL: u32 = u32::MAX;

/// This rank's view of the node and DOF numbering.
#[derive(Debug, Clone)]
pub struct DofMap {
    pub rank: usize,
    pub nranks: usize,
    /// Natural ids of the cells this rank assembles.
    pub local_cells: Vec<usize>,
    /// Natural id of every local node: owned ones first (in PETSc order), then ghosts.
    local_natural: Vec<usize>,
    n_owned: usize,
    /// PETSc node number of every natural node (known on every rank; it is what
    /// maps the output back to input order).
    petsc_node: Vec<u32>,
    /// Local index of every natural node, NOT_LOCAL when this rank does not see it.
    local_of_natural: Vec<u32>,
    /// Local node indices of the local cells, flat, cell_type.nodes() per cell.
    cell_nodes: Vec<u32>,
    owned_node_start: usize,
    global_nodes: usize,
}

impl DofMap {
    /// Builds the numbering from the global mesh and the cell partition.
    /// A node belongs to the lowest rank among the cells that contain it, and
    /// PETSc numbers the nodes rank by rank, each rank's in natural order, so
    /// the numbering is the same whatever the process that computes it.
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
        let n = mesh.num_nodes();
        let node_owner = node_owners(mesh, partition);
        let mut count_per_rank = vec![0usize; nranks];
        for &o in &node_owner {
            count_per_rank[o as usize] += 1;
        }
        let mut next = vec![0usize; nranks];
        let mut acc = 0;
        for r in 0..nranks {
            next[r] = acc;
            acc += count_per_rank[r];
        }
        let owned_node_start = next[rank];
        let mut petsc_node = vec![0u32; n];
        for (nat, &o) in node_owner.iter().enumerate() {
            petsc_node[nat] = next[o as usize] as u32;
            next[o as usize] += 1;
        }
        let local_cells: Vec<usize> = (0..mesh.num_cells())
            .filter(|&c| partition[c] as usize == rank)
            .collect();
        let mut local_natural: Vec<usize> =
            (0..n).filter(|&v| node_owner[v] as usize == rank).collect();
        let n_owned = local_natural.len();
        let mut ghosts: Vec<usize> = local_cells
            .iter()
            .flat_map(|&c| mesh.cell(c).iter().copied())
            .chain(extra_ghosts.iter().copied())
            .filter(|&v| node_owner[v] as usize != rank)
            .collect();
        ghosts.sort_unstable_by_key(|&v| petsc_node[v]);
        ghosts.dedup();
        local_natural.extend(ghosts);
        let mut local_of_natural = vec![NOT_LOCAL; n];
        for (l, &nat) in local_natural.iter().enumerate() {
            local_of_natural[nat] = l as u32;
        }
        let cell_nodes = local_cells
            .iter()
            .flat_map(|&c| mesh.cell(c).iter().map(|&v| local_of_natural[v]))
            .collect();
        DofMap {
            rank,
            nranks,
            local_cells,
            local_natural,
            n_owned,
            petsc_node,
            local_of_natural,
            cell_nodes,
            owned_node_start,
            global_nodes: n,
        }
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
        match self.local_of_natural.get(nat.0) {
            Some(&l) if l != NOT_LOCAL => Some(LocalNode(l as usize)),
            _ => None,
        }
    }

    pub fn is_owned(&self, l: LocalNode) -> bool {
        l.0 < self.n_owned
    }

    /// PETSc DOF of component `c` of a natural node (any node, local or not).
    pub fn dof_of_natural(&self, nat: NaturalNode, c: usize) -> GlobalDof {
        GlobalDof((DIM * self.petsc_node[nat.0] as usize + c) as PetscInt)
    }

    pub fn dof(&self, l: LocalNode, c: usize) -> GlobalDof {
        self.dof_of_natural(self.natural(l), c)
    }

    /// Local nodes of the i-th local cell.
    pub fn cell_local_nodes(&self, i: usize, nodes_per_cell: usize) -> &[u32] {
        &self.cell_nodes[i * nodes_per_cell..(i + 1) * nodes_per_cell]
    }

    /// Global DOFs of the ghost entries, in local order (for VecCreateGhost).
    pub fn ghost_dofs(&self) -> Vec<PetscInt> {
        self.local_natural[self.n_owned..]
            .iter()
            .flat_map(|&nat| {
                (0..DIM).map(move |c| (DIM * self.petsc_node[nat] as usize + c) as PetscInt)
            })
            .collect()
    }

    /// PETSc node number of a natural node.
    pub fn petsc_node(&self, nat: NaturalNode) -> usize {
        self.petsc_node[nat.0] as usize
    }

    /// The contiguous block of natural node ids this rank writes to the output
    /// file: nodes are split evenly in input order, whatever the partition.
    pub fn output_node_block(&self) -> std::ops::Range<usize> {
        even_block(self.global_nodes, self.rank, self.nranks)
    }
}

/// [start, end) of part `rank` when `n` items are split evenly over `nranks`.
pub fn even_block(n: usize, rank: usize, nranks: usize) -> std::ops::Range<usize> {
    let start = n * rank / nranks;
    let end = n * (rank + 1) / nranks;
    start..end
}

/// The owner of every node: the lowest rank among the cells containing it.
/// Nodes in no cell go to rank 0 (they carry no stiffness and are caught by
/// mesh validation, but they must still be numbered).
fn node_owners(mesh: &Mesh, partition: &[i32]) -> Vec<i32> {
    let mut owner = vec![i32::MAX; mesh.num_nodes()];
    for (c, &p) in partition.iter().enumerate().take(mesh.num_cells()) {
        for &v in mesh.cell(c) {
            owner[v] = owner[v].min(p);
        }
    }
    for o in &mut owner {
        if *o == i32::MAX {
            *o = 0;
        }
    }
    owner
}

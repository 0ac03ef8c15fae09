//! The global numbering, computed once on the rank that holds the mesh:
//! node owners and PETSc node numbers (two arrays of the node count), from
//! which each rank's [`Piece`] is cut.
use super::{even_block, Piece};
use crate::mesh::Mesh;

/// Node owners and PETSc numbers of a partitioned mesh. O(N) memory; it
/// lives only while pieces are cut.
#[derive(Debug, Clone)]
pub struct Numbering {
    nranks: usize,
    node_owner: Vec<i32>,
    petsc_node: Vec<u32>,
    /// First PETSc node of each rank.
    rank_start: Vec<usize>,
}

impl Numbering {
    /// A node belongs to the lowest rank among the cells that contain it, and
    /// PETSc numbers the nodes rank by rank, each rank's in natural order, so
    /// the numbering is the same whatever the process that computes it.
    pub fn new(mesh: &Mesh, partition: &[i32], nranks: usize) -> Self {
        let node_owner = node_owners(mesh, partition);
        let mut count_per_rank = vec![0usize; nranks];
        for &o in &node_owner {
            count_per_rank[o as usize] += 1;
        }
        let mut rank_start = vec![0usize; nranks];
        let mut acc = 0;
        for r in 0..nranks {
            rank_start[r] = acc;
            acc += count_per_rank[r];
        }
        let mut next = rank_start.clone();
        let mut petsc_node = vec![0u32; node_owner.len()];
        for (nat, &o) in node_owner.iter().enumerate() {
            petsc_node[nat] = next[o as usize] as u32;
            next[o as usize] += 1;
        }
        Numbering {
            nranks,
            node_owner,
            petsc_node,
            rank_start,
        }
    }

    /// PETSc node number of a natural node.
    pub fn petsc_node(&self, natural: usize) -> usize {
        self.petsc_node[natural] as usize
    }

    /// The piece of rank `rank`; see [`super::distribute`] for the arguments.
    pub fn piece(
        &self,
        mesh: &Mesh,
        partition: &[i32],
        rank: usize,
        extra_ghosts: &[usize],
        owner_sets: &[String],
    ) -> Piece {
        let n = self.node_owner.len();
        let local_cells: Vec<usize> = (0..mesh.num_cells())
            .filter(|&c| partition[c] as usize == rank)
            .collect();
        let owned = |v: usize| self.node_owner[v] as usize == rank;
        let mut local_natural: Vec<usize> = (0..n).filter(|&v| owned(v)).collect();
        let n_owned = local_natural.len();
        let mut ghosts: Vec<usize> = local_cells
            .iter()
            .flat_map(|&c| mesh.cell(c).iter().copied())
            .chain(extra_ghosts.iter().copied())
            .filter(|&v| !owned(v))
            .collect();
        ghosts.sort_unstable_by_key(|&v| self.petsc_node[v]);
        ghosts.dedup();
        local_natural.extend(ghosts);
        let local_petsc: Vec<u32> = local_natural.iter().map(|&v| self.petsc_node[v]).collect();
        let cell_nodes = local_cell_nodes(mesh, &local_cells, &local_natural);
        let node_block = even_block(n, rank, self.nranks);
        let cell_block = even_block(mesh.num_cells(), rank, self.nranks);
        let facet_owners = owner_sets
            .iter()
            .map(|set| {
                mesh.facet_sets
                    .get(set)
                    .map(|fs| fs.iter().map(|f| partition[f.cell]).collect())
                    .unwrap_or_default()
            })
            .collect();
        Piece {
            rank,
            nranks: self.nranks,
            global_nodes: n,
            global_cells: mesh.num_cells(),
            owned_node_start: self.rank_start[rank],
            n_owned,
            local_cells,
            local_natural,
            local_petsc,
            cell_nodes,
            block_petsc: self.petsc_node[node_block].to_vec(),
            block_partition: partition[cell_block].to_vec(),
            facet_owners,
        }
    }
}

/// Local indices of the local cells' nodes, by binary search in a
/// natural-sorted copy of the local nodes (local size, no O(N) lookup table).
fn local_cell_nodes(mesh: &Mesh, local_cells: &[usize], local_natural: &[usize]) -> Vec<u32> {
    let mut by_natural: Vec<(usize, u32)> = local_natural
        .iter()
        .enumerate()
        .map(|(l, &v)| (v, l as u32))
        .collect();
    by_natural.sort_unstable();
    local_cells
        .iter()
        .flat_map(|&c| mesh.cell(c).iter())
        .map(|v| {
            let i = by_natural.partition_point(|&(nat, _)| nat < *v);
            by_natural[i].1
        })
        .collect()
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

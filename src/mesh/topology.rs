//! Face adjacency: shared faces, boundary facets and the cell dual graph.

use std::collections::HashMap;

use super::{FacetRef, Mesh, MeshError};

/// Orientation-free identity of a face: its corner ids sorted, padded with
/// `usize::MAX` for triangles. Two cells share a face iff their keys agree
/// (the corners fix a face; a second-order face's other nodes follow).
/// Callers pass the corners only ([`FacetType::corners`]); extra ids are
/// ignored beyond the fourth.
pub(crate) type FaceKey = [usize; 4];

pub(crate) fn face_key(nodes: impl Iterator<Item = usize>) -> FaceKey {
    let mut key = [usize::MAX; 4];
    for (slot, n) in key.iter_mut().zip(nodes) {
        *slot = n;
    }
    key.sort_unstable();
    key
}

/// Compressed sparse row adjacency (`xadj`, `adjncy`) as METIS expects it.
pub type Csr = (Vec<usize>, Vec<usize>);

impl Mesh {
    /// Every local face of every cell, grouped by face key.
    pub(crate) fn faces_by_key(&self) -> HashMap<FaceKey, Vec<FacetRef>> {
        let faces = self.cell_type.local_faces();
        let corners: Vec<usize> = (0..faces.len())
            .map(|f| self.cell_type.face_type(f).corners())
            .collect();
        let mut map: HashMap<FaceKey, Vec<FacetRef>> = HashMap::new();
        for (cell, ids) in self.cells_iter().enumerate() {
            for (face, local) in faces.iter().enumerate() {
                let key = face_key(local[..corners[face]].iter().map(|&l| ids[l]));
                // Face counts are 4 or 6, so the cast cannot truncate.
                map.entry(key).or_default().push(FacetRef {
                    cell,
                    face: face as u8,
                });
            }
        }
        map
    }

    /// Faces that belong to exactly one cell, sorted by (cell, face). For a
    /// conforming mesh these are the body surfaces.
    pub fn boundary_facets(&self) -> Vec<FacetRef> {
        let mut boundary: Vec<FacetRef> = self.boundary_faces_by_key().into_values().collect();
        boundary.sort_unstable();
        boundary
    }

    /// Faces owned by exactly one cell, by face key: what a reader matches
    /// the surface elements of a file against. Interior faces are left out:
    /// a contact or load surface must be on the outside of a body.
    pub(crate) fn boundary_faces_by_key(&self) -> HashMap<FaceKey, FacetRef> {
        self.faces_by_key()
            .into_iter()
            .filter_map(|(key, owners)| match owners.as_slice() {
                [only] => Some((key, *only)),
                _ => None,
            })
            .collect()
    }

    /// Cell dual graph for graph partitioning: cells `a` and `b` are
    /// neighbours when they share at least `min_shared_nodes` nodes.
    ///
    /// With `min_shared_nodes` equal to the facet node count of a cell type
    /// with one facet type (4 for hex8, 3 for tet4, 6 for tet10, ...) this
    /// is face adjacency, built from a hash map of face keys in O(cells).
    /// Other values use node→cell incidence, still without comparing all
    /// pairs. Neighbour lists are sorted.
    pub fn dual_graph(&self, min_shared_nodes: usize) -> Result<Csr, MeshError> {
        let per_cell = self.cell_type.nodes();
        if min_shared_nodes == 0 || min_shared_nodes > per_cell {
            return Err(MeshError::InvalidArgument {
                operation: "dual_graph",
                argument: "min_shared_nodes",
                reason: format!(
                    "must be in 1..={per_cell} for {} cells (got {min_shared_nodes})",
                    self.cell_type.name()
                ),
            });
        }
        let face_nodes = self.cell_type.single_facet_type().map(|f| f.nodes());
        let neighbours = if Some(min_shared_nodes) == face_nodes {
            self.face_neighbours()
        } else {
            self.node_sharing_neighbours(min_shared_nodes)?
        };
        Ok(to_csr(neighbours))
    }

    /// Face-adjacency dual graph (the usual input of METIS).
    pub fn face_dual_graph(&self) -> Csr {
        to_csr(self.face_neighbours())
    }

    fn face_neighbours(&self) -> Vec<Vec<usize>> {
        let mut neighbours = vec![Vec::new(); self.num_cells()];
        for owners in self.faces_by_key().into_values() {
            for (i, a) in owners.iter().enumerate() {
                for b in &owners[i + 1..] {
                    if a.cell != b.cell {
                        neighbours[a.cell].push(b.cell);
                        neighbours[b.cell].push(a.cell);
                    }
                }
            }
        }
        neighbours
    }

    /// Counts, for each cell, how many nodes it shares with each cell that
    /// touches one of its nodes.
    fn node_sharing_neighbours(&self, min_shared: usize) -> Result<Vec<Vec<usize>>, MeshError> {
        let node_cells = self.node_to_cells()?;
        let mut shared = vec![0usize; self.num_cells()];
        let mut touched = Vec::new();
        let mut neighbours = vec![Vec::new(); self.num_cells()];
        for (cell, ids) in self.cells_iter().enumerate() {
            for &n in ids {
                for &other in &node_cells[n] {
                    if other != cell {
                        if shared[other] == 0 {
                            touched.push(other);
                        }
                        shared[other] += 1;
                    }
                }
            }
            for &other in &touched {
                if shared[other] >= min_shared {
                    neighbours[cell].push(other);
                }
                shared[other] = 0;
            }
            touched.clear();
        }
        Ok(neighbours)
    }

    /// Cells incident to each node (each cell once per node).
    pub(crate) fn node_to_cells(&self) -> Result<Vec<Vec<usize>>, MeshError> {
        let mut node_cells = vec![Vec::new(); self.num_nodes()];
        for (cell, ids) in self.cells_iter().enumerate() {
            for &n in ids {
                let list = node_cells.get_mut(n).ok_or(MeshError::NodeOutOfRange {
                    cell,
                    node: n,
                    num_nodes: self.num_nodes(),
                })?;
                if list.last() != Some(&cell) {
                    list.push(cell);
                }
            }
        }
        Ok(node_cells)
    }
}

fn to_csr(mut neighbours: Vec<Vec<usize>>) -> Csr {
    let mut xadj = Vec::with_capacity(neighbours.len() + 1);
    let mut adjncy = Vec::new();
    xadj.push(0);
    for list in &mut neighbours {
        list.sort_unstable();
        list.dedup();
        adjncy.extend_from_slice(list);
        xadj.push(adjncy.len());
    }
    (xadj, adjncy)
}

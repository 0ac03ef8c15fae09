//! Meshes of any cell type from a hex8 mesh: the splits (tets, wedges,
//! pyramids) and the second-order nodes (mid-edges, face and cell centres).

use std::collections::{BTreeMap, HashMap};

use super::{CellType, Mesh, MeshError};

/// Node key of a higher node: the sorted global ids of the corners it is
/// the mean of (two for an edge, four for a face, all for a cell centre,
/// which no other cell shares).
type HigherKey = Vec<usize>;

impl Mesh {
    /// This hex8 mesh as a mesh of `cell_type`: split into tets
    /// ([`Mesh::hex_to_tets`]), wedges ([`Mesh::hex_to_wedges`]) or
    /// pyramids ([`Mesh::hex_to_pyramids`]), then given second-order nodes
    /// when the type has them ([`Mesh::with_higher_nodes`]).
    pub fn hex_to(&self, cell_type: CellType) -> Result<Mesh, MeshError> {
        let linear = match cell_type.linear() {
            CellType::Tet4 => self.hex_to_tets()?,
            CellType::Wedge6 => self.hex_to_wedges()?,
            CellType::Pyramid5 => self.hex_to_pyramids()?,
            _ => {
                self.require(CellType::Hex8, "hex_to")?;
                self.clone()
            }
        };
        if cell_type.order() == 1 {
            Ok(linear)
        } else {
            linear.with_higher_nodes(cell_type)
        }
    }

    pub(crate) fn require(&self, cell: CellType, operation: &'static str) -> Result<(), MeshError> {
        if self.cell_type == cell {
            Ok(())
        } else {
            Err(MeshError::CellTypeMismatch {
                operation,
                expected: cell.name(),
                found: self.cell_type.name(),
            })
        }
    }

    /// This first-order mesh as one of the second-order `cell_type` on the
    /// same corners: every higher node ([`CellType::higher_nodes`]) at the
    /// mean of its corners, shared by the cells that share those corners
    /// (an edge's, a face's). Straight edges and flat faces: the geometry
    /// stays the first-order one, the interpolation gains an order.
    ///
    /// Facet sets keep their (cell, face) entries; a node set named like a
    /// facet set becomes that set's nodes, the others gain each new node
    /// whose corners all belong to them (the mid-edge nodes of a line of
    /// axis nodes).
    pub fn with_higher_nodes(&self, cell_type: CellType) -> Result<Mesh, MeshError> {
        self.require(cell_type.linear(), "with_higher_nodes")?;
        let corners = cell_type.corners();
        let higher = cell_type.higher_nodes();
        let mut out = Mesh::empty(cell_type);
        out.nodes = self.nodes.clone();
        out.bodies = self.bodies.clone();
        out.cell_body = self.cell_body.clone();
        out.facet_sets = self.facet_sets.clone();
        out.cells.reserve(self.num_cells() * cell_type.nodes());
        let mut made: HashMap<HigherKey, usize> = HashMap::new();
        let mut keys: Vec<HigherKey> = Vec::new();
        for ids in self.cells_iter() {
            out.cells.extend_from_slice(&ids[..corners]);
            for of in higher {
                let mut key: HigherKey = of.iter().map(|&a| ids[a]).collect();
                key.sort_unstable();
                let shared = key.len() < corners;
                let id = match made.get(&key) {
                    Some(&id) if shared => id,
                    _ => {
                        let id = out.nodes.len();
                        let mut x = [0.0; 3];
                        for &v in &key {
                            for (xi, vi) in x.iter_mut().zip(self.nodes[v]) {
                                *xi += vi / key.len() as f64;
                            }
                        }
                        out.nodes.push(x);
                        if shared {
                            made.insert(key.clone(), id);
                        }
                        keys.push(key);
                        id
                    }
                };
                out.cells.push(id);
            }
        }
        out.node_sets = self.higher_node_sets(&out, &keys)?;
        Ok(out)
    }

    /// The node sets of `out` (this mesh with the higher nodes `keys`
    /// appended after its own nodes).
    fn higher_node_sets(
        &self,
        out: &Mesh,
        keys: &[HigherKey],
    ) -> Result<BTreeMap<String, Vec<usize>>, MeshError> {
        let first = self.nodes.len();
        let mut sets = BTreeMap::new();
        for (name, nodes) in &self.node_sets {
            let set = if out.facet_sets.contains_key(name) {
                out.facet_set_nodes(name)?
            } else {
                let mut set = nodes.clone();
                set.extend(
                    keys.iter()
                        .enumerate()
                        .filter(|(_, key)| key.iter().all(|v| nodes.binary_search(v).is_ok()))
                        .map(|(k, _)| first + k),
                );
                set
            };
            sets.insert(name.clone(), set);
        }
        Ok(sets)
    }
}

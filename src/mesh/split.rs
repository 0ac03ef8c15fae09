//! Conforming subdivisions of a hex mesh into wedges and pyramids (the
//! tets are [`super::tets`]'), and the facet sets carried over to the
//! children.

use super::{CellType, FacetRef, Mesh, MeshError};

/// Hex8 face lists as pyramid bases: the pyramid on hex face `f` has the
/// face's corners in reverse (inward) order, so its base normal points at
/// the apex, the hex's centre.
fn pyramid_on_face(face: &[usize], ids: &[usize], centre: usize) -> [usize; 5] {
    [
        ids[face[0]],
        ids[face[3]],
        ids[face[2]],
        ids[face[1]],
        centre,
    ]
}

impl Mesh {
    /// Splits every hex into two wedges along the diagonal plane through
    /// its edges (0,4) and (2,6): the triangles lie in the hex's `ζ = ±1`
    /// faces, the quadrilaterals in its other four. Neighbours agree on the
    /// cut of a shared `ζ` face when their local axes agree, as in the
    /// structured blocks of the box generator; a mesh whose do not is
    /// refused ([`MeshError::InvalidArgument`]), since its wedges would not
    /// conform.
    pub fn hex_to_wedges(&self) -> Result<Mesh, MeshError> {
        self.require(CellType::Hex8, "hex_to_wedges")?;
        let mut out = self.children(CellType::Wedge6);
        let mut first_child = Vec::with_capacity(self.num_cells() + 1);
        for (c, ids) in self.cells_iter().enumerate() {
            first_child.push(out.num_cells());
            let body = self.cell_body.get(c).copied().unwrap_or(0);
            for w in [[0, 1, 2, 4, 5, 6], [0, 2, 3, 4, 6, 7]] {
                out.cells.extend(w.iter().map(|&k| ids[k]));
                out.cell_body.push(body);
            }
        }
        first_child.push(out.num_cells());
        out.facet_sets = self.children_facet_sets(&out, &first_child)?;
        let hex_boundary = self.boundary_facets().len();
        let child_boundary = out.boundary_facets();
        // Each boundary quad of the hexes is one wedge quad or two wedge
        // triangles; a split that does not conform leaves unmatched
        // triangles inside as well.
        let expected: usize = self
            .boundary_facets()
            .iter()
            .map(|f| if f.face >= 4 { 2 } else { 1 })
            .sum();
        if child_boundary.len() != expected {
            return Err(MeshError::InvalidArgument {
                operation: "hex_to_wedges",
                argument: "mesh",
                reason: format!(
                    "the hexes' local axes disagree across shared faces ({} boundary faces for {hex_boundary} boundary quads): the wedge split needs the structured orientation of the box generator",
                    child_boundary.len()
                ),
            });
        }
        Ok(out)
    }

    /// Splits every hex into six pyramids on its faces with their apex at
    /// a new node at the hex's centre (the mean of its corners). Conforming
    /// on any hex mesh: the hex faces stay whole, as pyramid bases.
    pub fn hex_to_pyramids(&self) -> Result<Mesh, MeshError> {
        self.require(CellType::Hex8, "hex_to_pyramids")?;
        let mut out = self.children(CellType::Pyramid5);
        let mut first_child = Vec::with_capacity(self.num_cells() + 1);
        for (c, ids) in self.cells_iter().enumerate() {
            first_child.push(out.num_cells());
            let body = self.cell_body.get(c).copied().unwrap_or(0);
            let centre = out.nodes.len();
            let mut x = [0.0; 3];
            for &v in ids {
                for (xi, vi) in x.iter_mut().zip(self.nodes[v]) {
                    *xi += vi / 8.0;
                }
            }
            out.nodes.push(x);
            for face in CellType::Hex8.local_faces() {
                out.cells.extend(pyramid_on_face(face, ids, centre));
                out.cell_body.push(body);
            }
        }
        first_child.push(out.num_cells());
        out.facet_sets = self.children_facet_sets(&out, &first_child)?;
        Ok(out)
    }

    /// An empty mesh of `cell_type` with this mesh's nodes, bodies and node
    /// sets, to split the cells into.
    pub(crate) fn children(&self, cell_type: CellType) -> Mesh {
        let mut out = Mesh::empty(cell_type);
        out.nodes = self.nodes.clone();
        out.bodies = self.bodies.clone();
        out.node_sets = self.node_sets.clone();
        out
    }

    /// Every facet set mapped onto the children (`first_child[c]..
    /// first_child[c + 1]` are the cells of parent `c`).
    pub(crate) fn children_facet_sets(
        &self,
        children: &Mesh,
        first_child: &[usize],
    ) -> Result<std::collections::BTreeMap<String, Vec<FacetRef>>, MeshError> {
        self.facet_sets
            .iter()
            .map(|(name, facets)| {
                let mapped = self.map_facets_to_children(name, facets, children, first_child)?;
                Ok((name.clone(), mapped))
            })
            .collect()
    }

    /// The faces of the children of each parent facet that lie on it: those
    /// whose corners are all nodes of the parent face.
    pub(crate) fn map_facets_to_children(
        &self,
        name: &str,
        facets: &[FacetRef],
        children: &Mesh,
        first_child: &[usize],
    ) -> Result<Vec<FacetRef>, MeshError> {
        let child_type = children.cell_type;
        let faces = child_type.local_faces();
        let mut mapped = Vec::with_capacity(2 * facets.len());
        for f in facets {
            let parent = self
                .facet_nodes(f)
                .map_err(|e| super::name_facet_error(e, name))?;
            for t in first_child[f.cell]..first_child[f.cell + 1] {
                let child = children.cell(t);
                for (face, local) in faces.iter().enumerate() {
                    let corners = &local[..child_type.face_type(face).corners()];
                    if corners.iter().all(|&l| parent.contains(&child[l])) {
                        mapped.push(FacetRef {
                            cell: t,
                            face: face as u8,
                        });
                    }
                }
            }
        }
        Ok(mapped)
    }
}

//! Multi-body volume meshes for the contact solver, plus generators for the
//! standard benchmark geometries (graded box, Hertz cylinder and sphere,
//! stacked blocks for the contact patch test).
//!
//! A [`Mesh`] holds one cell type (any of [`CellType`]), reference
//! coordinates, flat connectivity,
//! a body index per cell and named node and facet sets. Facets are stored as
//! (cell, local face) pairs so their orientation is always the outward one of
//! the owning cell, which is what the contact search needs for normals.
//!
//! Set names follow `<body>.<face>`, e.g. `block.top`, `cylinder.curved`.

mod cell;
mod error;
pub mod generate;
mod geometry;
mod gmsh;
mod inp;
mod ops;
mod order;
mod orient;
mod split;
mod tets;
mod topology;
mod validate;

#[cfg(test)]
mod tests;

use std::collections::BTreeMap;

pub use cell::{CellType, FacetType};
pub use error::MeshError;
pub use generate::{
    graded_box, hertz_cylinder, hertz_sphere, perturb_interior, stacked_blocks, BoxSpec, Grading,
    HertzCylinderSpec, HertzSphereSpec, Perturbation, StackedSpec,
};
pub use geometry::BoundingBox;
pub use gmsh::{parse_gmsh, read_gmsh, GmshError, GmshErrorKind, GmshReport, Location};
pub use inp::{parse_inp, read_inp, InpError, InpErrorKind, InpReport, InpRequest};
pub use topology::Csr;

/// One face of one cell; its orientation is the cell's outward one as given
/// by [`CellType::local_faces`].
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub struct FacetRef {
    /// Cell id.
    pub cell: usize,
    /// Local face index into `cell_type.local_faces()`.
    pub face: u8,
}

/// A single-cell-type volume mesh of one or more bodies.
#[derive(Debug, Clone, PartialEq)]
pub struct Mesh {
    /// Cell type of every cell.
    pub cell_type: CellType,
    /// Reference coordinates; the index is the global node id.
    pub nodes: Vec<[f64; 3]>,
    /// Flat connectivity, `cell_type.nodes()` entries per cell.
    pub cells: Vec<usize>,
    /// Body index of each cell, into `bodies`.
    pub cell_body: Vec<u32>,
    /// Body names.
    pub bodies: Vec<String>,
    /// Named node sets, each sorted and unique.
    pub node_sets: BTreeMap<String, Vec<usize>>,
    /// Named facet sets.
    pub facet_sets: BTreeMap<String, Vec<FacetRef>>,
}

impl Mesh {
    /// An empty mesh of the given cell type.
    pub fn empty(cell_type: CellType) -> Self {
        Mesh {
            cell_type,
            nodes: Vec::new(),
            cells: Vec::new(),
            cell_body: Vec::new(),
            bodies: Vec::new(),
            node_sets: BTreeMap::new(),
            facet_sets: BTreeMap::new(),
        }
    }

    /// Number of nodes.
    pub fn num_nodes(&self) -> usize {
        self.nodes.len()
    }

    /// Number of complete cells in the connectivity.
    pub fn num_cells(&self) -> usize {
        self.cells.len() / self.cell_type.nodes()
    }

    /// Node ids of cell `c`.
    ///
    /// # Panics
    /// If `c >= num_cells()`, like slice indexing; use [`Mesh::try_cell`] for
    /// ids that come from input.
    pub fn cell(&self, c: usize) -> &[usize] {
        let n = self.cell_type.nodes();
        &self.cells[c * n..(c + 1) * n]
    }

    /// Node ids of cell `c`, or an error naming the cell.
    pub fn try_cell(&self, c: usize) -> Result<&[usize], MeshError> {
        let n = self.cell_type.nodes();
        c.checked_mul(n)
            .and_then(|start| self.cells.get(start..start + n))
            .ok_or(MeshError::CellOutOfRange {
                cell: c,
                num_cells: self.num_cells(),
            })
    }

    /// Iterator over the node lists of all cells.
    pub fn cells_iter(&self) -> impl ExactSizeIterator<Item = &[usize]> + '_ {
        self.cells.chunks_exact(self.cell_type.nodes())
    }

    /// The cell's nodes and the local node list of the facet's face.
    fn facet_parts(&self, f: &FacetRef) -> Result<(&[usize], &'static [usize]), MeshError> {
        let invalid = MeshError::InvalidFacet {
            cell: f.cell,
            face: f.face,
        };
        let cell = self.try_cell(f.cell).map_err(|_| invalid.clone())?;
        let local = self
            .cell_type
            .local_faces()
            .get(usize::from(f.face))
            .ok_or(invalid)?;
        Ok((cell, local))
    }

    /// The facet type of a facet: its cell's local face's.
    pub fn facet_type(&self, f: &FacetRef) -> FacetType {
        self.cell_type.face_type(usize::from(f.face))
    }

    /// The distinct facet types of a facet set, in the order first met (one
    /// type unless the set holds a wedge's or pyramid's triangles and
    /// quadrilaterals together).
    pub fn facet_set_types(&self, name: &str) -> Result<Vec<FacetType>, MeshError> {
        let mut types = Vec::new();
        for f in self.facet_set(name)? {
            let t = self.facet_type(f);
            if !types.contains(&t) {
                types.push(t);
            }
        }
        Ok(types)
    }

    /// Global node ids of a facet, in outward order, without allocating.
    pub fn facet_nodes_iter(
        &self,
        f: &FacetRef,
    ) -> Result<impl ExactSizeIterator<Item = usize> + '_, MeshError> {
        let (cell, local) = self.facet_parts(f)?;
        // The face tables only hold indices below `cell_type.nodes()`, the
        // length of `cell`, so this indexing cannot fail.
        Ok(local.iter().map(move |&l| cell[l]))
    }

    /// Global node ids of a facet, in outward order.
    pub fn facet_nodes(&self, f: &FacetRef) -> Result<Vec<usize>, MeshError> {
        Ok(self.facet_nodes_iter(f)?.collect())
    }

    /// Facets of a named facet set.
    pub fn facet_set(&self, name: &str) -> Result<&[FacetRef], MeshError> {
        self.facet_sets
            .get(name)
            .map(Vec::as_slice)
            .ok_or_else(|| MeshError::UnknownSet {
                name: name.to_string(),
            })
    }

    /// Nodes of a named node set.
    pub fn node_set(&self, name: &str) -> Result<&[usize], MeshError> {
        self.node_sets
            .get(name)
            .map(Vec::as_slice)
            .ok_or_else(|| MeshError::UnknownSet {
                name: name.to_string(),
            })
    }

    /// Sorted, unique nodes touched by the facets of a facet set.
    pub fn facet_set_nodes(&self, name: &str) -> Result<Vec<usize>, MeshError> {
        let mut nodes = Vec::new();
        for f in self.facet_set(name)? {
            let facet = self
                .facet_nodes_iter(f)
                .map_err(|e| name_facet_error(e, name))?;
            nodes.extend(facet);
        }
        nodes.sort_unstable();
        nodes.dedup();
        Ok(nodes)
    }

    /// Index of the body with this name.
    pub fn body_id(&self, name: &str) -> Result<u32, MeshError> {
        self.bodies
            .iter()
            .position(|b| b == name)
            .and_then(|i| u32::try_from(i).ok())
            .ok_or_else(|| MeshError::UnknownBody {
                name: name.to_string(),
            })
    }

    /// Ids of the cells of body `body` (empty for an unknown index).
    pub fn body_cells(&self, body: u32) -> impl Iterator<Item = usize> + '_ {
        self.cell_body
            .iter()
            .enumerate()
            .filter(move |(_, &b)| b == body)
            .map(|(c, _)| c)
    }

    /// Sorted, unique nodes of the cells of body `body`.
    pub fn body_nodes(&self, body: u32) -> Vec<usize> {
        let mut nodes: Vec<usize> = self
            .body_cells(body)
            .filter_map(|c| self.try_cell(c).ok())
            .flatten()
            .copied()
            .collect();
        nodes.sort_unstable();
        nodes.dedup();
        nodes
    }
}

/// Puts the set name into a facet error raised while walking a set, so the
/// message says which set holds the bad facet.
fn name_facet_error(err: MeshError, set: &str) -> MeshError {
    match err {
        MeshError::InvalidFacet { cell, face } => MeshError::FacetOutOfRange {
            set: set.to_string(),
            cell,
            face,
        },
        other => other,
    }
}

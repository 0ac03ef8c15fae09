//! Structural and geometric checks of a mesh.

use std::collections::HashSet;

use super::topology::face_key;
use super::{FacetRef, Mesh, MeshError};

impl Mesh {
    /// Checks everything the solver relies on and reports the first problem:
    ///
    /// * the connectivity is a whole number of cells and every cell has a body,
    /// * node ids are in range and coordinates are finite,
    /// * every cell has a positive Jacobian (hex: at all 8 corners, which for
    ///   a trilinear hex is the standard practical criterion; tet: volume),
    /// * node sets are sorted, unique and in range,
    /// * facet sets refer to existing faces and are consistently oriented.
    pub fn validate(&self) -> Result<(), MeshError> {
        self.check_connectivity_length()?;
        self.check_coordinates()?;
        self.check_cells()?;
        self.check_bodies()?;
        self.check_node_sets()?;
        self.check_facet_sets()
    }

    fn check_connectivity_length(&self) -> Result<(), MeshError> {
        let per_cell = self.cell_type.nodes();
        if self.cells.len().is_multiple_of(per_cell) {
            Ok(())
        } else {
            Err(MeshError::ConnectivityLength {
                len: self.cells.len(),
                nodes_per_cell: per_cell,
            })
        }
    }

    fn check_coordinates(&self) -> Result<(), MeshError> {
        match self
            .nodes
            .iter()
            .position(|p| p.iter().any(|x| !x.is_finite()))
        {
            Some(node) => Err(MeshError::NonFiniteCoordinate {
                node,
                coords: self.nodes[node],
            }),
            None => Ok(()),
        }
    }

    /// Node ids first, so a bad id is reported as such rather than as a
    /// geometric failure.
    fn check_cells(&self) -> Result<(), MeshError> {
        for (cell, ids) in self.cells_iter().enumerate() {
            if let Some(&node) = ids.iter().find(|&&n| n >= self.nodes.len()) {
                return Err(MeshError::NodeOutOfRange {
                    cell,
                    node,
                    num_nodes: self.nodes.len(),
                });
            }
        }
        for cell in 0..self.num_cells() {
            let det = self.min_jacobian(cell)?;
            // NaN (from degenerate input) is rejected along with det ≤ 0.
            if det.is_nan() || det <= 0.0 {
                return Err(MeshError::InvertedCell { cell, det });
            }
        }
        Ok(())
    }

    fn check_bodies(&self) -> Result<(), MeshError> {
        if self.cell_body.len() != self.num_cells() {
            return Err(MeshError::CellBodyLength {
                len: self.cell_body.len(),
                num_cells: self.num_cells(),
            });
        }
        if let Some((cell, &body)) = self
            .cell_body
            .iter()
            .enumerate()
            .find(|(_, &b)| b as usize >= self.bodies.len())
        {
            return Err(MeshError::BodyOutOfRange {
                cell,
                body,
                num_bodies: self.bodies.len(),
            });
        }
        let mut seen = HashSet::new();
        match self.bodies.iter().find(|b| !seen.insert(b.as_str())) {
            Some(name) => Err(MeshError::DuplicateBody { name: name.clone() }),
            None => Ok(()),
        }
    }

    fn check_node_sets(&self) -> Result<(), MeshError> {
        for (name, nodes) in &self.node_sets {
            if let Some(&node) = nodes.iter().find(|&&n| n >= self.nodes.len()) {
                return Err(MeshError::NodeSetOutOfRange {
                    set: name.clone(),
                    node,
                    num_nodes: self.nodes.len(),
                });
            }
            if let Some(pair) = nodes.windows(2).find(|w| w[0] >= w[1]) {
                return Err(MeshError::NodeSetNotSorted {
                    set: name.clone(),
                    node: pair[1],
                });
            }
        }
        Ok(())
    }

    fn check_facet_sets(&self) -> Result<(), MeshError> {
        for (name, facets) in &self.facet_sets {
            self.check_facet_set_orientation(name, facets)?;
        }
        Ok(())
    }

    /// In a consistently oriented surface every edge shared by two facets is
    /// traversed in opposite directions by them. A directed edge seen twice
    /// means flipped neighbours, a facet listed twice, or both sides of an
    /// interior face — all of which would give the contact search
    /// contradictory normals.
    ///
    /// Both sides of one face pass the edge test (their edges run opposite
    /// ways), so faces are also checked for repeats by their node sets.
    fn check_facet_set_orientation(
        &self,
        name: &str,
        facets: &[FacetRef],
    ) -> Result<(), MeshError> {
        let mut directed_edges = HashSet::new();
        let mut faces = HashSet::new();
        for f in facets {
            let nodes = self
                .facet_nodes(f)
                .map_err(|e| super::name_facet_error(e, name))?;
            if !faces.insert(face_key(nodes.iter().copied())) {
                return Err(MeshError::DuplicateFacet {
                    set: name.to_string(),
                    cell: f.cell,
                    face: f.face,
                });
            }
            for (k, &a) in nodes.iter().enumerate() {
                let b = nodes[(k + 1) % nodes.len()];
                if !directed_edges.insert((a, b)) {
                    return Err(MeshError::InconsistentOrientation {
                        set: name.to_string(),
                        cell: f.cell,
                        face: f.face,
                        edge: [a, b],
                    });
                }
            }
        }
        Ok(())
    }
}

//! Structural and geometric checks of a mesh.

use std::collections::HashSet;

use super::topology::face_key;
use super::{FacetRef, Mesh, MeshError};
use crate::vec3::{add, norm, scale, sub};

impl Mesh {
    /// Checks everything the solver relies on and reports the first problem:
    ///
    /// * the connectivity is a whole number of cells and every cell has a body,
    /// * node ids are in range and coordinates are finite,
    /// * every cell has a positive Jacobian (hex: at all 8 corners, which for
    ///   a trilinear hex is the standard practical criterion; tet: volume;
    ///   the other types: at every quadrature point the solver uses), and
    ///   every second-order node lies near where its corners put it,
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
            self.check_higher_nodes(cell)?;
            let det = self.min_jacobian(cell)?;
            // NaN (from degenerate input) is rejected along with det ≤ 0.
            if det.is_nan() || det <= 0.0 {
                return Err(MeshError::InvertedCell { cell, det });
            }
        }
        Ok(())
    }

    /// Each higher node within a quarter of its corners' span of their
    /// mean ([`MeshError::MidNodeOffEdge`]).
    fn check_higher_nodes(&self, cell: usize) -> Result<(), MeshError> {
        let higher = self.cell_type.higher_nodes();
        if higher.is_empty() {
            return Ok(());
        }
        let x = self.cell_node_points(cell)?;
        let ids = self.cell(cell);
        let corners = self.cell_type.corners();
        for (k, of) in higher.iter().enumerate() {
            let local = corners + k;
            let mean = of
                .iter()
                .fold([0.0; 3], |m, &a| add(m, scale(x[a], 1.0 / of.len() as f64)));
            let span = of
                .iter()
                .flat_map(|&a| of.iter().map(move |&b| (a, b)))
                .map(|(a, b)| norm(sub(x[a], x[b])))
                .fold(0.0, f64::max);
            let offset = norm(sub(x[local], mean));
            if offset.is_nan() || offset > 0.25 * span {
                return Err(MeshError::MidNodeOffEdge {
                    cell,
                    node: ids[local],
                    local,
                    corners: of.iter().map(|&a| ids[a]).collect(),
                    offset,
                    span,
                });
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
            // The corners fix the face and its cycle: a second-order
            // facet's other nodes lie on its corner edges and add nothing.
            let nodes = &nodes[..self.facet_type(f).corners()];
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

//! Whole-mesh operations: merging meshes of separate bodies and moving nodes.

use std::collections::BTreeMap;

use super::{FacetRef, Mesh, MeshError};
use crate::vec3::{add, Vec3};

impl Mesh {
    /// Appends `other` as further bodies: its node, cell and body ids are
    /// shifted past those of `self`, its sets are kept. Nodes are not fused,
    /// so the bodies stay separate (they interact only through contact).
    ///
    /// Fails if the cell types differ or a body or set name occurs in both.
    pub fn merge(mut self, other: Mesh) -> Result<Mesh, MeshError> {
        if self.cell_type != other.cell_type {
            return Err(MeshError::CellTypeMismatch {
                operation: "merge",
                expected: self.cell_type.name(),
                found: other.cell_type.name(),
            });
        }
        check_disjoint_names(&self, &other)?;
        let node_offset = self.nodes.len();
        let cell_offset = self.num_cells();
        let body_offset = u32::try_from(self.bodies.len()).map_err(|_| too_many_bodies())?;
        self.nodes.extend_from_slice(&other.nodes);
        self.cells
            .extend(other.cells.iter().map(|&n| n.saturating_add(node_offset)));
        for &b in &other.cell_body {
            let shifted = b.checked_add(body_offset).ok_or_else(too_many_bodies)?;
            self.cell_body.push(shifted);
        }
        self.bodies.extend(other.bodies);
        append_node_sets(&mut self.node_sets, other.node_sets, node_offset);
        append_facet_sets(&mut self.facet_sets, other.facet_sets, cell_offset);
        Ok(self)
    }

    /// Moves every node by `offset`.
    pub fn translate(&mut self, offset: [f64; 3]) {
        self.transform(|p| add(p, offset));
    }

    /// Replaces every node position `p` by `f(p)`. A reflecting map inverts
    /// the cells; [`Mesh::validate`] reports that.
    pub fn transform(&mut self, f: impl Fn([f64; 3]) -> [f64; 3]) {
        for p in &mut self.nodes {
            *p = f(*p);
        }
    }

    /// Applies `f` to the nodes of one body only (bodies produced by the
    /// generators share no nodes, so the others stay put).
    pub fn transform_body(
        &mut self,
        body: &str,
        f: impl Fn([f64; 3]) -> [f64; 3],
    ) -> Result<(), MeshError> {
        let id = self.body_id(body)?;
        for n in self.body_nodes(id) {
            if let Some(p) = self.nodes.get_mut(n) {
                *p = f(*p);
            }
        }
        Ok(())
    }

    /// Moves the nodes of one body by `offset`.
    pub fn translate_body(&mut self, body: &str, offset: Vec3) -> Result<(), MeshError> {
        self.transform_body(body, |p| add(p, offset))
    }
}

fn too_many_bodies() -> MeshError {
    MeshError::InvalidArgument {
        operation: "merge",
        argument: "other",
        reason: "more than u32::MAX bodies".to_string(),
    }
}

// Offsets use saturating arithmetic so that a garbage id in `other` stays an
// out-of-range id (reported by `validate`) instead of overflowing.

/// Body and set names must stay unique, otherwise lookups by name would
/// silently pick one of two meanings.
fn check_disjoint_names(a: &Mesh, b: &Mesh) -> Result<(), MeshError> {
    if let Some(name) = b.bodies.iter().find(|n| a.bodies.contains(n)) {
        return Err(MeshError::DuplicateBody { name: name.clone() });
    }
    let clash = b
        .node_sets
        .keys()
        .find(|k| a.node_sets.contains_key(*k))
        .or_else(|| b.facet_sets.keys().find(|k| a.facet_sets.contains_key(*k)));
    match clash {
        Some(name) => Err(MeshError::DuplicateSet { name: name.clone() }),
        None => Ok(()),
    }
}

fn append_node_sets(
    into: &mut BTreeMap<String, Vec<usize>>,
    from: BTreeMap<String, Vec<usize>>,
    offset: usize,
) {
    for (name, nodes) in from {
        into.insert(
            name,
            nodes
                .into_iter()
                .map(|n| n.saturating_add(offset))
                .collect(),
        );
    }
}

fn append_facet_sets(
    into: &mut BTreeMap<String, Vec<FacetRef>>,
    from: BTreeMap<String, Vec<FacetRef>>,
    offset: usize,
) {
    for (name, facets) in from {
        let shifted = facets
            .into_iter()
            .map(|f| FacetRef {
                cell: f.cell.saturating_add(offset),
                face: f.face,
            })
            .collect();
        into.insert(name, shifted);
    }
}

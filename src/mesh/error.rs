//! Error type of the mesh module.
//!
//! Every variant names the offending item (cell id, node id, set or body
//! name, generator field) so a message alone is enough to find the problem in
//! a large input.

use thiserror::Error;

/// Everything that can go wrong while building, checking or querying a mesh.
#[derive(Debug, Clone, PartialEq, Error)]
pub enum MeshError {
    /// The flat connectivity is not a whole number of cells.
    #[error("connectivity has {len} entries, not a multiple of {nodes_per_cell} nodes per cell")]
    ConnectivityLength { len: usize, nodes_per_cell: usize },

    /// A cell refers to a node that does not exist.
    #[error("cell {cell} refers to node {node}, but the mesh has {num_nodes} nodes")]
    NodeOutOfRange {
        cell: usize,
        node: usize,
        num_nodes: usize,
    },

    /// A node coordinate is NaN or infinite.
    #[error("node {node} has a non-finite coordinate {coords:?}")]
    NonFiniteCoordinate { node: usize, coords: [f64; 3] },

    /// A cell id beyond the number of cells was asked for.
    #[error("cell {cell} does not exist: the mesh has {num_cells} cells")]
    CellOutOfRange { cell: usize, num_cells: usize },

    /// `cell_body` does not have one entry per cell.
    #[error("cell_body has {len} entries but the mesh has {num_cells} cells")]
    CellBodyLength { len: usize, num_cells: usize },

    /// A cell belongs to a body index that has no name.
    #[error("cell {cell} belongs to body {body}, but only {num_bodies} bodies are named")]
    BodyOutOfRange {
        cell: usize,
        body: u32,
        num_bodies: usize,
    },

    /// No body with this name.
    #[error("no body named `{name}`")]
    UnknownBody { name: String },

    /// Two bodies with the same name.
    #[error("body name `{name}` is used twice")]
    DuplicateBody { name: String },

    /// A cell has a non-positive Jacobian determinant (hex8: smallest of the
    /// eight corner values of the trilinear map from [−1,1]³; tet4: six times
    /// the signed volume, the determinant of the map from the unit tet; the
    /// other types: smallest over the quadrature points of their default
    /// rule).
    #[error("cell {cell} is inverted or degenerate: Jacobian determinant {det:e}")]
    InvertedCell { cell: usize, det: f64 },

    /// A second-order cell's mid-edge (or face or centre) node lies far
    /// from where its corners put it: more than a quarter of the corners'
    /// span from their mean. Curved boundaries move a mid-edge node by far
    /// less; a node this far off is a mix-up of node order.
    #[error(
        "cell {cell}: its node {node} (local node {local}) lies {offset:e} from the midpoint of the corners it sits between ({corners:?}), more than a quarter of their span {span:e}; check the node order of the cell"
    )]
    MidNodeOffEdge {
        cell: usize,
        node: usize,
        local: usize,
        corners: Vec<usize>,
        offset: f64,
        span: f64,
    },

    /// No node or facet set with this name.
    #[error("no set named `{name}`")]
    UnknownSet { name: String },

    /// The same set name appears twice (e.g. in both meshes of a merge).
    #[error("set name `{name}` is used twice")]
    DuplicateSet { name: String },

    /// A node set refers to a node that does not exist.
    #[error("node set `{set}` refers to node {node}, but the mesh has {num_nodes} nodes")]
    NodeSetOutOfRange {
        set: String,
        node: usize,
        num_nodes: usize,
    },

    /// A node set is not strictly increasing.
    #[error("node set `{set}` is not sorted and unique at node {node}")]
    NodeSetNotSorted { set: String, node: usize },

    /// A facet (cell, local face) that does not exist was asked for.
    #[error("face {face} of cell {cell} does not exist")]
    InvalidFacet { cell: usize, face: u8 },

    /// A facet set refers to a cell or local face that does not exist.
    #[error("facet set `{set}` refers to face {face} of cell {cell}, which does not exist")]
    FacetOutOfRange { set: String, cell: usize, face: u8 },

    /// A facet set covers the same face twice: a repeated entry, or both
    /// sides of an interior face (whose normals are opposite).
    #[error("facet set `{set}` covers the face {face} of cell {cell} a second time (repeated or both sides of one face)")]
    DuplicateFacet { set: String, cell: usize, face: u8 },

    /// Two facets of a set run along a shared edge in the same direction, so
    /// their normals disagree (or the facet is listed twice).
    #[error(
        "facet set `{set}` is not consistently oriented: face {face} of cell {cell} \
         runs along edge {edge:?} in the same direction as another facet"
    )]
    InconsistentOrientation {
        set: String,
        cell: usize,
        face: u8,
        edge: [usize; 2],
    },

    /// An operation needs a different cell type.
    #[error("{operation} needs {expected} cells but the mesh has {found} cells")]
    CellTypeMismatch {
        operation: &'static str,
        expected: &'static str,
        found: &'static str,
    },

    /// A generator spec field is out of its valid range.
    #[error("{generator}: invalid `{field}`: {reason}")]
    InvalidSpec {
        generator: &'static str,
        field: String,
        reason: String,
    },

    /// A method argument is out of its valid range.
    #[error("{operation}: invalid `{argument}`: {reason}")]
    InvalidArgument {
        operation: &'static str,
        argument: &'static str,
        reason: String,
    },
}

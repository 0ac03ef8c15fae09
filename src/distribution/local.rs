//! A rank's share of the mesh: the coordinates of its local nodes, the body
//! of its cells, its facets of every facet set, the natural-order block of
//! nodes and cells it writes, and the few surface-sized sets every rank needs
//! whole. Cut on the rank that holds the mesh ([`super::Numbering::piece`]);
//! nothing here is of the global node or cell count.
use crate::fem::{CellType, FacetType, MAX_FACET_NODES};
use crate::mesh::{BoundingBox, FacetRef, Mesh};
use std::collections::BTreeMap;

/// One facet of a local cell, in local numbering.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LocalFacet {
    /// Position in its facet set (the order output and contact rows use).
    pub set_index: usize,
    /// Natural id of the cell the facet belongs to.
    pub cell: usize,
    /// Local face of that cell.
    pub face: u8,
    /// Local node indices in outward order (the face type's node count
    /// used).
    pub nodes: [u32; MAX_FACET_NODES],
}

/// This rank's facets of one facet set.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct LocalFacetSet {
    /// Facets in the whole set (all ranks).
    pub global_len: usize,
    /// The facets of this rank's cells, by ascending set index.
    pub facets: Vec<LocalFacet>,
}

/// A facet of another rank's cell that touches a node this rank owns (a
/// contact slave set's ghost facet), with everything needed to integrate it.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct GhostFacet {
    pub set_index: usize,
    /// Natural node ids (`facet_type.nodes()` used).
    pub natural: [usize; MAX_FACET_NODES],
    pub x_ref: [[f64; 3]; MAX_FACET_NODES],
}

/// What a rank needs of a contact slave set beyond its own facets.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct SlaveSetPiece {
    /// Owning rank of every facet of the set, in set order: O(surface).
    pub owners: Vec<i32>,
    /// Mean shortest edge of the set's facets (the same on every rank).
    pub mean_edge: f64,
    /// Other ranks' facets that touch a node this rank owns.
    pub ghosts: Vec<GhostFacet>,
}

/// A facet set every rank sees whole (the result file's header, both sides
/// of a mortar pair): O(surface).
#[derive(Debug, Clone, Default, PartialEq)]
pub struct SharedSet {
    /// Natural cell of each facet, in set order.
    pub cells: Vec<usize>,
    /// Local face of each facet's cell.
    pub faces: Vec<u8>,
    /// Natural node ids, each facet's own node count (its face type's) in
    /// turn, outward order.
    pub nodes: Vec<usize>,
}

impl SharedSet {
    /// The facet type of every facet of the set, in set order.
    pub fn facet_types(&self, cell_type: CellType) -> impl Iterator<Item = FacetType> + '_ {
        self.faces
            .iter()
            .map(move |&face| cell_type.face_type(usize::from(face)))
    }
}

/// The natural-order block of nodes and cells a rank writes to the result
/// file (`even_block` of the node and of the cell count).
#[derive(Debug, Clone, Default, PartialEq)]
pub struct OutputBlock {
    pub nodes: Vec<[f64; 3]>,
    /// Natural node ids of the block's cells, `cell_type.nodes()` per cell.
    pub cells: Vec<usize>,
    pub cell_body: Vec<u32>,
}

/// This rank's mesh, local numbering (the DOF map's local node order and
/// ascending natural cell order).
#[derive(Debug, Clone, PartialEq)]
pub struct LocalMesh {
    pub cell_type: CellType,
    /// Body names (all bodies).
    pub bodies: Vec<String>,
    /// Bounding box of the whole mesh.
    pub bounding_box: Option<BoundingBox>,
    /// Nodes and cells of the whole mesh.
    pub global_nodes: usize,
    pub global_cells: usize,
    /// Reference coordinates of every local node.
    pub nodes: Vec<[f64; 3]>,
    /// Body of every local cell.
    pub cell_body: Vec<u32>,
    /// Body of every owned node: that of the highest natural cell holding it
    /// (`u32::MAX` for a node in no cell).
    pub owned_body: Vec<u32>,
    /// This rank's facets of every facet set of the mesh.
    pub facet_sets: BTreeMap<String, LocalFacetSet>,
    /// The contact slave sets asked for, in request order.
    pub slaves: Vec<SlaveSetPiece>,
    /// Every facet set of the mesh whole, by name (surface-sized).
    pub shared: BTreeMap<String, SharedSet>,
    /// Every node set of the mesh whole (surface-sized).
    pub node_sets: BTreeMap<String, Vec<usize>>,
    pub block: OutputBlock,
}

impl LocalMesh {
    /// Number of local nodes.
    pub fn num_nodes(&self) -> usize {
        self.nodes.len()
    }

    /// This rank's facets of a facet set; None for a set the mesh lacks.
    pub fn facet_set(&self, name: &str) -> Option<&LocalFacetSet> {
        self.facet_sets.get(name)
    }

    /// Names of the mesh's facet sets, for error messages.
    pub fn facet_set_names(&self) -> Vec<&str> {
        self.facet_sets.keys().map(String::as_str).collect()
    }

    /// The facet type of a local facet.
    pub fn facet_type(&self, f: &LocalFacet) -> FacetType {
        self.cell_type.face_type(usize::from(f.face))
    }

    /// The one facet type of every facet of set `name`; `None` for a set
    /// that mixes types (a wedge's triangles and quadrilaterals) or that the
    /// mesh lacks. An empty set has the type of the cells' first face.
    pub fn set_facet_type(&self, name: &str) -> Option<FacetType> {
        let mut types = self.shared.get(name)?.facet_types(self.cell_type);
        let first = types.next().unwrap_or(self.cell_type.face_type(0));
        types.all(|t| t == first).then_some(first)
    }

    /// Reference coordinates of a local facet's nodes.
    pub fn facet_x_ref(&self, f: &LocalFacet) -> Vec<[f64; 3]> {
        let n = self.facet_type(f).nodes();
        f.nodes[..n]
            .iter()
            .map(|&l| self.nodes[l as usize])
            .collect()
    }
}

/// Facets of `set` whose cell is local, in local numbering. `local_of` maps a
/// natural node of a local cell to its local index.
pub(super) fn local_facets(
    mesh: &Mesh,
    facets: &[FacetRef],
    is_local: impl Fn(usize) -> bool,
    local_of: impl Fn(usize) -> u32,
) -> LocalFacetSet {
    let mut out = Vec::new();
    for (set_index, f) in facets.iter().enumerate() {
        if !is_local(f.cell) {
            continue;
        }
        let mut nodes = [0u32; MAX_FACET_NODES];
        // A facet whose cell is out of range was rejected by mesh validation;
        // it cannot be local, so this walk only sees valid ones.
        if let Ok(it) = mesh.facet_nodes_iter(f) {
            for (slot, v) in nodes.iter_mut().zip(it) {
                *slot = local_of(v);
            }
        }
        out.push(LocalFacet {
            set_index,
            cell: f.cell,
            face: f.face,
            nodes,
        });
    }
    LocalFacetSet {
        global_len: facets.len(),
        facets: out,
    }
}

/// Mean shortest edge of a facet set's facets.
pub(super) fn mean_shortest_edge(mesh: &Mesh, facets: &[FacetRef]) -> f64 {
    let mut sum = 0.0;
    for f in facets {
        // The corners (they come first): a second-order facet's edges are
        // its chords.
        let corners = mesh.facet_type(f).corners();
        let x: Vec<[f64; 3]> = match mesh.facet_nodes_iter(f) {
            Ok(it) => it.take(corners).map(|v| mesh.nodes[v]).collect(),
            Err(_) => continue,
        };
        sum += shortest_edge(&x);
    }
    sum / facets.len().max(1) as f64
}

/// Shortest edge of a facet (corner nodes in order, closed polygon).
pub fn shortest_edge(x: &[[f64; 3]]) -> f64 {
    let n = x.len();
    (0..n)
        .map(|i| {
            let (a, b) = (x[i], x[(i + 1) % n]);
            ((a[0] - b[0]).powi(2) + (a[1] - b[1]).powi(2) + (a[2] - b[2]).powi(2)).sqrt()
        })
        .fold(f64::INFINITY, f64::min)
}

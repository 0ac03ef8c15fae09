//! Structured hex blocks and their assembly into one body.
//!
//! A block is an (i, j, k) grid of points from a mapping; its cells use
//! VTK order with (i, j, k) as (ξ, η, ζ), so a right-handed mapping gives
//! positive cells and the block's logical sides are hex faces 0..5. Blocks
//! of one body are glued by fusing coincident points (spatial hash), which
//! avoids bookkeeping of which block edges meet where.

use std::collections::{BTreeMap, HashMap};

use crate::mesh::geometry::{norm, sub, Vec3};
use crate::mesh::{CellType, FacetRef, Mesh};

/// Largest mesh a generator will build, to turn absurd specs into errors
/// rather than out-of-memory aborts.
pub(crate) const MAX_CELLS: usize = 20_000_000;

/// Points closer than this fraction of the body size are the same node.
/// Interface points of adjacent blocks agree to round-off (≈1e-16), while
/// distinct nodes are at least one element size apart.
const FUSE_TOLERANCE: f64 = 1e-9;

/// A logical side of a structured block.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum Side {
    IMin,
    IMax,
    JMin,
    JMax,
    KMin,
    KMax,
}

impl Side {
    /// Hex corners (VTK local ids) on this side, and the face index the
    /// documented convention gives it (ξ−, ξ+, η−, η+, ζ−, ζ+).
    fn hex_corners(self) -> ([usize; 4], usize) {
        match self {
            Side::IMin => ([0, 3, 4, 7], 0),
            Side::IMax => ([1, 2, 5, 6], 1),
            Side::JMin => ([0, 1, 4, 5], 2),
            Side::JMax => ([2, 3, 6, 7], 3),
            Side::KMin => ([0, 1, 2, 3], 4),
            Side::KMax => ([4, 5, 6, 7], 5),
        }
    }

    /// Local hex face index, looked up in the face table by node set so
    /// that a differently ordered table (from `fem`) is still honoured.
    fn hex_face(self) -> u8 {
        let (corners, documented) = self.hex_corners();
        let index = CellType::Hex8
            .local_faces()
            .iter()
            .position(|face| {
                let mut sorted = face.to_vec();
                sorted.sort_unstable();
                sorted == corners
            })
            .unwrap_or(documented);
        index as u8
    }

    /// Whether cell (i, j, k) of a block with `dims` cells touches this side.
    fn touches(self, [i, j, k]: [usize; 3], dims: [usize; 3]) -> bool {
        match self {
            Side::IMin => i == 0,
            Side::IMax => i + 1 == dims[0],
            Side::JMin => j == 0,
            Side::JMax => j + 1 == dims[1],
            Side::KMin => k == 0,
            Side::KMax => k + 1 == dims[2],
        }
    }
}

/// Offsets (di, dj, dk) of the VTK hex corners in the (i, j, k) grid.
const HEX_OFFSETS: [[usize; 3]; 8] = [
    [0, 0, 0],
    [1, 0, 0],
    [1, 1, 0],
    [0, 1, 0],
    [0, 0, 1],
    [1, 0, 1],
    [1, 1, 1],
    [0, 1, 1],
];

/// One structured block: `dims` cells per direction, points i-fastest.
pub(crate) struct Block {
    dims: [usize; 3],
    points: Vec<Vec3>,
    tags: Vec<(Side, &'static str)>,
}

impl Block {
    /// Block whose point (i, j, k) is `map(i, j, k)`.
    pub(crate) fn from_fn(
        dims: [usize; 3],
        map: impl Fn(usize, usize, usize) -> Vec3,
    ) -> Result<Block, String> {
        let cells = dims
            .iter()
            .try_fold(1usize, |acc, &d| acc.checked_mul(d))
            .filter(|&c| c > 0 && c <= MAX_CELLS)
            .ok_or_else(|| {
                format!("block of {dims:?} cells is empty or exceeds {MAX_CELLS} cells")
            })?;
        let mut points = Vec::with_capacity(cells);
        for k in 0..=dims[2] {
            for j in 0..=dims[1] {
                for i in 0..=dims[0] {
                    points.push(map(i, j, k));
                }
            }
        }
        Ok(Block {
            dims,
            points,
            tags: Vec::new(),
        })
    }

    /// Tensor-product block of three coordinate lines.
    pub(crate) fn tensor(x: &[f64], y: &[f64], z: &[f64]) -> Result<Block, String> {
        let dims = [x.len(), y.len(), z.len()].map(|n| n.saturating_sub(1));
        Block::from_fn(dims, |i, j, k| [x[i], y[j], z[k]])
    }

    /// Names the facet set (within the body) formed by one side.
    pub(crate) fn tag(mut self, side: Side, name: &'static str) -> Block {
        self.tags.push((side, name));
        self
    }

    fn point_index(&self, [i, j, k]: [usize; 3]) -> usize {
        i + (self.dims[0] + 1) * (j + (self.dims[1] + 1) * k)
    }

    /// Cell positions (i, j, k), i fastest.
    fn cell_positions(&self) -> impl Iterator<Item = [usize; 3]> + '_ {
        let [ni, nj, nk] = self.dims;
        (0..nk).flat_map(move |k| (0..nj).flat_map(move |j| (0..ni).map(move |i| [i, j, k])))
    }

    fn num_cells(&self) -> usize {
        self.dims.iter().product()
    }
}

/// Assembles the blocks of one body into a [`Mesh`].
pub(crate) struct BodyBuilder {
    name: String,
    nodes: Vec<Vec3>,
    cells: Vec<usize>,
    facet_sets: BTreeMap<String, Vec<FacetRef>>,
    fuser: PointFuser,
}

impl BodyBuilder {
    /// `size` is a length of the order of the body size; it sets the fusing
    /// tolerance.
    pub(crate) fn new(name: &str, size: f64) -> BodyBuilder {
        BodyBuilder {
            name: name.to_string(),
            nodes: Vec::new(),
            cells: Vec::new(),
            facet_sets: BTreeMap::new(),
            fuser: PointFuser::new(FUSE_TOLERANCE * size),
        }
    }

    /// Adds a block, fusing its points with coincident existing nodes.
    pub(crate) fn add(&mut self, block: &Block) -> Result<(), String> {
        if self.cells.len() / 8 + block.num_cells() > MAX_CELLS {
            return Err(format!("body `{}` exceeds {MAX_CELLS} cells", self.name));
        }
        let global: Vec<usize> = block
            .points
            .iter()
            .map(|&p| self.fuser.find_or_insert(p, &mut self.nodes))
            .collect();
        for pos in block.cell_positions() {
            let cell = self.cells.len() / 8;
            for offset in HEX_OFFSETS {
                let corner = [pos[0] + offset[0], pos[1] + offset[1], pos[2] + offset[2]];
                self.cells.push(global[block.point_index(corner)]);
            }
            for &(side, name) in &block.tags {
                if side.touches(pos, block.dims) {
                    let set = format!("{}.{}", self.name, name);
                    self.facet_sets.entry(set).or_default().push(FacetRef {
                        cell,
                        face: side.hex_face(),
                    });
                }
            }
        }
        Ok(())
    }

    /// The single-body hex mesh, with a node set for every facet set.
    pub(crate) fn finish(self) -> Mesh {
        let num_cells = self.cells.len() / 8;
        let mut mesh = Mesh::empty(CellType::Hex8);
        mesh.nodes = self.nodes;
        mesh.cells = self.cells;
        mesh.cell_body = vec![0; num_cells];
        mesh.bodies = vec![self.name];
        mesh.facet_sets = self.facet_sets;
        add_node_sets_from_facet_sets(&mut mesh);
        mesh
    }
}

/// Every facet set also becomes a node set of the same name, which is what
/// Dirichlet conditions and load application want.
pub(crate) fn add_node_sets_from_facet_sets(mesh: &mut Mesh) {
    let names: Vec<String> = mesh.facet_sets.keys().cloned().collect();
    for name in names {
        if let Ok(nodes) = mesh.facet_set_nodes(&name) {
            mesh.node_sets.insert(name, nodes);
        }
    }
}

/// Adds `to` as a copy of the node and facet sets `from` (e.g. `.top` as an
/// alias of `.zmax`).
pub(crate) fn alias_set(mesh: &mut Mesh, from: &str, to: &str) {
    if let Some(f) = mesh.facet_sets.get(from).cloned() {
        mesh.facet_sets.insert(to.to_string(), f);
    }
    if let Some(n) = mesh.node_sets.get(from).cloned() {
        mesh.node_sets.insert(to.to_string(), n);
    }
}

/// Adds `to` as the facets of `from` whose centroid satisfies `keep`, plus
/// the matching node set.
pub(crate) fn subset_set(mesh: &mut Mesh, from: &str, to: &str, keep: impl Fn(Vec3) -> bool) {
    let Some(facets) = mesh.facet_sets.get(from) else {
        return;
    };
    let chosen: Vec<FacetRef> = facets
        .iter()
        .copied()
        .filter(|f| mesh.facet_centroid(f).map(&keep).unwrap_or(false))
        .collect();
    mesh.facet_sets.insert(to.to_string(), chosen);
    if let Ok(nodes) = mesh.facet_set_nodes(to) {
        mesh.node_sets.insert(to.to_string(), nodes);
    }
}

/// Fuses points within `tol` of each other. Buckets are cubes of edge
/// `tol`, so any match lies in one of the 27 buckets around a point.
struct PointFuser {
    tol: f64,
    buckets: HashMap<[i64; 3], Vec<usize>>,
}

impl PointFuser {
    fn new(tol: f64) -> PointFuser {
        PointFuser {
            tol: if tol > 0.0 { tol } else { f64::MIN_POSITIVE },
            buckets: HashMap::new(),
        }
    }

    fn bucket(&self, p: Vec3) -> [i64; 3] {
        // `as` saturates, so far-away points only share buckets (and are
        // still told apart by the distance test).
        p.map(|x| (x / self.tol).floor() as i64)
    }

    fn find_or_insert(&mut self, p: Vec3, nodes: &mut Vec<Vec3>) -> usize {
        let b = self.bucket(p);
        for d in neighbour_offsets() {
            let key = [
                b[0].saturating_add(d[0]),
                b[1].saturating_add(d[1]),
                b[2].saturating_add(d[2]),
            ];
            if let Some(ids) = self.buckets.get(&key) {
                if let Some(&id) = ids.iter().find(|&&id| norm(sub(nodes[id], p)) <= self.tol) {
                    return id;
                }
            }
        }
        let id = nodes.len();
        nodes.push(p);
        self.buckets.entry(b).or_default().push(id);
        id
    }
}

fn neighbour_offsets() -> impl Iterator<Item = [i64; 3]> {
    (-1..=1).flat_map(|a| (-1..=1).flat_map(move |b| (-1..=1).map(move |c| [a, b, c])))
}

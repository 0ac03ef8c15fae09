//! Reader for Gmsh `.msh` meshes, format 4.1, ASCII or little-endian binary.
//!
//! What becomes what:
//!
//! * Volume elements of one type per file (the solver holds one cell type
//!   per mesh): tet4 (Gmsh type 4), tet10 (11), hex8 (5), hex20 (17), hex27
//!   (12), prism6 (6, our wedge6), prism15 (18, wedge15), pyramid5 (7).
//!   Gmsh's node order is ours ([`CellType`]) except for the mid-edge nodes
//!   of tet10, hex20, hex27, prism15 and hex27's face centres, which are
//!   renumbered (`crate::fem::GMSH_TET10` and its kin). Cells that come
//!   fully inverted are renumbered ([`CellType::mirror`]) and counted in
//!   [`GmshReport::reoriented`], tangled ones are an error.
//! * Second-order meshes (`gmsh -order 2`) place their mid-edge nodes on the
//!   curved geometry; a node far off its edge is an error of the mesh
//!   ([`crate::mesh::MeshError::MidNodeOffEdge`]). Prism18 (the complete
//!   quadratic prism) is not read: `Mesh.SecondOrderIncomplete = 1` makes
//!   Gmsh write prism15 (and hex20 instead of hex27).
//! * Each 3D physical group is one body named by its physical name. Without
//!   any 3D physical group, each volume entity is a body `volume<tag>`.
//! * Each 2D physical group is a facet set (its tri3/quad4 (tri6, quad8,
//!   quad9 in a second-order mesh) elements matched
//!   to boundary faces of the cells, so facets carry the outward orientation
//!   of their cell whatever Gmsh's surface orientation) and a node set of the
//!   same name.
//! * 0D and 1D physical groups (points, line2, line3) are node sets.
//!
//! Physical names are used verbatim as set and body names. The solver's
//! convention is `<body>.<face>` (`block.top`, `sphere.curved`), so name the
//! groups that way in the `.geo` file. Unnamed groups become
//! `physical<dim>d<tag>`. Nodes that no volume cell uses are dropped and the
//! rest renumbered from 0 in file order.
//!
//! Groups of different dimensions with the same name share one node set.
//! Partitioned files (`$PartitionedEntities`) are not supported: that section
//! is skipped like any unknown one, so their physical groups are not seen;
//! write unpartitioned meshes (the solver partitions with METIS itself).
//!
//! Every error names the file and the line (ASCII) or byte offset (binary),
//! and the Gmsh element or node tag where there is one. The reader never
//! panics on bad input; counts in the file are not trusted for allocation.

mod assemble;
mod cursor;
mod kind;
mod sections;
#[cfg(test)]
mod tests;

use std::fmt;
use std::path::Path;

use thiserror::Error;

use super::{Mesh, MeshError};
use assemble::{assemble, Ctx};
use cursor::Cursor;
use sections::read_sections;

/// What the reader did besides reading, for `check` to print.
#[derive(Debug, Clone, Default, PartialEq, Eq)]
pub struct GmshReport {
    /// Cells that came fully inverted (negative Jacobian everywhere) and were
    /// renumbered to positive orientation.
    pub reoriented: usize,
    /// Sections that were skipped (`$Periodic`, `$NodeData`, ...).
    pub skipped_sections: Vec<String>,
    /// Nodes in `$Nodes` that no volume cell uses (dropped).
    pub unused_nodes: usize,
}

/// Where in the file an error is.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Location {
    /// 1-based line of an ASCII file.
    Line(usize),
    /// Byte offset into a binary file.
    Byte(usize),
    /// The whole file (errors found after reading, with no element to blame).
    File,
}

impl fmt::Display for Location {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Location::Line(l) => write!(f, ", line {l}"),
            Location::Byte(b) => write!(f, ", byte offset {b}"),
            Location::File => Ok(()),
        }
    }
}

/// A Gmsh reading error: the file, where in it, and what.
#[derive(Debug, Clone, PartialEq, Error)]
#[error("{path}{location}: {kind}")]
pub struct GmshError {
    pub path: String,
    pub location: Location,
    pub kind: GmshErrorKind,
}

/// What went wrong while reading a `.msh` file.
#[derive(Debug, Clone, PartialEq, Error)]
pub enum GmshErrorKind {
    #[error("cannot read the file: {0}")]
    Io(String),
    #[error("not a Gmsh .msh file: expected `$MeshFormat`, found `{found}`")]
    NotGmsh { found: String },
    #[error("format {version} is not supported, re-export as 4.1 (gmsh -format msh41)")]
    UnsupportedVersion { version: String },
    #[error("bad $MeshFormat line `{line}`: expected `4.1 <0|1> 8` (file type 0 ascii or 1 binary, data size 8)")]
    BadMeshFormat { line: String },
    #[error("the binary endianness marker is {value}, not 1: only little-endian binary files are supported (re-export as ASCII, or on a little-endian machine)")]
    Endianness { value: i32 },
    #[error(
        "the file ends inside ${section} while reading {what}: it is truncated (no $End{section})"
    )]
    UnexpectedEof {
        section: &'static str,
        what: &'static str,
    },
    #[error("cannot read {what} from `{token}`")]
    BadNumber { what: &'static str, token: String },
    #[error("bad {what}: {value}")]
    BadValue { what: &'static str, value: String },
    #[error("expected `{expected}`, found `{found}`")]
    Expected { expected: String, found: String },
    #[error("$Elements comes before $Nodes")]
    ElementsBeforeNodes,
    #[error("node {node} is defined twice in $Nodes")]
    DuplicateNode { node: u64 },
    #[error("element {element} refers to node {node} which is not in $Nodes")]
    UnknownNode { element: u64, node: u64 },
    #[error("element {element} has type {gmsh_type} ({name}), which is not supported: use tet4 (4), tet10 (11), hex8 (5), hex20 (17), hex27 (12), prism6 (6), prism15 (18) or pyramid5 (7) volumes, tri3 (2), quad4 (3), tri6 (9), quad8 (16) or quad9 (10) surfaces, points (15) and line2 (1) or line3 (8) for node sets (at most second order; prism15 rather than prism18: Mesh.SecondOrderIncomplete = 1)")]
    UnsupportedElement {
        element: u64,
        gmsh_type: i32,
        name: &'static str,
    },
    #[error("element {element} is a {found} but earlier volume elements are {first}: the solver needs one cell type per mesh (mesh all volumes with one type, e.g. all tets or all hexes, of one order)")]
    MixedCellTypes {
        element: u64,
        first: &'static str,
        found: &'static str,
    },
    #[error("no volume elements (tet4 or hex8): mesh in 3D (gmsh -3)")]
    NoVolumeCells,
    #[error("volume entity {entity} is in no 3D physical group, while other volumes are; add it to a Physical Volume (its cells would have no body)")]
    VolumeWithoutPhysical { entity: i32 },
    #[error("volume entity {entity} is in two 3D physical groups, `{first}` and `{second}`; a cell belongs to one body only")]
    VolumeInTwoBodies {
        entity: i32,
        first: String,
        second: String,
    },
    #[error("cell from element {element} is tangled or degenerate (Jacobian determinants of mixed sign or zero, from {min:e} to {max:e})")]
    TangledCell { element: u64, min: f64, max: f64 },
    #[error("surface element {element} of physical group `{group}` matches no boundary face of a volume cell")]
    FacetNotOnCell { element: u64, group: String },
    #[error("surface element {element} of physical group `{group}` is a {found}, but the faces of {cells} cells are {expected}")]
    FacetTypeMismatch {
        element: u64,
        group: String,
        found: &'static str,
        cells: &'static str,
        expected: &'static str,
    },
    #[error("element {element} of physical group `{group}` uses node {node}, which belongs to no volume cell")]
    NodeNotInCells {
        element: u64,
        group: String,
        node: u64,
    },
    #[error("the mesh read is not valid: {0}")]
    Invalid(MeshError),
}

/// Reads a `.msh` 4.1 file into a validated [`Mesh`].
pub fn read_gmsh(path: &Path) -> Result<(Mesh, GmshReport), GmshError> {
    let name = path.display().to_string();
    let data = std::fs::read(path).map_err(|e| GmshError {
        path: name.clone(),
        location: Location::File,
        kind: GmshErrorKind::Io(e.to_string()),
    })?;
    parse_gmsh(&data, &name)
}

/// Parses the bytes of a `.msh` 4.1 file; `path` is only used in messages.
pub fn parse_gmsh(data: &[u8], path: &str) -> Result<(Mesh, GmshReport), GmshError> {
    let mut cursor = Cursor::new(data, path);
    let raw = read_sections(&mut cursor)?;
    assemble(raw, &Ctx { path })
}

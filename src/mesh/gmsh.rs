//! Reader for Gmsh `.msh` meshes, format 4.1, ASCII or little-endian binary.
//!
//! What becomes what:
//!
//! * Volume elements: tet4 (Gmsh type 4) or hex8 (type 5), one type per file
//!   (the solver holds one cell type per mesh). Gmsh numbers both like VTK,
//!   which is the node order of [`CellType`], so connectivity is taken as is;
//!   cells that come fully inverted are renumbered and counted in
//!   [`GmshReport::reoriented`], tangled ones are an error.
//! * Each 3D physical group is one body named by its physical name. Without
//!   any 3D physical group, each volume entity is a body `volume<tag>`.
//! * Each 2D physical group is a facet set (its tri3/quad4 elements matched
//!   to boundary faces of the cells, so facets carry the outward orientation
//!   of their cell whatever Gmsh's surface orientation) and a node set of the
//!   same name.
//! * 0D and 1D physical groups (points, line2) are node sets.
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

use std::collections::{BTreeMap, HashMap};
use std::fmt;
use std::path::Path;
use std::str::FromStr;

use thiserror::Error;

use super::geometry::{hex_corner_jacobians, tet_jacobian, Vec3};
use super::topology::{face_key, FaceKey};
use super::{CellType, FacetRef, Mesh, MeshError};

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
    #[error("element {element} has type {gmsh_type} ({name}), which is not supported: use tet4 (4) or hex8 (5) volumes, tri3 (2)/quad4 (3) surfaces, points (15) and line2 (1) for node sets (first order: gmsh -order 1)")]
    UnsupportedElement {
        element: u64,
        gmsh_type: i32,
        name: &'static str,
    },
    #[error("element {element} is a {found} but earlier volume elements are {first}: the solver needs one cell type per mesh (mesh all volumes with tets, or all with hexes)")]
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

// ---------------------------------------------------------------------------
// Element kinds

/// The Gmsh element types the reader accepts.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Kind {
    Point,
    Line,
    Tri,
    Quad,
    Tet,
    Hex,
}

impl Kind {
    #[cfg(test)]
    const ALL: [Kind; 6] = [
        Kind::Point,
        Kind::Line,
        Kind::Tri,
        Kind::Quad,
        Kind::Tet,
        Kind::Hex,
    ];

    fn from_gmsh(t: i32) -> Option<Kind> {
        match t {
            15 => Some(Kind::Point),
            1 => Some(Kind::Line),
            2 => Some(Kind::Tri),
            3 => Some(Kind::Quad),
            4 => Some(Kind::Tet),
            5 => Some(Kind::Hex),
            _ => None,
        }
    }

    fn index(self) -> usize {
        self as usize
    }

    fn nodes(self) -> usize {
        match self {
            Kind::Point => 1,
            Kind::Line => 2,
            Kind::Tri => 3,
            Kind::Quad | Kind::Tet => 4,
            Kind::Hex => 8,
        }
    }

    fn dim(self) -> usize {
        match self {
            Kind::Point => 0,
            Kind::Line => 1,
            Kind::Tri | Kind::Quad => 2,
            Kind::Tet | Kind::Hex => 3,
        }
    }

    fn name(self) -> &'static str {
        match self {
            Kind::Point => "point",
            Kind::Line => "line2",
            Kind::Tri => "tri3",
            Kind::Quad => "quad4",
            Kind::Tet => "tet4",
            Kind::Hex => "hex8",
        }
    }
}

/// Names of the Gmsh element types users are likely to meet, for messages.
fn gmsh_type_name(t: i32) -> &'static str {
    match t {
        6 => "prism6",
        7 => "pyramid5",
        8 => "line3",
        9 => "tri6",
        10 => "quad9",
        11 => "tet10",
        12 => "hex27",
        13 => "prism18",
        14 => "pyramid14",
        16 => "quad8",
        17 => "hex20",
        18 => "prism15",
        19 => "pyramid13",
        20..=28 => "higher-order triangle or line",
        29..=31 => "higher-order tetrahedron",
        92 | 93 => "higher-order hexahedron",
        _ => "unknown type",
    }
}

// ---------------------------------------------------------------------------
// Byte cursor shared by the ASCII and binary parsers

/// Reads tokens (ASCII) or little-endian values (binary) and knows where it
/// is, so every error can say so.
struct Cursor<'a> {
    data: &'a [u8],
    path: &'a str,
    pos: usize,
    /// 1-based line of `pos`; only meaningful in ASCII files.
    line: usize,
    /// Set by `$MeshFormat`: section bodies are binary, locations are bytes.
    binary: bool,
    /// The section being read, for end-of-file messages.
    section: &'static str,
}

impl<'a> Cursor<'a> {
    fn new(data: &'a [u8], path: &'a str) -> Self {
        Cursor {
            data,
            path,
            pos: 0,
            line: 1,
            binary: false,
            section: "MeshFormat",
        }
    }

    fn here(&self) -> Location {
        if self.binary {
            Location::Byte(self.pos)
        } else {
            Location::Line(self.line)
        }
    }

    fn error(&self, location: Location, kind: GmshErrorKind) -> GmshError {
        GmshError {
            path: self.path.to_string(),
            location,
            kind,
        }
    }

    fn eof(&self, what: &'static str) -> GmshError {
        self.error(
            self.here(),
            GmshErrorKind::UnexpectedEof {
                section: self.section,
                what,
            },
        )
    }

    fn at_end(&self) -> bool {
        self.pos >= self.data.len()
    }

    fn skip_ws(&mut self) {
        while let Some(&b) = self.data.get(self.pos) {
            if !b.is_ascii_whitespace() {
                break;
            }
            if b == b'\n' {
                self.line += 1;
            }
            self.pos += 1;
        }
    }

    /// Location of the next value: in ASCII the next token's line.
    fn start(&mut self) -> Location {
        if !self.binary {
            self.skip_ws();
        }
        self.here()
    }

    /// The next whitespace-delimited token and where it starts.
    fn token(&mut self, what: &'static str) -> Result<(&'a [u8], Location), GmshError> {
        self.skip_ws();
        let at = self.here();
        let start = self.pos;
        while self
            .data
            .get(self.pos)
            .is_some_and(|b| !b.is_ascii_whitespace())
        {
            self.pos += 1;
        }
        match self.data.get(start..self.pos) {
            Some(t) if !t.is_empty() => Ok((t, at)),
            _ => Err(self.eof(what)),
        }
    }

    /// The rest of the current line without its newline, which is consumed.
    fn rest_of_line(&mut self) -> &'a [u8] {
        let start = self.pos;
        while self.data.get(self.pos).is_some_and(|&b| b != b'\n') {
            self.pos += 1;
        }
        let line = self.data.get(start..self.pos).unwrap_or_default();
        if !self.at_end() {
            self.pos += 1;
            self.line += 1;
        }
        line
    }

    fn ascii<T: FromStr>(&mut self, what: &'static str) -> Result<T, GmshError> {
        let (token, at) = self.token(what)?;
        std::str::from_utf8(token)
            .ok()
            .and_then(|s| s.parse().ok())
            .ok_or_else(|| self.error(at, bad_number(what, token)))
    }

    fn bytes<const N: usize>(&mut self, what: &'static str) -> Result<[u8; N], GmshError> {
        let end = self.pos.checked_add(N).ok_or_else(|| self.eof(what))?;
        let b: [u8; N] = self
            .data
            .get(self.pos..end)
            .and_then(|s| s.try_into().ok())
            .ok_or_else(|| self.eof(what))?;
        self.pos = end;
        Ok(b)
    }

    /// A `size_t`: 8 bytes in binary sections.
    fn size(&mut self, what: &'static str) -> Result<u64, GmshError> {
        if self.binary {
            Ok(u64::from_le_bytes(self.bytes(what)?))
        } else {
            self.ascii(what)
        }
    }

    /// An `int`: 4 bytes in binary sections.
    fn int(&mut self, what: &'static str) -> Result<i32, GmshError> {
        if self.binary {
            Ok(i32::from_le_bytes(self.bytes(what)?))
        } else {
            self.ascii(what)
        }
    }

    /// A finite `double`.
    fn double(&mut self, what: &'static str) -> Result<f64, GmshError> {
        let at = self.start();
        let x: f64 = if self.binary {
            f64::from_le_bytes(self.bytes(what)?)
        } else {
            self.ascii(what)?
        };
        if x.is_finite() {
            Ok(x)
        } else {
            Err(self.error(at, bad_number(what, x.to_string().as_bytes())))
        }
    }

    /// The `$EndName` line closing the current section.
    fn expect_end(&mut self) -> Result<(), GmshError> {
        let expected = format!("$End{}", self.section);
        let (token, at) = self.token("the section end marker")?;
        if token == expected.as_bytes() {
            Ok(())
        } else {
            let found = shorten(token);
            Err(self.error(at, GmshErrorKind::Expected { expected, found }))
        }
    }

    /// Skips an unknown section by searching for its end marker.
    fn skip_section(&mut self, name: &str) -> Result<(), GmshError> {
        let marker = format!("$End{name}");
        let rest = self.data.get(self.pos..).unwrap_or_default();
        let found = rest
            .windows(marker.len())
            .position(|w| w == marker.as_bytes())
            .ok_or_else(|| self.eof("an unknown section"))?;
        let skipped = rest.get(..found + marker.len()).unwrap_or_default();
        self.line += skipped.iter().filter(|&&b| b == b'\n').count();
        self.pos += skipped.len();
        Ok(())
    }
}

fn bad_number(what: &'static str, token: &[u8]) -> GmshErrorKind {
    GmshErrorKind::BadNumber {
        what,
        token: shorten(token),
    }
}

/// A token for a message: lossy UTF-8, at most 40 characters.
fn shorten(token: &[u8]) -> String {
    String::from_utf8_lossy(token).chars().take(40).collect()
}

/// A count from the file as a capacity hint, capped so that a corrupt count
/// cannot exhaust memory; the read loops themselves stop at end of file.
fn capacity(count: u64) -> usize {
    usize::try_from(count).unwrap_or(usize::MAX).min(1 << 16)
}

// ---------------------------------------------------------------------------
// Sections

/// Elements of one accepted kind, flat.
#[derive(Debug, Default)]
struct ElementList {
    tags: Vec<u64>,
    entities: Vec<i32>,
    locations: Vec<Location>,
    /// Node indices into `Raw::coords`, `Kind::nodes()` per element.
    nodes: Vec<usize>,
}

impl ElementList {
    fn len(&self) -> usize {
        self.tags.len()
    }
}

/// Everything read from the file, before it becomes a [`Mesh`].
#[derive(Debug, Default)]
struct Raw {
    /// (dimension, physical tag) → name.
    physical_names: HashMap<(usize, i32), String>,
    /// Per dimension: entity tag → physical tags.
    entity_groups: [HashMap<i32, Vec<i32>>; 4],
    node_index: HashMap<u64, usize>,
    node_tags: Vec<u64>,
    coords: Vec<Vec3>,
    nodes_read: bool,
    /// One list per [`Kind`], indexed by `Kind::index`.
    elements: [ElementList; 6],
    volume_kind: Option<Kind>,
    skipped: Vec<String>,
}

impl Raw {
    fn list(&self, kind: Kind) -> &ElementList {
        &self.elements[kind.index()]
    }

    fn groups(&self, dim: usize, entity: i32) -> &[i32] {
        self.entity_groups
            .get(dim)
            .and_then(|m| m.get(&entity))
            .map_or(&[], Vec::as_slice)
    }

    fn group_name(&self, dim: usize, tag: i32) -> String {
        self.physical_names
            .get(&(dim, tag))
            .cloned()
            .unwrap_or_else(|| format!("physical{dim}d{tag}"))
    }
}

fn read_sections(c: &mut Cursor) -> Result<Raw, GmshError> {
    read_mesh_format(c)?;
    let mut raw = Raw::default();
    loop {
        c.skip_ws();
        if c.at_end() {
            break;
        }
        let (header, at) = c.token("a section header")?;
        // Binary section bodies start right after the header's newline.
        c.rest_of_line();
        let name = header.strip_prefix(b"$").ok_or_else(|| {
            let found = shorten(header);
            let expected = "a section header ($Name)".to_string();
            c.error(at, GmshErrorKind::Expected { expected, found })
        })?;
        read_section(c, name, &mut raw)?;
    }
    Ok(raw)
}

fn read_section(c: &mut Cursor, name: &[u8], raw: &mut Raw) -> Result<(), GmshError> {
    match name {
        b"PhysicalNames" => {
            c.section = "PhysicalNames";
            read_physical_names(c, raw)?;
        }
        b"Entities" => {
            c.section = "Entities";
            read_entities(c, raw)?;
        }
        b"Nodes" => {
            c.section = "Nodes";
            read_nodes(c, raw)?;
        }
        b"Elements" => {
            c.section = "Elements";
            read_elements(c, raw)?;
        }
        other => {
            let name = String::from_utf8_lossy(other).into_owned();
            c.section = "(unknown section)";
            c.skip_section(&name)?;
            raw.skipped.push(name);
            return Ok(());
        }
    }
    c.expect_end()
}

fn read_mesh_format(c: &mut Cursor) -> Result<(), GmshError> {
    let (header, at) = c.token("the $MeshFormat header")?;
    if header != b"$MeshFormat" {
        let found = shorten(header);
        return Err(c.error(at, GmshErrorKind::NotGmsh { found }));
    }
    c.rest_of_line();
    c.skip_ws();
    let at = c.here();
    let line = String::from_utf8_lossy(c.rest_of_line()).trim().to_string();
    let fields: Vec<&str> = line.split_whitespace().collect();
    let version = fields.first().copied().unwrap_or_default();
    if version != "4.1" {
        let version = if version.is_empty() {
            "(none)"
        } else {
            version
        };
        let kind = GmshErrorKind::UnsupportedVersion {
            version: version.to_string(),
        };
        return Err(c.error(at, kind));
    }
    c.binary = match fields.get(1..) {
        Some(["0", "8"]) => false,
        Some(["1", "8"]) => true,
        _ => return Err(c.error(at, GmshErrorKind::BadMeshFormat { line })),
    };
    if c.binary {
        check_endianness(c)?;
    }
    c.expect_end()
}

/// The binary int 1 that follows the format line in binary files.
fn check_endianness(c: &mut Cursor) -> Result<(), GmshError> {
    let at = c.here();
    let value = i32::from_le_bytes(c.bytes("the binary endianness marker")?);
    if value == 1 {
        Ok(())
    } else {
        Err(c.error(at, GmshErrorKind::Endianness { value }))
    }
}

/// Always ASCII, also in binary files: `dim tag "name"` per line.
fn read_physical_names(c: &mut Cursor, raw: &mut Raw) -> Result<(), GmshError> {
    let count: u64 = c.ascii("the number of physical names")?;
    for _ in 0..count {
        let what = "a physical name's dimension";
        let (token, at) = c.token(what)?;
        let dim = std::str::from_utf8(token)
            .ok()
            .and_then(|s| s.parse::<usize>().ok())
            .filter(|&d| d <= 3)
            .ok_or_else(|| c.error(at, bad_number(what, token)))?;
        let tag: i32 = c.ascii("a physical tag")?;
        c.skip_ws();
        let at = c.here();
        let line = String::from_utf8_lossy(c.rest_of_line()).trim().to_string();
        let name = line
            .strip_prefix('"')
            .and_then(|s| s.strip_suffix('"'))
            .ok_or_else(|| {
                let expected = "a quoted physical name".to_string();
                c.error(
                    at,
                    GmshErrorKind::Expected {
                        expected,
                        found: line.clone(),
                    },
                )
            })?;
        raw.physical_names.insert((dim, tag), name.to_string());
    }
    Ok(())
}

/// An entity dimension, 0 to 3.
fn read_dim(c: &mut Cursor, what: &'static str) -> Result<usize, GmshError> {
    let at = c.start();
    let dim = c.int(what)?;
    usize::try_from(dim)
        .ok()
        .filter(|&d| d <= 3)
        .ok_or_else(|| {
            let value = dim.to_string();
            c.error(at, GmshErrorKind::BadValue { what, value })
        })
}

/// Only the physical tags of each entity are kept; bounding boxes and
/// boundaries are read past.
fn read_entities(c: &mut Cursor, raw: &mut Raw) -> Result<(), GmshError> {
    let mut counts = [0u64; 4];
    for n in &mut counts {
        *n = c.size("an entity count")?;
    }
    for (dim, &count) in counts.iter().enumerate() {
        for _ in 0..count {
            let tag = c.int("an entity tag")?;
            // Points have X Y Z, the others a bounding box.
            let doubles = if dim == 0 { 3 } else { 6 };
            for _ in 0..doubles {
                c.double("an entity coordinate")?;
            }
            let groups = read_int_list(c, "a physical tag")?;
            if dim > 0 {
                read_int_list(c, "a bounding entity tag")?;
            }
            raw.entity_groups[dim].insert(tag, groups);
        }
    }
    Ok(())
}

/// A `size_t` count followed by that many ints.
fn read_int_list(c: &mut Cursor, what: &'static str) -> Result<Vec<i32>, GmshError> {
    let n = c.size("a list length")?;
    let mut list = Vec::with_capacity(capacity(n).min(64));
    for _ in 0..n {
        list.push(c.int(what)?);
    }
    Ok(list)
}

fn read_nodes(c: &mut Cursor, raw: &mut Raw) -> Result<(), GmshError> {
    let blocks = c.size("the number of node blocks")?;
    let total = c.size("the number of nodes")?;
    c.size("the smallest node tag")?;
    c.size("the largest node tag")?;
    raw.coords.reserve(capacity(total));
    for _ in 0..blocks {
        read_node_block(c, raw)?;
    }
    raw.nodes_read = true;
    Ok(())
}

/// `dim entity parametric n`, then n tags, then n coordinate tuples (with
/// `dim` parametric coordinates each when parametric, which are skipped).
fn read_node_block(c: &mut Cursor, raw: &mut Raw) -> Result<(), GmshError> {
    let dim = read_dim(c, "a node block's entity dimension")?;
    c.int("a node block's entity tag")?;
    let at = c.start();
    let parametric = c.int("a node block's parametric flag")?;
    let extra = match parametric {
        0 => 0,
        1 => dim,
        other => {
            let what = "parametric flag (0 or 1)";
            let value = other.to_string();
            return Err(c.error(at, GmshErrorKind::BadValue { what, value }));
        }
    };
    let n = c.size("the number of nodes in a block")?;
    let mut tags = Vec::with_capacity(capacity(n));
    for _ in 0..n {
        let at = c.start();
        tags.push((c.size("a node tag")?, at));
    }
    for (tag, at) in tags {
        let x = [
            c.double("a node coordinate")?,
            c.double("a node coordinate")?,
            c.double("a node coordinate")?,
        ];
        for _ in 0..extra {
            c.double("a parametric node coordinate")?;
        }
        let index = raw.coords.len();
        if raw.node_index.insert(tag, index).is_some() {
            return Err(c.error(at, GmshErrorKind::DuplicateNode { node: tag }));
        }
        raw.coords.push(x);
        raw.node_tags.push(tag);
    }
    Ok(())
}

fn read_elements(c: &mut Cursor, raw: &mut Raw) -> Result<(), GmshError> {
    if !raw.nodes_read {
        return Err(c.error(c.here(), GmshErrorKind::ElementsBeforeNodes));
    }
    let blocks = c.size("the number of element blocks")?;
    c.size("the number of elements")?;
    c.size("the smallest element tag")?;
    c.size("the largest element tag")?;
    for _ in 0..blocks {
        read_element_block(c, raw)?;
    }
    Ok(())
}

fn read_element_block(c: &mut Cursor, raw: &mut Raw) -> Result<(), GmshError> {
    read_dim(c, "an element block's entity dimension")?;
    let entity = c.int("an element block's entity tag")?;
    let gmsh_type = c.int("an element type")?;
    let n = c.size("the number of elements in a block")?;
    let Some(kind) = Kind::from_gmsh(gmsh_type) else {
        return reject_block(c, n, gmsh_type);
    };
    let mut ids = [0usize; 8];
    for _ in 0..n {
        let at = c.start();
        let tag = c.size("an element tag")?;
        for id in ids.iter_mut().take(kind.nodes()) {
            let node = c.size("an element's node tag")?;
            *id = *raw
                .node_index
                .get(&node)
                .ok_or_else(|| c.error(at, GmshErrorKind::UnknownNode { element: tag, node }))?;
        }
        check_volume_kind(c, raw, kind, tag, at)?;
        let list = &mut raw.elements[kind.index()];
        list.tags.push(tag);
        list.entities.push(entity);
        list.locations.push(at);
        list.nodes.extend_from_slice(&ids[..kind.nodes()]);
    }
    Ok(())
}

/// An unsupported type is an error at its first element; an empty block of
/// it is harmless.
fn reject_block(c: &mut Cursor, n: u64, gmsh_type: i32) -> Result<(), GmshError> {
    if n == 0 {
        return Ok(());
    }
    let at = c.start();
    let element = c.size("an element tag")?;
    let name = gmsh_type_name(gmsh_type);
    let kind = GmshErrorKind::UnsupportedElement {
        element,
        gmsh_type,
        name,
    };
    Err(c.error(at, kind))
}

fn check_volume_kind(
    c: &Cursor,
    raw: &mut Raw,
    kind: Kind,
    element: u64,
    at: Location,
) -> Result<(), GmshError> {
    if kind.dim() != 3 {
        return Ok(());
    }
    match raw.volume_kind {
        None => {
            raw.volume_kind = Some(kind);
            Ok(())
        }
        Some(first) if first == kind => Ok(()),
        Some(first) => {
            let kind = GmshErrorKind::MixedCellTypes {
                element,
                first: first.name(),
                found: kind.name(),
            };
            Err(c.error(at, kind))
        }
    }
}

// ---------------------------------------------------------------------------
// Assembly into a Mesh

/// File name for errors found after parsing.
struct Ctx<'a> {
    path: &'a str,
}

impl Ctx<'_> {
    fn error(&self, location: Location, kind: GmshErrorKind) -> GmshError {
        GmshError {
            path: self.path.to_string(),
            location,
            kind,
        }
    }

    fn whole_file(&self, kind: GmshErrorKind) -> GmshError {
        self.error(Location::File, kind)
    }
}

fn assemble(raw: Raw, ctx: &Ctx) -> Result<(Mesh, GmshReport), GmshError> {
    let kind = raw
        .volume_kind
        .ok_or_else(|| ctx.whole_file(GmshErrorKind::NoVolumeCells))?;
    let cell_type = match kind {
        Kind::Hex => CellType::Hex8,
        _ => CellType::Tet4,
    };
    let volumes = raw.list(kind);
    let (bodies, cell_body) = assign_bodies(&raw, volumes, ctx)?;
    let new_id = compact_nodes(raw.coords.len(), &volumes.nodes);
    let mut mesh = Mesh::empty(cell_type);
    mesh.nodes = raw
        .coords
        .iter()
        .zip(&new_id)
        .filter(|(_, id)| id.is_some())
        .map(|(x, _)| *x)
        .collect();
    // Every volume node is used, so the lookups all succeed.
    mesh.cells = volumes.nodes.iter().filter_map(|&n| new_id[n]).collect();
    mesh.cell_body = cell_body;
    mesh.bodies = bodies;
    let reoriented = orient_cells(&mut mesh, volumes, ctx)?;
    let sets = SetBuilder {
        raw: &raw,
        new_id: &new_id,
        ctx,
    };
    sets.facet_sets(&mut mesh)?;
    sets.node_sets(&mut mesh)?;
    mesh.validate()
        .map_err(|e| ctx.whole_file(GmshErrorKind::Invalid(e)))?;
    let report = GmshReport {
        reoriented,
        skipped_sections: raw.skipped.clone(),
        unused_nodes: raw.coords.len() - mesh.nodes.len(),
    };
    Ok((mesh, report))
}

/// Body names and each cell's body: 3D physical groups in tag order, or one
/// body per volume entity when the file has no 3D physical group.
fn assign_bodies(
    raw: &Raw,
    volumes: &ElementList,
    ctx: &Ctx,
) -> Result<(Vec<String>, Vec<u32>), GmshError> {
    let has_groups = raw.entity_groups[3].values().any(|g| !g.is_empty())
        || raw.physical_names.keys().any(|&(d, _)| d == 3);
    // (sort key, name) per cell, then bodies numbered in key order.
    let mut keys = Vec::with_capacity(volumes.len());
    for (i, &entity) in volumes.entities.iter().enumerate() {
        if !has_groups {
            keys.push((entity, format!("volume{entity}")));
            continue;
        }
        let at = volumes.locations[i];
        match raw.groups(3, entity) {
            [] => return Err(ctx.error(at, GmshErrorKind::VolumeWithoutPhysical { entity })),
            [g] => keys.push((*g, raw.group_name(3, *g))),
            [a, b, ..] => {
                let kind = GmshErrorKind::VolumeInTwoBodies {
                    entity,
                    first: raw.group_name(3, *a),
                    second: raw.group_name(3, *b),
                };
                return Err(ctx.error(at, kind));
            }
        }
    }
    let mut distinct: Vec<(i32, String)> = keys.clone();
    distinct.sort();
    distinct.dedup();
    let bodies: Vec<String> = distinct.iter().map(|(_, n)| n.clone()).collect();
    let cell_body = keys
        .iter()
        .map(|k| distinct.binary_search(k).unwrap_or(0) as u32)
        .collect();
    Ok((bodies, cell_body))
}

/// New node ids: nodes used by cells, numbered in file order.
fn compact_nodes(num_nodes: usize, cell_nodes: &[usize]) -> Vec<Option<usize>> {
    let mut used = vec![false; num_nodes];
    for &n in cell_nodes {
        used[n] = true;
    }
    let mut next = 0;
    used.iter()
        .map(|&u| {
            u.then(|| {
                next += 1;
                next - 1
            })
        })
        .collect()
}

/// Renumbering that reverses a cell: tet swaps nodes 1 and 2; hex swaps the
/// bottom and top quads (a reflection ζ → −ζ of the reference cube).
fn reversal(cell_type: CellType) -> &'static [usize] {
    match cell_type {
        CellType::Tet4 => &[0, 2, 1, 3],
        CellType::Hex8 => &[4, 5, 6, 7, 0, 1, 2, 3],
    }
}

/// Jacobian determinants of a cell: the tet's one, the hex's eight corners.
fn cell_jacobians(mesh: &Mesh, ids: &[usize]) -> Vec<f64> {
    let p = |k: usize| mesh.nodes[ids[k]];
    match mesh.cell_type {
        CellType::Tet4 => vec![tet_jacobian(&std::array::from_fn(p))],
        CellType::Hex8 => hex_corner_jacobians(&std::array::from_fn(p)).to_vec(),
    }
}

/// Reverses fully inverted cells (some generators emit them), rejects
/// tangled ones; returns how many were reversed.
fn orient_cells(mesh: &mut Mesh, volumes: &ElementList, ctx: &Ctx) -> Result<usize, GmshError> {
    let per = mesh.cell_type.nodes();
    let perm = reversal(mesh.cell_type);
    let mut reversed = 0;
    for c in 0..mesh.num_cells() {
        let ids: Vec<usize> = mesh.cell(c).to_vec();
        let dets = cell_jacobians(mesh, &ids);
        let min = dets.iter().copied().fold(f64::INFINITY, f64::min);
        let max = dets.iter().copied().fold(f64::NEG_INFINITY, f64::max);
        if min > 0.0 {
            continue;
        }
        if max >= 0.0 {
            let element = volumes.tags[c];
            let kind = GmshErrorKind::TangledCell { element, min, max };
            return Err(ctx.error(volumes.locations[c], kind));
        }
        for (k, &from) in perm.iter().enumerate() {
            mesh.cells[c * per + k] = ids[from];
        }
        reversed += 1;
    }
    Ok(reversed)
}

/// Builds the facet and node sets of the physical groups below dimension 3.
struct SetBuilder<'a> {
    raw: &'a Raw,
    new_id: &'a [Option<usize>],
    ctx: &'a Ctx<'a>,
}

impl SetBuilder<'_> {
    /// Mesh ids of element `i` of `list`, or an error naming the first node
    /// that no cell uses.
    fn element_nodes(
        &self,
        list: &ElementList,
        i: usize,
        per: usize,
        group: &str,
    ) -> Result<Vec<usize>, GmshError> {
        let old = list.nodes.get(i * per..(i + 1) * per).unwrap_or_default();
        old.iter()
            .map(|&n| {
                self.new_id[n].ok_or_else(|| {
                    let kind = GmshErrorKind::NodeNotInCells {
                        element: list.tags[i],
                        group: group.to_string(),
                        node: self.raw.node_tags[n],
                    };
                    self.ctx.error(list.locations[i], kind)
                })
            })
            .collect()
    }

    /// Each element of `kind` in a physical group, with the group's name.
    fn grouped(&self, kind: Kind) -> impl Iterator<Item = (usize, String)> + '_ {
        let list = self.raw.list(kind);
        let dim = kind.dim();
        (0..list.len()).flat_map(move |i| {
            self.raw
                .groups(dim, list.entities[i])
                .iter()
                .map(move |&g| (i, self.raw.group_name(dim, g)))
        })
    }

    fn facet_sets(&self, mesh: &mut Mesh) -> Result<(), GmshError> {
        let boundary = boundary_faces(mesh);
        let mut facet_sets: BTreeMap<String, Vec<FacetRef>> = BTreeMap::new();
        for kind in [Kind::Tri, Kind::Quad] {
            let list = self.raw.list(kind);
            for (i, group) in self.grouped(kind) {
                let element = list.tags[i];
                let at = list.locations[i];
                if kind.nodes() != mesh.cell_type.facet_type().nodes() {
                    let kind = GmshErrorKind::FacetTypeMismatch {
                        element,
                        group,
                        found: kind.name(),
                        cells: mesh.cell_type.name(),
                        expected: mesh.cell_type.facet_type().name(),
                    };
                    return Err(self.ctx.error(at, kind));
                }
                let nodes = self.element_nodes(list, i, kind.nodes(), &group)?;
                let facet = boundary.get(&face_key(nodes.iter().copied()));
                let Some(&facet) = facet else {
                    let kind = GmshErrorKind::FacetNotOnCell { element, group };
                    return Err(self.ctx.error(at, kind));
                };
                insert_nodes(&mut mesh.node_sets, &group, &nodes);
                facet_sets.entry(group).or_default().push(facet);
            }
        }
        for facets in facet_sets.values_mut() {
            facets.sort_unstable();
            facets.dedup();
        }
        mesh.facet_sets = facet_sets;
        finish_node_sets(&mut mesh.node_sets);
        Ok(())
    }

    fn node_sets(&self, mesh: &mut Mesh) -> Result<(), GmshError> {
        for kind in [Kind::Point, Kind::Line] {
            let list = self.raw.list(kind);
            for (i, group) in self.grouped(kind) {
                let nodes = self.element_nodes(list, i, kind.nodes(), &group)?;
                insert_nodes(&mut mesh.node_sets, &group, &nodes);
            }
        }
        finish_node_sets(&mut mesh.node_sets);
        Ok(())
    }
}

/// Faces owned by exactly one cell, by face key. Interior faces are left
/// out: a contact or load surface must be on the outside of a body.
fn boundary_faces(mesh: &Mesh) -> HashMap<FaceKey, FacetRef> {
    mesh.faces_by_key()
        .into_iter()
        .filter_map(|(key, owners)| match owners.as_slice() {
            [only] => Some((key, *only)),
            _ => None,
        })
        .collect()
}

fn insert_nodes(sets: &mut BTreeMap<String, Vec<usize>>, name: &str, nodes: &[usize]) {
    sets.entry(name.to_string())
        .or_default()
        .extend_from_slice(nodes);
}

fn finish_node_sets(sets: &mut BTreeMap<String, Vec<usize>>) {
    for nodes in sets.values_mut() {
        nodes.sort_unstable();
        nodes.dedup();
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// One unit tet (nodes 10, 20, 30, 40: sparse tags) with its bottom
    /// face as a physical surface and its apex as a physical point.
    const TET: &str = "$MeshFormat
4.1 0 8
$EndMeshFormat
$PhysicalNames
3
0 3 \"apex\"
2 2 \"solid.bottom\"
3 1 \"solid\"
$EndPhysicalNames
$Entities
1 0 1 1
7 0 0 1 1 3
4 0 0 0 1 1 0 1 2 0
9 0 0 0 1 1 1 1 1 1 4
$EndEntities
$Nodes
2 4 10 40
0 7 0 1
40
0 0 1
2 4 1 3
10
20
30
0 0 0 0 0
1 0 0 1 0
0 1 0 0 1
$EndNodes
$Elements
3 3 1 3
0 7 15 1
1 40
2 4 2 1
2 10 30 20
3 9 4 1
3 10 20 30 40
$EndElements
";

    fn parse(text: &str) -> Result<(Mesh, GmshReport), GmshError> {
        parse_gmsh(text.as_bytes(), "test.msh")
    }

    #[test]
    fn reads_a_tet_with_groups() {
        let (mesh, report) = parse(TET).unwrap();
        assert_eq!(mesh.cell_type, CellType::Tet4);
        assert_eq!(mesh.bodies, vec!["solid".to_string()]);
        assert_eq!(mesh.cells, vec![1, 2, 3, 0]);
        assert_eq!(mesh.nodes[0], [0.0, 0.0, 1.0]);
        assert_eq!(mesh.node_set("apex").unwrap(), &[0]);
        assert_eq!(mesh.node_set("solid.bottom").unwrap(), &[1, 2, 3]);
        // The bottom is the face opposite local node 3.
        let bottom = mesh.facet_set("solid.bottom").unwrap();
        assert_eq!(bottom, &[FacetRef { cell: 0, face: 0 }]);
        assert_eq!(report.reoriented, 0);
        assert_eq!(report.unused_nodes, 0);
    }

    #[test]
    fn inverted_tet_is_reversed_and_counted() {
        let text = TET.replace("3 10 20 30 40", "3 10 30 20 40");
        let (mesh, report) = parse(&text).unwrap();
        assert_eq!(report.reoriented, 1);
        assert_eq!(mesh.cells, vec![1, 2, 3, 0]);
    }

    #[test]
    fn flat_tet_is_tangled() {
        let text = TET.replace("0 0 1\n2 4", "0.5 0.5 0\n2 4");
        let err = parse(&text).unwrap_err();
        assert!(matches!(
            err.kind,
            GmshErrorKind::TangledCell { element: 3, .. }
        ));
        assert_eq!(err.location, Location::Line(36));
    }

    #[test]
    fn unknown_sections_are_skipped() {
        let text = TET.replace(
            "$Nodes",
            "$Periodic\n1\n$EndPeriodic\n$NodeData\nx y z\n$EndNodeData\n$Nodes",
        );
        let (_, report) = parse(&text).unwrap();
        assert_eq!(report.skipped_sections, vec!["Periodic", "NodeData"]);
    }

    #[test]
    fn truncation_names_the_section_and_line() {
        let cut = TET.find("$EndNodes").unwrap();
        let err = parse(&TET[..cut]).unwrap_err();
        assert_eq!(err.location, Location::Line(28));
        let msg = err.to_string();
        assert!(msg.starts_with("test.msh, line 28: "), "{msg}");
        assert!(msg.contains("no $EndNodes"), "{msg}");
    }

    /// Corrupts a valid file in many ways; the reader must return, never
    /// panic.
    #[test]
    fn never_panics_on_corrupt_input() {
        let inputs = [TET.as_bytes().to_vec(), binary_tet()];
        for bytes in inputs {
            for cut in (0..bytes.len()).step_by(7) {
                assert_no_panic(&bytes[..cut]);
                for flip in [0x01u8, 0x10, 0x80, 0xff] {
                    let mut corrupt = bytes.clone();
                    corrupt[cut] ^= flip;
                    assert_no_panic(&corrupt);
                }
            }
        }
    }

    fn assert_no_panic(bytes: &[u8]) {
        let result = std::panic::catch_unwind(|| parse_gmsh(bytes, "fuzz.msh").map(|_| ()));
        assert!(
            result.is_ok(),
            "panicked on input {:?}",
            String::from_utf8_lossy(bytes)
        );
    }

    /// The ASCII tet written as a binary file, by re-encoding its values.
    fn binary_tet() -> Vec<u8> {
        let mut b = Vec::new();
        b.extend_from_slice(b"$MeshFormat\n4.1 1 8\n");
        b.extend_from_slice(&1i32.to_le_bytes());
        b.extend_from_slice(b"\n$EndMeshFormat\n$Nodes\n");
        for v in [1u64, 4, 10, 40] {
            b.extend_from_slice(&v.to_le_bytes());
        }
        for v in [3i32, 9, 0] {
            b.extend_from_slice(&v.to_le_bytes());
        }
        b.extend_from_slice(&4u64.to_le_bytes());
        for v in [10u64, 20, 30, 40] {
            b.extend_from_slice(&v.to_le_bytes());
        }
        for x in [0.0f64, 0., 0., 1., 0., 0., 0., 1., 0., 0., 0., 1.] {
            b.extend_from_slice(&x.to_le_bytes());
        }
        b.extend_from_slice(b"\n$EndNodes\n$Elements\n");
        for v in [1u64, 1, 1, 1] {
            b.extend_from_slice(&v.to_le_bytes());
        }
        for v in [3i32, 9, 4] {
            b.extend_from_slice(&v.to_le_bytes());
        }
        for v in [1u64, 1, 10, 20, 30, 40] {
            b.extend_from_slice(&v.to_le_bytes());
        }
        b.extend_from_slice(b"\n$EndElements\n");
        b
    }

    #[test]
    fn binary_tet_reads() {
        let (mesh, _) = parse_gmsh(&binary_tet(), "b.msh").unwrap();
        assert_eq!(mesh.bodies, vec!["volume9".to_string()]);
        assert_eq!(mesh.cells, vec![0, 1, 2, 3]);
    }

    #[test]
    fn big_endian_marker_is_rejected() {
        let mut b = binary_tet();
        let at = b"$MeshFormat\n4.1 1 8\n".len();
        b[at..at + 4].copy_from_slice(&1i32.to_be_bytes());
        let err = parse_gmsh(&b, "b.msh").unwrap_err();
        assert_eq!(err.kind, GmshErrorKind::Endianness { value: 1 << 24 });
        assert_eq!(err.location, Location::Byte(at));
    }

    #[test]
    fn inverted_hex_is_reversed() {
        let mut mesh = Mesh::empty(CellType::Hex8);
        mesh.nodes = vec![
            [0., 0., 0.],
            [1., 0., 0.],
            [1., 1., 0.],
            [0., 1., 0.],
            [0., 0., 1.],
            [1., 0., 1.],
            [1., 1., 1.],
            [0., 1., 1.],
        ];
        mesh.cells = vec![4, 5, 6, 7, 0, 1, 2, 3];
        mesh.cell_body = vec![0];
        let list = ElementList {
            tags: vec![5],
            entities: vec![1],
            locations: vec![Location::Line(1)],
            nodes: Vec::new(),
        };
        let ctx = Ctx { path: "x" };
        assert_eq!(orient_cells(&mut mesh, &list, &ctx).unwrap(), 1);
        assert_eq!(mesh.cells, (0..8).collect::<Vec<_>>());
    }

    #[test]
    fn kinds_are_consistent() {
        for k in Kind::ALL {
            assert_eq!(Kind::ALL[k.index()], k);
        }
        assert_eq!(Kind::Tet.nodes(), CellType::Tet4.nodes());
        assert_eq!(Kind::Hex.nodes(), CellType::Hex8.nodes());
    }
}

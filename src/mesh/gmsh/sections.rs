//! The sections of a `.msh` file, read into [`Raw`] before it becomes a mesh.

use std::collections::HashMap;

use super::cursor::{bad_number, capacity, shorten, Cursor};
use super::kind::{gmsh_type_name, Kind};
use super::{GmshError, GmshErrorKind, Location};
use crate::vec3::Vec3;

/// Elements of one accepted kind, flat.
#[derive(Debug, Default)]
pub(super) struct ElementList {
    pub(super) tags: Vec<u64>,
    pub(super) entities: Vec<i32>,
    pub(super) locations: Vec<Location>,
    /// Node indices into `Raw::coords`, `Kind::nodes()` per element.
    pub(super) nodes: Vec<usize>,
}

impl ElementList {
    pub(super) fn len(&self) -> usize {
        self.tags.len()
    }
}

/// Everything read from the file, before it becomes a [`Mesh`].
#[derive(Debug, Default)]
pub(super) struct Raw {
    /// (dimension, physical tag) → name.
    pub(super) physical_names: HashMap<(usize, i32), String>,
    /// Per dimension: entity tag → physical tags.
    pub(super) entity_groups: [HashMap<i32, Vec<i32>>; 4],
    pub(super) node_index: HashMap<u64, usize>,
    pub(super) node_tags: Vec<u64>,
    pub(super) coords: Vec<Vec3>,
    pub(super) nodes_read: bool,
    /// One list per [`Kind`], indexed by `Kind::index`.
    pub(super) elements: [ElementList; Kind::ALL.len()],
    pub(super) volume_kind: Option<Kind>,
    pub(super) skipped: Vec<String>,
}

impl Raw {
    pub(super) fn list(&self, kind: Kind) -> &ElementList {
        &self.elements[kind.index()]
    }

    pub(super) fn groups(&self, dim: usize, entity: i32) -> &[i32] {
        self.entity_groups
            .get(dim)
            .and_then(|m| m.get(&entity))
            .map_or(&[], Vec::as_slice)
    }

    pub(super) fn group_name(&self, dim: usize, tag: i32) -> String {
        self.physical_names
            .get(&(dim, tag))
            .cloned()
            .unwrap_or_else(|| format!("physical{dim}d{tag}"))
    }
}

pub(super) fn read_sections(c: &mut Cursor) -> Result<Raw, GmshError> {
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
    let mut ids = [0usize; crate::fem::MAX_CELL_NODES];
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

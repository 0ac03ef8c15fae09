//! What was read made a validated [`Mesh`]: cells and their nodes numbered
//! from 0 in file order, bodies, cell orientation, facet and node sets.

use std::collections::{BTreeMap, HashMap};

use super::deck::{Fail, Loc};
use super::error::InpErrorKind;
use super::kind::{abaqus_faces, Kind};
use super::read::{Raw, DEFAULT_BODY};
use super::sets::{Face, Sets};
use crate::mesh::orient::orient_cells;
use crate::mesh::topology::face_key;
use crate::mesh::{FacetRef, Mesh, MeshError};

/// How many element ids or set names a message lists before `...`.
const LISTED: usize = 12;

/// The read elements with their nodes as indices into the read nodes, and
/// the mesh's ids of both.
struct Numbering<'a> {
    raw: &'a Raw,
    /// Read node index of each element node, laid out as `raw.elements.nodes`.
    nodes: Vec<usize>,
    /// Mesh node of each read node (None: no cell uses it).
    new_node: Vec<Option<usize>>,
    /// Read element of each cell, and the cell of each read element.
    cells: Vec<usize>,
    cell_of: Vec<Option<usize>>,
}

impl Numbering<'_> {
    fn nodes_of(&self, e: usize) -> &[usize] {
        let start = &self.raw.elements.start;
        let from = start.get(e).copied().unwrap_or(0);
        let to = start.get(e + 1).copied().unwrap_or(from);
        self.nodes.get(from..to).unwrap_or_default()
    }

    /// Mesh nodes of element `e`, or None if one is on no cell.
    fn mesh_nodes(&self, e: usize) -> Option<Vec<usize>> {
        self.nodes_of(e)
            .iter()
            .map(|&n| self.new_node.get(n).copied().flatten())
            .collect()
    }

    fn id(&self, e: usize) -> u64 {
        self.raw.elements.ids.get(e).copied().unwrap_or_default()
    }

    fn loc(&self, e: usize) -> Option<Loc> {
        self.raw.elements.locs.get(e).copied()
    }

    fn fail(&self, e: usize, kind: InpErrorKind) -> Fail {
        Fail {
            at: self.loc(e),
            kind,
        }
    }

    /// Type and `*ELEMENT` set of element `e`, for messages.
    fn type_and_set(&self, e: usize) -> (String, String) {
        let block = self.raw.elements.blocks.get(e).copied().unwrap_or_default();
        let set = self
            .raw
            .blocks
            .get(block as usize)
            .and_then(|b| b.elset.clone());
        (
            self.raw.type_name(block),
            set.unwrap_or_else(|| "(none)".into()),
        )
    }
}

/// What assembling did besides the mesh.
pub(super) struct Counts {
    /// Cells that came fully inverted and were renumbered.
    pub(super) reoriented: usize,
    /// Nodes that no cell uses (dropped).
    pub(super) unused_nodes: usize,
}

/// The mesh of what was read: `bodies` are the element sets that are the
/// bodies (empty: each `*ELEMENT` line's set), `names` the spelling of the
/// set names the caller uses.
pub(super) fn assemble(
    raw: &Raw,
    bodies: &[String],
    names: &[String],
) -> Result<(Mesh, Counts), Fail> {
    let (cell_type, _, _) = raw
        .cell_type
        .ok_or_else(|| Fail::whole_file(InpErrorKind::NoVolumeCells))?;
    let num = numbering(raw)?;
    let mut mesh = Mesh::empty(cell_type);
    mesh.nodes = raw
        .coords
        .iter()
        .zip(&num.new_node)
        .filter(|(_, id)| id.is_some())
        .map(|(x, _)| *x)
        .collect();
    mesh.cells = num
        .cells
        .iter()
        .flat_map(|&e| num.nodes_of(e))
        .filter_map(|&n| num.new_node.get(n).copied().flatten())
        .collect();
    let sets = Sets::resolve(raw)?;
    (mesh.bodies, mesh.cell_body) = body_sets(&num, &sets, bodies)?;
    let reoriented = orient_cells(&mut mesh).map_err(|t| {
        let e = num.cells.get(t.cell).copied().unwrap_or_default();
        let kind = InpErrorKind::TangledCell {
            element: num.id(e),
            min: t.min,
            max: t.max,
        };
        num.fail(e, kind)
    })?;
    let spelling: HashMap<String, &String> = names.iter().map(|n| (n.to_uppercase(), n)).collect();
    let name = |key: &str, first: &str| spelling.get(key).map_or(first, |s| s).to_string();
    let facets = facet_sets(&mesh, &num, &sets)?;
    for (key, (first, nodes)) in node_sets(&num, &sets) {
        mesh.node_sets.insert(name(&key, &first), nodes);
    }
    for (key, (first, mut list)) in facets {
        list.sort_unstable();
        list.dedup();
        let name = name(&key, &first);
        if !sets.nodes.contains_key(&key) {
            let mut nodes: Vec<usize> = Vec::new();
            for f in &list {
                nodes.extend(mesh.facet_nodes_iter(f).into_iter().flatten());
            }
            nodes.sort_unstable();
            nodes.dedup();
            mesh.node_sets.insert(name.clone(), nodes);
        }
        mesh.facet_sets.insert(name, list);
    }
    mesh.validate().map_err(|error| invalid(&num, error))?;
    let counts = Counts {
        reoriented,
        unused_nodes: raw.coords.len() - mesh.nodes.len(),
    };
    Ok((mesh, counts))
}

/// Element nodes as read-node indices; cells in file order; nodes that
/// cells use, numbered in file order.
fn numbering(raw: &Raw) -> Result<Numbering<'_>, Fail> {
    let e = &raw.elements;
    let mut nodes = Vec::with_capacity(e.nodes.len());
    for k in 0..e.len() {
        for &node in e.nodes_of(k) {
            let Some(&n) = raw.node_index.get(&node) else {
                let element = e.ids.get(k).copied().unwrap_or_default();
                let kind = InpErrorKind::UnknownNode { element, node };
                return Err(Fail {
                    at: e.locs.get(k).copied(),
                    kind,
                });
            };
            nodes.push(n);
        }
    }
    let cells: Vec<usize> = (0..e.len())
        .filter(|&k| matches!(e.kinds.get(k), Some(Kind::Cell(_))))
        .collect();
    let mut cell_of = vec![None; e.len()];
    for (c, &k) in cells.iter().enumerate() {
        cell_of[k] = Some(c);
    }
    let mut num = Numbering {
        raw,
        nodes,
        new_node: Vec::new(),
        cells,
        cell_of,
    };
    let mut used = vec![false; raw.coords.len()];
    for &k in &num.cells {
        for &n in num.nodes_of(k) {
            used[n] = true;
        }
    }
    let mut next = 0;
    num.new_node = used
        .iter()
        .map(|&u| {
            u.then(|| {
                next += 1;
                next - 1
            })
        })
        .collect();
    Ok(num)
}

/// Body names and each cell's body: the element sets `bodies` names (in
/// the order the file defines them), or else each `*ELEMENT` line's set.
fn body_sets(
    num: &Numbering,
    sets: &Sets,
    bodies: &[String],
) -> Result<(Vec<String>, Vec<u32>), Fail> {
    if bodies.is_empty() {
        return Ok(element_line_bodies(num));
    }
    let mut chosen: Vec<(usize, &String, &[usize])> = Vec::new();
    for name in bodies {
        let key = name.to_uppercase();
        let set = sets
            .elements
            .get(&key)
            .filter(|s| has_cells(num, &s.members));
        let Some(set) = set else {
            let known: Vec<&str> = sets
                .element_order
                .iter()
                .filter_map(|k| sets.elements.get(k))
                .filter(|s| has_cells(num, &s.members))
                .map(|s| s.name.as_str())
                .collect();
            let known = listed(&known, "none");
            let kind = InpErrorKind::UnknownBodySet {
                name: name.clone(),
                known,
            };
            return Err(Fail::whole_file(kind));
        };
        let order = sets.element_order.iter().position(|k| *k == key);
        chosen.push((order.unwrap_or(usize::MAX), name, &set.members));
    }
    chosen.sort_by_key(|c| c.0);
    let mut cell_body = vec![u32::MAX; num.cells.len()];
    for (b, (_, name, members)) in chosen.iter().enumerate() {
        let b = u32::try_from(b).unwrap_or(u32::MAX);
        for &e in members.iter() {
            let Some(Some(c)) = num.cell_of.get(e).copied() else {
                continue;
            };
            let owner = cell_body[c];
            if owner == u32::MAX || owner == b {
                cell_body[c] = b;
                continue;
            }
            let first = chosen.get(owner as usize).map_or("", |o| o.1.as_str());
            let kind = InpErrorKind::ElementInTwoBodies {
                element: num.id(e),
                first: first.to_string(),
                second: name.to_string(),
            };
            return Err(num.fail(e, kind));
        }
    }
    let orphans: Vec<usize> = (0..num.cells.len())
        .filter(|&c| cell_body[c] == u32::MAX)
        .map(|c| num.cells[c])
        .collect();
    if let Some(&first) = orphans.first() {
        let ids: Vec<String> = orphans.iter().map(|&e| num.id(e).to_string()).collect();
        let names: Vec<&str> = chosen.iter().map(|c| c.1.as_str()).collect();
        let kind = InpErrorKind::ElementsWithoutBody {
            count: orphans.len(),
            bodies: names.join(", "),
            list: listed(&ids, ""),
        };
        return Err(num.fail(first, kind));
    }
    let names = chosen.iter().map(|c| c.1.clone()).collect();
    Ok((names, cell_body))
}

/// One body per `ELSET=` of the `*ELEMENT` lines of cells (case-insensitive,
/// spelled as first written), in the order first met.
fn element_line_bodies(num: &Numbering) -> (Vec<String>, Vec<u32>) {
    let mut names: Vec<String> = Vec::new();
    let mut keys: Vec<String> = Vec::new();
    let mut cell_body = Vec::with_capacity(num.cells.len());
    for &e in &num.cells {
        let block = num.raw.elements.blocks.get(e).copied().unwrap_or_default();
        let set = num
            .raw
            .blocks
            .get(block as usize)
            .and_then(|b| b.elset.as_deref());
        let name = set.unwrap_or(DEFAULT_BODY);
        let key = name.to_uppercase();
        let b = keys.iter().position(|k| *k == key).unwrap_or_else(|| {
            keys.push(key);
            names.push(name.to_string());
            keys.len() - 1
        });
        cell_body.push(u32::try_from(b).unwrap_or(u32::MAX));
    }
    (names, cell_body)
}

fn has_cells(num: &Numbering, members: &[usize]) -> bool {
    members
        .iter()
        .any(|&e| num.cell_of.get(e).is_some_and(Option::is_some))
}

/// Facet sets by upper-case name: the faces of each `*SURFACE`, and the
/// triangles and quadrilaterals of each element set, each matched to the
/// boundary face with its nodes (every one of them, in a set or not).
fn facet_sets(
    mesh: &Mesh,
    num: &Numbering,
    sets: &Sets,
) -> Result<BTreeMap<String, (String, Vec<FacetRef>)>, Fail> {
    let boundary = mesh.boundary_faces_by_key();
    let kinds = &num.raw.elements.kinds;
    let mut facet_of: Vec<Option<FacetRef>> = vec![None; kinds.len()];
    for (e, kind) in kinds.iter().enumerate() {
        let Kind::Facet(found) = *kind else {
            continue;
        };
        let (ty, set) = num.type_and_set(e);
        let element = num.id(e);
        let facet = num.mesh_nodes(e).and_then(|nodes| {
            let corners = nodes.get(..found.corners())?;
            boundary.get(&face_key(corners.iter().copied()))
        });
        let Some(&facet) = facet else {
            let kind = InpErrorKind::FacetNotOnCell { ty, element, set };
            return Err(num.fail(e, kind));
        };
        let expected = mesh.facet_type(&facet);
        if found != expected {
            let kind = InpErrorKind::FacetTypeMismatch {
                ty,
                element,
                set,
                found,
                cells: mesh.cell_type,
                expected,
            };
            return Err(num.fail(e, kind));
        }
        facet_of[e] = Some(facet);
    }
    let mut out: BTreeMap<String, (String, Vec<FacetRef>)> = BTreeMap::new();
    for (key, set) in &sets.elements {
        let facets: Vec<FacetRef> = set
            .members
            .iter()
            .filter_map(|&e| facet_of.get(e).copied().flatten())
            .collect();
        if !facets.is_empty() {
            let entry = out
                .entry(key.clone())
                .or_insert_with(|| (set.name.clone(), vec![]));
            entry.1.extend(facets);
        }
    }
    for (key, (name, faces)) in &sets.surfaces {
        let facets = faces
            .iter()
            .map(|&face| local_face(mesh, num, name, face))
            .collect::<Result<Vec<_>, _>>()?;
        let entry = out
            .entry(key.clone())
            .or_insert_with(|| (name.clone(), vec![]));
        entry.1.extend(facets);
    }
    Ok(out)
}

/// The mesh facet of face S<k + 1> of a read element: the local face of its
/// cell with the same nodes (the cell may have been renumbered).
fn local_face(mesh: &Mesh, num: &Numbering, surface: &str, (e, k): Face) -> Result<FacetRef, Fail> {
    let cell = num.cell_of.get(e).copied().flatten();
    let nodes = num.mesh_nodes(e);
    let local = abaqus_faces(mesh.cell_type).get(k);
    let found = cell.zip(nodes).zip(local).and_then(|((c, nodes), local)| {
        let key = face_key(local.iter().filter_map(|&l| nodes.get(l).copied()));
        let ids = mesh.try_cell(c).ok()?;
        let cell_type = mesh.cell_type;
        // The local face tables index within the cell's nodes, corners first.
        let face = (0..cell_type.local_faces().len()).position(|f| {
            let corners = &cell_type.local_faces()[f][..cell_type.face_type(f).corners()];
            face_key(corners.iter().map(|&l| ids[l])) == key
        })?;
        Some(FacetRef {
            cell: c,
            face: u8::try_from(face).ok()?,
        })
    });
    found.ok_or_else(|| {
        let (ty, _) = num.type_and_set(e);
        let kind = InpErrorKind::BadFace {
            surface: surface.to_string(),
            label: format!("S{}", k + 1).into(),
            element: num.id(e),
            ty,
        };
        num.fail(e, kind)
    })
}

/// Node sets by upper-case name, nodes that no cell uses left out.
fn node_sets(num: &Numbering, sets: &Sets) -> BTreeMap<String, (String, Vec<usize>)> {
    sets.nodes
        .iter()
        .map(|(key, set)| {
            let mut nodes: Vec<usize> = set
                .members
                .iter()
                .filter_map(|&n| num.new_node.get(n).copied().flatten())
                .collect();
            nodes.sort_unstable();
            nodes.dedup();
            (key.clone(), (set.name.clone(), nodes))
        })
        .collect()
}

/// A validation error, with the element of the cell it names.
fn invalid(num: &Numbering, error: MeshError) -> Fail {
    let cell = match &error {
        MeshError::InvertedCell { cell, .. }
        | MeshError::NodeOutOfRange { cell, .. }
        | MeshError::BodyOutOfRange { cell, .. }
        | MeshError::FacetOutOfRange { cell, .. }
        | MeshError::DuplicateFacet { cell, .. }
        | MeshError::InconsistentOrientation { cell, .. } => Some(*cell),
        _ => None,
    };
    let e = cell.and_then(|c| num.cells.get(c).copied());
    let kind = InpErrorKind::Invalid {
        error: Box::new(error),
        element: e.map(|e| num.id(e)),
    };
    Fail {
        at: e.and_then(|e| num.loc(e)),
        kind,
    }
}

/// Items joined by commas, the first [`LISTED`] of them, or `empty`.
fn listed<T: AsRef<str>>(items: &[T], empty: &str) -> String {
    if items.is_empty() {
        return empty.to_string();
    }
    let shown: Vec<&str> = items.iter().take(LISTED).map(AsRef::as_ref).collect();
    let more = items.len().saturating_sub(LISTED);
    if more > 0 {
        format!("{} and {more} more", shown.join(", "))
    } else {
        shown.join(", ")
    }
}

//! The set and surface definitions resolved, in file order, to the elements
//! and nodes they hold: a set name inside a list is that set as defined so
//! far, a `GENERATE` range the defined ids in it.

use std::collections::{BTreeMap, HashMap};

use super::deck::{Fail, Loc};
use super::error::InpErrorKind;
use super::kind::{abaqus_faces, Kind};
use super::read::{Def, FaceLine, Member, Raw, SetKind, Target};

/// A set as resolved: its name as first written, and its members (indices
/// into the read nodes or elements; repeats possible).
#[derive(Debug, Default)]
pub(super) struct Set {
    pub(super) name: String,
    pub(super) members: Vec<usize>,
}

/// A face of an element: the element's index and its face (0 for S1).
pub(super) type Face = (usize, usize);

/// Every set and surface, by upper-case name.
#[derive(Debug, Default)]
pub(super) struct Sets {
    pub(super) nodes: BTreeMap<String, Set>,
    pub(super) elements: BTreeMap<String, Set>,
    /// Element set names in the order first defined.
    pub(super) element_order: Vec<String>,
    pub(super) surfaces: BTreeMap<String, (String, Vec<Face>)>,
}

/// Ids sorted with their index, built once when a `GENERATE` range is
/// larger than the ids defined.
struct Ids<'a> {
    index: &'a HashMap<u64, usize>,
    sorted: Option<Vec<(u64, usize)>>,
}

impl Ids<'_> {
    /// Indices of the defined ids first, first + step, ..., up to last: at
    /// most as many steps as there are ids, whatever the range.
    fn range(&mut self, first: u64, last: u64, step: u64, out: &mut Vec<usize>) {
        let count = (last - first) / step + 1;
        if count <= self.index.len() as u64 {
            for k in 0..count {
                if let Some(&i) = self.index.get(&(first + k * step)) {
                    out.push(i);
                }
            }
            return;
        }
        let index = self.index;
        let sorted = self.sorted.get_or_insert_with(|| {
            let mut all: Vec<(u64, usize)> = index.iter().map(|(&id, &i)| (id, i)).collect();
            all.sort_unstable();
            all
        });
        let from = sorted.partition_point(|&(id, _)| id < first);
        for &(id, i) in sorted.get(from..).unwrap_or_default() {
            if id > last {
                break;
            }
            if (id - first).is_multiple_of(step) {
                out.push(i);
            }
        }
    }
}

impl Sets {
    pub(super) fn resolve(raw: &Raw) -> Result<Sets, Fail> {
        let mut sets = Sets::default();
        let mut node_ids = Ids {
            index: &raw.node_index,
            sorted: None,
        };
        let mut element_ids = Ids {
            index: &raw.element_index,
            sorted: None,
        };
        for def in &raw.defs {
            match def {
                Def::Set {
                    kind: SetKind::Node,
                    name,
                    members,
                } => {
                    let new = sets.list(members, SetKind::Node, name, &mut node_ids)?;
                    extend(&mut sets.nodes, name, new);
                }
                Def::Set {
                    kind: SetKind::Element,
                    name,
                    members,
                } => {
                    let new = sets.list(members, SetKind::Element, name, &mut element_ids)?;
                    if !sets.elements.contains_key(&name.to_uppercase()) {
                        sets.element_order.push(name.to_uppercase());
                    }
                    extend(&mut sets.elements, name, new);
                }
                Def::Surface { name, faces } => {
                    let new = sets.faces(raw, name, faces)?;
                    let entry = sets
                        .surfaces
                        .entry(name.to_uppercase())
                        .or_insert_with(|| (name.clone(), Vec::new()));
                    entry.1.extend(new);
                }
            }
        }
        Ok(sets)
    }

    /// The members of one list, set names resolved against the sets so far.
    fn list(
        &self,
        members: &[Member],
        kind: SetKind,
        name: &str,
        ids: &mut Ids,
    ) -> Result<Vec<usize>, Fail> {
        let (defined, what, item) = match kind {
            SetKind::Node => (&self.nodes, "node set", "node"),
            SetKind::Element => (&self.elements, "element set", "element"),
        };
        let mut out = Vec::new();
        for m in members {
            match m {
                Member::Id(id, at) => match ids.index.get(id) {
                    Some(&i) => out.push(i),
                    None => {
                        let kind = InpErrorKind::UnknownMember {
                            what,
                            set: name.to_string(),
                            item,
                            id: *id,
                        };
                        return Err(Fail::at(*at, kind));
                    }
                },
                Member::Range(first, last, step, _) => ids.range(*first, *last, *step, &mut out),
                Member::Set(other, at) => {
                    let set = defined
                        .get(&other.to_uppercase())
                        .ok_or_else(|| unknown_set(what, other, *at))?;
                    out.extend_from_slice(&set.members);
                }
            }
        }
        Ok(out)
    }

    /// The faces of one `*SURFACE`: each line's element (or each element of
    /// its set) must be a 3D element with that face.
    fn faces(&self, raw: &Raw, surface: &str, lines: &[FaceLine]) -> Result<Vec<Face>, Fail> {
        let mut out = Vec::new();
        for line in lines {
            let elements: Vec<usize> = match &line.target {
                Target::Element(id) => {
                    let e = raw.element_index.get(id).copied().ok_or_else(|| {
                        let kind = InpErrorKind::UnknownMember {
                            what: "surface",
                            set: surface.to_string(),
                            item: "element",
                            id: *id,
                        };
                        Fail::at(line.at, kind)
                    })?;
                    vec![e]
                }
                Target::Set(name) => self
                    .elements
                    .get(&name.to_uppercase())
                    .ok_or_else(|| unknown_set("element set", name, line.at))?
                    .members
                    .clone(),
            };
            for e in elements {
                out.push((e, face_number(raw, surface, e, line)?));
            }
        }
        Ok(out)
    }
}

/// The face `S<k>` of element `e` as k − 1, if `e` is a 3D element with it.
fn face_number(raw: &Raw, surface: &str, e: usize, line: &FaceLine) -> Result<usize, Fail> {
    let element = raw.elements.ids.get(e).copied().unwrap_or_default();
    let block = raw.elements.blocks.get(e).copied().unwrap_or_default();
    let ty = raw.type_name(block);
    let Some(Kind::Cell(cell)) = raw.elements.kinds.get(e).copied() else {
        let kind = InpErrorKind::FaceOfNonCell {
            surface: surface.to_string(),
            element,
            ty,
        };
        return Err(Fail::at(line.at, kind));
    };
    let faces = abaqus_faces(cell).len();
    line.label
        .strip_prefix('S')
        .and_then(|k| k.parse::<usize>().ok())
        .filter(|k| (1..=faces).contains(k))
        .map(|k| k - 1)
        .ok_or_else(|| {
            let kind = InpErrorKind::BadFace {
                surface: surface.to_string(),
                label: line.label.as_str().into(),
                element,
                ty,
            };
            Fail::at(line.at, kind)
        })
}

fn extend(sets: &mut BTreeMap<String, Set>, name: &str, members: Vec<usize>) {
    let set = sets.entry(name.to_uppercase()).or_insert_with(|| Set {
        name: name.to_string(),
        members: Vec::new(),
    });
    set.members.extend(members);
}

fn unknown_set(kind: &'static str, name: &str, at: Loc) -> Fail {
    let name = name.to_string();
    Fail::at(at, InpErrorKind::UnknownSet { kind, name })
}

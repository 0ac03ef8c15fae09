//! The keywords the reader reads, into [`Raw`] (file ids, sets as written);
//! every other keyword skipped and remembered. `assemble` makes a mesh of it.

use std::collections::{HashMap, HashSet};

use super::deck::{shorten, unquote, DataLine, Fail, Handler, Keyword, Loc};
use super::error::InpErrorKind;
use super::kind::{classify, Class, Kind};
use crate::mesh::CellType;
use crate::vec3::Vec3;

/// The body of 3D elements whose `*ELEMENT` line names no `ELSET`, when the
/// bodies are taken from those lines.
pub(super) const DEFAULT_BODY: &str = "EALL";

/// Keywords whose meaning the mesh would miss: they are errors, not notes.
const GENERATION: [&str; 8] = [
    "NGEN", "NFILL", "NCOPY", "NMAP", "ELGEN", "ELCOPY", "SYSTEM", "NODE GEN",
];

/// Keywords of parts and instances.
const PARTS: [&str; 6] = [
    "PART",
    "END PART",
    "ASSEMBLY",
    "END ASSEMBLY",
    "INSTANCE",
    "END INSTANCE",
];

/// Elements as read: file ids, kinds, nodes as file ids.
#[derive(Debug, Default)]
pub(super) struct Elements {
    pub(super) ids: Vec<u64>,
    pub(super) kinds: Vec<Kind>,
    /// Index into [`Raw::blocks`]: the `*ELEMENT` line the element is under.
    pub(super) blocks: Vec<u32>,
    pub(super) locs: Vec<Loc>,
    /// Element `e`'s nodes are `nodes[start[e]..start[e + 1]]`.
    pub(super) start: Vec<usize>,
    pub(super) nodes: Vec<u64>,
}

impl Elements {
    pub(super) fn len(&self) -> usize {
        self.ids.len()
    }

    pub(super) fn nodes_of(&self, e: usize) -> &[u64] {
        let from = self.start.get(e).copied().unwrap_or(0);
        let to = self.start.get(e + 1).copied().unwrap_or(from);
        self.nodes.get(from..to).unwrap_or_default()
    }
}

/// An `*ELEMENT` line: its type as written (upper case) and its `ELSET`.
#[derive(Debug)]
pub(super) struct ElementBlock {
    pub(super) ty: String,
    pub(super) elset: Option<String>,
}

/// One entry of a set's list.
#[derive(Debug, Clone, PartialEq)]
pub(super) enum Member {
    Id(u64, Loc),
    /// `GENERATE`: first, last, step.
    Range(u64, u64, u64, Loc),
    /// Another set of the same kind, by name as written.
    Set(String, Loc),
}

#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(super) enum SetKind {
    Node,
    Element,
}

/// A face line of `*SURFACE, TYPE=ELEMENT`: an element or element set, and
/// the face label as written (`S3`).
#[derive(Debug, Clone, PartialEq)]
pub(super) struct FaceLine {
    pub(super) target: Target,
    pub(super) label: String,
    pub(super) at: Loc,
}

#[derive(Debug, Clone, PartialEq)]
pub(super) enum Target {
    Element(u64),
    Set(String),
}

/// A set or surface definition, in file order (a name used inside a list
/// means that set as defined so far).
#[derive(Debug)]
pub(super) enum Def {
    Set {
        kind: SetKind,
        name: String,
        members: Vec<Member>,
    },
    Surface {
        name: String,
        faces: Vec<FaceLine>,
    },
}

/// The keyword block the data lines belong to.
#[derive(Debug, Default)]
enum Block {
    #[default]
    None,
    Skip,
    Nodes {
        def: Option<usize>,
    },
    Elements {
        kind: Kind,
        block: u32,
        def: Option<usize>,
        pending: Option<Pending>,
    },
    /// A set's list; `first_only` for a node surface (its lines may carry
    /// a weight after the node or set).
    Set {
        def: usize,
        generate: bool,
        first_only: bool,
    },
    Faces {
        def: usize,
    },
}

/// An element whose node list continues on the next line.
#[derive(Debug)]
struct Pending {
    id: u64,
    nodes: Vec<u64>,
    at: Loc,
}

/// Everything read, before it becomes a mesh.
#[derive(Debug, Default)]
pub(super) struct Raw {
    pub(super) node_index: HashMap<u64, usize>,
    pub(super) node_ids: Vec<u64>,
    pub(super) coords: Vec<Vec3>,
    pub(super) elements: Elements,
    pub(super) element_index: HashMap<u64, usize>,
    pub(super) blocks: Vec<ElementBlock>,
    /// The cell type, and the first cell's element id and line.
    pub(super) cell_type: Option<(CellType, u64, Loc)>,
    pub(super) defs: Vec<Def>,
    /// Keywords skipped, each once, where first seen.
    pub(super) skipped: Vec<(String, Loc)>,
    seen: HashSet<String>,
    /// The first unsupported facet, beam or other non-volume type: reported
    /// after reading, unless a volume problem comes first.
    deferred: Option<Fail>,
    block: Block,
}

impl Raw {
    /// Ends the reading: an element left incomplete, or a deferred error.
    pub(super) fn finish(&mut self) -> Result<(), Fail> {
        self.close_block()?;
        self.deferred.take().map_or(Ok(()), Err)
    }

    fn close_block(&mut self) -> Result<(), Fail> {
        if let Block::Elements {
            pending: Some(p),
            block,
            kind,
            ..
        } = std::mem::take(&mut self.block)
        {
            return Err(self.node_count(&p, block, kind.nodes()));
        }
        Ok(())
    }

    fn node_count(&self, p: &Pending, block: u32, expected: usize) -> Fail {
        let kind = InpErrorKind::NodeCount {
            element: p.id,
            ty: self.type_name(block),
            expected,
            found: p.nodes.len(),
        };
        Fail::at(p.at, kind)
    }

    pub(super) fn type_name(&self, block: u32) -> String {
        self.blocks
            .get(block as usize)
            .map_or_else(String::new, |b| b.ty.clone())
    }

    fn new_def(&mut self, def: Def) -> usize {
        self.defs.push(def);
        self.defs.len() - 1
    }

    fn members(&mut self, def: usize) -> Option<&mut Vec<Member>> {
        match self.defs.get_mut(def) {
            Some(Def::Set { members, .. }) => Some(members),
            _ => None,
        }
    }

    fn set_def(&mut self, kind: SetKind, name: &str) -> usize {
        self.new_def(Def::Set {
            kind,
            name: name.to_string(),
            members: Vec::new(),
        })
    }

    fn node_keyword(&mut self, k: &Keyword) -> Result<Block, Fail> {
        self.params(k, &["NSET", "SYSTEM"])?;
        if let Some(system) = k.value("SYSTEM").filter(|s| !s.eq_ignore_ascii_case("R")) {
            let kind = InpErrorKind::BadParameter {
                keyword: "NODE",
                parameter: "SYSTEM",
                value: system.to_string(),
                expected: "coordinates are read as rectangular (SYSTEM=R)",
            };
            return Err(Fail::at(k.at, kind));
        }
        let def = k.value("NSET").map(|n| self.set_def(SetKind::Node, n));
        Ok(Block::Nodes { def })
    }

    fn element_keyword(&mut self, k: &Keyword) -> Result<Block, Fail> {
        self.params(k, &["TYPE", "ELSET"])?;
        let ty = k.require("TYPE")?.to_uppercase();
        let elset = k.value("ELSET").map(str::to_string);
        let kind = match classify(&ty) {
            Class::Read(kind) => kind,
            Class::OtherVolume => {
                let fail = Fail::at(k.at, InpErrorKind::OtherVolume { ty });
                return self.defer(fail, true);
            }
            Class::Unsupported(what) => {
                let set = elset.unwrap_or_else(|| "(none)".into());
                let fail = Fail::at(k.at, InpErrorKind::Unsupported { ty, what, set });
                return self.defer(fail, false);
            }
            Class::Unknown => return Err(Fail::at(k.at, InpErrorKind::UnknownType(ty))),
        };
        let set = match (&elset, kind) {
            (Some(name), _) => Some(name.as_str()),
            (None, Kind::Cell(_)) => Some(DEFAULT_BODY),
            (None, Kind::Facet(_)) => None,
        };
        let def = set.map(|n| self.set_def(SetKind::Element, n));
        let block = u32::try_from(self.blocks.len()).unwrap_or(u32::MAX);
        self.blocks.push(ElementBlock { ty, elset });
        Ok(Block::Elements {
            kind,
            block,
            def,
            pending: None,
        })
    }

    /// A type the mesh cannot hold: an error now for 3D elements, after the
    /// reading otherwise (a second-order volume mesh reports its volumes,
    /// not the facets a mesher writes before them).
    fn defer(&mut self, fail: Fail, now: bool) -> Result<Block, Fail> {
        if now {
            return Err(fail);
        }
        self.deferred.get_or_insert(fail);
        Ok(Block::Skip)
    }

    fn set_keyword(&mut self, k: &Keyword, kind: SetKind) -> Result<Block, Fail> {
        let param = match kind {
            SetKind::Node => "NSET",
            SetKind::Element => "ELSET",
        };
        self.params(k, &[param, "GENERATE", "INTERNAL", "UNSORTED"])?;
        let name = k.require(param)?.to_string();
        let def = self.set_def(kind, &name);
        let generate = k.has("GENERATE");
        Ok(Block::Set {
            def,
            generate,
            first_only: false,
        })
    }

    fn surface_keyword(&mut self, k: &Keyword) -> Result<Block, Fail> {
        self.params(k, &["NAME", "TYPE", "INTERNAL"])?;
        let name = k.require("NAME")?.to_string();
        let ty = k.value("TYPE").unwrap_or("ELEMENT").to_uppercase();
        match ty.as_str() {
            "ELEMENT" => {
                let def = self.new_def(Def::Surface {
                    name,
                    faces: Vec::new(),
                });
                Ok(Block::Faces { def })
            }
            // A node surface is a node set of that name.
            "NODE" => {
                let def = self.set_def(SetKind::Node, &name);
                Ok(Block::Set {
                    def,
                    generate: false,
                    first_only: true,
                })
            }
            _ => Err(Fail::at(
                k.at,
                InpErrorKind::BadParameter {
                    keyword: "SURFACE",
                    parameter: "TYPE",
                    value: ty,
                    expected: "surfaces are TYPE=ELEMENT (faces) or TYPE=NODE",
                },
            )),
        }
    }

    fn node_line(&mut self, line: &DataLine, def: Option<usize>) -> Result<(), Fail> {
        let f = line.fields;
        if !(1..=7).contains(&f.len()) {
            let kind = InpErrorKind::FieldCount {
                what: "a *NODE line",
                expected: "id, x, y, z",
                found: f.len(),
            };
            return Err(Fail::at(line.at, kind));
        }
        let id = parse_id(f[0], "node", line.at)?;
        let mut x = [0.0; 3];
        for (slot, token) in x.iter_mut().zip(&f[1..]) {
            *slot = parse_coordinate(token, line.at)?;
        }
        let index = self.coords.len();
        if self.node_index.insert(id, index).is_some() {
            return Err(Fail::at(line.at, InpErrorKind::DuplicateNode(id)));
        }
        self.coords.push(x);
        self.node_ids.push(id);
        if let Some(members) = def.and_then(|d| self.members(d)) {
            members.push(Member::Id(id, line.at));
        }
        Ok(())
    }

    /// An element line, or the continuation of one.
    fn element_line(&mut self, line: &DataLine) -> Result<(), Fail> {
        let Block::Elements {
            kind,
            block,
            def,
            mut pending,
        } = std::mem::take(&mut self.block)
        else {
            return Ok(());
        };
        // A new element's line starts with its id; a continuation does not.
        let (mut p, skip) = match pending.take() {
            Some(p) => (p, 0),
            None => {
                let first = line.fields.first().copied().unwrap_or_default();
                let id = parse_id(first, "element", line.at)?;
                let nodes = Vec::with_capacity(kind.nodes());
                (
                    Pending {
                        id,
                        nodes,
                        at: line.at,
                    },
                    1,
                )
            }
        };
        for token in line.fields.iter().skip(skip) {
            p.nodes.push(parse_id(token, "node", line.at)?);
        }
        let needed = kind.nodes();
        if p.nodes.len() > needed || (p.nodes.len() < needed && !line.continued) {
            return Err(self.node_count(&p, block, needed));
        }
        if p.nodes.len() < needed {
            pending = Some(p);
        } else {
            self.add_element(p, kind, block, def)?;
        }
        self.block = Block::Elements {
            kind,
            block,
            def,
            pending,
        };
        Ok(())
    }

    fn add_element(
        &mut self,
        p: Pending,
        kind: Kind,
        block: u32,
        def: Option<usize>,
    ) -> Result<(), Fail> {
        let index = self.elements.len();
        if self.element_index.insert(p.id, index).is_some() {
            return Err(Fail::at(p.at, InpErrorKind::DuplicateElement(p.id)));
        }
        if let Kind::Cell(cell) = kind {
            match self.cell_type {
                None => self.cell_type = Some((cell, p.id, p.at)),
                Some((first_type, first, first_at)) if first_type != cell => {
                    let kind = InpErrorKind::MixedCellTypes {
                        element: p.id,
                        found: cell.name(),
                        first,
                        first_line: first_at.line as usize,
                        first_type: first_type.name(),
                    };
                    return Err(Fail::at(p.at, kind));
                }
                Some(_) => {}
            }
        }
        let e = &mut self.elements;
        if e.start.is_empty() {
            e.start.push(0);
        }
        e.ids.push(p.id);
        e.kinds.push(kind);
        e.blocks.push(block);
        e.locs.push(p.at);
        e.nodes.extend_from_slice(&p.nodes);
        e.start.push(e.nodes.len());
        if let Some(members) = def.and_then(|d| self.members(d)) {
            members.push(Member::Id(p.id, p.at));
        }
        Ok(())
    }

    fn set_line(
        &mut self,
        line: &DataLine,
        def: usize,
        generate: bool,
        first_only: bool,
    ) -> Result<(), Fail> {
        let at = line.at;
        let mut new = Vec::new();
        if generate {
            let bad = || Fail::at(at, InpErrorKind::BadGenerate(shorten(line.text)));
            let ids: Vec<u64> = line
                .fields
                .iter()
                .map(|t| t.parse::<u64>().map_err(|_| bad()))
                .collect::<Result<_, _>>()?;
            let (first, last, step) = match ids.as_slice() {
                [a, b] => (*a, *b, 1),
                [a, b, s] => (*a, *b, *s),
                _ => return Err(bad()),
            };
            if first == 0 || last < first || step == 0 {
                return Err(bad());
            }
            new.push(Member::Range(first, last, step, at));
        } else {
            let take = if first_only { 1 } else { line.fields.len() };
            for token in line.fields.iter().take(take).filter(|t| !t.is_empty()) {
                new.push(member(token, at)?);
            }
        }
        if let Some(members) = self.members(def) {
            members.extend(new);
        }
        Ok(())
    }

    fn face_line(&mut self, line: &DataLine, def: usize) -> Result<(), Fail> {
        let (target, label) = match line.fields {
            [t, l] | [t, l, ..] if !t.is_empty() && !l.is_empty() => (*t, *l),
            _ => {
                let kind = InpErrorKind::FieldCount {
                    what: "a *SURFACE line",
                    expected: "element or element set, face (S1..S6)",
                    found: line.fields.len(),
                };
                return Err(Fail::at(line.at, kind));
            }
        };
        let target = match member(target, line.at)? {
            Member::Set(name, _) => Target::Set(name),
            _ => Target::Element(parse_id(target, "element", line.at)?),
        };
        if let Some(Def::Surface { faces, .. }) = self.defs.get_mut(def) {
            faces.push(FaceLine {
                target,
                label: label.to_uppercase(),
                at: line.at,
            });
        }
        Ok(())
    }

    fn skip(&mut self, k: &Keyword) -> Block {
        if k.name != "HEADING" {
            self.note(k.name.clone(), k.at);
        }
        Block::Skip
    }

    /// Lists a keyword (or `KEYWORD, PARAMETER=`) not read, once.
    fn note(&mut self, what: String, at: Loc) {
        if self.seen.insert(what.clone()) {
            self.skipped.push((what, at));
        }
    }

    /// Notes the parameters of a keyword read that are not in `known`.
    fn params(&mut self, k: &Keyword, known: &[&str]) -> Result<(), Fail> {
        for p in k.unknown_params(known)? {
            self.note(format!("{}, {p}=", k.name), k.at);
        }
        Ok(())
    }
}

impl Handler for Raw {
    fn keyword(&mut self, k: Keyword) -> Result<(), Fail> {
        self.close_block()?;
        let name = k.name.as_str();
        self.block = match name {
            "NODE" => self.node_keyword(&k)?,
            "ELEMENT" => self.element_keyword(&k)?,
            "NSET" => self.set_keyword(&k, SetKind::Node)?,
            "ELSET" => self.set_keyword(&k, SetKind::Element)?,
            "SURFACE" => self.surface_keyword(&k)?,
            _ if PARTS.contains(&name) => {
                return Err(Fail::at(k.at, InpErrorKind::Parts(k.name.clone())))
            }
            _ if GENERATION.contains(&name) => {
                return Err(Fail::at(k.at, InpErrorKind::Generation(k.name.clone())))
            }
            _ => self.skip(&k),
        };
        Ok(())
    }

    fn data(&mut self, line: &DataLine) -> Result<(), Fail> {
        match self.block {
            Block::None => {
                let kind = InpErrorKind::DataBeforeKeyword(shorten(line.text));
                Err(Fail::at(line.at, kind))
            }
            Block::Skip => Ok(()),
            Block::Nodes { def } => self.node_line(line, def),
            Block::Elements { .. } => self.element_line(line),
            Block::Set {
                def,
                generate,
                first_only,
            } => self.set_line(line, def, generate, first_only),
            Block::Faces { def } => self.face_line(line, def),
        }
    }
}

/// A list entry: an id (it starts with a digit or a sign) or a set name.
fn member(token: &str, at: Loc) -> Result<Member, Fail> {
    if token.starts_with(|c: char| c.is_ascii_digit() || c == '-' || c == '+') {
        Ok(Member::Id(parse_id(token, "id", at)?, at))
    } else {
        Ok(Member::Set(unquote(token).to_string(), at))
    }
}

/// A node or element id: a positive integer.
pub(super) fn parse_id(token: &str, what: &'static str, at: Loc) -> Result<u64, Fail> {
    match token.parse::<u64>() {
        Ok(id) if id > 0 => Ok(id),
        Ok(_) => Err(Fail::at(
            at,
            InpErrorKind::BadId {
                what,
                id: token.to_string(),
            },
        )),
        Err(_) if token.parse::<i64>().is_ok() => Err(Fail::at(
            at,
            InpErrorKind::BadId {
                what,
                id: token.to_string(),
            },
        )),
        Err(_) => Err(Fail::at(
            at,
            InpErrorKind::BadNumber {
                what: "an id",
                token: shorten(token),
            },
        )),
    }
}

/// A finite coordinate; an empty field is 0, as in Abaqus; Fortran's `D`
/// exponent is read as `E`.
fn parse_coordinate(token: &str, at: Loc) -> Result<f64, Fail> {
    if token.is_empty() {
        return Ok(0.0);
    }
    let x = token
        .parse::<f64>()
        .or_else(|_| token.replace(['d', 'D'], "e").parse::<f64>());
    match x {
        Ok(x) if x.is_finite() => Ok(x),
        _ => Err(Fail::at(
            at,
            InpErrorKind::BadNumber {
                what: "a coordinate",
                token: shorten(token),
            },
        )),
    }
}

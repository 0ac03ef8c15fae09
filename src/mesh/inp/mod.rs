//! Reader for Abaqus/CalculiX input files (`.inp`): the mesh of a deck as
//! CalculiX, Gmsh (`-format inp`), FreeCAD, Salome and Abaqus/CAE (flat
//! input, without parts) write it. The physics stays in the scene.
//!
//! The format: keyword lines (`*ELEMENT, TYPE=C3D8, ELSET=Part`), keywords,
//! parameters and set names case-insensitive; data lines of comma-separated
//! fields, a trailing comma continuing an element's node list (and a keyword
//! line) on the next line; `**` comment lines and blank lines ignored;
//! `*INCLUDE, INPUT=file` reads a file relative to the including one, in
//! place (it may hold data lines of the block it is included in).
//!
//! What becomes what:
//!
//! * `*NODE` (optionally `NSET=`): nodes with arbitrary positive ids, sparse
//!   and in any order. Nodes that no 3D element uses are dropped, the rest
//!   numbered from 0 in file order; messages keep the file's ids.
//! * `*ELEMENT, TYPE=..` (optionally `ELSET=`): C3D4 (tet4), C3D10 (tet10),
//!   C3D6 (wedge6), C3D15 (wedge15), C3D8, C3D8R, C3D8I (hex8) and C3D20,
//!   C3D20R (hex20) cells, integrated by the program's rules for the cell
//!   (R and I name Abaqus' variants, not ours), one cell type per file.
//!   Abaqus numbers them as [`CellType`](crate::mesh::CellType) does; fully
//!   inverted cells are renumbered and counted, tangled ones are an error.
//!   Triangles and quadrilaterals of first and second order (S3, S4, S6,
//!   S8, CPS3, CPS6, M3D9, ...: what meshers write for boundary groups) must
//!   each be a boundary face of a cell, matched by their corners and of the
//!   face's type. Other 3D types (C3D27, ...), beams, trusses, springs and
//!   unknown types are one error naming the type, file and line.
//! * Bodies are element sets: the sets the scene's `[[body]]` names give (a
//!   3D element in none of them, or in two, is an error naming it); without
//!   names, each `ELSET=` of the `*ELEMENT` lines of 3D elements (`EALL` for
//!   those without one).
//! * `*NSET` and `*ELSET` (id lists, set names inside lists, `GENERATE`
//!   first, last, step): node sets, and element sets. An element set of
//!   triangles or quadrilaterals is a facet set and a node set.
//! * `*SURFACE, TYPE=ELEMENT` (the default): lines `element or set, S1..S6`,
//!   faces numbered as Abaqus does (C3D8: S1 = 1-2-3-4, S2 = 5-8-7-6, S3 =
//!   1-5-6-2, S4 = 2-6-7-3, S5 = 3-7-8-4, S6 = 4-8-5-1; C3D4: S1 = 1-2-3,
//!   S2 = 1-4-2, S3 = 2-4-3, S4 = 3-4-1; C3D6: S1 = 1-2-3, S2 = 4-6-5, S3 =
//!   1-4-5-2, S4 = 2-5-6-3, S5 = 3-6-4-1; second-order types as their
//!   corners), a facet set and a node set.
//!   `*SURFACE, TYPE=NODE`: a node set.
//! * A set name used inside a list must be defined above it (as CalculiX
//!   reads); a set named twice collects both. A node set wins over a facet
//!   set's node set of the same name.
//! * Every other keyword (`*MATERIAL`, `*STEP`, `*BOUNDARY`, ...) is skipped
//!   with its data lines and listed once in [`InpReport::note`]; `*HEADING`
//!   silently; so are the parameters of a keyword read that the reader does
//!   not read (`*NSET, FREQUENCY=`). Parts and instances and the mesh generation keywords (`*NGEN`,
//!   `*ELGEN`, ...) are errors: what they define would be missing.
//!
//! Every error is one line naming the file, the line and the element, node
//! or set id as the file writes it. The reader never panics on bad input; a
//! `GENERATE` range costs at most the number of ids defined.

mod assemble;
mod deck;
mod error;
mod kind;
mod read;
mod sets;
#[cfg(test)]
mod tests;

use std::path::{Path, PathBuf};

use super::Mesh;
use deck::Fail;
pub use error::{InpError, InpErrorKind};

/// What the scene asks of the file: the element sets that are its bodies,
/// and the spelling of the names it uses (Abaqus names are case-insensitive:
/// a set the scene spells `Top` is found as `TOP` and named `Top`).
#[derive(Debug, Clone, Default, PartialEq, Eq)]
pub struct InpRequest {
    /// Element sets that are the bodies, named as given; empty: each
    /// `ELSET=` of an `*ELEMENT` line of 3D elements is a body.
    pub bodies: Vec<String>,
    /// Node and facet set names as the scene spells them.
    pub names: Vec<String>,
}

/// What the reader did besides reading, for `check` and the run to print.
#[derive(Debug, Clone, Default, PartialEq, Eq)]
pub struct InpReport {
    /// The file read, as given.
    pub file: String,
    /// The files `*INCLUDE` read, in the order first read.
    pub included: Vec<PathBuf>,
    /// Keywords skipped and parameters not read, each once, with where it
    /// first appears (`*MATERIAL (line 120)`, `*STEP (steps.inp, line 3)`,
    /// `*NSET, FREQUENCY= (line 36)`).
    pub skipped: Vec<String>,
    /// Abaqus variants read as this program's cell with its own rule
    /// (`C3D8R`, `C3D8I`, `C3D20R`), each once, in file order.
    pub variants: Vec<String>,
    /// Cells that came fully inverted and were renumbered.
    pub reoriented: usize,
    /// Nodes that no 3D element uses (dropped).
    pub unused_nodes: usize,
}

impl InpReport {
    /// The note a run prints once: what was read and what was not.
    pub fn note(&self) -> String {
        let name = Path::new(&self.file)
            .file_name()
            .map_or(self.file.clone(), |n| n.to_string_lossy().into_owned());
        let mut note = format!("read the mesh of {name}");
        if !self.skipped.is_empty() {
            note.push_str(&format!(
                "; not read (the scene holds the physics): {}",
                self.skipped.join(", ")
            ));
        }
        if !self.variants.is_empty() {
            note.push_str(&format!(
                "; {} integrated by this program's full rule, not Abaqus' (`integration = \"reduced\"` in a [[body]] gives hex20 the 2x2x2 rule)",
                self.variants.join(", ")
            ));
        }
        if self.reoriented > 0 {
            note.push_str(&format!("; {} inverted cells renumbered", self.reoriented));
        }
        note
    }
}

/// Reads an `.inp` file (and what it includes) into a validated [`Mesh`].
pub fn read_inp(path: &Path, request: &InpRequest) -> Result<(Mesh, InpReport), InpError> {
    let name = path.display().to_string();
    let text = deck::read_file(path).map_err(|e| InpError {
        file: name.clone(),
        line: None,
        kind: InpErrorKind::Io(e.to_string()),
    })?;
    parse_inp(&String::from_utf8_lossy(&text), path, request)
}

/// Parses the text of an `.inp` file; `path` names it in messages and is
/// where `*INCLUDE` paths are relative to.
pub fn parse_inp(
    text: &str,
    path: &Path,
    request: &InpRequest,
) -> Result<(Mesh, InpReport), InpError> {
    let mut reader = deck::Reader::new(path);
    let mut raw = read::Raw::default();
    let read = reader.read_main(text, &mut raw).and_then(|()| raw.finish());
    let result = read.and_then(|()| assemble::assemble(&raw, &request.bodies, &request.names));
    let (mesh, counts) = result.map_err(|f: Fail| reader.error(f))?;
    let report = InpReport {
        file: path.display().to_string(),
        included: reader.included(),
        skipped: raw
            .skipped
            .iter()
            .map(|(keyword, at)| format!("*{keyword} ({})", reader.place(*at)))
            .collect(),
        variants: variants(&raw),
        reoriented: counts.reoriented,
        unused_nodes: counts.unused_nodes,
    };
    Ok((mesh, report))
}

/// The element types of the file that name an Abaqus integration variant
/// this program does not have, each once.
fn variants(raw: &read::Raw) -> Vec<String> {
    let mut out: Vec<String> = Vec::new();
    for block in &raw.blocks {
        let variant = matches!(block.ty.as_str(), "C3D8R" | "C3D8I" | "C3D20R");
        if variant && !out.contains(&block.ty) {
            out.push(block.ty.clone());
        }
    }
    out
}

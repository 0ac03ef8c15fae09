//! The reader's error: one line naming the file, the line when there is
//! one, and what went wrong, with ids as the file writes them.

use thiserror::Error;

use super::kind;
use crate::mesh::{CellType, FacetType, MeshError};

/// An error of the reader: the file, the line when there is one, and what.
#[derive(Debug, Clone, PartialEq, Error)]
#[error("{file}{}: {kind}", line.map_or(String::new(), |l| format!(", line {l}")))]
pub struct InpError {
    pub file: String,
    pub line: Option<usize>,
    pub kind: InpErrorKind,
}

/// What went wrong while reading an `.inp` file. Ids are the file's.
#[derive(Debug, Clone, PartialEq, Error)]
pub enum InpErrorKind {
    #[error("cannot read the file: {0}")]
    Io(String),
    #[error("cannot read the included file {path}: {reason}")]
    Include { path: String, reason: String },
    #[error("include cycle: {0}")]
    IncludeCycle(String),
    #[error("includes nested deeper than {0} files")]
    IncludeDepth(usize),
    #[error("a data line before any keyword: `{0}`")]
    DataBeforeKeyword(String),
    #[error("bad keyword line `{0}`")]
    BadKeyword(String),
    #[error("*{keyword} needs {parameter}=")]
    MissingParameter {
        keyword: String,
        parameter: &'static str,
    },
    #[error("*{0}: INPUT= (the data lines in another file) is not supported: put them in the file, or *INCLUDE them")]
    DataElsewhere(String),
    #[error("*{keyword}: {parameter}={value} is not supported; {expected}")]
    BadParameter {
        keyword: &'static str,
        parameter: &'static str,
        value: String,
        expected: &'static str,
    },
    #[error("*{0}: parts, assemblies and instances are not supported: write a flat input file (Abaqus/CAE: Model > Edit Attributes > Do not use parts and assemblies in input files)")]
    Parts(String),
    #[error("*{0} generates or transforms nodes or elements, which this reader does not do: write the mesh out as nodes and elements (a mesher's export does)")]
    Generation(String),
    #[error("cannot read {what} from `{token}`")]
    BadNumber { what: &'static str, token: String },
    #[error("{what} {id} is not a positive integer")]
    BadId { what: &'static str, id: String },
    #[error("{what}: expected {expected}, found {found} fields")]
    FieldCount {
        what: &'static str,
        expected: &'static str,
        found: usize,
    },
    #[error("node {0} is defined twice")]
    DuplicateNode(u64),
    #[error("element {0} is defined twice")]
    DuplicateElement(u64),
    #[error("element {element} ({ty}) has {found} nodes, {ty} has {expected} (a line ending in a comma continues on the next)")]
    NodeCount {
        element: u64,
        ty: String,
        expected: usize,
        found: usize,
    },
    #[error("element {element} refers to node {node}, which no *NODE line defines")]
    UnknownNode { element: u64, node: u64 },
    #[error("{ty} elements are not supported: this program reads C3D4, C3D10, C3D6, C3D15, C3D8 (C3D8R, C3D8I) and C3D20 (C3D20R) cells")]
    OtherVolume { ty: String },
    #[error("{ty} elements ({what}) in element set {set} are not supported: the mesh is volumes of C3D4, C3D10, C3D6, C3D15, C3D8 or C3D20 cells, triangles or quadrilaterals on their faces, and sets")]
    Unsupported {
        ty: String,
        what: &'static str,
        set: String,
    },
    #[error("element type {0} is not known to this reader (it reads C3D4, C3D10, C3D6, C3D15, C3D8, C3D8R, C3D8I, C3D20, C3D20R and the triangles and quadrilaterals S3, S4, S4R, S6, S8, S8R, CPS3, CPS4, CPS6, CPS8, CPE3, CPE4, M3D3, M3D4, M3D9, SFM3D3, SFM3D4 and kin on their faces)")]
    UnknownType(String),
    #[error("element {element} is a {found} cell but element {first} (line {first_line}) is a {first_type}: a mesh holds one cell type today (mesh all volumes with one type of one order)")]
    MixedCellTypes {
        element: u64,
        found: &'static str,
        first: u64,
        first_line: usize,
        first_type: &'static str,
    },
    #[error(
        "no 3D elements (C3D4, C3D10, C3D6, C3D15, C3D8, C3D20): the file holds no volume mesh"
    )]
    NoVolumeCells,
    #[error("{kind} {name} is not defined above this line")]
    UnknownSet { kind: &'static str, name: String },
    #[error("{what} {set}: {item} {id} is not defined in the file")]
    UnknownMember {
        what: &'static str,
        set: String,
        item: &'static str,
        id: u64,
    },
    #[error("GENERATE needs first, last[, step] with 0 < first ≤ last and step ≥ 1, found `{0}`")]
    BadGenerate(String),
    #[error(
        "surface {surface}: face `{label}` of element {element} ({ty}) is not one of S1..S{}",
        kind::face_count(ty)
    )]
    BadFace {
        surface: String,
        label: Box<str>,
        element: u64,
        ty: String,
    },
    #[error("surface {surface}: element {element} is a {ty}, not a 3D element: *SURFACE faces are faces of 3D elements")]
    FaceOfNonCell {
        surface: String,
        element: u64,
        ty: String,
    },
    #[error("cell from element {element} is tangled or degenerate (Jacobian determinants of mixed sign or zero, from {min:e} to {max:e})")]
    TangledCell { element: u64, min: f64, max: f64 },
    #[error("{ty} element {element} of element set {set} is no boundary face of a 3D element (matched by its nodes): shells and membranes are not supported")]
    FacetNotOnCell {
        ty: String,
        element: u64,
        set: String,
    },
    #[error("{ty} element {element} of element set {set} is a {}, but the face of the {} cell it lies on is a {}", found.name(), cells.name(), expected.name())]
    FacetTypeMismatch {
        ty: String,
        element: u64,
        set: String,
        found: FacetType,
        cells: CellType,
        expected: FacetType,
    },
    #[error("no element set {name} of 3D elements for the body {name} (element sets of 3D elements: {known})")]
    UnknownBodySet { name: String, known: String },
    #[error("element {element} is in the element sets {first} and {second}, which are both bodies; a cell belongs to one body")]
    ElementInTwoBodies {
        element: u64,
        first: String,
        second: String,
    },
    #[error(
        "{count} 3D elements are in no element set that is a body ({bodies}): elements {list}"
    )]
    ElementsWithoutBody {
        count: usize,
        bodies: String,
        list: String,
    },
    #[error("the mesh read is not valid: {error}{}", element.map_or(String::new(), |e| format!(" (the cell of element {e})")))]
    Invalid {
        error: Box<MeshError>,
        element: Option<u64>,
    },
}

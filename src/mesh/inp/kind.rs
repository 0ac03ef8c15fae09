//! The Abaqus element types: what the reader makes of each, and the face
//! numbering S1..S6 of the 3D ones.

use crate::mesh::{CellType, FacetType};

/// What an element read becomes.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(super) enum Kind {
    /// A volume cell of the mesh.
    Cell(CellType),
    /// A surface element that must be a face of a cell.
    Facet(FacetType),
}

impl Kind {
    pub(super) fn nodes(self) -> usize {
        match self {
            Kind::Cell(c) => c.nodes(),
            Kind::Facet(f) => f.nodes(),
        }
    }
}

/// How the reader treats an element type.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(super) enum Class {
    Read(Kind),
    /// A 3D type the program does not have the cell of (C3D27, C3D13, ...).
    OtherVolume,
    /// A type that is no volume or face: beams, trusses, springs, ...
    Unsupported(&'static str),
    Unknown,
}

/// The class of an element type given in upper case.
pub(super) fn classify(ty: &str) -> Class {
    use Class::*;
    match ty {
        "C3D4" => Read(Kind::Cell(CellType::Tet4)),
        "C3D10" => Read(Kind::Cell(CellType::Tet10)),
        "C3D6" => Read(Kind::Cell(CellType::Wedge6)),
        "C3D15" => Read(Kind::Cell(CellType::Wedge15)),
        "C3D8" | "C3D8R" | "C3D8I" => Read(Kind::Cell(CellType::Hex8)),
        "C3D20" | "C3D20R" => Read(Kind::Cell(CellType::Hex20)),
        "S3" | "S3R" | "STRI3" | "CPS3" | "CPE3" | "M3D3" | "SFM3D3" => {
            Read(Kind::Facet(FacetType::Tri3))
        }
        "S4" | "S4R" | "S4R5" | "CPS4" | "CPS4R" | "CPE4" | "CPE4R" | "M3D4" | "M3D4R"
        | "SFM3D4" | "SFM3D4R" => Read(Kind::Facet(FacetType::Quad4)),
        "S6" | "STRI65" | "CPS6" | "CPE6" | "M3D6" | "SFM3D6" => Read(Kind::Facet(FacetType::Tri6)),
        "S8" | "S8R" | "S8R5" | "CPS8" | "CPS8R" | "CPE8" | "CPE8R" | "M3D8" | "M3D8R"
        | "SFM3D8" | "SFM3D8R" => Read(Kind::Facet(FacetType::Quad8)),
        "S9R5" | "M3D9" => Read(Kind::Facet(FacetType::Quad9)),
        _ if ty.starts_with("C3D") => OtherVolume,
        _ if numbered(ty, "B") => Unsupported("beams"),
        _ if numbered(ty, "T") => Unsupported("trusses"),
        _ if ty.starts_with("CAX") || ty.starts_with("CGAX") => Unsupported("axisymmetric"),
        _ if ty.starts_with("SPRING") => Unsupported("springs"),
        _ if ty.starts_with("DASHPOT") => Unsupported("dashpots"),
        _ if ty.starts_with("MASS") || ty.starts_with("ROTARYI") => Unsupported("point masses"),
        _ if ty.starts_with("GAP") => Unsupported("gap elements"),
        _ if ty.starts_with("R3D") || ty.starts_with("R2D") => Unsupported("rigid elements"),
        _ if numbered(ty, "DC") => Unsupported("heat transfer"),
        _ if numbered(ty, "F") => Unsupported("fluid"),
        "D" | "DCOUP3D" => Unsupported("fluid network or coupling"),
        _ if ty.starts_with("CPS") || ty.starts_with("CPE") || ty.starts_with("S") => {
            Unsupported("plane or shell")
        }
        _ => Unknown,
    }
}

/// `B31`, `T3D2`: a letter, then a digit.
fn numbered(ty: &str, letter: &str) -> bool {
    ty.strip_prefix(letter)
        .and_then(|rest| rest.chars().next())
        .is_some_and(|c| c.is_ascii_digit())
}

/// The faces S1, S2, ... of an Abaqus 3D element as the local indices of
/// their corners (from 0), as the Abaqus and CalculiX manuals number them;
/// a second-order element's faces are its linear kin's. Their orientation
/// is not used: a face is found among [`CellType::local_faces`] by its
/// corners.
pub(super) fn abaqus_faces(cell: CellType) -> &'static [&'static [usize]] {
    match cell.linear() {
        CellType::Hex8 => &[
            &[0, 1, 2, 3],
            &[4, 7, 6, 5],
            &[0, 4, 5, 1],
            &[1, 5, 6, 2],
            &[2, 6, 7, 3],
            &[3, 7, 4, 0],
        ],
        CellType::Tet4 => &[&[0, 1, 2], &[0, 3, 1], &[1, 3, 2], &[2, 3, 0]],
        CellType::Wedge6 => &[
            &[0, 1, 2],
            &[3, 5, 4],
            &[0, 3, 4, 1],
            &[1, 4, 5, 2],
            &[2, 5, 3, 0],
        ],
        // No Abaqus type is read as a pyramid.
        _ => &[],
    }
}

/// How many faces an element type has: S1..S<n> (0 if it is no 3D type
/// this reader reads).
pub(super) fn face_count(ty: &str) -> usize {
    match classify(ty) {
        Class::Read(Kind::Cell(cell)) => abaqus_faces(cell).len(),
        _ => 0,
    }
}

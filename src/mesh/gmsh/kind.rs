//! The Gmsh element types the reader accepts, their node orders, and names
//! for the others.

use crate::fem::{CellType, FacetType, GMSH_HEX20, GMSH_HEX27, GMSH_TET10, GMSH_WEDGE15};

/// The Gmsh element types the reader accepts: points and lines for node
/// sets, surface elements for facet sets, one volume type for the cells.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(super) enum Kind {
    Point,
    Line,
    Line3,
    Facet(FacetType),
    Cell(CellType),
}

impl Kind {
    /// Every accepted kind, in list order ([`Kind::index`]).
    pub(super) const ALL: [Kind; 16] = [
        Kind::Point,
        Kind::Line,
        Kind::Line3,
        Kind::Facet(FacetType::Tri3),
        Kind::Facet(FacetType::Quad4),
        Kind::Facet(FacetType::Tri6),
        Kind::Facet(FacetType::Quad8),
        Kind::Facet(FacetType::Quad9),
        Kind::Cell(CellType::Tet4),
        Kind::Cell(CellType::Hex8),
        Kind::Cell(CellType::Tet10),
        Kind::Cell(CellType::Hex20),
        Kind::Cell(CellType::Hex27),
        Kind::Cell(CellType::Wedge6),
        Kind::Cell(CellType::Wedge15),
        Kind::Cell(CellType::Pyramid5),
    ];

    /// Gmsh's element type numbers (the .msh 4.1 documentation, "Node
    /// ordering").
    pub(super) fn from_gmsh(t: i32) -> Option<Kind> {
        let kind = match t {
            15 => Kind::Point,
            1 => Kind::Line,
            8 => Kind::Line3,
            2 => Kind::Facet(FacetType::Tri3),
            3 => Kind::Facet(FacetType::Quad4),
            9 => Kind::Facet(FacetType::Tri6),
            16 => Kind::Facet(FacetType::Quad8),
            10 => Kind::Facet(FacetType::Quad9),
            4 => Kind::Cell(CellType::Tet4),
            5 => Kind::Cell(CellType::Hex8),
            11 => Kind::Cell(CellType::Tet10),
            17 => Kind::Cell(CellType::Hex20),
            12 => Kind::Cell(CellType::Hex27),
            6 => Kind::Cell(CellType::Wedge6),
            18 => Kind::Cell(CellType::Wedge15),
            7 => Kind::Cell(CellType::Pyramid5),
            _ => return None,
        };
        Some(kind)
    }

    pub(super) fn index(self) -> usize {
        Kind::ALL.iter().position(|&k| k == self).unwrap_or(0)
    }

    pub(super) fn nodes(self) -> usize {
        match self {
            Kind::Point => 1,
            Kind::Line => 2,
            Kind::Line3 => 3,
            Kind::Facet(f) => f.nodes(),
            Kind::Cell(c) => c.nodes(),
        }
    }

    pub(super) fn dim(self) -> usize {
        match self {
            Kind::Point => 0,
            Kind::Line | Kind::Line3 => 1,
            Kind::Facet(_) => 2,
            Kind::Cell(_) => 3,
        }
    }

    pub(super) fn name(self) -> &'static str {
        match self {
            Kind::Point => "point",
            Kind::Line => "line2",
            Kind::Line3 => "line3",
            Kind::Facet(f) => f.name(),
            Kind::Cell(c) => c.name(),
        }
    }

    /// Gmsh's node order as ours: our node `k` is Gmsh's node `order[k]`.
    /// Gmsh numbers the mid-edge nodes of tet10, hex20, hex27 and prism15
    /// (and hex27's face centres) differently ([`crate::fem::GMSH_HEX20`]
    /// and its kin); its other types agree with ours.
    pub(super) fn to_ours(self) -> Option<&'static [usize]> {
        match self {
            Kind::Cell(CellType::Tet10) => Some(&GMSH_TET10),
            Kind::Cell(CellType::Hex20) => Some(&GMSH_HEX20),
            Kind::Cell(CellType::Hex27) => Some(&GMSH_HEX27),
            Kind::Cell(CellType::Wedge15) => Some(&GMSH_WEDGE15),
            _ => None,
        }
    }
}

/// Names of the Gmsh element types users are likely to meet, for messages.
pub(super) fn gmsh_type_name(t: i32) -> &'static str {
    match t {
        13 => "prism18",
        14 => "pyramid14",
        19 => "pyramid13",
        20..=28 => "higher-order triangle or line",
        29..=31 => "higher-order tetrahedron",
        92 | 93 => "higher-order hexahedron",
        _ => Kind::from_gmsh(t).map_or("unknown type", Kind::name),
    }
}

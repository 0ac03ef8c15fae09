//! The Gmsh element types the reader accepts, and names for the others.

/// The Gmsh element types the reader accepts.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(super) enum Kind {
    Point,
    Line,
    Tri,
    Quad,
    Tet,
    Hex,
}

impl Kind {
    #[cfg(test)]
    pub(super) const ALL: [Kind; 6] = [
        Kind::Point,
        Kind::Line,
        Kind::Tri,
        Kind::Quad,
        Kind::Tet,
        Kind::Hex,
    ];

    pub(super) fn from_gmsh(t: i32) -> Option<Kind> {
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

    pub(super) fn index(self) -> usize {
        self as usize
    }

    pub(super) fn nodes(self) -> usize {
        match self {
            Kind::Point => 1,
            Kind::Line => 2,
            Kind::Tri => 3,
            Kind::Quad | Kind::Tet => 4,
            Kind::Hex => 8,
        }
    }

    pub(super) fn dim(self) -> usize {
        match self {
            Kind::Point => 0,
            Kind::Line => 1,
            Kind::Tri | Kind::Quad => 2,
            Kind::Tet | Kind::Hex => 3,
        }
    }

    pub(super) fn name(self) -> &'static str {
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
pub(super) fn gmsh_type_name(t: i32) -> &'static str {
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

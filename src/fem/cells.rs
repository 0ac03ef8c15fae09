//! Reference cells and facets: the supported shapes, their node numbering,
//! outward local faces and the position of every node that is not a corner.
//!
//! A new element type is a variant here plus its rows in these tables;
//! everything that walks faces, edges or mid-side nodes reads the tables.
//!
//! # Node numbering
//!
//! Tetrahedra and hexahedra follow VTK, which for them is also Abaqus'
//! order, so the Abaqus → ours permutation is the identity:
//!
//! | ours | VTK | Abaqus | Gmsh (type) | Gmsh → ours |
//! | --- | --- | --- | --- | --- |
//! | `Tet4` | `VTK_TETRA` | C3D4 | 4 | identity |
//! | `Tet10` | `VTK_QUADRATIC_TETRA` | C3D10 | 11 | nodes 8 and 9 swapped |
//! | `Hex8` | `VTK_HEXAHEDRON` | C3D8 (R, I) | 5 | identity |
//! | `Hex20` | `VTK_QUADRATIC_HEXAHEDRON` | C3D20 (R) | 17 | [`GMSH_HEX20`] |
//! | `Hex27` | `VTK_TRIQUADRATIC_HEXAHEDRON` | — (CalculiX has none) | 12 | [`GMSH_HEX27`] |
//! | `Wedge6` | `VTK_WEDGE` with 1↔2, 4↔5 | C3D6 | 6 | identity |
//! | `Wedge15` | `VTK_QUADRATIC_WEDGE` permuted | C3D15 | 18 | [`GMSH_WEDGE15`] |
//! | `Pyramid5` | `VTK_PYRAMID` | — | 7 | identity |
//!
//! - `Tet10`: corners as `Tet4`, then the mid-edge nodes of the edges
//!   (0,1), (1,2), (2,0), (0,3), (1,3), (2,3). Gmsh lists the last two the
//!   other way round, (3,2) before (3,1).
//! - `Hex20`: corners as `Hex8`, then the mid-edge nodes of (0,1), (1,2),
//!   (2,3), (3,0) (bottom), (4,5), (5,6), (6,7), (7,4) (top), (0,4), (1,5),
//!   (2,6), (3,7) (vertical).
//! - `Hex27`: `Hex20`, then the face centres in local face order (ξ−, ξ+,
//!   η−, η+, ζ−, ζ+), then the cell centre.
//! - `Wedge6`: the triangle (0,1,2) at `ζ = −1`, counter-clockwise seen from
//!   `+ζ`, and (3,4,5) above it at `ζ = +1`: Abaqus' and Gmsh's orientation.
//!   VTK's wedge lists the triangles the other way round (its (0,1,2) has
//!   its normal pointing away from (3,4,5)), so VTK order is ours with nodes
//!   1↔2 and 4↔5 swapped ([`CellType::vtk_order`]).
//! - `Wedge15`: `Wedge6`, then the mid-edge nodes of (0,1), (1,2), (2,0),
//!   (3,4), (4,5), (5,3), (0,3), (1,4), (2,5) (Abaqus C3D15).
//! - `Pyramid5`: the base quad (0,1,2,3) at `ζ = 0`, counter-clockwise seen
//!   from the apex 4 at `ζ = 1`.
//!
//! Facets: `Tri6` is `Tri3` then the mid-edge nodes of (0,1), (1,2), (2,0);
//! `Quad8` is `Quad4` then those of (0,1), (1,2), (2,3), (3,0); `Quad9` adds
//! the centre. VTK, Gmsh (types 9, 16, 10) and Abaqus (STRI65's face, S8)
//! agree on these.
//!
//! # Local faces and Abaqus' face labels
//!
//! Faces are listed corners first (outward right-hand order), then their
//! mid-edge nodes in the same cyclic order, then a face centre. Abaqus'
//! `S1..S6` labels map onto our local faces as: hexahedra S1→4, S2→5, S3→2,
//! S4→1, S5→3, S6→0; tetrahedra S1→0, S2→1, S3→3, S4→2; wedges S1..S5 →
//! 0..4 (the wedge faces are numbered as Abaqus numbers them).

/// Volume cell shapes; see the module documentation for node numbering.
///
/// Reference cells: `Hex*` the cube `[-1, 1]³`; `Tet*` the unit simplex
/// (nodes (0,0,0), (1,0,0), (0,1,0), (0,0,1)); `Wedge*` the unit triangle
/// in `(ξ, η)` times `ζ ∈ [-1, 1]`; `Pyramid5` the square `[-1, 1]²` at
/// `ζ = 0` with its apex at `(0, 0, 1)`. A positively oriented cell maps its
/// reference cell with `det J > 0`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum CellType {
    Hex8,
    Tet4,
    Tet10,
    Hex20,
    Hex27,
    Wedge6,
    Wedge15,
    Pyramid5,
}

/// Surface facet shapes (boundary faces of the cells).
///
/// - `Quad4`, `Quad8`, `Quad9`: reference square `[-1, 1]²`, corners
///   counter-clockwise from `(-1,-1)`.
/// - `Tri3`, `Tri6`: reference triangle, corners at `(0,0)`, `(1,0)`,
///   `(0,1)`.
///
/// The right-hand normal `∂x/∂ξ₁ × ∂x/∂ξ₂` is the orientation of a facet; it
/// has the direction of `(x1−x0) × (x2−x0)` for a triangle and of
/// `(x2−x0) × (x3−x1)` for a quadrilateral (corners).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum FacetType {
    Quad4,
    Tri3,
    Tri6,
    Quad8,
    Quad9,
}

const HEX8_FACES: [&[usize]; 6] = [
    &[0, 4, 7, 3], // ξ = -1
    &[1, 2, 6, 5], // ξ = +1
    &[0, 1, 5, 4], // η = -1
    &[2, 3, 7, 6], // η = +1
    &[0, 3, 2, 1], // ζ = -1
    &[4, 5, 6, 7], // ζ = +1
];

const TET4_FACES: [&[usize]; 4] = [
    &[0, 2, 1], // opposite node 3
    &[0, 1, 3], // opposite node 2
    &[0, 3, 2], // opposite node 1
    &[1, 2, 3], // opposite node 0
];

const TET10_FACES: [&[usize]; 4] = [
    &[0, 2, 1, 6, 5, 4],
    &[0, 1, 3, 4, 8, 7],
    &[0, 3, 2, 7, 9, 6],
    &[1, 2, 3, 5, 9, 8],
];

const HEX20_FACES: [&[usize]; 6] = [
    &[0, 4, 7, 3, 16, 15, 19, 11],
    &[1, 2, 6, 5, 9, 18, 13, 17],
    &[0, 1, 5, 4, 8, 17, 12, 16],
    &[2, 3, 7, 6, 10, 19, 14, 18],
    &[0, 3, 2, 1, 11, 10, 9, 8],
    &[4, 5, 6, 7, 12, 13, 14, 15],
];

const HEX27_FACES: [&[usize]; 6] = [
    &[0, 4, 7, 3, 16, 15, 19, 11, 20],
    &[1, 2, 6, 5, 9, 18, 13, 17, 21],
    &[0, 1, 5, 4, 8, 17, 12, 16, 22],
    &[2, 3, 7, 6, 10, 19, 14, 18, 23],
    &[0, 3, 2, 1, 11, 10, 9, 8, 24],
    &[4, 5, 6, 7, 12, 13, 14, 15, 25],
];

const WEDGE6_FACES: [&[usize]; 5] = [
    &[0, 2, 1],    // ζ = -1 (Abaqus S1)
    &[3, 4, 5],    // ζ = +1 (S2)
    &[0, 1, 4, 3], // η = 0 (S3)
    &[1, 2, 5, 4], // ξ + η = 1 (S4)
    &[2, 0, 3, 5], // ξ = 0 (S5)
];

const WEDGE15_FACES: [&[usize]; 5] = [
    &[0, 2, 1, 8, 7, 6],
    &[3, 4, 5, 9, 10, 11],
    &[0, 1, 4, 3, 6, 13, 9, 12],
    &[1, 2, 5, 4, 7, 14, 10, 13],
    &[2, 0, 3, 5, 8, 12, 11, 14],
];

const PYRAMID5_FACES: [&[usize]; 5] = [
    &[0, 3, 2, 1], // the base, ζ = 0
    &[0, 1, 4],
    &[1, 2, 4],
    &[2, 3, 4],
    &[3, 0, 4],
];

const TET10_HIGHER: [&[usize]; 6] = [&[0, 1], &[1, 2], &[2, 0], &[0, 3], &[1, 3], &[2, 3]];

const HEX20_HIGHER: [&[usize]; 12] = [
    &[0, 1],
    &[1, 2],
    &[2, 3],
    &[3, 0],
    &[4, 5],
    &[5, 6],
    &[6, 7],
    &[7, 4],
    &[0, 4],
    &[1, 5],
    &[2, 6],
    &[3, 7],
];

const HEX27_HIGHER: [&[usize]; 19] = [
    &[0, 1],
    &[1, 2],
    &[2, 3],
    &[3, 0],
    &[4, 5],
    &[5, 6],
    &[6, 7],
    &[7, 4],
    &[0, 4],
    &[1, 5],
    &[2, 6],
    &[3, 7],
    &[0, 4, 7, 3],
    &[1, 2, 6, 5],
    &[0, 1, 5, 4],
    &[2, 3, 7, 6],
    &[0, 3, 2, 1],
    &[4, 5, 6, 7],
    &[0, 1, 2, 3, 4, 5, 6, 7],
];

const WEDGE15_HIGHER: [&[usize]; 9] = [
    &[0, 1],
    &[1, 2],
    &[2, 0],
    &[3, 4],
    &[4, 5],
    &[5, 3],
    &[0, 3],
    &[1, 4],
    &[2, 5],
];

const TRI6_HIGHER: [&[usize]; 3] = [&[0, 1], &[1, 2], &[2, 0]];
const QUAD8_HIGHER: [&[usize]; 4] = [&[0, 1], &[1, 2], &[2, 3], &[3, 0]];
const QUAD9_HIGHER: [&[usize]; 5] = [&[0, 1], &[1, 2], &[2, 3], &[3, 0], &[0, 1, 2, 3]];

/// Gmsh's hex20 (type 17) as ours: `ours[k] = gmsh[GMSH_HEX20[k]]`. Gmsh
/// orders the edges (0,1), (0,3), (0,4), (1,2), (1,5), (2,3), (2,6), (3,7),
/// (4,5), (4,7), (5,6), (6,7).
pub const GMSH_HEX20: [usize; 20] = [
    0, 1, 2, 3, 4, 5, 6, 7, 8, 11, 13, 9, 16, 18, 19, 17, 10, 12, 14, 15,
];

/// Gmsh's hex27 (type 12) as ours: the hex20 part as [`GMSH_HEX20`], then
/// Gmsh's face centres (ζ−, η−, ξ−, ξ+, η+, ζ+) in our face order, then the
/// centre.
pub const GMSH_HEX27: [usize; 27] = [
    0, 1, 2, 3, 4, 5, 6, 7, 8, 11, 13, 9, 16, 18, 19, 17, 10, 12, 14, 15, 22, 23, 21, 24, 20, 25,
    26,
];

/// Gmsh's tet10 (type 11) as ours: its edges (3,2) and (3,1) come in the
/// other order.
pub const GMSH_TET10: [usize; 10] = [0, 1, 2, 3, 4, 5, 6, 7, 9, 8];

/// Gmsh's prism15 (type 18) as ours. Gmsh orders the edges (0,1), (0,2),
/// (0,3), (1,2), (1,4), (2,5), (3,4), (3,5), (4,5).
pub const GMSH_WEDGE15: [usize; 15] = [0, 1, 2, 3, 4, 5, 6, 9, 7, 12, 14, 13, 8, 10, 11];

impl CellType {
    /// Every supported cell type.
    pub const ALL: [CellType; 8] = [
        CellType::Hex8,
        CellType::Tet4,
        CellType::Tet10,
        CellType::Hex20,
        CellType::Hex27,
        CellType::Wedge6,
        CellType::Wedge15,
        CellType::Pyramid5,
    ];

    pub const fn nodes(self) -> usize {
        match self {
            CellType::Hex8 => 8,
            CellType::Tet4 => 4,
            CellType::Tet10 => 10,
            CellType::Hex20 => 20,
            CellType::Hex27 => 27,
            CellType::Wedge6 => 6,
            CellType::Wedge15 => 15,
            CellType::Pyramid5 => 5,
        }
    }

    /// Number of corner (vertex) nodes, listed first.
    pub const fn corners(self) -> usize {
        self.linear().nodes()
    }

    /// The first-order type on the same corners (itself when first order).
    pub const fn linear(self) -> CellType {
        match self {
            CellType::Hex8 | CellType::Hex20 | CellType::Hex27 => CellType::Hex8,
            CellType::Tet4 | CellType::Tet10 => CellType::Tet4,
            CellType::Wedge6 | CellType::Wedge15 => CellType::Wedge6,
            CellType::Pyramid5 => CellType::Pyramid5,
        }
    }

    /// Polynomial order of the shape functions along an edge (1 or 2).
    pub const fn order(self) -> usize {
        if self.nodes() == self.corners() {
            1
        } else {
            2
        }
    }

    pub const fn name(self) -> &'static str {
        match self {
            CellType::Hex8 => "hex8",
            CellType::Tet4 => "tet4",
            CellType::Tet10 => "tet10",
            CellType::Hex20 => "hex20",
            CellType::Hex27 => "hex27",
            CellType::Wedge6 => "wedge6",
            CellType::Wedge15 => "wedge15",
            CellType::Pyramid5 => "pyramid5",
        }
    }

    /// The type with this [`CellType::name`].
    pub fn from_name(name: &str) -> Option<CellType> {
        CellType::ALL.into_iter().find(|c| c.name() == name)
    }

    /// Face node lists in local numbering, each ordered so the facet's
    /// right-hand normal (see [`FacetType`]) points out of the cell, which is
    /// what `surface` needs for pressure and what contact needs for gaps.
    /// Corners come first, then mid-edge nodes, then a face centre.
    ///
    /// - hexahedra, face index: 0 `ξ=-1`, 1 `ξ=+1`, 2 `η=-1`, 3 `η=+1`,
    ///   4 `ζ=-1`, 5 `ζ=+1`.
    /// - tetrahedra, face `f` is the face opposite node `3 − f`: 0 opposite
    ///   node 3 (`ζ=0`), 1 opposite node 2 (`η=0`), 2 opposite node 1
    ///   (`ξ=0`), 3 opposite node 0 (the slanted face).
    /// - wedges: 0 `ζ=-1`, 1 `ζ=+1` (triangles), 2 `η=0`, 3 `ξ+η=1`,
    ///   4 `ξ=0` (quadrilaterals).
    /// - pyramid: 0 the base, then the triangles on the base edges (0,1),
    ///   (1,2), (2,3), (3,0).
    pub const fn local_faces(self) -> &'static [&'static [usize]] {
        match self {
            CellType::Hex8 => &HEX8_FACES,
            CellType::Tet4 => &TET4_FACES,
            CellType::Tet10 => &TET10_FACES,
            CellType::Hex20 => &HEX20_FACES,
            CellType::Hex27 => &HEX27_FACES,
            CellType::Wedge6 => &WEDGE6_FACES,
            CellType::Wedge15 => &WEDGE15_FACES,
            CellType::Pyramid5 => &PYRAMID5_FACES,
        }
    }

    /// Number of local faces.
    pub const fn num_faces(self) -> usize {
        self.local_faces().len()
    }

    /// The facet type of local face `face` (a wedge has triangles and
    /// quadrilaterals, a pyramid one quadrilateral and four triangles).
    /// Out-of-range faces get the type of face 0.
    pub fn face_type(self, face: usize) -> FacetType {
        let faces = self.local_faces();
        let nodes = faces.get(face).unwrap_or(&faces[0]).len();
        match nodes {
            3 => FacetType::Tri3,
            6 => FacetType::Tri6,
            8 => FacetType::Quad8,
            9 => FacetType::Quad9,
            _ => FacetType::Quad4,
        }
    }

    /// The facet type shared by all faces, for cells that have one
    /// (hexahedra, tetrahedra); `None` for wedges and pyramids.
    pub fn single_facet_type(self) -> Option<FacetType> {
        let first = self.face_type(0);
        (1..self.num_faces())
            .all(|f| self.face_type(f) == first)
            .then_some(first)
    }

    /// Each node after the corners, as the corners whose mean it is in the
    /// reference cell (an edge's two ends, a face's corners, all corners
    /// for the centre); node `corners() + k` is entry `k`.
    pub const fn higher_nodes(self) -> &'static [&'static [usize]] {
        match self {
            CellType::Tet10 => &TET10_HIGHER,
            CellType::Hex20 => &HEX20_HIGHER,
            CellType::Hex27 => &HEX27_HIGHER,
            CellType::Wedge15 => &WEDGE15_HIGHER,
            CellType::Hex8 | CellType::Tet4 | CellType::Wedge6 | CellType::Pyramid5 => &[],
        }
    }

    /// A relabelling that reflects the cell (`new[k] = old[mirror()[k]]`):
    /// a cell given with the wrong orientation, every Jacobian negative,
    /// becomes a valid one. Tetrahedra swap corners 1 and 2, hexahedra and
    /// wedges their bottom and top, the pyramid corners 1 and 3; the higher
    /// nodes follow their corners.
    pub const fn mirror(self) -> &'static [usize] {
        match self {
            CellType::Tet4 => &[0, 2, 1, 3],
            CellType::Tet10 => &[0, 2, 1, 3, 6, 5, 4, 7, 9, 8],
            CellType::Hex8 => &[4, 5, 6, 7, 0, 1, 2, 3],
            CellType::Hex20 => &[
                4, 5, 6, 7, 0, 1, 2, 3, 12, 13, 14, 15, 8, 9, 10, 11, 16, 17, 18, 19,
            ],
            CellType::Hex27 => &[
                4, 5, 6, 7, 0, 1, 2, 3, 12, 13, 14, 15, 8, 9, 10, 11, 16, 17, 18, 19, 20, 21, 22,
                23, 25, 24, 26,
            ],
            CellType::Wedge6 => &[3, 4, 5, 0, 1, 2],
            CellType::Wedge15 => &[3, 4, 5, 0, 1, 2, 9, 10, 11, 6, 7, 8, 12, 13, 14],
            CellType::Pyramid5 => &[0, 3, 2, 1, 4],
        }
    }

    /// VTK's (and XDMF's) node order in our local numbering: VTK's node `j`
    /// is our node `vtk_order()[j]`. The identity except for wedges (see the
    /// module docs); the permutations are involutions.
    pub const fn vtk_order(self) -> &'static [usize] {
        const WEDGE6: [usize; 6] = [0, 2, 1, 3, 5, 4];
        const WEDGE15: [usize; 15] = [0, 2, 1, 3, 5, 4, 8, 7, 6, 11, 10, 9, 12, 14, 13];
        const IDENTITY: [usize; 27] = [
            0, 1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11, 12, 13, 14, 15, 16, 17, 18, 19, 20, 21, 22, 23,
            24, 25, 26,
        ];
        match self {
            CellType::Wedge6 => &WEDGE6,
            CellType::Wedge15 => &WEDGE15,
            CellType::Hex8 => IDENTITY.split_at(8).0,
            CellType::Tet4 => IDENTITY.split_at(4).0,
            CellType::Tet10 => IDENTITY.split_at(10).0,
            CellType::Hex20 => IDENTITY.split_at(20).0,
            CellType::Hex27 => &IDENTITY,
            CellType::Pyramid5 => IDENTITY.split_at(5).0,
        }
    }
}

impl FacetType {
    /// Every supported facet type.
    pub const ALL: [FacetType; 5] = [
        FacetType::Quad4,
        FacetType::Tri3,
        FacetType::Tri6,
        FacetType::Quad8,
        FacetType::Quad9,
    ];

    pub const fn nodes(self) -> usize {
        match self {
            FacetType::Quad4 => 4,
            FacetType::Tri3 => 3,
            FacetType::Tri6 => 6,
            FacetType::Quad8 => 8,
            FacetType::Quad9 => 9,
        }
    }

    /// The first-order type on the same corners (itself when first order).
    pub const fn linear(self) -> FacetType {
        match self {
            FacetType::Quad4 | FacetType::Quad8 | FacetType::Quad9 => FacetType::Quad4,
            FacetType::Tri3 | FacetType::Tri6 => FacetType::Tri3,
        }
    }

    /// Number of corner nodes, listed first.
    pub const fn corners(self) -> usize {
        self.linear().nodes()
    }

    /// True for the first-order facets (tri3, quad4).
    pub const fn is_linear(self) -> bool {
        self.nodes() == self.corners()
    }

    pub const fn name(self) -> &'static str {
        match self {
            FacetType::Quad4 => "quad4",
            FacetType::Tri3 => "tri3",
            FacetType::Tri6 => "tri6",
            FacetType::Quad8 => "quad8",
            FacetType::Quad9 => "quad9",
        }
    }

    /// The type with this [`FacetType::name`].
    pub fn from_name(name: &str) -> Option<FacetType> {
        FacetType::ALL.into_iter().find(|f| f.name() == name)
    }

    /// As [`CellType::higher_nodes`], on the reference facet.
    pub const fn higher_nodes(self) -> &'static [&'static [usize]] {
        match self {
            FacetType::Tri6 => &TRI6_HIGHER,
            FacetType::Quad8 => &QUAD8_HIGHER,
            FacetType::Quad9 => &QUAD9_HIGHER,
            FacetType::Quad4 | FacetType::Tri3 => &[],
        }
    }
}

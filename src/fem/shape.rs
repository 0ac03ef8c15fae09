//! Shape functions and their derivatives with respect to the reference
//! coordinates, for every cell and facet type of [`super::cells`].
//!
//! The evaluators write into caller-provided slices of exactly the element's
//! node count ([`eval_cell`], [`eval_facet`]), so a kernel sizes its buffers
//! by the element at hand and a first-order element never touches more than
//! its own nodes. [`CellShape`] and [`FacetShape`] are fixed-size holders for
//! code that wants one value.

use super::{CellType, FacetType, MAX_CELL_NODES, MAX_FACET_NODES};

mod higher;

pub use higher::HEX27_REF_NODES;

/// Reference coordinates of the hex8 nodes (VTK order).
pub const HEX8_REF_NODES: [[f64; 3]; 8] = [
    [-1.0, -1.0, -1.0],
    [1.0, -1.0, -1.0],
    [1.0, 1.0, -1.0],
    [-1.0, 1.0, -1.0],
    [-1.0, -1.0, 1.0],
    [1.0, -1.0, 1.0],
    [1.0, 1.0, 1.0],
    [-1.0, 1.0, 1.0],
];

/// Reference coordinates of the tet4 nodes (VTK order).
pub const TET4_REF_NODES: [[f64; 3]; 4] = [
    [0.0, 0.0, 0.0],
    [1.0, 0.0, 0.0],
    [0.0, 1.0, 0.0],
    [0.0, 0.0, 1.0],
];

/// Reference coordinates of the wedge6 corners (Abaqus / Gmsh order).
pub const WEDGE6_REF_NODES: [[f64; 3]; 6] = [
    [0.0, 0.0, -1.0],
    [1.0, 0.0, -1.0],
    [0.0, 1.0, -1.0],
    [0.0, 0.0, 1.0],
    [1.0, 0.0, 1.0],
    [0.0, 1.0, 1.0],
];

/// Reference coordinates of the pyramid5 nodes: the base square, the apex.
pub const PYRAMID5_REF_NODES: [[f64; 3]; 5] = [
    [-1.0, -1.0, 0.0],
    [1.0, -1.0, 0.0],
    [1.0, 1.0, 0.0],
    [-1.0, 1.0, 0.0],
    [0.0, 0.0, 1.0],
];

/// Reference coordinates of the quad4 nodes.
pub const QUAD4_REF_NODES: [[f64; 2]; 4] = [[-1.0, -1.0], [1.0, -1.0], [1.0, 1.0], [-1.0, 1.0]];

/// Reference coordinates of the tri3 nodes.
pub const TRI3_REF_NODES: [[f64; 2]; 3] = [[0.0, 0.0], [1.0, 0.0], [0.0, 1.0]];

/// Reference coordinates of every node of `cell`: the corners, then each
/// higher node at the mean of its corners ([`CellType::higher_nodes`]).
pub fn cell_reference_nodes(cell: CellType) -> Vec<[f64; 3]> {
    let corners: &[[f64; 3]] = match cell.linear() {
        CellType::Tet4 => &TET4_REF_NODES,
        CellType::Wedge6 => &WEDGE6_REF_NODES,
        CellType::Pyramid5 => &PYRAMID5_REF_NODES,
        _ => &HEX8_REF_NODES,
    };
    let mut nodes = corners.to_vec();
    nodes.extend(cell.higher_nodes().iter().map(|of| mean(corners, of)));
    nodes
}

/// As [`cell_reference_nodes`], on the reference facet.
pub fn facet_reference_nodes(facet: FacetType) -> Vec<[f64; 2]> {
    let corners: &[[f64; 2]] = match facet.linear() {
        FacetType::Tri3 => &TRI3_REF_NODES,
        _ => &QUAD4_REF_NODES,
    };
    let mut nodes = corners.to_vec();
    nodes.extend(facet.higher_nodes().iter().map(|of| mean(corners, of)));
    nodes
}

fn mean<const D: usize>(points: &[[f64; D]], of: &[usize]) -> [f64; D] {
    let mut m = [0.0; D];
    for &a in of {
        for (mi, pi) in m.iter_mut().zip(points[a]) {
            *mi += pi / of.len() as f64;
        }
    }
    m
}

/// Values `n[a]` and reference gradients `dn[a][j] = ∂N_a/∂ξ_j` of a cell's
/// shape functions at one point; the first `nodes` entries are meaningful.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CellShape {
    pub nodes: usize,
    pub n: [f64; MAX_CELL_NODES],
    pub dn: [[f64; 3]; MAX_CELL_NODES],
}

/// Values and reference gradients (two surface coordinates) of a facet's
/// shape functions at one point, for facets of up to `N` nodes; the first
/// `nodes` entries are meaningful.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct FacetShape<const N: usize = MAX_FACET_NODES> {
    pub nodes: usize,
    pub n: [f64; N],
    pub dn: [[f64; 2]; N],
}

/// Writes `N_a(ξ)` and `∂N_a/∂ξ` of `cell` into `n` and `dn`, which hold
/// exactly `cell.nodes()` entries.
pub fn eval_cell(cell: CellType, xi: [f64; 3], n: &mut [f64], dn: &mut [[f64; 3]]) {
    match cell {
        CellType::Hex8 => hex8_into(xi, n, dn),
        CellType::Tet4 => tet4_into(xi, n, dn),
        CellType::Tet10 => higher::tet10(xi, n, dn),
        CellType::Hex20 => higher::hex20(xi, n, dn),
        CellType::Hex27 => higher::hex27(xi, n, dn),
        CellType::Wedge6 => higher::wedge6(xi, n, dn),
        CellType::Wedge15 => higher::wedge15(xi, n, dn),
        CellType::Pyramid5 => higher::pyramid5(xi, n, dn),
    }
}

/// Writes `N_a(ξ)` and `∂N_a/∂ξ` of `facet` into `n` and `dn`, which hold
/// exactly `facet.nodes()` entries.
pub fn eval_facet(facet: FacetType, xi: [f64; 2], n: &mut [f64], dn: &mut [[f64; 2]]) {
    match facet {
        FacetType::Quad4 => quad4_into(xi, n, dn),
        FacetType::Tri3 => tri3_into(xi, n, dn),
        FacetType::Tri6 => higher::tri6(xi, n, dn),
        FacetType::Quad8 => higher::quad8(xi, n, dn),
        FacetType::Quad9 => higher::quad9(xi, n, dn),
    }
}

pub fn cell_shape(cell: CellType, xi: [f64; 3]) -> CellShape {
    let mut s = CellShape {
        nodes: cell.nodes(),
        n: [0.0; MAX_CELL_NODES],
        dn: [[0.0; 3]; MAX_CELL_NODES],
    };
    let k = s.nodes;
    eval_cell(cell, xi, &mut s.n[..k], &mut s.dn[..k]);
    s
}

impl<const N: usize> FacetShape<N> {
    /// The shape of `facet` at `xi`, or `None` when it has more than `N`
    /// nodes.
    pub fn of(facet: FacetType, xi: [f64; 2]) -> Option<Self> {
        let k = facet.nodes();
        if k > N {
            return None;
        }
        let mut s = FacetShape {
            nodes: k,
            n: [0.0; N],
            dn: [[0.0; 2]; N],
        };
        eval_facet(facet, xi, &mut s.n[..k], &mut s.dn[..k]);
        Some(s)
    }

    /// The second derivatives (see [`eval_facet_second`]) of `facet` at
    /// `xi`, or `None` when it has more than `N` nodes.
    pub fn second(facet: FacetType, xi: [f64; 2]) -> Option<[[f64; 3]; N]> {
        let k = facet.nodes();
        if k > N {
            return None;
        }
        let mut ddn = [[0.0; 3]; N];
        eval_facet_second(facet, xi, &mut ddn[..k]);
        Some(ddn)
    }

    /// The third derivatives (see [`eval_facet_third`]) of `facet` at `xi`,
    /// or `None` when it has more than `N` nodes.
    pub fn third(facet: FacetType, xi: [f64; 2]) -> Option<[[f64; 2]; N]> {
        let k = facet.nodes();
        if k > N {
            return None;
        }
        let mut dddn = [[0.0; 2]; N];
        eval_facet_third(facet, xi, &mut dddn[..k]);
        Some(dddn)
    }
}

/// Writes the second reference derivatives `[∂²N_a/∂ξ₁², ∂²N_a/∂ξ₁∂ξ₂,
/// ∂²N_a/∂ξ₂²]` of `facet` at `xi` into `ddn`, which holds exactly
/// `facet.nodes()` entries (zero for tri3; only the mixed one for quad4).
pub fn eval_facet_second(facet: FacetType, xi: [f64; 2], ddn: &mut [[f64; 3]]) {
    match facet {
        FacetType::Quad4 => {
            for (d, node) in ddn.iter_mut().zip(&QUAD4_REF_NODES) {
                *d = [0.0, 0.25 * node[0] * node[1], 0.0];
            }
        }
        FacetType::Tri3 => ddn.fill([0.0; 3]),
        FacetType::Tri6 => higher::tri6_second(ddn),
        FacetType::Quad8 => higher::quad8_second(xi, ddn),
        FacetType::Quad9 => higher::quad9_second(xi, ddn),
    }
}

/// Writes the third reference derivatives `[∂³N_a/∂ξ₁²∂ξ₂,
/// ∂³N_a/∂ξ₁∂ξ₂²]` of `facet` at `xi` into `dddn` (`facet.nodes()`
/// entries). `∂³/∂ξ₁³` and `∂³/∂ξ₂³` vanish on every facet type (each is at
/// most quadratic in either coordinate alone), and so do these two on the
/// triangles and on quad4.
pub fn eval_facet_third(facet: FacetType, xi: [f64; 2], dddn: &mut [[f64; 2]]) {
    match facet {
        FacetType::Quad4 | FacetType::Tri3 | FacetType::Tri6 => dddn.fill([0.0; 2]),
        FacetType::Quad8 => higher::quad8_third(dddn),
        FacetType::Quad9 => higher::quad9_third(xi, dddn),
    }
}

/// Any facet's shape at `xi`.
pub fn facet_shape(facet: FacetType, xi: [f64; 2]) -> FacetShape {
    let mut s = FacetShape {
        nodes: facet.nodes(),
        n: [0.0; MAX_FACET_NODES],
        dn: [[0.0; 2]; MAX_FACET_NODES],
    };
    let k = s.nodes;
    eval_facet(facet, xi, &mut s.n[..k], &mut s.dn[..k]);
    s
}

/// The first-order shape functions on the facet's corners (the facet's own
/// for tri3 and quad4): what contact, which handles first-order facets only,
/// evaluates, in a holder of four.
pub fn linear_facet_shape(facet: FacetType, xi: [f64; 2]) -> FacetShape<4> {
    let mut s = FacetShape {
        nodes: facet.corners(),
        n: [0.0; 4],
        dn: [[0.0; 2]; 4],
    };
    let k = s.nodes;
    match facet.linear() {
        FacetType::Tri3 => tri3_into(xi, &mut s.n[..k], &mut s.dn[..k]),
        _ => quad4_into(xi, &mut s.n[..k], &mut s.dn[..k]),
    }
    s
}

/// Trilinear: N_a = ⅛ (1 + ξ ξ_a)(1 + η η_a)(1 + ζ ζ_a).
pub fn hex8(xi: [f64; 3]) -> CellShape {
    cell_shape(CellType::Hex8, xi)
}

fn hex8_into(xi: [f64; 3], n: &mut [f64], dn: &mut [[f64; 3]]) {
    for ((na, da), node) in n.iter_mut().zip(dn.iter_mut()).zip(&HEX8_REF_NODES) {
        let f = [
            1.0 + xi[0] * node[0],
            1.0 + xi[1] * node[1],
            1.0 + xi[2] * node[2],
        ];
        *na = 0.125 * f[0] * f[1] * f[2];
        *da = [
            0.125 * node[0] * f[1] * f[2],
            0.125 * f[0] * node[1] * f[2],
            0.125 * f[0] * f[1] * node[2],
        ];
    }
}

/// Barycentric: N = (1 − ξ − η − ζ, ξ, η, ζ).
pub fn tet4(xi: [f64; 3]) -> CellShape {
    cell_shape(CellType::Tet4, xi)
}

fn tet4_into(xi: [f64; 3], n: &mut [f64], dn: &mut [[f64; 3]]) {
    n.copy_from_slice(&[1.0 - xi[0] - xi[1] - xi[2], xi[0], xi[1], xi[2]]);
    dn.copy_from_slice(&[
        [-1.0, -1.0, -1.0],
        [1.0, 0.0, 0.0],
        [0.0, 1.0, 0.0],
        [0.0, 0.0, 1.0],
    ]);
}

/// Bilinear: N_a = ¼ (1 + ξ ξ_a)(1 + η η_a).
pub fn quad4(xi: [f64; 2]) -> FacetShape<4> {
    linear_facet_shape(FacetType::Quad4, xi)
}

fn quad4_into(xi: [f64; 2], n: &mut [f64], dn: &mut [[f64; 2]]) {
    for ((na, da), node) in n.iter_mut().zip(dn.iter_mut()).zip(&QUAD4_REF_NODES) {
        let f = [1.0 + xi[0] * node[0], 1.0 + xi[1] * node[1]];
        *na = 0.25 * f[0] * f[1];
        *da = [0.25 * node[0] * f[1], 0.25 * f[0] * node[1]];
    }
}

/// Linear: N = (1 − ξ − η, ξ, η).
pub fn tri3(xi: [f64; 2]) -> FacetShape<4> {
    linear_facet_shape(FacetType::Tri3, xi)
}

fn tri3_into(xi: [f64; 2], n: &mut [f64], dn: &mut [[f64; 2]]) {
    n.copy_from_slice(&[1.0 - xi[0] - xi[1], xi[0], xi[1]]);
    dn.copy_from_slice(&[[-1.0, -1.0], [1.0, 0.0], [0.0, 1.0]]);
}

#[cfg(test)]
mod tests;

//! Shape functions of the second-order cells and facets, the wedge and the
//! pyramid. Each writes exactly its element's node count.
//!
//! - tet10, tri6: `L(2L − 1)` at corners, `4 L_i L_j` at mid-edges, in the
//!   barycentric coordinates `L`.
//! - hex20, quad8: the serendipity functions (Zienkiewicz & Taylor, *The
//!   Finite Element Method*, vol. 1, §8.7).
//! - hex27, quad9: tensor products of the 1-D quadratic Lagrange functions
//!   on {−1, 0, 1}.
//! - wedge6, wedge15: triangle × line (ibid. §8.9).
//! - pyramid5: the rational functions of Bedrosian (1992, "Shape functions
//!   and integration formulas for three-dimensional finite element
//!   analysis", IJNME 35): `N_a = (1−ζ+ξ_aξ)(1−ζ+η_aη) / (4(1−ζ))` on the
//!   base, `ζ` at the apex; they reproduce linear fields and are
//!   continuous with the neighbouring tets' and hexes' faces.

use super::QUAD4_REF_NODES;
use crate::fem::CellType;

/// Reference coordinates of the hex27 nodes (the first 20 are hex20's):
/// corners, mid-edges, face centres (ξ−, ξ+, η−, η+, ζ−, ζ+), centre.
pub const HEX27_REF_NODES: [[f64; 3]; 27] = [
    [-1.0, -1.0, -1.0],
    [1.0, -1.0, -1.0],
    [1.0, 1.0, -1.0],
    [-1.0, 1.0, -1.0],
    [-1.0, -1.0, 1.0],
    [1.0, -1.0, 1.0],
    [1.0, 1.0, 1.0],
    [-1.0, 1.0, 1.0],
    [0.0, -1.0, -1.0],
    [1.0, 0.0, -1.0],
    [0.0, 1.0, -1.0],
    [-1.0, 0.0, -1.0],
    [0.0, -1.0, 1.0],
    [1.0, 0.0, 1.0],
    [0.0, 1.0, 1.0],
    [-1.0, 0.0, 1.0],
    [-1.0, -1.0, 0.0],
    [1.0, -1.0, 0.0],
    [1.0, 1.0, 0.0],
    [-1.0, 1.0, 0.0],
    [-1.0, 0.0, 0.0],
    [1.0, 0.0, 0.0],
    [0.0, -1.0, 0.0],
    [0.0, 1.0, 0.0],
    [0.0, 0.0, -1.0],
    [0.0, 0.0, 1.0],
    [0.0, 0.0, 0.0],
];

/// Quad9 reference nodes: quad4's corners, the mid-edges, the centre.
const QUAD9_REF_NODES: [[f64; 2]; 9] = [
    [-1.0, -1.0],
    [1.0, -1.0],
    [1.0, 1.0],
    [-1.0, 1.0],
    [0.0, -1.0],
    [1.0, 0.0],
    [0.0, 1.0],
    [-1.0, 0.0],
    [0.0, 0.0],
];

/// The 1-D quadratic Lagrange function of the node at `a ∈ {−1, 0, 1}` and
/// its derivative, at `t`.
fn lagrange(a: f64, t: f64) -> (f64, f64) {
    if a < 0.0 {
        (0.5 * t * (t - 1.0), t - 0.5)
    } else if a > 0.0 {
        (0.5 * t * (t + 1.0), t + 0.5)
    } else {
        (1.0 - t * t, -2.0 * t)
    }
}

/// The second derivative of [`lagrange`] (constant).
fn lagrange_second(a: f64) -> f64 {
    if a == 0.0 {
        -2.0
    } else {
        1.0
    }
}

/// Barycentric coordinates of the triangle and their constant gradients.
fn triangle(xi: [f64; 2]) -> ([f64; 3], [[f64; 2]; 3]) {
    (
        [1.0 - xi[0] - xi[1], xi[0], xi[1]],
        [[-1.0, -1.0], [1.0, 0.0], [0.0, 1.0]],
    )
}

/// Quadratic simplex functions over barycentric coordinates `l` (gradients
/// `dl`): corners `L(2L − 1)`, then `4 L_i L_j` for each edge of `edges`.
fn quadratic_simplex<const D: usize>(
    l: &[f64],
    dl: &[[f64; D]],
    edges: &[&[usize]],
    n: &mut [f64],
    dn: &mut [[f64; D]],
) {
    for (a, (&la, dla)) in l.iter().zip(dl).enumerate() {
        n[a] = la * (2.0 * la - 1.0);
        dn[a] = dla.map(|d| (4.0 * la - 1.0) * d);
    }
    for (k, e) in edges.iter().enumerate() {
        let (i, j) = (e[0], e[1]);
        let a = l.len() + k;
        n[a] = 4.0 * l[i] * l[j];
        dn[a] = std::array::from_fn(|d| 4.0 * (dl[i][d] * l[j] + l[i] * dl[j][d]));
    }
}

pub(super) fn tet10(xi: [f64; 3], n: &mut [f64], dn: &mut [[f64; 3]]) {
    let l = [1.0 - xi[0] - xi[1] - xi[2], xi[0], xi[1], xi[2]];
    let dl = [
        [-1.0, -1.0, -1.0],
        [1.0, 0.0, 0.0],
        [0.0, 1.0, 0.0],
        [0.0, 0.0, 1.0],
    ];
    quadratic_simplex(&l, &dl, CellType::Tet10.higher_nodes(), n, dn);
}

pub(super) fn tri6(xi: [f64; 2], n: &mut [f64], dn: &mut [[f64; 2]]) {
    let (l, dl) = triangle(xi);
    quadratic_simplex(&l, &dl, crate::fem::FacetType::Tri6.higher_nodes(), n, dn);
}

/// Second derivatives of tri6 (constant): corners `4 ∂L_a ∂L_a`, mid-edges
/// `4 (∂L_i ∂L_j + ∂L_j ∂L_i)`, as `[11, 12, 22]`.
pub(super) fn tri6_second(ddn: &mut [[f64; 3]]) {
    let (_, dl) = triangle([0.0, 0.0]);
    let sym = |g: [f64; 2], h: [f64; 2]| {
        [
            4.0 * (g[0] * h[0] + h[0] * g[0]),
            4.0 * (g[0] * h[1] + h[0] * g[1]),
            4.0 * (g[1] * h[1] + h[1] * g[1]),
        ]
    };
    for a in 0..3 {
        ddn[a] = sym(dl[a], dl[a]).map(|v| 0.5 * v);
    }
    for (k, e) in crate::fem::FacetType::Tri6
        .higher_nodes()
        .iter()
        .enumerate()
    {
        ddn[3 + k] = sym(dl[e[0]], dl[e[1]]);
    }
}

/// Serendipity hex: corners `⅛ Π(1 + ξ_j a_j) (Σ ξ_j a_j − 2)`, mid-edge
/// nodes (`a_k = 0`) `¼ (1 − ξ_k²) Π_{j≠k} (1 + ξ_j a_j)`.
pub(super) fn hex20(xi: [f64; 3], n: &mut [f64], dn: &mut [[f64; 3]]) {
    for (a, node) in HEX27_REF_NODES[..20].iter().enumerate() {
        let f = [0, 1, 2].map(|j| 1.0 + xi[j] * node[j]);
        if a < 8 {
            let s = xi[0] * node[0] + xi[1] * node[1] + xi[2] * node[2] - 2.0;
            n[a] = 0.125 * f[0] * f[1] * f[2] * s;
            dn[a] = std::array::from_fn(|j| {
                let others = f[(j + 1) % 3] * f[(j + 2) % 3];
                0.125 * node[j] * others * (f[j] + s)
            });
        } else {
            // The axis along the edge (the zero coordinate).
            let k = (0..3).find(|&j| node[j] == 0.0).unwrap_or(0);
            let bubble = 1.0 - xi[k] * xi[k];
            let (p, q) = ((k + 1) % 3, (k + 2) % 3);
            n[a] = 0.25 * bubble * f[p] * f[q];
            let mut d = [0.0; 3];
            d[k] = -0.5 * xi[k] * f[p] * f[q];
            d[p] = 0.25 * bubble * node[p] * f[q];
            d[q] = 0.25 * bubble * f[p] * node[q];
            dn[a] = d;
        }
    }
}

pub(super) fn hex27(xi: [f64; 3], n: &mut [f64], dn: &mut [[f64; 3]]) {
    for (a, node) in HEX27_REF_NODES.iter().enumerate() {
        let l = [0, 1, 2].map(|j| lagrange(node[j], xi[j]));
        n[a] = l[0].0 * l[1].0 * l[2].0;
        dn[a] = [
            l[0].1 * l[1].0 * l[2].0,
            l[0].0 * l[1].1 * l[2].0,
            l[0].0 * l[1].0 * l[2].1,
        ];
    }
}

/// Serendipity quad: corners `¼ (1 + ξξ_a)(1 + ηη_a)(ξξ_a + ηη_a − 1)`,
/// mid-edges `½ (1 − ξ²)(1 + ηη_a)` or `½ (1 + ξξ_a)(1 − η²)`.
pub(super) fn quad8(xi: [f64; 2], n: &mut [f64], dn: &mut [[f64; 2]]) {
    for (a, node) in QUAD9_REF_NODES[..8].iter().enumerate() {
        let f = [1.0 + xi[0] * node[0], 1.0 + xi[1] * node[1]];
        if a < 4 {
            let s = xi[0] * node[0] + xi[1] * node[1] - 1.0;
            n[a] = 0.25 * f[0] * f[1] * s;
            dn[a] = [
                0.25 * node[0] * f[1] * (f[0] + s),
                0.25 * node[1] * f[0] * (f[1] + s),
            ];
        } else if node[0] == 0.0 {
            n[a] = 0.5 * (1.0 - xi[0] * xi[0]) * f[1];
            dn[a] = [-xi[0] * f[1], 0.5 * (1.0 - xi[0] * xi[0]) * node[1]];
        } else {
            n[a] = 0.5 * f[0] * (1.0 - xi[1] * xi[1]);
            dn[a] = [0.5 * node[0] * (1.0 - xi[1] * xi[1]), -xi[1] * f[0]];
        }
    }
}

/// Second derivatives of [`quad8`] as `[ξξ, ξη, ηη]`.
pub(super) fn quad8_second(xi: [f64; 2], ddn: &mut [[f64; 3]]) {
    for (a, node) in QUAD9_REF_NODES[..8].iter().enumerate() {
        let f = [1.0 + xi[0] * node[0], 1.0 + xi[1] * node[1]];
        ddn[a] = if a < 4 {
            let s = xi[0] * node[0] + xi[1] * node[1] - 1.0;
            [
                0.5 * f[1],
                0.25 * node[0] * node[1] * (f[0] + f[1] + s),
                0.5 * f[0],
            ]
        } else if node[0] == 0.0 {
            [-f[1], -xi[0] * node[1], 0.0]
        } else {
            [0.0, -xi[1] * node[0], -f[0]]
        };
    }
}

/// Third derivatives of [`quad8`] as `[ξξη, ξηη]` (constant).
pub(super) fn quad8_third(dddn: &mut [[f64; 2]]) {
    for (a, node) in QUAD9_REF_NODES[..8].iter().enumerate() {
        dddn[a] = if a < 4 {
            [0.5 * node[1], 0.5 * node[0]]
        } else if node[0] == 0.0 {
            [-node[1], 0.0]
        } else {
            [0.0, -node[0]]
        };
    }
}

/// Third derivatives of [`quad9`] as `[ξξη, ξηη]`.
pub(super) fn quad9_third(xi: [f64; 2], dddn: &mut [[f64; 2]]) {
    for (a, node) in QUAD9_REF_NODES.iter().enumerate() {
        let l = [lagrange(node[0], xi[0]), lagrange(node[1], xi[1])];
        dddn[a] = [
            lagrange_second(node[0]) * l[1].1,
            l[0].1 * lagrange_second(node[1]),
        ];
    }
}

/// Second derivatives of [`quad9`] as `[ξξ, ξη, ηη]`.
pub(super) fn quad9_second(xi: [f64; 2], ddn: &mut [[f64; 3]]) {
    for (a, node) in QUAD9_REF_NODES.iter().enumerate() {
        let l = [lagrange(node[0], xi[0]), lagrange(node[1], xi[1])];
        ddn[a] = [
            lagrange_second(node[0]) * l[1].0,
            l[0].1 * l[1].1,
            l[0].0 * lagrange_second(node[1]),
        ];
    }
}

pub(super) fn quad9(xi: [f64; 2], n: &mut [f64], dn: &mut [[f64; 2]]) {
    for (a, node) in QUAD9_REF_NODES.iter().enumerate() {
        let l = [lagrange(node[0], xi[0]), lagrange(node[1], xi[1])];
        n[a] = l[0].0 * l[1].0;
        dn[a] = [l[0].1 * l[1].0, l[0].0 * l[1].1];
    }
}

/// Linear triangle × linear line.
pub(super) fn wedge6(xi: [f64; 3], n: &mut [f64], dn: &mut [[f64; 3]]) {
    let (l, dl) = triangle([xi[0], xi[1]]);
    for a in 0..6 {
        let (t, s) = (a % 3, if a < 3 { -1.0 } else { 1.0 });
        let z = 0.5 * (1.0 + s * xi[2]);
        n[a] = l[t] * z;
        dn[a] = [dl[t][0] * z, dl[t][1] * z, 0.5 * s * l[t]];
    }
}

/// Quadratic serendipity wedge: corners `½ L [(2L − 1)(1 + sζ) − (1 − ζ²)]`,
/// triangle mid-edges `2 L_i L_j (1 + sζ)`, vertical mid-edges
/// `L (1 − ζ²)`, with `s = ∓1` the level of the node.
pub(super) fn wedge15(xi: [f64; 3], n: &mut [f64], dn: &mut [[f64; 3]]) {
    let (l, dl) = triangle([xi[0], xi[1]]);
    let z = xi[2];
    let bubble = 1.0 - z * z;
    for a in 0..6 {
        let (t, s) = (a % 3, if a < 3 { -1.0 } else { 1.0 });
        let lin = 1.0 + s * z;
        n[a] = 0.5 * l[t] * ((2.0 * l[t] - 1.0) * lin - bubble);
        let g = 0.5 * ((4.0 * l[t] - 1.0) * lin - bubble);
        dn[a] = [
            g * dl[t][0],
            g * dl[t][1],
            0.5 * l[t] * ((2.0 * l[t] - 1.0) * s + 2.0 * z),
        ];
    }
    for (k, e) in CellType::Wedge15.higher_nodes().iter().enumerate() {
        let a = 6 + k;
        let (i, j) = (e[0] % 3, e[1] % 3);
        if k < 6 {
            let s = if k < 3 { -1.0 } else { 1.0 };
            let lin = 1.0 + s * z;
            n[a] = 2.0 * l[i] * l[j] * lin;
            dn[a] = [
                2.0 * (dl[i][0] * l[j] + l[i] * dl[j][0]) * lin,
                2.0 * (dl[i][1] * l[j] + l[i] * dl[j][1]) * lin,
                2.0 * l[i] * l[j] * s,
            ];
        } else {
            n[a] = l[i] * bubble;
            dn[a] = [dl[i][0] * bubble, dl[i][1] * bubble, -2.0 * z * l[i]];
        }
    }
}

/// Bedrosian's rational pyramid. The functions and their gradients are
/// bounded but not continuous at the apex, which no quadrature point
/// reaches; `1 − ζ` is kept away from zero so the apex itself evaluates to
/// finite values.
pub(super) fn pyramid5(xi: [f64; 3], n: &mut [f64], dn: &mut [[f64; 3]]) {
    let r = (1.0 - xi[2]).max(1e-12);
    for (a, c) in QUAD4_REF_NODES.iter().enumerate() {
        let (p, q) = (r + c[0] * xi[0], r + c[1] * xi[1]);
        n[a] = p * q / (4.0 * r);
        dn[a] = [
            c[0] * q / (4.0 * r),
            c[1] * p / (4.0 * r),
            0.25 * (c[0] * c[1] * xi[0] * xi[1] / (r * r) - 1.0),
        ];
    }
    n[4] = xi[2];
    dn[4] = [0.0, 0.0, 1.0];
}

//! Shape functions and their derivatives with respect to the reference
//! coordinates.
//!
//! Results come back in fixed-size arrays sized for the largest shape, so
//! evaluating them in the element loops never allocates; only the first
//! `nodes()` entries are meaningful.

use super::{CellType, FacetType, MAX_CELL_NODES, MAX_FACET_NODES};

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

/// Reference coordinates of the quad4 nodes.
pub const QUAD4_REF_NODES: [[f64; 2]; 4] = [[-1.0, -1.0], [1.0, -1.0], [1.0, 1.0], [-1.0, 1.0]];

/// Reference coordinates of the tri3 nodes.
pub const TRI3_REF_NODES: [[f64; 2]; 3] = [[0.0, 0.0], [1.0, 0.0], [0.0, 1.0]];

/// Values `n[a]` and reference gradients `dn[a][j] = ∂N_a/∂ξ_j` of a cell's
/// shape functions at one point.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CellShape {
    pub nodes: usize,
    pub n: [f64; MAX_CELL_NODES],
    pub dn: [[f64; 3]; MAX_CELL_NODES],
}

/// Values and reference gradients (two surface coordinates) of a facet's
/// shape functions at one point.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct FacetShape {
    pub nodes: usize,
    pub n: [f64; MAX_FACET_NODES],
    pub dn: [[f64; 2]; MAX_FACET_NODES],
}

pub fn cell_shape(cell: CellType, xi: [f64; 3]) -> CellShape {
    match cell {
        CellType::Hex8 => hex8(xi),
        CellType::Tet4 => tet4(xi),
    }
}

pub fn facet_shape(facet: FacetType, xi: [f64; 2]) -> FacetShape {
    match facet {
        FacetType::Quad4 => quad4(xi),
        FacetType::Tri3 => tri3(xi),
    }
}

/// Trilinear: N_a = ⅛ (1 + ξ ξ_a)(1 + η η_a)(1 + ζ ζ_a).
pub fn hex8(xi: [f64; 3]) -> CellShape {
    let mut s = CellShape {
        nodes: 8,
        n: [0.0; MAX_CELL_NODES],
        dn: [[0.0; 3]; MAX_CELL_NODES],
    };
    for (a, node) in HEX8_REF_NODES.iter().enumerate() {
        let f = [
            1.0 + xi[0] * node[0],
            1.0 + xi[1] * node[1],
            1.0 + xi[2] * node[2],
        ];
        s.n[a] = 0.125 * f[0] * f[1] * f[2];
        s.dn[a] = [
            0.125 * node[0] * f[1] * f[2],
            0.125 * f[0] * node[1] * f[2],
            0.125 * f[0] * f[1] * node[2],
        ];
    }
    s
}

/// Barycentric: N = (1 − ξ − η − ζ, ξ, η, ζ).
pub fn tet4(xi: [f64; 3]) -> CellShape {
    let mut s = CellShape {
        nodes: 4,
        n: [0.0; MAX_CELL_NODES],
        dn: [[0.0; 3]; MAX_CELL_NODES],
    };
    s.n[..4].copy_from_slice(&[1.0 - xi[0] - xi[1] - xi[2], xi[0], xi[1], xi[2]]);
    s.dn[..4].copy_from_slice(&[
        [-1.0, -1.0, -1.0],
        [1.0, 0.0, 0.0],
        [0.0, 1.0, 0.0],
        [0.0, 0.0, 1.0],
    ]);
    s
}

/// Bilinear: N_a = ¼ (1 + ξ ξ_a)(1 + η η_a).
pub fn quad4(xi: [f64; 2]) -> FacetShape {
    let mut s = FacetShape {
        nodes: 4,
        n: [0.0; MAX_FACET_NODES],
        dn: [[0.0; 2]; MAX_FACET_NODES],
    };
    for (a, node) in QUAD4_REF_NODES.iter().enumerate() {
        let f = [1.0 + xi[0] * node[0], 1.0 + xi[1] * node[1]];
        s.n[a] = 0.25 * f[0] * f[1];
        s.dn[a] = [0.25 * node[0] * f[1], 0.25 * f[0] * node[1]];
    }
    s
}

/// Linear: N = (1 − ξ − η, ξ, η).
pub fn tri3(xi: [f64; 2]) -> FacetShape {
    let mut s = FacetShape {
        nodes: 3,
        n: [0.0; MAX_FACET_NODES],
        dn: [[0.0; 2]; MAX_FACET_NODES],
    };
    s.n[..3].copy_from_slice(&[1.0 - xi[0] - xi[1], xi[0], xi[1]]);
    s.dn[..3].copy_from_slice(&[[-1.0, -1.0], [1.0, 0.0], [0.0, 1.0]]);
    s
}

#[cfg(test)]
mod tests {
    use super::super::test_util::Lcg;
    use super::*;

    const H: f64 = 1e-6;

    fn cell_points(cell: CellType, rng: &mut Lcg) -> Vec<[f64; 3]> {
        (0..20)
            .map(|_| {
                let p = rng.vec3(1.0);
                match cell {
                    CellType::Hex8 => p,
                    // Map into the simplex; exactness does not need the
                    // points inside, but it keeps the test honest.
                    CellType::Tet4 => p.map(|v| (v + 1.0) / 6.0),
                }
            })
            .collect()
    }

    #[test]
    fn cell_partition_of_unity_and_gradient_sum() {
        let mut rng = Lcg::new(1);
        for cell in [CellType::Hex8, CellType::Tet4] {
            for xi in cell_points(cell, &mut rng) {
                let s = cell_shape(cell, xi);
                assert_eq!(s.nodes, cell.nodes());
                let sum: f64 = s.n[..s.nodes].iter().sum();
                assert!((sum - 1.0).abs() < 1e-14, "{} sum {sum}", cell.name());
                for j in 0..3 {
                    let g: f64 = s.dn[..s.nodes].iter().map(|d| d[j]).sum();
                    assert!(g.abs() < 1e-14, "{} grad sum {g}", cell.name());
                }
            }
        }
    }

    #[test]
    fn facet_partition_of_unity_and_gradient_sum() {
        let mut rng = Lcg::new(2);
        for facet in [FacetType::Quad4, FacetType::Tri3] {
            for _ in 0..20 {
                let xi = [rng.next(), rng.next()];
                let s = facet_shape(facet, xi);
                assert_eq!(s.nodes, facet.nodes());
                let sum: f64 = s.n[..s.nodes].iter().sum();
                assert!((sum - 1.0).abs() < 1e-14);
                for j in 0..2 {
                    let g: f64 = s.dn[..s.nodes].iter().map(|d| d[j]).sum();
                    assert!(g.abs() < 1e-14);
                }
            }
        }
    }

    #[test]
    fn kronecker_property_at_nodes() {
        let cells: [(CellType, &[[f64; 3]]); 2] = [
            (CellType::Hex8, &HEX8_REF_NODES),
            (CellType::Tet4, &TET4_REF_NODES),
        ];
        for (cell, nodes) in cells {
            for (b, xb) in nodes.iter().enumerate() {
                let s = cell_shape(cell, *xb);
                for a in 0..cell.nodes() {
                    let expect = if a == b { 1.0 } else { 0.0 };
                    assert!((s.n[a] - expect).abs() < 1e-15);
                }
            }
        }
        let facets: [(FacetType, &[[f64; 2]]); 2] = [
            (FacetType::Quad4, &QUAD4_REF_NODES),
            (FacetType::Tri3, &TRI3_REF_NODES),
        ];
        for (facet, nodes) in facets {
            for (b, xb) in nodes.iter().enumerate() {
                let s = facet_shape(facet, *xb);
                for a in 0..facet.nodes() {
                    let expect = if a == b { 1.0 } else { 0.0 };
                    assert!((s.n[a] - expect).abs() < 1e-15);
                }
            }
        }
    }

    #[test]
    fn cell_gradients_match_finite_differences() {
        let mut rng = Lcg::new(3);
        for cell in [CellType::Hex8, CellType::Tet4] {
            for xi in cell_points(cell, &mut rng) {
                let s = cell_shape(cell, xi);
                for j in 0..3 {
                    let mut xp = xi;
                    let mut xm = xi;
                    xp[j] += H;
                    xm[j] -= H;
                    let (sp, sm) = (cell_shape(cell, xp), cell_shape(cell, xm));
                    for a in 0..cell.nodes() {
                        let fd = (sp.n[a] - sm.n[a]) / (2.0 * H);
                        assert!(
                            (fd - s.dn[a][j]).abs() < 1e-9,
                            "{} a={a} j={j}",
                            cell.name()
                        );
                    }
                }
            }
        }
    }

    #[test]
    fn facet_gradients_match_finite_differences() {
        let mut rng = Lcg::new(4);
        for facet in [FacetType::Quad4, FacetType::Tri3] {
            for _ in 0..20 {
                let xi = [rng.next(), rng.next()];
                let s = facet_shape(facet, xi);
                for j in 0..2 {
                    let mut xp = xi;
                    let mut xm = xi;
                    xp[j] += H;
                    xm[j] -= H;
                    let (sp, sm) = (facet_shape(facet, xp), facet_shape(facet, xm));
                    for a in 0..facet.nodes() {
                        let fd = (sp.n[a] - sm.n[a]) / (2.0 * H);
                        assert!((fd - s.dn[a][j]).abs() < 1e-9);
                    }
                }
            }
        }
    }
}

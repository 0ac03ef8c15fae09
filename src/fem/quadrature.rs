//! Quadrature rules on the reference cells and facets.
//!
//! Points always carry three coordinates so one type serves cells and
//! facets; facet rules leave the third coordinate at zero. Weights sum to the
//! reference measure: 8 (cube), 1/6 (tetrahedron), 4 (square), 1/2
//! (triangle).

use super::{CellType, FacetType, FemError};

#[derive(Debug, Clone, PartialEq)]
pub struct QuadRule {
    pub points: Vec<[f64; 3]>,
    pub weights: Vec<f64>,
}

/// Gauss–Legendre abscissae and weights on [-1, 1], exact to degree 2n − 1.
fn gauss_legendre(n: usize) -> Option<(Vec<f64>, Vec<f64>)> {
    let rule = match n {
        1 => (vec![0.0], vec![2.0]),
        2 => {
            let a = 1.0 / 3f64.sqrt();
            (vec![-a, a], vec![1.0, 1.0])
        }
        3 => {
            let a = 0.6f64.sqrt();
            (vec![-a, 0.0, a], vec![5.0 / 9.0, 8.0 / 9.0, 5.0 / 9.0])
        }
        4 => {
            let s = (6.0f64 / 5.0).sqrt();
            let inner = (3.0 / 7.0 - 2.0 / 7.0 * s).sqrt();
            let outer = (3.0 / 7.0 + 2.0 / 7.0 * s).sqrt();
            let w_inner = (18.0 + 30f64.sqrt()) / 36.0;
            let w_outer = (18.0 - 30f64.sqrt()) / 36.0;
            (
                vec![-outer, -inner, inner, outer],
                vec![w_outer, w_inner, w_inner, w_outer],
            )
        }
        _ => return None,
    };
    Some(rule)
}

impl QuadRule {
    pub fn len(&self) -> usize {
        self.weights.len()
    }

    pub fn is_empty(&self) -> bool {
        self.weights.is_empty()
    }

    /// Rejects rules whose lists disagree, are empty or hold non-finite
    /// values: the fields are public, so a rule may not come from here.
    pub fn check(&self) -> Result<(), FemError> {
        if self.points.is_empty() || self.points.len() != self.weights.len() {
            return Err(FemError::MalformedRule {
                points: self.points.len(),
                weights: self.weights.len(),
            });
        }
        let finite = self.weights.iter().all(|w| w.is_finite())
            && self.points.iter().flatten().all(|c| c.is_finite());
        if finite {
            Ok(())
        } else {
            Err(FemError::NonFinite {
                what: "quadrature rule",
            })
        }
    }

    /// Tensor Gauss rule with `n` points per direction (n = 1..=4) on the
    /// cube `[-1, 1]³`.
    pub fn hex_gauss(n: usize) -> Result<Self, FemError> {
        let (x, w) = gauss_legendre(n).ok_or(FemError::UnsupportedRule { what: "hex", n })?;
        let mut rule = Self::with_capacity(n * n * n);
        for k in 0..n {
            for j in 0..n {
                for i in 0..n {
                    rule.push([x[i], x[j], x[k]], w[i] * w[j] * w[k]);
                }
            }
        }
        Ok(rule)
    }

    /// The default for hex8: exact for the trilinear stiffness of an affine
    /// cell and for the volume of any trilinear cell.
    pub fn hex_2x2x2() -> Self {
        Self::tensor_or_empty(Self::hex_gauss(2))
    }

    pub fn hex_3x3x3() -> Self {
        Self::tensor_or_empty(Self::hex_gauss(3))
    }

    /// Tensor Gauss rule with `n` points per direction (n = 1..=4) on the
    /// square `[-1, 1]²`.
    pub fn quad_gauss(n: usize) -> Result<Self, FemError> {
        let (x, w) = gauss_legendre(n).ok_or(FemError::UnsupportedRule { what: "quad", n })?;
        let mut rule = Self::with_capacity(n * n);
        for j in 0..n {
            for i in 0..n {
                rule.push([x[i], x[j], 0.0], w[i] * w[j]);
            }
        }
        Ok(rule)
    }

    /// The default for quad4: exact for the pressure load and its tangent,
    /// whose integrands are bi-quadratic at most.
    pub fn quad_2x2() -> Self {
        Self::tensor_or_empty(Self::quad_gauss(2))
    }

    pub fn quad_3x3() -> Self {
        Self::tensor_or_empty(Self::quad_gauss(3))
    }

    pub fn quad_4x4() -> Self {
        Self::tensor_or_empty(Self::quad_gauss(4))
    }

    /// Centroid rule, exact to degree 1: all a linear tetrahedron needs.
    pub fn tet_1() -> Self {
        Self {
            points: vec![[0.25; 3]],
            weights: vec![1.0 / 6.0],
        }
    }

    /// Symmetric 4-point rule, exact to degree 2 (mass matrices, body forces
    /// with linearly varying loads).
    pub fn tet_4() -> Self {
        let a = (5.0 + 3.0 * 5f64.sqrt()) / 20.0;
        let b = (5.0 - 5f64.sqrt()) / 20.0;
        Self {
            points: vec![[b, b, b], [a, b, b], [b, a, b], [b, b, a]],
            weights: vec![1.0 / 24.0; 4],
        }
    }

    /// Centroid rule, exact to degree 1.
    pub fn tri_1() -> Self {
        Self {
            points: vec![[1.0 / 3.0, 1.0 / 3.0, 0.0]],
            weights: vec![0.5],
        }
    }

    /// Interior 3-point rule, exact to degree 2; the tri3 default, since the
    /// pressure integrand N·(x,1 × x,2) is linear.
    pub fn tri_3() -> Self {
        let a = 1.0 / 6.0;
        let b = 2.0 / 3.0;
        Self {
            points: vec![[a, a, 0.0], [b, a, 0.0], [a, b, 0.0]],
            weights: vec![1.0 / 6.0; 3],
        }
    }

    /// Dunavant's 6-point rule, exact to degree 4.
    pub fn tri_6() -> Self {
        let a = 0.445_948_490_915_964_9;
        let wa = 0.223_381_589_678_011_5 / 2.0;
        let b = 0.091_576_213_509_770_74;
        let wb = 0.109_951_743_655_321_87 / 2.0;
        Self {
            points: vec![
                [a, a, 0.0],
                [1.0 - 2.0 * a, a, 0.0],
                [a, 1.0 - 2.0 * a, 0.0],
                [b, b, 0.0],
                [1.0 - 2.0 * b, b, 0.0],
                [b, 1.0 - 2.0 * b, 0.0],
            ],
            weights: vec![wa, wa, wa, wb, wb, wb],
        }
    }

    /// The rule the solver uses unless told otherwise.
    pub fn default_for_cell(cell: CellType) -> Self {
        match cell {
            CellType::Hex8 => Self::hex_2x2x2(),
            // One point integrates a linear tet exactly; four make the
            // body-force and L2-error integrals of a test more accurate.
            CellType::Tet4 => Self::tet_1(),
        }
    }

    pub fn default_for_facet(facet: FacetType) -> Self {
        match facet {
            FacetType::Quad4 => Self::quad_2x2(),
            FacetType::Tri3 => Self::tri_3(),
        }
    }

    /// Composite rule on a facet: the reference facet cut into `cells` ×
    /// `cells` equal parts (squares for quad4, triangles for tri3), each
    /// with the 4×4 Gauss or the 6-point rule. For integrands with a kink
    /// inside the facet (a pressure profile's edge), where one rule of any
    /// degree converges slowly.
    pub fn composite_for_facet(facet: FacetType, cells: usize) -> Self {
        let m = cells.max(1);
        let mut rule = Self::with_capacity(16 * m * m);
        match facet {
            FacetType::Quad4 => {
                let base = Self::quad_4x4();
                let h = 2.0 / m as f64;
                for j in 0..m {
                    for i in 0..m {
                        let c = [-1.0 + h * (i as f64 + 0.5), -1.0 + h * (j as f64 + 0.5)];
                        for (p, w) in base.points.iter().zip(&base.weights) {
                            rule.push(
                                [c[0] + 0.5 * h * p[0], c[1] + 0.5 * h * p[1], 0.0],
                                w * 0.25 * h * h,
                            );
                        }
                    }
                }
            }
            FacetType::Tri3 => {
                let base = Self::tri_6();
                let h = 1.0 / m as f64;
                let mut cell = |o: [f64; 2], e1: [f64; 2], e2: [f64; 2]| {
                    for (p, w) in base.points.iter().zip(&base.weights) {
                        let x = [
                            o[0] + h * (e1[0] * p[0] + e2[0] * p[1]),
                            o[1] + h * (e1[1] * p[0] + e2[1] * p[1]),
                        ];
                        rule.push([x[0], x[1], 0.0], w * h * h);
                    }
                };
                for j in 0..m {
                    for i in 0..m - j {
                        let o = [h * i as f64, h * j as f64];
                        cell(o, [1.0, 0.0], [0.0, 1.0]);
                        if i + j + 1 < m {
                            // The downward triangle between two upward ones.
                            cell([o[0] + h, o[1] + h], [-1.0, 0.0], [0.0, -1.0]);
                        }
                    }
                }
            }
        }
        rule
    }

    /// Nodal (Lobatto / vertex) rule on a facet: the points are the facet's
    /// nodes, exact for linear integrands. Contact uses it to put one
    /// constraint at each slave node instead of several per facet.
    pub fn nodal_for_facet(facet: FacetType) -> Self {
        match facet {
            FacetType::Quad4 => Self {
                points: vec![
                    [-1.0, -1.0, 0.0],
                    [1.0, -1.0, 0.0],
                    [1.0, 1.0, 0.0],
                    [-1.0, 1.0, 0.0],
                ],
                weights: vec![1.0; 4],
            },
            FacetType::Tri3 => Self {
                points: vec![[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]],
                weights: vec![1.0 / 6.0; 3],
            },
        }
    }

    fn with_capacity(n: usize) -> Self {
        Self {
            points: Vec::with_capacity(n),
            weights: Vec::with_capacity(n),
        }
    }

    fn push(&mut self, point: [f64; 3], weight: f64) {
        self.points.push(point);
        self.weights.push(weight);
    }

    /// The fixed-order constructors cannot fail; this keeps them infallible
    /// without an `unwrap` in library code.
    fn tensor_or_empty(rule: Result<Self, FemError>) -> Self {
        rule.unwrap_or_else(|_| Self::with_capacity(0))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn factorial(n: u32) -> f64 {
        (1..=n).map(f64::from).product()
    }

    /// ∫_{-1}^{1} x^p dx.
    fn line_moment(p: u32) -> f64 {
        if p % 2 == 1 {
            0.0
        } else {
            2.0 / f64::from(p + 1)
        }
    }

    fn apply(rule: &QuadRule, f: impl Fn([f64; 3]) -> f64) -> f64 {
        rule.points
            .iter()
            .zip(&rule.weights)
            .map(|(p, w)| w * f(*p))
            .sum()
    }

    fn monomial(x: [f64; 3], p: [u32; 3]) -> f64 {
        x[0].powi(p[0] as i32) * x[1].powi(p[1] as i32) * x[2].powi(p[2] as i32)
    }

    /// Largest error over all monomials of per-direction degree ≤ `deg`
    /// (tensor rules) on the cube/square; `dims` = 2 or 3.
    fn tensor_error(rule: &QuadRule, dims: usize, deg: u32) -> f64 {
        let mut worst = 0.0f64;
        let zdeg = if dims == 3 { deg } else { 0 };
        for a in 0..=deg {
            for b in 0..=deg {
                for c in 0..=zdeg {
                    let p = [a, b, c];
                    let exact = line_moment(a)
                        * line_moment(b)
                        * if dims == 3 { line_moment(c) } else { 1.0 };
                    worst = worst.max((apply(rule, |x| monomial(x, p)) - exact).abs());
                }
            }
        }
        worst
    }

    /// Largest error over monomials of total degree ≤ `deg` on the unit
    /// simplex, exact value a!b!c!/(a+b+c+d)! with d the dimension.
    fn simplex_error(rule: &QuadRule, dims: u32, deg: u32) -> f64 {
        let mut worst = 0.0f64;
        for a in 0..=deg {
            for b in 0..=(deg - a) {
                let cmax = if dims == 3 { deg - a - b } else { 0 };
                for c in 0..=cmax {
                    let p = [a, b, c];
                    let exact =
                        factorial(a) * factorial(b) * factorial(c) / factorial(a + b + c + dims);
                    worst = worst.max((apply(rule, |x| monomial(x, p)) - exact).abs());
                }
            }
        }
        worst
    }

    #[test]
    fn tensor_rules_exact_to_degree_2n_minus_1() {
        for n in 1..=4u32 {
            let hex = QuadRule::hex_gauss(n as usize).unwrap();
            let quad = QuadRule::quad_gauss(n as usize).unwrap();
            assert_eq!(hex.len(), (n * n * n) as usize);
            assert!(tensor_error(&hex, 3, 2 * n - 1) < 1e-13, "hex n={n}");
            assert!(tensor_error(&quad, 2, 2 * n - 1) < 1e-13, "quad n={n}");
            // One degree higher must fail, or the check above proves nothing.
            assert!(tensor_error(&hex, 3, 2 * n) > 1e-3, "hex n={n} too exact");
            assert!(tensor_error(&quad, 2, 2 * n) > 1e-3, "quad n={n} too exact");
        }
        assert!(QuadRule::hex_gauss(5).is_err());
        assert!(QuadRule::quad_gauss(0).is_err());
    }

    #[test]
    fn composite_facet_rules_keep_their_cells_degree_and_integrate_a_kink() {
        for m in 1..=3 {
            let quad = QuadRule::composite_for_facet(FacetType::Quad4, m);
            let tri = QuadRule::composite_for_facet(FacetType::Tri3, m);
            assert_eq!((quad.len(), tri.len()), (16 * m * m, 6 * m * m));
            quad.check().unwrap();
            tri.check().unwrap();
            assert!(tensor_error(&quad, 2, 7) < 1e-13, "quad m={m}");
            assert!(simplex_error(&tri, 2, 4) < 1e-13, "tri m={m}");
        }
        // |x| has its kink on a cell boundary of the 2 × 2 split: exact there,
        // not with one cell.
        let kink = |r: &QuadRule| (apply(r, |x| x[0].abs()) - 2.0).abs();
        assert!(kink(&QuadRule::composite_for_facet(FacetType::Quad4, 2)) < 1e-13);
        assert!(kink(&QuadRule::composite_for_facet(FacetType::Quad4, 1)) > 1e-3);
    }

    #[test]
    fn simplex_rules_exact_to_their_degree() {
        let cases: [(QuadRule, u32, u32); 5] = [
            (QuadRule::tet_1(), 3, 1),
            (QuadRule::tet_4(), 3, 2),
            (QuadRule::tri_1(), 2, 1),
            (QuadRule::tri_3(), 2, 2),
            (QuadRule::tri_6(), 2, 4),
        ];
        for (rule, dims, deg) in cases {
            rule.check().unwrap();
            let err = simplex_error(&rule, dims, deg);
            assert!(err < 1e-14, "dims {dims} degree {deg}: {err:e}");
            let over = simplex_error(&rule, dims, deg + 1);
            assert!(over > 1e-6, "dims {dims} degree {deg}: exact beyond degree");
        }
    }

    #[test]
    fn named_constructors_match_orders() {
        assert_eq!(QuadRule::hex_2x2x2().len(), 8);
        assert_eq!(QuadRule::hex_3x3x3().len(), 27);
        assert_eq!(QuadRule::quad_2x2().len(), 4);
        assert_eq!(QuadRule::quad_3x3().len(), 9);
        assert_eq!(QuadRule::quad_4x4().len(), 16);
        assert_eq!(QuadRule::default_for_cell(CellType::Hex8).len(), 8);
        assert_eq!(QuadRule::default_for_facet(FacetType::Tri3).len(), 3);
    }

    #[test]
    fn malformed_rules_rejected() {
        let bad = QuadRule {
            points: vec![[0.0; 3]; 2],
            weights: vec![1.0],
        };
        assert!(matches!(bad.check(), Err(FemError::MalformedRule { .. })));
        let nan = QuadRule {
            points: vec![[f64::NAN, 0.0, 0.0]],
            weights: vec![1.0],
        };
        assert!(matches!(nan.check(), Err(FemError::NonFinite { .. })));
        assert!(QuadRule::tri_1().check().is_ok());
    }
}

//! Quadrature rules on the reference cells and facets.
//!
//! Points always carry three coordinates so one type serves cells and
//! facets; facet rules leave the third coordinate at zero. Weights sum to the
//! reference measure: 8 (cube), 1/6 (tetrahedron), 1 (wedge), 4/3
//! (pyramid), 4 (square), 1/2 (triangle).
//!
//! Per cell type the solver integrates with [`QuadRule::default_for_cell`]
//! (the "full" rule of common practice), offers [`QuadRule::reduced_for_cell`]
//! where reduced integration is the practice, and builds the consistent mass
//! with [`QuadRule::mass_for_cell`] where the default rule is too weak for
//! `N_a N_b`.

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

/// How a body's cells integrate their stiffness: the full rule of the cell
/// type, or the reduced one where that is the practice (hex20's 2×2×2, as
/// Abaqus' C3D20R). The mass always takes a rule exact for `N_a N_b`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Integration {
    #[default]
    Full,
    Reduced,
}

impl Integration {
    pub fn name(self) -> &'static str {
        match self {
            Integration::Full => "full",
            Integration::Reduced => "reduced",
        }
    }
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

    /// Walkington's 14-point rule, exact to degree 5 with positive weights
    /// (J. Walkington, "Quadrature on simplices of arbitrary dimension",
    /// CMU 2000; also Keast's degree-5 family): the tet10 mass `N_a N_b` is
    /// of degree 4.
    pub fn tet_14() -> Self {
        let mut rule = Self::with_capacity(14);
        for (a, w) in [
            (0.092_735_250_310_891_2, 0.012_248_840_519_393_66),
            (0.310_885_919_263_300_6, 0.018_781_320_953_002_64),
        ] {
            let c = 1.0 - 3.0 * a;
            for p in [[a, a, a], [c, a, a], [a, c, a], [a, a, c]] {
                rule.push(p, w);
            }
        }
        let b = 0.454_496_295_874_350_4;
        let c = 0.5 - b;
        let w = 0.007_091_003_462_846_911;
        // Two barycentric coordinates b and two c, in every arrangement; the
        // point is (L1, L2, L3).
        for l in [
            [b, b, c, c],
            [b, c, b, c],
            [b, c, c, b],
            [c, b, b, c],
            [c, b, c, b],
            [c, c, b, b],
        ] {
            rule.push([l[1], l[2], l[3]], w);
        }
        rule
    }

    /// Triangle rule × `n`-point Gauss in ζ on the reference wedge.
    pub fn wedge(triangle: &QuadRule, n: usize) -> Result<Self, FemError> {
        let (z, wz) = gauss_legendre(n).ok_or(FemError::UnsupportedRule { what: "wedge", n })?;
        let mut rule = Self::with_capacity(triangle.len() * n);
        for (zk, wk) in z.iter().zip(&wz) {
            for (p, w) in triangle.points.iter().zip(&triangle.weights) {
                rule.push([p[0], p[1], *zk], w * wk);
            }
        }
        Ok(rule)
    }

    /// Collapsed (Duffy) Gauss rule on the reference pyramid: the cube
    /// `(u, v, w) ∈ [-1, 1]² × [0, 1]` mapped by `ξ = u(1 − w)`,
    /// `η = v(1 − w)`, `ζ = w`, Jacobian `(1 − w)²` folded into the weights
    /// (Karniadakis & Sherwin, *Spectral/hp Element Methods*, 2nd ed.,
    /// §4.1.1). In these coordinates Bedrosian's pyramid functions are
    /// polynomials of degree 1 in u and v and their reference gradients are
    /// independent of w, so `n_uv = 2`, `n_w = 2` integrates the stiffness
    /// of an affine pyramid exactly and `n_w = 3` its mass.
    pub fn pyramid_collapsed(n_uv: usize, n_w: usize) -> Result<Self, FemError> {
        let bad = |n| FemError::UnsupportedRule { what: "pyramid", n };
        let (u, wu) = gauss_legendre(n_uv).ok_or(bad(n_uv))?;
        let (t, wt) = gauss_legendre(n_w).ok_or(bad(n_w))?;
        let mut rule = Self::with_capacity(n_uv * n_uv * n_w);
        for (tk, wk) in t.iter().zip(&wt) {
            let w = 0.5 * (1.0 + tk);
            let shrink = 1.0 - w;
            for (vj, wj) in u.iter().zip(&wu) {
                for (ui, wi) in u.iter().zip(&wu) {
                    let weight = wi * wj * 0.5 * wk * shrink * shrink;
                    rule.push([ui * shrink, vj * shrink, w], weight);
                }
            }
        }
        Ok(rule)
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

    /// The rule the solver uses unless told otherwise: the full
    /// integration of common practice (Abaqus' C3D8, C3D4, C3D10 (4
    /// points), C3D20 (27), C3D6 (triangle 3 × 2), C3D15 (triangle 3 × 3)).
    pub fn default_for_cell(cell: CellType) -> Self {
        let rule = match cell {
            CellType::Hex8 => Ok(Self::hex_2x2x2()),
            // One point integrates a linear tet exactly; four make the
            // body-force and L2-error integrals of a test more accurate.
            CellType::Tet4 => Ok(Self::tet_1()),
            // Degree 2: exact for the stiffness of a straight-sided tet10.
            CellType::Tet10 => Ok(Self::tet_4()),
            CellType::Hex20 | CellType::Hex27 => Ok(Self::hex_3x3x3()),
            CellType::Wedge6 => Self::wedge(&Self::tri_3(), 2),
            CellType::Wedge15 => Self::wedge(&Self::tri_3(), 3),
            CellType::Pyramid5 => Self::pyramid_collapsed(2, 2),
        };
        Self::tensor_or_empty(rule)
    }

    /// The stiffness rule of `cell` under `integration`; `None` when the
    /// type has no reduced rule.
    pub fn for_cell(cell: CellType, integration: Integration) -> Option<Self> {
        match integration {
            Integration::Full => Some(Self::default_for_cell(cell)),
            Integration::Reduced => Self::reduced_for_cell(cell),
        }
    }

    /// Reduced integration where it is the practice: hex20's 2×2×2 (Abaqus
    /// C3D20R; its one spurious mode per element does not propagate
    /// through a mesh). `None` for the other types.
    pub fn reduced_for_cell(cell: CellType) -> Option<Self> {
        match cell {
            CellType::Hex20 => Some(Self::hex_2x2x2()),
            _ => None,
        }
    }

    /// The rule for the consistent mass where [`Self::default_for_cell`] does
    /// not integrate `N_a N_b` exactly on an affine cell: tet10 (degree 4:
    /// the 14-point rule), wedge15 (triangle degree 4 × ζ degree 4:
    /// 6-point × 3), pyramid5 (w-degree 4: 2×2×3). `None` where the default
    /// rule is exact (hex8, hex20, hex27, wedge6) or a closed form is used
    /// (tet4).
    pub fn mass_for_cell(cell: CellType) -> Option<Self> {
        match cell {
            CellType::Tet10 => Some(Self::tet_14()),
            CellType::Wedge15 => Self::wedge(&Self::tri_6(), 3).ok(),
            CellType::Pyramid5 => Self::pyramid_collapsed(2, 3).ok(),
            _ => None,
        }
    }

    /// The facet rule of loads: exact for the follower pressure and its
    /// tangent (`N_a (x,1 × x,2)` is bi-quadratic on quad4, linear on tri3,
    /// of degree 4 on tri6 and of degree 5 per direction on quad8/quad9).
    pub fn default_for_facet(facet: FacetType) -> Self {
        match facet {
            FacetType::Quad4 => Self::quad_2x2(),
            FacetType::Tri3 => Self::tri_3(),
            FacetType::Tri6 => Self::tri_6(),
            FacetType::Quad8 | FacetType::Quad9 => Self::quad_3x3(),
        }
    }

    /// Composite rule on a facet: the reference facet cut into `cells` ×
    /// `cells` equal parts (squares for quadrilaterals, triangles for
    /// triangles), each with the 4×4 Gauss or the 6-point rule. For
    /// integrands with a kink
    /// inside the facet (a pressure profile's edge), where one rule of any
    /// degree converges slowly.
    pub fn composite_for_facet(facet: FacetType, cells: usize) -> Self {
        let m = cells.max(1);
        let mut rule = Self::with_capacity(16 * m * m);
        match facet.linear() {
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
            _ => {
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
        }
        rule
    }

    /// Nodal (Lobatto / vertex) rule on a facet: the points are the facet's
    /// corners, exact for linear integrands. Contact uses it to put one
    /// constraint at each slave node instead of several per facet.
    pub fn nodal_for_facet(facet: FacetType) -> Self {
        match facet.linear() {
            FacetType::Quad4 => Self {
                points: vec![
                    [-1.0, -1.0, 0.0],
                    [1.0, -1.0, 0.0],
                    [1.0, 1.0, 0.0],
                    [-1.0, 1.0, 0.0],
                ],
                weights: vec![1.0; 4],
            },
            _ => Self {
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
    fn tet_14_is_exact_to_degree_5() {
        let rule = QuadRule::tet_14();
        rule.check().unwrap();
        assert_eq!(rule.len(), 14);
        assert!(rule.weights.iter().all(|&w| w > 0.0));
        let err = simplex_error(&rule, 3, 5);
        assert!(err < 1e-15, "{err:e}");
        assert!(simplex_error(&rule, 3, 6) > 1e-8);
    }

    /// ∫ ξ^a η^b ζ^c over the wedge: a! b! / (a + b + 2)! · ∫ ζ^c.
    fn wedge_error(rule: &QuadRule, tri_deg: u32, z_deg: u32) -> f64 {
        let mut worst = 0.0f64;
        for a in 0..=tri_deg {
            for b in 0..=(tri_deg - a) {
                for c in 0..=z_deg {
                    let exact = factorial(a) * factorial(b) / factorial(a + b + 2) * line_moment(c);
                    let got = apply(rule, |x| monomial(x, [a, b, c]));
                    worst = worst.max((got - exact).abs());
                }
            }
        }
        worst
    }

    #[test]
    fn wedge_rules_are_triangle_times_gauss() {
        for (tri, deg) in [(QuadRule::tri_3(), 2), (QuadRule::tri_6(), 4)] {
            for n in 1..=4u32 {
                let rule = QuadRule::wedge(&tri, n as usize).unwrap();
                assert_eq!(rule.len(), tri.len() * n as usize);
                assert!(wedge_error(&rule, deg, 2 * n - 1) < 1e-15);
                assert!(wedge_error(&rule, deg, 2 * n) > 1e-6);
                assert!(wedge_error(&rule, deg + 1, 2 * n - 1) > 1e-6);
            }
        }
        assert!(QuadRule::wedge(&QuadRule::tri_3(), 5).is_err());
    }

    /// ∫ ξ^a η^b ζ^c over the pyramid: the square at height ζ has half
    /// side 1 − ζ, so the integral is m(a) m(b) B(c + 1, a + b + 3).
    fn pyramid_moment(p: [u32; 3]) -> f64 {
        let [a, b, c] = p;
        line_moment(a) * line_moment(b) * factorial(c) * factorial(a + b + 2)
            / factorial(a + b + c + 3)
    }

    #[test]
    fn collapsed_pyramid_rules_are_exact_to_their_degree() {
        for n_uv in 1..=3u32 {
            for n_w in 1..=4u32 {
                let rule = QuadRule::pyramid_collapsed(n_uv as usize, n_w as usize).unwrap();
                rule.check().unwrap();
                for a in 0..=2 * n_uv - 1 {
                    for b in 0..=2 * n_uv - 1 {
                        for c in 0..=4 {
                            let p = [a, b, c];
                            let err = (apply(&rule, |x| monomial(x, p)) - pyramid_moment(p)).abs();
                            // Exact when the w-polynomial ζ^c (1 − ζ)^(a+b+2)
                            // has degree ≤ 2 n_w − 1.
                            if a + b + c + 2 < 2 * n_w {
                                assert!(err < 1e-15, "{n_uv}x{n_w} {p:?}: {err:e}");
                            }
                        }
                    }
                }
            }
        }
        let volume: f64 = QuadRule::pyramid_collapsed(2, 2)
            .unwrap()
            .weights
            .iter()
            .sum();
        assert!((volume - 4.0 / 3.0).abs() < 1e-15);
        assert!(QuadRule::pyramid_collapsed(0, 2).is_err());
    }

    #[test]
    fn every_cell_has_a_default_rule_of_its_reference_measure() {
        for cell in CellType::ALL {
            let rule = QuadRule::default_for_cell(cell);
            rule.check().unwrap();
            let measure: f64 = rule.weights.iter().sum();
            let exact = match cell.linear() {
                CellType::Hex8 => 8.0,
                CellType::Tet4 => 1.0 / 6.0,
                CellType::Wedge6 => 1.0,
                _ => 4.0 / 3.0,
            };
            assert!((measure - exact).abs() < 1e-14, "{}", cell.name());
            if let Some(mass) = QuadRule::mass_for_cell(cell) {
                let m: f64 = mass.weights.iter().sum();
                assert!((m - exact).abs() < 1e-14, "{}", cell.name());
                assert!(mass.len() >= cell.nodes(), "{}", cell.name());
            }
        }
        assert_eq!(QuadRule::default_for_cell(CellType::Hex20).len(), 27);
        assert_eq!(
            QuadRule::reduced_for_cell(CellType::Hex20).map(|r| r.len()),
            Some(8)
        );
        assert!(QuadRule::reduced_for_cell(CellType::Tet10).is_none());
        assert_eq!(QuadRule::default_for_cell(CellType::Tet10).len(), 4);
        assert_eq!(QuadRule::default_for_cell(CellType::Wedge15).len(), 9);
        for facet in FacetType::ALL {
            let m: f64 = QuadRule::default_for_facet(facet).weights.iter().sum();
            let exact = if facet.linear() == FacetType::Tri3 {
                0.5
            } else {
                4.0
            };
            assert!((m - exact).abs() < 1e-14, "{}", facet.name());
        }
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

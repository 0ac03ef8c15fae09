//! Dual shape functions on a slave facet and the mortar integrals of one
//! slave–master segment.
//!
//! Dual (biorthogonal) shape functions `Φ_j = Σ_k A_jk N_k` satisfy
//! `∫ Φ_j N_k dA = δ_jk ∫ N_k dA` over the slave facet, which gives
//! `A = D M⁻¹` with `D = diag(∫ N_j dA)` and `M_jk = ∫ N_j N_k dA`, computed
//! once per facet from its REFERENCE geometry (so `A` is constant, as the
//! integrals are over the reference surface). Since `M·1 = diag(D)`, `Σ_j Φ_j = 1`:
//! a uniform multiplier field is represented exactly.
//!
//! On a segment (the overlap of the slave facet with one master facet in the
//! slave's auxiliary plane) the kernel integrates
//! - the weighted gap `g̃_j = ∫ Φ_j g dA` with `g = ν·(x² − x¹)`, `ν` the
//!   auxiliary plane's normal (outward of the slave), `> 0` apart;
//! - the mortar matrices `D_jk = ∫ Φ_j N¹_k dA` and `M_jl = ∫ Φ_j N²_l dA`,
//!   with which `g̃_j = Σ_l M_jl ν·x²_l − Σ_k D_jk ν·x¹_k` and the contact
//!   force of node `j`'s multiplier `p_j` is `+p_j D_jk ν` on slave node `k`
//!   and `−p_j M_jl ν` on master node `l` (residual sign, see `system`).
//!
//! Over a slave facet its segments cover whole, `Σ D_jk = δ_jk ∫ N_j dA`
//! (biorthogonality), a constant: such a facet takes that diagonal instead
//! of the segments' sum (`system::covered_facets`).
use super::geometry::{overlap, shape_gradients, NEAR_AFFINE};
use super::MAX_FACET_NODES;
use super::{facet_shape, FacetShape};
use crate::contact::autodiff::{self, Scalar, Vec3};
use crate::fem::{FacetType, QuadRule};

/// A quadrature rule as (point, weight) pairs.
pub type Rule = Vec<([f64; 2], f64)>;

/// The rules the mortar kernels integrate with: on the whole slave facet (for
/// `D` and `M` of the dual basis) and on the triangles of a segment.
#[derive(Debug, Clone)]
pub struct MortarRules {
    pub quad_facet: Rule,
    pub tri_facet: Rule,
    pub triangle: Rule,
    /// On the triangles of a tri3-on-tri3 segment, where both facets map
    /// affinely: every integrand there (`Φ_j g`, `Φ_j N¹_k`, `Φ_j N²_l`
    /// times a constant area ratio) is a polynomial of degree 2, exact
    /// with three points at any positions, so its derivatives are too.
    pub affine_triangle: Rule,
    /// On the triangles of a segment whose facets are all parallelograms
    /// or triangles (both projected facets and the slave's reference
    /// facet): the parametric maps are affine in the plane, the integrands
    /// polynomials of degree 4 and their first derivatives in the nodes
    /// (a perturbation bends a map, and `∂ζ/∂x` is quadratic) of degree 5,
    /// so a degree-5 rule gives the degree-6 rule's values and tangent.
    /// Also where they are nearly so ([`NEAR_AFFINE`]).
    pub parallelogram_triangle: Rule,
}

fn pairs(rule: &QuadRule) -> Rule {
    rule.points
        .iter()
        .zip(&rule.weights)
        .map(|(p, w)| ([p[0], p[1]], *w))
        .collect()
}

/// Dunavant's 12-point rule on the reference triangle, exact to degree 6
/// (positive weights, points inside); weights sum to ½.
fn dunavant_12() -> Rule {
    const A: [(f64, f64); 2] = [
        (0.063_089_014_491_503_48, 0.050_844_906_370_208_49),
        (0.249_286_745_170_904_9, 0.116_786_275_726_388_72),
    ];
    const B: f64 = 0.053_145_049_844_813_39;
    const C: f64 = 0.310_352_451_033_788_3;
    const W: f64 = 0.082_851_075_618_368_08;
    let mut rule = Rule::new();
    for (a, w) in A {
        for p in [[a, a], [a, 1.0 - 2.0 * a], [1.0 - 2.0 * a, a]] {
            rule.push((p, 0.5 * w));
        }
    }
    let d = 1.0 - B - C;
    for p in [[B, C], [C, B], [B, d], [d, B], [C, d], [d, C]] {
        rule.push((p, 0.5 * W));
    }
    rule
}

/// Radon's 7-point rule on the reference triangle, exact to degree 5
/// (positive weights, points inside); weights sum to ½.
fn radon_7() -> Rule {
    let r = 15f64.sqrt();
    let mut rule = vec![([1.0 / 3.0, 1.0 / 3.0], 9.0 / 80.0)];
    for (a, w) in [(6.0 - r) / 21.0, (6.0 + r) / 21.0]
        .into_iter()
        .zip([(155.0 - r) / 2400.0, (155.0 + r) / 2400.0])
    {
        for p in [[a, a], [a, 1.0 - 2.0 * a], [1.0 - 2.0 * a, a]] {
            rule.push((p, w));
        }
    }
    rule
}

impl Default for MortarRules {
    /// 3×3 Gauss on quads (exact for `N_j N_k J`, biquadratic × bilinear),
    /// the degree-4 six-point rule on tri facets. On segment triangles the
    /// integrands `N(ζ(p))` are not polynomial where a quad facet is not a
    /// parallelogram (the inverse bilinear map): a degree-6 rule keeps
    /// their error below the patch test's 1e-6 on a 30 %-distorted mesh,
    /// where the six-point rule left 7e-7. Dunavant's 12 points do it with
    /// three quarters of the collapsed 4×4 Gauss rule's 16.
    fn default() -> Self {
        MortarRules {
            quad_facet: pairs(&QuadRule::quad_3x3()),
            tri_facet: pairs(&QuadRule::tri_6()),
            triangle: dunavant_12(),
            affine_triangle: pairs(&QuadRule::tri_3()),
            parallelogram_triangle: radon_7(),
        }
    }
}

impl MortarRules {
    pub fn facet(&self, facet: FacetType) -> &Rule {
        match facet.linear() {
            FacetType::Tri3 => &self.tri_facet,
            _ => &self.quad_facet,
        }
    }

    /// The rule on a segment's triangles: where a quad4 facet is not a
    /// parallelogram, not even nearly ([`NEAR_AFFINE`]; `parallelograms`
    /// false), its inverse map makes the integrands rational, so they get
    /// the degree-6 rule.
    pub fn segment(&self, slave: FacetType, master: FacetType, parallelograms: bool) -> &Rule {
        match (slave, master) {
            (FacetType::Tri3, FacetType::Tri3) => &self.affine_triangle,
            _ if parallelograms => &self.parallelogram_triangle,
            _ => &self.triangle,
        }
    }
}

/// Dual-basis coefficients `A` (row `j` gives `Φ_j`) of a slave facet at
/// positions `x` (the pair passes the reference ones). `None` for a
/// degenerate facet.
pub fn dual_coefficients<T: Scalar>(
    facet: FacetType,
    x: &[Vec3<T>],
    rules: &MortarRules,
) -> Option<[[T; MAX_FACET_NODES]; MAX_FACET_NODES]> {
    let n = facet.nodes();
    let (d, m) = facet_moments(facet, x, rules);
    let inv = invert(m, n)?;
    let mut a = [[T::from_f64(0.0); MAX_FACET_NODES]; MAX_FACET_NODES];
    for j in 0..n {
        for k in 0..n {
            a[j][k] = d[j] * inv[j][k];
        }
    }
    Some(a)
}

/// `∫ N_j dA` of a facet at positions `x` with the rule the dual basis is
/// built with: by biorthogonality `∫ Φ_j N_k dA = δ_jk` times this, the
/// facet's `D` when segments cover it whole (see `system::covered_facets`).
pub fn nodal_areas(
    facet: FacetType,
    x: &[[f64; 3]],
    rules: &MortarRules,
) -> [f64; MAX_FACET_NODES] {
    facet_moments::<f64>(facet, x, rules).0
}

/// `(∫ N_j dA, ∫ N_j N_k dA)` over a facet at positions `x`.
#[allow(clippy::type_complexity)]
fn facet_moments<T: Scalar>(
    facet: FacetType,
    x: &[Vec3<T>],
    rules: &MortarRules,
) -> (
    [T; MAX_FACET_NODES],
    [[T; MAX_FACET_NODES]; MAX_FACET_NODES],
) {
    let n = facet.nodes();
    let zero = T::from_f64(0.0);
    let mut m = [[zero; MAX_FACET_NODES]; MAX_FACET_NODES];
    let mut d = [zero; MAX_FACET_NODES];
    for (zeta, w) in rules.facet(facet) {
        let s = facet_shape(facet, *zeta);
        let (mut t1, mut t2) = (
            autodiff::constant3::<T>([0.0; 3]),
            autodiff::constant3::<T>([0.0; 3]),
        );
        for (a, xa) in x.iter().enumerate().take(n) {
            t1 = autodiff::axpy(&t1, s.dn[a][0], xa);
            t2 = autodiff::axpy(&t2, s.dn[a][1], xa);
        }
        let jw = autodiff::norm(&autodiff::cross(&t1, &t2)) * *w;
        for ((dj, mj), nj) in d.iter_mut().zip(m.iter_mut()).zip(&s.n).take(n) {
            *dj = *dj + jw * *nj;
            for (mjk, nk) in mj.iter_mut().zip(&s.n).take(n) {
                *mjk = *mjk + jw * (nj * nk);
            }
        }
    }
    (d, m)
}

/// Gauss–Jordan inverse of the leading `n × n` block with partial pivoting
/// (pivots chosen on the f64 values); `None` if singular.
fn invert<T: Scalar>(
    mut m: [[T; MAX_FACET_NODES]; MAX_FACET_NODES],
    n: usize,
) -> Option<[[T; MAX_FACET_NODES]; MAX_FACET_NODES]> {
    let zero = T::from_f64(0.0);
    let mut inv = [[zero; MAX_FACET_NODES]; MAX_FACET_NODES];
    for (i, row) in inv.iter_mut().enumerate().take(n) {
        row[i] = T::from_f64(1.0);
    }
    let size = (0..n).map(|i| m[i][i].re().abs()).fold(0.0, f64::max);
    for col in 0..n {
        let pivot =
            (col..n).max_by(|&a, &b| m[a][col].re().abs().total_cmp(&m[b][col].re().abs()))?;
        let magnitude = m[pivot][col].re().abs();
        if magnitude.is_nan() || magnitude <= 1e-13 * size {
            return None;
        }
        m.swap(col, pivot);
        inv.swap(col, pivot);
        let p = m[col][col].recip();
        for k in 0..n {
            m[col][k] = m[col][k] * p;
            inv[col][k] = inv[col][k] * p;
        }
        for row in 0..n {
            if row == col {
                continue;
            }
            let f = m[row][col];
            for k in 0..n {
                m[row][k] = m[row][k] - f * m[col][k];
                inv[row][k] = inv[row][k] - f * inv[col][k];
            }
        }
    }
    Some(inv)
}

/// `Φ_j(ζ)` from the coefficients and the standard shape values.
pub fn dual_values<T: Scalar>(
    a: &[[T; MAX_FACET_NODES]; MAX_FACET_NODES],
    n: &[T; MAX_FACET_NODES],
    nodes: usize,
) -> [T; MAX_FACET_NODES] {
    let mut phi = [T::from_f64(0.0); MAX_FACET_NODES];
    for j in 0..nodes {
        for k in 0..nodes {
            phi[j] = phi[j] + a[j][k] * n[k];
        }
    }
    phi
}

/// The mortar integrals of one segment (rows `j`: slave facet nodes).
#[derive(Debug, Clone, Copy)]
pub struct SegmentTerms<T> {
    /// `∫ Φ_j g dA`.
    pub weighted_gap: [T; MAX_FACET_NODES],
    /// `D_jk = ∫ Φ_j N¹_k dA`.
    pub d: [[T; MAX_FACET_NODES]; MAX_FACET_NODES],
    /// `M_jl = ∫ Φ_j N²_l dA`.
    pub m: [[T; MAX_FACET_NODES]; MAX_FACET_NODES],
    /// The auxiliary plane's unit normal (outward of the slave).
    pub normal: Vec3<T>,
    /// The segment's reference area (on the slave).
    pub area: T,
}

/// Shape values at a point in `T` through [`Scalar::linearised`] (one pass
/// over the gradient each, where the bilinear product in `T` took five),
/// and the f64 shape there.
fn linearised_shape<T: Scalar>(
    facet: FacetType,
    zeta: &[T; 2],
) -> (FacetShape, [T; MAX_FACET_NODES]) {
    let s = facet_shape(facet, [zeta[0].re(), zeta[1].re()]);
    let mut n = [T::from_f64(0.0); MAX_FACET_NODES];
    for (na, (v, g)) in n.iter_mut().zip(s.n.iter().zip(&s.dn)).take(s.nodes) {
        *na = T::linearised(*v, *g, zeta);
    }
    (s, n)
}

/// `Φ_j = Σ_k A_jk N_k` at a point with the f64 shape `s` there, linearised
/// (the sum in f64, one pass over the gradient per `j`).
fn linearised_dual_basis<T: Scalar>(
    a: &[[f64; MAX_FACET_NODES]; MAX_FACET_NODES],
    s: &FacetShape,
    zeta: &[T; 2],
) -> [T; MAX_FACET_NODES] {
    let mut phi = [T::from_f64(0.0); MAX_FACET_NODES];
    for (p, row) in phi.iter_mut().zip(a).take(s.nodes) {
        let (mut v, mut g) = (0.0, [0.0; 2]);
        for (ajk, (nk, dk)) in row.iter().zip(s.n.iter().zip(&s.dn)).take(s.nodes) {
            v += ajk * nk;
            g = [g[0] + ajk * dk[0], g[1] + ajk * dk[1]];
        }
        *p = T::linearised(v, g, zeta);
    }
    phi
}

/// `Σ_a N_a(ζ) h_a` in `T` for nodal values `h`: their derivatives times
/// the f64 shape values, plus the f64 slope along the point's `ζ`.
fn interpolate<T: Scalar>(s: &FacetShape, h: &[T], zeta: &[T; 2]) -> T {
    let mut t = [0.0; 2];
    for (d, ha) in s.dn.iter().zip(h).take(s.nodes) {
        t = [t[0] + d[0] * ha.re(), t[1] + d[1] * ha.re()];
    }
    let mut v = T::linearised(0.0, t, zeta);
    for (na, ha) in s.n.iter().zip(h).take(s.nodes) {
        v.add_scaled(ha, *na);
    }
    v
}

/// The nodes' heights `ν · x_a` over the auxiliary plane.
fn heights<T: Scalar>(normal: &Vec3<T>, x: &[Vec3<T>]) -> [T; MAX_FACET_NODES] {
    let mut h = [T::from_f64(0.0); MAX_FACET_NODES];
    for (ha, xa) in h.iter_mut().zip(x) {
        *ha = autodiff::dot(normal, xa);
    }
    h
}

/// `|∂X/∂ζ₁ × ∂X/∂ζ₂|` of the reference slave facet at a point in `T`.
/// The facet is fixed, so the value depends on the segment variables only
/// through `ζ`: it is computed with the two derivatives along `ζ` and
/// linearised, instead of carrying every segment variable through the
/// cross product (a tenth of a frictional mortar run).
fn reference_jacobian<T: Scalar>(facet: FacetType, x_ref: &[[f64; 3]], zeta: &[T; 2]) -> T {
    use crate::contact::autodiff::Dual;
    let z: [Dual<2>; 2] = [
        Dual::variable(zeta[0].re(), 0),
        Dual::variable(zeta[1].re(), 1),
    ];
    let dn = shape_gradients(facet, &z);
    let zero = autodiff::constant3::<Dual<2>>([0.0; 3]);
    let (mut t1, mut t2) = (zero, zero);
    for (d, x) in dn.iter().zip(x_ref).take(facet.nodes()) {
        let x = autodiff::constant3::<Dual<2>>(*x);
        t1 = autodiff::add(&t1, &autodiff::scale(&x, d[0]));
        t2 = autodiff::add(&t2, &autodiff::scale(&x, d[1]));
    }
    let j = autodiff::norm(&autodiff::cross(&t1, &t2));
    T::linearised(j.re, j.eps, zeta)
}

/// The distortion ([`NEAR_AFFINE`]) of a facet in 3D (reference
/// positions): `|b| / √|a₁ × a₂|` of `X(ζ) = c + a₁ ζ₁ + a₂ ζ₂ + b ζ₁ ζ₂`;
/// zero for a triangle or a parallelogram, whose area element `J₀` is then
/// constant.
pub(super) fn reference_distortion(facet: FacetType, x: &[[f64; 3]]) -> f64 {
    match facet.linear() {
        FacetType::Tri3 => 0.0,
        _ => {
            let combine = |w: [f64; 4]| -> [f64; 3] {
                [0, 1, 2].map(|i| 0.25 * (0..4).map(|a| w[a] * x[a][i]).sum::<f64>())
            };
            let a1 = combine([-1.0, 1.0, 1.0, -1.0]);
            let a2 = combine([-1.0, -1.0, 1.0, 1.0]);
            let b = combine([1.0, -1.0, 1.0, -1.0]);
            super::bilinear::distortion(
                autodiff::norm(&b),
                autodiff::norm(&autodiff::cross(&a1, &a2)),
            )
        }
    }
}

/// `det ∂P/∂ζ` of the slave facet projected into the auxiliary plane at an
/// f64 point.
fn plane_jacobian<T: Scalar>(facet: FacetType, nodes: &[[T; 2]], zeta: [f64; 2]) -> T {
    let dn = facet_shape(facet, zeta).dn;
    let mut j = [[T::from_f64(0.0); 2]; 2];
    for (d, p) in dn.iter().zip(nodes).take(facet.nodes()) {
        for (row, pr) in j.iter_mut().zip(p) {
            row[0].add_scaled(pr, d[0]);
            row[1].add_scaled(pr, d[1]);
        }
    }
    j[0][0] * j[1][1] - j[0][1] * j[1][0]
}

/// [`plane_jacobian`] as `c₀ + c₁ ζ₁ + c₂ ζ₂`: the columns of a bilinear
/// quad's Jacobian are affine in the other coordinate, so the `ζ₁ ζ₂` term
/// of their cross product is the bilinear vector's with itself, zero; a
/// triangle's is constant. Three evaluations per segment instead of one
/// per quadrature point.
struct PlaneJacobian<T>([T; 3]);

impl<T: Scalar> PlaneJacobian<T> {
    fn of(facet: FacetType, nodes: &[[T; 2]]) -> Self {
        let c0 = plane_jacobian(facet, nodes, [0.0, 0.0]);
        PlaneJacobian([
            c0,
            plane_jacobian(facet, nodes, [1.0, 0.0]) - c0,
            plane_jacobian(facet, nodes, [0.0, 1.0]) - c0,
        ])
    }

    fn at(&self, zeta: &[T; 2]) -> T {
        self.0[0] + self.0[1] * zeta[0] + self.0[2] * zeta[1]
    }
}

/// The integrals of the segment between slave facet `xs` (reference
/// positions `x_ref`, dual coefficients `a`) and master facet `xm`; `None`
/// when they do not overlap.
///
/// The integrals are over the REFERENCE slave surface: a point's area in the
/// auxiliary plane is scaled by `J₀(ζ) / |det ∂P/∂ζ|`, the reference
/// facet's area element over the projected one. The multipliers are then
/// nominal pressures (force per reference area, as the links'), the
/// traction a body load applies is matched node by node, and `A` is that of
/// the reference facet.
///
/// With `fixed_d` the segment's `D` is not integrated but set to that
/// diagonal (a constant): see `system::covered_facets`.
#[allow(clippy::too_many_arguments)]
pub fn segment_terms<T: Scalar>(
    slave_type: FacetType,
    xs: &[Vec3<T>],
    x_ref: &[[f64; 3]],
    master_type: FacetType,
    xm: &[Vec3<T>],
    a: &[[f64; MAX_FACET_NODES]; MAX_FACET_NODES],
    rules: &MortarRules,
    fixed_d: Option<&[f64; MAX_FACET_NODES]>,
) -> Option<SegmentTerms<T>> {
    let ov = overlap(slave_type, xs, master_type, xm)?;
    let (ns, nm) = (slave_type.nodes(), master_type.nodes());
    let zero = T::from_f64(0.0);
    let mut terms = SegmentTerms {
        weighted_gap: [zero; MAX_FACET_NODES],
        d: [[zero; MAX_FACET_NODES]; MAX_FACET_NODES],
        m: [[zero; MAX_FACET_NODES]; MAX_FACET_NODES],
        normal: ov.plane.normal,
        area: zero,
    };
    let normal = ov.plane.normal;
    let projected_jacobian = PlaneJacobian::of(slave_type, &ov.slave_nodes);
    let parallelograms =
        ov.maps_nearly_affinely() && reference_distortion(slave_type, x_ref) <= NEAR_AFFINE;
    let rule = rules.segment(slave_type, master_type, parallelograms);
    let (slave_heights, master_heights) = (heights(&normal, xs), heights(&normal, xm));
    let mapped = ov.for_each_point(slave_type, master_type, rule, |q| {
        let projected = projected_jacobian.at(&q.zeta);
        let scale = reference_jacobian(slave_type, x_ref, &q.zeta) / projected;
        // The projected facet is counter-clockwise or clockwise depending on
        // its node order; the area element is the absolute value.
        let scale = if projected.re() < 0.0 { -scale } else { scale };
        let weight = q.weight * scale;
        let (s1, n1) = linearised_shape(slave_type, &q.zeta);
        let (s2, n2) = linearised_shape(master_type, &q.xi);
        // Φ_j = Σ_k A_jk N_k with the constant A in f64.
        let phi = linearised_dual_basis(a, &s1, &q.zeta);
        // ν · (x²(ξ) − x¹(ζ)) as the difference of the points' heights
        // over the plane, each interpolated from its nodes' (ν is the
        // segment's): a third of the dual operations of the 3D points.
        let gap =
            interpolate(&s2, &master_heights, &q.xi) - interpolate(&s1, &slave_heights, &q.zeta);
        terms.area = terms.area + weight;
        for (j, phi_j) in phi.iter().enumerate().take(ns) {
            let pw = *phi_j * weight;
            terms.weighted_gap[j].add_product(pw, gap);
            if fixed_d.is_none() {
                for (djk, nk) in terms.d[j].iter_mut().zip(&n1).take(ns) {
                    djk.add_product(pw, *nk);
                }
            }
            for (mjl, nl) in terms.m[j].iter_mut().zip(&n2).take(nm) {
                mjl.add_product(pw, *nl);
            }
        }
    });
    if let Some(diagonal) = fixed_d {
        for (j, dj) in diagonal.iter().enumerate().take(ns) {
            terms.d[j][j] = T::from_f64(*dj);
        }
    }
    mapped.then_some(terms)
}

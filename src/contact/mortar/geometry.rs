//! Segment geometry of the mortar formulation: the slave facet's auxiliary
//! plane, both facets projected onto it, the clipped overlap polygon, its
//! triangulation and the quadrature points mapped back to both facets'
//! parametric coordinates.
//!
//! Everything is written in the scalar type `T` (f64 or a dual number), so
//! the derivative of the clipped geometry (moving vertices, moving plane)
//! comes out of the same code. Combinatorial decisions (which vertex is
//! inside, which edges cross) are made on the f64 values: the derivative is
//! then that of the current clipping pattern, which is the derivative almost
//! everywhere.
use super::bilinear::Bilinear;
use super::MAX_FACET_NODES;
use crate::contact::autodiff::{self, Scalar, Vec3};
use crate::fem::FacetType;

/// A 2-vector in the auxiliary plane.
pub type Vec2<T> = [T; 2];

/// Most vertices a clipped polygon can have: a convex n-gon clipped by a
/// convex m-gon keeps at most n + m.
pub const MAX_POLYGON: usize = 2 * MAX_FACET_NODES;

/// Relative size (to the slave facet's size) under which two vertices are the
/// same and a point counts as lying on a clipping edge.
pub const GEOMETRY_TOL: f64 = 1e-9;

/// The auxiliary plane of a slave facet: through the facet centre, normal to
/// the facet there (outward of the slave body, towards the master), with an
/// orthonormal in-plane basis.
#[derive(Debug, Clone, Copy)]
pub struct Plane<T> {
    pub origin: Vec3<T>,
    pub normal: Vec3<T>,
    pub e1: Vec3<T>,
    pub e2: Vec3<T>,
}

impl<T: Scalar> Plane<T> {
    /// The plane of a slave facet (current positions `x`); `None` for a
    /// degenerate facet (no normal at its centre).
    pub fn of_facet(facet: FacetType, x: &[Vec3<T>]) -> Option<Self> {
        let centre = crate::contact::projection::reference_centre(facet);
        let s = super::facet_shape(facet, centre);
        let zero = autodiff::constant3::<T>([0.0; 3]);
        let (mut origin, mut t1, mut t2) = (zero, zero, zero);
        for (a, xa) in x.iter().enumerate().take(facet.nodes()) {
            origin = autodiff::axpy(&origin, s.n[a], xa);
            t1 = autodiff::axpy(&t1, s.dn[a][0], xa);
            t2 = autodiff::axpy(&t2, s.dn[a][1], xa);
        }
        let (l1, l2) = (autodiff::norm(&t1), autodiff::norm(&t2));
        let n = autodiff::cross(&t1, &t2);
        let ln = autodiff::norm(&n);
        if !(l1.re() > 0.0 && l2.re() > 0.0 && ln.re() > 1e-12 * l1.re() * l2.re()) {
            return None;
        }
        let normal = autodiff::scale(&n, ln.recip());
        let e1 = autodiff::scale(&t1, l1.recip());
        let e2 = autodiff::cross(&normal, &e1);
        Some(Plane {
            origin,
            normal,
            e1,
            e2,
        })
    }

    /// In-plane coordinates of the projection of `x` along the normal.
    pub fn coordinates(&self, x: &Vec3<T>) -> Vec2<T> {
        let d = autodiff::sub(x, &self.origin);
        [autodiff::dot(&d, &self.e1), autodiff::dot(&d, &self.e2)]
    }
}

/// A polygon of at most [`MAX_POLYGON`] vertices (no allocation).
#[derive(Debug, Clone, Copy)]
pub struct Polygon<T> {
    pub vertices: [Vec2<T>; MAX_POLYGON],
    pub len: usize,
}

impl<T: Scalar> Polygon<T> {
    pub fn new() -> Self {
        Polygon {
            vertices: [[T::from_f64(0.0); 2]; MAX_POLYGON],
            len: 0,
        }
    }

    pub fn from_points(points: &[Vec2<T>]) -> Self {
        let mut p = Self::new();
        for v in points.iter().take(MAX_POLYGON) {
            p.push(*v);
        }
        p
    }

    fn push(&mut self, v: Vec2<T>) {
        if let Some(slot) = self.vertices.get_mut(self.len) {
            *slot = v;
            self.len += 1;
        }
    }

    pub fn points(&self) -> &[Vec2<T>] {
        &self.vertices[..self.len]
    }

    /// Signed area (> 0 counter-clockwise), shoelace formula.
    pub fn signed_area(&self) -> T {
        let mut twice = T::from_f64(0.0);
        let p = self.points();
        for i in 0..p.len() {
            let (a, b) = (p[i], p[(i + 1) % p.len()]);
            twice = twice + (a[0] * b[1] - a[1] * b[0]);
        }
        twice * 0.5
    }

    /// The same polygon counter-clockwise.
    pub fn counter_clockwise(mut self) -> Self {
        if self.signed_area().re() < 0.0 {
            self.vertices[..self.len].reverse();
        }
        self
    }

    /// Whether every turn is to the left (allowing straight angles to `tol`).
    pub fn is_convex_ccw(&self, tol: f64) -> bool {
        let p = self.points();
        let n = p.len();
        n >= 3
            && (0..n).all(|i| {
                let (a, b, c) = (p[i], p[(i + 1) % n], p[(i + 2) % n]);
                cross2(&sub2(&b, &a), &sub2(&c, &b)).re() >= -tol
            })
    }

    /// Arithmetic mean of the vertices (inside a convex polygon).
    pub fn centroid(&self) -> Vec2<T> {
        let mut c = [T::from_f64(0.0); 2];
        for v in self.points() {
            c = [c[0] + v[0], c[1] + v[1]];
        }
        let inv = 1.0 / self.len.max(1) as f64;
        [c[0] * inv, c[1] * inv]
    }
}

impl<T: Scalar> Default for Polygon<T> {
    fn default() -> Self {
        Self::new()
    }
}

pub fn sub2<T: Scalar>(a: &Vec2<T>, b: &Vec2<T>) -> Vec2<T> {
    [a[0] - b[0], a[1] - b[1]]
}

pub fn cross2<T: Scalar>(a: &Vec2<T>, b: &Vec2<T>) -> T {
    a[0] * b[1] - a[1] * b[0]
}

/// Where a point lies relative to a clipping edge.
#[derive(Clone, Copy, PartialEq, Eq)]
enum Side {
    In,
    On,
    Out,
}

/// Sutherland–Hodgman: the part of `subject` inside the convex,
/// counter-clockwise `clip`. `tol` is a length: points within it of a clip
/// edge's line count as on it. Intersections are computed only between a
/// point strictly inside and one strictly outside, so the division is by at
/// least `2 tol` and the derivative stays bounded when edges coincide.
pub fn clip<T: Scalar>(subject: &Polygon<T>, clip: &Polygon<T>, tol: f64) -> Polygon<T> {
    // Two buffers clipped into in turn: a fresh polygon per edge was zeroed
    // and copied (3 KB each in `Dual`, 4 % of a frictional mortar run).
    let (mut first, mut second) = (*subject, Polygon::new());
    let (mut from, mut to) = (&mut first, &mut second);
    let c = clip.points();
    for i in 0..c.len() {
        if from.len == 0 {
            break;
        }
        let (a, b) = (c[i], c[(i + 1) % c.len()]);
        if clip_by_edge(from, &a, &b, tol, to) {
            std::mem::swap(&mut from, &mut to);
        }
    }
    remove_duplicates(from, tol);
    *from
}

/// The part of `poly` on the inner side of the line `a`–`b` into `out`;
/// false (and `out` untouched) for a degenerate edge, which clips nothing.
fn clip_by_edge<T: Scalar>(
    poly: &Polygon<T>,
    a: &Vec2<T>,
    b: &Vec2<T>,
    tol: f64,
    out: &mut Polygon<T>,
) -> bool {
    let edge = sub2(b, a);
    let length = edge[0].re().hypot(edge[1].re());
    if length <= 0.0 {
        return false;
    }
    out.len = 0;
    // Signed distance from the edge's line, > 0 on the inner (left) side.
    let distance = |p: &Vec2<T>| cross2(&edge, &sub2(p, a)) * (1.0 / length);
    let side = |d: f64| {
        if d > tol {
            Side::In
        } else if d < -tol {
            Side::Out
        } else {
            Side::On
        }
    };
    let p = poly.points();
    for j in 0..p.len() {
        let (p0, p1) = (&p[(j + p.len() - 1) % p.len()], &p[j]);
        let (d0, d1) = (distance(p0), distance(p1));
        let (s0, s1) = (side(d0.re()), side(d1.re()));
        let crossing = (s0 == Side::In && s1 == Side::Out) || (s0 == Side::Out && s1 == Side::In);
        if crossing {
            let t = d0 / (d0 - d1);
            out.push([p0[0] + (p1[0] - p0[0]) * t, p0[1] + (p1[1] - p0[1]) * t]);
        }
        if s1 != Side::Out {
            out.push(*p1);
        }
    }
    true
}

/// Drops vertices that coincide (within `tol`) with their predecessor, in
/// place.
fn remove_duplicates<T: Scalar>(poly: &mut Polygon<T>, tol: f64) {
    let same =
        |v: &Vec2<T>, w: &Vec2<T>| (v[0].re() - w[0].re()).hypot(v[1].re() - w[1].re()) <= tol;
    let mut kept = 0;
    for i in 0..poly.len {
        if kept > 0 && same(&poly.vertices[i], &poly.vertices[kept - 1]) {
            continue;
        }
        poly.vertices[kept] = poly.vertices[i];
        kept += 1;
    }
    poly.len = kept;
    while poly.len > 1 && same(&poly.vertices[0], &poly.vertices[poly.len - 1]) {
        poly.len -= 1;
    }
}

/// A triangle of the overlap's triangulation.
#[derive(Debug, Clone, Copy)]
pub struct Triangle<T> {
    pub corners: [Vec2<T>; 3],
}

impl<T: Scalar> Triangle<T> {
    pub fn area(&self) -> T {
        let [a, b, c] = self.corners;
        cross2(&sub2(&b, &a), &sub2(&c, &a)) * 0.5
    }

    /// `a + ξ (b − a) + η (c − a)`.
    pub fn point(&self, xi: [f64; 2]) -> Vec2<T> {
        let [a, b, c] = self.corners;
        [
            a[0] + (b[0] - a[0]) * xi[0] + (c[0] - a[0]) * xi[1],
            a[1] + (b[1] - a[1]) * xi[0] + (c[1] - a[1]) * xi[1],
        ]
    }
}

/// Fan triangulation of a convex polygon about its vertex centroid: one
/// triangle per edge, so every vertex enters smoothly (no vertex is special).
pub fn triangulate<T: Scalar>(poly: &Polygon<T>) -> impl Iterator<Item = Triangle<T>> + '_ {
    let c = poly.centroid();
    let p = poly.points();
    let n = if p.len() >= 3 { p.len() } else { 0 };
    (0..n).map(move |i| Triangle {
        corners: [c, p[i], p[(i + 1) % n]],
    })
}

/// Fan triangulation of a convex polygon from its first vertex: `n − 2`
/// triangles, two on a quadrilateral overlap where [`triangulate`] makes
/// four. Used where both facets map affinely onto the plane: the
/// integrands are then polynomials the triangle rule integrates exactly on
/// any triangulation (elsewhere its larger triangles leave a larger error:
/// 3.3e-7 against 1.9e-8 on the 30 %-distorted patch test).
pub fn triangulate_from_vertex<T: Scalar>(
    poly: &Polygon<T>,
) -> impl Iterator<Item = Triangle<T>> + '_ {
    let p = poly.points();
    let end = if p.len() >= 3 { p.len() - 1 } else { 1 };
    (1..end).map(move |i| Triangle {
        corners: [p[0], p[i], p[i + 1]],
    })
}

/// Distortion of a quad facet, `|b| / √|a₁ × a₂|` of its map `c + a₁ ζ₁ +
/// a₂ ζ₂ + b ζ₁ ζ₂` (zero for a triangle or a parallelogram, free of the
/// facet's position and size), up to which it counts as affine: a segment
/// is triangulated from a vertex and, when the slave's reference facet is
/// as close to a parallelogram, integrated with the 7-point rule
/// (`segment::MortarRules`). Both are exact where the maps are affine. Off
/// it, the integrals differ from the 12-point rule's on the vertex
/// centroid's fan by about 1.5e-4 times the distortion squared, relative
/// to the largest (random bent quad pairs, rule_tests.rs: 4.5e-12 at
/// 1.8e-4, 4.0e-11 at 5.3e-4, 1.1e-10 at 8.8e-4, 4.5e-10 at 1.8e-3, 3.6e-9
/// at 4.9e-3; the 7-point rule alone on the centroid's fan a thirtieth of
/// that), so at this bound the switch moves an integral by about 1.5e-10
/// of it. The tangent stays the exact derivative of the residual either
/// way. `impact`'s Neo-Hookean faces bend to distortions up to 1e-3, the
/// 30 %-distorted patch test's are a few tenths.
pub const NEAR_AFFINE: f64 = 1e-3;

/// Relative size of the bilinear term under which the map is affine to
/// rounding: one Newton step from anywhere is its inverse (the error is
/// that term times the step squared).
pub const EXACTLY_AFFINE_TOL: f64 = 1e-13;

/// Facet shape functions at a parametric point in `T` (bilinear quad,
/// linear triangle), so a dual-valued point carries its derivative.
pub fn shape_values<T: Scalar>(facet: FacetType, zeta: &Vec2<T>) -> [T; MAX_FACET_NODES] {
    let one = T::from_f64(1.0);
    let zero = T::from_f64(0.0);
    // Contact facets are first order; `linear` names their reference shape.
    match facet.linear() {
        FacetType::Quad4 => {
            let mut n = [zero; MAX_FACET_NODES];
            for (na, node) in n.iter_mut().zip(crate::fem::shape::QUAD4_REF_NODES) {
                *na = (zeta[0] * node[0] + 1.0) * (zeta[1] * node[1] + 1.0) * 0.25;
            }
            n
        }
        _ => [one - zeta[0] - zeta[1], zeta[0], zeta[1], zero],
    }
}

/// A facet's map from parametric coordinates onto the auxiliary plane,
/// inverted point by point ([`PlanarMap::invert`]). A facet affine to
/// rounding keeps its constant inverse Jacobian and the image of its centre,
/// so a point costs a matrix-vector product instead of Newton iterations.
pub struct PlanarMap<'a, T> {
    facet: FacetType,
    nodes: &'a [Vec2<T>],
    map: Bilinear,
    affine: Option<AffineMap>,
}

/// `ζ = centre + inverse (p − image)`.
struct AffineMap {
    centre: Vec2<f64>,
    image: Vec2<f64>,
    inverse: [[f64; 2]; 2],
}

impl<'a, T: Scalar> PlanarMap<'a, T> {
    /// The map of the projected nodes `nodes` (their f64 form `map`), taken
    /// as affine where its relative bilinear term is at most `affine_tol`;
    /// `None` if it is affine and singular.
    fn new(facet: FacetType, nodes: &'a [Vec2<T>], map: Bilinear, affine_tol: f64) -> Option<Self> {
        let affine = if map.relative_bilinear_term() <= affine_tol {
            let centre = crate::contact::projection::reference_centre(facet);
            Some(AffineMap {
                centre,
                image: map.at(centre),
                inverse: map.inverse_jacobian(centre)?,
            })
        } else {
            None
        };
        Some(PlanarMap {
            facet,
            nodes,
            map,
            affine,
        })
    }

    /// Parametric coordinates of the facet point whose projection is `p`:
    /// in f64 (the affine map, or Newton from the facet centre), then
    /// [`implicit_step`] in `T`. `None` if Newton fails (folded projection).
    pub fn invert(&self, p: &Vec2<T>) -> Option<Vec2<T>> {
        let target = [p[0].re(), p[1].re()];
        let (zeta, inverse) = match &self.affine {
            Some(a) => {
                let r = sub2(&target, &a.image);
                let zeta = [
                    a.centre[0] + a.inverse[0][0] * r[0] + a.inverse[0][1] * r[1],
                    a.centre[1] + a.inverse[1][0] * r[0] + a.inverse[1][1] * r[1],
                ];
                (zeta, a.inverse)
            }
            None => {
                let centre = crate::contact::projection::reference_centre(self.facet);
                let zeta = self.map.newton(target, centre)?;
                (zeta, self.map.inverse_jacobian(zeta)?)
            }
        };
        Some(implicit_step(self.facet, &inverse, self.nodes, p, zeta))
    }
}

/// Parametric coordinates of the facet point whose projection is `p`, given
/// the projected nodes `nodes` (Newton however the facet maps).
pub fn inverse_map<T: Scalar>(facet: FacetType, nodes: &[Vec2<T>], p: &Vec2<T>) -> Option<Vec2<T>> {
    PlanarMap::new(facet, nodes, Bilinear::of(facet, nodes), -1.0)?.invert(p)
}

/// One more Newton step from the solution `ζ₀` (f64), in `T` with the shape
/// values and the inverse Jacobian `J⁻¹` in f64: `ζ₀ + J⁻¹ (p − Σ_a N_a(ζ₀)
/// v_a)`. Its derivative is the implicit function's, `J⁻¹ (dp − Σ_a N_a(ζ₀)
/// dv_a)`, exactly: that of `J` multiplies the residual, zero at `ζ₀`. A
/// step with `J` in `T` (what this replaces) cost six times the dual
/// operations; the affine case's single step from the centre in `T` (also
/// replaced) missed the `N_a(ζ₀)` of a facet that is a parallelogram now
/// but not under a perturbation (its bilinear term's derivative).
fn implicit_step<T: Scalar>(
    facet: FacetType,
    inverse: &[[f64; 2]; 2],
    nodes: &[Vec2<T>],
    p: &Vec2<T>,
    zeta: Vec2<f64>,
) -> Vec2<T> {
    let n = shape_values(facet, &zeta);
    let mut r = *p;
    for (na, v) in n.iter().zip(nodes).take(facet.nodes()) {
        r[0].add_scaled(&v[0], -na);
        r[1].add_scaled(&v[1], -na);
    }
    let component = |k: usize| {
        let mut z = r[0] * inverse[k][0];
        z.add_scaled(&r[1], inverse[k][1]);
        z + zeta[k]
    };
    [component(0), component(1)]
}

/// `∂N_a/∂ζ` at a point in `T`.
pub fn shape_gradients<T: Scalar>(facet: FacetType, zeta: &Vec2<T>) -> [[T; 2]; MAX_FACET_NODES] {
    let zero = T::from_f64(0.0);
    let mut dn = [[zero; 2]; MAX_FACET_NODES];
    match facet.linear() {
        FacetType::Quad4 => {
            for (d, node) in dn.iter_mut().zip(crate::fem::shape::QUAD4_REF_NODES) {
                *d = [
                    (zeta[1] * node[1] + 1.0) * (0.25 * node[0]),
                    (zeta[0] * node[0] + 1.0) * (0.25 * node[1]),
                ];
            }
        }
        _ => {
            let (one, m) = (T::from_f64(1.0), T::from_f64(-1.0));
            dn[0] = [m, m];
            dn[1] = [one, zero];
            dn[2] = [zero, one];
        }
    }
    dn
}

/// The overlap of a slave and a master facet in the slave's auxiliary plane.
#[derive(Debug, Clone, Copy)]
pub struct Overlap<T> {
    pub plane: Plane<T>,
    /// Projected slave and master nodes (in-plane coordinates).
    pub slave_nodes: [Vec2<T>; MAX_FACET_NODES],
    pub master_nodes: [Vec2<T>; MAX_FACET_NODES],
    /// The clipped polygon, counter-clockwise about the plane normal.
    pub polygon: Polygon<T>,
    /// The projected slave and master facets' maps in f64.
    maps: [Bilinear; 2],
}

/// A quadrature point of an overlap: its weight (area in the plane) and its
/// parametric coordinates on both facets.
#[derive(Debug, Clone, Copy)]
pub struct SegmentPoint<T> {
    pub weight: T,
    pub zeta: Vec2<T>,
    pub xi: Vec2<T>,
}

/// The size of a facet (largest node distance from its first node), what
/// the geometric tolerance is scaled with.
pub fn facet_size<T: Scalar>(x: &[Vec3<T>]) -> f64 {
    x.iter()
        .map(|p| autodiff::norm(&autodiff::sub(&autodiff::re3(p), &autodiff::re3(&x[0]))))
        .fold(0.0, f64::max)
}

/// How far apart, in clipping tolerances, two projected facets' bounding
/// boxes must be for [`overlap`] to skip the clip. The clip keeps points
/// within the tolerance outside each master edge, which near a master
/// corner of angle θ reaches tol / sin(θ/2) beyond the box (5.8 tol at θ =
/// 20°); 1e3 leaves any facet a valid mesh has inside the margin.
pub(super) const BOX_MARGIN: f64 = 1e3;

/// Whether the bounding boxes of two projected facets are more than `tol`
/// apart in some direction: then their clipped overlap is empty.
pub(super) fn boxes_apart<T: Scalar>(a: &[Vec2<T>], b: &[Vec2<T>], tol: f64) -> bool {
    let bounds = |p: &[Vec2<T>], k: usize| {
        p.iter()
            .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), v| {
                (lo.min(v[k].re()), hi.max(v[k].re()))
            })
    };
    (0..2).any(|k| {
        let ((alo, ahi), (blo, bhi)) = (bounds(a, k), bounds(b, k));
        alo > bhi + tol || blo > ahi + tol
    })
}

/// Projects and clips a slave and a master facet (current positions). `None`
/// when they do not overlap (or the geometry is degenerate: a slave facet
/// without normal, a master projected edge-on or folded).
pub fn overlap<T: Scalar>(
    slave_type: FacetType,
    xs: &[Vec3<T>],
    master_type: FacetType,
    xm: &[Vec3<T>],
) -> Option<Overlap<T>> {
    let plane = Plane::of_facet(slave_type, xs)?;
    let tol = GEOMETRY_TOL * facet_size(xs);
    let mut slave_nodes = [[T::from_f64(0.0); 2]; MAX_FACET_NODES];
    let mut master_nodes = slave_nodes;
    for (o, x) in slave_nodes.iter_mut().zip(xs).take(slave_type.nodes()) {
        *o = plane.coordinates(x);
    }
    for (o, x) in master_nodes.iter_mut().zip(xm).take(master_type.nodes()) {
        *o = plane.coordinates(x);
    }
    let (slave_2d, master_2d) = (
        &slave_nodes[..slave_type.nodes()],
        &master_nodes[..master_type.nodes()],
    );
    if boxes_apart(slave_2d, master_2d, BOX_MARGIN * tol) {
        // Most candidates of a slave facet lie beside it: their clip would
        // be empty, at the cost of orienting and clipping.
        return None;
    }
    let subject = Polygon::from_points(slave_2d).counter_clockwise();
    let clipper = Polygon::from_points(master_2d).counter_clockwise();
    let area_tol = tol * facet_size(xs);
    if !clipper.is_convex_ccw(area_tol) || clipper.signed_area().re() <= area_tol {
        return None;
    }
    let polygon = clip(&subject, &clipper, tol);
    if polygon.len < 3 || polygon.signed_area().re() <= area_tol {
        return None;
    }
    let maps = [
        Bilinear::of(slave_type, slave_2d),
        Bilinear::of(master_type, master_2d),
    ];
    Some(Overlap {
        plane,
        slave_nodes,
        master_nodes,
        polygon,
        maps,
    })
}

impl<T: Scalar> Overlap<T> {
    /// Whether both projected facets map affinely onto the plane, nearly
    /// ([`NEAR_AFFINE`]): triangles and (near) parallelograms.
    pub fn maps_nearly_affinely(&self) -> bool {
        self.maps.iter().all(|m| m.distortion() <= NEAR_AFFINE)
    }

    /// Quadrature points on the overlap's triangles with the triangle rule
    /// `rule` (reference triangle, weights summing to ½), mapped back to both
    /// facets; `f` is called once per point. Returns false if a point could
    /// not be mapped back (then the overlap should be dropped).
    pub fn for_each_point(
        &self,
        slave_type: FacetType,
        master_type: FacetType,
        rule: &[([f64; 2], f64)],
        mut f: impl FnMut(&SegmentPoint<T>),
    ) -> bool {
        let affine = self.maps_nearly_affinely();
        let maps = (
            PlanarMap::new(
                slave_type,
                &self.slave_nodes,
                self.maps[0],
                EXACTLY_AFFINE_TOL,
            ),
            PlanarMap::new(
                master_type,
                &self.master_nodes,
                self.maps[1],
                EXACTLY_AFFINE_TOL,
            ),
        );
        let (Some(slave_map), Some(master_map)) = maps else {
            return false;
        };
        let triangles: &mut dyn Iterator<Item = Triangle<T>> = if affine {
            &mut triangulate_from_vertex(&self.polygon)
        } else {
            &mut triangulate(&self.polygon)
        };
        for tri in triangles {
            let area = tri.area();
            for (xi_ref, w) in rule {
                let p = tri.point(*xi_ref);
                let (Some(zeta), Some(xi)) = (slave_map.invert(&p), master_map.invert(&p)) else {
                    return false;
                };
                f(&SegmentPoint {
                    weight: area * (2.0 * w),
                    zeta,
                    xi,
                });
            }
        }
        true
    }
}

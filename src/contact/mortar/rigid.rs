//! Mortar contact against a rigid analytic master (plane, sphere, cylinder;
//! docs/formulation.md §13.5). There is no master mesh to clip against: the
//! integrals of a slave node run over its slave facets alone, and the
//! tangent has slave–slave blocks only.
//!
//! Per slave facet, with the facet's dual basis `Φ_j` (of the reference
//! facet, as for deformable masters) and a rule over the whole facet (4×4
//! Gauss on quads, the degree-6 segment-triangle rule on triangles: the distance to
//! a curved surface is not polynomial over the facet):
//! - `g(x)` the signed distance of the slave point `x = Σ N_k x_k` to the
//!   placed surface (> 0 outside the rigid body), `n(x) = ∂g/∂x` its outward
//!   normal there;
//! - weighted gap `g̃_j = ∫ Φ_j g dA₀`;
//! - force coefficients `c_jk = −∫ Φ_j N_k n dA₀ = ∂(−g̃_j)/∂x_k`: the
//!   residual `+p_j c_jk` on slave node `k` is exactly `−p_j ∂g̃_j/∂x` (no
//!   quantity is held fixed, unlike the deformable case), the gradient of
//!   the augmented-Lagrangian potential, so its tangent
//!   `Σ_j p_j ∂c_j/∂x + c_j ⊗ ∂p_j/∂x` is symmetric up to rounding;
//! - `D_jk = ∫ Φ_j N_k dA₀` (constant: reference quantities), the node's
//!   coverage and its friction weights, and `a_j = Σ ∫ N_j n dA₀`, the
//!   node normal of the friction law.
//!
//! The prescribed translation of the surface enters through its placement
//! (`RigidSurface::moved` at the current load factor) and, with friction,
//! through the master's increment in the slip (`rigid_friction`).
use super::facet_shape;
use super::segment::{dual_coefficients, dual_values, MortarRules, Rule};
use super::system::{emit_scaled_outer, NodalData, NodeDof, NodeState};
use super::MAX_FACET_NODES;
use crate::contact::autodiff::{self, Dual, Scalar, Seed, Vec3};
use crate::fem::{FacetType, QuadRule};
use crate::model::RigidSurface;

/// Variables of one slave facet: node `a` at `3a + i`.
pub const RIGID_DOFS: usize = 3 * MAX_FACET_NODES;
pub(super) type RD = Dual<RIGID_DOFS>;

/// A slave surface against a rigid master, as node ids into `positions`.
#[derive(Debug, Clone, Copy)]
pub struct RigidInterface<'a> {
    pub facet_type: FacetType,
    /// Current and reference position of every slave node id.
    pub positions: &'a [[f64; 3]],
    pub reference: &'a [[f64; 3]],
    pub facets: &'a [[u32; MAX_FACET_NODES]],
    /// The facets integrated (from the step's search), ascending, as
    /// (slave facet, 0): the pair's candidates, with no master facet.
    pub candidates: &'a [(u32, u32)],
    /// Per slave facet: whether its forces are assembled on this rank.
    pub assembled: &'a [bool],
    /// The surface at its current placement (unit normal / axis).
    pub surface: RigidSurface,
}

/// The integrals of one slave facet (rows `j`, columns `k`: its nodes).
#[derive(Debug, Clone, Copy)]
pub struct RigidFacet<T> {
    pub facet: u32,
    /// `∫ Φ_j g dA₀`.
    pub weighted_gap: [T; MAX_FACET_NODES],
    /// `c_jk = −∫ Φ_j N_k n dA₀`.
    pub force: [[Vec3<T>; MAX_FACET_NODES]; MAX_FACET_NODES],
    /// `D_jk = ∫ Φ_j N_k dA₀`.
    pub d: [[f64; MAX_FACET_NODES]; MAX_FACET_NODES],
    /// `∫ N_a n dA₀` per row.
    pub normal: [Vec3<T>; MAX_FACET_NODES],
}

/// The rule over a whole slave facet for the rigid integrals.
pub fn facet_rule(facet: FacetType, rules: &MortarRules) -> Rule {
    match facet.linear() {
        FacetType::Quad4 => {
            let q = QuadRule::quad_4x4();
            q.points
                .iter()
                .zip(&q.weights)
                .map(|(p, w)| ([p[0], p[1]], *w))
                .collect()
        }
        _ => rules.triangle.clone(),
    }
}

/// Signed distance of `x` to the placed surface and the outward unit normal
/// there; `None` where the normal is undefined (at a sphere's centre, on a
/// cylinder's axis).
pub fn distance<T: Scalar>(surface: &RigidSurface, x: &Vec3<T>) -> Option<(T, Vec3<T>)> {
    let radial = |v: Vec3<T>, radius: f64| {
        let len = autodiff::norm(&v);
        (len.re() > 1e-12 * radius).then(|| (len - radius, autodiff::scale(&v, len.recip())))
    };
    match *surface {
        RigidSurface::Plane { point, normal } => {
            let n = autodiff::constant3::<T>(normal);
            Some((
                autodiff::dot(&autodiff::sub(x, &autodiff::constant3(point)), &n),
                n,
            ))
        }
        RigidSurface::Sphere { centre, radius } => {
            radial(autodiff::sub(x, &autodiff::constant3(centre)), radius)
        }
        RigidSurface::Cylinder {
            point,
            axis,
            radius,
        } => {
            let d = autodiff::sub(x, &autodiff::constant3(point));
            let a = autodiff::constant3::<T>(axis);
            let along = autodiff::scale(&a, autodiff::dot(&d, &a));
            radial(autodiff::sub(&d, &along), radius)
        }
    }
}

/// `|∂X/∂ζ₁ × ∂X/∂ζ₂|` of the reference facet at `zeta`.
fn reference_jacobian(facet: FacetType, x_ref: &[[f64; 3]], zeta: [f64; 2]) -> f64 {
    let s = facet_shape(facet, zeta);
    let (mut t1, mut t2) = ([0.0; 3], [0.0; 3]);
    for (x, d) in x_ref.iter().zip(&s.dn) {
        t1 = autodiff::axpy(&t1, d[0], x);
        t2 = autodiff::axpy(&t2, d[1], x);
    }
    autodiff::norm(&autodiff::cross(&t1, &t2))
}

/// Every candidate facet's integrals (a facet with a point where the
/// normal is undefined, or a degenerate reference facet, is left out: its
/// nodes are then not covered).
pub fn facets<T: Seed>(interface: &RigidInterface, rules: &MortarRules) -> Vec<RigidFacet<T>> {
    let ft = interface.facet_type;
    let ns = ft.nodes();
    let rule = facet_rule(ft, rules);
    let zero = T::from_f64(0.0);
    let mut out = Vec::with_capacity(interface.candidates.len());
    'facets: for &(f, _) in interface.candidates {
        let nodes = &interface.facets[f as usize][..ns];
        let mut x_ref = [[0.0; 3]; MAX_FACET_NODES];
        let mut xs = [[zero; 3]; MAX_FACET_NODES];
        for (a, &n) in nodes.iter().enumerate() {
            x_ref[a] = interface.reference[n as usize];
            let p = interface.positions[n as usize];
            xs[a] = [0, 1, 2].map(|i| T::seed(p[i], 3 * a + i));
        }
        let Some(coef) = dual_coefficients::<f64>(ft, &x_ref[..ns], rules) else {
            continue;
        };
        let mut terms = RigidFacet {
            facet: f,
            weighted_gap: [zero; MAX_FACET_NODES],
            force: [[[zero; 3]; MAX_FACET_NODES]; MAX_FACET_NODES],
            d: [[0.0; MAX_FACET_NODES]; MAX_FACET_NODES],
            normal: [[zero; 3]; MAX_FACET_NODES],
        };
        for (zeta, w) in &rule {
            let s = facet_shape(ft, *zeta);
            let w0 = w * reference_jacobian(ft, &x_ref[..ns], *zeta);
            let mut x = [zero; 3];
            for (na, xa) in s.n.iter().zip(&xs).take(ns) {
                x = autodiff::add(&x, &autodiff::scale_f64(xa, *na));
            }
            let Some((gap, n)) = distance(&interface.surface, &x) else {
                continue 'facets;
            };
            let phi = dual_values(&coef, &s.n, ns);
            for (j, phi_j) in phi.iter().enumerate().take(ns) {
                let pw = phi_j * w0;
                terms.weighted_gap[j] = terms.weighted_gap[j] + gap * pw;
                for k in 0..ns {
                    let c = pw * s.n[k];
                    terms.d[j][k] += c;
                    terms.force[j][k] =
                        autodiff::sub(&terms.force[j][k], &autodiff::scale_f64(&n, c));
                }
                terms.normal[j] =
                    autodiff::add(&terms.normal[j], &autodiff::scale_f64(&n, s.n[j] * w0));
            }
        }
        out.push(terms);
    }
    out
}

/// Calls `visit(index, facet, a, j)` for every integrated facet (`index`
/// into `facets`) and each of its nodes `a` that carries a nodal slot `j`
/// (`assembled_only`: only the facets whose forces this rank assembles).
pub(super) fn for_each_node<T>(
    interface: &RigidInterface,
    nodal: &NodalData,
    facets: &[RigidFacet<T>],
    assembled_only: bool,
    mut visit: impl FnMut(usize, &RigidFacet<T>, usize, usize),
) {
    let ns = interface.facet_type.nodes();
    for (index, f) in facets.iter().enumerate() {
        if assembled_only && !interface.assembled[f.facet as usize] {
            continue;
        }
        for (a, &node) in interface.facets[f.facet as usize][..ns].iter().enumerate() {
            if let Some(j) = nodal.slot_of(node) {
                visit(index, f, a, j);
            }
        }
    }
}

/// Nodal weighted gaps `g̃_j` (by slot) and whether every facet of the node
/// (`expected[j]` of them on this rank) was integrated.
pub fn weighted_gaps<T: Scalar>(
    interface: &RigidInterface,
    nodal: &NodalData,
    facets: &[RigidFacet<T>],
    expected: &[u32],
) -> (Vec<f64>, Vec<bool>) {
    let mut gap = vec![0.0; nodal.nodes.len()];
    let mut count = vec![0u32; nodal.nodes.len()];
    for_each_node(interface, nodal, facets, false, |_, f, a, j| {
        gap[j] += f.weighted_gap[a].re();
        count[j] += 1;
    });
    let covered = count.iter().zip(expected).map(|(c, e)| c == e).collect();
    (gap, covered)
}

/// Adds the residual `+p_j c_jk` of the assembled facets:
/// `emit(node, component, value)`.
pub fn residual<T: Scalar>(
    interface: &RigidInterface,
    nodal: &NodalData,
    facets: &[RigidFacet<T>],
    states: &[NodeState],
    mut emit: impl FnMut(u32, usize, f64),
) {
    let ns = interface.facet_type.nodes();
    for_each_node(interface, nodal, facets, true, |_, f, a, j| {
        let p = states[j].pressure;
        if p == 0.0 {
            return;
        }
        for (k, &node) in interface.facets[f.facet as usize][..ns].iter().enumerate() {
            for i in 0..3 {
                emit(node, i, p * f.force[a][k][i].re());
            }
        }
    });
}

/// Adds the tangent of the assembled facets: `emit(row, col, value)`.
/// `facets` must hold every integrated facet of every node of an assembled
/// facet.
pub fn tangent(
    interface: &RigidInterface,
    nodal: &NodalData,
    facets: &[RigidFacet<RD>],
    states: &[NodeState],
    mut emit: impl FnMut(NodeDof, NodeDof, f64),
) {
    let ns = interface.facet_type.nodes();
    let nn = nodal.nodes.len();
    let mut grad: Vec<Vec<(NodeDof, f64)>> = vec![Vec::new(); nn];
    let mut rows: Vec<Vec<(NodeDof, f64)>> = vec![Vec::new(); nn];
    for f in facets {
        let ids = &interface.facets[f.facet as usize][..ns];
        let assembled = interface.assembled[f.facet as usize];
        for (a, &node) in ids.iter().enumerate() {
            let Some(j) = nodal.slot_of(node) else {
                continue;
            };
            if !states[j].closed {
                continue;
            }
            let p = states[j].pressure;
            for v in 0..3 * ns {
                grad[j].push(((ids[v / 3], v % 3), f.weighted_gap[a].eps[v]));
            }
            if !assembled {
                continue;
            }
            for (k, &id) in ids.iter().enumerate() {
                for i in 0..3 {
                    let c = f.force[a][k][i];
                    rows[j].push(((id, i), c.re));
                    // p_j ∂c_j/∂x: local to the facet.
                    if p != 0.0 {
                        for (w, d) in c.eps.iter().enumerate().take(3 * ns) {
                            if *d != 0.0 {
                                emit((id, i), (ids[w / 3], w % 3), p * d);
                            }
                        }
                    }
                }
            }
        }
    }
    // c_j ⊗ ∂p_j/∂x with ∂p_j/∂x = −(ε_j/A_j) ∂g̃_j/∂x.
    emit_scaled_outer(nodal, -1.0, rows, grad, emit);
}

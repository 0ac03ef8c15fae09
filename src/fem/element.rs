//! Total-Lagrangian volume element kernels.
//!
//! Geometry (reference gradients, Jacobian-weighted quadrature weights) is
//! computed once per cell in [`ElementGeometry`]; the kernels then only need
//! the nodal displacements. Internal force `r_{ai} = ∫ P_{iJ} ∂N_a/∂X_J dV`,
//! tangent `k = ∂r/∂u`, both over the reference volume.
//!
//! On `Err` the output buffers hold partial results and must be discarded.

use nalgebra::{Matrix3, Vector3};

use super::material::Tangent;
use super::shape::{self, HEX8_REF_NODES};
use super::{check_finite_points, check_len, CellType, FemError, Material, QuadRule};

/// Per-cell data precomputed from the reference coordinates.
///
/// `grad_n[qp * nodes + a]` is `∂N_a/∂X` and `n[qp * nodes + a]` is `N_a` at
/// quadrature point `qp`; `jxw[qp]` is `det J · weight`.
#[derive(Debug, Clone, PartialEq)]
pub struct ElementGeometry {
    pub cell_type: CellType,
    pub grad_n: Vec<[f64; 3]>,
    pub jxw: Vec<f64>,
    pub n: Vec<f64>,
}

impl ElementGeometry {
    /// Fails with [`FemError::InvertedElement`] if `det J ≤ 0` at a
    /// quadrature point and, for hex8, with [`FemError::InvertedCorner`] if
    /// it is `≤ 0` at a corner node: Gauss points alone miss a hex folded
    /// near one corner.
    pub fn new(cell_type: CellType, x_ref: &[[f64; 3]], rule: &QuadRule) -> Result<Self, FemError> {
        let nodes = cell_type.nodes();
        check_len("x_ref", nodes, x_ref.len())?;
        check_finite_points("x_ref", x_ref)?;
        rule.check()?;
        let mut geom = Self {
            cell_type,
            grad_n: Vec::with_capacity(rule.len() * nodes),
            jxw: Vec::with_capacity(rule.len()),
            n: Vec::with_capacity(rule.len() * nodes),
        };
        for (qp, (xi, weight)) in rule.points.iter().zip(&rule.weights).enumerate() {
            // The reference gradients go where the physical ones will be and
            // are mapped in place.
            let base = geom.n.len();
            geom.n.resize(base + nodes, 0.0);
            geom.grad_n.resize(base + nodes, [0.0; 3]);
            let grad = &mut geom.grad_n[base..];
            shape::eval_cell(cell_type, *xi, &mut geom.n[base..], grad);
            let jac = reference_jacobian(x_ref, grad);
            let det_j = jac.determinant();
            let inverted = FemError::InvertedElement { qp, det_j };
            if det_j.is_nan() || det_j <= 0.0 {
                return Err(inverted);
            }
            let j_inv_t = jac.try_inverse().ok_or(inverted)?.transpose();
            for dn in grad.iter_mut() {
                let g = j_inv_t * Vector3::from(*dn);
                *dn = [g.x, g.y, g.z];
            }
            geom.jxw.push(det_j * weight);
        }
        check_hex_corners(cell_type, x_ref)?;
        Ok(geom)
    }

    pub fn nodes(&self) -> usize {
        self.cell_type.nodes()
    }

    pub fn n_qp(&self) -> usize {
        self.jxw.len()
    }

    /// The fields are public, so a geometry may have been assembled by hand;
    /// every kernel checks the lengths agree before indexing.
    pub fn check(&self) -> Result<(), FemError> {
        let per_qp = self.n_qp() * self.nodes();
        check_len("ElementGeometry::grad_n", per_qp, self.grad_n.len())?;
        check_len("ElementGeometry::n", per_qp, self.n.len())
    }

    fn qp_grad(&self, qp: usize) -> &[[f64; 3]] {
        let nodes = self.nodes();
        &self.grad_n[qp * nodes..(qp + 1) * nodes]
    }

    fn qp_n(&self, qp: usize) -> &[f64] {
        let nodes = self.nodes();
        &self.n[qp * nodes..(qp + 1) * nodes]
    }

    fn check_qp(&self, qp: usize) -> Result<(), FemError> {
        if qp < self.n_qp() {
            Ok(())
        } else {
            Err(FemError::QpOutOfRange {
                qp,
                n_qp: self.n_qp(),
            })
        }
    }
}

/// `J_ij = ∂X_i/∂ξ_j`.
fn reference_jacobian(x: &[[f64; 3]], dn: &[[f64; 3]]) -> Matrix3<f64> {
    let mut jac = Matrix3::zeros();
    for (xa, da) in x.iter().zip(dn) {
        jac += Vector3::from(*xa) * Vector3::from(*da).transpose();
    }
    jac
}

fn check_hex_corners(cell_type: CellType, x_ref: &[[f64; 3]]) -> Result<(), FemError> {
    if cell_type != CellType::Hex8 {
        // A linear tet has one constant Jacobian, already checked.
        return Ok(());
    }
    let (mut n, mut dn) = ([0.0; 8], [[0.0; 3]; 8]);
    for (corner, xi) in HEX8_REF_NODES.iter().enumerate() {
        shape::eval_cell(CellType::Hex8, *xi, &mut n, &mut dn);
        let det_j = reference_jacobian(x_ref, &dn).determinant();
        if det_j.is_nan() || det_j <= 0.0 {
            return Err(FemError::InvertedCorner { corner, det_j });
        }
    }
    Ok(())
}

/// Common argument checks of the displacement kernels; returns the node
/// count.
fn check_inputs(
    material: &Material,
    geom: &ElementGeometry,
    u: &[[f64; 3]],
) -> Result<usize, FemError> {
    material.validate()?;
    geom.check()?;
    check_len("u", geom.nodes(), u.len())?;
    check_finite_points("u", u)?;
    Ok(geom.nodes())
}

/// `F = I + Σ_a u_a ⊗ ∇N_a`.
fn deformation_gradient_at(grad: &[[f64; 3]], u: &[[f64; 3]]) -> Matrix3<f64> {
    let mut f = Matrix3::identity();
    for (g, ua) in grad.iter().zip(u) {
        f += Vector3::from(*ua) * Vector3::from(*g).transpose();
    }
    f
}

/// `r_{ai} += jxw · P_{iJ} ∂N_a/∂X_J`.
fn add_stress_divergence(p: &Matrix3<f64>, grad: &[[f64; 3]], jxw: f64, r: &mut [f64]) {
    for (ra, g) in r.chunks_exact_mut(3).zip(grad) {
        let pg = p * Vector3::from(*g);
        for (ri, v) in ra.iter_mut().zip(pg.iter()) {
            *ri += jxw * v;
        }
    }
}

/// `k_{ai,bk} += jxw · ∂N_a/∂X_J A_{iJkL} ∂N_b/∂X_L`, contracted in two
/// passes per node a (first over J, then over L per node pair) so the cost
/// is O(n·81 + n²·27) instead of O(n²·81), with one node's 27 contractions
/// on the stack whatever the cell. With `upper_only` the blocks b < a are
/// skipped and must be mirrored afterwards.
fn add_material_tangent(a: &Tangent, grad: &[[f64; 3]], jxw: f64, k: &mut [f64], upper_only: bool) {
    let nodes = grad.len();
    let ndof = 3 * nodes;
    let a = a.as_slice(); // column-major: A_{(r, col)} = a[col * 9 + r]
    for (node_a, ga) in grad.iter().enumerate() {
        // ca[i][L][k] = jxw · Σ_J ∂N_a/∂X_J A_{iJkL}; stored with L outside
        // k so the second pass reads three contiguous 3-vectors.
        let mut ca = [[[0.0f64; 3]; 3]; 3];
        let g = [jxw * ga[0], jxw * ga[1], jxw * ga[2]];
        for (i, ca_i) in ca.iter_mut().enumerate() {
            for (kl, col) in a.chunks_exact(9).enumerate() {
                let col = &col[3 * i..3 * i + 3];
                ca_i[kl % 3][kl / 3] = g[0] * col[0] + g[1] * col[1] + g[2] * col[2];
            }
        }
        let first_b = if upper_only { node_a } else { 0 };
        for (node_b, gb) in grad.iter().enumerate().skip(first_b) {
            for (i, ca_i) in ca.iter().enumerate() {
                let row = (3 * node_a + i) * ndof + 3 * node_b;
                let block = &mut k[row..row + 3];
                for (kk, kv) in block.iter_mut().enumerate() {
                    *kv += ca_i[0][kk] * gb[0] + ca_i[1][kk] * gb[1] + ca_i[2][kk] * gb[2];
                }
            }
        }
    }
}

/// Copies the upper node blocks (b > a) onto the lower ones.
fn mirror_upper_blocks(k: &mut [f64], nodes: usize) {
    let ndof = 3 * nodes;
    for node_a in 0..nodes {
        for node_b in node_a + 1..nodes {
            for i in 0..3 {
                for kk in 0..3 {
                    let upper = (3 * node_a + i) * ndof + 3 * node_b + kk;
                    let lower = (3 * node_b + kk) * ndof + 3 * node_a + i;
                    k[lower] = k[upper];
                }
            }
        }
    }
}

fn constitutive_error(qp: usize) -> impl Fn(super::MaterialError) -> FemError {
    move |source| FemError::Constitutive { qp, source }
}

/// Internal force `r = ∫ Bᵀ P dV` (node-major, `3n` entries, overwritten).
pub fn internal_force(
    material: &Material,
    geom: &ElementGeometry,
    u: &[[f64; 3]],
    r: &mut [f64],
) -> Result<(), FemError> {
    let nodes = check_inputs(material, geom, u)?;
    check_len("r", 3 * nodes, r.len())?;
    r.fill(0.0);
    for (qp, &jxw) in geom.jxw.iter().enumerate() {
        let grad = geom.qp_grad(qp);
        let f = deformation_gradient_at(grad, u);
        let p = material
            .first_piola_unchecked(&f)
            .map_err(constitutive_error(qp))?;
        add_stress_divergence(&p, grad, jxw, r);
    }
    Ok(())
}

/// Internal force and its consistent tangent `k = ∂r/∂u` (material plus
/// geometric stiffness, both carried by `A = ∂P/∂F`). `k` is the row-major
/// `(3n) × (3n)` block; both outputs are overwritten. Allocation-free.
pub fn internal_force_and_tangent(
    material: &Material,
    geom: &ElementGeometry,
    u: &[[f64; 3]],
    r: &mut [f64],
    k: &mut [f64],
) -> Result<(), FemError> {
    let nodes = check_inputs(material, geom, u)?;
    check_len("r", 3 * nodes, r.len())?;
    check_len("k", 9 * nodes * nodes, k.len())?;
    r.fill(0.0);
    k.fill(0.0);
    let symmetric = material.tangent_is_symmetric();
    let constant_tangent = constant_tangent(material)?;
    for (qp, &jxw) in geom.jxw.iter().enumerate() {
        let grad = geom.qp_grad(qp);
        let f = deformation_gradient_at(grad, u);
        let (p, a) = stress_and_tangent(material, constant_tangent.as_ref(), &f)
            .map_err(constitutive_error(qp))?;
        add_stress_divergence(&p, grad, jxw, r);
        add_material_tangent(&a, grad, jxw, k, symmetric);
    }
    if symmetric {
        mirror_upper_blocks(k, nodes);
    }
    Ok(())
}

/// The tangent of a linear law, built once per element instead of once per
/// quadrature point.
fn constant_tangent(material: &Material) -> Result<Option<Tangent>, FemError> {
    if !material.is_linear() {
        return Ok(None);
    }
    let (_, a) = material
        .first_piola_and_tangent_unchecked(&Matrix3::identity())
        .map_err(constitutive_error(0))?;
    Ok(Some(a))
}

fn stress_and_tangent(
    material: &Material,
    constant_tangent: Option<&Tangent>,
    f: &Matrix3<f64>,
) -> Result<(Matrix3<f64>, Tangent), super::MaterialError> {
    match constant_tangent {
        Some(a) => Ok((material.first_piola_unchecked(f)?, *a)),
        None => material.first_piola_and_tangent_unchecked(f),
    }
}

/// The tangent at `u = 0`. For `LinearElastic` that is the stiffness at every
/// state, to assemble once; for `NeoHookean` it is the same small-strain
/// matrix (the laws agree to first order at `F = I`).
pub fn linear_stiffness(
    material: &Material,
    geom: &ElementGeometry,
    k: &mut [f64],
) -> Result<(), FemError> {
    material.validate()?;
    geom.check()?;
    let nodes = geom.nodes();
    check_len("k", 9 * nodes * nodes, k.len())?;
    k.fill(0.0);
    let (_, a) = material
        .first_piola_and_tangent_unchecked(&Matrix3::identity())
        .map_err(constitutive_error(0))?;
    let symmetric = material.tangent_is_symmetric();
    for (qp, &jxw) in geom.jxw.iter().enumerate() {
        add_material_tangent(&a, geom.qp_grad(qp), jxw, k, symmetric);
    }
    if symmetric {
        mirror_upper_blocks(k, nodes);
    }
    Ok(())
}

/// Stored energy `∫ W(F) dV`; its gradient is [`internal_force`].
pub fn strain_energy(
    material: &Material,
    geom: &ElementGeometry,
    u: &[[f64; 3]],
) -> Result<f64, FemError> {
    check_inputs(material, geom, u)?;
    let mut energy = 0.0;
    for (qp, &jxw) in geom.jxw.iter().enumerate() {
        let f = deformation_gradient_at(geom.qp_grad(qp), u);
        energy += jxw
            * material
                .strain_energy_unchecked(&f)
                .map_err(constitutive_error(qp))?;
    }
    Ok(energy)
}

/// `F` at one quadrature point, for stress output and post-processing.
pub fn deformation_gradient(
    geom: &ElementGeometry,
    qp: usize,
    u: &[[f64; 3]],
) -> Result<Matrix3<f64>, FemError> {
    geom.check()?;
    geom.check_qp(qp)?;
    check_len("u", geom.nodes(), u.len())?;
    Ok(deformation_gradient_at(geom.qp_grad(qp), u))
}

/// Consistent nodal forces of a uniform body force per reference volume:
/// `f_{ai} = ∫ N_a b_i dV` (overwritten).
pub fn body_force(geom: &ElementGeometry, b: [f64; 3], f: &mut [f64]) -> Result<(), FemError> {
    geom.check()?;
    check_finite_points("body force", &[b])?;
    check_len("f", 3 * geom.nodes(), f.len())?;
    f.fill(0.0);
    for (qp, &jxw) in geom.jxw.iter().enumerate() {
        add_weighted_load(geom.qp_n(qp), b, jxw, f);
    }
    Ok(())
}

/// As [`body_force`], with `b` evaluated at each quadrature point's
/// reference position (manufactured solutions, gravity gradients).
pub fn body_force_fn(
    geom: &ElementGeometry,
    x_ref: &[[f64; 3]],
    b: impl Fn([f64; 3]) -> [f64; 3],
    f: &mut [f64],
) -> Result<(), FemError> {
    geom.check()?;
    check_len("x_ref", geom.nodes(), x_ref.len())?;
    check_len("f", 3 * geom.nodes(), f.len())?;
    f.fill(0.0);
    for (qp, &jxw) in geom.jxw.iter().enumerate() {
        let n = geom.qp_n(qp);
        let b_qp = b(interpolate_at(n, x_ref));
        check_finite_points("body force", &[b_qp])?;
        add_weighted_load(n, b_qp, jxw, f);
    }
    Ok(())
}

fn add_weighted_load(n: &[f64], b: [f64; 3], jxw: f64, f: &mut [f64]) {
    for (fa, na) in f.chunks_exact_mut(3).zip(n) {
        for (fi, bi) in fa.iter_mut().zip(b) {
            *fi += jxw * na * bi;
        }
    }
}

/// Consistent mass `M_{(3a+i)(3b+j)} = δ_ij ∫ ρ N_a N_b dV` over the
/// reference volume (row-major `(3n) × (3n)`, overwritten). `density` is the
/// reference density, so in total-Lagrangian form the matrix never changes
/// with the deformation and is assembled once per run.
///
/// Quadrature, chosen so the matrix is exact where it can be and never
/// singular:
///
/// - `Tet4` always uses the 4-point degree-2 rule, whatever rule built the
///   geometry: `N_a N_b` is quadratic and the default 1-point rule would
///   lump everything onto the centroid (rank 3). `det J` is constant on a
///   linear tet, so the volume from any rule carries over exactly and the
///   result is the closed form `ρ V (1 + δ_ab) / 20`.
/// - Every other type uses the geometry's own rule, which must have at
///   least as many points as the cell has nodes (fewer give a
///   rank-deficient matrix: [`FemError::UnderintegratedMass`]). Build the
///   geometry with [`QuadRule::mass_for_cell`] where that exists (tet10,
///   wedge15, pyramid5), else with the default rule: both integrate
///   `N_a N_b` exactly on an affine cell. On a distorted cell the integrand
///   also carries the non-constant `det J` and the result is approximate,
///   but the total mass `Σ_ab M_ab = ρ V` stays exact because `Σ_a N_a = 1`
///   reduces it to the volume integral.
pub fn mass_matrix(geom: &ElementGeometry, density: f64, m: &mut [f64]) -> Result<(), FemError> {
    geom.check()?;
    if !(density.is_finite() && density >= 0.0) {
        return Err(FemError::InvalidDensity { density });
    }
    let nodes = geom.nodes();
    check_len("m", 9 * nodes * nodes, m.len())?;
    m.fill(0.0);
    match geom.cell_type {
        CellType::Tet4 => {
            let rule = QuadRule::tet_4();
            let reference_volume: f64 = rule.weights.iter().sum();
            let det_j = element_volume(geom) / reference_volume;
            let (mut n, mut dn) = ([0.0; 4], [[0.0; 3]; 4]);
            for (xi, w) in rule.points.iter().zip(&rule.weights) {
                shape::eval_cell(CellType::Tet4, *xi, &mut n, &mut dn);
                add_mass_at(&n, density * det_j * w, m);
            }
        }
        _ => {
            if geom.n_qp() < nodes {
                return Err(FemError::UnderintegratedMass {
                    cell: geom.cell_type.name(),
                    n_qp: geom.n_qp(),
                    needed: nodes,
                });
            }
            for (qp, &jxw) in geom.jxw.iter().enumerate() {
                add_mass_at(geom.qp_n(qp), density * jxw, m);
            }
        }
    }
    Ok(())
}

/// `M_{(3a+i)(3b+i)} += weight · N_a N_b`; the three components share one
/// scalar mass, so only the diagonal of each 3×3 node block is touched.
fn add_mass_at(n: &[f64], weight: f64, m: &mut [f64]) {
    let ndof = 3 * n.len();
    for (a, na) in n.iter().enumerate() {
        for (b, nb) in n.iter().enumerate() {
            // `na * nb` first: IEEE products commute, so the matrix comes out
            // bit-for-bit symmetric and CG sees no asymmetry.
            let v = weight * (na * nb);
            for i in 0..3 {
                m[(3 * a + i) * ndof + 3 * b + i] += v;
            }
        }
    }
}

/// Reference volume `Σ det J · w`.
pub fn element_volume(geom: &ElementGeometry) -> f64 {
    geom.jxw.iter().sum()
}

/// Reference positions of the quadrature points, in quadrature order; with
/// `jxw` these integrate error norms against exact solutions.
pub fn qp_positions(geom: &ElementGeometry, x_ref: &[[f64; 3]]) -> Result<Vec<[f64; 3]>, FemError> {
    geom.check()?;
    check_len("x_ref", geom.nodes(), x_ref.len())?;
    Ok((0..geom.n_qp())
        .map(|qp| interpolate_at(geom.qp_n(qp), x_ref))
        .collect())
}

/// `Σ_a N_a(ξ_qp) v_a` for a nodal vector field.
pub fn interpolate(
    geom: &ElementGeometry,
    qp: usize,
    nodal: &[[f64; 3]],
) -> Result<[f64; 3], FemError> {
    geom.check()?;
    geom.check_qp(qp)?;
    check_len("nodal", geom.nodes(), nodal.len())?;
    Ok(interpolate_at(geom.qp_n(qp), nodal))
}

fn interpolate_at(n: &[f64], nodal: &[[f64; 3]]) -> [f64; 3] {
    let mut v = [0.0; 3];
    for (na, xa) in n.iter().zip(nodal) {
        for (vi, xi) in v.iter_mut().zip(xa) {
            *vi += na * xi;
        }
    }
    v
}

#[cfg(test)]
mod mass_tests;
#[cfg(test)]
mod tests;

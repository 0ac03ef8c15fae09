//! Local finite-element kernels for total-Lagrangian solid mechanics.
//!
//! Everything here works on one cell or one facet at a time and writes into
//! caller-provided dense buffers; global assembly, boundary conditions and the
//! Newton loop live elsewhere. Conventions shared by all kernels:
//!
//! - Nodal vectors are node-major: component `i` of node `a` is entry `3a + i`.
//! - Element matrices are row-major `(3n) × (3n)` blocks: entry
//!   `(3a + i) * 3n + (3b + k)` is `∂r_{ai} / ∂u_{bk}`.
//! - Residual sign: `R = f_int − f_ext`, Newton solves `K Δu = −R` with
//!   `K = ∂R/∂u` (see `surface` for how the follower load enters).
//! - The 9×9 material tangent maps the flattened deformation gradient
//!   `(iJ) ↦ 3i + J` (row-major), see `material`.

mod cells;
pub mod element;
pub mod material;
pub mod quadrature;
pub mod shape;
pub mod surface;

pub use cells::{CellType, FacetType, GMSH_HEX20, GMSH_HEX27, GMSH_TET10, GMSH_WEDGE15};
pub use element::{
    body_force, body_force_fn, deformation_gradient, element_volume, internal_force,
    internal_force_and_tangent, interpolate, linear_stiffness, mass_matrix, qp_positions,
    strain_energy, ElementGeometry,
};
pub use material::{Material, MaterialError, Tangent};
pub use quadrature::{Integration, QuadRule};
pub use surface::{dead_traction, facet_area, facet_normal_at_centre, follower_pressure};

use thiserror::Error;

/// Largest node count of any supported cell (hex27). Kernels size their
/// buffers by the cell at hand, never by this, so first-order cells pay for
/// nothing.
pub const MAX_CELL_NODES: usize = 27;

/// Largest node count of any supported facet (quad9). Contact, which handles
/// first-order facets only, has its own `contact::MAX_FACET_NODES`.
pub const MAX_FACET_NODES: usize = 9;

/// Errors of the element and facet kernels.
#[derive(Debug, Clone, PartialEq, Error)]
pub enum FemError {
    /// The reference-to-physical map is not orientation preserving at a
    /// quadrature point (inverted node order or a collapsed cell).
    #[error("inverted element: det J = {det_j:e} at quadrature point {qp}")]
    InvertedElement { qp: usize, det_j: f64 },
    /// A hexahedron whose Jacobian is positive at the Gauss points but not
    /// at a corner node: too distorted to trust, although it integrates.
    #[error("distorted hex8: det J = {det_j:e} at corner node {corner}")]
    InvertedCorner { corner: usize, det_j: f64 },
    /// Invalid material parameters.
    #[error(transparent)]
    Material(#[from] MaterialError),
    /// The constitutive law failed at a quadrature point (typically the
    /// current configuration is inverted there: J ≤ 0). Solvers treat this as
    /// "step too large" and cut back.
    #[error("constitutive update failed at quadrature point {qp}: {source}")]
    Constitutive {
        qp: usize,
        #[source]
        source: MaterialError,
    },
    #[error("{what}: expected length {expected}, got {got}")]
    LengthMismatch {
        what: &'static str,
        expected: usize,
        got: usize,
    },
    #[error("{what} contains a non-finite value")]
    NonFinite { what: &'static str },
    #[error("unsupported quadrature rule: {what} with {n} points per direction")]
    UnsupportedRule { what: &'static str, n: usize },
    /// A quadrature rule whose point and weight lists disagree or are empty.
    #[error("malformed quadrature rule: {points} points, {weights} weights")]
    MalformedRule { points: usize, weights: usize },
    #[error("quadrature point {qp} out of range (element has {n_qp})")]
    QpOutOfRange { qp: usize, n_qp: usize },
    /// A reference density that is negative or not finite. Zero is allowed:
    /// a massless body is quasi-static inside a dynamic run.
    #[error("invalid density {density}: must be finite and ≥ 0")]
    InvalidDensity { density: f64 },
    /// A quadrature rule with fewer points than the cell has nodes makes
    /// the mass matrix singular, and with it the dynamic tangent of a body
    /// with no Dirichlet support.
    #[error(
        "{cell} mass matrix needs at least {needed} quadrature points, the geometry has {n_qp}"
    )]
    UnderintegratedMass {
        cell: &'static str,
        n_qp: usize,
        needed: usize,
    },
    /// A facet with (numerically) zero area has no normal.
    #[error("degenerate {facet} facet: area element {area:e}")]
    DegenerateFacet { facet: &'static str, area: f64 },
}

pub(crate) fn check_len(what: &'static str, expected: usize, got: usize) -> Result<(), FemError> {
    if expected == got {
        Ok(())
    } else {
        Err(FemError::LengthMismatch {
            what,
            expected,
            got,
        })
    }
}

pub(crate) fn check_finite_points(what: &'static str, x: &[[f64; 3]]) -> Result<(), FemError> {
    if x.iter().flatten().all(|v| v.is_finite()) {
        Ok(())
    } else {
        Err(FemError::NonFinite { what })
    }
}

#[cfg(test)]
pub(crate) mod test_util {
    /// Deterministic generator so failures reproduce; quality is irrelevant.
    pub struct Lcg(u64);

    impl Lcg {
        pub fn new(seed: u64) -> Self {
            Lcg(seed.wrapping_mul(6364136223846793005).wrapping_add(1))
        }

        /// Uniform in [-1, 1).
        pub fn next(&mut self) -> f64 {
            self.0 = self
                .0
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            ((self.0 >> 11) as f64 / (1u64 << 53) as f64) * 2.0 - 1.0
        }

        pub fn vec3(&mut self, scale: f64) -> [f64; 3] {
            [
                scale * self.next(),
                scale * self.next(),
                scale * self.next(),
            ]
        }
    }

    /// max |a − b| / max |b|: one number per comparison, robust to the
    /// entries of `b` that are zero by symmetry.
    pub fn rel_err(a: &[f64], b: &[f64]) -> f64 {
        assert_eq!(a.len(), b.len());
        let scale = b.iter().fold(0.0f64, |m, v| m.max(v.abs()));
        let diff = a
            .iter()
            .zip(b)
            .fold(0.0f64, |m, (x, y)| m.max((x - y).abs()));
        diff / scale
    }

    pub fn hex8_unit() -> [[f64; 3]; 8] {
        [
            [0.0, 0.0, 0.0],
            [1.0, 0.0, 0.0],
            [1.0, 1.0, 0.0],
            [0.0, 1.0, 0.0],
            [0.0, 0.0, 1.0],
            [1.0, 0.0, 1.0],
            [1.0, 1.0, 1.0],
            [0.0, 1.0, 1.0],
        ]
    }

    pub fn tet4_unit() -> [[f64; 3]; 4] {
        [
            [0.0, 0.0, 0.0],
            [1.0, 0.0, 0.0],
            [0.0, 1.0, 0.0],
            [0.0, 0.0, 1.0],
        ]
    }

    /// The reference cell of `cell` mapped onto a unit-sized physical cell
    /// (hexahedra: the unit cube; wedges: ζ ↦ (ζ + 1)/2; the others as
    /// they are), every node where the map puts it.
    pub fn unit_cell(cell: super::CellType) -> Vec<[f64; 3]> {
        use super::CellType;
        super::shape::cell_reference_nodes(cell)
            .into_iter()
            .map(|p| match cell.linear() {
                CellType::Hex8 => p.map(|v| 0.5 * (v + 1.0)),
                CellType::Wedge6 => [p[0], p[1], 0.5 * (p[2] + 1.0)],
                _ => p,
            })
            .collect()
    }

    /// A distorted cell: the unit cell's corners moved by up to `amp`, each
    /// higher node at the mean of its moved corners plus its own move of
    /// up to `amp / 2` (curved edges and faces).
    pub fn distorted_cell(cell: super::CellType, seed: u64, amp: f64) -> Vec<[f64; 3]> {
        let mut rng = Lcg::new(seed);
        let mut x = unit_cell(cell);
        let corners = cell.corners();
        perturb(&mut x[..corners], &mut rng, amp);
        for (k, of) in cell.higher_nodes().iter().enumerate() {
            let mut m = [0.0; 3];
            for &a in of.iter() {
                for i in 0..3 {
                    m[i] += x[a][i] / of.len() as f64;
                }
            }
            let d = rng.vec3(0.5 * amp);
            x[corners + k] = [m[0] + d[0], m[1] + d[1], m[2] + d[2]];
        }
        x
    }

    pub fn perturb(x: &mut [[f64; 3]], rng: &mut Lcg, amp: f64) {
        for p in x.iter_mut() {
            let d = rng.vec3(amp);
            for (c, dc) in p.iter_mut().zip(d) {
                *c += dc;
            }
        }
    }
}

#[cfg(test)]
mod tests;

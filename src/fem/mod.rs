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

pub mod element;
pub mod material;
pub mod quadrature;
pub mod shape;
pub mod surface;

pub use element::{
    body_force, body_force_fn, deformation_gradient, element_volume, internal_force,
    internal_force_and_tangent, interpolate, linear_stiffness, mass_matrix, qp_positions,
    strain_energy, ElementGeometry,
};
pub use material::{Material, MaterialError, Tangent};
pub use quadrature::QuadRule;
pub use surface::{dead_traction, facet_area, facet_normal_at_centre, follower_pressure};

use thiserror::Error;

/// Largest node count of any supported cell; sizes the stack buffers of the
/// element kernels so the Newton hot path never allocates.
pub const MAX_CELL_NODES: usize = 8;

/// Largest node count of any supported facet.
pub const MAX_FACET_NODES: usize = 4;

/// Volume cell shapes.
///
/// Node numbering follows VTK (which for these two shapes agrees with
/// Abaqus' C3D8 / C3D4):
///
/// - `Hex8`: reference cube `[-1, 1]³`; nodes 0..3 are the bottom face
///   `ζ = -1` counter-clockwise seen from `+ζ`, starting at `(-1,-1,-1)`;
///   nodes 4..7 are the top face `ζ = +1` in the same order.
/// - `Tet4`: reference simplex, nodes at `(0,0,0)`, `(1,0,0)`, `(0,1,0)`,
///   `(0,0,1)`; a positively oriented cell has
///   `((x1−x0) × (x2−x0)) · (x3−x0) > 0`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum CellType {
    Hex8,
    Tet4,
}

/// Surface facet shapes (boundary faces of the cells).
///
/// - `Quad4`: reference square `[-1, 1]²`, nodes counter-clockwise from
///   `(-1,-1)`.
/// - `Tri3`: reference triangle, nodes at `(0,0)`, `(1,0)`, `(0,1)`.
///
/// The right-hand normal `∂x/∂ξ₁ × ∂x/∂ξ₂` is the orientation of a facet; it
/// has the direction of `(x1−x0) × (x2−x0)` for `Tri3` and of
/// `(x2−x0) × (x3−x1)` for `Quad4`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum FacetType {
    Quad4,
    Tri3,
}

const HEX8_FACES: [&[usize]; 6] = [
    &[0, 4, 7, 3], // ξ = -1
    &[1, 2, 6, 5], // ξ = +1
    &[0, 1, 5, 4], // η = -1
    &[2, 3, 7, 6], // η = +1
    &[0, 3, 2, 1], // ζ = -1
    &[4, 5, 6, 7], // ζ = +1
];

const TET4_FACES: [&[usize]; 4] = [
    &[0, 2, 1], // opposite node 3
    &[0, 1, 3], // opposite node 2
    &[0, 3, 2], // opposite node 1
    &[1, 2, 3], // opposite node 0
];

impl CellType {
    pub const fn nodes(self) -> usize {
        match self {
            CellType::Hex8 => 8,
            CellType::Tet4 => 4,
        }
    }

    pub const fn facet_type(self) -> FacetType {
        match self {
            CellType::Hex8 => FacetType::Quad4,
            CellType::Tet4 => FacetType::Tri3,
        }
    }

    pub const fn name(self) -> &'static str {
        match self {
            CellType::Hex8 => "hex8",
            CellType::Tet4 => "tet4",
        }
    }

    /// Face node lists in local numbering, each ordered so the facet's
    /// right-hand normal (see [`FacetType`]) points out of the cell, which is
    /// what `surface` needs for pressure and what contact needs for gaps.
    ///
    /// - `Hex8`, face index: 0 `ξ=-1`, 1 `ξ=+1`, 2 `η=-1`, 3 `η=+1`,
    ///   4 `ζ=-1`, 5 `ζ=+1`.
    /// - `Tet4`, face `f` is the face opposite node `3 − f`: 0 opposite
    ///   node 3 (`ζ=0`), 1 opposite node 2 (`η=0`), 2 opposite node 1
    ///   (`ξ=0`), 3 opposite node 0 (the slanted face).
    pub const fn local_faces(self) -> &'static [&'static [usize]] {
        match self {
            CellType::Hex8 => &HEX8_FACES,
            CellType::Tet4 => &TET4_FACES,
        }
    }
}

impl FacetType {
    pub const fn nodes(self) -> usize {
        match self {
            FacetType::Quad4 => 4,
            FacetType::Tri3 => 3,
        }
    }

    pub const fn name(self) -> &'static str {
        match self {
            FacetType::Quad4 => "quad4",
            FacetType::Tri3 => "tri3",
        }
    }
}

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
mod tests {
    use super::test_util::{hex8_unit, perturb, tet4_unit, Lcg};
    use super::*;
    use crate::vec3::{cross, dot, sub};

    fn corner_normal(x: &[[f64; 3]]) -> [f64; 3] {
        match x.len() {
            3 => cross(sub(x[1], x[0]), sub(x[2], x[0])),
            _ => cross(sub(x[2], x[0]), sub(x[3], x[1])),
        }
    }

    fn centroid(x: &[[f64; 3]]) -> [f64; 3] {
        let mut c = [0.0; 3];
        for p in x {
            for i in 0..3 {
                c[i] += p[i] / x.len() as f64;
            }
        }
        c
    }

    /// On a convex cell the outward normal of every face points away from the
    /// cell centroid; checked on distorted (still convex) cells so a face
    /// listed in the wrong orientation cannot pass by symmetry.
    fn assert_faces_outward(cell: CellType, x: &[[f64; 3]]) {
        let c = centroid(x);
        for (f, face) in cell.local_faces().iter().enumerate() {
            assert_eq!(face.len(), cell.facet_type().nodes());
            let xf: Vec<[f64; 3]> = face.iter().map(|&a| x[a]).collect();
            let n = corner_normal(&xf);
            let out = sub(centroid(&xf), c);
            assert!(dot(n, out) > 0.0, "{} face {f} points inward", cell.name());
        }
    }

    #[test]
    fn faces_point_outward() {
        let mut rng = Lcg::new(7);
        let mut hex = hex8_unit();
        perturb(&mut hex, &mut rng, 0.1);
        assert_faces_outward(CellType::Hex8, &hex);
        let mut tet = tet4_unit();
        perturb(&mut tet, &mut rng, 0.1);
        assert_faces_outward(CellType::Tet4, &tet);
    }

    #[test]
    fn faces_cover_each_node_consistently() {
        // Every hex node lies on exactly 3 faces, every tet node on 3 faces,
        // and the tet face f must not contain node 3 - f.
        for cell in [CellType::Hex8, CellType::Tet4] {
            let mut count = vec![0; cell.nodes()];
            for face in cell.local_faces() {
                for &a in face.iter() {
                    count[a] += 1;
                }
            }
            assert!(count.iter().all(|&c| c == 3), "{}: {count:?}", cell.name());
        }
        for (f, face) in CellType::Tet4.local_faces().iter().enumerate() {
            assert!(!face.contains(&(3 - f)));
        }
    }

    #[test]
    fn hex_face_order_matches_reference_coordinates() {
        use super::shape::HEX8_REF_NODES;
        // (axis, sign) of face f: 0 ξ-, 1 ξ+, 2 η-, 3 η+, 4 ζ-, 5 ζ+.
        for (f, face) in CellType::Hex8.local_faces().iter().enumerate() {
            let axis = f / 2;
            let sign = if f % 2 == 0 { -1.0 } else { 1.0 };
            for &a in face.iter() {
                assert_eq!(HEX8_REF_NODES[a][axis], sign, "face {f} node {a}");
            }
        }
    }

    #[test]
    fn names_and_counts() {
        assert_eq!(CellType::Hex8.name(), "hex8");
        assert_eq!(CellType::Tet4.name(), "tet4");
        assert_eq!(FacetType::Quad4.name(), "quad4");
        assert_eq!(FacetType::Tri3.name(), "tri3");
        assert_eq!(CellType::Hex8.facet_type(), FacetType::Quad4);
        assert_eq!(CellType::Tet4.facet_type(), FacetType::Tri3);
        assert_eq!(CellType::Hex8.nodes(), 8);
        assert_eq!(FacetType::Tri3.nodes(), 3);
    }
}

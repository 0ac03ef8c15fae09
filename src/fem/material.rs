//! Constitutive laws in total-Lagrangian form: deformation gradient `F` in,
//! first Piola–Kirchhoff stress `P` and material tangent `A = ∂P/∂F` out.
//!
//! Tangent index convention: `A[(3i + J, 3k + L)] = ∂P_{iJ} / ∂F_{kL}`, i.e.
//! both `P` and `F` are flattened row-major (lower-case index = spatial row,
//! upper-case index = material column).

use nalgebra::{Matrix3, SMatrix};
use thiserror::Error;

/// The 9×9 material tangent `∂P/∂F`, indexed `(3i + J, 3k + L)`.
pub type Tangent = SMatrix<f64, 9, 9>;

#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Material {
    /// Small-strain Hooke's law, `P = σ(ε)` with `ε = sym(F − I)`. Not
    /// frame-indifferent: only for small rotations.
    LinearElastic { youngs: f64, poisson: f64 },
    /// Compressible Neo-Hookean,
    /// `W = μ/2 (I₁ − 3) − μ ln J + λ/2 (ln J)²`.
    NeoHookean { youngs: f64, poisson: f64 },
}

#[derive(Debug, Clone, Copy, PartialEq, Error)]
pub enum MaterialError {
    #[error("Young's modulus must be positive and finite, got {youngs}")]
    InvalidYoungs { youngs: f64 },
    #[error("Poisson's ratio must lie in (-1, 0.5), got {poisson}")]
    InvalidPoisson { poisson: f64 },
    /// The deformation is inverted or collapsed where the law needs `ln J`.
    #[error("deformation gradient has det F = {det_f:e} <= 0")]
    NonPositiveJacobian { det_f: f64 },
    #[error("deformation gradient contains a non-finite entry")]
    NonFiniteDeformation,
}

impl Material {
    pub fn youngs(&self) -> f64 {
        match *self {
            Material::LinearElastic { youngs, .. } | Material::NeoHookean { youngs, .. } => youngs,
        }
    }

    pub fn poisson(&self) -> f64 {
        match *self {
            Material::LinearElastic { poisson, .. } | Material::NeoHookean { poisson, .. } => {
                poisson
            }
        }
    }

    /// E > 0 and finite, −1 < ν < 0.5 (ν = 0.5 makes λ infinite; these
    /// displacement-only elements have no incompressible formulation).
    pub fn validate(&self) -> Result<(), MaterialError> {
        let (youngs, poisson) = (self.youngs(), self.poisson());
        if !(youngs.is_finite() && youngs > 0.0) {
            return Err(MaterialError::InvalidYoungs { youngs });
        }
        if !(poisson.is_finite() && poisson > -1.0 && poisson < 0.5) {
            return Err(MaterialError::InvalidPoisson { poisson });
        }
        Ok(())
    }

    /// Lamé parameters `(λ, μ)`.
    pub fn lame(&self) -> (f64, f64) {
        let (e, nu) = (self.youngs(), self.poisson());
        let lambda = e * nu / ((1.0 + nu) * (1.0 - 2.0 * nu));
        let mu = e / (2.0 * (1.0 + nu));
        (lambda, mu)
    }

    /// True when the tangent is independent of the deformation, so a solver
    /// may assemble the stiffness once and reuse it.
    pub fn is_linear(&self) -> bool {
        matches!(self, Material::LinearElastic { .. })
    }

    /// Whether `A_{iJkL} = A_{kLiJ}`. Every law here derives from a stored
    /// energy, so the element kernels may build half the stiffness and
    /// mirror it; a new non-potential law must answer false here.
    pub fn tangent_is_symmetric(&self) -> bool {
        match self {
            Material::LinearElastic { .. } | Material::NeoHookean { .. } => true,
        }
    }

    /// Stored energy density per reference volume.
    pub fn strain_energy(&self, f: &Matrix3<f64>) -> Result<f64, MaterialError> {
        self.validate()?;
        check_finite(f)?;
        self.strain_energy_unchecked(f)
    }

    /// First Piola–Kirchhoff stress `P`.
    pub fn first_piola(&self, f: &Matrix3<f64>) -> Result<Matrix3<f64>, MaterialError> {
        self.validate()?;
        check_finite(f)?;
        self.first_piola_unchecked(f)
    }

    /// First Piola–Kirchhoff stress and the tangent `A = ∂P/∂F`.
    pub fn first_piola_and_tangent(
        &self,
        f: &Matrix3<f64>,
    ) -> Result<(Matrix3<f64>, Tangent), MaterialError> {
        self.validate()?;
        check_finite(f)?;
        self.first_piola_and_tangent_unchecked(f)
    }

    /// Cauchy stress `σ = P Fᵀ / J`. For `LinearElastic` this is `σ(ε)`
    /// itself: small-strain theory does not tell the stress measures apart.
    pub fn cauchy_stress(&self, f: &Matrix3<f64>) -> Result<Matrix3<f64>, MaterialError> {
        self.validate()?;
        check_finite(f)?;
        match *self {
            Material::LinearElastic { .. } => self.first_piola_unchecked(f),
            Material::NeoHookean { .. } => {
                let (lambda, mu) = self.lame();
                let (det_f, ln_j) = log_det(f)?;
                let b = f * f.transpose();
                Ok(
                    (mu * (b - Matrix3::identity())
                        + Matrix3::from_diagonal_element(lambda * ln_j))
                        / det_f,
                )
            }
        }
    }

    // The element kernels validate once per element and then call these at
    // every quadrature point.

    pub(crate) fn strain_energy_unchecked(&self, f: &Matrix3<f64>) -> Result<f64, MaterialError> {
        let (lambda, mu) = self.lame();
        match self {
            Material::LinearElastic { .. } => {
                let eps = small_strain(f);
                Ok(0.5 * lambda * eps.trace().powi(2) + mu * eps.component_mul(&eps).sum())
            }
            Material::NeoHookean { .. } => {
                let (_, ln_j) = log_det(f)?;
                let i1 = f.component_mul(f).sum();
                Ok(0.5 * mu * (i1 - 3.0) - mu * ln_j + 0.5 * lambda * ln_j * ln_j)
            }
        }
    }

    pub(crate) fn first_piola_unchecked(
        &self,
        f: &Matrix3<f64>,
    ) -> Result<Matrix3<f64>, MaterialError> {
        let (lambda, mu) = self.lame();
        match self {
            Material::LinearElastic { .. } => Ok(hooke(lambda, mu, &small_strain(f))),
            Material::NeoHookean { .. } => {
                let (_, ln_j) = log_det(f)?;
                let f_inv_t = inverse_transpose(f)?;
                Ok(mu * (f - f_inv_t) + lambda * ln_j * f_inv_t)
            }
        }
    }

    pub(crate) fn first_piola_and_tangent_unchecked(
        &self,
        f: &Matrix3<f64>,
    ) -> Result<(Matrix3<f64>, Tangent), MaterialError> {
        let (lambda, mu) = self.lame();
        match self {
            Material::LinearElastic { .. } => Ok((
                hooke(lambda, mu, &small_strain(f)),
                linear_tangent(lambda, mu),
            )),
            Material::NeoHookean { .. } => {
                let (_, ln_j) = log_det(f)?;
                let h = inverse_transpose(f)?;
                let p = mu * (f - h) + lambda * ln_j * h;
                Ok((p, neo_hookean_tangent(lambda, mu, ln_j, &h)))
            }
        }
    }
}

fn check_finite(f: &Matrix3<f64>) -> Result<(), MaterialError> {
    if f.iter().all(|v| v.is_finite()) {
        Ok(())
    } else {
        Err(MaterialError::NonFiniteDeformation)
    }
}

/// `(J, ln J)`, refusing `J ≤ 0` so no NaN ever leaves the law.
fn log_det(f: &Matrix3<f64>) -> Result<(f64, f64), MaterialError> {
    let det_f = f.determinant();
    if det_f > 0.0 && det_f.is_finite() {
        Ok((det_f, det_f.ln()))
    } else {
        Err(MaterialError::NonPositiveJacobian { det_f })
    }
}

fn inverse_transpose(f: &Matrix3<f64>) -> Result<Matrix3<f64>, MaterialError> {
    f.try_inverse()
        .map(|inv| inv.transpose())
        .ok_or(MaterialError::NonPositiveJacobian {
            det_f: f.determinant(),
        })
}

fn small_strain(f: &Matrix3<f64>) -> Matrix3<f64> {
    let grad_u = f - Matrix3::identity();
    0.5 * (grad_u + grad_u.transpose())
}

fn hooke(lambda: f64, mu: f64, eps: &Matrix3<f64>) -> Matrix3<f64> {
    Matrix3::from_diagonal_element(lambda * eps.trace()) + 2.0 * mu * eps
}

/// `λ δ_iJ δ_kL + μ (δ_ik δ_JL + δ_iL δ_Jk)`: the derivative of `σ(sym(F−I))`.
fn linear_tangent(lambda: f64, mu: f64) -> Tangent {
    Tangent::from_fn(|row, col| {
        let (i, j) = (row / 3, row % 3);
        let (k, l) = (col / 3, col % 3);
        lambda * delta(i, j) * delta(k, l)
            + mu * (delta(i, k) * delta(j, l) + delta(i, l) * delta(j, k))
    })
}

/// With `H = F⁻ᵀ`, `∂H_iJ/∂F_kL = −H_iL H_kJ` and `∂ln J/∂F_kL = H_kL`, so
/// `A = μ δ_ik δ_JL + (μ − λ ln J) H_iL H_kJ + λ H_iJ H_kL`.
fn neo_hookean_tangent(lambda: f64, mu: f64, ln_j: f64, h: &Matrix3<f64>) -> Tangent {
    let c = mu - lambda * ln_j;
    Tangent::from_fn(|row, col| {
        let (i, j) = (row / 3, row % 3);
        let (k, l) = (col / 3, col % 3);
        mu * delta(i, k) * delta(j, l)
            + c * (h[(i, l)] * h[(k, j)])
            + lambda * (h[(i, j)] * h[(k, l)])
    })
}

fn delta(a: usize, b: usize) -> f64 {
    if a == b {
        1.0
    } else {
        0.0
    }
}

#[cfg(test)]
mod tests {
    use super::super::test_util::{rel_err, Lcg};
    use super::*;

    const H: f64 = 1e-6;

    fn materials() -> [Material; 2] {
        [
            Material::LinearElastic {
                youngs: 210.0,
                poisson: 0.3,
            },
            Material::NeoHookean {
                youngs: 210.0,
                poisson: 0.3,
            },
        ]
    }

    /// A generic (non-symmetric, rotated, sheared) F scaled to det F = 1.3.
    fn random_f(seed: u64) -> Matrix3<f64> {
        let mut rng = Lcg::new(seed);
        let f = Matrix3::identity() + Matrix3::from_fn(|_, _| 0.3 * rng.next());
        let det = f.determinant();
        assert!(det > 0.0);
        f * (1.3 / det).cbrt()
    }

    fn flat(m: &Matrix3<f64>) -> [f64; 9] {
        std::array::from_fn(|r| m[(r / 3, r % 3)])
    }

    fn fd_tangent(mat: &Material, f: &Matrix3<f64>) -> Tangent {
        let mut a = Tangent::zeros();
        for col in 0..9 {
            let (k, l) = (col / 3, col % 3);
            let (mut fp, mut fm) = (*f, *f);
            fp[(k, l)] += H;
            fm[(k, l)] -= H;
            let dp = (mat.first_piola(&fp).unwrap() - mat.first_piola(&fm).unwrap()) / (2.0 * H);
            for row in 0..9 {
                a[(row, col)] = dp[(row / 3, row % 3)];
            }
        }
        a
    }

    fn fd_stress(mat: &Material, f: &Matrix3<f64>) -> Matrix3<f64> {
        Matrix3::from_fn(|k, l| {
            let (mut fp, mut fm) = (*f, *f);
            fp[(k, l)] += H;
            fm[(k, l)] -= H;
            (mat.strain_energy(&fp).unwrap() - mat.strain_energy(&fm).unwrap()) / (2.0 * H)
        })
    }

    #[test]
    fn tangent_matches_finite_differences() {
        for mat in materials() {
            for seed in 1..6 {
                let f = random_f(seed);
                assert!((f.determinant() - 1.3).abs() < 1e-12);
                let (p, a) = mat.first_piola_and_tangent(&f).unwrap();
                assert_eq!(p, mat.first_piola(&f).unwrap());
                let err = rel_err(a.as_slice(), fd_tangent(&mat, &f).as_slice());
                println!("material tangent FD {mat:?} seed {seed}: {err:.2e}");
                assert!(err < 1e-6, "{mat:?}: {err:e}");
            }
        }
    }

    #[test]
    fn stress_matches_energy_finite_differences() {
        for mat in materials() {
            for seed in 1..6 {
                let f = random_f(seed);
                let p = mat.first_piola(&f).unwrap();
                let err = rel_err(&flat(&p), &flat(&fd_stress(&mat, &f)));
                println!("stress-vs-energy FD {mat:?} seed {seed}: {err:.2e}");
                assert!(err < 1e-6, "{mat:?}: {err:e}");
            }
        }
    }

    #[test]
    fn tangent_has_major_symmetry() {
        for mat in materials() {
            let (_, a) = mat.first_piola_and_tangent(&random_f(9)).unwrap();
            assert!(mat.tangent_is_symmetric());
            assert!((a - a.transpose()).abs().max() < 1e-14 * a.abs().max());
        }
    }

    #[test]
    fn neo_hookean_reduces_to_linear_at_small_strain() {
        let [lin, nh] = materials();
        let mut rng = Lcg::new(11);
        let g = Matrix3::from_fn(|_, _| rng.next());
        let gap = |s: f64| {
            let f = Matrix3::identity() + s * g;
            let d = nh.first_piola(&f).unwrap() - lin.first_piola(&f).unwrap();
            d.abs().max()
        };
        let (e1, e2) = (gap(1e-3), gap(5e-4));
        // Stress itself is O(E·s) = O(0.2); the difference must be O(E·s²).
        assert!(e1 < 10.0 * 210.0 * 1e-6, "difference {e1:e} not O(strain²)");
        let ratio = e1 / e2;
        assert!(
            (ratio - 4.0).abs() < 0.1,
            "halving strain gave ratio {ratio}"
        );
        let (_, a_nh) = nh.first_piola_and_tangent(&Matrix3::identity()).unwrap();
        let (_, a_lin) = lin.first_piola_and_tangent(&Matrix3::identity()).unwrap();
        assert!((a_nh - a_lin).abs().max() < 1e-12);
    }

    #[test]
    fn rotation_gives_zero_neo_hookean_stress() {
        let [_, nh] = materials();
        let r = nalgebra::Rotation3::from_euler_angles(0.7, -1.1, 2.3).into_inner();
        assert!(nh.first_piola(&r).unwrap().abs().max() < 1e-12);
        assert!(nh.cauchy_stress(&r).unwrap().abs().max() < 1e-12);
    }

    #[test]
    fn cauchy_stress_is_push_forward_of_piola() {
        let [_, nh] = materials();
        let f = random_f(3);
        let sigma = nh.cauchy_stress(&f).unwrap();
        let from_p = nh.first_piola(&f).unwrap() * f.transpose() / f.determinant();
        assert!((sigma - from_p).abs().max() < 1e-10);
        assert!((sigma - sigma.transpose()).abs().max() < 1e-10);
    }

    #[test]
    fn inverted_deformation_is_an_error_not_nan() {
        let [lin, nh] = materials();
        let f = Matrix3::from_diagonal(&nalgebra::Vector3::new(-1.0, 1.0, 1.0));
        for result in [
            nh.first_piola(&f).map(|_| ()),
            nh.first_piola_and_tangent(&f).map(|_| ()),
            nh.strain_energy(&f).map(|_| ()),
            nh.cauchy_stress(&f).map(|_| ()),
        ] {
            assert_eq!(
                result,
                Err(MaterialError::NonPositiveJacobian { det_f: -1.0 })
            );
        }
        assert!(nh.first_piola(&Matrix3::zeros()).is_err());
        // Small strain has no ln J: an inverted F is merely a large strain.
        assert!(lin.first_piola(&f).is_ok());
        let nan = Matrix3::from_element(f64::NAN);
        assert_eq!(
            lin.first_piola(&nan),
            Err(MaterialError::NonFiniteDeformation)
        );
    }

    #[test]
    fn validation_names_the_bad_value() {
        let bad_e = Material::NeoHookean {
            youngs: -5.0,
            poisson: 0.3,
        };
        assert_eq!(
            bad_e.validate(),
            Err(MaterialError::InvalidYoungs { youngs: -5.0 })
        );
        assert!(bad_e.validate().unwrap_err().to_string().contains("-5"));
        for nu in [0.5, -1.0, 0.7, f64::NAN] {
            let m = Material::LinearElastic {
                youngs: 1.0,
                poisson: nu,
            };
            assert!(matches!(
                m.validate(),
                Err(MaterialError::InvalidPoisson { .. })
            ));
        }
        let inf = Material::LinearElastic {
            youngs: f64::INFINITY,
            poisson: 0.2,
        };
        assert!(inf.validate().is_err());
        assert!(inf.first_piola(&Matrix3::identity()).is_err());
        assert!(materials().iter().all(|m| m.validate().is_ok()));
    }

    #[test]
    fn lame_parameters() {
        let m = Material::LinearElastic {
            youngs: 260.0,
            poisson: 0.3,
        };
        let (lambda, mu) = m.lame();
        assert!((mu - 100.0).abs() < 1e-12);
        assert!((lambda - 150.0).abs() < 1e-12);
        assert!(m.is_linear());
        assert!(!materials()[1].is_linear());
    }
}

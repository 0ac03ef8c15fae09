//! Implicit dynamics as a scene states it: the time step, the Newmark-β
//! parameters, densities and initial velocities. The scheme itself (the
//! affine maps `a(u)`, `v(u)` and their properties) is `solve::newmark`.

/// What a scene says about dynamics.
#[derive(Debug, Clone)]
pub struct DynamicsSpec {
    pub time_step: f64,
    pub newmark: Newmark,
    /// Mass density of each body (indexed like `mesh.bodies`).
    pub density: Vec<f64>,
    /// Initial velocity of each body.
    pub initial_velocity: Vec<[f64; 3]>,
}

/// Newmark-β in displacement form.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Newmark {
    pub beta: f64,
    pub gamma: f64,
}

impl Newmark {
    /// `β = ¼, γ = ½`: the average-acceleration (trapezoidal) rule.
    pub fn trapezoidal() -> Self {
        Newmark {
            beta: 0.25,
            gamma: 0.5,
        }
    }

    /// `β = (γ + ½)² / 4`: for a given `γ > ½` the choice that maximises
    /// high-frequency damping while staying unconditionally stable (it is
    /// `2β ≥ γ` with equality only at `γ = ½`).
    pub fn with_dissipation(gamma: f64) -> Self {
        Newmark {
            beta: (gamma + 0.5).powi(2) / 4.0,
            gamma,
        }
    }

    /// Accepts only the unconditionally stable range `2β ≥ γ ≥ ½`,
    /// `0 < β ≤ ½`: an implicit contact solve takes steps far beyond any
    /// explicit stability limit, and `β = 0` (explicit) has no displacement
    /// form at all since `a(u)` carries `1/β`.
    pub fn validate(&self) -> Result<(), String> {
        let Newmark { beta, gamma } = *self;
        if !beta.is_finite() || beta <= 0.0 || beta > 0.5 {
            return Err(format!("Newmark beta = {beta}: must be in (0, 1/2]"));
        }
        if !gamma.is_finite() || gamma < 0.5 {
            return Err(format!(
                "Newmark gamma = {gamma}: must be finite and >= 1/2"
            ));
        }
        // A few ulps of slack: `with_dissipation(γ)` has 2β − γ = (γ − ½)²/2,
        // which rounding can push just below zero for γ within 1e-8 of ½.
        if 2.0 * beta - gamma < -4.0 * f64::EPSILON {
            return Err(format!(
                "Newmark beta = {beta}, gamma = {gamma}: beta must be >= gamma/2 for \
                 unconditional stability"
            ));
        }
        Ok(())
    }

    /// Rejects time steps that would make the coefficients non-finite.
    pub fn validate_dt(dt: f64) -> Result<(), String> {
        if dt.is_finite() && dt > 0.0 {
            Ok(())
        } else {
            Err(format!("time step dt = {dt}: must be finite and > 0"))
        }
    }
}

//! The linear solves' floor of a Newton solve: a test after the KSP's own
//! that stops a linear solve once it has removed what the Newton solve
//! still needs.
use crate::petsc::{LinearTest, Newton, Result, Snes};

/// The floor's state: its fraction and the linear solve's first residual
/// norm.
struct LinearFloor {
    fraction: f64,
    rnorm0: f64,
}

/// Stops each linear solve of a Newton iteration of `snes` once its
/// residual has fallen to `fraction` of what that Newton solve still has
/// to remove, i.e. below `fraction` · max(atol, rtol·|R0|) / |R_k| of its
/// start, whatever looser or tighter tolerance the linear solver had: the
/// last Newton iteration of a solve needs only the reduction left, not the
/// one the forcing sequence asks for. Keeps the KSP's own test (and the
/// Eisenstat–Walker tolerances it is given). 0: no floor. Collective;
/// after `Snes::set_from_options`.
pub fn set_linear_floor(snes: &mut Snes, fraction: f64) -> Result<()> {
    if let Some(f) = snes.linear_test_mut::<LinearFloor>() {
        f.fraction = fraction;
        return Ok(());
    }
    snes.add_linear_test(LinearFloor {
        fraction,
        rnorm0: 0.0,
    })
}

impl LinearTest for LinearFloor {
    fn converged(&mut self, iteration: usize, rnorm: f64, decided: bool, newton: &Newton) -> bool {
        if iteration == 0 {
            self.rnorm0 = rnorm;
            return false;
        }
        if self.fraction <= 0.0 || decided {
            return false;
        }
        let Some(p) = newton.progress() else {
            return false;
        };
        if p.function_norm.is_nan() || p.function_norm <= 0.0 {
            return false;
        }
        let target = p.atol.max(p.rtol * p.first_norm);
        rnorm <= self.fraction * (target / p.function_norm) * self.rnorm0
    }
}

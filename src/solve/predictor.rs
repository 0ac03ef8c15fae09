//! The initial guess of a load step: the last converged state, or (the
//! `extrapolate` setting) the last two extrapolated linearly in the load
//! factor.
use crate::error::Result;
use crate::petsc::Vector;

/// The converged states a load step's initial guess is made from.
pub(super) struct Predictor {
    /// The converged state before the last one, and its load factor
    /// (None: no extrapolation).
    older: Option<(Vector, f64)>,
}

impl Predictor {
    pub(super) fn new(like: &Vector, enabled: bool) -> Result<Self> {
        let older = if enabled {
            Some((like.duplicate()?, f64::NAN))
        } else {
            None
        };
        Ok(Predictor { older })
    }

    /// x ← x + (to − from)/(from − f_older)·(x − x_older), once two converged
    /// states exist (a step cut back retries with a shorter extrapolation).
    pub(super) fn extrapolate(&self, x: &mut Vector, from: f64, to: f64) -> Result<()> {
        let Some((older, f_older)) = &self.older else {
            return Ok(());
        };
        let span = from - f_older;
        if span.is_nan() || span <= 0.0 {
            return Ok(());
        }
        // x + r (x − x_older) = (1 + r) x − r x_older, without a work vector.
        let ratio = (to - from) / span;
        x.scale(1.0 + ratio)?;
        x.axpy(-ratio, older)?;
        Ok(())
    }

    /// A step from `x_start` (converged at load `f_start`) has converged.
    pub(super) fn accept(&mut self, x_start: &Vector, f_start: f64) -> Result<()> {
        if let Some((older, f_older)) = self.older.as_mut() {
            older.copy_from(x_start)?;
            *f_older = f_start;
        }
        Ok(())
    }
}

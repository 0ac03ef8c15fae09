//! A condensed Newton load step's life, the same on both Schur paths.
use crate::petsc::{Result, Vector};

/// A condensed Newton load step's life, on either path (`schur::newton`
/// and `low_rank::newton`): its start x0 from `arm` until the step
/// ends, and the path's `S` from the step's first linear solve on.
pub struct Armed<S> {
    pub(super) x0: Option<Vector>,
    pub(super) step: Option<S>,
}

impl<S> Default for Armed<S> {
    fn default() -> Self {
        Armed {
            x0: None,
            step: None,
        }
    }
}

impl<S> Armed<S> {
    /// A step starts at `x0`: the next linear solve is a whole one.
    pub fn arm(&mut self, x0: &Vector) -> Result<()> {
        let mut copy = x0.duplicate()?;
        copy.copy_from(x0)?;
        self.x0 = Some(copy);
        self.step = None;
        Ok(())
    }

    /// The step ended without `expand` (failed, or cut back).
    pub fn disarm(&mut self) {
        self.x0 = None;
        self.step = None;
    }

    /// Armed, before the step's first linear solve.
    pub fn awaits_first_solve(&self) -> bool {
        self.x0.is_some() && self.step.is_none()
    }

    /// The SNES vector is the condensed one.
    pub fn is_active(&self) -> bool {
        self.step.is_some()
    }

    /// Before the first condensed residual: x0, when the step's state
    /// still `needs` the contact residual there.
    pub fn base_wanted(&self, needs: impl Fn(&S) -> bool) -> Option<&Vector> {
        match &self.step {
            Some(s) if needs(s) => self.x0.as_ref(),
            _ => None,
        }
    }
}

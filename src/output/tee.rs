//! Chaining step sinks.

use crate::error::Result;
use crate::petsc::Vector;
use crate::solve::{PairFields, StepReport, StepSink};

/// Two sinks in a row.
pub struct Tee<'a, A: StepSink>(pub A, pub &'a mut dyn StepSink);

impl<A: StepSink> StepSink for Tee<'_, A> {
    fn step(
        &mut self,
        report: &StepReport,
        u: &Vector,
        r: &Vector,
        contact: &[PairFields],
        nodal: &[f64],
        velocity: Option<&Vector>,
    ) -> Result<()> {
        self.0.step(report, u, r, contact, nodal, velocity)?;
        self.1.step(report, u, r, contact, nodal, velocity)
    }
}

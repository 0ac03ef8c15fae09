//! The Uzawa update of the links' multipliers, and what the Uzawa loop and
//! a failure report read of them.
use super::multipliers::PointState;
use super::LinksPair;
use crate::contact::autodiff::{norm, sub};
use crate::contact::formulation::{At, Census};
use crate::contact::outcome::UzawaStats;
use crate::contact::penalty::contact_pressure;
use crate::error::{Error, Result};

impl LinksPair {
    /// The Uzawa update λN ← ⟨λN − εN gN⟩ (and, with friction, λT ← tT) at
    /// every slave point of this rank (points without a link get λ = 0),
    /// then the halo exchange.
    pub(super) fn update(&mut self, at: &At) -> Result<UzawaStats> {
        let before = self.multipliers.nodal_forces()?;
        let before_t = self.multipliers.nodal_tangential_forces()?;
        let states = self.evaluate_links(at);
        let mut new_lambda = vec![0.0; self.slave.num_qps()];
        let mut stats = UzawaStats::default();
        for (l, s) in self.links.iter().zip(&states) {
            let q = l.qp_index();
            let facet = q / self.slave.nqp;
            new_lambda[q] =
                contact_pressure(self.multipliers.lambda[q], self.facet_penalty[facet], s.gap);
            stats.max_penetration = stats
                .max_penetration
                .max(-s.gap / self.slave.facets[facet].h);
            if new_lambda[q] > 0.0 {
                stats.active += 1;
            }
        }
        stats.max_multiplier = new_lambda.iter().copied().fold(0.0, f64::max);
        self.multipliers.lambda = new_lambda;
        stats.sliding = self.update_friction(&states, at.factor);
        self.multipliers.exchange()?;
        let after = self.multipliers.nodal_forces()?;
        for (b, a) in before.iter().zip(&after) {
            stats.max_change = stats.max_change.max((a - b).abs());
            stats.max_force = stats.max_force.max(a.abs());
        }
        let after_t = self.multipliers.nodal_tangential_forces()?;
        for (b, a) in before_t.iter().zip(&after_t) {
            stats.max_change = stats.max_change.max(norm(&sub(a, b)));
        }
        Ok(stats)
    }

    /// The links at `at` as they stand: pressed together (gap < 0 or
    /// λN > 0), sliding at the last update, and the deepest penetration.
    pub(super) fn link_census(&mut self, at: &At) -> Census {
        let states = self.evaluate_links(at);
        let mut gap = vec![self.search_distance; self.slave.num_qps()];
        for (l, s) in self.links.iter().zip(&states) {
            gap[l.qp_index()] = s.gap;
        }
        let pressed = gap
            .iter()
            .zip(&self.multipliers.lambda)
            .filter(|(g, l)| **g < 0.0 || **l > 0.0)
            .count();
        let sliding = self.multipliers.tangential.as_ref().map_or(0, |t| {
            t.points
                .iter()
                .filter(|p| p.state == PointState::Slip)
                .count()
        });
        Census {
            pressed,
            sliding,
            max_penetration: gap.iter().fold(0.0f64, |m, g| m.max(-g)),
        }
    }

    /// Replaces λN of every owned point (the values `normal_multipliers`
    /// gave, same length, non-negative), then refreshes the ghosts.
    pub(super) fn set_lambda(&mut self, lambda: &[f64]) -> Result<()> {
        if lambda.len() != self.multipliers.lambda.len() {
            return Err(Error::Internal(format!(
                "accelerated multipliers: {} values for {} points",
                lambda.len(),
                self.multipliers.lambda.len()
            )));
        }
        self.multipliers.lambda.copy_from_slice(lambda);
        self.multipliers.exchange()
    }

    /// This rank's points in contact (λN > 0) and, of those, sliding.
    pub(super) fn states(&self) -> (usize, usize) {
        let active = self.multipliers.lambda.iter().filter(|l| **l > 0.0).count();
        let sliding = self.multipliers.tangential.as_ref().map_or(0, |t| {
            t.points
                .iter()
                .filter(|p| p.state == PointState::Slip)
                .count()
        });
        (active, sliding)
    }
}

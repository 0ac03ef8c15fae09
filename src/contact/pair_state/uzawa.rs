//! The Uzawa update of a pair's multipliers, and its penalty.
use super::ContactPair;
use crate::contact::autodiff::{norm, sub};
use crate::contact::multipliers::{updated_multiplier, PointState};
use crate::contact::outcome::UzawaStats;
use crate::error::Result;

impl ContactPair {
    /// The Uzawa update λN ← ⟨λN − εN gN⟩ (and, with friction, λT ← tT) at
    /// every slave point of this rank (points without a link get λ = 0),
    /// then the halo exchange.
    pub fn uzawa_update(&mut self, u_local: &[f64], factor: f64) -> Result<UzawaStats> {
        if let Some(m) = &mut self.mortar {
            let rate = self.rate.as_ref().map(super::output::mortar_rate);
            return Ok(m.uzawa_update(u_local, rate.as_ref(), factor));
        }
        let before = self.multipliers.nodal_forces()?;
        let before_t = self.multipliers.nodal_tangential_forces()?;
        let states = self.evaluate_links(u_local, factor);
        let mut new_lambda = vec![0.0; self.slave.num_qps()];
        let mut stats = UzawaStats::default();
        for (l, s) in self.links.iter().zip(&states) {
            let q = l.qp_index();
            let facet = q / self.slave.nqp;
            new_lambda[q] =
                updated_multiplier(self.multipliers.lambda[q], self.facet_penalty[facet], s.gap);
            stats.max_penetration = stats
                .max_penetration
                .max(-s.gap / self.slave.facets[facet].h);
            if new_lambda[q] > 0.0 {
                stats.active += 1;
            }
        }
        stats.max_multiplier = new_lambda.iter().copied().fold(0.0, f64::max);
        self.multipliers.lambda = new_lambda;
        stats.sliding = self.update_friction(&states, factor);
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

    /// A mortar pair's nodes at `u_local` as its Uzawa update would find
    /// them (pressed, sliding, deepest mean penetration relative to h),
    /// nothing changed; None for a links pair.
    pub fn mortar_census(&self, u_local: &[f64], factor: f64) -> Option<UzawaStats> {
        let m = self.mortar.as_ref()?;
        Some(m.census(u_local, self.mortar_rate().as_ref(), factor))
    }

    /// A mortar pair's nodes that change between open and closed on the
    /// way from `u0` to `u1`: the fraction of the way at which the last of
    /// them changes (the mortar pair's `state_change_fraction`); None for a
    /// links pair or none changing.
    pub fn state_change_fraction(&self, u0: &[f64], u1: &[f64], factor: f64) -> Option<f64> {
        let m = self.mortar.as_ref()?;
        m.state_change_fraction(u0, u1, self.mortar_rate().as_ref(), factor)
    }

    /// Multiplies the normal penalty by `factor`, and the tangential one
    /// when it follows the normal one (no `tangential_penalty` given). The
    /// multipliers are kept: the augmented Lagrangian converges to the same
    /// solution for any penalty, only faster for a larger one.
    pub fn raise_penalty(&mut self, factor: f64) {
        self.penalty *= factor;
        self.facet_penalty.iter_mut().for_each(|p| *p *= factor);
        if let Some(m) = &mut self.mortar {
            m.raise_penalty(factor);
        }
        let follows = self
            .spec
            .active_friction()
            .is_some_and(|f| f.penalty.is_none());
        if let (true, Some(f)) = (follows, &mut self.friction) {
            f.penalty.iter_mut().for_each(|p| *p *= factor);
        }
    }

    /// The normal multipliers an accelerated Uzawa update works on (see
    /// `solve::anderson`): λN of every point (links: the owned points) or
    /// node (mortar: every node this rank updates) and whether it is owned
    /// here (enters global sums); None with friction, whose update also
    /// classifies stick and slip from the solved state.
    pub fn normal_multipliers(&self) -> Option<(Vec<f64>, Vec<bool>)> {
        if self.has_friction() {
            return None;
        }
        if let Some(m) = &self.mortar {
            return Some(m.normal_multipliers());
        }
        let lambda = self.multipliers.lambda.clone();
        let owned = vec![true; lambda.len()];
        Some((lambda, owned))
    }

    /// Replaces the normal multipliers `normal_multipliers` gave (same
    /// length, non-negative), then refreshes the ghosts.
    pub fn set_normal_multipliers(&mut self, lambda: &[f64]) -> Result<()> {
        if let Some(m) = &mut self.mortar {
            m.set_normal_multipliers(lambda);
            return Ok(());
        }
        if lambda.len() != self.multipliers.lambda.len() {
            return Err(crate::error::Error::Internal(format!(
                "accelerated multipliers: {} values for {} points",
                lambda.len(),
                self.multipliers.lambda.len()
            )));
        }
        self.multipliers.lambda.copy_from_slice(lambda);
        self.multipliers.exchange()
    }

    /// This rank's points in contact (λN > 0) and, of those, sliding.
    pub fn multiplier_states(&self) -> (usize, usize) {
        if let Some(m) = &self.mortar {
            return (m.active_nodes(), m.sliding_nodes());
        }
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

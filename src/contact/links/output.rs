//! A links pair's fields for the result file: per slave point (position,
//! pressure, gap, λN, area weight and, with friction, traction, slip,
//! stick/slip state and the history a restart reads), this rank's part of
//! the contact force, and the nodal pressure of its owned slave nodes.
use super::multipliers::PointFriction;
use super::LinksPair;
use crate::contact::autodiff::norm;
use crate::contact::fields::{self, Field, PairOutput};
use crate::contact::formulation::At;
use crate::contact::outcome::PairForce;
use crate::error::Result;

impl LinksPair {
    /// Reference position and nodal contact pressure of every slave node
    /// this rank owns. Reference, because small-strain closed forms (Hertz)
    /// describe the pressure over the undeformed surface: the surfaces also
    /// slide inward under load (about 1 % of the Hertz width here).
    fn node_values(&self) -> Result<Vec<([f64; 3], f64)>> {
        let pressures = self.multipliers.nodal_pressures()?;
        Ok(self
            .multipliers
            .owned_nodes()
            .iter()
            .zip(pressures)
            .map(|((_, x), p)| (*x, p))
            .collect())
    }

    /// The point fields at the current state (pressure from the current
    /// multipliers: after a converged Uzawa loop λN is the pressure), and
    /// this rank's part of the total contact force on the slave surface.
    pub(super) fn fields(&mut self, at: &At) -> Result<PairOutput> {
        let nq = self.slave.num_qps();
        let states = self.evaluate_links(at);
        let points: Vec<[f64; 3]> = (0..nq).map(|q| self.slave.qp_position(q, at.u)).collect();
        let mut pressure = vec![0.0; nq];
        let mut gap = vec![self.search_distance; nq];
        let mut force = PairForce::default();
        for (l, s) in self.links.iter().zip(&states) {
            let q = l.qp_index();
            // The updated multiplier ⟨λN − εN gN⟩ is exactly the pressure the
            // last Newton solve balanced, so forces computed from it are in
            // equilibrium with the reactions to the Newton tolerance.
            let p = self.multipliers.lambda[q];
            pressure[q] = p;
            gap[q] = s.gap;
            let w = self.slave.qp_weight[q];
            for (f, n) in force.force.iter_mut().zip(s.normal) {
                *f += p * n * w;
            }
            force.normal += p * w;
            if let Some(t) = &self.multipliers.tangential {
                // The traction of the last Uzawa update, like λN above.
                let traction = t.points[q].traction;
                for (f, tc) in force.force.iter_mut().zip(traction) {
                    *f += tc * w;
                }
                force.tangential += norm(&traction) * w;
            }
        }
        let mut point_fields = vec![
            Field::vector(fields::PAIR_POINTS, &points),
            Field::scalar(fields::PAIR_PRESSURE, pressure),
            Field::scalar(fields::PAIR_GAP, gap),
            Field::scalar(fields::PAIR_LAMBDA_N, self.multipliers.lambda.clone()),
            Field::scalar(fields::PAIR_WEIGHT, self.slave.qp_weight.clone()),
        ];
        if let Some(t) = &self.multipliers.tangential {
            let p = &t.points;
            let records: Vec<_> = p.iter().map(PointFriction::record).collect();
            let vector = |name, f: &dyn Fn(usize) -> [f64; 3]| {
                Field::vector(name, &(0..p.len()).map(f).collect::<Vec<_>>())
            };
            point_fields.extend([
                vector(fields::PAIR_TRACTION_T, &|i| p[i].traction),
                vector(fields::PAIR_SLIP, &|i| p[i].slip),
                // 0 open, 1 stick, 2 slip (stored as f64 like every step array).
                Field::scalar(
                    fields::PAIR_STATE,
                    p.iter().map(|p| f64::from(p.state as i8)).collect(),
                ),
                // The friction history, so `run --restart` continues exactly.
                vector(fields::PAIR_LAMBDA_T, &|i| records[i].lambda),
                vector(fields::PAIR_SLIP_ORIGIN, &|i| records[i].origin),
                vector(fields::PAIR_HISTORY_IDS, &|i| records[i].ids),
            ]);
        }
        Ok(PairOutput {
            point_fields,
            node_fields: Vec::new(),
            force,
            nodes: self.node_values()?,
        })
    }
}

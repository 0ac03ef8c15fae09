//! A pair's values for the result file: per slave point, per owned slave
//! node, and this rank's part of the contact force.
use super::ContactPair;
use crate::contact::dual::norm;
use crate::contact::multipliers::{FrictionRecord, PointFriction};
use crate::contact::outcome::PairForce;
use crate::error::Result;
use crate::hertz::{facet_samples, NodalSample};

/// Point values for output, for this rank's slave points.
pub struct PointValues {
    pub points: Vec<[f64; 3]>,
    pub pressure: Vec<f64>,
    pub gap: Vec<f64>,
    pub lambda: Vec<f64>,
    /// Each point's area weight (reference configuration, the same weight
    /// the contact force Σ pN·w uses), so readers can integrate pressures
    /// and measure the contact area Σ w over points with pN > 0.
    pub weight: Vec<f64>,
    /// Friction (empty for a frictionless pair): tangential traction on the
    /// slave, slip increment of the step, state (0 open, 1 stick, 2 slip).
    pub traction: Vec<[f64; 3]>,
    pub slip: Vec<[f64; 3]>,
    pub state: Vec<i8>,
    /// Friction history a restart needs (empty for a frictionless pair).
    pub records: Vec<FrictionRecord>,
    /// Owned slave nodes: reference position and nodal contact pressure.
    pub nodes: Vec<([f64; 3], f64)>,
    /// Mortar pairs: the nodal fields, per owned mesh node.
    pub mortar: Option<crate::contact::mortar::pair::NodeFields>,
}

impl PointValues {
    fn empty() -> Self {
        PointValues {
            points: Vec::new(),
            pressure: Vec::new(),
            gap: Vec::new(),
            lambda: Vec::new(),
            weight: Vec::new(),
            traction: Vec::new(),
            slip: Vec::new(),
            state: Vec::new(),
            records: Vec::new(),
            nodes: Vec::new(),
            mortar: None,
        }
    }
}

impl ContactPair {
    /// Reference position and nodal contact pressure of every slave node
    /// this rank owns. Reference, because small-strain closed forms (Hertz)
    /// describe the pressure over the undeformed surface: the surfaces also
    /// slide inward under load (about 1 % of the Hertz width here).
    pub fn node_values(&self) -> Result<Vec<([f64; 3], f64)>> {
        if let Some(m) = &self.mortar {
            return Ok(m.node_values());
        }
        let pressures = self.multipliers.nodal_pressures()?;
        Ok(self
            .multipliers
            .owned_nodes()
            .iter()
            .zip(pressures)
            .map(|((_, x), p)| (*x, p))
            .collect())
    }

    /// Samples of the shape functions of the slave nodes `wanted` picks, over
    /// every facet of this rank that has one of them as a corner (reference
    /// configuration), so that a reader can form ∫N_j p dA / ∫N_j dA of a
    /// closed-form pressure p: what the nodal pressure of
    /// [`Self::node_values`] approximates (hertz::fit_nodal_averages). Each
    /// facet is on one rank only, so the samples of all ranks together
    /// cover each node's support once. (The facets were checked when the
    /// surface was built, so none fails here.)
    pub fn nodal_samples(&self, wanted: &dyn Fn(&[f64; 3]) -> bool) -> Vec<NodalSample> {
        let facets = self.slave.facets.iter().map(|f| f.x_ref.as_slice());
        facet_samples(self.slave.facet_type, facets, wanted).unwrap_or_default()
    }

    /// Point values at the current state for output (pressure from the
    /// current multipliers: after a converged Uzawa loop λN is the pressure),
    /// and this rank's part of the total contact force on the slave surface.
    pub fn point_values(
        &mut self,
        u_local: &[f64],
        factor: f64,
    ) -> Result<(PointValues, PairForce)> {
        if self.mortar.is_some() {
            return Ok(self.mortar_point_values(u_local, factor));
        }
        let nq = self.slave.num_qps();
        let states = self.evaluate_links(u_local, factor);
        let mut values = PointValues {
            points: (0..nq)
                .map(|q| self.slave.qp_position(q, u_local))
                .collect(),
            pressure: vec![0.0; nq],
            gap: vec![self.search_distance; nq],
            lambda: self.multipliers.lambda.clone(),
            weight: self.slave.qp_weight.clone(),
            traction: Vec::new(),
            slip: Vec::new(),
            state: Vec::new(),
            records: Vec::new(),
            nodes: self.node_values()?,
            mortar: None,
        };
        if let Some(t) = &self.multipliers.tangential {
            values.traction = t.points.iter().map(|p| p.traction).collect();
            values.slip = t.points.iter().map(|p| p.slip).collect();
            values.state = t.points.iter().map(|p| p.state as i8).collect();
            values.records = t.points.iter().map(PointFriction::record).collect();
        }
        let mut force = PairForce::default();
        for (l, s) in self.links.iter().zip(&states) {
            let q = l.qp_index();
            // The updated multiplier ⟨λN − εN gN⟩ is exactly the pressure the
            // last Newton solve balanced, so forces computed from it are in
            // equilibrium with the reactions to the Newton tolerance.
            let p = self.multipliers.lambda[q];
            values.pressure[q] = p;
            values.gap[q] = s.gap;
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
        Ok((values, force))
    }

    /// Mortar pair: the slave points carry λ interpolated from the nodes
    /// with the standard shape functions (Σ N_a λ_a, the smooth nodal
    /// traction; the mortar field Σ Φ_a λ_a itself oscillates inside a facet).
    fn mortar_point_values(&self, u_local: &[f64], factor: f64) -> (PointValues, PairForce) {
        let Some(m) = &self.mortar else {
            return (PointValues::empty(), PairForce::default());
        };
        let lambda = m.lambda_by_local_node();
        let nq = self.slave.num_qps();
        let mut pressure = vec![0.0; nq];
        for (q, p) in pressure.iter_mut().enumerate() {
            let facet = &self.slave.facets[q / self.slave.nqp];
            let s = crate::fem::shape::facet_shape(self.slave.facet_type, self.slave.qp_zeta[q]);
            *p = facet
                .nodes
                .iter()
                .zip(s.n)
                .map(|(n, na)| na * lambda.get(&n.to_u32()).copied().unwrap_or(0.0))
                .sum();
        }
        let (fields, force) = m.output(u_local, self.mortar_rate().as_ref(), factor);
        let mut values = PointValues {
            points: (0..nq)
                .map(|q| self.slave.qp_position(q, u_local))
                .collect(),
            lambda: pressure.clone(),
            pressure,
            gap: vec![0.0; nq],
            weight: self.slave.qp_weight.clone(),
            nodes: m.node_values(),
            mortar: Some(fields),
            ..PointValues::empty()
        };
        if self.has_friction() {
            (values.traction, values.slip, values.state) =
                m.point_friction(&self.slave, &values.pressure);
            values.records = vec![FrictionRecord::default(); nq];
        }
        (values, force)
    }

    /// The dynamic slip rate in the mortar pair's terms (None quasi-static).
    pub(super) fn mortar_rate(&self) -> Option<crate::contact::mortar::friction::Rate<'_>> {
        self.rate.as_ref().map(mortar_rate)
    }

    /// Adds this pair's nodal contact pressure (owned nodes) into the field.
    pub fn add_nodal_pressure(&self, numerator: &mut [f64], denominator: &mut [f64]) -> Result<()> {
        match &self.mortar {
            Some(m) => {
                m.add_nodal_pressure(numerator, denominator);
                Ok(())
            }
            None => self.multipliers.add_nodal_pressure(numerator, denominator),
        }
    }
}

/// A pair's slip-rate map in the mortar pair's terms.
pub(super) fn mortar_rate(r: &super::SlipRateMap) -> crate::contact::mortar::friction::Rate<'_> {
    crate::contact::mortar::friction::Rate {
        dt: r.dt,
        dv_du: r.dv_du,
        offset: &r.offset,
        master_velocity: r.rigid_velocity,
    }
}

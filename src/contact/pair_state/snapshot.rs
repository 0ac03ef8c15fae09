//! What a pair keeps across steps: the snapshot a cutback restores, the
//! commit that ends a converged step, and the restart from a result file.
use super::ContactPair;
use crate::contact::mortar::pair::{MortarPair, MortarSnapshot};
pub use crate::contact::mortar::pair_restart::MortarRows;
use crate::contact::multipliers::{FrictionRecord, PointFriction};
use crate::error::{Error, Result};

/// What [`ContactPair::restart_from`] takes over: the rows of a result file
/// this rank's share of the pair needs, and nothing more. A links pair's
/// arrays hold one row per slave point of this rank, in the pair's point
/// order (the file rows [`ContactPair::restart_points`] names); a mortar
/// pair's, one per pair node ([`MortarPair::restart_nodes`]).
#[derive(Debug, Clone, Default)]
pub struct RestartRows {
    /// The pair's penalty at that step (None in files that lack it).
    pub penalty: Option<f64>,
    pub lambda: Vec<f64>,
    pub friction: Option<FrictionRows>,
    /// A mortar pair's nodal state.
    pub mortar: Option<MortarRows>,
}

#[derive(Debug, Clone, Default)]
pub struct FrictionRows {
    pub records: Vec<FrictionRecord>,
    pub state: Vec<f64>,
    pub traction: Vec<[f64; 3]>,
}

/// What a cut-back step restores: the multipliers and friction state of the
/// last converged step.
pub struct PairSnapshot {
    lambda: Vec<f64>,
    friction: Option<Vec<PointFriction>>,
    /// The nodal multipliers of a mortar pair.
    mortar: Option<MortarSnapshot>,
}

impl ContactPair {
    /// A converged step is final: the next one measures slip from here.
    pub fn commit(&mut self) -> Result<()> {
        if let Some(m) = &mut self.mortar {
            m.commit();
            return Ok(());
        }
        if let Some(t) = &mut self.multipliers.tangential {
            t.commit();
            self.multipliers.exchange()?;
        }
        Ok(())
    }

    /// The rows of the per-point datasets (set facet × quadrature point)
    /// that hold this rank's slave points, in the pair's point order; none
    /// for a mortar pair (it restarts from its nodal datasets).
    pub fn restart_points(&self) -> Vec<usize> {
        if self.mortar.is_some() {
            return Vec::new();
        }
        let nqp = self.slave.nqp;
        (0..self.slave.num_qps())
            .map(|i| self.slave.facets[i / nqp].set_index * nqp + i % nqp)
            .collect()
    }

    /// Whether a restart reads a friction history (links: per point; mortar:
    /// nodal λT and slip origins).
    pub fn restarts_friction(&self) -> bool {
        match &self.mortar {
            Some(m) => m.restarts_friction(),
            None => self.multipliers.tangential.is_some(),
        }
    }

    /// Takes over a converged step's multipliers and friction history from a
    /// result file, given as this rank's rows (see [`RestartRows`]), then
    /// commits them as the step end did. A row the file lacks arrives as
    /// NaN and is refused here.
    pub fn restart_from(&mut self, rows: &RestartRows) -> Result<()> {
        if self.mortar.is_some() {
            return self.restart_mortar(rows);
        }
        let n = self.slave.num_qps();
        let lambda = (0..n)
            .map(|i| rows.lambda.get(i).copied())
            .collect::<Option<Vec<f64>>>()
            .filter(|l| l.iter().all(|v| v.is_finite() && *v >= 0.0))
            .ok_or_else(|| self.restart_error("lambda_n"))?;
        let friction = match (&self.multipliers.tangential, &rows.friction) {
            (None, _) => None,
            (Some(_), None) => return Err(self.restart_error("friction history")),
            (Some(_), Some(f)) => Some(
                (0..n)
                    .map(|i| {
                        PointFriction::from_record(
                            f.records.get(i)?,
                            *f.state.get(i)?,
                            *f.traction.get(i)?,
                        )
                    })
                    .collect::<Option<Vec<_>>>()
                    .ok_or_else(|| self.restart_error("friction history"))?,
            ),
        };
        if let Some(p) = rows.penalty.filter(|p| p.is_finite() && *p > 0.0) {
            // Raised during the first run: continue with the same penalty.
            self.raise_penalty(p / self.penalty);
        }
        self.restore(PairSnapshot {
            lambda,
            friction,
            mortar: None,
        })?;
        self.commit()
    }

    /// A mortar pair's [`ContactPair::restart_from`]: the nodal multipliers,
    /// λT and slip origins of the pair's nodes.
    fn restart_mortar(&mut self, rows: &RestartRows) -> Result<()> {
        let name = self.spec.name.clone();
        let misfit = |what: &str| {
            Error::Restart(format!(
                "contact pair '{name}': the file's {what} does not fit this mortar pair (another scene, or a file written before mortar restarts existed?)"
            ))
        };
        let Some(m_rows) = &rows.mortar else {
            return Err(misfit("node_lambda"));
        };
        if let Some(p) = rows.penalty.filter(|p| p.is_finite() && *p > 0.0) {
            // Raised during the first run: continue with the same penalty.
            self.raise_penalty(p / self.penalty);
        }
        match &mut self.mortar {
            Some(m) => m.restart(m_rows).map_err(misfit),
            None => Ok(()),
        }
    }

    fn restart_error(&self, what: &str) -> Error {
        Error::Restart(format!(
            "contact pair '{}': the file's {what} does not fit this pair's {} slave points",
            self.spec.name,
            self.slave.global_facets * self.slave.nqp
        ))
    }

    /// The multipliers and friction state, to restore on a cutback.
    pub fn snapshot(&self) -> PairSnapshot {
        PairSnapshot {
            lambda: self.multipliers.lambda.clone(),
            friction: self
                .multipliers
                .tangential
                .as_ref()
                .map(|t| t.points.clone()),
            mortar: self.mortar.as_ref().map(MortarPair::snapshot),
        }
    }

    pub fn restore(&mut self, snap: PairSnapshot) -> Result<()> {
        if let (Some(m), Some(lambda)) = (&mut self.mortar, snap.mortar) {
            m.restore(lambda);
        }
        self.multipliers.lambda = snap.lambda;
        if let (Some(t), Some(points)) = (&mut self.multipliers.tangential, snap.friction) {
            t.points = points;
        }
        self.multipliers.exchange()
    }
}

//! What a links pair keeps across steps: the snapshot a cutback restores,
//! the commit that ends a converged step, and the restart from a result
//! file (λN and, with friction, the history of this rank's points).
use super::multipliers::{FrictionRecord, PointFriction};
use super::LinksPair;
use crate::contact::fields::{self, RestartField, RestartRequest, RestartRows, RowSpace};
use crate::error::{Error, Result};

/// What a cut-back step restores: the multipliers and friction state of
/// the last converged step.
pub(super) struct Snapshot {
    lambda: Vec<f64>,
    friction: Option<Vec<PointFriction>>,
}

/// The datasets a restart reads, in request order: λN, then with friction
/// λT, the slip origin, the history's facet ids, the state and the traction.
const LAMBDA: usize = 0;
const LAMBDA_T: usize = 1;
const ORIGIN: usize = 2;
const IDS: usize = 3;
const STATE: usize = 4;
const TRACTION: usize = 5;

impl LinksPair {
    /// A converged step is final: the next one measures slip from here.
    pub(super) fn commit_step(&mut self) -> Result<()> {
        if let Some(t) = &mut self.multipliers.tangential {
            t.commit();
            self.multipliers.exchange()?;
        }
        Ok(())
    }

    pub(super) fn take_snapshot(&self) -> Snapshot {
        Snapshot {
            lambda: self.multipliers.lambda.clone(),
            friction: self
                .multipliers
                .tangential
                .as_ref()
                .map(|t| t.points.clone()),
        }
    }

    pub(super) fn restore_snapshot(&mut self, snap: Snapshot) -> Result<()> {
        self.multipliers.lambda = snap.lambda;
        if let (Some(t), Some(points)) = (&mut self.multipliers.tangential, snap.friction) {
            t.points = points;
        }
        self.multipliers.exchange()
    }

    /// The rows of the per-point datasets (set facet × quadrature point)
    /// that hold this rank's slave points, in the pair's point order.
    fn restart_points(&self) -> Vec<usize> {
        let nqp = self.slave.nqp;
        (0..self.slave.num_qps())
            .map(|i| self.slave.facets[i / nqp].set_index * nqp + i % nqp)
            .collect()
    }

    pub(super) fn request(&self) -> RestartRequest {
        let rows = self.restart_points();
        let field = |name, cols| RestartField {
            name,
            cols,
            space: RowSpace::Points,
            rows: rows.clone(),
        };
        let mut fields = vec![field(fields::PAIR_LAMBDA_N, 1)];
        if self.multipliers.tangential.is_some() {
            fields.extend([
                field(fields::PAIR_LAMBDA_T, 3),
                field(fields::PAIR_SLIP_ORIGIN, 3),
                field(fields::PAIR_HISTORY_IDS, 3),
                field(fields::PAIR_STATE, 1),
                field(fields::PAIR_TRACTION_T, 3),
            ]);
        }
        RestartRequest { fields }
    }

    /// Takes over a converged step's multipliers and friction history from
    /// a result file's rows (see `request`), then commits them as the step
    /// end did. A row the file lacks arrives as NaN and is refused here.
    pub(super) fn take_over(&mut self, rows: &RestartRows) -> Result<()> {
        let n = self.slave.num_qps();
        let lambda = (0..n)
            .map(|i| rows.field(LAMBDA).get(i).copied())
            .collect::<Option<Vec<f64>>>()
            .filter(|l| l.iter().all(|v| v.is_finite() && *v >= 0.0))
            .ok_or_else(|| self.restart_error("lambda_n"))?;
        let friction = match &self.multipliers.tangential {
            None => None,
            Some(_) => {
                let (lambda_t, origin, ids) = (
                    rows.triples(LAMBDA_T),
                    rows.triples(ORIGIN),
                    rows.triples(IDS),
                );
                let (state, traction) = (rows.field(STATE), rows.triples(TRACTION));
                Some(
                    (0..n)
                        .map(|i| {
                            let record = FrictionRecord {
                                lambda: *lambda_t.get(i)?,
                                origin: *origin.get(i)?,
                                ids: *ids.get(i)?,
                            };
                            PointFriction::from_record(&record, *state.get(i)?, *traction.get(i)?)
                        })
                        .collect::<Option<Vec<_>>>()
                        .ok_or_else(|| self.restart_error("friction history"))?,
                )
            }
        };
        self.restore_snapshot(Snapshot { lambda, friction })?;
        self.commit_step()
    }

    fn restart_error(&self, what: &str) -> Error {
        Error::Restart(format!(
            "contact pair '{}': the file's {what} does not fit this pair's {} slave points",
            self.name,
            self.slave.global_facets * self.slave.nqp
        ))
    }
}

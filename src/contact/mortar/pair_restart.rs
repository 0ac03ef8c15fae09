//! A mortar pair taking over a converged step from a result file: the nodal
//! multipliers and, with friction, λT and the slip origins (the
//! `node_lambda`, `node_lambda_t` and `node_slip_origin` datasets, rows by
//! natural node).
use super::pair::MortarPair;

/// What a result file holds of a mortar pair at one step, rows by natural
/// node (every mesh node; zero off the pair).
#[derive(Debug, Clone, Default)]
pub struct MortarRows {
    pub lambda: Vec<f64>,
    /// Frictional pairs: λT_j and every pair node's slip origin.
    pub lambda_t: Option<Vec<[f64; 3]>>,
    pub slip_origin: Option<Vec<[f64; 3]>>,
    /// The step's load factor (a rigid master's placement it ended at).
    pub load_factor: f64,
}

impl MortarPair {
    /// Takes over `rows` as the end of a converged step (then committed, as
    /// the step end did). On a mismatch, says which dataset does not fit.
    pub fn restart(&mut self, rows: &MortarRows) -> Result<(), &'static str> {
        let natural = &self.natural;
        let slot_rows: Vec<usize> = self
            .nodal
            .nodes
            .iter()
            .map(|&id| natural[id as usize])
            .collect();
        let lambda = slot_rows
            .iter()
            .map(|&r| rows.lambda.get(r).copied())
            .collect::<Option<Vec<f64>>>()
            .filter(|l| l.iter().all(|v| v.is_finite() && *v >= 0.0))
            .ok_or("node_lambda")?;
        if let Some(f) = &mut self.friction {
            let lambda_t = rows.lambda_t.as_ref().ok_or("node_lambda_t")?;
            let origin = rows.slip_origin.as_ref().ok_or("node_slip_origin")?;
            let take = |v: &[[f64; 3]], at: &[usize], what| {
                at.iter()
                    .map(|&r| {
                        v.get(r)
                            .copied()
                            .filter(|x| x.iter().all(|c| c.is_finite()))
                    })
                    .collect::<Option<Vec<[f64; 3]>>>()
                    .ok_or(what)
            };
            f.nodal.lambda = take(lambda_t, &slot_rows, "node_lambda_t")?;
            f.last = take(origin, natural, "node_slip_origin")?;
        }
        self.nodal.lambda = lambda;
        if let Some(r) = &mut self.rigid {
            r.last_factor = rows.load_factor;
        }
        self.commit();
        Ok(())
    }
}

//! A mortar pair taking over a converged step from a result file: the nodal
//! multipliers and, with friction, λT and the slip origins (the
//! `node_lambda`, `node_lambda_t` and `node_slip_origin` datasets, rows by
//! natural node).
use super::master::Master;
use super::pair::MortarPair;
use crate::contact::fields::{self, RestartField, RestartRequest, RestartRows, RowSpace};

impl MortarPair {
    /// The fields a restart reads (λ_j and, with friction, λT_j and the
    /// slip origins), and their natural (file) rows: the slave nodes this
    /// rank holds (in id order), then its owned nodes of either surface
    /// (whose slip origins it hands on, see [`MortarPair::committed_origins`]).
    pub(super) fn request(&self) -> RestartRequest {
        let field = |name, cols| RestartField {
            name,
            cols,
            space: RowSpace::Nodes,
            rows: self.restart_rows.clone(),
        };
        let mut fields = vec![field(fields::PAIR_NODE_LAMBDA, 1)];
        if self.friction.is_some() {
            fields.push(field(fields::PAIR_NODE_LAMBDA_T, 3));
            fields.push(field(fields::PAIR_NODE_SLIP_ORIGIN, 3));
        }
        RestartRequest { fields }
    }

    /// Takes over `rows` (see `request`) as the end of a converged step
    /// (then committed, as the step end did). On a mismatch, says which
    /// dataset does not fit.
    pub(super) fn restart(&mut self, rows: &RestartRows) -> Result<(), &'static str> {
        let slots: Vec<usize> = self.nodal.nodes.iter().map(|&id| id as usize).collect();
        let lambda = slots
            .iter()
            .map(|&r| rows.field(0).get(r).copied())
            .collect::<Option<Vec<f64>>>()
            .filter(|l| l.iter().all(|v| v.is_finite() && *v >= 0.0))
            .ok_or("node_lambda")?;
        let mut pending = None;
        if let Some(f) = &mut self.friction {
            let (lambda_t, origin) = (&rows.triples(1), &rows.triples(2));
            let take = |v: &[[f64; 3]], at: &mut dyn Iterator<Item = usize>, what| {
                at.map(|r| {
                    v.get(r)
                        .copied()
                        .filter(|x| x.iter().all(|c| c.is_finite()))
                })
                .collect::<Option<Vec<[f64; 3]>>>()
                .ok_or(what)
            };
            f.nodal.lambda = take(lambda_t, &mut slots.iter().copied(), "node_lambda_t")?;
            let owned = self.owned_pair_nodes.len();
            let origins = take(
                origin,
                &mut (self.n_slave..self.n_slave + owned),
                "node_slip_origin",
            )?;
            pending = Some(origins);
        }
        self.nodal.lambda = lambda;
        if let Master::Rigid(r) = &mut self.master {
            r.last_factor = rows.load_factor;
        }
        self.commit_step();
        self.pending_origins = pending;
        Ok(())
    }

    /// After a restart, until its first step has converged: the file's slip
    /// origins of this rank's owned pair nodes, as displacements (local
    /// node, origin − reference position). The solver writes them into the
    /// committed state the search hands [`MortarPair::start_slip_from`],
    /// so every rank holding a node measures from the file's origin.
    pub(super) fn committed_origins(&self) -> Vec<(u32, [f64; 3])> {
        let Some(origins) = &self.pending_origins else {
            return Vec::new();
        };
        self.owned_pair_nodes
            .iter()
            .zip(origins)
            .map(|(&(l, x), o)| (l, [0, 1, 2].map(|c| o[c] - x[c])))
            .collect()
    }
}

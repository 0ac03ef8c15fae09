//! The tangential state of a frictional mortar pair at run time: λT_j and
//! εT_j per slave node, where the step's slip is measured from, and the
//! stick/slip outcome of the last Uzawa update (docs/formulation.md §13.3).
use super::friction::{NodalFriction, Rate};
use crate::dofs::DIM;
use crate::model::FrictionSpec;

/// Friction of a mortar pair at run time (per slot, as `NodalData`).
pub(super) struct PairFriction {
    pub nodal: NodalFriction,
    /// εT follows εN (no `tangential_penalty`): raised with it.
    pub follows: bool,
    /// Every pair node's position at the end of the last converged step:
    /// the quasi-static slip increment is measured from there.
    pub start: Vec<[f64; 3]>,
    /// The positions of the last Uzawa update (the next `start` once the
    /// step has converged).
    pub last: Vec<[f64; 3]>,
    /// Per slot: sliding, and the tangential mean slip of the step, at the
    /// last Uzawa update.
    pub sliding: Vec<bool>,
    pub slip: Vec<[f64; 3]>,
}

impl PairFriction {
    /// `normal_penalty`: εN per slot (εT's default); `x_ref`: every pair
    /// node's reference position (the first step starts there).
    pub fn new(spec: FrictionSpec, normal_penalty: &[f64], x_ref: &[[f64; 3]]) -> Self {
        let n = normal_penalty.len();
        PairFriction {
            nodal: NodalFriction {
                mu: spec.mu,
                penalty: match spec.penalty {
                    Some(p) => vec![p; n],
                    None => normal_penalty.to_vec(),
                },
                lambda: vec![[0.0; 3]; n],
            },
            follows: spec.penalty.is_none(),
            start: x_ref.to_vec(),
            last: x_ref.to_vec(),
            sliding: vec![false; n],
            slip: vec![[0.0; 3]; n],
        }
    }

    /// The step's increment of every pair node (see `friction::Increment`)
    /// and its slope: `x − xₙ` quasi-static, `Δt v(u)` in dynamics
    /// (`node_local`: each pair node's local mesh node).
    pub fn increments(
        &self,
        node_local: &[u32],
        x: &[[f64; 3]],
        u_local: &[f64],
        rate: Option<&Rate>,
    ) -> (Vec<[f64; 3]>, f64) {
        match rate {
            None => (
                x.iter()
                    .zip(&self.start)
                    .map(|(x, s)| [0, 1, 2].map(|i| x[i] - s[i]))
                    .collect(),
                1.0,
            ),
            Some(r) => (
                node_local
                    .iter()
                    .map(|&l| {
                        let b = DIM * l as usize;
                        [0, 1, 2].map(|i| r.dt * (r.dv_du * u_local[b + i] + r.offset[b + i]))
                    })
                    .collect(),
                r.dt * r.dv_du,
            ),
        }
    }
}

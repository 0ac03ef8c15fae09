//! The normal part of a link: gap, open/closed, the contact pressure
//! pN = ⟨λN − εN gN⟩ (`contact::penalty`'s law), and the frictionless state
//! and potential.

use super::evaluate;
use super::input::{check_input, first_order, nodes_as, LinkInput, LinkMaster, LinkState};
use super::kinematics::{rigid_kinematics, slave_point};
use crate::contact::penalty::{contact_pressure, trial_pressure};
use crate::contact::projection;
use crate::contact::{LINEAR_FACET_NODES, MAX_FACET_NODES};

/// Gap, normal, pressure and open/closed, without the friction state.
pub(super) fn evaluate_normal(input: &LinkInput) -> LinkState {
    if first_order(input) {
        evaluate_normal_in::<LINEAR_FACET_NODES>(input)
    } else {
        evaluate_normal_in::<MAX_FACET_NODES>(input)
    }
}

/// [`evaluate_normal`] in holders of `M` nodes.
fn evaluate_normal_in<const M: usize>(input: &LinkInput) -> LinkState {
    if check_input(input).is_err() {
        return LinkState::invalid();
    }
    let slave = nodes_as::<f64, M>(input.slave_x);
    let x1 = slave_point::<f64, M>(
        input.slave_facet,
        input.zeta,
        &slave[..input.slave_facet.nodes()],
    );
    let mut state = match input.master {
        LinkMaster::Facet { facet, x } => {
            let p = projection::project(facet, x, x1, Some(input.xi_start));
            LinkState {
                gap: p.gap,
                normal: p.normal,
                xi: p.xi,
                pressure: 0.0,
                closed: false,
                slave_point: x1,
                master_point: p.point,
                projection_converged: p.converged,
                outside: p.outside,
                friction: None,
            }
        }
        _ => match rigid_kinematics::<f64, M>(&x1, &input.master) {
            Some(kin) => LinkState {
                gap: kin.gap,
                normal: kin.normal,
                xi: [0.0; 2],
                pressure: 0.0,
                closed: false,
                slave_point: x1,
                master_point: kin.master_point,
                projection_converged: true,
                outside: 0.0,
                friction: None,
            },
            None => LinkState {
                slave_point: x1,
                ..LinkState::invalid()
            },
        },
    };
    if state.projection_converged {
        state.closed = trial_pressure(input.lambda_n, input.penalty, state.gap) >= 0.0;
        state.pressure = contact_pressure(input.lambda_n, input.penalty, state.gap);
    }
    state
}

/// The link potential `Πc = (pN² − λN²)/(2 εN) · w` (0 for bad input). Not
/// needed by Newton; it is what `r` is the gradient of, for line searches
/// and consistency checks.
pub fn potential(input: &LinkInput) -> f64 {
    if check_input(input).is_err() {
        return 0.0;
    }
    let p = evaluate(input).pressure;
    (p * p - input.lambda_n * input.lambda_n) / (2.0 * input.penalty) * input.weight
}

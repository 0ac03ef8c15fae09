//! Coulomb friction of a link (docs/formulation.md §5): the slip increment
//! ΔgT, λT in the current tangent plane, the trial traction and the return
//! map onto the cone |tT| ≤ μ pN.

use super::input::{Friction, LinkInput, SlipHistory};
use super::kinematics::{tangential, Frame, Kinematics};
use crate::contact::autodiff::{self, Scalar, Vec3};
use crate::contact::facet_shape;

/// `Σ N_a (v̄_a + dv_dx (x_a − x̄_a))`: the integrator's velocity, affine in
/// the positions, interpolated with shape values `n`.
fn interpolated_velocity<T: Scalar>(n: &[T], x: &[Vec3<T>], v: &[[f64; 3]], dv_dx: f64) -> Vec3<T> {
    let mut out = autodiff::constant3::<T>([0.0; 3]);
    for ((na, xa), va) in n.iter().zip(x).zip(v) {
        for i in 0..3 {
            out[i] = out[i] + *na * ((xa[i] - xa[i].re()) * dv_dx + va[i]);
        }
    }
    out
}

/// Slip increment ΔgT of the slave relative to the master.
pub(super) fn slip_increment<T: Scalar, const M: usize>(
    input: &LinkInput,
    friction: &Friction,
    kin: &Kinematics<T, M>,
    slave: &[Vec3<T>],
    master: &[Vec3<T>],
) -> Vec3<T> {
    if let Some(rate) = &friction.rate {
        let s = facet_shape::<M>(input.slave_facet, input.zeta);
        let n_slave = s.n.map(T::from_f64);
        let v1 = interpolated_velocity(&n_slave[..slave.len()], slave, rate.slave_v, rate.dv_dx);
        let v2 = match kin.frame {
            Frame::Facet { .. } => interpolated_velocity(
                &kin.master_n[..master.len()],
                master,
                rate.master_v,
                rate.dv_dx,
            ),
            Frame::Rigid { .. } => autodiff::constant3(rate.master_v[0]),
        };
        return autodiff::scale_f64(&tangential(&autodiff::sub(&v1, &v2), &kin.normal), rate.dt);
    }
    match (&kin.frame, friction.history) {
        (Frame::Facet { xi, tangents, .. }, SlipHistory::Convected { xi_n, .. }) => autodiff::add(
            &autodiff::scale(&tangents[0], xi[0] - xi_n[0]),
            &autodiff::scale(&tangents[1], xi[1] - xi_n[1]),
        ),
        (Frame::Rigid { .. }, SlipHistory::Spatial { point_n, .. }) => tangential(
            &autodiff::sub(&kin.master_point, &autodiff::constant3(point_n)),
            &kin.normal,
        ),
        // `check_input` rejects a history that does not match the master.
        _ => autodiff::constant3([0.0; 3]),
    }
}

/// λT as a vector in the current tangent plane.
fn multiplier_vector<T: Scalar, const M: usize>(
    history: SlipHistory,
    kin: &Kinematics<T, M>,
) -> Vec3<T> {
    match (&kin.frame, history) {
        (
            Frame::Facet {
                tangents: [t1, t2], ..
            },
            SlipHistory::Convected { lambda, .. },
        ) => {
            // Contravariant basis m^α = M^{αβ} τ_β, so that λT·τ_α = λ_α.
            let (m11, m12, m22) = (
                autodiff::dot(t1, t1),
                autodiff::dot(t1, t2),
                autodiff::dot(t2, t2),
            );
            let det = m11 * m22 - m12 * m12;
            let c1 = (m22 * lambda[0] - m12 * lambda[1]) / det;
            let c2 = (m11 * lambda[1] - m12 * lambda[0]) / det;
            autodiff::add(&autodiff::scale(t1, c1), &autodiff::scale(t2, c2))
        }
        (_, SlipHistory::Spatial { lambda, .. }) => {
            tangential(&autodiff::constant3(lambda), &kin.normal)
        }
        _ => autodiff::constant3([0.0; 3]),
    }
}

/// The friction law at one link: trial, stick/slip decision (on the f64
/// value) and return map. Returns `tT` (the traction resisting the slip).
pub(super) fn friction_traction<T: Scalar, const M: usize>(
    friction: &Friction,
    kin: &Kinematics<T, M>,
    pressure: T,
    slip: &Vec3<T>,
) -> (Vec3<T>, bool) {
    let lambda = multiplier_vector(friction.history, kin);
    let trial = autodiff::add(&lambda, &autodiff::scale_f64(slip, friction.penalty));
    let size = autodiff::norm(&trial);
    let limit = pressure * friction.mu;
    if size.re() > limit.re() && size.re() > 0.0 {
        (autodiff::scale(&trial, limit / size), true)
    } else {
        (trial, false)
    }
}

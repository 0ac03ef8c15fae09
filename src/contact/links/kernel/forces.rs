//! The nodal forces of one closed link and the two passes that form them:
//! f64 (residual only) and dual (residual and exact tangent).

use super::friction::{friction_traction, slip_increment};
use super::input::{
    dof_count, first_order, master_x, nodes_as, seed, FrictionState, LinkInput, SlipHistory,
};
use super::kinematics::{kinematics, tangential, Frame, Kinematics};
use crate::contact::autodiff::{self, Dual, Scalar, Vec3};
use crate::contact::penalty::trial_pressure;
use crate::contact::{facet_shape, LINEAR_FACET_NODES, MAX_FACET_NODES};

/// The contact forces of one link (normal, plus friction when the input has
/// it), handed to `emit(dof, value)` once per DOF. Slave node `a` gets
/// `N¹_a (g − pN ν) w`; master node `b` gets `(pN ν − g) N²_b w + (x¹ − x²)
/// c^α N²_b,α w`, where `g = τ_α c^α` (facet) or `Jᵀ tT` (rigid) is the
/// friction's generalized force and `c = H⁻¹ [tT·τ_α]`.
pub(super) fn link_forces<T: Scalar, const M: usize>(
    input: &LinkInput,
    kin: &Kinematics<T, M>,
    slave: &[Vec3<T>],
    master: &[Vec3<T>],
    mut emit: impl FnMut(usize, T),
) -> Option<FrictionState> {
    let s = facet_shape::<M>(input.slave_facet, input.zeta);
    let ns = input.slave_facet.nodes();
    let n_master = master.len();
    // Closed branch (the caller decided it from the f64 gap): pN = λN − εN gN.
    let pressure = trial_pressure(input.lambda_n, input.penalty, kin.gap);
    // The main-part tangent: ν and N²_b as constants, so only the pressure
    // carries derivatives (in the f64 pass this changes nothing).
    let main_part = input.main_part_tangent && input.friction.is_none();
    let mut common = if main_part {
        autodiff::scale(
            &autodiff::constant3::<T>(autodiff::re3(&kin.normal)),
            -pressure,
        )
    } else {
        autodiff::scale(&kin.normal, -pressure)
    };
    let mut master_extra = [T::from_f64(0.0); M];
    let mut state = None;
    if let Some(friction) = &input.friction {
        let slip = slip_increment(input, friction, kin, slave, master);
        let (traction, sliding) = friction_traction(friction, kin, pressure, &slip);
        let (g, updated) = match &kin.frame {
            Frame::Facet {
                xi,
                tangents: [t1, t2],
                hessian: [h11, h12, h22],
                master_dn,
            } => {
                let t = [autodiff::dot(&traction, t1), autodiff::dot(&traction, t2)];
                let det = *h11 * *h22 - *h12 * *h12;
                let c1 = (*h22 * t[0] - *h12 * t[1]) / det;
                let c2 = (*h11 * t[1] - *h12 * t[0]) / det;
                for (extra, dn) in master_extra.iter_mut().zip(master_dn).take(n_master) {
                    *extra = c1 * dn[0] + c2 * dn[1];
                }
                let g = autodiff::add(&autodiff::scale(t1, c1), &autodiff::scale(t2, c2));
                let updated = SlipHistory::Convected {
                    xi_n: [xi[0].re(), xi[1].re()],
                    lambda: [t[0].re(), t[1].re()],
                };
                (g, updated)
            }
            Frame::Rigid { scale, axis } => {
                let along = match axis {
                    Some(a) => {
                        let a = autodiff::constant3::<T>(*a);
                        autodiff::scale(&a, autodiff::dot(&a, &traction))
                    }
                    None => autodiff::constant3([0.0; 3]),
                };
                let across = tangential(&autodiff::sub(&traction, &along), &kin.normal);
                let g = autodiff::add(&along, &autodiff::scale(&across, *scale));
                let updated = SlipHistory::Spatial {
                    point_n: autodiff::re3(&kin.master_point),
                    lambda: autodiff::re3(&traction),
                };
                (g, updated)
            }
        };
        common = autodiff::add(&common, &g);
        state = Some(FrictionState {
            traction: autodiff::re3(&traction).map(|v| -v),
            slip: autodiff::re3(&slip),
            sliding,
            updated,
        });
    }
    let common = autodiff::scale_f64(&common, input.weight);
    for a in 0..ns {
        for (i, ci) in common.iter().enumerate() {
            emit(3 * a + i, *ci * s.n[a]);
        }
    }
    for (b, (extra_b, n_b)) in master_extra
        .iter()
        .zip(&kin.master_n)
        .take(n_master)
        .enumerate()
    {
        for (i, (sep, c)) in kin.separation.iter().zip(&common).enumerate() {
            let extra = *sep * *extra_b * input.weight;
            let n_b = if main_part {
                T::from_f64(n_b.re())
            } else {
                *n_b
            };
            emit(3 * (ns + b) + i, extra - *c * n_b);
        }
    }
    state
}

/// Residual only (f64 path; the Newton step is then a harmless polish).
/// `None` where the kernel has no usable closest point.
pub(super) fn residual_f64(
    input: &LinkInput,
    xi_bar: [f64; 2],
    r: &mut [f64],
) -> Option<Option<FrictionState>> {
    if first_order(input) {
        residual_f64_in::<LINEAR_FACET_NODES>(input, xi_bar, r)
    } else {
        residual_f64_in::<MAX_FACET_NODES>(input, xi_bar, r)
    }
}

/// [`residual_f64`] in holders of `M` nodes.
fn residual_f64_in<const M: usize>(
    input: &LinkInput,
    xi_bar: [f64; 2],
    r: &mut [f64],
) -> Option<Option<FrictionState>> {
    let ns = input.slave_facet.nodes();
    let xm = master_x(input);
    let slave = nodes_as::<f64, M>(input.slave_x);
    let master = nodes_as::<f64, M>(xm);
    let kin = kinematics::<f64, M>(input, &slave[..ns], &master[..xm.len()], xi_bar)?;
    Some(link_forces(
        input,
        &kin,
        &slave[..ns],
        &master[..xm.len()],
        |dof, v| {
            if let Some(ri) = r.get_mut(dof) {
                *ri = v;
            }
        },
    ))
}

/// Residual and tangent with `N` = number of link DOFs, in holders of `M`
/// nodes.
fn residual_dual<const N: usize, const M: usize>(
    input: &LinkInput,
    xi_bar: [f64; 2],
    r: &mut [f64],
    k: &mut [f64],
) -> Option<Option<FrictionState>> {
    let ns = input.slave_facet.nodes();
    let xm = master_x(input);
    let slave = seed::<N, M>(input.slave_x, 0);
    let master = seed::<N, M>(xm, 3 * ns);
    let kin = kinematics::<Dual<N>, M>(input, &slave[..ns], &master[..xm.len()], xi_bar)?;
    Some(link_forces(
        input,
        &kin,
        &slave[..ns],
        &master[..xm.len()],
        |dof, v: Dual<N>| {
            if let Some(ri) = r.get_mut(dof) {
                *ri = v.re;
            }
            if let Some(row) = k.get_mut(dof * N..(dof + 1) * N) {
                row.copy_from_slice(&v.eps);
            }
        },
    ))
}

/// Monomorphised for the possible link sizes so the dual arrays are exactly
/// as long as needed. First-order facets (holders of four nodes): quad–quad
/// 24, quad–tri 21, tri–tri 18, rigid 12 / 9. A link with a second-order
/// facet (holders of nine): `3 (n_s + n_m)` for slave and master node
/// counts in {3, 4, 6, 8, 9} (0 for a rigid master), one of them second
/// order: tri6 / quad8 / quad9 against a rigid master 18 / 24 / 27,
/// tri6–tri6 36, quad8–quad8 48, quad9–quad9 54, mixed pairs in between.
pub(super) fn residual_tangent_sized(
    input: &LinkInput,
    xi_bar: [f64; 2],
    r: &mut [f64],
    k: &mut [f64],
) -> Option<Option<FrictionState>> {
    const L: usize = LINEAR_FACET_NODES;
    if first_order(input) {
        return match dof_count(input) {
            24 => residual_dual::<24, L>(input, xi_bar, r, k),
            21 => residual_dual::<21, L>(input, xi_bar, r, k),
            18 => residual_dual::<18, L>(input, xi_bar, r, k),
            12 => residual_dual::<12, L>(input, xi_bar, r, k),
            9 => residual_dual::<9, L>(input, xi_bar, r, k),
            _ => None,
        };
    }
    macro_rules! second_order {
        ($($n:literal)*) => {
            match dof_count(input) {
                $($n => residual_dual::<$n, MAX_FACET_NODES>(input, xi_bar, r, k),)*
                _ => None,
            }
        };
    }
    second_order!(18 24 27 30 33 36 39 42 45 48 51 54)
}

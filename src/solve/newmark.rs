//! Newmark-β time integration in displacement form, for implicit dynamics.
//!
//! The unknown of a step is the end-of-step displacement `u`, as in the
//! static solver, so Dirichlet conditions, contact and the Newton loop are
//! reused unchanged. Acceleration and velocity are affine in `u`:
//!
//! ```text
//! a(u) = (u − u_n) / (βΔt²) − v_n / (βΔt) − (1/(2β) − 1) a_n
//! v(u) = v_n + Δt ((1 − γ) a_n + γ a(u))
//! ```
//!
//! and the dynamic residual `M a(u) + f_int(u) − f_ext` has the tangent
//! `K + M / (βΔt²)` (plus `γ/(βΔt) C` with viscous damping).
//!
//! For linear problems the scheme is unconditionally stable for
//! `2β ≥ γ ≥ ½`. `γ = ½, β = ¼` (trapezoidal rule) is second-order accurate
//! and conserves energy exactly; `γ > ½` damps the high, mesh-dependent
//! frequencies that contact impacts excite, at the price of first-order
//! accuracy.
//!
//! Energy with `γ > ½`: what decreases monotonically step by step is
//! `Ê = ½ vᵀMv + ½ uᵀKu + (β − γ/2) Δt² · ½ aᵀMa`, by
//! `(γ − ½) ([[u]]ᵀK[[u]] + (β − γ/2) Δt² [[a]]ᵀM[[a]])` per step. The plain
//! mechanical energy `½ vᵀMv + ½ uᵀKu` differs from it by the last term and
//! can rise by a tiny amount in single steps; it is non-increasing only over
//! whole oscillations. Energy-balance checks should use `Ê`.

use crate::model::Newmark;

/// End-of-step acceleration and velocity as affine functions of the
/// end-of-step displacement `u`, given the previous state `(u_n, v_n, a_n)`:
///
/// ```text
/// a = a_u (u − u_n) + a_v v_n + a_a a_n
/// v = v_u (u − u_n) + v_v v_n + v_a a_n
/// ```
///
/// Written in `u − u_n` rather than `u` so that a step starting from rest
/// with `u = u_n` gives exactly zero, without cancellation between two
/// large terms.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Coefficients {
    /// `1/(βΔt²)`.
    pub a_u: f64,
    /// `−1/(βΔt)`.
    pub a_v: f64,
    /// `1 − 1/(2β)`.
    pub a_a: f64,
    /// `γ/(βΔt)`.
    pub v_u: f64,
    /// `1 − γ/β`.
    pub v_v: f64,
    /// `Δt (1 − γ/(2β))`.
    pub v_a: f64,
}

impl Coefficients {
    /// The affine maps `a(u)`, `v(u)` for a step of length `dt`. Call
    /// [`Newmark::validate`] and [`Newmark::validate_dt`] first: invalid
    /// parameters give non-finite or meaningless coefficients, not a panic.
    pub fn new(newmark: &Newmark, dt: f64) -> Self {
        let Newmark { beta, gamma } = *newmark;
        Coefficients {
            a_u: 1.0 / (beta * dt * dt),
            a_v: -1.0 / (beta * dt),
            a_a: 1.0 - 1.0 / (2.0 * beta),
            v_u: gamma / (beta * dt),
            v_v: 1.0 - gamma / beta,
            v_a: dt * (1.0 - gamma / (2.0 * beta)),
        }
    }

    /// `a(u)` for one entry.
    pub fn acceleration(&self, u: f64, u_n: f64, v_n: f64, a_n: f64) -> f64 {
        self.a_u * (u - u_n) + self.a_v * v_n + self.a_a * a_n
    }

    /// `v(u)` for one entry.
    pub fn velocity(&self, u: f64, u_n: f64, v_n: f64, a_n: f64) -> f64 {
        self.v_u * (u - u_n) + self.v_v * v_n + self.v_a * a_n
    }

    /// `∂a/∂u = 1/(βΔt²)`: the factor of `M` in the dynamic tangent.
    pub fn mass_factor(&self) -> f64 {
        self.a_u
    }

    /// `∂v/∂u = γ/(βΔt)`: the factor of a viscous damping matrix `C` in the
    /// dynamic tangent.
    pub fn damping_factor(&self) -> f64 {
        self.v_u
    }

    /// [`Coefficients::acceleration`] entry by entry into `out`.
    pub fn accelerations(
        &self,
        u: &[f64],
        u_n: &[f64],
        v_n: &[f64],
        a_n: &[f64],
        out: &mut [f64],
    ) -> Result<(), String> {
        entrywise(u, u_n, v_n, a_n, out, |u, u_n, v_n, a_n| {
            self.acceleration(u, u_n, v_n, a_n)
        })
    }

    /// [`Coefficients::velocity`] entry by entry into `out`.
    pub fn velocities(
        &self,
        u: &[f64],
        u_n: &[f64],
        v_n: &[f64],
        a_n: &[f64],
        out: &mut [f64],
    ) -> Result<(), String> {
        entrywise(u, u_n, v_n, a_n, out, |u, u_n, v_n, a_n| {
            self.velocity(u, u_n, v_n, a_n)
        })
    }
}

/// `out[i] = f(u[i], u_n[i], v_n[i], a_n[i])` for slices of one length.
fn entrywise(
    u: &[f64],
    u_n: &[f64],
    v_n: &[f64],
    a_n: &[f64],
    out: &mut [f64],
    f: impl Fn(f64, f64, f64, f64) -> f64,
) -> Result<(), String> {
    check_lengths(u, u_n, v_n, a_n, out)?;
    for ((((o, &u), &u_n), &v_n), &a_n) in out.iter_mut().zip(u).zip(u_n).zip(v_n).zip(a_n) {
        *o = f(u, u_n, v_n, a_n);
    }
    Ok(())
}

/// `zip` would silently stop at the shortest slice and leave the rest of
/// `out` stale; a mismatch is a caller bug to report instead.
fn check_lengths(
    u: &[f64],
    u_n: &[f64],
    v_n: &[f64],
    a_n: &[f64],
    out: &[f64],
) -> Result<(), String> {
    let n = out.len();
    for (name, len) in [
        ("u", u.len()),
        ("u_n", u_n.len()),
        ("v_n", v_n.len()),
        ("a_n", a_n.len()),
    ] {
        if len != n {
            return Err(format!("Newmark: {name} has length {len}, out has {n}"));
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::f64::consts::PI;

    /// Single-DOF state (u, v, a).
    #[derive(Debug, Clone, Copy)]
    struct State {
        u: f64,
        v: f64,
        a: f64,
    }

    /// `m ü + k u = 0` started at u = 1 at rest, with the consistent initial
    /// acceleration.
    fn released(m: f64, k: f64) -> State {
        State {
            u: 1.0,
            v: 0.0,
            a: -k / m,
        }
    }

    /// One step of `m a(u) + k u = 0`, solved exactly: the residual is
    /// affine in u, `(m a_u + k) u = m (a_u u_n − a_v v_n − a_a a_n)`.
    fn step(c: &Coefficients, m: f64, k: f64, s: State) -> State {
        let u = m * (c.a_u * s.u - c.a_v * s.v - c.a_a * s.a) / (m * c.a_u + k);
        State {
            u,
            v: c.velocity(u, s.u, s.v, s.a),
            a: c.acceleration(u, s.u, s.v, s.a),
        }
    }

    fn energy(m: f64, k: f64, s: State) -> f64 {
        0.5 * m * s.v * s.v + 0.5 * k * s.u * s.u
    }

    /// The quantity Newmark provably never increases (see the module docs).
    fn algorithmic_energy(nm: &Newmark, dt: f64, m: f64, k: f64, s: State) -> f64 {
        energy(m, k, s) + (nm.beta - nm.gamma / 2.0) * dt * dt * 0.5 * m * s.a * s.a
    }

    #[test]
    fn coefficients_reproduce_the_newmark_update() {
        let dt = 0.013;
        let (u_n, v_n, a_n, u) = (0.3, -1.2, 4.5, 0.29);
        for nm in [Newmark::trapezoidal(), Newmark::with_dissipation(0.65)] {
            let Newmark { beta, gamma } = nm;
            let c = Coefficients::new(&nm, dt);
            let a = c.acceleration(u, u_n, v_n, a_n);
            let v = c.velocity(u, u_n, v_n, a_n);
            // The textbook form: u from (u_n, v_n, a_n, a), v from (v_n, a_n, a).
            let u_back =
                u_n + dt * v_n + dt * dt / 2.0 * ((1.0 - 2.0 * beta) * a_n + 2.0 * beta * a);
            let v_back = v_n + dt * ((1.0 - gamma) * a_n + gamma * a);
            assert!((u_back - u).abs() < 1e-14, "{nm:?}: u {u_back} vs {u}");
            assert!((v_back - v).abs() < 1e-12, "{nm:?}: v {v_back} vs {v}");
            // Both maps are affine, so a finite difference is exact up to
            // rounding.
            let h = 1e-4;
            let da = (c.acceleration(u + h, u_n, v_n, a_n) - a) / h;
            let dv = (c.velocity(u + h, u_n, v_n, a_n) - v) / h;
            assert!((da / c.mass_factor() - 1.0).abs() < 1e-8);
            assert!((dv / c.damping_factor() - 1.0).abs() < 1e-8);
            assert!((c.mass_factor() - 1.0 / (beta * dt * dt)).abs() < 1e-9 * c.mass_factor());
            assert!((c.damping_factor() - gamma / (beta * dt)).abs() < 1e-12 * c.damping_factor());
        }
    }

    #[test]
    fn slice_versions_match_scalars_and_check_lengths() {
        let c = Coefficients::new(&Newmark::with_dissipation(0.6), 0.1);
        let u = [1.0, 2.0, -3.0];
        let u_n = [0.5, 2.5, -2.0];
        let v_n = [0.1, -0.2, 0.3];
        let a_n = [4.0, 5.0, -6.0];
        let mut a = [0.0; 3];
        let mut v = [0.0; 3];
        c.accelerations(&u, &u_n, &v_n, &a_n, &mut a).unwrap();
        c.velocities(&u, &u_n, &v_n, &a_n, &mut v).unwrap();
        for i in 0..3 {
            assert_eq!(a[i], c.acceleration(u[i], u_n[i], v_n[i], a_n[i]));
            assert_eq!(v[i], c.velocity(u[i], u_n[i], v_n[i], a_n[i]));
        }
        let err = c
            .accelerations(&u, &u_n[..2], &v_n, &a_n, &mut a)
            .unwrap_err();
        assert!(err.contains("u_n"), "{err}");
        let err = c.velocities(&u, &u_n, &v_n, &a_n, &mut v[..2]).unwrap_err();
        assert!(err.contains("out has 2"), "{err}");
    }

    #[test]
    fn trapezoidal_conserves_energy() {
        let (m, k): (f64, f64) = (2.0, 5.0);
        let omega = (k / m).sqrt();
        let nm = Newmark::trapezoidal();
        nm.validate().unwrap();
        // A coarse step (ωΔt = 0.5) and a huge one (ωΔt = 20): conservation
        // is exact for any Δt, not a small-step property.
        for dt in [0.5 / omega, 20.0 / omega] {
            let c = Coefficients::new(&nm, dt);
            let mut s = released(m, k);
            let e0 = energy(m, k, s);
            let mut worst = 0.0f64;
            for _ in 0..1000 {
                s = step(&c, m, k, s);
                worst = worst.max((energy(m, k, s) - e0).abs() / e0);
            }
            println!(
                "trapezoidal ωΔt = {:.1}: max energy drift {worst:.2e}",
                omega * dt
            );
            assert!(worst < 1e-12, "ωΔt = {}: drift {worst:e}", omega * dt);
        }
    }

    /// Phase `θ` with `(u, v/ω) = (cos θ, −sin θ)` after integrating
    /// `n_periods` periods with `steps_per_period` steps; exact: θ = 0 mod 2π.
    fn phase_error(steps_per_period: usize, n_periods: usize) -> f64 {
        let (m, k) = (1.0, 4.0 * PI * PI); // period 1
        let omega = (k / m).sqrt();
        let dt = 1.0 / steps_per_period as f64;
        let c = Coefficients::new(&Newmark::trapezoidal(), dt);
        let mut s = released(m, k);
        for _ in 0..steps_per_period * n_periods {
            s = step(&c, m, k, s);
        }
        // The numerical solution lags, so θ is negative; atan2 keeps it in
        // (−π, π], where a lag below half a turn stays unwrapped.
        (-s.v / omega).atan2(s.u)
    }

    #[test]
    fn trapezoidal_period_error_is_second_order() {
        let n_periods = 10;
        let coarse = phase_error(20, n_periods);
        let fine = phase_error(40, n_periods);
        let ratio = coarse / fine;
        println!("phase error at t = 10 T: {coarse:.6} (T/20), {fine:.6} (T/40), ratio {ratio:.4}");
        assert!((3.8..4.2).contains(&ratio), "ratio {ratio}");
        // The trapezoidal rule is a rotation by 2 atan(ωΔt/2) per step in the
        // (u, v/ω) plane; the computed phase must match that exactly.
        for (steps, got) in [(20usize, coarse), (40, fine)] {
            let wdt = 2.0 * PI / steps as f64;
            let lag = (steps * n_periods) as f64 * (2.0 * (wdt / 2.0).atan() - wdt);
            assert!((got - lag).abs() < 1e-10, "T/{steps}: {got} vs {lag}");
        }
    }

    #[test]
    fn dissipative_newmark_never_gains_energy() {
        let (m, k) = (1.0, 4.0 * PI * PI);
        let nm = Newmark::with_dissipation(0.6);
        nm.validate().unwrap();
        for steps_per_period in [20.0, 7.0, 0.3] {
            let dt = 1.0 / steps_per_period;
            let c = Coefficients::new(&nm, dt);
            let mut s = released(m, k);
            let e0 = energy(m, k, s);
            let mut prev_hat = algorithmic_energy(&nm, dt, m, k, s);
            let mut plain_rises = 0;
            let mut prev = e0;
            for n in 0..1000 {
                s = step(&c, m, k, s);
                let e_hat = algorithmic_energy(&nm, dt, m, k, s);
                // Slack for rounding only, relative to the starting energy.
                assert!(
                    e_hat <= prev_hat + 1e-15 * e0,
                    "Δt = T/{steps_per_period}, step {n}: Ê rose {prev_hat:e} -> {e_hat:e}"
                );
                let e = energy(m, k, s);
                if e > prev {
                    plain_rises += 1;
                }
                prev = e;
                prev_hat = e_hat;
            }
            println!(
                "γ = 0.6, Δt = T/{steps_per_period}: energy {e0:.3e} -> {prev:.3e}, \
                 plain energy rose in {plain_rises} of 1000 steps"
            );
            assert!(prev < 0.5 * e0, "γ = 0.6 should dissipate: {prev} of {e0}");
        }
    }

    /// Sampled once per period the plain mechanical energy decays strictly:
    /// the dissipation over a period (≈ 4πζE, ζ ≈ (γ − ½) ωΔt / 2) dwarfs
    /// the `(β − γ/2) Δt² ½ma²` by which E and Ê differ.
    #[test]
    fn dissipative_newmark_energy_decays_period_by_period() {
        let (m, k) = (1.0, 4.0 * PI * PI);
        let nm = Newmark::with_dissipation(0.6);
        let steps_per_period = 20;
        let c = Coefficients::new(&nm, 1.0 / steps_per_period as f64);
        let mut s = released(m, k);
        let mut prev = energy(m, k, s);
        for period in 0..50 {
            for _ in 0..steps_per_period {
                s = step(&c, m, k, s);
            }
            let e = energy(m, k, s);
            assert!(e < prev, "period {period}: {prev} -> {e}");
            prev = e;
        }
    }

    /// Largest relative change of the momentum `m1 v1 + m2 v2` over 1000
    /// steps of two masses joined by a spring, free-free. Newmark conserves
    /// it exactly in exact arithmetic: the spring forces cancel, so
    /// `m1 a1 + m2 a2 = 0` at every step and `v(u)` is affine in `a`.
    ///
    /// Each step solves `(a_u M + K) Δu = −M (a_v v_n + a_a a_n) − K u_n` for
    /// the increment, as Newton does. With `from_increment` the new
    /// acceleration and velocity are evaluated from that `Δu`; without it,
    /// from the stored `u_n + Δu` and `u_n`, whose difference has lost the
    /// rounding of `|u|` (growing with the distance travelled) and feeds it
    /// through `γ/(βΔt)` into the velocity.
    fn two_mass_momentum_drift(nm: Newmark, from_increment: bool) -> f64 {
        let (m1, m2, k) = (1.5, 0.4, 30.0);
        let c = Coefficients::new(&nm, 0.05);
        // Stretched spring plus a drift, so the momentum is not zero.
        let mut u = [0.0, 0.3];
        let mut v = [1.0, -0.5];
        let spring_force = |u: [f64; 2]| k * (u[1] - u[0]);
        let mut a = [spring_force(u) / m1, -spring_force(u) / m2];
        let p0 = m1 * v[0] + m2 * v[1];
        let mut worst = 0.0f64;
        for _ in 0..1000 {
            let f = spring_force(u);
            let r = [
                -m1 * (c.a_v * v[0] + c.a_a * a[0]) + f,
                -m2 * (c.a_v * v[1] + c.a_a * a[1]) - f,
            ];
            // K = k [[1, −1], [−1, 1]]; Cramer's rule on a_u M + K.
            let (k11, k12, k22) = (c.a_u * m1 + k, -k, c.a_u * m2 + k);
            let det = k11 * k22 - k12 * k12;
            let du = [
                (r[0] * k22 - k12 * r[1]) / det,
                (k11 * r[1] - k12 * r[0]) / det,
            ];
            let un = [u[0] + du[0], u[1] + du[1]];
            let (end, start) = if from_increment {
                (du, [0.0; 2])
            } else {
                (un, u)
            };
            let mut an = [0.0; 2];
            let mut vn = [0.0; 2];
            c.accelerations(&end, &start, &v, &a, &mut an).unwrap();
            c.velocities(&end, &start, &v, &a, &mut vn).unwrap();
            (u, v, a) = (un, vn, an);
            let p = m1 * v[0] + m2 * v[1];
            worst = worst.max((p - p0).abs() / p0.abs());
        }
        worst
    }

    #[test]
    fn two_masses_and_a_spring_conserve_momentum() {
        for nm in [Newmark::trapezoidal(), Newmark::with_dissipation(0.7)] {
            nm.validate().unwrap();
            let exact = two_mass_momentum_drift(nm, true);
            let stored = two_mass_momentum_drift(nm, false);
            println!(
                "{nm:?}: momentum drift {exact:.2e} from increments, {stored:.2e} from stored u"
            );
            assert!(exact < 1e-12, "{nm:?}: momentum drift {exact:e}");
            // Rounding of |u| ≈ 35 amplified by γ/(βΔt) = 40, random-walking
            // over 1000 steps: a few 1e-12, not a scheme error.
            assert!(stored < 1e-10, "{nm:?}: momentum drift {stored:e}");
        }
    }

    #[test]
    fn validate_names_the_bad_parameter() {
        // (parameters, a name the message must contain, one it must not).
        let cases = [
            (
                Newmark {
                    beta: 0.0,
                    gamma: 0.5,
                },
                "beta",
                "gamma",
            ),
            (
                Newmark {
                    beta: -0.25,
                    gamma: 0.5,
                },
                "beta",
                "gamma",
            ),
            (
                Newmark {
                    beta: 0.6,
                    gamma: 0.5,
                },
                "beta",
                "gamma",
            ),
            (
                Newmark {
                    beta: f64::NAN,
                    gamma: 0.5,
                },
                "beta",
                "gamma",
            ),
            (
                Newmark {
                    beta: 0.25,
                    gamma: 0.4,
                },
                "gamma",
                "beta",
            ),
            (
                Newmark {
                    beta: 0.25,
                    gamma: f64::NAN,
                },
                "gamma",
                "beta",
            ),
            (
                Newmark {
                    beta: 0.25,
                    gamma: f64::INFINITY,
                },
                "gamma",
                "beta",
            ),
            (Newmark::with_dissipation(0.3), "gamma", "beta"),
            // Each parameter fine alone, the pair outside the stable range.
            (
                Newmark {
                    beta: 0.3,
                    gamma: 0.7,
                },
                "gamma/2",
                "dt",
            ),
        ];
        for (nm, named, not_named) in cases {
            let err = nm.validate().unwrap_err();
            assert!(
                err.contains(named) && !err.contains(not_named),
                "{nm:?}: {err}"
            );
        }
        assert!(Newmark::trapezoidal().validate().is_ok());
        for gamma in [0.5, 0.5 + 1e-12, 0.5 + 1e-9, 0.55, 0.6, 0.75, 0.9] {
            let nm = Newmark::with_dissipation(gamma);
            assert!(nm.validate().is_ok(), "{nm:?}: {:?}", nm.validate());
        }
        for dt in [0.0, -1.0, f64::NAN, f64::INFINITY] {
            assert!(Newmark::validate_dt(dt).unwrap_err().contains("dt"));
        }
        assert!(Newmark::validate_dt(1e-3).is_ok());
    }
}

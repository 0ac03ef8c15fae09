//! Newton on the condensed contact system on one rank, with the iterates
//! Newton on the whole vector would take.
//!
//! On the Schur path J = K + Kc with Kc non-zero only on C, and K linear:
//! the rows off C of the residual, R_I(x) = (K x − b)_I, are linear in x,
//! and each exact Newton step x − λ y (y = J⁻¹ R) scales them by (1 − λ).
//! So from a step's start x0 they stay θ q (q = R(x0) off C, θ the product
//! of the (1 − λ) so far), and with h = K_CI K_II⁻¹ q_I the rows on C are
//! R_C(x) = L0 + S0 (x_C − x0_C) + (θ − 1) h + r_c(x_C), L0 the linear
//! part of R_C(x0) and r_c the contact residual. Newton's C part is
//! y_C = S⁻¹ (R_C − θ h) (S = S0 + D, the dense Schur complement).
//!
//! The SNES vector keeps x_C and carries θ off C as x0_I − (1 − θ) q_I (a
//! step y_I = θ q_I keeps that form for any line-search λ); the residual
//! norm is the whole vector's, so the line search, the convergence tests
//! and the iterates on C are Newton's on the whole vector. The interior
//! is formed once at the end (one solve with the factor): a step costs the
//! first Newton iteration's sparse solve (which also gives h) and that one,
//! where each Newton iteration took one before; every later iteration is a
//! dense solve on C, and each residual a dense product with S0 instead of
//! one with K.
use super::super::armed::Armed;
use super::layout::Layout;
use crate::petsc::{PetscError, Result, Vector};

/// The condensed Newton state of one load step (one rank).
#[derive(Default)]
pub struct Condensation {
    armed: Armed<Step>,
}

struct Step {
    layout: std::rc::Rc<Layout>,
    /// R(x0) off C (zero on C) and its squared norm.
    q: Vector,
    qq: f64,
    /// R(x0) on C and h, in Schur positions.
    f0: Vec<f64>,
    h: Vec<f64>,
    /// L0 = R_C(x0) − r_c(x0) (Schur positions), once the residual has
    /// given r_c(x0).
    lin0: Option<Vec<f64>>,
    /// Work vectors of |C| entries for the dense solves.
    rhs: Vector,
    sol: Vector,
}

impl Condensation {
    pub fn arm(&mut self, x0: &Vector) -> Result<()> {
        self.armed.arm(x0)
    }

    pub fn disarm(&mut self) {
        self.armed.disarm()
    }

    pub fn awaits_first_solve(&self) -> bool {
        self.armed.awaits_first_solve()
    }

    /// The SNES vector is the condensed one (residuals and steps below).
    pub fn is_active(&self) -> bool {
        self.armed.is_active()
    }

    /// Before the first condensed residual: the state whose contact
    /// residual L0 needs (None when it has it).
    pub fn base_wanted(&self) -> Option<&Vector> {
        self.armed.base_wanted(|s| s.lin0.is_none())
    }

    /// Gives L0 the contact residual `rc0` at x0 (whole vector; its
    /// constrained entries are ignored).
    pub fn set_base_contact(&mut self, rc0: &Vector) -> Result<()> {
        let Some(s) = self.armed.step.as_mut() else {
            return Ok(());
        };
        let rc = rc0.with_array(|a| s.layout.gather(a))?;
        let l = &s.layout;
        s.lin0 = Some(
            (0..l.c.len())
                .map(|p| if l.fixed[p] { s.f0[p] } else { s.f0[p] - rc[p] })
                .collect(),
        );
        Ok(())
    }

    /// The step's first solve: `b` = R(x0), `y` = J⁻¹ b solved whole, and
    /// `s_times` the product with S = S0 + D. Sets h = b_C − S y_C and q,
    /// and turns `y` into the condensed step (y_I = q_I).
    pub fn start(
        &mut self,
        layout: &std::rc::Rc<Layout>,
        s_times: impl Fn(&[f64]) -> Vec<f64>,
        b: &Vector,
        y: &mut Vector,
    ) -> Result<()> {
        let f0 = b.with_array(|a| layout.gather(a))?;
        let yc = y.with_array(|a| layout.gather(a))?;
        let sy = s_times(&yc);
        let h: Vec<f64> = (0..f0.len())
            .map(|p| if layout.fixed[p] { 0.0 } else { f0[p] - sy[p] })
            .collect();
        let mut q = b.duplicate()?;
        q.copy_from(b)?;
        q.with_array_mut(|a| layout.scatter(&vec![0.0; f0.len()], a))?;
        let qq = q.dot(&q)?;
        y.copy_from(&q)?;
        y.with_array_mut(|a| layout.scatter(&yc, a))?;
        let n = layout.c.len();
        self.armed.step = Some(Step {
            layout: layout.clone(),
            q,
            qq,
            f0,
            h,
            lin0: None,
            rhs: Vector::new_mpi(n)?,
            sol: Vector::new_mpi(n)?,
        });
        Ok(())
    }

    fn parts(&self) -> Result<(&Vector, &Step)> {
        match (&self.armed.x0, &self.armed.step) {
            (Some(x0), Some(s)) => Ok((x0, s)),
            _ => Err(PetscError::new(
                "Condensation",
                "used outside a condensed step".into(),
            )),
        }
    }

    /// θ of the condensed vector `x` (the factor left of R(x0) off C).
    fn theta(x0: &Vector, s: &Step, x: &Vector) -> Result<f64> {
        if s.qq == 0.0 {
            return Ok(0.0);
        }
        // (x0 − x)·q summed as differences: x_I − x0_I is −(1 − θ) q_I,
        // small against x0 where q is.
        let moved = x0.with_array(|a0| {
            x.with_array(|a| {
                s.q.with_array(|q| {
                    a0.iter()
                        .zip(a)
                        .zip(q)
                        .map(|((a0, a), q)| (a0 - a) * q)
                        .sum::<f64>()
                })
            })
        })???;
        Ok(1.0 - moved / s.qq)
    }

    /// x_C − x0_C in Schur positions.
    fn moved(x0: &Vector, s: &Step, x: &Vector) -> Result<Vec<f64>> {
        let a = x.with_array(|a| s.layout.gather(a))?;
        let b = x0.with_array(|a| s.layout.gather(a))?;
        Ok(a.iter().zip(&b).map(|(a, b)| a - b).collect())
    }

    /// The residual at the condensed vector `x` from the contact residual
    /// `rc` there (whole vector, constrained entries ignored).
    pub fn residual(&self, x: &Vector, rc: &Vector, out: &mut Vector) -> Result<()> {
        let (x0, s) = self.parts()?;
        let lin0 = s
            .lin0
            .as_ref()
            .ok_or_else(|| PetscError::new("Condensation::residual", "L0 not set".into()))?;
        let theta = Self::theta(x0, s, x)?;
        let sd = s.layout.times_base(&Self::moved(x0, s, x)?);
        let r = rc.with_array(|a| s.layout.gather(a))?;
        let l = &s.layout;
        let on_c: Vec<f64> = (0..l.c.len())
            .map(|p| {
                let contact = if l.fixed[p] { 0.0 } else { r[p] };
                lin0[p] + sd[p] + (theta - 1.0) * s.h[p] + contact
            })
            .collect();
        out.copy_from(&s.q)?;
        out.scale(theta)?;
        out.with_array_mut(|a| l.scatter(&on_c, a))
    }

    /// The condensed Newton step y for the right-hand side `b` (a residual
    /// of the condensed form): y_C = S⁻¹ (b_C − θ_b h), y_I = θ_b q_I.
    /// `solve_schur` solves with the factored S (vectors in positions).
    pub fn step(
        &mut self,
        solve_schur: impl FnOnce(&Vector, &mut Vector) -> Result<()>,
        b: &Vector,
        y: &mut Vector,
    ) -> Result<()> {
        let Some(s) = self.armed.step.as_mut() else {
            return Err(PetscError::new(
                "Condensation::step",
                "no condensed step".into(),
            ));
        };
        let theta = if s.qq == 0.0 {
            0.0
        } else {
            b.dot(&s.q)? / s.qq
        };
        let bc = b.with_array(|a| s.layout.gather(a))?;
        let h = &s.h;
        s.rhs.with_array_mut(|a| {
            for (p, v) in a.iter_mut().enumerate() {
                *v = bc[p] - theta * h[p];
            }
        })?;
        solve_schur(&s.rhs, &mut s.sol)?;
        let yc = s.sol.with_array(|a| a.to_vec())?;
        y.copy_from(&s.q)?;
        y.scale(theta)?;
        y.with_array_mut(|a| s.layout.scatter(&yc, a))
    }

    /// Ends the step: the condensed vector `x` becomes the whole state
    /// (x_C kept; x_I = x0_I + w_I with K_II w_I + K_IC Δ_C = (θ − 1) q_I,
    /// Δ_C = x_C − x0_C). `s_times` multiplies by S = S0 + D and `solve`
    /// solves with J = K + Kc, whose Schur complement is that S: w solves
    /// J w = [(θ − 1) q_I; S Δ_C + (θ − 1) h].
    pub fn expand(
        &mut self,
        s_times: impl Fn(&[f64]) -> Vec<f64>,
        solve: impl FnOnce(&Vector, &mut Vector) -> Result<()>,
        x: &mut Vector,
    ) -> Result<()> {
        let (x0, s) = self.parts()?;
        let theta = Self::theta(x0, s, x)?;
        let delta = Self::moved(x0, s, x)?;
        let sd = s_times(&delta);
        let t: Vec<f64> = (0..delta.len())
            .map(|p| sd[p] + (theta - 1.0) * s.h[p])
            .collect();
        let mut rhs = s.q.duplicate()?;
        rhs.copy_from(&s.q)?;
        rhs.scale(theta - 1.0)?;
        rhs.with_array_mut(|a| s.layout.scatter(&t, a))?;
        let mut w = rhs.duplicate()?;
        solve(&rhs, &mut w)?;
        let xc = x.with_array(|a| s.layout.gather(a))?;
        x.copy_from(x0)?;
        x.axpy(1.0, &w)?;
        let layout = s.layout.clone();
        x.with_array_mut(|a| layout.scatter(&xc, a))?;
        self.disarm();
        Ok(())
    }
}

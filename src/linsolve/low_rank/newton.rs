//! Newton on the condensed contact system on several ranks: the iterates
//! Newton on the whole vector would take, with K's factor used twice per
//! load step instead of twice per Newton iteration.
//!
//! K stands for the factored K + A and ρ(x_C) = r_c(x_C) − A x_C for the
//! contact residual less the shift (as in the module above), so that
//! R(x) = K x − f + P ρ(x_C). From a step's start x0, with b0 = R(x0),
//! z = K⁻¹ b0 (the step's first solve) and ρ0 = ρ(x0_C), every iterate of
//! the exact Newton steps is
//!
//!   x = x0 + (θ − 1) z + K⁻¹ P s,   R(x) = θ b0 + P (s + ρ(x_C) − ρ0),
//!
//! for a scalar θ and forces s on W, the positions of C whose columns of
//! G = Pᵀ K⁻¹ P are known (rows on all of C). A step y = J⁻¹ b for such a
//! residual b (θ_b = b·q / q·q, q = b0 off C; σ = b_C − θ_b b0_C) is
//! y = θ_b z + K⁻¹ P t with (I + D G) t = σ − θ_b D z_C, so y_C = θ_b z_C +
//! G t: dense work on rank 0, no solve. x − λ y keeps the form (θ − λ θ_b,
//! s − λ t).
//!
//! As on one rank (`schur::newton`), the SNES vector holds the true x_C
//! and carries θ off C as x0_I − (1 − θ) q_I, so the line search and the
//! convergence tests are Newton's on the whole vector; s is read back from
//! x_W as G_WW⁻¹ (x_W − x0_W − (θ − 1) z_W). The interior is formed once,
//! when the step ends (one solve for K⁻¹ P s).
use super::super::armed::Armed;
use super::{at_c, LowRankPreconditioner};
use crate::petsc::{PetscError, Result, Scatter, Vector};
use nalgebra::{DMatrix, DVector};
use std::cell::RefCell;
use std::rc::Rc;

/// G_WW on rank 0, factored: W's positions in C and the factor that
/// recovers s from x_W.
#[derive(Default)]
pub(super) struct Window {
    pub(super) w: Vec<usize>,
    factor: Option<WindowFactor>,
}

enum WindowFactor {
    Cholesky(nalgebra::Cholesky<f64, nalgebra::Dyn>),
    Lu(nalgebra::LU<f64, nalgebra::Dyn, nalgebra::Dyn>),
}

impl Window {
    /// W = `w` with G column-major |C| × |C| (valid on C × W). G_WW is
    /// symmetric positive definite when K is on the free DOFs; LU when
    /// rounding makes the Cholesky fail.
    pub(super) fn new(w: Vec<usize>, g: &[f64], n: usize) -> Result<Self> {
        let m = DMatrix::from_fn(w.len(), w.len(), |i, j| g[w[j] * n + w[i]]);
        let factor = match nalgebra::Cholesky::new(m.clone()) {
            Some(c) => WindowFactor::Cholesky(c),
            None => {
                let lu = m.lu();
                if !lu.is_invertible() {
                    return Err(PetscError::new(
                        "condensed Newton",
                        format!("G on the {} contact DOFs W is singular", w.len()),
                    ));
                }
                WindowFactor::Lu(lu)
            }
        };
        Ok(Window {
            w,
            factor: Some(factor),
        })
    }

    /// G_WW⁻¹ d (empty W: empty).
    fn solve(&self, d: Vec<f64>) -> Result<Vec<f64>> {
        let d = DVector::from_vec(d);
        let s = match &self.factor {
            None => return Ok(Vec::new()),
            Some(WindowFactor::Cholesky(c)) => c.solve(&d),
            Some(WindowFactor::Lu(lu)) => lu
                .solve(&d)
                .ok_or_else(|| PetscError::new("condensed Newton", "G_WW is singular".into()))?,
        };
        Ok(s.iter().copied().collect())
    }
}

/// The condensed Newton state of one load step (every rank; the C parts
/// on rank 0, empty elsewhere).
#[derive(Default)]
pub struct Reduced {
    armed: Armed<Step>,
    pub(super) window: Window,
}

pub(super) struct Step {
    /// b0 off C (zero on C), its squared norm, and z = K⁻¹ b0.
    q: Vector,
    qq: f64,
    z: Vector,
    /// Rank 0, at C's positions: b0, z, x0, the shift A, the fixed
    /// positions, and ρ0's contact part r_c(x0) once the first condensed
    /// residual has given it.
    pub(super) b0: Vec<f64>,
    pub(super) zc: Vec<f64>,
    x0c: Vec<f64>,
    shift: Vec<f64>,
    pub(super) fixed: Vec<bool>,
    rc0: Option<Vec<f64>>,
    /// Full vector → C on rank 0, with its own sequential vector.
    pick: Scatter,
    small: Vector,
    work: Vector,
}

impl Step {
    pub(super) fn gather(&mut self, v: &Vector) -> Result<Vec<f64>> {
        at_c(&self.pick, v, &mut self.small)
    }

    /// `out` = `scale` · q + P `on_c` (`on_c` rank 0's, empty elsewhere).
    /// Collective.
    pub(super) fn compose(&mut self, scale: f64, on_c: &[f64], out: &mut Vector) -> Result<()> {
        out.copy_from(&self.q)?;
        out.scale(scale)?;
        self.small.with_array_mut(|a| a.copy_from_slice(on_c))?;
        self.pick.reverse_add(&self.small, out)
    }

    /// b·q / q·q: the θ of a residual of the condensed form. Collective.
    pub(super) fn theta_of(&self, b: &Vector) -> Result<f64> {
        if self.qq == 0.0 {
            return Ok(0.0);
        }
        Ok(b.dot(&self.q)? / self.qq)
    }

    /// θ of the condensed vector `x` (x_I = x0_I − (1 − θ) q_I). Collective.
    fn theta(&mut self, x0: &Vector, x: &Vector) -> Result<f64> {
        if self.qq == 0.0 {
            return Ok(0.0);
        }
        self.work.copy_from(x0)?;
        self.work.axpy(-1.0, x)?;
        Ok(1.0 - self.work.dot(&self.q)? / self.qq)
    }

    /// Rank 0: s on W from x_C (see the module's comment).
    fn forces(&self, window: &Window, theta: f64, xc: &[f64]) -> Result<Vec<f64>> {
        let d = window
            .w
            .iter()
            .map(|&p| xc[p] - self.x0c[p] - (theta - 1.0) * self.zc[p])
            .collect();
        window.solve(d)
    }
}

impl Reduced {
    pub fn arm(&mut self, x0: &Vector) -> Result<()> {
        self.armed.arm(x0)
    }

    pub fn disarm(&mut self) {
        self.armed.disarm()
    }

    pub fn awaits_first_solve(&self) -> bool {
        self.armed.awaits_first_solve()
    }

    pub fn is_active(&self) -> bool {
        self.armed.is_active()
    }

    /// Before the first condensed residual: the state whose contact
    /// residual ρ0 needs (None when it has it).
    pub fn base_wanted(&self) -> Option<&Vector> {
        self.armed.base_wanted(|s| s.rc0.is_none())
    }

    /// Gives ρ0 the contact residual `rc0` at x0 (whole vector).
    /// Collective.
    pub fn set_base_contact(&mut self, rc0: &Vector) -> Result<()> {
        if let Some(s) = self.armed.step.as_mut() {
            s.rc0 = Some(s.gather(rc0)?);
        }
        Ok(())
    }

    /// The step's first solve gave z = K⁻¹ `b` (`b` = R(x0)); `pick` is
    /// the preconditioner's scatter onto C (shared here), `shift` and
    /// `fixed` C's (rank 0). Collective.
    pub(super) fn start(
        &mut self,
        b: &Vector,
        z: &Vector,
        pick: &Scatter,
        shift: &[f64],
        fixed: &[bool],
    ) -> Result<()> {
        let x0 = self
            .armed
            .x0
            .as_ref()
            .ok_or_else(|| PetscError::new("Reduced::start", "not armed".into()))?;
        let pick = pick.share()?;
        let mut small = Vector::new_seq(fixed.len())?;
        let b0 = at_c(&pick, b, &mut small)?;
        let zc = at_c(&pick, z, &mut small)?;
        let x0c = at_c(&pick, x0, &mut small)?;
        let mut q = b.duplicate()?;
        q.copy_from(b)?;
        // q = b − P b_C: zero on C exactly.
        small.with_array_mut(|a| a.iter_mut().zip(&b0).for_each(|(v, b)| *v = -b))?;
        pick.reverse_add(&small, &mut q)?;
        let qq = q.dot(&q)?;
        let mut zz = z.duplicate()?;
        zz.copy_from(z)?;
        self.armed.step = Some(Step {
            work: q.duplicate()?,
            q,
            qq,
            z: zz,
            b0,
            zc,
            x0c,
            shift: shift.to_vec(),
            fixed: fixed.to_vec(),
            rc0: None,
            pick,
            small,
        });
        Ok(())
    }

    /// The residual at the condensed vector `x` from the contact residual
    /// `rc` there (whole vector, constrained entries ignored). Collective;
    /// a failure on rank 0 leaves non-finite entries and is returned there.
    pub fn residual(&mut self, x: &Vector, rc: &Vector, out: &mut Vector) -> Result<()> {
        let (Some(x0), Some(s)) = (&self.armed.x0, self.armed.step.as_mut()) else {
            return Err(PetscError::new(
                "Reduced::residual",
                "no condensed step".into(),
            ));
        };
        let theta = s.theta(x0, x)?;
        let xc = s.gather(x)?;
        let r = s.gather(rc)?;
        let local = match xc.is_empty() {
            true => Ok(Vec::new()),
            false => Self::residual_on_c(s, &self.window, theta, &xc, &r),
        };
        let on_c = match &local {
            Ok(v) => v.clone(),
            Err(_) => vec![f64::NAN; xc.len()],
        };
        s.compose(theta, &on_c, out)?;
        local.map(|_| ())
    }

    /// Rank 0: R_C = θ b0_C + s + r_c(x_C) − r_c(x0_C) − A (x_C − x0_C),
    /// b0's entries alone at the fixed positions.
    fn residual_on_c(
        s: &Step,
        window: &Window,
        theta: f64,
        xc: &[f64],
        r: &[f64],
    ) -> Result<Vec<f64>> {
        let rc0 = s
            .rc0
            .as_ref()
            .ok_or_else(|| PetscError::new("Reduced::residual", "ρ0 not set".into()))?;
        let mut out: Vec<f64> = (0..xc.len())
            .map(|p| {
                let contact = match s.fixed[p] {
                    true => 0.0,
                    false => {
                        let a = s.shift.get(p).copied().unwrap_or(0.0);
                        r[p] - rc0[p] - a * (xc[p] - s.x0c[p])
                    }
                };
                theta * s.b0[p] + contact
            })
            .collect();
        let forces = s.forces(window, theta, xc)?;
        for (&p, f) in window.w.iter().zip(forces) {
            out[p] += f;
        }
        Ok(out)
    }

    /// Ends the step, first part: θ of the condensed vector `x` and x_C
    /// (rank 0). Collective.
    pub(super) fn theta_and_c(&mut self, x: &Vector) -> Result<(f64, Vec<f64>)> {
        let (Some(x0), Some(s)) = (&self.armed.x0, self.armed.step.as_mut()) else {
            return Err(PetscError::new(
                "Reduced::expand",
                "no condensed step".into(),
            ));
        };
        let theta = s.theta(x0, x)?;
        Ok((theta, s.gather(x)?))
    }

    /// Rank 0: s at C's positions (zero off W) for θ and x_C.
    pub(super) fn forces_on_c(&self, theta: f64, xc: &[f64]) -> Result<Vec<f64>> {
        let s = self
            .armed
            .step
            .as_ref()
            .ok_or_else(|| PetscError::new("Reduced::expand", "no condensed step".into()))?;
        let mut out = vec![0.0; xc.len()];
        let f = s.forces(&self.window, theta, xc)?;
        for (&p, v) in self.window.w.iter().zip(f) {
            out[p] = v;
        }
        Ok(out)
    }

    /// Ends the step: x = x0 + (θ − 1) z + `w` (`w` = K⁻¹ P s), with x_C
    /// kept as the condensed vector had it (`xc`, rank 0). Collective.
    pub(super) fn finish(
        &mut self,
        x: &mut Vector,
        theta: f64,
        w: &Vector,
        xc: &[f64],
    ) -> Result<()> {
        let (Some(x0), Some(s)) = (&self.armed.x0, self.armed.step.as_mut()) else {
            return Err(PetscError::new(
                "Reduced::expand",
                "no condensed step".into(),
            ));
        };
        x.copy_from(x0)?;
        x.axpy(theta - 1.0, &s.z)?;
        x.axpy(1.0, w)?;
        let now = s.gather(x)?;
        let fix: Vec<f64> = xc.iter().zip(&now).map(|(a, b)| a - b).collect();
        s.small.with_array_mut(|a| a.copy_from_slice(&fix))?;
        s.pick.reverse_add(&s.small, x)?;
        self.disarm();
        Ok(())
    }
}

/// The positions of `v` (rank 0's, at C's positions) with a non-zero
/// entry, not fixed, and not yet in `known`.
pub(super) fn outside(v: &[f64], fixed: &[bool], known: &[bool]) -> Vec<usize> {
    (0..v.len())
        .filter(|&p| v[p] != 0.0 && !fixed[p] && !known[p])
        .collect()
}

impl LowRankPreconditioner {
    /// Turns on Newton on the condensed system: the returned state is the
    /// one the residual reads. G's new columns are then computed at every
    /// row of C (the steps need x on all of C).
    pub fn condense(&mut self) -> Rc<RefCell<Reduced>> {
        self.reduced
            .get_or_insert_with(|| Rc::new(RefCell::new(Reduced::default())))
            .clone()
    }

    /// A load step starts at `x0` (condensed Newton only).
    pub fn arm(&mut self, x0: &Vector) -> Result<()> {
        match &self.reduced {
            Some(r) => r.borrow_mut().arm(x0),
            None => Ok(()),
        }
    }

    /// The step failed: its condensed state is dropped.
    pub fn disarm(&mut self) {
        if let Some(r) = &self.reduced {
            r.borrow_mut().disarm();
        }
    }

    /// The step converged: the condensed vector `x` becomes the whole
    /// state (one solve with K's factor), when it is condensed. Collective.
    pub fn expand(&mut self, x: &mut Vector) -> Result<()> {
        let Some(r) = self.reduced.clone() else {
            return Ok(());
        };
        let mut r = r.borrow_mut();
        if !r.is_active() {
            r.disarm();
            return Ok(());
        }
        let (theta, xc) = r.theta_and_c(x)?;
        let local = match self.root {
            true => r.forces_on_c(theta, &xc),
            false => Ok(Vec::new()),
        };
        let Some(forces) = self.agreed(local)? else {
            r.disarm();
            return Err(PetscError::new(
                "condensed Newton",
                self.failed.clone().unwrap_or_default(),
            ));
        };
        let (Some(t), Some(z), Some(small), Some(pick), Some(factor)) = (
            &mut self.t,
            &mut self.z,
            &mut self.small,
            &self.pick,
            &self.factor,
        ) else {
            return Err(PetscError::new(
                "condensed Newton",
                "no work vectors".into(),
            ));
        };
        t.set_all(0.0)?;
        small.with_array_mut(|a| a.copy_from_slice(&forces))?;
        pick.reverse_add(small, t)?;
        factor.solve(t, z)?;
        self.sparse_solves += 1;
        r.finish(x, theta, z, &xc)
    }

    /// x = J⁻¹ b as a condensed step (the step's first solve whole, then
    /// dense work on rank 0 alone). Collective.
    pub(super) fn condensed_apply(
        &mut self,
        r: &Rc<RefCell<Reduced>>,
        b: &Vector,
        x: &mut Vector,
    ) -> Result<()> {
        let mut red = r.borrow_mut();
        if red.awaits_first_solve() {
            let (Some(z), Some(pick), Some(factor)) = (&mut self.z, &self.pick, &self.factor)
            else {
                return Err(PetscError::new("condensed Newton", "no work vector".into()));
            };
            factor.solve(b, z)?;
            self.sparse_solves += 1;
            // C's parts live on rank 0 alone.
            let fixed: &[bool] = if self.root { &self.fixed } else { &[] };
            red.start(b, z, pick, &self.shift_c, fixed)?;
        }
        let Reduced { armed, window } = &mut *red;
        let s = armed
            .step
            .as_mut()
            .ok_or_else(|| PetscError::new("condensed Newton", "no condensed step".into()))?;
        let theta = s.theta_of(b)?;
        let bc = s.gather(b)?;
        let sigma: Vec<f64> = (0..bc.len())
            .map(|p| match s.fixed[p] {
                true => 0.0,
                false => bc[p] - theta * s.b0[p],
            })
            .collect();
        // A link that closed where no set-up has looked yet: its columns.
        let new = match self.root {
            true => outside(&sigma, &s.fixed, &self.known),
            false => Vec::new(),
        };
        if self.widen(&new)? {
            self.refresh_window(window)?;
        }
        let local = match (self.failed.is_some(), self.root) {
            (true, _) => Err(PetscError::new("condensed Newton", "failed set-up".into())),
            (false, true) => self.dense_step(theta, sigma, &s.zc),
            (false, false) => Ok(Vec::new()),
        };
        self.dense_steps += 1;
        let finite = matches!(&local, Ok(y) if y.iter().all(|v| v.is_finite()));
        if (self.any_rank)(!finite) {
            if self.failed.is_none() {
                self.failed = Some(match local {
                    Err(e) => e.to_string(),
                    Ok(_) => "the condensed contact step is not finite".into(),
                });
            }
            return x.set_all(f64::INFINITY);
        }
        s.compose(theta, &local?, x)
    }

    /// Rank 0: y_C = θ z_C + G t with (I + D G) t = σ − θ D z_C, t zero
    /// off W (rows of M off U are the identity's: t = σ there).
    fn dense_step(&mut self, theta: f64, mut t: Vec<f64>, zc: &[f64]) -> Result<Vec<f64>> {
        let n = self.c.len();
        for &i in &self.u {
            t[i] -= theta * self.d.row(i).map(|(k, v)| v * zc[k]).sum::<f64>();
        }
        let mut in_u = vec![false; n];
        for &i in &self.u {
            in_u[i] = true;
        }
        let outer: Vec<usize> = (0..n).filter(|&j| t[j] != 0.0 && !in_u[j]).collect();
        if let Some(&j) = outer.iter().find(|&&j| !self.known[j]) {
            return Err(PetscError::new(
                "condensed Newton",
                format!("no column of G at DOF {}", self.c[j]),
            ));
        }
        if let (Some(m), Some(rhs), Some(sol)) = (&self.m, self.m_rhs.as_mut(), self.m_sol.as_mut())
        {
            // G t_outer at U's rows, then M_UU t_U = rhs_U − D (G t_outer).
            let mut g_outer = vec![0.0; n];
            for &k in &self.u {
                g_outer[k] = outer.iter().map(|&j| self.g[j * n + k] * t[j]).sum();
            }
            let (d, u) = (&self.d, &self.u);
            rhs.with_array_mut(|a| {
                for (v, &i) in a.iter_mut().zip(u) {
                    *v = t[i] - d.row(i).map(|(k, dv)| dv * g_outer[k]).sum::<f64>();
                }
            })?;
            // M_UU is factored: the set-up succeeded on every rank before
            // any solve.
            m.solve(rhs, sol)?;
            sol.with_array(|a| {
                for (&i, &v) in u.iter().zip(a) {
                    t[i] = v;
                }
            })?;
        }
        let mut y: Vec<f64> = zc.iter().map(|z| theta * z).collect();
        for (j, &tj) in t.iter().enumerate() {
            if tj == 0.0 {
                continue;
            }
            let col = &self.g[j * n..(j + 1) * n];
            for (yo, g) in y.iter_mut().zip(col) {
                *yo += g * tj;
            }
        }
        Ok(y)
    }

    /// G's columns at the positions `new` (rank 0's; agreed whether any).
    /// Whether any came. Collective.
    fn widen(&mut self, new: &[usize]) -> Result<bool> {
        if !(self.any_rank)(!new.is_empty()) {
            return Ok(false);
        }
        self.request_columns(new, true)?;
        Ok(true)
    }

    /// W = the known columns, G_WW factored on rank 0 (agreed). Collective.
    pub(super) fn refresh_window(&mut self, window: &mut Window) -> Result<()> {
        let local = match self.root {
            true => {
                let w: Vec<usize> = (0..self.known.len()).filter(|&p| self.known[p]).collect();
                Window::new(w, &self.g, self.c.len())
            }
            false => Ok(Window::default()),
        };
        *window = self.agreed(local)?.unwrap_or_default();
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// G column-major n × n from a row-major listing.
    fn column_major(rows: &[&[f64]]) -> Vec<f64> {
        let n = rows.len();
        (0..n * n).map(|k| rows[k % n][k / n]).collect()
    }

    #[test]
    fn the_window_recovers_forces_from_g_ww() {
        // W = {0, 2} of a 3 × 3 G: G_WW = [[4, 1], [1, 3]].
        let g = column_major(&[&[4.0, 9.0, 1.0], &[9.0, 7.0, 9.0], &[1.0, 9.0, 3.0]]);
        let w = Window::new(vec![0, 2], &g, 3).unwrap();
        // G_WW (2, −1) = (7, −1).
        let s = w.solve(vec![7.0, -1.0]).unwrap();
        assert!(
            (s[0] - 2.0).abs() < 1e-14 && (s[1] + 1.0).abs() < 1e-14,
            "{s:?}"
        );
    }

    #[test]
    fn an_indefinite_g_ww_falls_back_to_lu_and_a_singular_one_is_an_error() {
        let g = column_major(&[&[1.0, 2.0], &[2.0, 1.0]]);
        let w = Window::new(vec![0, 1], &g, 2).unwrap();
        let s = w.solve(vec![3.0, 3.0]).unwrap();
        assert!(
            (s[0] - 1.0).abs() < 1e-14 && (s[1] - 1.0).abs() < 1e-14,
            "{s:?}"
        );
        let singular = column_major(&[&[1.0, 1.0], &[1.0, 1.0]]);
        let e = Window::new(vec![0, 1], &singular, 2).err().unwrap();
        assert!(e.to_string().contains("singular"), "{e}");
    }

    #[test]
    fn an_empty_window_gives_no_forces() {
        assert!(Window::default().solve(Vec::new()).unwrap().is_empty());
    }

    #[test]
    fn outside_lists_the_loaded_free_unknown_positions() {
        let v = [0.0, 1.0, 2.0, 3.0, -1.0];
        let fixed = [false, false, true, false, false];
        let known = [false, true, false, false, false];
        assert_eq!(outside(&v, &fixed, &known), vec![3, 4]);
    }
}

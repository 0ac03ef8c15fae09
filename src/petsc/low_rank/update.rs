//! The dense part on rank 0: D read from the contact tangent, M_UU =
//! I + D_UU G_UU and its LU per set-up, and y = M_UU⁻¹ (D z_C)_U per solve.
use super::super::shell::error;
use super::super::{petsc_call, sys, to_petsc_int, Matrix, Result, Vector};
use super::sparse::{gather_sparse, Sparse};
use super::{self_comm, LowRankPreconditioner, OwnedMat};

impl LowRankPreconditioner {
    /// D from `kc` onto rank 0 (empty elsewhere). Collective.
    pub(super) fn read_tangent(&mut self, kc: &Matrix) -> Result<Sparse> {
        gather_sparse(kc.raw(), &self.c, &self.fixed)
    }

    /// Rank 0: M_UU = I + D_UU G_UU, column by column (D sparse), and its
    /// LU; nothing to factor when U is empty (no contact acts).
    pub(super) fn factor_dense(&mut self) -> Result<()> {
        let (n, u) = (self.c.len(), &self.u);
        let nu = u.len();
        self.m = OwnedMat(std::ptr::null_mut());
        self.m_rhs = None;
        self.m_sol = None;
        if nu == 0 {
            return Ok(());
        }
        let len = to_petsc_int(nu)?;
        let mut m = OwnedMat(std::ptr::null_mut());
        let (mut rhs, mut sol): (sys::Vec, sys::Vec) = (std::ptr::null_mut(), std::ptr::null_mut());
        // SAFETY: a new sequential dense matrix of |U| × |U|, its array
        // (column-major, leading dimension |U| as created with no user
        // array) written only between Get and Restore; the vectors go to
        // owning wrappers at once.
        unsafe {
            petsc_call!(MatCreateSeqDense(
                self_comm(),
                len,
                len,
                std::ptr::null_mut(),
                &mut m.0
            ))?;
            let mut a: *mut f64 = std::ptr::null_mut();
            petsc_call!(MatDenseGetArrayWrite(m.0, &mut a))?;
            let out = std::slice::from_raw_parts_mut(a, nu * nu);
            let mut finite = true;
            for (j, &cj) in u.iter().enumerate() {
                // G's column at U's position cj (valid at every row of U).
                let g = &self.g[cj * n..(cj + 1) * n];
                let col = &mut out[j * nu..(j + 1) * nu];
                for (i, (v, &ci)) in col.iter_mut().zip(u).enumerate() {
                    let s: f64 = self.d.row(ci).map(|(k, d)| d * g[k]).sum();
                    *v = s + if i == j { 1.0 } else { 0.0 };
                    finite &= v.is_finite();
                }
            }
            petsc_call!(MatDenseRestoreArrayWrite(m.0, &mut a))?;
            if !finite {
                return Err(error(
                    "LowRankPreconditioner::update",
                    "the contact tangent is not finite".into(),
                ));
            }
            let mut info = sys::MatFactorInfo::default();
            petsc_call!(MatFactorInfoInitialize(&mut info))?;
            petsc_call!(MatLUFactor(
                m.0,
                std::ptr::null_mut(),
                std::ptr::null_mut(),
                &info
            ))?;
            petsc_call!(VecCreateSeq(self_comm(), len, &mut rhs))?;
            self.m_rhs = Some(Vector::owned_from_raw(rhs));
            petsc_call!(VecCreateSeq(self_comm(), len, &mut sol))?;
            self.m_sol = Some(Vector::owned_from_raw(sol));
        }
        self.m = m;
        Ok(())
    }
}

/// Rank 0's share of a solve: the last set-up's D, U and M_UU's factors.
pub(super) struct Update<'a> {
    pub(super) d: &'a Sparse,
    pub(super) u: &'a [usize],
    pub(super) m: sys::Mat,
    pub(super) rhs: Option<&'a mut Vector>,
    pub(super) sol: Option<&'a mut Vector>,
}

impl Update<'_> {
    /// `small`: z_C in, y = M⁻¹ D z_C out (zero outside U). Whether y is
    /// finite.
    pub(super) fn solve(self, small: &mut Vector) -> Result<bool> {
        let zc: Vec<f64> = small.with_array(|a| a.to_vec())?;
        let (Some(rhs), Some(sol)) = (self.rhs, self.sol) else {
            // U is empty: D is zero.
            small.set_all(0.0)?;
            return Ok(true);
        };
        let (d, u) = (self.d, self.u);
        rhs.with_array_mut(|r| {
            for (v, &i) in r.iter_mut().zip(u) {
                *v = d.row(i).map(|(k, dv)| dv * zc[k]).sum();
            }
        })?;
        // SAFETY: M_UU is factored (the set-up succeeded on every rank
        // before any solve); sequential vectors of its size.
        unsafe { petsc_call!(MatSolve(self.m, rhs.raw(), sol.raw()))? };
        let y: Vec<f64> = sol.with_array(|a| a.to_vec())?;
        small.with_array_mut(|out| {
            out.fill(0.0);
            for (&i, &v) in u.iter().zip(&y) {
                out[i] = v;
            }
        })?;
        Ok(y.iter().all(|v| v.is_finite()))
    }
}

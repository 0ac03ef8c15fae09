//! The dense part on rank 0: D read from the contact tangent, M_UU =
//! I + D_UU G_UU and its LU per set-up, and y = M_UU⁻¹ (D z_C)_U per solve.
use super::sparse::{gather_sparse, Sparse};
use super::LowRankPreconditioner;
use crate::petsc::{DenseMatrix, Matrix, PetscError, Result, Vector};

impl LowRankPreconditioner {
    /// D from `kc` onto rank 0 (empty elsewhere). Collective.
    pub(super) fn read_tangent(&mut self, kc: &Matrix) -> Result<Sparse> {
        gather_sparse(kc, &self.c, &self.fixed)
    }

    /// Rank 0: M_UU = I + D_UU G_UU, column by column (D sparse), and its
    /// LU; nothing to factor when U is empty (no contact acts).
    pub(super) fn factor_dense(&mut self) -> Result<()> {
        let (n, u) = (self.c.len(), &self.u);
        let nu = u.len();
        self.m = None;
        self.m_rhs = None;
        self.m_sol = None;
        if nu == 0 {
            return Ok(());
        }
        let mut m = DenseMatrix::new_seq(nu, nu)?;
        // Column-major, leading dimension |U|.
        let finite = m.with_array_write(|out| {
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
            finite
        })?;
        if !finite {
            return Err(PetscError::new(
                "LowRankPreconditioner::update",
                "the contact tangent is not finite".into(),
            ));
        }
        m.lu_factor()?;
        self.m_rhs = Some(Vector::new_seq(nu)?);
        self.m_sol = Some(Vector::new_seq(nu)?);
        self.m = Some(m);
        Ok(())
    }
}

/// Rank 0's share of a solve: the last set-up's D, U and M_UU's factors.
pub(super) struct Update<'a> {
    pub(super) d: &'a Sparse,
    pub(super) u: &'a [usize],
    pub(super) m: Option<&'a DenseMatrix>,
    pub(super) rhs: Option<&'a mut Vector>,
    pub(super) sol: Option<&'a mut Vector>,
}

impl Update<'_> {
    /// `small`: z_C in, y = M⁻¹ D z_C out (zero outside U). Whether y is
    /// finite.
    pub(super) fn solve(self, small: &mut Vector) -> Result<bool> {
        let zc: Vec<f64> = small.with_array(|a| a.to_vec())?;
        let (Some(m), Some(rhs), Some(sol)) = (self.m, self.rhs, self.sol) else {
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
        // M_UU is factored: the set-up succeeded on every rank before any
        // solve.
        m.solve(rhs, sol)?;
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

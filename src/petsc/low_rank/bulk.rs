//! K's MUMPS factor, shifted on the contact DOFs so that it exists when a
//! body is held by contact alone.
//!
//! The Woodbury formula needs K⁻¹, but K alone is singular whenever a body
//! has no Dirichlet condition against a rigid motion and only the contact
//! holds it (the mortar patch test's upper block, pressed by a traction:
//! its z translation). MUMPS then factors K with a pivot of rounding size
//! and the update loses every digit (the first solve of tests/mortar.rs on
//! 2 ranks diverged). So the factor is of K' = K + A, A diagonal on the
//! DOFs the first contact tangent D0 touches (K's own diagonal there, so
//! the shift has K's scale), and the update carries −A: J = K' + P (D − A)
//! Pᵀ, the same J. K' is nonsingular whenever the first Jacobian is: a null
//! vector v of K with v = 0 where D0 acts has D0 v_C = 0 too, so it is one
//! of K + P D0 Pᵀ. Shifting those DOFs only (not all of C) keeps U, where
//! D − A acts, the contact zone.
use super::super::shell::error;
use super::super::{petsc_call, sys, Matrix, Result, Vector};
use super::LowRankPreconditioner;

impl LowRankPreconditioner {
    /// K' = K + A (with the Dirichlet replacement) factored by MUMPS: LDLᵀ,
    /// K being symmetric on this path whatever the contact tangent is.
    /// `touched`: rank 0's positions in C that A shifts (sorted; empty
    /// elsewhere). Collective.
    pub(super) fn factor_bulk(&mut self, touched: &[usize]) -> Result<()> {
        let mut kd = self.k.duplicate()?;
        kd.zero_rows_columns_identity(&self.constrained)?;
        let shift = self.shift_on(&kd, touched)?;
        let own_root = !super::super::options::has("-mat_mumps_icntl_13")?;
        // SAFETY: `kd` and `shift` are valid, of matching layouts; the
        // factor is owned by `self` (destroyed in Drop).
        unsafe {
            petsc_call!(MatDiagonalSet(
                kd.raw(),
                shift.raw(),
                sys::InsertMode_ADD_VALUES
            ))?;
            petsc_call!(MatGetFactor(
                kd.raw(),
                c"mumps".as_ptr(),
                sys::MatFactorType_MAT_FACTOR_CHOLESKY,
                &mut self.factor
            ))?;
            if own_root {
                // The root front factored sequentially, not by ScaLAPACK:
                // with a ScaLAPACK root, MUMPS's selected inverse entries
                // (G's columns) came out wrong (hertz-sphere fine_size 0.42
                // on 2 ranks: both requests failed their probe); without
                // it they pass, and the run took 9.3 s against 64.3 s
                // with the columns by whole solves. Set before the
                // analysis, which reads it; the user's option wins.
                petsc_call!(MatMumpsSetIcntl(self.factor, 13, 1))?;
            }
            let mut info = sys::MatFactorInfo::default();
            petsc_call!(MatFactorInfoInitialize(&mut info))?;
            petsc_call!(MatCholeskyFactorSymbolic(
                self.factor,
                kd.raw(),
                std::ptr::null_mut(),
                &info
            ))?;
            petsc_call!(MatCholeskyFactorNumeric(self.factor, kd.raw(), &info))?;
            // MUMPS reports a failed factorisation through the factor's
            // error type (from its global INFOG, so alike on every rank);
            // agreed all the same.
            let mut err: sys::MatFactorError = 0;
            petsc_call!(MatFactorGetError(self.factor, &mut err))?;
            let failed = err != sys::MatFactorError_MAT_FACTOR_NOERROR;
            if (self.any_rank)(failed) {
                // Tried again at the next set-up.
                sys::MatDestroy(&mut self.factor);
                self.failed = Some(format!(
                    "the MUMPS factorisation of the bulk stiffness failed (error type {err} here)"
                ));
                return Ok(());
            }
        }
        if let Some(small) = self.small.as_mut() {
            self.shift_c = super::at_c(self.pick, &shift, small)?;
        }
        self.shift = Some(shift);
        self.bulk_factorisations += 1;
        Ok(())
    }

    /// A in K's layout: |K_ii| at the DOFs of `touched`, zero elsewhere
    /// (the positions sent from rank 0 back through C's scatter).
    /// Collective.
    fn shift_on(&mut self, kd: &Matrix, touched: &[usize]) -> Result<Vector> {
        let (Some(z), Some(small)) = (self.z.as_ref(), self.small.as_mut()) else {
            return Err(error("factor_bulk", "no C yet".into()));
        };
        let mut shift = z.duplicate()?;
        let diagonal = z.duplicate()?;
        shift.set_all(0.0)?;
        small.with_array_mut(|a| {
            a.fill(0.0);
            for &i in touched {
                a[i] = 1.0;
            }
        })?;
        super::scatter(self.pick, small.raw(), shift.raw(), true)?;
        // SAFETY: `kd` and `diagonal` are valid, of matching layouts.
        unsafe { petsc_call!(MatGetDiagonal(kd.raw(), diagonal.raw()))? };
        let k_ii = diagonal.with_array(|a| a.to_vec())?;
        shift.with_array_mut(|a| {
            for (v, k) in a.iter_mut().zip(&k_ii) {
                *v *= k.abs();
            }
        })?;
        Ok(shift)
    }
}

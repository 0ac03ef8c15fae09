//! K's MUMPS factor, shifted on the contact DOFs so that it exists when a
//! body is held by contact alone.
//!
//! The Woodbury formula needs K⁻¹, but K alone is singular whenever a body
//! has no Dirichlet condition against a rigid motion and only the contact
//! holds it (the mortar patch test's upper block, pressed by a traction:
//! its z translation). MUMPS then factors K with a pivot of rounding size
//! and the update loses every digit (the first solve of tests/mortar.rs on
//! 2 ranks diverged). So the factor is of K' = K + A, A diagonal on C's
//! unconstrained DOFs at the first set-up (K's own diagonal there, so the
//! shift has K's scale), and the update carries −A: J = K' + P (D − A) Pᵀ,
//! the same J. Any body the contact can hold has a DOF in C, so K' is
//! positive definite wherever J is.
use super::super::{petsc_call, sys, PetscInt, Result, Vector};
use super::LowRankPreconditioner;

impl LowRankPreconditioner {
    /// K' = K + A (with the Dirichlet replacement) factored by MUMPS: LDLᵀ,
    /// K being symmetric on this path whatever the contact tangent is. `c`:
    /// the DOFs A shifts (sorted). Collective.
    pub(super) fn factor_bulk(&mut self, c: &[PetscInt]) -> Result<()> {
        let mut kd = self.k.duplicate()?;
        kd.zero_rows_columns_identity(&self.constrained)?;
        let mut right: sys::Vec = std::ptr::null_mut();
        let mut left: sys::Vec = std::ptr::null_mut();
        let mut shift: sys::Vec = std::ptr::null_mut();
        // SAFETY: `kd` is a valid assembled matrix; the factor is owned by
        // `self` (destroyed in Drop); the work vectors are handed to owning
        // wrappers at once.
        unsafe {
            petsc_call!(MatCreateVecs(kd.raw(), &mut right, &mut left))?;
            self.z = Some(Vector::owned_from_raw(right));
            self.t = Some(Vector::owned_from_raw(left));
            petsc_call!(MatCreateVecs(kd.raw(), &mut shift, std::ptr::null_mut()))?;
        }
        // SAFETY: a new vector of K's column layout, owned from here on.
        let mut shift = unsafe { Vector::owned_from_raw(shift) };
        // SAFETY: `kd` and `shift` are valid, of matching layouts.
        unsafe { petsc_call!(MatGetDiagonal(kd.raw(), shift.raw()))? };
        self.keep_shift_on(&mut shift, c)?;
        // SAFETY: as above; the factor is owned by `self` (destroyed in Drop).
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
        self.shift = Some(shift);
        self.bulk_factorisations += 1;
        Ok(())
    }

    /// `diagonal` (K's, this rank's rows) becomes A: |K_ii| on the
    /// unconstrained DOFs of `c`, zero elsewhere.
    fn keep_shift_on(&self, diagonal: &mut Vector, c: &[PetscInt]) -> Result<()> {
        let (lo, _) = diagonal.ownership_range()?;
        let constrained = &self.constrained;
        diagonal.with_array_mut(|a| {
            for (i, v) in a.iter_mut().enumerate() {
                let g = (lo + i) as PetscInt;
                let shifted = c.binary_search(&g).is_ok() && constrained.binary_search(&g).is_err();
                *v = if shifted { v.abs() } else { 0.0 };
            }
        })
    }
}

//! Sparse matrices factored by MUMPS (LDLᵀ): solves with the factor, the
//! dense Schur complement on chosen rows (PETSc gives it on one process
//! only), selected entries of the inverse, and MUMPS's control parameters.
use super::{comm_world, petsc_call, sys, to_petsc_int, DenseMatrix, Matrix, PetscError};
use super::{PetscInt, Result, Vector};

/// A MUMPS factor matrix (`MatGetFactor`), owned.
pub struct Factor {
    raw: sys::Mat,
    /// The Schur complement's rows (null: none) and their count.
    schur_is: sys::IS,
    schur_n: usize,
    /// PETSc has factored the Schur complement (its dense solve is
    /// installed) and nothing has marked it unfactored since.
    schur_factored: bool,
}

impl Factor {
    /// MUMPS's Cholesky factor of the symmetric `k`, not yet factored.
    pub fn cholesky(k: &Matrix) -> Result<Factor> {
        let mut f = Factor {
            raw: std::ptr::null_mut(),
            schur_is: std::ptr::null_mut(),
            schur_n: 0,
            schur_factored: false,
        };
        // SAFETY: `k` is a valid matrix; the factor is owned by `f`.
        unsafe {
            petsc_call!(MatGetFactor(
                k.raw(),
                c"mumps".as_ptr(),
                sys::MatFactorType_MAT_FACTOR_CHOLESKY,
                &mut f.raw
            ))?
        };
        Ok(f)
    }

    /// The same with a dense Schur complement on the rows `schur` (its
    /// order the Schur complement's). One process.
    pub fn cholesky_with_schur(k: &Matrix, schur: &[PetscInt]) -> Result<Factor> {
        let mut f = Factor {
            raw: std::ptr::null_mut(),
            schur_is: std::ptr::null_mut(),
            schur_n: schur.len(),
            schur_factored: false,
        };
        // SAFETY: `k` is a valid matrix; the index set and the factor are
        // owned by `f` (destroyed in Drop, also on an early error); the
        // indices are copied.
        unsafe {
            petsc_call!(ISCreateGeneral(
                comm_world(),
                to_petsc_int(schur.len())?,
                schur.as_ptr(),
                sys::PetscCopyMode_PETSC_COPY_VALUES,
                &mut f.schur_is
            ))?;
            petsc_call!(MatGetFactor(
                k.raw(),
                c"mumps".as_ptr(),
                sys::MatFactorType_MAT_FACTOR_CHOLESKY,
                &mut f.raw
            ))?;
            petsc_call!(MatFactorSetSchurIS(f.raw, f.schur_is))?;
        }
        Ok(f)
    }

    /// Sets MUMPS's control parameter ICNTL(`i`).
    pub fn set_icntl(&mut self, i: PetscInt, value: PetscInt) -> Result<()> {
        // SAFETY: a valid MUMPS factor.
        unsafe { petsc_call!(MatMumpsSetIcntl(self.raw, i, value)) }
    }

    /// MUMPS's control parameter ICNTL(`i`).
    pub fn icntl(&self, i: PetscInt) -> Result<PetscInt> {
        let mut v: PetscInt = 0;
        // SAFETY: a valid MUMPS factor and out-pointer.
        unsafe { petsc_call!(MatMumpsGetIcntl(self.raw, i, &mut v))? };
        Ok(v)
    }

    /// Factors `k` (the matrix the factor was made for): the symbolic
    /// analysis with MUMPS's own ordering, then the numeric factorisation.
    /// A failed factorisation shows in [`Self::error_type`].
    pub fn factor(&mut self, k: &Matrix) -> Result<()> {
        let mut info = sys::MatFactorInfo::default();
        // SAFETY: a valid factor of `k`'s layout; the info is a local.
        unsafe {
            petsc_call!(MatFactorInfoInitialize(&mut info))?;
            petsc_call!(MatCholeskyFactorSymbolic(
                self.raw,
                k.raw(),
                std::ptr::null_mut(),
                &info
            ))?;
            petsc_call!(MatCholeskyFactorNumeric(self.raw, k.raw(), &info))
        }
    }

    /// MUMPS's failure of the last factorisation (a singular matrix, say),
    /// as PETSc's factor error type: it reports one through the factor,
    /// not the call's code. None when it succeeded.
    pub fn error_type(&self) -> Result<Option<u32>> {
        let mut err: sys::MatFactorError = 0;
        // SAFETY: a valid factor; out-pointer is a local.
        unsafe { petsc_call!(MatFactorGetError(self.raw, &mut err))? };
        Ok((err != sys::MatFactorError_MAT_FACTOR_NOERROR).then_some(err))
    }

    /// x = A⁻¹ b. Collective.
    pub fn solve(&self, b: &Vector, x: &mut Vector) -> Result<()> {
        // SAFETY: a valid factor; vectors of its size (PETSc checks).
        unsafe { petsc_call!(MatSolve(self.raw, b.raw(), x.raw())) }
    }

    /// X = A⁻¹ B for the columns of B at once. Collective.
    pub fn solve_many(&self, b: &DenseMatrix, x: &mut DenseMatrix) -> Result<()> {
        // SAFETY: a valid factor; dense matrices of its rows (PETSc checks).
        unsafe { petsc_call!(MatMatSolve(self.raw, b.raw(), x.raw())) }
    }

    /// Selected entries of A⁻¹ (MUMPS's ICNTL(30)): `request` lists them as
    /// the transpose (its row i names the rows of A⁻¹'s column i), and
    /// MUMPS writes the entries into its values. PETSc leaves the factor in
    /// the selected-inverse mode (ICNTL(30) = 1, ICNTL(21) = 0). Collective.
    pub fn inverse_entries(&self, request: &mut Matrix) -> Result<()> {
        // SAFETY: a valid factor and an assembled AIJ matrix of its size
        // held on the first process (PETSc checks).
        unsafe { petsc_call!(MatMumpsGetInverseTranspose(self.raw, request.raw())) }
    }

    /// The dense Schur complement (column-major, n × n), a copy. Factored.
    pub fn schur_complement(&self) -> Result<Vec<f64>> {
        let n = self.schur_n;
        let mut s: sys::Mat = std::ptr::null_mut();
        let mut status: sys::MatFactorSchurStatus = 0;
        // SAFETY: a factored matrix with a Schur complement of n rows: the
        // copy `s` is a dense n × n matrix, read only while it lives and
        // destroyed on every path.
        unsafe {
            petsc_call!(MatFactorCreateSchurComplement(
                self.raw,
                &mut s,
                &mut status
            ))?;
            let read = (|| -> Result<Vec<f64>> {
                let mut arr: *const f64 = std::ptr::null();
                petsc_call!(MatDenseGetArrayRead(s, &mut arr))?;
                let out = std::slice::from_raw_parts(arr, n * n).to_vec();
                petsc_call!(MatDenseRestoreArrayRead(s, &mut arr))?;
                Ok(out)
            })();
            sys::MatDestroy(&mut s);
            read
        }
    }

    /// Solves with the factored Schur complement alone: `rhs` and `sol`
    /// vectors of its n entries. (PETSc factors it first if it is not.)
    pub fn solve_schur(&self, rhs: &Vector, sol: &mut Vector) -> Result<()> {
        // SAFETY: a valid factor with a Schur complement; vectors of its
        // size (PETSc checks).
        unsafe {
            petsc_call!(MatFactorSolveSchurComplement(
                self.raw,
                rhs.raw(),
                sol.raw()
            ))
        }
    }

    /// The Schur complement becomes `values` (column-major n × n), its old
    /// dense factors cleared (marked unfactored, not SPD), and PETSc
    /// factors it: LDLᵀ (dsytrf) for a Cholesky factor's.
    pub fn set_schur_complement(&mut self, values: &[f64]) -> Result<()> {
        let n = self.schur_n;
        if self.schur_is.is_null() || values.len() != n * n {
            return Err(PetscError::new(
                "Factor::set_schur_complement",
                format!("{} values for a Schur complement of {n} rows", values.len()),
            ));
        }
        let mut s: sys::Mat = std::ptr::null_mut();
        let mut status: sys::MatFactorSchurStatus = 0;
        self.schur_factored = false;
        // SAFETY: a valid factor with a Schur complement of n rows; the
        // Schur matrix is the factor's own (borrowed between Get and
        // Restore); its array holds n × n column-major values and is
        // written only between MatDenseGetArray and its restore.
        unsafe {
            petsc_call!(MatFactorGetSchurComplement(self.raw, &mut s, &mut status))?;
            petsc_call!(MatFactorRestoreSchurComplement(
                self.raw,
                &mut s,
                sys::MatFactorSchurStatus_MAT_FACTOR_SCHUR_UNFACTORED
            ))?;
            petsc_call!(MatFactorGetSchurComplement(self.raw, &mut s, &mut status))?;
            let mut arr: *mut f64 = std::ptr::null_mut();
            petsc_call!(MatDenseGetArray(s, &mut arr))?;
            std::slice::from_raw_parts_mut(arr, n * n).copy_from_slice(values);
            petsc_call!(MatDenseRestoreArray(s, &mut arr))?;
            petsc_call!(MatSetOption(
                s,
                sys::MatOption_MAT_SPD,
                sys::PetscBool_PETSC_FALSE
            ))?;
            petsc_call!(MatFactorRestoreSchurComplement(
                self.raw,
                &mut s,
                sys::MatFactorSchurStatus_MAT_FACTOR_SCHUR_UNFACTORED
            ))?;
            petsc_call!(MatFactorFactorizeSchurComplement(self.raw))?;
        }
        self.schur_factored = true;
        Ok(())
    }

    /// PETSc has factored the Schur complement and nothing has marked it
    /// unfactored since ([`Self::set_schur_complement`] succeeded last).
    pub fn schur_is_factored(&self) -> bool {
        self.schur_factored
    }

    /// `f` on the array of the factored Schur complement (n × n,
    /// column-major), which stays marked factored, and SPD: PETSc's dense
    /// solve then reads it as a lower Cholesky factor (dpotrs), which `f`
    /// must leave there. Refused unless [`Self::schur_is_factored`].
    pub fn write_schur_cholesky(&mut self, f: impl FnOnce(&mut [f64])) -> Result<()> {
        if !self.schur_factored {
            return Err(PetscError::new(
                "Factor::write_schur_cholesky",
                "the Schur complement has not been factored".into(),
            ));
        }
        let n = self.schur_n;
        let mut s: sys::Mat = std::ptr::null_mut();
        let mut status: sys::MatFactorSchurStatus = 0;
        // SAFETY: a valid factor with a Schur complement of n rows, factored
        // by PETSc (checked above); the Schur matrix is the factor's own,
        // borrowed between Get and Restore; its array holds n × n
        // column-major values, written only between MatDenseGetArray and
        // its restore.
        unsafe {
            petsc_call!(MatFactorGetSchurComplement(self.raw, &mut s, &mut status))?;
            let mut arr: *mut f64 = std::ptr::null_mut();
            petsc_call!(MatDenseGetArray(s, &mut arr))?;
            f(std::slice::from_raw_parts_mut(arr, n * n));
            petsc_call!(MatDenseRestoreArray(s, &mut arr))?;
            petsc_call!(MatSetOption(
                s,
                sys::MatOption_MAT_SPD,
                sys::PetscBool_PETSC_TRUE
            ))?;
            petsc_call!(MatFactorRestoreSchurComplement(
                self.raw,
                &mut s,
                sys::MatFactorSchurStatus_MAT_FACTOR_SCHUR_FACTORED
            ))?;
        }
        Ok(())
    }
}

impl Drop for Factor {
    fn drop(&mut self) {
        // SAFETY: owned and destroyed once (null handles are skipped by PETSc).
        unsafe {
            sys::MatDestroy(&mut self.raw);
            sys::ISDestroy(&mut self.schur_is);
        }
    }
}

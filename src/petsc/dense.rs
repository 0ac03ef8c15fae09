//! Dense matrices in PETSc's own storage: sequential ones factored in place
//! (LU) and solved with, parallel ones as blocks of right-hand sides.
use super::matrix::{final_assembly, set_values};
use super::vector::self_comm;
use super::{comm_world, petsc_call, sys, to_petsc_int, Result, Vector};

/// A dense matrix: `rows` local rows (all of them on one process) of
/// `cols` columns, column-major with leading dimension `rows`.
pub struct DenseMatrix {
    raw: sys::Mat,
    rows: usize,
    cols: usize,
}

impl DenseMatrix {
    /// A `rows` × `cols` matrix on this process alone.
    pub fn new_seq(rows: usize, cols: usize) -> Result<Self> {
        let mut raw: sys::Mat = std::ptr::null_mut();
        // SAFETY: PETSc allocates the storage (no user array); the matrix
        // goes to an owning value at once.
        unsafe {
            petsc_call!(MatCreateSeqDense(
                self_comm(),
                to_petsc_int(rows)?,
                to_petsc_int(cols)?,
                std::ptr::null_mut(),
                &mut raw
            ))?
        };
        Ok(DenseMatrix { raw, rows, cols })
    }

    /// A parallel matrix with `local_rows` rows on this rank (as a vector
    /// of that layout has) and `cols` columns. Collective.
    pub fn new_mpi(local_rows: usize, cols: usize) -> Result<Self> {
        let mut raw: sys::Mat = std::ptr::null_mut();
        // SAFETY: as in `new_seq`.
        unsafe {
            petsc_call!(MatCreateDense(
                comm_world(),
                to_petsc_int(local_rows)?,
                sys::PETSC_DECIDE,
                sys::PETSC_DETERMINE,
                to_petsc_int(cols)?,
                std::ptr::null_mut(),
                &mut raw
            ))?
        };
        Ok(DenseMatrix {
            raw,
            rows: local_rows,
            cols,
        })
    }

    pub(super) fn raw(&self) -> sys::Mat {
        self.raw
    }

    /// The same layout, its values not copied (zero). Collective.
    pub fn duplicate_layout(&self) -> Result<Self> {
        let mut raw: sys::Mat = std::ptr::null_mut();
        // SAFETY: a valid matrix and out-pointer.
        unsafe {
            petsc_call!(MatDuplicate(
                self.raw,
                sys::MatDuplicateOption_MAT_DO_NOT_COPY_VALUES,
                &mut raw
            ))?
        };
        Ok(DenseMatrix {
            raw,
            rows: self.rows,
            cols: self.cols,
        })
    }

    /// Writes this rank's rows (column-major, every entry to be written:
    /// PETSc need not keep the old values).
    pub fn with_array_write<T>(&mut self, f: impl FnOnce(&mut [f64]) -> T) -> Result<T> {
        let n = self.rows * self.cols;
        let mut a: *mut f64 = std::ptr::null_mut();
        // SAFETY: PETSc's own storage of this rank's rows × cols entries
        // (leading dimension `rows`, no user array), valid until restored;
        // the slice does not escape `f`.
        unsafe {
            petsc_call!(MatDenseGetArrayWrite(self.raw, &mut a))?;
            let out = f(if n == 0 {
                &mut []
            } else {
                std::slice::from_raw_parts_mut(a, n)
            });
            petsc_call!(MatDenseRestoreArrayWrite(self.raw, &mut a))?;
            Ok(out)
        }
    }

    /// Sets the entry at global (`row`, `col`) (any rank's; call
    /// [`Self::assemble`] afterwards).
    pub fn set(&mut self, row: super::PetscInt, col: super::PetscInt, value: f64) -> Result<()> {
        set_values(
            self.raw,
            &[row],
            &[col],
            &[value],
            sys::InsertMode_INSERT_VALUES,
        )
    }

    /// Collective.
    pub fn assemble(&mut self) -> Result<()> {
        final_assembly(self.raw)
    }

    /// LU factors with row pivots in place (LAPACK's, through PETSc), for
    /// [`Self::solve`].
    pub fn lu_factor(&mut self) -> Result<()> {
        let mut info = sys::MatFactorInfo::default();
        // SAFETY: a valid dense matrix; null orderings are the natural ones;
        // the info is a local.
        unsafe {
            petsc_call!(MatFactorInfoInitialize(&mut info))?;
            petsc_call!(MatLUFactor(
                self.raw,
                std::ptr::null_mut(),
                std::ptr::null_mut(),
                &info
            ))
        }
    }

    /// x = A⁻¹ b with the factors of [`Self::lu_factor`].
    pub fn solve(&self, b: &Vector, x: &mut Vector) -> Result<()> {
        // SAFETY: a valid matrix (PETSc refuses one not factored); vectors
        // of its size (PETSc checks).
        unsafe { petsc_call!(MatSolve(self.raw, b.raw(), x.raw())) }
    }

    /// `f` on column `j` as a vector (of the matrix's row layout), read
    /// only.
    pub fn with_column<T>(&self, j: usize, f: impl FnOnce(&Vector) -> T) -> Result<T> {
        let mut v: sys::Vec = std::ptr::null_mut();
        let j = to_petsc_int(j)?;
        // SAFETY: PETSc lends the column as a vector until it is restored;
        // the borrowed wrapper does not escape `f`.
        unsafe {
            petsc_call!(MatDenseGetColumnVecRead(self.raw, j, &mut v))?;
            let out = f(&Vector::borrowed(v));
            petsc_call!(MatDenseRestoreColumnVecRead(self.raw, j, &mut v))?;
            Ok(out)
        }
    }
}

impl Drop for DenseMatrix {
    fn drop(&mut self) {
        // SAFETY: owned and destroyed once.
        unsafe {
            sys::MatDestroy(&mut self.raw);
        }
    }
}

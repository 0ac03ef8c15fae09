//! Distributed sparse matrices (MPIAIJ), created exactly preallocated for a
//! pattern the caller gives (`assembly::pattern` records it).
use super::{comm_world, petsc_call, sys, to_petsc_int, PetscError, PetscInt, Result, Vector};

pub struct Matrix {
    raw: sys::Mat,
    owned: bool,
}

impl Matrix {
    /// Takes ownership of `raw` (destroyed on drop).
    pub(super) fn owned(raw: sys::Mat) -> Self {
        Matrix { raw, owned: true }
    }

    /// # Safety
    /// `raw` must be valid for the lifetime of the returned value.
    pub(crate) unsafe fn borrowed(raw: sys::Mat) -> Self {
        Matrix { raw, owned: false }
    }

    pub(crate) fn raw(&self) -> sys::Mat {
        self.raw
    }

    pub fn zero_entries(&mut self) -> Result<()> {
        // SAFETY: valid mat.
        unsafe { petsc_call!(MatZeroEntries(self.raw)) }
    }

    /// Adds a dense row-major block at global (rows, cols); negative indices are
    /// skipped by PETSc (used for constrained DOFs).
    pub fn add_block(
        &mut self,
        rows: &[PetscInt],
        cols: &[PetscInt],
        values: &[f64],
    ) -> Result<()> {
        set_values(self.raw, rows, cols, values, sys::InsertMode_ADD_VALUES)
    }

    /// The first row this rank owns that holds a NaN or infinite value
    /// (local, no communication; the matrix must be assembled). Used to say
    /// which rank made a linear solve fail.
    pub fn first_nonfinite_owned_row(&self) -> Result<Option<PetscInt>> {
        let (mut lo, mut hi) = (0, 0);
        // SAFETY: valid assembled mat; MatGetRow's pointers are read only
        // between it and the paired MatRestoreRow.
        unsafe {
            petsc_call!(MatGetOwnershipRange(self.raw, &mut lo, &mut hi))?;
            for row in lo..hi {
                let mut n: PetscInt = 0;
                let mut vals: *const f64 = std::ptr::null();
                petsc_call!(MatGetRow(
                    self.raw,
                    row,
                    &mut n,
                    std::ptr::null_mut(),
                    &mut vals
                ))?;
                let bad = !vals.is_null()
                    && n > 0
                    && std::slice::from_raw_parts(vals, n as usize)
                        .iter()
                        .any(|v| !v.is_finite());
                petsc_call!(MatRestoreRow(
                    self.raw,
                    row,
                    &mut n,
                    std::ptr::null_mut(),
                    &mut vals
                ))?;
                if bad {
                    return Ok(Some(row));
                }
            }
        }
        Ok(None)
    }

    pub fn assemble(&mut self) -> Result<()> {
        final_assembly(self.raw)
    }

    /// Replaces rows and columns of constrained DOFs by the identity, keeping
    /// the matrix symmetric (so CG stays usable). Collective.
    pub fn zero_rows_columns_identity(&mut self, rows: &[PetscInt]) -> Result<()> {
        // SAFETY: rows valid for its length; null x/b mean no right-hand-side fix-up.
        unsafe {
            petsc_call!(MatZeroRowsColumns(
                self.raw,
                rows.len() as PetscInt,
                rows.as_ptr(),
                1.0,
                std::ptr::null_mut(),
                std::ptr::null_mut()
            ))
        }
    }

    /// Copies values from `other` (same non-zero pattern).
    pub fn copy_from(&mut self, other: &Matrix) -> Result<()> {
        // SAFETY: both valid; PETSc checks the patterns.
        unsafe {
            petsc_call!(MatCopy(
                other.raw,
                self.raw,
                sys::MatStructure_SAME_NONZERO_PATTERN
            ))
        }
    }

    /// A second owning handle on the same matrix (PETSc counts references):
    /// both see every change, and the storage goes with the last handle.
    pub fn share(&self) -> Result<Matrix> {
        // SAFETY: valid mat; the new handle's Drop releases this reference.
        unsafe { petsc_call!(PetscObjectReference(self.raw as sys::PetscObject))? };
        Ok(Matrix {
            raw: self.raw,
            owned: true,
        })
    }

    /// Whether both handles name the same PETSc matrix.
    pub fn same_as(&self, other: &Matrix) -> bool {
        self.raw == other.raw
    }

    pub fn duplicate(&self) -> Result<Matrix> {
        let mut raw: sys::Mat = std::ptr::null_mut();
        // SAFETY: valid mat and out-pointer.
        unsafe {
            petsc_call!(MatDuplicate(
                self.raw,
                sys::MatDuplicateOption_MAT_COPY_VALUES,
                &mut raw
            ))?
        };
        Ok(Matrix { raw, owned: true })
    }

    /// y = A x
    pub fn mult(&self, x: &Vector, y: &mut Vector) -> Result<()> {
        // SAFETY: all valid; PETSc checks layouts.
        unsafe { petsc_call!(MatMult(self.raw, x.raw(), y.raw())) }
    }

    /// Attaches the rigid-body modes computed from nodal coordinates (a blocked
    /// vector of owned coordinates, block size 3) as the near-null space, which
    /// algebraic multigrid needs for elasticity.
    pub fn set_rigid_body_near_null_space(&mut self, coords: &Vector) -> Result<()> {
        let mut ns: sys::MatNullSpace = std::ptr::null_mut();
        // SAFETY: coords valid with block size 3; the matrix keeps its own reference
        // to the null space, so ours is destroyed here.
        unsafe {
            petsc_call!(MatNullSpaceCreateRigidBody(coords.raw(), &mut ns))?;
            petsc_call!(MatSetNearNullSpace(self.raw, ns))?;
            petsc_call!(MatNullSpaceDestroy(&mut ns))
        }
    }

    /// Total number of stored non-zeros over all ranks.
    pub fn global_nonzeros(&self) -> Result<f64> {
        let mut info = sys::MatInfo::default();
        // SAFETY: valid mat and out-pointer.
        unsafe {
            petsc_call!(MatGetInfo(
                self.raw,
                sys::MatInfoType_MAT_GLOBAL_SUM,
                &mut info
            ))?
        };
        Ok(info.nz_used)
    }
}

impl Drop for Matrix {
    fn drop(&mut self) {
        if self.owned && !self.raw.is_null() {
            // SAFETY: owned and destroyed exactly once.
            unsafe {
                sys::MatDestroy(&mut self.raw);
            }
        }
    }
}

impl Matrix {
    /// self += a · other, where other's non-zeros are a subset of self's.
    pub fn add_scaled_subset(&mut self, a: f64, other: &Matrix) -> Result<()> {
        // SAFETY: both valid; PETSc checks sizes and the subset property.
        unsafe {
            petsc_call!(MatAXPY(
                self.raw,
                a,
                other.raw,
                sys::MatStructure_SUBSET_NONZERO_PATTERN
            ))
        }
    }
}

impl Matrix {
    /// A square AIJ matrix with `local` rows and columns on this rank of
    /// `global`, and `per_row[i]` non-zeros in local row i's diagonal block
    /// (none in the off-diagonal ones; None: no preallocation). Collective.
    pub fn new_aij(
        local: PetscInt,
        global: PetscInt,
        per_row: Option<&[PetscInt]>,
    ) -> Result<Self> {
        if per_row.is_some_and(|p| p.len() < local.max(0) as usize) {
            return Err(PetscError::new(
                "MatCreateAIJ",
                format!("fewer row lengths than the {local} local rows"),
            ));
        }
        let mut raw: sys::Mat = std::ptr::null_mut();
        // SAFETY: `per_row` holds an entry per local row (checked above) or
        // is null; PETSc copies it; the matrix goes to an owning value.
        unsafe {
            petsc_call!(MatCreateAIJ(
                comm_world(),
                local,
                local,
                global,
                global,
                0,
                per_row.map_or(std::ptr::null(), <[PetscInt]>::as_ptr),
                0,
                std::ptr::null(),
                &mut raw
            ))?
        };
        Ok(Matrix::owned(raw))
    }

    /// Sets a dense row-major block at global (rows, cols), replacing what
    /// is there (off-rank rows allowed; assemble afterwards).
    pub fn set_block(
        &mut self,
        rows: &[PetscInt],
        cols: &[PetscInt],
        values: &[f64],
    ) -> Result<()> {
        set_values(self.raw, rows, cols, values, sys::InsertMode_INSERT_VALUES)
    }

    /// Global (rows, columns).
    pub fn size(&self) -> Result<(PetscInt, PetscInt)> {
        let (mut m, mut n) = (0, 0);
        // SAFETY: valid mat and out-pointers.
        unsafe { petsc_call!(MatGetSize(self.raw, &mut m, &mut n))? };
        Ok((m, n))
    }

    /// This rank's (rows, columns).
    pub fn local_size(&self) -> Result<(PetscInt, PetscInt)> {
        let (mut m, mut n) = (0, 0);
        // SAFETY: valid mat and out-pointers.
        unsafe { petsc_call!(MatGetLocalSize(self.raw, &mut m, &mut n))? };
        Ok((m, n))
    }

    /// [first, end) of the rows this rank owns.
    pub fn ownership_range(&self) -> Result<(PetscInt, PetscInt)> {
        let (mut lo, mut hi) = (0, 0);
        // SAFETY: valid mat and out-pointers.
        unsafe { petsc_call!(MatGetOwnershipRange(self.raw, &mut lo, &mut hi))? };
        Ok((lo, hi))
    }

    /// Vectors of the column and the row layout (x and b of A x = b).
    /// Collective.
    pub fn create_vecs(&self) -> Result<(Vector, Vector)> {
        let (mut right, mut left): (sys::Vec, sys::Vec) =
            (std::ptr::null_mut(), std::ptr::null_mut());
        // SAFETY: valid mat; the vectors go to owning wrappers at once.
        unsafe {
            petsc_call!(MatCreateVecs(self.raw, &mut right, &mut left))?;
            Ok((Vector::owned_from_raw(right), Vector::owned_from_raw(left)))
        }
    }

    /// The diagonal into `d` (of the row layout).
    pub fn diagonal(&self, d: &mut Vector) -> Result<()> {
        // SAFETY: valid mat and vector (PETSc checks the layout).
        unsafe { petsc_call!(MatGetDiagonal(self.raw, d.raw())) }
    }

    /// Adds `d` to the diagonal. Collective.
    pub fn add_diagonal(&mut self, d: &Vector) -> Result<()> {
        // SAFETY: valid mat and vector (PETSc checks the layout).
        unsafe {
            petsc_call!(MatDiagonalSet(
                self.raw,
                d.raw(),
                sys::InsertMode_ADD_VALUES
            ))
        }
    }

    /// y = Aᵀ x
    pub fn mult_transpose(&self, x: &Vector, y: &mut Vector) -> Result<()> {
        // SAFETY: all valid; PETSc checks layouts.
        unsafe { petsc_call!(MatMultTranspose(self.raw, x.raw(), y.raw())) }
    }

    /// Calls `f(row, columns, values)` for each row in `rows` of the
    /// assembled matrix (rows this process holds: any of a sequential
    /// matrix, the owned ones of a parallel one); an empty row comes with
    /// empty slices. An error of `f` ends the walk (after the row's
    /// restore) and is returned.
    pub fn for_rows(
        &self,
        rows: impl Iterator<Item = PetscInt>,
        mut f: impl FnMut(PetscInt, &[PetscInt], &[f64]) -> Result<()>,
    ) -> Result<()> {
        for row in rows {
            let mut nz: PetscInt = 0;
            let mut cols: *const PetscInt = std::ptr::null();
            let mut vals: *const f64 = std::ptr::null();
            // SAFETY: a valid assembled matrix holding `row` on this process;
            // the row's pointers are read only between MatGetRow and the
            // paired MatRestoreRow, and hold `nz` entries each.
            unsafe {
                petsc_call!(MatGetRow(self.raw, row, &mut nz, &mut cols, &mut vals))?;
                let read = if nz > 0 && !cols.is_null() && !vals.is_null() {
                    let cs = std::slice::from_raw_parts(cols, nz as usize);
                    let vs = std::slice::from_raw_parts(vals, nz as usize);
                    f(row, cs, vs)
                } else {
                    f(row, &[], &[])
                };
                petsc_call!(MatRestoreRow(self.raw, row, &mut nz, &mut cols, &mut vals))?;
                read?;
            }
        }
        Ok(())
    }
}

impl Matrix {
    /// A dense row-major block's values match its rows and columns.
    pub fn check_block(rows: &[PetscInt], cols: &[PetscInt], values: &[f64]) -> Result<()> {
        check_block(rows, cols, values)
    }

    /// An AIJ matrix of `rows` rows on this rank (following the lower
    /// ranks'), block size `block_size`, not yet preallocated. Collective.
    fn create_aij(rows: usize, block_size: usize) -> Result<Matrix> {
        let n = to_petsc_int(rows)?;
        let mut raw: sys::Mat = std::ptr::null_mut();
        // SAFETY: PETSc is initialised; out-pointer valid; `m` owns the new
        // matrix and destroys it on every exit.
        unsafe {
            petsc_call!(MatCreate(comm_world(), &mut raw))?;
            let m = Matrix::owned(raw);
            petsc_call!(MatSetSizes(
                raw,
                n,
                n,
                sys::PETSC_DETERMINE,
                sys::PETSC_DETERMINE
            ))?;
            petsc_call!(MatSetBlockSize(raw, to_petsc_int(block_size)?))?;
            petsc_call!(MatSetType(raw, c"aij".as_ptr()))?;
            Ok(m)
        }
    }

    /// Fixes the pattern: inserting outside it is an error (a bug, not a
    /// slowdown), and zeroed rows (Dirichlet) keep their entries, so the
    /// pattern and the preconditioner's symbolic set-up survive across
    /// Newton iterations.
    fn fix_pattern(self) -> Result<Matrix> {
        // SAFETY: `self.raw` is a valid assembled matrix this value owns.
        unsafe {
            petsc_call!(MatSetOption(
                self.raw,
                sys::MatOption_MAT_NEW_NONZERO_ALLOCATION_ERR,
                sys::PetscBool_PETSC_TRUE
            ))?;
            petsc_call!(MatSetOption(
                self.raw,
                sys::MatOption_MAT_KEEP_NONZERO_PATTERN,
                sys::PetscBool_PETSC_TRUE
            ))?;
        }
        Ok(self)
    }

    /// One rank: the matrix of `rows` rows whose row `i` has `lengths[i]`
    /// columns, the rows' column indices one after another in `cols`
    /// (sorted and distinct per row, below the size), fixed with explicit
    /// zeros. PETSc copies the indices.
    pub fn with_compressed_rows(
        rows: usize,
        block_size: usize,
        lengths: &[PetscInt],
        cols: &mut [PetscInt],
    ) -> Result<Matrix> {
        let total: usize = lengths.iter().map(|&l| l.max(0) as usize).sum();
        if lengths.len() != rows || total != cols.len() {
            return Err(PetscError {
                call: "MatSeqAIJSetColumnIndices",
                code: -1,
                message: format!(
                    "{} row lengths summing to {total} for {rows} rows and {} column indices",
                    lengths.len(),
                    cols.len()
                ),
            });
        }
        let m = Self::create_aij(rows, block_size)?;
        // SAFETY: `m` is a valid, not yet preallocated sequential AIJ matrix
        // of `rows` rows; `lengths` holds one count per row and `cols` that
        // many indices in all, which is what MatSeqAIJSetColumnIndices reads.
        unsafe {
            petsc_call!(MatSeqAIJSetPreallocation(m.raw, 0, lengths.as_ptr()))?;
            petsc_call!(MatSeqAIJSetColumnIndices(m.raw, cols.as_mut_ptr()))?;
            final_assembly(m.raw)?;
            petsc_call!(MatZeroEntries(m.raw))?;
        }
        m.fix_pattern()
    }

    /// Several ranks: the matrix of `rows` rows on this rank, row `i`
    /// holding `on[i]` columns inside the diagonal block and `off[i]`
    /// outside it; `fill` is handed a setter it calls once per row with
    /// the row's global index and its columns (sorted, distinct, in range,
    /// as many as counted), which puts explicit zeros there. Collective.
    pub fn with_rows(
        rows: usize,
        block_size: usize,
        (on, off): (&[PetscInt], &[PetscInt]),
        fill: impl FnOnce(&mut dyn FnMut(PetscInt, &[PetscInt]) -> Result<()>) -> Result<()>,
    ) -> Result<Matrix> {
        if on.len() != rows || off.len() != rows {
            return Err(PetscError {
                call: "MatMPIAIJSetPreallocation",
                code: -1,
                message: format!("{} and {} row counts for {rows} rows", on.len(), off.len()),
            });
        }
        let widest = on
            .iter()
            .zip(off)
            .map(|(a, b)| (a + b).max(0) as usize)
            .max();
        let zeros = vec![0.0; widest.unwrap_or(0)];
        let m = Self::create_aij(rows, block_size)?;
        // SAFETY: `m` is a valid, not yet preallocated MPIAIJ matrix of
        // `rows` local rows and `on`/`off` hold one count per row.
        unsafe {
            petsc_call!(MatMPIAIJSetPreallocation(
                m.raw,
                0,
                on.as_ptr(),
                0,
                off.as_ptr()
            ))?;
        }
        let raw = m.raw;
        fill(&mut |row, cols| {
            let n = to_petsc_int(cols.len())?;
            if cols.len() > zeros.len() {
                return Err(PetscError {
                    call: "MatSetValues",
                    code: -1,
                    message: format!("row {row}: {n} columns, more than counted"),
                });
            }
            // SAFETY: `raw` is the matrix preallocated above; one row of
            // `n` columns with as many zeros, which MatSetValues reads and
            // copies.
            unsafe {
                petsc_call!(MatSetValues(
                    raw,
                    1,
                    &row,
                    n,
                    cols.as_ptr(),
                    zeros.as_ptr(),
                    sys::InsertMode_INSERT_VALUES
                ))
            }
        })?;
        final_assembly(raw)?;
        m.fix_pattern()
    }
}

/// A dense row-major block's values match its rows and columns.
pub(super) fn check_block(rows: &[PetscInt], cols: &[PetscInt], values: &[f64]) -> Result<()> {
    if rows.len() * cols.len() != values.len() {
        return Err(super::PetscError {
            call: "MatSetValues",
            code: -1,
            message: format!(
                "{} values for a {}×{} block",
                values.len(),
                rows.len(),
                cols.len()
            ),
        });
    }
    Ok(())
}

/// MatSetValues for a dense row-major block.
pub(super) fn set_values(
    raw: sys::Mat,
    rows: &[PetscInt],
    cols: &[PetscInt],
    values: &[f64],
    mode: sys::InsertMode,
) -> Result<()> {
    check_block(rows, cols, values)?;
    // SAFETY: `raw` is a valid matrix owned by the caller; values holds
    // rows × cols entries in row-major order, as MatSetValues reads them.
    unsafe {
        petsc_call!(MatSetValues(
            raw,
            rows.len() as PetscInt,
            rows.as_ptr(),
            cols.len() as PetscInt,
            cols.as_ptr(),
            values.as_ptr(),
            mode
        ))
    }
}

/// MatAssemblyBegin/End, final assembly.
pub(super) fn final_assembly(raw: sys::Mat) -> Result<()> {
    // SAFETY: `raw` is a valid matrix owned by the caller; begin/end are paired.
    unsafe {
        petsc_call!(MatAssemblyBegin(
            raw,
            sys::MatAssemblyType_MAT_FINAL_ASSEMBLY
        ))?;
        petsc_call!(MatAssemblyEnd(raw, sys::MatAssemblyType_MAT_FINAL_ASSEMBLY))
    }
}

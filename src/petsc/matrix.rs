//! Distributed sparse matrices (MPIAIJ) with exact preallocation.
use super::{comm_world, petsc_call, sys, to_petsc_int, PetscInt, Result, Vector};

/// Records the non-zero pattern of a matrix, including entries in rows other
/// ranks own, and then creates the matrix exactly preallocated for it.
/// On several ranks PETSc's MATPREALLOCATOR keeps the record (the off-rank
/// bookkeeping is PETSc's); on one rank it is kept here as sorted couplings
/// of whole nodes (a block of consecutive DOFs), which is several times
/// cheaper than PETSc's hash of every entry, and the matrix is created
/// from the compressed rows directly.
pub struct PatternBuilder {
    raw: sys::Mat,
    local_rows: usize,
    block_size: usize,
    zeros: Vec<f64>,
    /// One rank: the record kept here (`raw` is then null).
    serial: Option<SerialPattern>,
}

impl PatternBuilder {
    pub fn new(local_rows: usize, block_size: usize) -> Result<Self> {
        use mpi::traits::Communicator;
        // PETSc's world is MPI's (set before PetscInitialize).
        if mpi::topology::SimpleCommunicator::world().size() == 1 {
            return Ok(PatternBuilder {
                raw: std::ptr::null_mut(),
                local_rows,
                block_size,
                zeros: Vec::new(),
                serial: Some(SerialPattern::new(local_rows, block_size)),
            });
        }
        let n = to_petsc_int(local_rows)?;
        let mut raw: sys::Mat = std::ptr::null_mut();
        // SAFETY: PETSc is initialised; out-pointer valid; the matrix is destroyed
        // in Drop.
        unsafe {
            petsc_call!(MatCreate(comm_world(), &mut raw))?;
            petsc_call!(MatSetSizes(
                raw,
                n,
                n,
                sys::PETSC_DETERMINE,
                sys::PETSC_DETERMINE
            ))?;
            petsc_call!(MatSetBlockSize(raw, to_petsc_int(block_size)?))?;
            petsc_call!(MatSetType(raw, c"preallocator".as_ptr()))?;
            petsc_call!(MatSetUp(raw))?;
        }
        Ok(PatternBuilder {
            raw,
            local_rows,
            block_size,
            zeros: Vec::new(),
            serial: None,
        })
    }

    /// Records the couplings of `dofs` with themselves (a square element block).
    pub fn add_square(&mut self, dofs: &[PetscInt]) -> Result<()> {
        if let Some(p) = &mut self.serial {
            return p.add_square(dofs);
        }
        let n = dofs.len() * dofs.len();
        if self.zeros.len() < n {
            self.zeros.resize(n, 0.0);
        }
        let zeros = std::mem::take(&mut self.zeros);
        let r = self.add_block(dofs, dofs, &zeros[..n]);
        self.zeros = zeros;
        r
    }

    /// Creates the AIJ matrix with this pattern, filled with explicit zeros so
    /// the pattern is fixed from the start. Collective.
    pub fn build(mut self) -> Result<Matrix> {
        let n = to_petsc_int(self.local_rows)?;
        let serial = self.serial.take();
        let mut raw: sys::Mat = std::ptr::null_mut();
        // SAFETY: the preallocator (several ranks) is assembled before use;
        // the new matrix has the same sizes; out-pointer valid. On one rank
        // `lengths` holds one row length per row and `cols` their sum of
        // column indices, sorted and distinct per row and in range, which
        // is what MatSeqAIJSetColumnIndices needs; PETSc copies both.
        unsafe {
            if serial.is_none() {
                final_assembly(self.raw)?;
            }
            petsc_call!(MatCreate(comm_world(), &mut raw))?;
            let m = Matrix { raw, owned: true };
            petsc_call!(MatSetSizes(
                raw,
                n,
                n,
                sys::PETSC_DETERMINE,
                sys::PETSC_DETERMINE
            ))?;
            petsc_call!(MatSetBlockSize(raw, to_petsc_int(self.block_size)?))?;
            petsc_call!(MatSetType(raw, c"aij".as_ptr()))?;
            match serial {
                Some(p) => {
                    // Exact row lengths, then the column indices in one copy
                    // (MatSeqAIJSetPreallocationCSR would insert them entry
                    // by entry), then explicit zeros.
                    let (lengths, mut cols) = p.compressed_rows()?;
                    petsc_call!(MatSeqAIJSetPreallocation(raw, 0, lengths.as_ptr()))?;
                    petsc_call!(MatSeqAIJSetColumnIndices(raw, cols.as_mut_ptr()))?;
                    final_assembly(raw)?;
                    petsc_call!(MatZeroEntries(raw))?;
                }
                None => petsc_call!(MatPreallocatorPreallocate(
                    self.raw,
                    sys::PetscBool_PETSC_TRUE,
                    raw
                ))?,
            }
            // Inserting outside the recorded pattern is a bug, not a slowdown.
            petsc_call!(MatSetOption(
                raw,
                sys::MatOption_MAT_NEW_NONZERO_ALLOCATION_ERR,
                sys::PetscBool_PETSC_TRUE
            ))?;
            // Zeroed rows (Dirichlet) keep their entries, so the pattern, and the
            // preconditioner's symbolic set-up, survive across Newton iterations.
            petsc_call!(MatSetOption(
                raw,
                sys::MatOption_MAT_KEEP_NONZERO_PATTERN,
                sys::PetscBool_PETSC_TRUE
            ))?;
            Ok(m)
        }
    }
}

impl PatternBuilder {
    /// Records the entries of a dense block at global (rows, cols).
    pub fn add_block(
        &mut self,
        rows: &[PetscInt],
        cols: &[PetscInt],
        values: &[f64],
    ) -> Result<()> {
        if let Some(p) = &mut self.serial {
            check_block(rows, cols, values)?;
            return p.add_entries(rows, cols);
        }
        set_values(self.raw, rows, cols, values, sys::InsertMode_INSERT_VALUES)
    }
}

/// The pattern of a one-rank matrix: couplings of whole nodes (`bs`
/// consecutive DOFs from a multiple of `bs`), and single entries for
/// blocks that are not made of whole nodes; negative indices are skipped,
/// as MatSetValues does.
struct SerialPattern {
    rows: usize,
    bs: usize,
    /// (row node, column node), with repeats until `compressed_rows`.
    nodes: Vec<(u32, u32)>,
    /// (row, column) entries outside whole-node blocks.
    entries: Vec<(PetscInt, PetscInt)>,
    scratch: Vec<u32>,
}

impl SerialPattern {
    fn new(rows: usize, bs: usize) -> Self {
        SerialPattern {
            rows,
            bs: bs.max(1),
            nodes: Vec::new(),
            entries: Vec::new(),
            scratch: Vec::new(),
        }
    }

    fn out_of_range(&self, d: PetscInt) -> super::PetscError {
        super::PetscError {
            call: "MatSetValues",
            code: -1,
            message: format!("index {d} outside the {} rows of the pattern", self.rows),
        }
    }

    /// Whether `dofs` is made of whole nodes, each node's DOFs consecutive
    /// and in order; their node numbers are then in `scratch`.
    fn whole_nodes(&mut self, dofs: &[PetscInt]) -> Result<bool> {
        let bs = self.bs;
        self.scratch.clear();
        if !dofs.len().is_multiple_of(bs) || !self.rows.is_multiple_of(bs) {
            return Ok(false);
        }
        for chunk in dofs.chunks_exact(bs) {
            let first = chunk[0];
            let whole = first >= 0
                && (first as usize).is_multiple_of(bs)
                && chunk
                    .iter()
                    .enumerate()
                    .all(|(c, &d)| d == first + c as PetscInt);
            if !whole {
                return Ok(false);
            }
            if first as usize >= self.rows {
                return Err(self.out_of_range(first));
            }
            let node = u32::try_from(first as usize / bs).map_err(|_| self.out_of_range(first))?;
            self.scratch.push(node);
        }
        Ok(true)
    }

    fn add_square(&mut self, dofs: &[PetscInt]) -> Result<()> {
        if !self.whole_nodes(dofs)? {
            return self.add_entries(dofs, dofs);
        }
        let nodes = &self.scratch;
        self.nodes.reserve(nodes.len() * nodes.len());
        for &a in nodes {
            for &b in nodes {
                self.nodes.push((a, b));
            }
        }
        Ok(())
    }

    fn add_entries(&mut self, rows: &[PetscInt], cols: &[PetscInt]) -> Result<()> {
        for &d in rows.iter().chain(cols) {
            if d >= 0 && d as usize >= self.rows {
                return Err(self.out_of_range(d));
            }
        }
        for &r in rows.iter().filter(|&&r| r >= 0) {
            for &c in cols.iter().filter(|&&c| c >= 0) {
                self.entries.push((r, c));
            }
        }
        Ok(())
    }

    /// Row lengths and the sorted, distinct column indices of every row.
    fn compressed_rows(mut self) -> Result<(Vec<PetscInt>, Vec<PetscInt>)> {
        self.nodes.sort_unstable();
        self.nodes.dedup();
        self.entries.sort_unstable();
        self.entries.dedup();
        let bs = self.bs;
        let mut lengths = Vec::with_capacity(self.rows);
        let mut cols: Vec<PetscInt> = Vec::with_capacity(self.nodes.len() * bs * bs);
        let (mut ni, mut ei) = (0, 0);
        let mut row_nodes: &[(u32, u32)] = &[];
        let mut merged: Vec<PetscInt> = Vec::new();
        for row in 0..self.rows {
            if row.is_multiple_of(bs) {
                let node = (row / bs) as u32;
                let start = ni;
                while ni < self.nodes.len() && self.nodes[ni].0 == node {
                    ni += 1;
                }
                row_nodes = &self.nodes[start..ni];
            }
            let start = ei;
            while ei < self.entries.len() && self.entries[ei].0 == row as PetscInt {
                ei += 1;
            }
            let extra = &self.entries[start..ei];
            let expanded = row_nodes
                .iter()
                .flat_map(|&(_, m)| (0..bs).map(move |c| (m as usize * bs + c) as PetscInt));
            if extra.is_empty() {
                cols.extend(expanded);
            } else {
                merged.clear();
                merged.extend(expanded);
                merged.extend(extra.iter().map(|&(_, c)| c));
                merged.sort_unstable();
                merged.dedup();
                cols.extend_from_slice(&merged);
            }
            lengths.push(to_petsc_int(cols.len())?);
        }
        let mut last = 0;
        for l in lengths.iter_mut() {
            (*l, last) = (*l - last, *l);
        }
        Ok((lengths, cols))
    }
}

impl Drop for PatternBuilder {
    fn drop(&mut self) {
        // SAFETY: owned and destroyed once (a null handle, one rank, is
        // skipped by PETSc).
        unsafe {
            sys::MatDestroy(&mut self.raw);
        }
    }
}

pub struct Matrix {
    raw: sys::Mat,
    owned: bool,
}

impl Matrix {
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

/// A dense row-major block's values match its rows and columns.
fn check_block(rows: &[PetscInt], cols: &[PetscInt], values: &[f64]) -> Result<()> {
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
fn set_values(
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
fn final_assembly(raw: sys::Mat) -> Result<()> {
    // SAFETY: `raw` is a valid matrix owned by the caller; begin/end are paired.
    unsafe {
        petsc_call!(MatAssemblyBegin(
            raw,
            sys::MatAssemblyType_MAT_FINAL_ASSEMBLY
        ))?;
        petsc_call!(MatAssemblyEnd(raw, sys::MatAssemblyType_MAT_FINAL_ASSEMBLY))
    }
}

//! The bulk stiffness factored once with a MUMPS Schur complement on the
//! contact DOFs, and the PETSc shell preconditioner that solves
//! (K + Kc) x = b exactly with it when Kc is non-zero only on those DOFs.
//!
//! With C the contact candidate DOFs and I the rest, MUMPS factors K_II
//! and returns S0 = K_CC − K_CI K_II⁻¹ K_IC (dense). A Jacobian J = K + Kc
//! has the Schur complement S0 + Kc_CC, so each new contact tangent Kc
//! costs a dense factorisation of |C|² entries instead of a sparse one of
//! the whole matrix; MatSolve on the MUMPS factor then condenses the
//! right-hand side on C, solves with the dense factors held in the factor
//! matrix, and expands back. The preconditioner is set up from Kc alone
//! (the operator SNES hands it holds only the contact tangent; K is in the
//! factor), so nothing of the size of K is copied per Jacobian. PETSc
//! supports Schur complements of MUMPS on one process only.
use super::{petsc_call, sys, Matrix, PetscError, PetscInt, Result, Vector};
use std::ffi::c_void;
use std::panic::{catch_unwind, AssertUnwindSafe};

/// K factored with a dense Schur complement on the sorted DOFs `c`.
pub struct SchurFactor {
    factor: sys::Mat,
    is: sys::IS,
    c: Vec<PetscInt>,
    /// Whether the DOF at each position of `c` is constrained (its row and
    /// column are the identity's in the factored K).
    fixed: Vec<bool>,
    /// S0, column-major |C| × |C|, both triangles.
    base: Vec<f64>,
}

/// A (square, sequential) sparse submatrix `m`'s values added into the
/// dense column-major |C| × |C| `out`, except in the rows and columns
/// `fixed` marks.
fn add_sparse_dense(m: sys::Mat, fixed: &[bool], out: &mut [f64]) -> Result<()> {
    let n = fixed.len();
    for row in 0..n {
        if fixed[row] {
            continue;
        }
        let mut nz: PetscInt = 0;
        let mut cols: *const PetscInt = std::ptr::null();
        let mut vals: *const f64 = std::ptr::null();
        // SAFETY: `m` is a valid assembled sequential matrix with n rows;
        // the row's pointers are read only between MatGetRow and the paired
        // MatRestoreRow, and hold `nz` entries each.
        unsafe {
            petsc_call!(MatGetRow(m, row as PetscInt, &mut nz, &mut cols, &mut vals))?;
            if nz > 0 && !cols.is_null() && !vals.is_null() {
                let cs = std::slice::from_raw_parts(cols, nz as usize);
                let vs = std::slice::from_raw_parts(vals, nz as usize);
                for (&c, &v) in cs.iter().zip(vs) {
                    if !fixed[c as usize] {
                        out[c as usize * n + row] += v;
                    }
                }
            }
            petsc_call!(MatRestoreRow(
                m,
                row as PetscInt,
                &mut nz,
                &mut cols,
                &mut vals
            ))?;
        }
    }
    Ok(())
}

fn error(call: &'static str, message: String) -> PetscError {
    PetscError {
        call,
        code: -1,
        message,
    }
}

impl SchurFactor {
    /// Factors `k` (assembled, sequential, the rows and columns of the
    /// sorted DOFs `constrained` replaced by the identity) with the Schur
    /// complement on the sorted, distinct DOFs `c`: LDLᵀ when `cholesky`,
    /// else LU.
    pub fn new(
        k: &Matrix,
        c: Vec<PetscInt>,
        constrained: &[PetscInt],
        cholesky: bool,
    ) -> Result<Self> {
        if c.is_empty() || c.windows(2).any(|w| w[0] >= w[1]) {
            return Err(error(
                "SchurFactor::new",
                "the Schur DOFs must be sorted, distinct and not empty".into(),
            ));
        }
        let n = c.len();
        let fixed = c
            .iter()
            .map(|d| constrained.binary_search(d).is_ok())
            .collect();
        let mut me = SchurFactor {
            factor: std::ptr::null_mut(),
            is: std::ptr::null_mut(),
            c,
            fixed,
            base: vec![0.0; n * n],
        };
        let kind = if cholesky {
            sys::MatFactorType_MAT_FACTOR_CHOLESKY
        } else {
            sys::MatFactorType_MAT_FACTOR_LU
        };
        let mut s0: sys::Mat = std::ptr::null_mut();
        // SAFETY: `k` is a valid assembled matrix; the factor and the index
        // set are owned by `me` (destroyed in Drop, also on an early error);
        // `me.c` outlives the IS (PETSC_COPY_VALUES copies it anyway). The
        // Schur copy `s0` is destroyed below on every path; its array is
        // read only while it lives.
        unsafe {
            petsc_call!(ISCreateGeneral(
                super::comm_world(),
                super::to_petsc_int(n)?,
                me.c.as_ptr(),
                sys::PetscCopyMode_PETSC_COPY_VALUES,
                &mut me.is
            ))?;
            petsc_call!(MatGetFactor(
                k.raw(),
                c"mumps".as_ptr(),
                kind,
                &mut me.factor
            ))?;
            petsc_call!(MatFactorSetSchurIS(me.factor, me.is))?;
            let mut info = sys::MatFactorInfo::default();
            petsc_call!(MatFactorInfoInitialize(&mut info))?;
            if cholesky {
                petsc_call!(MatCholeskyFactorSymbolic(
                    me.factor,
                    k.raw(),
                    std::ptr::null_mut(),
                    &info
                ))?;
                petsc_call!(MatCholeskyFactorNumeric(me.factor, k.raw(), &info))?;
            } else {
                petsc_call!(MatLUFactorSymbolic(
                    me.factor,
                    k.raw(),
                    std::ptr::null_mut(),
                    std::ptr::null_mut(),
                    &info
                ))?;
                petsc_call!(MatLUFactorNumeric(me.factor, k.raw(), &info))?;
            }
            me.check_factor_error()?;
            let mut status: sys::MatFactorSchurStatus = 0;
            petsc_call!(MatFactorCreateSchurComplement(
                me.factor,
                &mut s0,
                &mut status
            ))?;
            let read = (|| -> Result<()> {
                let mut arr: *const f64 = std::ptr::null();
                petsc_call!(MatDenseGetArrayRead(s0, &mut arr))?;
                me.base
                    .copy_from_slice(std::slice::from_raw_parts(arr, n * n));
                petsc_call!(MatDenseRestoreArrayRead(s0, &mut arr))?;
                if cholesky {
                    symmetrise(&mut me.base, n);
                }
                Ok(())
            })();
            sys::MatDestroy(&mut s0);
            read?;
        }
        Ok(me)
    }

    /// MUMPS reports a failed factorisation (a singular K_II, say) through
    /// the factor's error type, not the call's code.
    fn check_factor_error(&self) -> Result<()> {
        let mut err: sys::MatFactorError = 0;
        // SAFETY: valid factor; out-pointer is a local.
        unsafe { petsc_call!(MatFactorGetError(self.factor, &mut err))? };
        if err != sys::MatFactorError_MAT_FACTOR_NOERROR {
            return Err(error(
                "MatFactorGetError",
                format!("the MUMPS factorisation of the bulk stiffness with a Schur complement on {} contact DOFs failed (error type {err})", self.c.len()),
            ));
        }
        Ok(())
    }

    /// The Schur DOFs (sorted).
    pub fn dofs(&self) -> &[PetscInt] {
        &self.c
    }

    /// Sets the dense Schur complement to that of K + `kc` and factors it:
    /// `kc` is the contact tangent alone (non-zero only in C × C; its
    /// entries in constrained rows and columns are ignored, as the
    /// Jacobian's Dirichlet replacement would drop them).
    pub fn update(&mut self, kc: &Matrix) -> Result<()> {
        let n = self.c.len();
        let mut jcc: sys::Mat = std::ptr::null_mut();
        let mut s: sys::Mat = std::ptr::null_mut();
        let mut status: sys::MatFactorSchurStatus = 0;
        let mut dense = self.base.clone();
        // SAFETY: valid factor with a Schur complement of size n (set in
        // `new`) and valid index set; `kc` is a valid assembled matrix of the
        // factored size. The submatrix is destroyed on every path. The Schur
        // matrix is the factor's own (borrowed between Get and Restore); its
        // array holds n × n column-major values and is written only between
        // MatDenseGetArray and its restore. Restoring it as unfactored clears
        // its old dense factors, so the factorisation that follows is fresh.
        unsafe {
            petsc_call!(MatCreateSubMatrix(
                kc.raw(),
                self.is,
                self.is,
                sys::MatReuse_MAT_INITIAL_MATRIX,
                &mut jcc
            ))?;
            let added = add_sparse_dense(jcc, &self.fixed, &mut dense);
            sys::MatDestroy(&mut jcc);
            added?;
            petsc_call!(MatFactorGetSchurComplement(
                self.factor,
                &mut s,
                &mut status
            ))?;
            petsc_call!(MatFactorRestoreSchurComplement(
                self.factor,
                &mut s,
                sys::MatFactorSchurStatus_MAT_FACTOR_SCHUR_UNFACTORED
            ))?;
            petsc_call!(MatFactorGetSchurComplement(
                self.factor,
                &mut s,
                &mut status
            ))?;
            let mut arr: *mut f64 = std::ptr::null_mut();
            petsc_call!(MatDenseGetArray(s, &mut arr))?;
            std::slice::from_raw_parts_mut(arr, n * n).copy_from_slice(&dense);
            petsc_call!(MatDenseRestoreArray(s, &mut arr))?;
            petsc_call!(MatFactorRestoreSchurComplement(
                self.factor,
                &mut s,
                sys::MatFactorSchurStatus_MAT_FACTOR_SCHUR_UNFACTORED
            ))?;
            petsc_call!(MatFactorFactorizeSchurComplement(self.factor))?;
        }
        Ok(())
    }

    /// x = (K + Kc)⁻¹ b with the Kc of the last [`Self::update`] (K with
    /// its Dirichlet replacement, Kc without the constrained rows and
    /// columns).
    pub fn solve(&self, b: &Vector, x: &mut Vector) -> Result<()> {
        // SAFETY: valid factor, its Schur complement set and factored by
        // `update` (MatSolve factors it first otherwise); vectors of the
        // factored size (PETSc checks).
        unsafe { petsc_call!(MatSolve(self.factor, b.raw(), x.raw())) }
    }
}

/// The Schur complement of an LDLᵀ factorisation may come with one
/// triangle filled and the other zero: the zero one becomes the mirror of
/// the other (the dense Cholesky reads the lower one, and the contact part
/// added later is added to both).
fn symmetrise(a: &mut [f64], n: usize) {
    let (mut lower, mut upper) = (false, false);
    for j in 0..n {
        for i in 0..n {
            let filled = a[j * n + i] != 0.0;
            lower |= filled && i > j;
            upper |= filled && i < j;
        }
    }
    if lower == upper {
        return;
    }
    for j in 0..n {
        for i in (j + 1)..n {
            if lower {
                a[i * n + j] = a[j * n + i];
            } else {
                a[j * n + i] = a[i * n + j];
            }
        }
    }
}

impl Drop for SchurFactor {
    fn drop(&mut self) {
        // SAFETY: owned and destroyed once (null handles are skipped by PETSc).
        unsafe {
            sys::MatDestroy(&mut self.factor);
            sys::ISDestroy(&mut self.is);
        }
    }
}

/// What the shell preconditioner keeps: a handle on the bulk stiffness and
/// the constrained rows, its Schur factor for the current contact DOFs, the DOFs the
/// contact tangent may touch now, and counters.
pub struct SchurPreconditioner {
    k: Matrix,
    constrained: Vec<PetscInt>,
    cholesky: bool,
    factor: Option<SchurFactor>,
    wanted: Vec<PetscInt>,
    /// Sparse factorisations of K (the first, and one per growth of C).
    pub bulk_factorisations: usize,
    /// Dense factorisations of the Schur complement (one per set-up).
    pub schur_factorisations: usize,
    /// Times C had to grow.
    pub growths: usize,
    /// The last set-up's failure, for the report.
    pub last_error: Option<String>,
}

impl SchurPreconditioner {
    /// `k`: the linear bulk stiffness; `constrained`: the rows and columns
    /// the Jacobian replaces by the identity (K is factored with the same
    /// replacement, made on a copy that lives only while it is factored,
    /// and the contact tangent's entries there are dropped).
    pub fn new(k: Matrix, mut constrained: Vec<PetscInt>, cholesky: bool) -> Self {
        constrained.sort_unstable();
        constrained.dedup();
        SchurPreconditioner {
            k,
            constrained,
            cholesky,
            factor: None,
            wanted: Vec::new(),
            bulk_factorisations: 0,
            schur_factorisations: 0,
            growths: 0,
            last_error: None,
        }
    }

    /// The DOFs the contact tangent may touch from now on (any order,
    /// repeats allowed): C grows at the next set-up if they are not in it.
    pub fn want(&mut self, mut dofs: Vec<PetscInt>) {
        dofs.sort_unstable();
        dofs.dedup();
        self.wanted = dofs;
    }

    /// |C| of the current factor (0 before the first).
    pub fn schur_size(&self) -> usize {
        self.factor.as_ref().map_or(0, |f| f.dofs().len())
    }

    /// Set-up for the Jacobian K + `kc`, from the contact tangent `kc`
    /// alone: K factored again only when C must grow.
    pub fn set_up(&mut self, kc: &Matrix) -> Result<()> {
        let grow = match &self.factor {
            None => true,
            Some(f) => !is_subset(&self.wanted, f.dofs()),
        };
        if grow {
            let mut c: Vec<PetscInt> = self.wanted.clone();
            if let Some(f) = &self.factor {
                c.extend_from_slice(f.dofs());
                self.growths += 1;
            }
            c.sort_unstable();
            c.dedup();
            if c.is_empty() {
                // No contact coupling yet: any one DOF makes a (trivial) C.
                c.push(0);
            }
            self.factor = None;
            let mut kd = self.k.duplicate()?;
            kd.zero_rows_columns_identity(&self.constrained)?;
            self.factor = Some(SchurFactor::new(&kd, c, &self.constrained, self.cholesky)?);
            self.bulk_factorisations += 1;
        }
        let f = self
            .factor
            .as_mut()
            .ok_or_else(|| error("SchurPreconditioner::set_up", "no factor".into()))?;
        f.update(kc)?;
        self.schur_factorisations += 1;
        Ok(())
    }

    pub fn apply(&self, b: &Vector, x: &mut Vector) -> Result<()> {
        match &self.factor {
            Some(f) => f.solve(b, x),
            None => Err(error(
                "SchurPreconditioner::apply",
                "applied before its set-up".into(),
            )),
        }
    }
}

/// Both sorted: every entry of `a` is in `b`.
fn is_subset(a: &[PetscInt], b: &[PetscInt]) -> bool {
    a.iter().all(|x| b.binary_search(x).is_ok())
}

/// Makes `pc` a shell preconditioner backed by `state`.
///
/// # Safety
/// `pc` must be a valid PC and `state` must stay at its address, alive,
/// until the PC is destroyed or given another type.
pub(super) unsafe fn install(pc: sys::PC, state: *mut SchurPreconditioner) -> Result<()> {
    // SAFETY: as the caller promises; the callbacks below read the context
    // only while PETSc runs them on this PC.
    unsafe {
        petsc_call!(PCSetType(pc, c"shell".as_ptr()))?;
        petsc_call!(PCShellSetContext(pc, state as *mut c_void))?;
        petsc_call!(PCShellSetSetUp(pc, Some(set_up_trampoline)))?;
        petsc_call!(PCShellSetApply(pc, Some(apply_trampoline)))?;
        petsc_call!(PCShellSetName(
            pc,
            c"MUMPS Schur complement on the contact DOFs".as_ptr()
        ))
    }
}

/// The shell's context.
///
/// # Safety
/// `pc` is a shell PC set up by [`install`].
unsafe fn context<'a>(pc: sys::PC) -> Result<&'a mut SchurPreconditioner> {
    let mut ctx: *mut c_void = std::ptr::null_mut();
    // SAFETY: valid shell PC; PCShellGetContext writes the stored pointer
    // into the out-pointer (passed as void*, as PETSc 3.18 declares it).
    unsafe {
        petsc_call!(PCShellGetContext(
            pc,
            &mut ctx as *mut *mut c_void as *mut c_void
        ))?;
        (ctx as *mut SchurPreconditioner)
            .as_mut()
            .ok_or_else(|| error("PCShellGetContext", "no context".into()))
    }
}

fn code_of(r: std::thread::Result<Result<()>>, state: Option<&mut SchurPreconditioner>) -> i32 {
    let message = match r {
        Ok(Ok(())) => return 0,
        Ok(Err(e)) => e.to_string(),
        Err(_) => "panic in the Schur preconditioner".into(),
    };
    if let Some(s) = state {
        s.last_error = Some(message);
    }
    sys::PETSC_ERR_LIB
}

unsafe extern "C" fn set_up_trampoline(pc: sys::PC) -> sys::PetscErrorCode {
    // SAFETY: PETSc calls this on the shell PC `install` set up.
    let Ok(state) = (unsafe { context(pc) }) else {
        return sys::PETSC_ERR_LIB;
    };
    let mut a: sys::Mat = std::ptr::null_mut();
    let mut p: sys::Mat = std::ptr::null_mut();
    // SAFETY: valid PC; the operators are borrowed for this call only.
    let got = unsafe { petsc_call!(PCGetOperators(pc, &mut a, &mut p)) };
    let r = catch_unwind(AssertUnwindSafe(|| {
        got?;
        // SAFETY: the preconditioning matrix is valid during the set-up.
        // On this path it holds the contact tangent alone (see
        // `solve::mechanics`).
        let kc = unsafe { Matrix::borrowed(p) };
        state.set_up(&kc)
    }));
    code_of(r, Some(state))
}

unsafe extern "C" fn apply_trampoline(
    pc: sys::PC,
    b: sys::Vec,
    x: sys::Vec,
) -> sys::PetscErrorCode {
    // SAFETY: PETSc calls this on the shell PC `install` set up.
    let Ok(state) = (unsafe { context(pc) }) else {
        return sys::PETSC_ERR_LIB;
    };
    // SAFETY: PETSc passes valid vectors for the call's duration.
    let (bv, mut xv) = unsafe { (Vector::borrowed(b), Vector::borrowed(x)) };
    let r = catch_unwind(AssertUnwindSafe(|| state.apply(&bv, &mut xv)));
    code_of(r, Some(state))
}

//! G = Pᵀ K⁻¹ P by MUMPS's selected inverse entries.
use super::super::shell::error;
use super::super::{comm_world, petsc_call, sys, PetscInt, Result};
use super::{LowRankPreconditioner, OwnedMat};

impl LowRankPreconditioner {
    /// G's entries by MUMPS's selected inverse (ICNTL(30)): the pattern
    /// C × C of K⁻¹ requested on rank 0 as the transpose of a sparse
    /// right-hand side, so MUMPS prunes its solves to the tree paths of C
    /// (whole solves with |C| unit right-hand sides cost 1.99e11 flops per
    /// rank at hertz-cylinder h = 0.2, against 4.9e9 for the 14 solves of
    /// the run). The request is an N × N matrix held on rank 0 whose row c
    /// lists C: K⁻¹'s column c at the rows of C.
    pub(super) fn inverse_entries(&mut self, rows: PetscInt) -> Result<()> {
        let n = self.c.len();
        let here = if self.root { rows } else { 0 };
        let nn = super::super::to_petsc_int(n)?;
        let lengths: Vec<PetscInt> = if self.root {
            let mut l = vec![0; rows as usize];
            for &d in &self.c {
                l[d as usize] = nn;
            }
            l
        } else {
            Vec::new()
        };
        let ones = vec![1.0; n];
        let mut bt = OwnedMat(std::ptr::null_mut());
        // SAFETY: the request matrix is owned by its guard; `lengths` holds
        // one entry per local row and the rows set are local (rank 0 owns
        // every row and column); MUMPS writes the entries into its values;
        // each row is read between MatGetRow and its restore. ICNTL(30) and
        // ICNTL(21) are put back to what MatSolve expects (PETSc leaves the
        // selected-inverse mode and a centralised solution set).
        unsafe {
            petsc_call!(MatCreateAIJ(
                comm_world(),
                here,
                here,
                rows,
                rows,
                0,
                if self.root {
                    lengths.as_ptr()
                } else {
                    std::ptr::null()
                },
                0,
                std::ptr::null(),
                &mut bt.0
            ))?;
            if self.root {
                for &d in &self.c {
                    petsc_call!(MatSetValues(
                        bt.0,
                        1,
                        &d,
                        nn,
                        self.c.as_ptr(),
                        ones.as_ptr(),
                        sys::InsertMode_INSERT_VALUES
                    ))?;
                }
            }
            petsc_call!(MatAssemblyBegin(
                bt.0,
                sys::MatAssemblyType_MAT_FINAL_ASSEMBLY
            ))?;
            petsc_call!(MatAssemblyEnd(
                bt.0,
                sys::MatAssemblyType_MAT_FINAL_ASSEMBLY
            ))?;
            let got = petsc_call!(MatMumpsGetInverseTranspose(self.factor, bt.0));
            petsc_call!(MatMumpsSetIcntl(self.factor, 30, 0))?;
            petsc_call!(MatMumpsSetIcntl(self.factor, 21, 1))?;
            got?;
        }
        let local = (|| -> Result<()> {
            if !self.root {
                return Ok(());
            }
            // SAFETY: rank 0 reads its own rows of the assembled request,
            // each between MatGetRow and its restore.
            unsafe {
                for (j, &d) in self.c.iter().enumerate() {
                    let mut nz: PetscInt = 0;
                    let mut cols: *const PetscInt = std::ptr::null();
                    let mut vals: *const f64 = std::ptr::null();
                    petsc_call!(MatGetRow(bt.0, d, &mut nz, &mut cols, &mut vals))?;
                    let ok = nz == nn && !vals.is_null();
                    if ok {
                        let vs = std::slice::from_raw_parts(vals, n);
                        self.g[j * n..(j + 1) * n].copy_from_slice(vs);
                    }
                    petsc_call!(MatRestoreRow(bt.0, d, &mut nz, &mut cols, &mut vals))?;
                    if !ok {
                        return Err(error(
                            "MatMumpsGetInverseTranspose",
                            format!("row {d} of the inverse entries has {nz} of {n} entries"),
                        ));
                    }
                }
            }
            Ok(())
        })();
        let failed = (self.any_rank)(local.is_err());
        local?;
        if failed {
            return Err(error(
                "MatMumpsGetInverseTranspose",
                "reading the inverse entries failed on rank 0".into(),
            ));
        }
        Ok(())
    }
}

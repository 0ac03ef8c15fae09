//! Index sets as collectives: every rank's indices on every rank.
use super::{comm_world, petsc_call, sys, to_petsc_int, PetscInt, Result};

/// Every rank's `local` indices on every rank, in rank order (ISAllGather).
/// Collective.
pub fn all_gather(local: &[PetscInt]) -> Result<Vec<PetscInt>> {
    let mut is: sys::IS = std::ptr::null_mut();
    let mut all: sys::IS = std::ptr::null_mut();
    // SAFETY: `local` is valid for its length and copied; both index sets
    // are destroyed on every path; the gathered indices are read only
    // between ISGetIndices and its restore.
    unsafe {
        petsc_call!(ISCreateGeneral(
            comm_world(),
            to_petsc_int(local.len())?,
            local.as_ptr(),
            sys::PetscCopyMode_PETSC_COPY_VALUES,
            &mut is
        ))?;
        let read = (|| -> Result<Vec<PetscInt>> {
            petsc_call!(ISAllGather(is, &mut all))?;
            let mut n: PetscInt = 0;
            petsc_call!(ISGetLocalSize(all, &mut n))?;
            let mut p: *const PetscInt = std::ptr::null();
            petsc_call!(ISGetIndices(all, &mut p))?;
            let v = if n > 0 && !p.is_null() {
                std::slice::from_raw_parts(p, n as usize).to_vec()
            } else {
                Vec::new()
            };
            petsc_call!(ISRestoreIndices(all, &mut p))?;
            Ok(v)
        })();
        sys::ISDestroy(&mut all);
        sys::ISDestroy(&mut is);
        read
    }
}

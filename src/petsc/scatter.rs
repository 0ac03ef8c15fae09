//! Vector scatters: moving entries between layouts (e.g. PETSc's DOF order to
//! the input order the output file uses).
use super::{petsc_call, sys, PetscInt, Result, Vector};

/// A scatter from a source vector's entries `from[i]` into a target vector's
/// entries `to[i]` (global indices on both sides).
pub struct Scatter {
    raw: sys::VecScatter,
}

impl Scatter {
    pub fn new(src: &Vector, from: &[PetscInt], dst: &Vector, to: &[PetscInt]) -> Result<Self> {
        let mut is_from: sys::IS = std::ptr::null_mut();
        let mut is_to: sys::IS = std::ptr::null_mut();
        let mut raw: sys::VecScatter = std::ptr::null_mut();
        // SAFETY: index slices valid and copied by ISCreateGeneral; the index sets
        // are destroyed after the scatter (which keeps what it needs) is built.
        unsafe {
            let comm = super::comm_world();
            petsc_call!(ISCreateGeneral(
                comm,
                from.len() as PetscInt,
                from.as_ptr(),
                sys::PetscCopyMode_PETSC_COPY_VALUES,
                &mut is_from
            ))?;
            petsc_call!(ISCreateGeneral(
                comm,
                to.len() as PetscInt,
                to.as_ptr(),
                sys::PetscCopyMode_PETSC_COPY_VALUES,
                &mut is_to
            ))?;
            let made = petsc_call!(VecScatterCreate(
                src.raw(),
                is_from,
                dst.raw(),
                is_to,
                &mut raw
            ));
            sys::ISDestroy(&mut is_from);
            sys::ISDestroy(&mut is_to);
            made?;
        }
        Ok(Scatter { raw })
    }

    /// dst[to] = src[from]. Collective.
    pub fn forward(&self, src: &Vector, dst: &mut Vector) -> Result<()> {
        // SAFETY: vectors match the layouts the scatter was built with (PETSc checks).
        unsafe {
            petsc_call!(VecScatterBegin(
                self.raw,
                src.raw(),
                dst.raw(),
                sys::InsertMode_INSERT_VALUES,
                sys::ScatterMode_SCATTER_FORWARD
            ))?;
            petsc_call!(VecScatterEnd(
                self.raw,
                src.raw(),
                dst.raw(),
                sys::InsertMode_INSERT_VALUES,
                sys::ScatterMode_SCATTER_FORWARD
            ))
        }
    }
}

impl Drop for Scatter {
    fn drop(&mut self) {
        // SAFETY: owned and destroyed once.
        unsafe {
            sys::VecScatterDestroy(&mut self.raw);
        }
    }
}

impl Scatter {
    /// A scatter that copies all of `src` into a new sequential vector on every rank.
    pub fn to_all(src: &Vector) -> Result<(Scatter, Vector)> {
        let mut raw: sys::VecScatter = std::ptr::null_mut();
        let mut out: sys::Vec = std::ptr::null_mut();
        // SAFETY: valid source vec; PETSc creates both the scatter and the output vector.
        unsafe {
            petsc_call!(VecScatterCreateToAll(src.raw(), &mut raw, &mut out))?;
            Ok((Scatter { raw }, Vector::owned_from_raw(out)))
        }
    }
}

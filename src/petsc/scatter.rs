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
        Self::with_index_sets(super::comm_world(), src, from, dst, to)
    }

    /// As [`Self::new`], with index sets on this process alone: each rank
    /// names the entries it moves (a parallel vector's entries to a
    /// sequential one, say). Collective.
    pub fn new_local(
        src: &Vector,
        from: &[PetscInt],
        dst: &Vector,
        to: &[PetscInt],
    ) -> Result<Self> {
        Self::with_index_sets(super::vector::self_comm(), src, from, dst, to)
    }

    fn with_index_sets(
        comm: sys::MPI_Comm,
        src: &Vector,
        from: &[PetscInt],
        dst: &Vector,
        to: &[PetscInt],
    ) -> Result<Self> {
        let mut is_from: sys::IS = std::ptr::null_mut();
        let mut is_to: sys::IS = std::ptr::null_mut();
        let mut raw: sys::VecScatter = std::ptr::null_mut();
        // SAFETY: index slices valid and copied by ISCreateGeneral; the index sets
        // are destroyed after the scatter (which keeps what it needs) is built.
        unsafe {
            petsc_call!(ISCreateGeneral(
                comm,
                super::to_petsc_int(from.len())?,
                from.as_ptr(),
                sys::PetscCopyMode_PETSC_COPY_VALUES,
                &mut is_from
            ))?;
            let made = petsc_call!(ISCreateGeneral(
                comm,
                super::to_petsc_int(to.len())?,
                to.as_ptr(),
                sys::PetscCopyMode_PETSC_COPY_VALUES,
                &mut is_to
            ))
            .and_then(|()| {
                petsc_call!(VecScatterCreate(
                    src.raw(),
                    is_from,
                    dst.raw(),
                    is_to,
                    &mut raw
                ))
            });
            sys::ISDestroy(&mut is_from);
            sys::ISDestroy(&mut is_to);
            made?;
        }
        Ok(Scatter { raw })
    }

    /// Another handle on the same scatter (PETSc counts references).
    pub fn share(&self) -> Result<Scatter> {
        // SAFETY: a valid scatter; the new handle's Drop releases this reference.
        unsafe { petsc_call!(PetscObjectReference(self.raw as sys::PetscObject))? };
        Ok(Scatter { raw: self.raw })
    }

    /// dst[from] += src[to]: the reverse scatter, adding. Collective.
    pub fn reverse_add(&self, src: &Vector, dst: &mut Vector) -> Result<()> {
        // SAFETY: vectors match the layouts the scatter was built with, the
        // other way round (PETSc checks); begin and end are paired.
        unsafe {
            petsc_call!(VecScatterBegin(
                self.raw,
                src.raw(),
                dst.raw(),
                sys::InsertMode_ADD_VALUES,
                sys::ScatterMode_SCATTER_REVERSE
            ))?;
            petsc_call!(VecScatterEnd(
                self.raw,
                src.raw(),
                dst.raw(),
                sys::InsertMode_ADD_VALUES,
                sys::ScatterMode_SCATTER_REVERSE
            ))
        }
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

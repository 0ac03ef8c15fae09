//! Distributed vectors: plain (`Vector`) and with ghost entries (`GhostedVector`,
//! the owned + ghost layout the halo exchange of nodal fields runs on).
use super::{comm_world, petsc_call, sys, to_petsc_int, PetscInt, Result};

/// A distributed PETSc vector, owned (destroyed on drop) or borrowed from PETSc.
pub struct Vector {
    raw: sys::Vec,
    owned: bool,
}

impl Vector {
    /// A vector with `local` entries on this rank, on PETSc's world communicator.
    pub fn new_mpi(local: usize) -> Result<Self> {
        let mut raw: sys::Vec = std::ptr::null_mut();
        // SAFETY: PETSc is initialised; `raw` is a valid out-pointer.
        unsafe {
            petsc_call!(VecCreateMPI(
                comm_world(),
                to_petsc_int(local)?,
                sys::PETSC_DETERMINE,
                &mut raw
            ))?;
        }
        Ok(Vector { raw, owned: true })
    }

    /// A vector of `n` entries on this process alone.
    pub fn new_seq(n: usize) -> Result<Self> {
        let mut raw: sys::Vec = std::ptr::null_mut();
        // SAFETY: PETSc is initialised; `raw` is a valid out-pointer.
        unsafe { petsc_call!(VecCreateSeq(self_comm(), to_petsc_int(n)?, &mut raw))? };
        Ok(Vector { raw, owned: true })
    }

    /// Wraps a vector PETSc owns (e.g. inside a SNES callback); not destroyed on drop.
    ///
    /// # Safety
    /// `raw` must be a valid Vec for the lifetime of the returned value.
    pub(crate) unsafe fn borrowed(raw: sys::Vec) -> Self {
        Vector { raw, owned: false }
    }

    /// # Safety
    /// `raw` must be a valid Vec whose single reference is handed to the result.
    pub(crate) unsafe fn owned_from_raw(raw: sys::Vec) -> Self {
        Vector { raw, owned: true }
    }

    pub(crate) fn raw(&self) -> sys::Vec {
        self.raw
    }

    pub fn duplicate(&self) -> Result<Self> {
        let mut raw: sys::Vec = std::ptr::null_mut();
        // SAFETY: self.raw is valid; out-pointer valid.
        unsafe { petsc_call!(VecDuplicate(self.raw, &mut raw))? };
        Ok(Vector { raw, owned: true })
    }

    /// [start, end) of the global indices this rank owns.
    pub fn ownership_range(&self) -> Result<(usize, usize)> {
        let (mut lo, mut hi): (PetscInt, PetscInt) = (0, 0);
        // SAFETY: valid vec and out-pointers.
        unsafe { petsc_call!(VecGetOwnershipRange(self.raw, &mut lo, &mut hi))? };
        Ok((lo as usize, hi as usize))
    }

    pub fn global_size(&self) -> Result<usize> {
        let mut n: PetscInt = 0;
        // SAFETY: valid vec and out-pointer.
        unsafe { petsc_call!(VecGetSize(self.raw, &mut n))? };
        Ok(n as usize)
    }

    pub fn set_all(&mut self, value: f64) -> Result<()> {
        // SAFETY: valid vec.
        unsafe { petsc_call!(VecSet(self.raw, value)) }
    }

    /// Adds `values` at global indices (off-rank entries allowed); call
    /// [`Vector::assemble`] afterwards.
    pub fn add_values(&mut self, indices: &[PetscInt], values: &[f64]) -> Result<()> {
        debug_assert_eq!(indices.len(), values.len());
        // SAFETY: slices have equal length, given as the count.
        unsafe {
            petsc_call!(VecSetValues(
                self.raw,
                indices.len() as PetscInt,
                indices.as_ptr(),
                values.as_ptr(),
                sys::InsertMode_ADD_VALUES
            ))
        }
    }

    pub fn assemble(&mut self) -> Result<()> {
        // SAFETY: valid vec; begin/end paired.
        unsafe {
            petsc_call!(VecAssemblyBegin(self.raw))?;
            petsc_call!(VecAssemblyEnd(self.raw))
        }
    }

    /// The global dot product `self · other` (collective).
    pub fn dot(&self, other: &Vector) -> Result<f64> {
        let mut d = 0.0;
        // SAFETY: both valid vecs of the same layout (PETSc checks); out-pointer valid.
        unsafe { petsc_call!(VecDot(self.raw, other.raw, &mut d))? };
        Ok(d)
    }

    pub fn norm2(&self) -> Result<f64> {
        self.norm(sys::NormType_NORM_2)
    }

    pub fn norm_inf(&self) -> Result<f64> {
        self.norm(sys::NormType_NORM_INFINITY)
    }

    fn norm(&self, kind: sys::NormType) -> Result<f64> {
        let mut n = 0.0;
        // SAFETY: valid vec and out-pointer.
        unsafe { petsc_call!(VecNorm(self.raw, kind, &mut n))? };
        Ok(n)
    }

    /// Whether both hold the same entries (collective).
    pub fn equals(&self, other: &Vector) -> Result<bool> {
        let mut same = sys::PetscBool_PETSC_FALSE;
        // SAFETY: both valid vecs of the same layout (PETSc checks); out-pointer valid.
        unsafe { petsc_call!(VecEqual(self.raw, other.raw, &mut same))? };
        Ok(same == sys::PetscBool_PETSC_TRUE)
    }

    pub fn copy_from(&mut self, other: &Vector) -> Result<()> {
        // SAFETY: both valid with the same layout (caller's contract, PETSc checks).
        unsafe { petsc_call!(VecCopy(other.raw, self.raw)) }
    }

    /// self += a * x
    pub fn axpy(&mut self, a: f64, x: &Vector) -> Result<()> {
        // SAFETY: both valid; PETSc checks compatible layouts.
        unsafe { petsc_call!(VecAXPY(self.raw, a, x.raw)) }
    }

    pub fn scale(&mut self, a: f64) -> Result<()> {
        // SAFETY: valid vec.
        unsafe { petsc_call!(VecScale(self.raw, a)) }
    }

    /// Reads the owned entries.
    pub fn with_array<T>(&self, f: impl FnOnce(&[f64]) -> T) -> Result<T> {
        let n = self.local_size()?;
        let mut ptr: *const f64 = std::ptr::null();
        // SAFETY: PETSc returns a pointer to `n` owned entries, valid until restore;
        // the slice does not escape `f`.
        unsafe {
            petsc_call!(VecGetArrayRead(self.raw, &mut ptr))?;
            let out = f(if n == 0 {
                &[]
            } else {
                std::slice::from_raw_parts(ptr, n)
            });
            petsc_call!(VecRestoreArrayRead(self.raw, &mut ptr))?;
            Ok(out)
        }
    }

    /// Reads and writes the owned entries.
    pub fn with_array_mut<T>(&mut self, f: impl FnOnce(&mut [f64]) -> T) -> Result<T> {
        let n = self.local_size()?;
        let mut ptr: *mut f64 = std::ptr::null_mut();
        // SAFETY: as in `with_array`, with exclusive access through &mut self.
        unsafe {
            petsc_call!(VecGetArray(self.raw, &mut ptr))?;
            let out = f(if n == 0 {
                &mut []
            } else {
                std::slice::from_raw_parts_mut(ptr, n)
            });
            petsc_call!(VecRestoreArray(self.raw, &mut ptr))?;
            Ok(out)
        }
    }

    pub fn local_size(&self) -> Result<usize> {
        let mut n: PetscInt = 0;
        // SAFETY: valid vec and out-pointer.
        unsafe { petsc_call!(VecGetLocalSize(self.raw, &mut n))? };
        Ok(n as usize)
    }

    pub fn set_block_size(&mut self, bs: usize) -> Result<()> {
        // SAFETY: valid vec.
        unsafe { petsc_call!(VecSetBlockSize(self.raw, to_petsc_int(bs)?)) }
    }
}

impl Drop for Vector {
    fn drop(&mut self) {
        if self.owned && !self.raw.is_null() {
            // SAFETY: we own this Vec and destroy it exactly once.
            unsafe {
                sys::VecDestroy(&mut self.raw);
            }
        }
    }
}

/// MPI's communicator of this process alone.
pub(super) fn self_comm() -> sys::MPI_Comm {
    // SAFETY: MPI is initialised while PETSc is; the handle is a constant.
    unsafe { sys::RSMPI_COMM_SELF }
}

/// A vector with owned entries followed by ghost copies of off-rank entries.
///
/// Forward update copies owners' values into ghosts (halo refresh); reverse
/// update adds ghost contributions back into the owners (assembly).
pub struct GhostedVector {
    vec: Vector,
    n_owned: usize,
    n_ghost: usize,
}

impl GhostedVector {
    /// `ghosts` are global indices of off-rank entries this rank needs.
    pub fn new(n_owned: usize, ghosts: &[PetscInt]) -> Result<Self> {
        let mut raw: sys::Vec = std::ptr::null_mut();
        // SAFETY: ghost slice valid for its length; PETSc copies it.
        unsafe {
            petsc_call!(VecCreateGhost(
                comm_world(),
                to_petsc_int(n_owned)?,
                sys::PETSC_DECIDE,
                to_petsc_int(ghosts.len())?,
                ghosts.as_ptr(),
                &mut raw
            ))?;
        }
        Ok(GhostedVector {
            vec: Vector { raw, owned: true },
            n_owned,
            n_ghost: ghosts.len(),
        })
    }

    /// The global (owned-part) view, usable wherever a `Vector` is.
    pub fn global(&self) -> &Vector {
        &self.vec
    }

    pub fn global_mut(&mut self) -> &mut Vector {
        &mut self.vec
    }

    /// Copies owners' values into every rank's ghost slots.
    pub fn update_ghosts(&mut self) -> Result<()> {
        // SAFETY: valid ghosted vec; begin/end paired.
        unsafe {
            petsc_call!(VecGhostUpdateBegin(
                self.vec.raw,
                sys::InsertMode_INSERT_VALUES,
                sys::ScatterMode_SCATTER_FORWARD
            ))?;
            petsc_call!(VecGhostUpdateEnd(
                self.vec.raw,
                sys::InsertMode_INSERT_VALUES,
                sys::ScatterMode_SCATTER_FORWARD
            ))
        }
    }

    /// Adds ghost-slot contributions into their owners (then ghosts hold stale values).
    pub fn accumulate_ghosts(&mut self) -> Result<()> {
        // SAFETY: valid ghosted vec; begin/end paired.
        unsafe {
            petsc_call!(VecGhostUpdateBegin(
                self.vec.raw,
                sys::InsertMode_ADD_VALUES,
                sys::ScatterMode_SCATTER_REVERSE
            ))?;
            petsc_call!(VecGhostUpdateEnd(
                self.vec.raw,
                sys::InsertMode_ADD_VALUES,
                sys::ScatterMode_SCATTER_REVERSE
            ))
        }
    }

    /// Reads owned + ghost entries (owned first, ghosts in the order given at creation).
    pub fn with_local<T>(&self, f: impl FnOnce(&[f64]) -> T) -> Result<T> {
        let n = self.n_owned + self.n_ghost;
        let mut local: sys::Vec = std::ptr::null_mut();
        let mut ptr: *const f64 = std::ptr::null();
        // SAFETY: the local form is a sequential view of n entries, valid until
        // restored; the slice does not escape `f`.
        unsafe {
            petsc_call!(VecGhostGetLocalForm(self.vec.raw, &mut local))?;
            petsc_call!(VecGetArrayRead(local, &mut ptr))?;
            let out = f(if n == 0 {
                &[]
            } else {
                std::slice::from_raw_parts(ptr, n)
            });
            petsc_call!(VecRestoreArrayRead(local, &mut ptr))?;
            petsc_call!(VecGhostRestoreLocalForm(self.vec.raw, &mut local))?;
            Ok(out)
        }
    }

    /// Writes owned + ghost entries.
    pub fn with_local_mut<T>(&mut self, f: impl FnOnce(&mut [f64]) -> T) -> Result<T> {
        let n = self.n_owned + self.n_ghost;
        let mut local: sys::Vec = std::ptr::null_mut();
        let mut ptr: *mut f64 = std::ptr::null_mut();
        // SAFETY: as in `with_local`, exclusive through &mut self.
        unsafe {
            petsc_call!(VecGhostGetLocalForm(self.vec.raw, &mut local))?;
            petsc_call!(VecGetArray(local, &mut ptr))?;
            let out = f(if n == 0 {
                &mut []
            } else {
                std::slice::from_raw_parts_mut(ptr, n)
            });
            petsc_call!(VecRestoreArray(local, &mut ptr))?;
            petsc_call!(VecGhostRestoreLocalForm(self.vec.raw, &mut local))?;
            Ok(out)
        }
    }
}

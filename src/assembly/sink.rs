//! Where assembled contributions go. `assembly`, `contact` and `fem` add
//! element blocks through these traits and never name the storage behind
//! them; the PETSc matrix and pattern builder implement them here, the one
//! place where `GlobalDof`s become PETSc indices.
use super::pattern::PatternBuilder;
use crate::dofs::GlobalDof;
use crate::error::Result;
use crate::petsc::{Matrix, PetscInt};

/// Something dense blocks of a matrix are added to.
pub trait MatrixSink {
    /// Adds a dense row-major block at (rows, cols); negative DOFs are
    /// skipped (constrained DOFs).
    fn add_block(&mut self, rows: &[GlobalDof], cols: &[GlobalDof], values: &[f64]) -> Result<()>;
}

/// Something that records where a matrix has non-zeros.
pub trait PatternSink {
    /// Records the couplings of `dofs` with themselves (a square element block).
    fn add_square(&mut self, dofs: &[GlobalDof]) -> Result<()>;
}

impl MatrixSink for Matrix {
    fn add_block(&mut self, rows: &[GlobalDof], cols: &[GlobalDof], values: &[f64]) -> Result<()> {
        let (mut r, mut c) = (Indices::default(), Indices::default());
        Ok(Matrix::add_block(self, r.of(rows), c.of(cols), values)?)
    }
}

impl MatrixSink for PatternBuilder {
    fn add_block(&mut self, rows: &[GlobalDof], cols: &[GlobalDof], values: &[f64]) -> Result<()> {
        let (mut r, mut c) = (Indices::default(), Indices::default());
        Ok(PatternBuilder::add_block(
            self,
            r.of(rows),
            c.of(cols),
            values,
        )?)
    }
}

impl PatternSink for PatternBuilder {
    fn add_square(&mut self, dofs: &[GlobalDof]) -> Result<()> {
        let mut d = Indices::default();
        Ok(PatternBuilder::add_square(self, d.of(dofs))?)
    }
}

/// Element blocks have at most this many DOFs in the common case (a hex8
/// has 24, a contact link up to 24): their indices are converted on the
/// stack, larger ones (mortar rows) on the heap.
const STACK_DOFS: usize = 64;

/// Scratch space for one slice of PETSc indices.
struct Indices {
    stack: [PetscInt; STACK_DOFS],
    heap: Vec<PetscInt>,
}

impl Default for Indices {
    fn default() -> Self {
        Indices {
            stack: [0; STACK_DOFS],
            heap: Vec::new(),
        }
    }
}

impl Indices {
    fn of(&mut self, dofs: &[GlobalDof]) -> &[PetscInt] {
        if dofs.len() <= STACK_DOFS {
            for (s, d) in self.stack.iter_mut().zip(dofs) {
                *s = d.0;
            }
            &self.stack[..dofs.len()]
        } else {
            self.heap.clear();
            self.heap.extend(dofs.iter().map(|d| d.0));
            &self.heap
        }
    }
}

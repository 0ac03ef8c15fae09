//! Rows of a natural-order dataset brought to the ranks that need them: each
//! rank reads one contiguous block of the file (`even_block` of the row
//! count, a single hyperslab) and a PETSc scatter moves every row to the
//! rank that asked for it. No rank ever holds the whole array: per rank,
//! its block (rows / ranks) plus the rows it asked for.
use crate::dofs::even_block;
use crate::error::Result;
use crate::petsc::{PetscInt, Scatter, Vector};

/// The block-to-wanted scatter of one row count, column count and wanted
/// row list (reused for every dataset of that shape).
pub(super) struct Fetch {
    scatter: Scatter,
    block: Vector,
    wanted: Vector,
    /// Positions in the wanted list of rows the file does not have (they
    /// come back as NaN, which every consumer refuses).
    missing: Vec<usize>,
    cols: usize,
}

impl Fetch {
    /// `wanted`: the natural rows this rank needs, in the order it wants
    /// them (rows at or past `rows` are reported missing). Collective.
    pub(super) fn new(
        rows: usize,
        cols: usize,
        wanted: &[usize],
        rank: usize,
        nranks: usize,
    ) -> Result<Self> {
        let block = Vector::new_mpi(cols * even_block(rows, rank, nranks).len())?;
        let target = Vector::new_mpi(cols * wanted.len())?;
        let (first, _) = target.ownership_range()?;
        let mut from: Vec<PetscInt> = Vec::with_capacity(cols * wanted.len());
        let mut to: Vec<PetscInt> = Vec::with_capacity(cols * wanted.len());
        let mut missing = Vec::new();
        for (k, &row) in wanted.iter().enumerate() {
            if row >= rows {
                missing.push(k);
                continue;
            }
            for c in 0..cols {
                // The blocks tile 0..rows in rank order, as the block
                // vector's ownership ranges do: row r's value c is entry
                // cols·r + c of it.
                from.push((cols * row + c) as PetscInt);
                to.push((first + cols * k + c) as PetscInt);
            }
        }
        let scatter = Scatter::new(&block, &from, &target, &to)?;
        Ok(Fetch {
            scatter,
            block,
            wanted: target,
            missing,
            cols,
        })
    }

    /// The wanted rows (`cols` values each, flat) of the array whose block
    /// this rank read as `block`. Collective.
    pub(super) fn fetch(&mut self, block: &[f64]) -> Result<Vec<f64>> {
        // The caller read exactly this rank's block (checked against the
        // dataset's shape before any rank got here); copying the common
        // length keeps a slip from panicking between collective calls.
        self.block.with_array_mut(|a| {
            let n = a.len().min(block.len());
            a[..n].copy_from_slice(&block[..n]);
        })?;
        self.scatter.forward(&self.block, &mut self.wanted)?;
        let mut out = self.wanted.with_array(<[f64]>::to_vec)?;
        for &k in &self.missing {
            out[self.cols * k..self.cols * (k + 1)].fill(f64::NAN);
        }
        Ok(out)
    }
}

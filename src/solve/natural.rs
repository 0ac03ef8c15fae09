//! Moving fields from PETSc's (rank-contiguous) order to the input (natural)
//! order the output file uses, so files from any rank count compare row by row.
use crate::dofs::{even_block, DofMap, DIM};
use crate::error::Result;
use crate::petsc::{PetscInt, Scatter, Vector};

/// A scatter from a field stored in PETSc row order (rows owned contiguously
/// per rank, `cols` values per row) into a vector whose rank r holds a
/// contiguous block of natural rows.
pub struct NaturalOrder {
    scatter: Scatter,
    source: Vector,
    target: Vector,
    block: std::ops::Range<usize>,
}

/// The PETSc node of a natural node of this rank's output block, the only
/// rows [`NaturalOrder::new`] asks for.
fn block_row(dofs: &DofMap) -> impl Fn(usize) -> usize + '_ {
    let start = dofs.output_node_block().start;
    let block = dofs.output_block_petsc();
    move |n| block[n - start] as usize
}

impl NaturalOrder {
    /// `owned_rows`: rows this rank owns in PETSc order; `petsc_row(i)`: the
    /// PETSc row of natural row i, asked only for the rows of this rank's
    /// block `even_block(global_rows, rank, nranks)`. Collective.
    pub fn new(
        global_rows: usize,
        cols: usize,
        owned_rows: usize,
        petsc_row: impl Fn(usize) -> usize,
        rank: usize,
        nranks: usize,
    ) -> Result<Self> {
        let block = even_block(global_rows, rank, nranks);
        let source = Vector::new_mpi(cols * owned_rows)?;
        let target = Vector::new_mpi(cols * block.len())?;
        let mut from = Vec::with_capacity(cols * block.len());
        let mut to = Vec::with_capacity(cols * block.len());
        for nat in block.clone() {
            let p = petsc_row(nat);
            for c in 0..cols {
                from.push((cols * p + c) as PetscInt);
                to.push((cols * nat + c) as PetscInt);
            }
        }
        let scatter = Scatter::new(&source, &from, &target, &to)?;
        Ok(NaturalOrder {
            scatter,
            source,
            target,
            block,
        })
    }

    /// Nodal vector fields (3 per node) in the DOF layout.
    pub fn nodal(dofs: &DofMap) -> Result<Self> {
        Self::new(
            dofs.num_global_nodes(),
            DIM,
            dofs.num_owned_nodes(),
            block_row(dofs),
            dofs.rank,
            dofs.nranks,
        )
    }

    /// Nodal scalar fields (one value per owned node, PETSc node order).
    pub fn nodal_scalar(dofs: &DofMap) -> Result<Self> {
        Self::new(
            dofs.num_global_nodes(),
            1,
            dofs.num_owned_nodes(),
            block_row(dofs),
            dofs.rank,
            dofs.nranks,
        )
    }

    /// This rank's natural-order block of `v`: (first natural row, rows × cols values).
    pub fn block_of(&mut self, v: &Vector) -> Result<(usize, Vec<f64>)> {
        self.scatter.forward(v, &mut self.target)?;
        let data = self.target.with_array(|a| a.to_vec())?;
        Ok((self.block.start, data))
    }

    /// As `block_of`, from this rank's owned rows given as a slice.
    pub fn block_of_owned(&mut self, owned: &[f64]) -> Result<(usize, Vec<f64>)> {
        self.source.with_array_mut(|a| a.copy_from_slice(owned))?;
        self.scatter.forward(&self.source, &mut self.target)?;
        let data = self.target.with_array(|a| a.to_vec())?;
        Ok((self.block.start, data))
    }

    /// The whole field in natural order on rank 0, empty on the other ranks
    /// (the run report's final displacement: O(N) memory on rank 0 only,
    /// which receives the natural-order blocks straight into the result).
    /// Collective.
    pub fn gather_root(mut self, v: &Vector) -> Result<Vec<f64>> {
        let (_, block) = self.block_of(v)?;
        // This rank's block is all it needs from here on.
        drop(self);
        let world = mpi::topology::SimpleCommunicator::world();
        Ok(crate::parallel::gather_root(&world, block))
    }
}

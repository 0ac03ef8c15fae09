//! Moving nodal fields from PETSc's DOF order to the input (natural) order the
//! output file uses, so files from any rank count compare row by row.
use crate::dofs::{DofMap, NaturalNode, DIM};
use crate::error::Result;
use crate::petsc::{PetscInt, Scatter, Vector};

/// A scatter from a PETSc-ordered nodal vector into a vector whose rank r
/// holds a contiguous block of natural node ids.
pub struct NaturalOrder {
    scatter: Scatter,
    target: Vector,
    block: std::ops::Range<usize>,
}

impl NaturalOrder {
    pub fn new(dofs: &DofMap) -> Result<Self> {
        let block = dofs.output_node_block();
        let target = Vector::new_mpi(DIM * block.len())?;
        let template = Vector::new_mpi(dofs.num_owned_dofs())?;
        let mut from = Vec::with_capacity(DIM * block.len());
        let mut to = Vec::with_capacity(DIM * block.len());
        for nat in block.clone() {
            for c in 0..DIM {
                from.push(dofs.dof_of_natural(NaturalNode(nat), c).0);
                to.push((DIM * nat + c) as PetscInt);
            }
        }
        let scatter = Scatter::new(&template, &from, &target, &to)?;
        Ok(NaturalOrder {
            scatter,
            target,
            block,
        })
    }

    /// This rank's natural-order block of `v`: (first natural node, N_block×3 values).
    pub fn block_of(&mut self, v: &Vector) -> Result<(usize, Vec<f64>)> {
        self.scatter.forward(v, &mut self.target)?;
        let data = self.target.with_array(|a| a.to_vec())?;
        Ok((self.block.start, data))
    }

    /// The whole field in natural order on every rank (for tests and small
    /// post-processing; O(N) memory per rank). Collective.
    pub fn gather_all(&mut self, v: &Vector) -> Result<Vec<f64>> {
        self.scatter.forward(v, &mut self.target)?;
        let (to_all, mut all) = Scatter::to_all(&self.target)?;
        to_all.forward(&self.target, &mut all)?;
        Ok(all.with_array(|a| a.to_vec())?)
    }
}

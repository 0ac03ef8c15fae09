//! The Newton line search's slope on the contact paths whose Jacobian
//! matrix holds the contact tangent alone (the Schur and low-rank paths:
//! K lives in the preconditioner's factor).
//!
//! PETSc's backtracking line search takes its initial slope as F · (A y),
//! A the SNES's operator and y the step the linear solve returned; with A
//! the contact tangent alone that is not the whole system's slope, and a
//! step the search cuts gets another length than on the full
//! factorisation. The operator is therefore a shell: its product with the
//! step the last linear solve returned is that solve's right-hand side (A y
//! = F for the exact solves these paths make, so the slope is −|F|²; a
//! Krylov method a user puts around them leaves the residual of its
//! tolerance), and any other product is the contact tangent's, as before.
use crate::petsc::{Matrix, Result, ShellOperator, Vector};

/// The shell operator's state: the last linear solve's right-hand side
/// and solution.
#[derive(Default)]
pub struct LastSolve {
    rhs: Option<Vector>,
    sol: Option<Vector>,
}

impl ShellOperator for LastSolve {
    fn solved(&mut self, b: &Vector, x: &Vector) -> Result<()> {
        for (kept, v) in [(&mut self.rhs, b), (&mut self.sol, x)] {
            if kept.is_none() {
                *kept = Some(v.duplicate()?);
            }
            if let Some(k) = kept.as_mut() {
                k.copy_from(v)?;
            }
        }
        Ok(())
    }

    /// y = A x: the last right-hand side when x is the last solution, else
    /// the contact tangent's product.
    fn mult(&mut self, tangent: &Matrix, x: &Vector, y: &mut Vector) -> Result<()> {
        if let (Some(sol), Some(rhs)) = (&self.sol, &self.rhs) {
            if x.equals(sol)? {
                return y.copy_from(rhs);
            }
        }
        tangent.mult(x, y)
    }

    /// Aᵀ x with the contact tangent (what SNES asks when its line search
    /// has failed, to tell a local minimum).
    fn mult_transpose(&mut self, tangent: &Matrix, x: &Vector, y: &mut Vector) -> Result<()> {
        tangent.mult_transpose(x, y)
    }
}

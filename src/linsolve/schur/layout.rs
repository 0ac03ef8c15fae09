//! C, the contact DOFs of the Schur complement, in the order the
//! complement has them, with S0 = K_CC − K_CI K_II⁻¹ K_IC: what the factor
//! and the condensed Newton step share.
use crate::petsc::PetscInt;

/// C and its Schur order, with S0.
pub struct Layout {
    /// The Schur DOFs, sorted.
    pub c: Vec<PetscInt>,
    /// The position in the Schur complement (the index set's order) of
    /// each entry of `c`.
    pub pos: Vec<usize>,
    /// Whether the DOF at each position is constrained (its row and column
    /// are the identity's in the factored K).
    pub fixed: Vec<bool>,
    /// S0, column-major |C| × |C|, both triangles.
    pub base: Vec<f64>,
}

impl Layout {
    /// S0 v, `v` in Schur positions.
    pub fn times_base(&self, v: &[f64]) -> Vec<f64> {
        let n = self.c.len();
        let mut out = vec![0.0; n];
        for (j, &vj) in v.iter().enumerate() {
            if vj == 0.0 {
                continue;
            }
            let col = &self.base[j * n..(j + 1) * n];
            for (o, &s) in out.iter_mut().zip(col) {
                *o += s * vj;
            }
        }
        out
    }

    /// The mean of S0's diagonal over the unconstrained positions (1 when
    /// there are none or it is not positive).
    pub fn mean_free_diagonal(&self) -> f64 {
        let n = self.c.len();
        let free: Vec<f64> = (0..n)
            .filter(|&p| !self.fixed[p])
            .map(|p| self.base[p * n + p])
            .collect();
        let mean = free.iter().sum::<f64>() / free.len().max(1) as f64;
        if mean > 0.0 && mean.is_finite() {
            mean
        } else {
            1.0
        }
    }

    /// The entries of the whole vector `a` on C, in Schur positions.
    pub(super) fn gather(&self, a: &[f64]) -> Vec<f64> {
        let mut out = vec![0.0; self.c.len()];
        for (&d, &p) in self.c.iter().zip(&self.pos) {
            out[p] = a[d as usize];
        }
        out
    }

    /// Writes `v` (Schur positions) into the entries of `a` on C.
    pub(super) fn scatter(&self, v: &[f64], a: &mut [f64]) {
        for (&d, &p) in self.c.iter().zip(&self.pos) {
            a[d as usize] = v[p];
        }
    }
}

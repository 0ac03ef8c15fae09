//! K's MUMPS factor, shifted on the contact DOFs so that it exists when a
//! body is held by contact alone.
//!
//! The Woodbury formula needs K⁻¹, but K alone is singular whenever a body
//! has no Dirichlet condition against a rigid motion and only the contact
//! holds it (the mortar patch test's upper block, pressed by a traction:
//! its z translation). MUMPS then factors K with a pivot of rounding size
//! and the update loses every digit (the first solve of tests/mortar.rs on
//! 2 ranks diverged). So the factor is of K' = K + A, A diagonal on the
//! DOFs the first contact tangent D0 touches (K's own diagonal there, so
//! the shift has K's scale), and the update carries −A: J = K' + P (D − A)
//! Pᵀ, the same J. K' is nonsingular whenever the first Jacobian is: a null
//! vector v of K with v = 0 where D0 acts has D0 v_C = 0 too, so it is one
//! of K + P D0 Pᵀ. Shifting those DOFs only (not all of C) keeps U, where
//! D − A acts, the contact zone.
use super::LowRankPreconditioner;
use crate::petsc::{options, Factor, Matrix, PetscError, Result, Vector};

impl LowRankPreconditioner {
    /// K' = K + A (with the Dirichlet replacement) factored by MUMPS: LDLᵀ,
    /// K being symmetric on this path whatever the contact tangent is.
    /// `touched`: rank 0's positions in C that A shifts (sorted; empty
    /// elsewhere). Collective.
    pub(super) fn factor_bulk(&mut self, touched: &[usize]) -> Result<()> {
        let mut kd = self.k.duplicate()?;
        kd.zero_rows_columns_identity(&self.constrained)?;
        let shift = self.shift_on(&kd, touched)?;
        let own_root = !options::has("-mat_mumps_icntl_13")?;
        kd.add_diagonal(&shift)?;
        let factor = self.factor.insert(Factor::cholesky(&kd)?);
        if own_root {
            // The root front factored sequentially, not by ScaLAPACK:
            // with a ScaLAPACK root, MUMPS's selected inverse entries
            // (G's columns) came out wrong (hertz-sphere fine_size 0.42
            // on 2 ranks: both requests failed their probe); without
            // it they pass, and the run took 9.3 s against 64.3 s
            // with the columns by whole solves. Set before the
            // analysis, which reads it; the user's option wins.
            factor.set_icntl(13, 1)?;
        }
        factor.factor(&kd)?;
        // MUMPS reports a failed factorisation through the factor's error
        // type (from its global INFOG, so alike on every rank); agreed all
        // the same.
        let err = factor.error_type()?;
        if (self.any_rank)(err.is_some()) {
            // Tried again at the next set-up.
            self.factor = None;
            self.failed = Some(format!(
                "the MUMPS factorisation of the bulk stiffness failed (error type {} here)",
                err.unwrap_or(0)
            ));
            return Ok(());
        }
        if let (Some(small), Some(pick)) = (self.small.as_mut(), &self.pick) {
            self.shift_c = super::at_c(pick, &shift, small)?;
        }
        self.shift = Some(shift);
        self.bulk_factorisations += 1;
        Ok(())
    }

    /// A in K's layout: |K_ii| at the DOFs of `touched`, zero elsewhere
    /// (the positions sent from rank 0 back through C's scatter).
    /// Collective.
    fn shift_on(&mut self, kd: &Matrix, touched: &[usize]) -> Result<Vector> {
        let (Some(z), Some(small), Some(pick)) = (self.z.as_ref(), self.small.as_mut(), &self.pick)
        else {
            return Err(PetscError::new("factor_bulk", "no C yet".into()));
        };
        let mut shift = z.duplicate()?;
        let mut diagonal = z.duplicate()?;
        shift.set_all(0.0)?;
        small.with_array_mut(|a| {
            a.fill(0.0);
            for &i in touched {
                a[i] = 1.0;
            }
        })?;
        pick.reverse_add(small, &mut shift)?;
        kd.diagonal(&mut diagonal)?;
        let k_ii = diagonal.with_array(|a| a.to_vec())?;
        shift.with_array_mut(|a| {
            for (v, k) in a.iter_mut().zip(&k_ii) {
                *v *= k.abs();
            }
        })?;
        Ok(shift)
    }
}

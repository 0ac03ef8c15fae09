//! The contact Schur path on one rank: the shell preconditioner's state,
//! K's handle and the constrained rows, the current [`SchurFactor`] (K
//! factored once with a MUMPS Schur complement on the contact DOFs C, and
//! again only when C grows; `factor.rs`, on `layout.rs`'s C and S0, with
//! the dense factorisations of `partial.rs`), and the condensed Newton
//! state it shares with the residual (`newton.rs`).
mod factor;
mod layout;
mod newton;
mod partial;

pub use factor::DenseCounts;
pub use newton::Condensation;

use crate::petsc::{Matrix, PetscError, PetscInt, Result, ShellPreconditioner, Vector};
use factor::SchurFactor;
use std::cell::RefCell;
use std::rc::Rc;

/// What the shell preconditioner keeps: a handle on the bulk stiffness and
/// the constrained rows, its Schur factor for the current contact DOFs, the DOFs the
/// contact tangent may touch now, and counters.
pub struct SchurPreconditioner {
    k: Matrix,
    constrained: Vec<PetscInt>,
    /// The contact tangent is symmetric (see `SchurFactor`).
    symmetric: bool,
    factor: Option<SchurFactor>,
    wanted: Vec<PetscInt>,
    reserved: Vec<PetscInt>,
    key: Vec<(PetscInt, f64)>,
    /// Sparse factorisations of K (the first, and one per growth of C).
    pub bulk_factorisations: usize,
    /// Dense factorisations of the Schur complement (one per set-up).
    pub schur_factorisations: usize,
    /// How they were made, for the factors dropped when C grew (see
    /// [`Self::dense_counts`]).
    dense: DenseCounts,
    /// Times C had to grow.
    pub growths: usize,
    /// The last set-up's failure, for the report.
    pub last_error: Option<String>,
    /// Newton on the condensed system (shared with the residual); None:
    /// every solve is a whole one.
    condensed: Option<Rc<RefCell<Condensation>>>,
    /// Solves with the sparse factor (condensation and expansion) and with
    /// the dense Schur complement alone.
    pub sparse_solves: usize,
    pub dense_solves: usize,
}

impl SchurPreconditioner {
    /// `k`: the linear bulk stiffness; `constrained`: the rows and columns
    /// the Jacobian replaces by the identity (K is factored with the same
    /// replacement, made on a copy that lives only while it is factored,
    /// and the contact tangent's entries there are dropped).
    pub fn new(k: Matrix, mut constrained: Vec<PetscInt>, symmetric: bool) -> Self {
        constrained.sort_unstable();
        constrained.dedup();
        SchurPreconditioner {
            k,
            constrained,
            symmetric,
            factor: None,
            wanted: Vec::new(),
            reserved: Vec::new(),
            key: Vec::new(),
            bulk_factorisations: 0,
            schur_factorisations: 0,
            dense: DenseCounts::default(),
            growths: 0,
            last_error: None,
            condensed: None,
            sparse_solves: 0,
            dense_solves: 0,
        }
    }

    /// Turns on Newton on the condensed system: the returned state is the
    /// one the residual reads (see `newton.rs`).
    pub fn condense(&mut self) -> Rc<RefCell<Condensation>> {
        self.condensed
            .get_or_insert_with(|| Rc::new(RefCell::new(Condensation::default())))
            .clone()
    }

    /// A load step starts at `x0` (condensed Newton only).
    pub fn arm(&mut self, x0: &Vector) -> Result<()> {
        match &self.condensed {
            Some(c) => c.borrow_mut().arm(x0),
            None => Ok(()),
        }
    }

    /// The step failed: its condensed state is dropped.
    pub fn disarm(&mut self) {
        if let Some(c) = &self.condensed {
            c.borrow_mut().disarm();
        }
    }

    /// The step converged: the condensed vector `x` becomes the whole
    /// state (one solve with the factor), when it is condensed.
    pub fn expand(&mut self, x: &mut Vector) -> Result<()> {
        let Some(c) = self.condensed.clone() else {
            return Ok(());
        };
        let mut c = c.borrow_mut();
        let Some(f) = self.factor.as_ref().filter(|_| c.is_active()) else {
            c.disarm();
            return Ok(());
        };
        c.expand(|v| f.times_schur(v), |b, w| f.solve(b, w), x)?;
        self.sparse_solves += 1;
        Ok(())
    }

    /// The DOFs the contact tangent may touch from now on (any order,
    /// repeats allowed): C grows at the next set-up if they are not in it;
    /// and the `reserved` ones, taken into C whenever it is formed, which
    /// do not make it grow (a contact zone expected to reach them within
    /// the run: one factorisation of K instead of one per growth).
    pub fn want(&mut self, mut dofs: Vec<PetscInt>, mut reserved: Vec<PetscInt>) {
        dofs.sort_unstable();
        dofs.dedup();
        self.wanted = dofs;
        reserved.sort_unstable();
        reserved.dedup();
        self.reserved = reserved;
    }

    /// An order key for the DOFs of C (smallest: most likely to be touched
    /// by a contact tangent, such as the distance to the other body), used
    /// when C is next formed.
    pub fn order_by(&mut self, mut key: Vec<(PetscInt, f64)>) {
        key.sort_by_key(|e| e.0);
        key.dedup_by_key(|e| e.0);
        self.key = key;
    }

    /// |C| of the current factor (0 before the first).
    pub fn schur_size(&self) -> usize {
        self.factor.as_ref().map_or(0, |f| f.dofs().len())
    }

    /// How the dense Schur complements were factored, over the run.
    pub fn dense_counts(&self) -> DenseCounts {
        let mut d = self.dense;
        if let Some(f) = &self.factor {
            d.add(f.counts);
        }
        d
    }

    /// Set-up for the Jacobian K + `kc`, from the contact tangent `kc`
    /// alone: K factored again only when C must grow.
    pub fn set_up(&mut self, kc: &Matrix) -> Result<()> {
        let grow = match &self.factor {
            None => true,
            Some(f) => !is_subset(&self.wanted, f.dofs()),
        };
        if grow
            && self
                .condensed
                .as_ref()
                .is_some_and(|c| c.borrow().is_active())
        {
            // The condensed state is in the old C's positions.
            return Err(PetscError::new(
                "SchurPreconditioner::set_up",
                "the contact DOFs grew inside a condensed Newton step".into(),
            ));
        }
        if grow {
            let mut c: Vec<PetscInt> = self.wanted.clone();
            c.extend_from_slice(&self.reserved);
            if let Some(f) = &self.factor {
                c.extend_from_slice(f.dofs());
                self.growths += 1;
            }
            c.sort_unstable();
            c.dedup();
            if c.is_empty() {
                // No contact coupling yet: any one DOF makes a (trivial) C.
                c.push(0);
            }
            if let Some(old) = self.factor.take() {
                self.dense.add(old.counts);
            }
            let mut kd = self.k.duplicate()?;
            kd.zero_rows_columns_identity(&self.constrained)?;
            self.factor = Some(SchurFactor::new(
                &kd,
                c,
                &self.constrained,
                self.symmetric,
                &self.key,
            )?);
            self.bulk_factorisations += 1;
        }
        let f = self
            .factor
            .as_mut()
            .ok_or_else(|| PetscError::new("SchurPreconditioner::set_up", "no factor".into()))?;
        f.update(kc)?;
        self.schur_factorisations += 1;
        Ok(())
    }

    pub fn apply(&mut self, b: &Vector, x: &mut Vector) -> Result<()> {
        let condensed = self.condensed.clone();
        let dense = condensed.as_ref().is_some_and(|c| c.borrow().is_active());
        if dense {
            self.dense_solves += 1;
        } else {
            self.sparse_solves += 1;
        }
        let Some(f) = &self.factor else {
            return Err(PetscError::new(
                "SchurPreconditioner::apply",
                "applied before its set-up".into(),
            ));
        };
        let Some(c) = condensed else {
            return f.solve(b, x);
        };
        let mut c = c.borrow_mut();
        if dense {
            return c.step(|r, s| f.solve_schur(r, s), b, x);
        }
        f.solve(b, x)?;
        if c.awaits_first_solve() {
            c.start(f.layout(), |v| f.times_schur(v), b, x)?;
        }
        Ok(())
    }
}

impl ShellPreconditioner for SchurPreconditioner {
    const NAME: &'static std::ffi::CStr = c"MUMPS Schur complement on the contact DOFs";
    fn set_up(&mut self, kc: &Matrix) -> Result<()> {
        SchurPreconditioner::set_up(self, kc)
    }
    fn apply(&mut self, b: &Vector, x: &mut Vector) -> Result<()> {
        SchurPreconditioner::apply(self, b, x)
    }
    fn failed(&self) -> Option<bool> {
        None
    }
    fn record_error(&mut self, message: String) {
        self.last_error = Some(message);
    }
}

/// Both sorted: every entry of `a` is in `b`.
fn is_subset(a: &[PetscInt], b: &[PetscInt]) -> bool {
    a.iter().all(|x| b.binary_search(x).is_ok())
}

//! The contact solve on several ranks with the bulk stiffness factored
//! once: the exact inverse of J = K + P D Pᵀ (D the contact tangent on the
//! contact DOFs C, P the columns of the identity on C) by a low-rank update
//! of K's factor, which needs no D⁻¹:
//!
//!   G = Pᵀ K⁻¹ P (selected entries of K⁻¹),
//!   M = I + D G  (dense, LU per Jacobian),
//!   x = K⁻¹ (b − P M⁻¹ D (K⁻¹ b)_C)  (two solves with K's factor).
//!
//! (Woodbury: (K + P D Pᵀ)⁻¹ = K⁻¹ − K⁻¹ P D (I + G D)⁻¹ Pᵀ K⁻¹, and
//! D (I + G D)⁻¹ = (I + D G)⁻¹ D.) PETSc's MUMPS Schur complement, which
//! the one-rank path uses, is sequential; this path uses only an ordinary
//! parallel MUMPS factor. K is parallel; G, D and M live on rank 0.
//!
//! Only the DOFs U that D touches matter: a row of M outside U is the
//! identity's and its right-hand side zero, so M⁻¹ D z_C is M_UU⁻¹ (D z_C)_U
//! and needs G on U × U alone. The contact zone is a part of C (hertz-
//! cylinder h = 0.1: 200 of |C| = 972 DOFs over the run), so G's columns are computed as U first
//! takes them (`inverse`) and each set-up factors M_UU only (`update`).
//!
//! K stands for K + A throughout, A a diagonal shift on the DOFs the first
//! tangent touches, with D for D − A (the same J; see `bulk`): K alone is
//! singular when a body is held by contact only.
//!
//! Every decision one rank could take alone (C must grow, a factorisation
//! failed, a non-finite update) goes through the caller's agreement hook
//! before any rank acts on it, so no rank leaves a collective call the
//! others are still in.
mod bulk;
mod inverse;
mod newton;
mod sparse;
mod update;

pub use newton::Reduced;

use crate::petsc::{index_set, world_rank, Factor, LogStage, Matrix, PetscError, PetscInt};
use crate::petsc::{DenseMatrix, Result, Scatter, ShellPreconditioner, Vector};
use crate::runtime::cpu_seconds;
use sparse::Sparse;
use std::cell::RefCell;
use std::rc::Rc;

/// Collective: true on every rank if the flag is true on any (the caller's
/// parallel module provides it).
pub type AnyRank = Box<dyn Fn(bool) -> bool>;

/// Every rank's `local` indices on every rank, sorted and distinct.
/// Collective.
fn gather_sorted(local: &[PetscInt]) -> Result<Vec<PetscInt>> {
    let mut out = index_set::all_gather(local)?;
    out.sort_unstable();
    out.dedup();
    Ok(out)
}

/// The shell preconditioner's state (see the module's comment).
pub struct LowRankPreconditioner {
    k: Matrix,
    /// Every rank's constrained DOFs (sorted): K's rows and columns there
    /// are the identity's, and D drops them.
    constrained: Vec<PetscInt>,
    any_rank: AnyRank,
    root: bool,
    /// K's MUMPS factor (None before the first set-up).
    factor: Option<Factor>,
    /// C, the same on every rank.
    c: Vec<PetscInt>,
    fixed: Vec<bool>,
    wanted: Vec<PetscInt>,
    /// Full vector → its C entries on rank 0 (none elsewhere).
    pick: Option<Scatter>,
    /// Sequential, |C| entries on rank 0 and none elsewhere.
    small: Option<Vector>,
    /// A, the diagonal shift of K's factor (K' = K + A; see `bulk`), in
    /// K's layout, and on rank 0 at C's positions (D's update carries −A).
    shift: Option<Vector>,
    shift_c: Vec<f64>,
    /// Work vectors in K's layout.
    z: Option<Vector>,
    t: Option<Vector>,
    /// Rank 0: G column-major |C| × |C|, valid at the rows and columns of
    /// the positions in C marked `known`.
    g: Vec<f64>,
    known: Vec<bool>,
    /// Rank 0: D (less A) at C's positions, and U, the positions it
    /// touches (sorted).
    d: Sparse,
    u: Vec<usize>,
    /// Rank 0: the LU factors of M_UU = I + D_UU G_UU (None when U is
    /// empty), and sequential work vectors of |U| entries.
    m: Option<DenseMatrix>,
    m_rhs: Option<Vector>,
    m_sol: Option<Vector>,
    /// Newton on the condensed system (`newton`), shared with the
    /// residual; None: every solve is a whole one.
    reduced: Option<Rc<RefCell<Reduced>>>,
    /// `-log_view` stages of G's columns and of the dense set-ups.
    stages: [LogStage; 2],
    /// Sparse factorisations of K (one per run).
    pub bulk_factorisations: usize,
    /// Requests for selected entries of K⁻¹, and the columns of G they
    /// brought.
    pub inverse_blocks: usize,
    pub inverse_columns: usize,
    /// Dense LU factorisations of M (one per set-up).
    pub dense_factorisations: usize,
    /// Solves with K's factor (two per whole application; with the condensed
    /// Newton one per step start and end, and one per widened column of
    /// G), and the condensed Newton's dense steps.
    pub sparse_solves: usize,
    pub dense_steps: usize,
    /// Of G's columns, those from whole solves (the same on every rank,
    /// unlike `inverse_columns`, which is rank 0's).
    pub solved_columns: usize,
    /// Whole solves that probed the selected inverse's entries, and the
    /// requests whose entries failed the probe and were redone by whole
    /// solves.
    pub probe_solves: usize,
    pub inverse_redone: usize,
    /// Times C had to grow.
    pub growths: usize,
    /// This rank's CPU seconds in forming G (all of them) and in the
    /// dense set-ups (D, M and its LU).
    pub inverse_cpu_seconds: f64,
    pub dense_cpu_seconds: f64,
    /// The last set-up's or solve's numeric failure (a failed
    /// factorisation, a non-finite update), agreed by every rank: the shell
    /// reports it as a failed preconditioner, which SNES takes as a failed
    /// linear solve (a cutback), as it does a failed MUMPS factor.
    pub failed: Option<String>,
    /// The last set-up's or solve's error, for the report.
    pub last_error: Option<String>,
}

impl LowRankPreconditioner {
    /// `k`: the linear bulk stiffness; `constrained`: this rank's rows and
    /// columns the Jacobian replaces by the identity (gathered here: K is
    /// factored with the same replacement, on a copy that lives only while
    /// it is factored). Collective.
    pub fn new(k: Matrix, constrained: &[PetscInt], any_rank: AnyRank) -> Result<Self> {
        Ok(LowRankPreconditioner {
            k,
            constrained: gather_sorted(constrained)?,
            any_rank,
            root: world_rank()? == 0,
            factor: None,
            c: Vec::new(),
            fixed: Vec::new(),
            wanted: Vec::new(),
            pick: None,
            small: None,
            shift: None,
            shift_c: Vec::new(),
            z: None,
            t: None,
            g: Vec::new(),
            known: Vec::new(),
            d: Sparse::default(),
            u: Vec::new(),
            m: None,
            m_rhs: None,
            m_sol: None,
            reduced: None,
            stages: [
                LogStage::register("low-rank G")?,
                LogStage::register("low-rank dense")?,
            ],
            bulk_factorisations: 0,
            inverse_blocks: 0,
            inverse_columns: 0,
            dense_factorisations: 0,
            sparse_solves: 0,
            dense_steps: 0,
            solved_columns: 0,
            probe_solves: 0,
            inverse_redone: 0,
            growths: 0,
            inverse_cpu_seconds: 0.0,
            dense_cpu_seconds: 0.0,
            failed: None,
            last_error: None,
        })
    }

    /// The DOFs the contact tangent may touch from now on, this rank's
    /// share (any order, repeats allowed): gathered over the ranks, so C
    /// is the same everywhere. Collective.
    pub fn want(&mut self, dofs: &[PetscInt]) -> Result<()> {
        self.wanted = gather_sorted(dofs)?;
        Ok(())
    }

    /// |C| (0 before the first set-up).
    pub fn schur_size(&self) -> usize {
        self.c.len()
    }

    /// Set-up for the Jacobian K + `kc` from the contact tangent `kc`
    /// alone: K is factored at the first set-up only, C grown when the
    /// pattern reaches outside it, G given the columns U newly touches.
    /// Collective.
    pub fn set_up(&mut self, kc: &Matrix) -> Result<()> {
        self.failed = None;
        let grow = self.c.is_empty() || !is_subset(&self.wanted, &self.c);
        if (self.any_rank)(grow) {
            if self
                .reduced
                .as_ref()
                .is_some_and(|r| r.borrow().is_active())
            {
                // The condensed state is in the old C's positions: a failed
                // set-up (a cutback), and the step's retry grows C before
                // its condensed Newton starts.
                self.failed = Some("the contact DOFs grew inside a condensed Newton step".into());
                return Ok(());
            }
            if !self.c.is_empty() {
                self.growths += 1;
            }
            self.set_c(self.grown_c())?;
        }
        let [g_stage, dense_stage] = self.stages;
        let t0 = cpu_seconds();
        let read = dense_stage.scope(|| self.read_tangent(kc));
        self.dense_cpu_seconds += cpu_seconds() - t0;
        let Some(d) = self.agreed(read)? else {
            return Ok(());
        };
        if self.factor.is_none() {
            // K' is shifted where the first tangent acts (see `bulk`).
            self.factor_bulk(&d.touched())?;
            if self.failed.is_some() {
                return Ok(());
            }
        }
        self.d = d.shifted(&self.shift_c);
        self.u = self.d.touched();
        let t0 = cpu_seconds();
        let grew = g_stage.scope(|| self.complete_inverse())?;
        self.inverse_cpu_seconds += cpu_seconds() - t0;
        if let (true, Some(r)) = (grew, self.reduced.clone()) {
            self.refresh_window(&mut r.borrow_mut().window)?;
            if self.failed.is_some() {
                return Ok(());
            }
        }
        let t0 = cpu_seconds();
        let local = dense_stage.scope(|| match self.root {
            true => self.factor_dense(),
            false => Ok(()),
        });
        self.dense_cpu_seconds += cpu_seconds() - t0;
        if self.agreed(local)?.is_some() {
            self.dense_factorisations += 1;
        }
        Ok(())
    }

    /// A step of the set-up that may fail on some ranks only: its outcome
    /// agreed, a failure kept as the set-up's (None then). Collective.
    fn agreed<T>(&mut self, local: Result<T>) -> Result<Option<T>> {
        if (self.any_rank)(local.is_err()) {
            self.failed = Some(match local {
                Err(e) => e.to_string(),
                Ok(_) => "the contact update's set-up failed on another rank".into(),
            });
            return Ok(None);
        }
        local.map(Some)
    }

    /// C with the wanted DOFs added (the same on every rank).
    fn grown_c(&self) -> Vec<PetscInt> {
        let mut c = self.wanted.clone();
        c.extend_from_slice(&self.c);
        c.sort_unstable();
        c.dedup();
        if c.is_empty() {
            // No contact coupling yet: any one DOF makes a (trivial) C.
            c.push(0);
        }
        c
    }

    /// C becomes `c`: the scatter onto rank 0, G's entries forgotten (its
    /// positions change). Collective.
    fn set_c(&mut self, c: Vec<PetscInt>) -> Result<()> {
        let n = c.len();
        let here = if self.root { n } else { 0 };
        self.fixed = c
            .iter()
            .map(|d| self.constrained.binary_search(d).is_ok())
            .collect();
        self.c = c;
        self.g = vec![0.0; if self.root { n * n } else { 0 }];
        self.known = vec![false; here];
        if let Some(r) = &self.reduced {
            r.borrow_mut().window = newton::Window::default();
        }
        self.ensure_work_vectors()?;
        let z = self
            .z
            .as_ref()
            .ok_or_else(|| PetscError::new("set_c", "no work vector".into()))?;
        let positions: Vec<PetscInt> = (0..here as PetscInt).collect();
        let small = Vector::new_seq(here)?;
        self.pick = None;
        let pick = Scatter::new_local(z, &self.c[..here], &small, &positions)?;
        self.small = Some(small);
        self.pick = Some(pick);
        self.shift_c = match (&self.shift, &mut self.small, &self.pick) {
            (Some(v), Some(small), Some(pick)) => at_c(pick, v, small)?,
            _ => Vec::new(),
        };
        Ok(())
    }

    /// The work vectors z and t in K's layout (once). Collective.
    fn ensure_work_vectors(&mut self) -> Result<()> {
        if self.z.is_some() {
            return Ok(());
        }
        let (right, left) = self.k.create_vecs()?;
        self.z = Some(right);
        self.t = Some(left);
        Ok(())
    }

    /// x = (K + P D Pᵀ)⁻¹ b with the D of the last set-up. Collective.
    pub fn apply(&mut self, b: &Vector, x: &mut Vector) -> Result<()> {
        if self.failed.is_some() {
            // As MatSolve does with a failed MUMPS factor.
            return x.set_all(f64::INFINITY);
        }
        if let Some(r) = self.reduced.clone() {
            let armed = {
                let r = r.borrow();
                r.is_active() || r.awaits_first_solve()
            };
            if armed {
                return self.condensed_apply(&r, b, x);
            }
        }
        let (Some(z), Some(t), Some(small), Some(pick), Some(factor)) = (
            &mut self.z,
            &mut self.t,
            &mut self.small,
            &self.pick,
            &self.factor,
        ) else {
            return Err(PetscError::new(
                "LowRankPreconditioner::apply",
                "applied before its set-up".into(),
            ));
        };
        factor.solve(b, z)?;
        self.sparse_solves += 1;
        pick.forward(z, small)?;
        let update = update::Update {
            d: &self.d,
            u: &self.u,
            m: self.m.as_ref(),
            rhs: self.m_rhs.as_mut(),
            sol: self.m_sol.as_mut(),
        };
        let local = match self.root {
            true => update.solve(small),
            false => Ok(true),
        };
        if (self.any_rank)(!matches!(local, Ok(true))) {
            self.failed = Some(match local {
                Err(e) => e.to_string(),
                Ok(_) => "the low-rank update of the contact solve is not finite".into(),
            });
            return x.set_all(f64::INFINITY);
        }
        // t = b − P y, then x = K⁻¹ t.
        small.scale(-1.0)?;
        t.copy_from(b)?;
        pick.reverse_add(small, t)?;
        self.sparse_solves += 1;
        factor.solve(t, x)
    }
}

/// `v` (K's layout) at C's positions on rank 0 (empty elsewhere), through
/// `small`. Collective.
fn at_c(pick: &Scatter, v: &Vector, small: &mut Vector) -> Result<Vec<f64>> {
    pick.forward(v, small)?;
    small.with_array(|a| a.to_vec())
}

/// Both sorted: every entry of `a` is in `b`.
fn is_subset(a: &[PetscInt], b: &[PetscInt]) -> bool {
    a.iter().all(|x| b.binary_search(x).is_ok())
}

impl ShellPreconditioner for LowRankPreconditioner {
    const NAME: &'static std::ffi::CStr =
        c"MUMPS factor of the bulk stiffness with a low-rank contact update";
    fn set_up(&mut self, kc: &Matrix) -> Result<()> {
        LowRankPreconditioner::set_up(self, kc)
    }
    fn apply(&mut self, b: &Vector, x: &mut Vector) -> Result<()> {
        LowRankPreconditioner::apply(self, b, x)
    }
    fn failed(&self) -> Option<bool> {
        Some(self.failed.is_some())
    }
    fn record_error(&mut self, message: String) {
        self.last_error = Some(message);
    }
}

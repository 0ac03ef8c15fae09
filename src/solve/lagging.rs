//! When Newton rebuilds the preconditioner (the LU/LDLᵀ factors or the AMG
//! hierarchy): only when the contact active set has changed since the last
//! build, or when the kept one has stopped working.
//!
//! With linear-elastic bodies the tangent is K plus the penalty stiffness of
//! the closed contacts (and small geometric terms ∝ pN). While the same
//! contacts are closed on the same master facets, consecutive tangents differ only in
//! those small terms, so the factors of an earlier one precondition GMRES to
//! convergence in a few iterations. After an active-set change they do not
//! (lagging across such changes cost hundreds of GMRES iterations on
//! hertz-cylinder), so a change, agreed by all ranks, forces a rebuild.
//!
//! An AMG hierarchy (the iterative path) is different: it is no exact
//! inverse of any tangent, and GMRES with the hierarchy of the first
//! Jacobian of a step converged as fast after every active-set change as
//! with a fresh one (hertz-sphere h = 0.5, 2 ranks: 158 -> 160 GMRES
//! iterations, 11 -> 1 set-ups), so there only a worn one is rebuilt.
use mpi::traits::Communicator;

/// The active-set watch of one run.
#[derive(Debug, Clone)]
pub struct PreconditionerLag {
    /// Per contact pair, this rank's signature at the last rebuild.
    built: Option<Vec<u64>>,
    /// An active-set change forces a rebuild (exact factors); without, only
    /// a worn preconditioner is rebuilt (an approximate one, see `iterative`).
    pub rebuild_on_change: bool,
    /// A kept preconditioner that needed more linear iterations than this in
    /// the last solve is rebuilt even without an active-set change.
    pub max_reused_iterations: usize,
    /// Counters for reports and tests.
    pub rebuilds: usize,
    pub reuses: usize,
    /// The last decision was a reuse (its linear iterations judge it).
    reused_last: bool,
}

/// More GMRES iterations than this with kept factors: they no longer fit.
pub const MAX_REUSED_ITERATIONS: usize = 30;

/// More GMRES iterations than this with a kept AMG hierarchy: it no longer
/// fits. A fresh one needs about 67 to the full 1e-10 on hertz-sphere
/// (h = 0.5, Eisenstat–Walker off), so only a solve well past that counts.
pub const MAX_REUSED_ITERATIONS_AMG: usize = 100;

impl Default for PreconditionerLag {
    fn default() -> Self {
        PreconditionerLag {
            built: None,
            rebuild_on_change: true,
            max_reused_iterations: MAX_REUSED_ITERATIONS,
            rebuilds: 0,
            reuses: 0,
            reused_last: false,
        }
    }
}

impl PreconditionerLag {
    /// The watch for an iterative solve (GMRES + AMG). The hierarchy is only
    /// an approximate inverse anyway, and the penalty terms of a few contacts
    /// more or less change it little, so it is kept across active-set
    /// changes until the linear iterations say it has worn out.
    pub fn iterative() -> Self {
        PreconditionerLag {
            rebuild_on_change: false,
            max_reused_iterations: MAX_REUSED_ITERATIONS_AMG,
            ..Self::default()
        }
    }

    /// Forgets the last build (a new load step, a new Jacobian pattern).
    pub fn reset(&mut self) {
        self.built = None;
        self.reused_last = false;
    }

    /// The decision for a Jacobian just assembled with the active sets
    /// `signatures` (this rank's, one per pair). Collective: every rank
    /// calls it for the same Jacobian and gets the same answer.
    pub fn decide(
        &mut self,
        world: &impl Communicator,
        signatures: &[u64],
        last_linear_iterations: usize,
    ) -> bool {
        let never = self.built.is_none();
        let changed = self.rebuild_on_change && self.built.as_deref() != Some(signatures);
        let worn = self.reused_last && last_linear_iterations > self.max_reused_iterations;
        let rebuild = crate::parallel::any_rank(world, never || changed || worn);
        if rebuild {
            self.built = Some(signatures.to_vec());
            self.rebuilds += 1;
        } else {
            self.reuses += 1;
        }
        self.reused_last = !rebuild;
        rebuild
    }
}

//! When Newton rebuilds the preconditioner (the LU/LDLᵀ factors or the AMG
//! hierarchy): only when the contact active set has changed since the last
//! build, or when the kept one has stopped working.
//!
//! With linear-elastic bodies the tangent is K plus the penalty stiffness of
//! the closed links (and small geometric terms ∝ pN). While the same links
//! are closed on the same master facets, consecutive tangents differ only in
//! those small terms, so the factors of an earlier one precondition GMRES to
//! convergence in a few iterations. After an active-set change they do not
//! (lagging across such changes cost hundreds of GMRES iterations on
//! hertz-cylinder), so a change, agreed by all ranks, forces a rebuild.
use mpi::traits::Communicator;

/// The active-set watch of one run.
#[derive(Debug, Clone)]
pub struct PreconditionerLag {
    /// Per contact pair, this rank's signature at the last rebuild.
    built: Option<Vec<u64>>,
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

impl Default for PreconditionerLag {
    fn default() -> Self {
        PreconditionerLag {
            built: None,
            max_reused_iterations: MAX_REUSED_ITERATIONS,
            rebuilds: 0,
            reuses: 0,
            reused_last: false,
        }
    }
}

impl PreconditionerLag {
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
        let changed = self.built.as_deref() != Some(signatures);
        let worn = self.reused_last && last_linear_iterations > self.max_reused_iterations;
        let rebuild = crate::parallel::any_rank(world, changed || worn);
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

//! Where the time goes: the named phases of a run, timed on every rank and
//! pushed as PETSc log stages of the same names (so `-log_view` splits its
//! tables the same way). Linear solve is what SNES spends outside our
//! residual and Jacobian callbacks (KSP, preconditioner set-up, line search
//! bookkeeping).
use crate::contact::ContactPair;
use crate::error::Result;
use crate::parallel;
use crate::petsc::LogStage;
use mpi::traits::Communicator;
use std::time::Instant;

/// The phases, in report order.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Phase {
    BulkAssembly = 0,
    ContactSearch,
    ContactAssembly,
    LinearSolve,
    HaloExchange,
    UzawaUpdate,
    Output,
}

pub const PHASE_COUNT: usize = 7;

impl Phase {
    pub const ALL: [Phase; PHASE_COUNT] = [
        Phase::BulkAssembly,
        Phase::ContactSearch,
        Phase::ContactAssembly,
        Phase::LinearSolve,
        Phase::HaloExchange,
        Phase::UzawaUpdate,
        Phase::Output,
    ];

    pub fn name(self) -> &'static str {
        match self {
            Phase::BulkAssembly => "bulk assembly",
            Phase::ContactSearch => "contact search",
            Phase::ContactAssembly => "contact assembly",
            Phase::LinearSolve => "linear solve",
            Phase::HaloExchange => "halo exchange",
            Phase::UzawaUpdate => "Uzawa update",
            Phase::Output => "output",
        }
    }

    /// Column name in the history CSV.
    pub fn key(self) -> &'static str {
        match self {
            Phase::BulkAssembly => "t_bulk",
            Phase::ContactSearch => "t_search",
            Phase::ContactAssembly => "t_contact",
            Phase::LinearSolve => "t_linear",
            Phase::HaloExchange => "t_halo",
            Phase::UzawaUpdate => "t_uzawa",
            Phase::Output => "t_output",
        }
    }
}

/// Seconds per phase.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct PhaseTimes(pub [f64; PHASE_COUNT]);

impl PhaseTimes {
    pub fn get(&self, p: Phase) -> f64 {
        self.0[p as usize]
    }

    pub fn add(&mut self, p: Phase, seconds: f64) {
        self.0[p as usize] += seconds;
    }

    pub fn total(&self) -> f64 {
        self.0.iter().sum()
    }

    /// `self − earlier`, phase by phase.
    pub fn since(&self, earlier: &PhaseTimes) -> PhaseTimes {
        let mut d = *self;
        for (a, b) in d.0.iter_mut().zip(earlier.0) {
            *a -= b;
        }
        d
    }

    /// `self + other`, phase by phase.
    pub fn plus(&self, other: &PhaseTimes) -> PhaseTimes {
        let mut t = *self;
        for (x, y) in t.0.iter_mut().zip(other.0) {
            *x += y;
        }
        t
    }

    /// Collective: the largest time of each phase over the ranks.
    pub fn max_over_ranks(self, world: &impl Communicator) -> PhaseTimes {
        PhaseTimes(parallel::max(world, self.0))
    }
}

/// The PETSc stage of every phase (registered once per process).
#[derive(Debug, Clone, Copy)]
pub struct Stages([LogStage; PHASE_COUNT]);

impl Stages {
    pub fn register() -> Result<Self> {
        let mut stages = Vec::with_capacity(PHASE_COUNT);
        for p in Phase::ALL {
            stages.push(LogStage::register(p.name())?);
        }
        let array: [LogStage; PHASE_COUNT] = stages
            .try_into()
            .map_err(|_| crate::error::Error::Internal("phase stage count".into()))?;
        Ok(Stages(array))
    }

    /// Runs `f` inside phase `p`'s stage (no timing).
    pub fn scope<T>(&self, p: Phase, f: impl FnOnce() -> T) -> T {
        self.0[p as usize].scope(f)
    }

    /// Runs `f` inside phase `p`'s stage, adding its wall time to `times`.
    pub fn time<T>(&self, p: Phase, times: &mut PhaseTimes, f: impl FnOnce() -> T) -> T {
        let start = Instant::now();
        let out = self.0[p as usize].scope(f);
        times.add(p, start.elapsed().as_secs_f64());
        out
    }
}

/// The start of a phase measured around work that may call the residual or
/// Jacobian (which book their own phases in `callbacks`) or exchange
/// multipliers (halo): `book` charges the phase with the rest only, so
/// nothing counts twice.
pub struct PhaseMark {
    start: Instant,
    callbacks: f64,
    halo: f64,
}

impl PhaseMark {
    pub fn new(callbacks: &PhaseTimes, pairs: &[ContactPair]) -> Self {
        PhaseMark {
            start: Instant::now(),
            callbacks: callbacks.total(),
            halo: multiplier_halo_seconds(pairs),
        }
    }

    pub fn book(
        self,
        p: Phase,
        times: &mut PhaseTimes,
        callbacks: &PhaseTimes,
        pairs: &[ContactPair],
    ) {
        let halo = multiplier_halo_seconds(pairs) - self.halo;
        let nested = callbacks.total() - self.callbacks + halo;
        times.add(p, (self.start.elapsed().as_secs_f64() - nested).max(0.0));
        times.add(Phase::HaloExchange, halo);
    }
}

fn multiplier_halo_seconds(pairs: &[ContactPair]) -> f64 {
    pairs.iter().map(|p| p.multiplier_halo().0).sum()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn times_add_and_subtract_by_phase() {
        let mut a = PhaseTimes::default();
        a.add(Phase::LinearSolve, 2.0);
        a.add(Phase::Output, 0.5);
        let mut b = a;
        b.add(Phase::LinearSolve, 1.0);
        let d = b.since(&a);
        assert_eq!(d.get(Phase::LinearSolve), 1.0);
        assert_eq!(d.get(Phase::Output), 0.0);
        assert_eq!(b.total(), 3.5);
        let names: std::collections::BTreeSet<_> = Phase::ALL.iter().map(|p| p.key()).collect();
        assert_eq!(names.len(), PHASE_COUNT);
    }
}

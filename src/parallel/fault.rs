//! Fault injection for the tests of the agreement paths: the environment
//! variable `CONTACTLINK_FAULT=RANK:PHASE[:COUNT[:SKIP]]` makes rank RANK
//! fail at PHASE, after letting the first SKIP visits pass (default 0), for
//! COUNT visits (a number, or `all`, the default). Without the variable
//! nothing happens: [`check`] is one atomic load.
//!
//! PHASE is one of `bulk-residual`, `jacobian`, `contact-assembly`,
//! `search`, `uzawa-update`, `linear-solve`, `output-write`,
//! `restart-read`.
use crate::error::{Error, Result};
use std::sync::atomic::{AtomicUsize, Ordering};
use std::sync::OnceLock;

/// The environment variable the tests set.
pub const VARIABLE: &str = "CONTACTLINK_FAULT";

/// Where a fault can be injected.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum FaultPhase {
    BulkResidual,
    Jacobian,
    ContactAssembly,
    Search,
    UzawaUpdate,
    LinearSolve,
    OutputWrite,
    RestartRead,
}

impl FaultPhase {
    pub const ALL: [FaultPhase; 8] = [
        FaultPhase::BulkResidual,
        FaultPhase::Jacobian,
        FaultPhase::ContactAssembly,
        FaultPhase::Search,
        FaultPhase::UzawaUpdate,
        FaultPhase::LinearSolve,
        FaultPhase::OutputWrite,
        FaultPhase::RestartRead,
    ];

    /// The name in `CONTACTLINK_FAULT`.
    pub fn key(self) -> &'static str {
        match self {
            FaultPhase::BulkResidual => "bulk-residual",
            FaultPhase::Jacobian => "jacobian",
            FaultPhase::ContactAssembly => "contact-assembly",
            FaultPhase::Search => "search",
            FaultPhase::UzawaUpdate => "uzawa-update",
            FaultPhase::LinearSolve => "linear-solve",
            FaultPhase::OutputWrite => "output-write",
            FaultPhase::RestartRead => "restart-read",
        }
    }

    /// The name in error messages.
    pub fn name(self) -> &'static str {
        match self {
            FaultPhase::BulkResidual => "bulk residual",
            FaultPhase::Jacobian => "Jacobian",
            FaultPhase::ContactAssembly => "contact assembly",
            FaultPhase::Search => "contact search",
            FaultPhase::UzawaUpdate => "Uzawa update",
            FaultPhase::LinearSolve => "linear solve",
            FaultPhase::OutputWrite => "output write",
            FaultPhase::RestartRead => "restart read",
        }
    }
}

/// A parsed `CONTACTLINK_FAULT`.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Fault {
    pub rank: usize,
    pub phase: FaultPhase,
    /// Visits that fail (None: all of them).
    pub count: Option<usize>,
    /// Visits that pass before the first failure.
    pub skip: usize,
}

impl Fault {
    pub fn parse(text: &str) -> std::result::Result<Fault, String> {
        let bad =
            |why: String| format!("{VARIABLE}={text}: {why} (expected RANK:PHASE[:COUNT[:SKIP]])");
        let parts: Vec<&str> = text.trim().split(':').collect();
        if !(2..=4).contains(&parts.len()) {
            return Err(bad("wrong number of fields".into()));
        }
        let rank = parts[0]
            .parse()
            .map_err(|_| bad(format!("rank '{}' is not a number", parts[0])))?;
        let phase = FaultPhase::ALL
            .into_iter()
            .find(|p| p.key() == parts[1])
            .ok_or_else(|| {
                let keys: Vec<&str> = FaultPhase::ALL.iter().map(|p| p.key()).collect();
                bad(format!(
                    "unknown phase '{}'; one of {}",
                    parts[1],
                    keys.join(", ")
                ))
            })?;
        let count = match parts.get(2) {
            None | Some(&"all") => None,
            Some(n) => Some(
                n.parse()
                    .map_err(|_| bad(format!("count '{n}' is not a number or 'all'")))?,
            ),
        };
        let skip = match parts.get(3) {
            None => 0,
            Some(n) => n
                .parse()
                .map_err(|_| bad(format!("skip '{n}' is not a number")))?,
        };
        Ok(Fault {
            rank,
            phase,
            count,
            skip,
        })
    }

    /// Whether visit number `visit` (0-based) of `phase` on `rank` fails.
    fn fails(&self, rank: usize, phase: FaultPhase, visit: usize) -> bool {
        rank == self.rank
            && phase == self.phase
            && visit >= self.skip
            && self.count.is_none_or(|c| visit - self.skip < c)
    }
}

struct Armed {
    fault: Fault,
    rank: usize,
    visits: AtomicUsize,
}

static ARMED: OnceLock<Option<Armed>> = OnceLock::new();

/// Reads `CONTACTLINK_FAULT` once per process, for this rank. Every rank
/// reads the same environment, so a malformed value fails on all of them.
pub fn arm(rank: usize) -> Result<()> {
    let text = match std::env::var(VARIABLE) {
        Ok(t) if !t.trim().is_empty() => t,
        _ => {
            let _ = ARMED.set(None);
            return Ok(());
        }
    };
    let fault = Fault::parse(&text).map_err(|e| Error::Io(std::io::Error::other(e)))?;
    let _ = ARMED.set(Some(Armed {
        fault,
        rank,
        visits: AtomicUsize::new(0),
    }));
    Ok(())
}

/// Whether this visit of `phase` is to fail on this rank (counts the visit).
pub fn fires(phase: FaultPhase) -> bool {
    let Some(Some(armed)) = ARMED.get() else {
        return false;
    };
    if armed.fault.phase != phase || armed.fault.rank != armed.rank {
        return false;
    }
    let visit = armed.visits.fetch_add(1, Ordering::Relaxed);
    armed.fault.fails(armed.rank, phase, visit)
}

/// `Err` naming the phase when this visit of `phase` is to fail here.
pub fn check(phase: FaultPhase) -> Result<()> {
    if fires(phase) {
        return Err(Error::Fault(phase.name()));
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn parses_the_documented_forms() {
        let f = Fault::parse("1:bulk-residual").unwrap();
        assert_eq!(
            (f.rank, f.phase, f.count, f.skip),
            (1, FaultPhase::BulkResidual, None, 0)
        );
        let f = Fault::parse("2:search:all:3").unwrap();
        assert_eq!((f.count, f.skip), (None, 3));
        let f = Fault::parse("0:linear-solve:1").unwrap();
        assert_eq!((f.phase, f.count), (FaultPhase::LinearSolve, Some(1)));
        for p in FaultPhase::ALL {
            assert_eq!(Fault::parse(&format!("0:{}", p.key())).unwrap().phase, p);
        }
    }

    #[test]
    fn rejects_malformed_values_with_the_expected_form() {
        for bad in [
            "",
            "1",
            "x:search",
            "1:nowhere",
            "1:search:two",
            "1:search:1:2:3",
        ] {
            let e = Fault::parse(bad).unwrap_err();
            assert!(e.contains("RANK:PHASE"), "{bad}: {e}");
        }
    }

    #[test]
    fn counts_and_skips_visits() {
        let f = Fault::parse("1:jacobian:2:1").unwrap();
        let hits: Vec<bool> = (0..5)
            .map(|v| f.fails(1, FaultPhase::Jacobian, v))
            .collect();
        assert_eq!(hits, [false, true, true, false, false]);
        assert!(!f.fails(0, FaultPhase::Jacobian, 1), "another rank");
        assert!(!f.fails(1, FaultPhase::Search, 1), "another phase");
    }
}

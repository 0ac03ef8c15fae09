//! What a run costs before and while it solves, per rank: resident memory
//! (the peak, and at named set-up checkpoints) and the set-up time (scene and
//! mesh build, partition, DOF numbering, assembly set-up and Jacobian
//! allocation: everything before the first solve).
//!
//! The numbers come from /proc/self/status: `VmHWM` is the kernel's
//! high-water mark of this process's resident set, the same figure
//! getrusage(RUSAGE_SELF) returns as `ru_maxrss`; `VmRSS` is the resident
//! set now, and `RssFile` the part of it that is file-backed pages (the
//! program's and its shared libraries' code and read-only data: PETSc,
//! MPI, hypre, MUMPS, BLAS; 33 MiB of the 40 MiB a rank starts at, 39–41
//! MiB by the end of a GAMG solve).
//! Those pages are one copy in the page cache for all the ranks on a node,
//! though every rank's `VmHWM` counts them. Reading them costs one small
//! file read (no libc call).
//!
//! Checkpoints print only when `CONTACTLINK_MEMORY` is set in the
//! environment (to anything but `0`); each rank prints its own line to
//! stderr, so they involve no communication and cost nothing when off.
use mpi::topology::{Communicator, SimpleCommunicator};
use std::sync::OnceLock;
use std::time::Instant;

/// The environment variable that switches the set-up checkpoints on.
pub const CHECKPOINTS_ENV: &str = "CONTACTLINK_MEMORY";

static SETUP_START: OnceLock<Instant> = OnceLock::new();
static SETUP_SECONDS: OnceLock<f64> = OnceLock::new();
static ENABLED: OnceLock<bool> = OnceLock::new();

const KIB_PER_MIB: f64 = 1024.0;

/// Marks the start of set-up (after MPI and PETSc are up). Only the first
/// call counts.
pub fn setup_started() {
    SETUP_START.get_or_init(Instant::now);
}

/// Marks the end of set-up (the Jacobian is allocated; the first solve is
/// next). Only the first call after [`setup_started`] counts.
pub fn setup_finished() {
    if let Some(start) = SETUP_START.get() {
        SETUP_SECONDS.get_or_init(|| start.elapsed().as_secs_f64());
    }
}

/// Seconds from [`setup_started`] to [`setup_finished`] on this rank.
pub fn setup_seconds() -> Option<f64> {
    SETUP_SECONDS.get().copied()
}

/// Peak resident memory of this process so far, MiB.
pub fn peak_mib() -> Option<f64> {
    status_kib("VmHWM:").map(|k| k as f64 / KIB_PER_MIB)
}

/// Resident memory of this process now, MiB.
pub fn resident_mib() -> Option<f64> {
    status_kib("VmRSS:").map(|k| k as f64 / KIB_PER_MIB)
}

/// The file-backed part of the resident memory now (mapped program and
/// library pages, shared with the other processes that map them), MiB.
pub fn file_backed_mib() -> Option<f64> {
    status_kib("RssFile:").map(|k| k as f64 / KIB_PER_MIB)
}

/// A `key: N kB` line of /proc/self/status.
fn status_kib(key: &str) -> Option<u64> {
    let status = std::fs::read_to_string("/proc/self/status").ok()?;
    parse_status_kib(&status, key)
}

fn parse_status_kib(status: &str, key: &str) -> Option<u64> {
    let line = status.lines().find(|l| l.starts_with(key))?;
    line[key.len()..].split_whitespace().next()?.parse().ok()
}

/// Whether [`checkpoint`] prints (read once per process).
pub fn checkpoints_enabled() -> bool {
    *ENABLED.get_or_init(|| std::env::var(CHECKPOINTS_ENV).is_ok_and(|v| !v.is_empty() && v != "0"))
}

/// When checkpoints are on, prints this rank's resident and peak memory
/// after `phase` to stderr. Rank-local: no collective call, so a rank whose
/// environment differs cannot stall the others.
pub fn checkpoint(phase: &str) {
    if !checkpoints_enabled() {
        return;
    }
    let world = SimpleCommunicator::world();
    let since = SETUP_START.get().map_or(0.0, |s| s.elapsed().as_secs_f64());
    eprintln!(
        "{}",
        checkpoint_line(
            world.rank() as usize,
            world.size() as usize,
            phase,
            Memory {
                resident: resident_mib().unwrap_or(0.0),
                peak: peak_mib().unwrap_or(0.0),
                file_backed: file_backed_mib().unwrap_or(0.0),
            },
            since
        )
    );
}

/// One checkpoint's figures, MiB.
struct Memory {
    resident: f64,
    peak: f64,
    file_backed: f64,
}

/// `memory: rank R of N after PHASE: resident X MiB, peak Y MiB,
/// file-backed F MiB, at T s` (the format scripts/memory.py parses).
fn checkpoint_line(rank: usize, size: usize, phase: &str, m: Memory, t: f64) -> String {
    let Memory {
        resident,
        peak,
        file_backed,
    } = m;
    format!(
        "memory: rank {rank} of {size} after {phase}: resident {resident:.1} MiB, peak {peak:.1} MiB, file-backed {file_backed:.1} MiB, at {t:.2} s"
    )
}

/// The run's footprint agreed over all ranks.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Footprint {
    /// Peak resident memory of the rank that used the most, MiB.
    pub peak_largest_mib: f64,
    /// Peak resident memory of the rank that used the least, MiB.
    pub peak_smallest_mib: f64,
    /// Set-up seconds, the largest over the ranks (0 when not measured).
    pub setup_seconds: f64,
    pub ranks: usize,
}

impl Footprint {
    /// Collective: every rank must call it. Peak memory 0 means this
    /// system does not report it.
    pub fn over_ranks(world: &impl Communicator) -> Footprint {
        let peak = peak_mib().unwrap_or(0.0);
        let setup = setup_seconds().unwrap_or(0.0);
        let [largest, minus_smallest, setup] = crate::parallel::max(world, [peak, -peak, setup]);
        Footprint {
            peak_largest_mib: largest,
            peak_smallest_mib: -minus_smallest,
            setup_seconds: setup,
            ranks: world.size() as usize,
        }
    }

    /// The summary line of `contactlink run`.
    pub fn summary_line(&self) -> String {
        format!(
            "  memory: peak resident {:.1} MiB on the largest rank, {:.1} MiB on the smallest ({} rank(s)); set-up (scene, mesh, partition, DOFs, matrix) {:.2} s",
            self.peak_largest_mib, self.peak_smallest_mib, self.ranks, self.setup_seconds
        )
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn status_lines_are_read_in_kib() {
        let status =
            "Name:\tcontactlink\nVmHWM:\t  625012 kB\nVmRSS:\t  601000 kB\nRssFile:\t   38012 kB\n";
        assert_eq!(parse_status_kib(status, "VmHWM:"), Some(625_012));
        assert_eq!(parse_status_kib(status, "VmRSS:"), Some(601_000));
        assert_eq!(parse_status_kib(status, "RssFile:"), Some(38_012));
        assert_eq!(parse_status_kib(status, "VmSwap:"), None);
    }

    #[test]
    fn this_process_reports_its_memory() {
        let peak = peak_mib().expect("VmHWM in /proc/self/status");
        let now = resident_mib().expect("VmRSS in /proc/self/status");
        let file = file_backed_mib().expect("RssFile in /proc/self/status");
        assert!(peak > 0.0 && now > 0.0 && now <= peak + 1.0);
        assert!(file > 0.0 && file <= now);
    }

    #[test]
    fn checkpoint_line_has_the_parsed_format() {
        assert_eq!(
            checkpoint_line(
                1,
                4,
                "DOF map",
                Memory {
                    resident: 12.34,
                    peak: 56.78,
                    file_backed: 9.01
                },
                1.5
            ),
            "memory: rank 1 of 4 after DOF map: resident 12.3 MiB, peak 56.8 MiB, file-backed 9.0 MiB, at 1.50 s"
        );
    }
}

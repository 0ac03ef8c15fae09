//! Runs ended from outside: a rank killed (SIGKILL), and a run stopped by
//! SIGTERM, sent to mpirun, to one rank only, or to a run without mpirun.
//! SIGKILL cannot be caught: the file must still hold every step the CSV
//! lists (each step is flushed before its row appears). SIGTERM is a request
//! every rank agrees on at the next step boundary: the run ends there with
//! exit code 143, one error line, and a file holding exactly the CSV's steps.
mod common;
use common::*;
use std::path::{Path, PathBuf};
use std::process::{Child, Command, Stdio};
use std::time::{Duration, Instant};

/// `contactlink run impact` long enough to be interrupted: under mpirun on
/// `ranks` ranks (0: the binary alone). Its stderr goes to `<out>.err`.
/// `sigkill_after`: seconds mpirun waits between forwarding SIGTERM and
/// sending SIGKILL (Open MPI's default is 1).
fn start_long_run(out: &Path, ranks: usize, sigkill_after: u32) -> Child {
    let mut cmd = if ranks == 0 {
        Command::new(binary())
    } else {
        let mut c = Command::new("mpirun");
        c.env("OMPI_ALLOW_RUN_AS_ROOT", "1")
            .env("OMPI_ALLOW_RUN_AS_ROOT_CONFIRM", "1")
            .env("OMPI_MCA_btl", "self,vader")
            .env("OMPI_MCA_btl_vader_single_copy_mechanism", "none")
            .env("OMPI_MCA_rmaps_base_oversubscribe", "1")
            .env(
                "OMPI_MCA_odls_base_sigkill_timeout",
                sigkill_after.to_string(),
            )
            .args(["--allow-run-as-root", "--oversubscribe", "-n"])
            .arg(ranks.to_string())
            .arg(binary());
        c
    };
    let err = std::fs::File::create(out.with_extension("err")).expect("stderr file");
    cmd.args(["run", "impact", "--set", "steps.count=2000", "-q", "-o"])
        .arg(out)
        .stdout(Stdio::null())
        .stderr(err)
        .spawn()
        .expect("spawn the run")
}

/// Waits until the history CSV lists at least `rows` steps.
fn wait_for_rows(csv: &Path, rows: usize, child: &mut Child) -> Vec<usize> {
    let deadline = Instant::now() + Duration::from_secs(120);
    loop {
        let steps = csv_steps(csv);
        if steps.len() >= rows {
            return steps;
        }
        if let Ok(Some(status)) = child.try_wait() {
            panic!("the run ended ({status}) before {rows} steps");
        }
        assert!(Instant::now() < deadline, "no {rows} steps after 120 s");
        std::thread::sleep(Duration::from_millis(20));
    }
}

/// The rank processes: mpirun's children running the contactlink binary.
fn rank_pids(mpirun: u32) -> Vec<u32> {
    let mut pids = Vec::new();
    let tasks = std::fs::read_dir(format!("/proc/{mpirun}/task")).expect("mpirun's tasks");
    for task in tasks.flatten() {
        let children = std::fs::read_to_string(task.path().join("children")).unwrap_or_default();
        pids.extend(
            children
                .split_whitespace()
                .filter_map(|p| p.parse::<u32>().ok()),
        );
    }
    pids.retain(|p| {
        std::fs::read_to_string(format!("/proc/{p}/comm")).is_ok_and(|c| c.trim() == "contactlink")
    });
    pids
}

fn signal(pid: u32, sig: &str) {
    let ok = Command::new("kill")
        .args([sig, &pid.to_string()])
        .status()
        .is_ok_and(|s| s.success());
    assert!(ok, "kill {sig} {pid} failed");
}

/// Waits for the run to end (mpirun aborts the job when a rank dies).
fn wait_exit(child: &mut Child) -> std::process::ExitStatus {
    let deadline = Instant::now() + Duration::from_secs(60);
    loop {
        if let Some(status) = child.try_wait().expect("wait for the run") {
            return status;
        }
        if Instant::now() > deadline {
            let _ = child.kill();
            panic!("the run still going 60 s after the signal");
        }
        std::thread::sleep(Duration::from_millis(50));
    }
}

/// Starts a run on `ranks` ranks, waits for 3 converged steps, interrupts
/// it, waits for the end. Returns the file, the CSV's steps, the exit status
/// and the run's stderr.
fn interrupted_run(
    name: &str,
    ranks: usize,
    sigkill_after: u32,
    interrupt: impl FnOnce(&Child),
) -> (PathBuf, Vec<usize>, std::process::ExitStatus, String) {
    let dir = scratch(name);
    let out = dir.join("k.h5");
    let csv = out.with_extension("csv");
    let mut child = start_long_run(&out, ranks, sigkill_after);
    let before = wait_for_rows(&csv, 3, &mut child);
    interrupt(&child);
    let status = wait_exit(&mut child);
    // Rows written after `before` was read belong to steps flushed too.
    let listed = csv_steps(&csv);
    assert!(listed.starts_with(&before), "{before:?} vs {listed:?}");
    let err = std::fs::read_to_string(out.with_extension("err")).unwrap_or_default();
    (out, listed, status, err)
}

/// A stopped run: exit code 143 (`code`; mpirun itself signalled exits with
/// its own non-zero code, `None`), one error line naming the signal and the
/// last step, no panic, and the file holding exactly the CSV's steps (the
/// stop came at a step boundary, after both were written).
fn assert_stopped(
    out: &Path,
    listed: &[usize],
    (status, code): (std::process::ExitStatus, Option<i32>),
    err: &str,
) {
    match code {
        Some(c) => assert_eq!(status.code(), Some(c), "{status}\n{err}"),
        None => assert!(!status.success(), "{status}\n{err}"),
    }
    let stops: Vec<&str> = err
        .lines()
        .filter(|l| l.contains("stopped by SIGTERM"))
        .collect();
    assert_eq!(stops.len(), 1, "{err}");
    let last = listed.last().expect("steps before the stop");
    assert!(
        stops[0].contains(&format!("after load step {last} ")),
        "{}\nCSV ends at step {last}",
        stops[0]
    );
    assert!(!err.contains("panicked"), "{err}");
    assert_file_holds(out, listed);
    let steps = contactlink::output::list_steps(out).expect("the file opens");
    assert_eq!(steps, listed, "file steps against CSV steps");
}

#[test]
fn run_killed_midway_keeps_every_completed_step() {
    let (out, listed, _, _) = interrupted_run("fault-sigkill", 2, 1, |child| {
        let ranks = rank_pids(child.id());
        assert_eq!(ranks.len(), 2, "rank processes of mpirun: {ranks:?}");
        signal(ranks[1], "-KILL");
    });
    assert_file_holds(&out, &listed);
}

#[test]
fn run_terminated_through_mpirun_stops_at_a_step_boundary() {
    // mpirun forwards SIGTERM to both ranks and, by default, sends SIGKILL
    // 1 s later; 5 s leave a loaded machine time to end the step (mpirun
    // waits them out before it exits).
    let (out, listed, status, err) =
        interrupted_run("fault-sigterm", 2, 5, |child| signal(child.id(), "-TERM"));
    assert_stopped(&out, &listed, (status, None), &err);
}

#[test]
fn one_rank_terminated_stops_every_rank_together() {
    // Only rank 1 of 3 sees the signal; the other two learn it at the step
    // boundary's agreement, so none waits for it in a collective call.
    let (out, listed, status, err) = interrupted_run("fault-sigterm-one", 3, 5, |child| {
        let ranks = rank_pids(child.id());
        assert_eq!(ranks.len(), 3, "rank processes of mpirun: {ranks:?}");
        signal(ranks[1], "-TERM");
    });
    assert_stopped(&out, &listed, (status, Some(143)), &err);
}

#[test]
fn run_without_mpirun_terminated_stops_at_a_step_boundary() {
    let (out, listed, status, err) = interrupted_run("fault-sigterm-serial", 0, 1, |child| {
        signal(child.id(), "-TERM")
    });
    assert_stopped(&out, &listed, (status, Some(143)), &err);
    assert!(err.contains("stop requested"), "{err}");
}

//! One rank fails on purpose (`CONTACTLINK_FAULT=RANK:PHASE[:COUNT[:SKIP]]`)
//! at each phase of a run, on 2 and 3 ranks: every run must end within 30 s
//! (a hang detector: a rank left waiting in a collective call never ends),
//! either with a cutback that recovers or with a non-zero exit and exactly
//! one error line naming the phase and the rank, and its result file must
//! hold every step the run completed. Then the scenes that used to hang or
//! take per-rank decisions: a Neo-Hookean bar pushed to inversion in one
//! step, a cantilever bent until a cell inverts, and a contact patch test
//! whose follower-pressure facets all sit on one rank.
mod common;
use common::*;
use contactlink::output::layout;
use std::path::{Path, PathBuf};
use std::process::{Command, ExitStatus, Stdio};
use std::sync::mpsc;
use std::sync::Mutex;
use std::time::{Duration, Instant};

/// The hang detector's limit.
const LIMIT: Duration = Duration::from_secs(30);

/// One MPI run at a time: the runs are short, but the 30 s limit must not
/// be eaten by a dozen of them sharing two cores.
static SERIAL: Mutex<()> = Mutex::new(());

/// A small contact scene: two stacked non-matching blocks pressed together
/// in two load steps (about a second a run).
const PAIR: &str = r#"
[mesh]
generator = "stacked-blocks"
lower_divisions = [3, 3, 1]
upper_divisions = [2, 2, 1]

[[body]]
name = "lower"
material = "linear-elastic"
youngs = 1000.0
poisson = 0.3

[[body]]
name = "upper"
material = "linear-elastic"
youngs = 1000.0
poisson = 0.3

[[dirichlet]]
set = "lower.bottom"

[[dirichlet]]
set = "upper.xmin"
components = ["x"]

[[dirichlet]]
set = "upper.ymin"
components = ["y"]

[[dirichlet]]
set = "upper.top"
components = ["z"]
value = [-0.01]

[[contact]]
name = "interface"
slave = "upper.bottom"
master = "lower.top"

[steps]
count = 2

[solver]
max_cutbacks = 1
"#;

struct Run {
    status: ExitStatus,
    text: String,
    args: String,
}

impl Run {
    /// Lines the program printed as errors (`contactlink: ...`, not warnings).
    fn error_lines(&self) -> Vec<&str> {
        self.text
            .lines()
            .filter(|l| l.starts_with("contactlink:") && !l.starts_with("contactlink: warning"))
            .collect()
    }

    fn cutback_lines(&self) -> Vec<&str> {
        self.text
            .lines()
            .filter(|l| l.trim_start().starts_with("cutback:"))
            .collect()
    }
}

/// `mpirun -n N contactlink ARGS` with `fault` in the environment; fails the
/// test when the run does not end within [`LIMIT`] (after stopping it).
fn bounded_run(n: usize, fault: Option<&str>, args: &[&str]) -> Run {
    let _one = SERIAL.lock().unwrap_or_else(|e| e.into_inner());
    let mut cmd = mpirun_command(n);
    cmd.env_remove("CONTACTLINK_FAULT")
        .args(args)
        .stdout(Stdio::piped())
        .stderr(Stdio::piped());
    if let Some(f) = fault {
        cmd.env("CONTACTLINK_FAULT", f);
    }
    let described = format!(
        "CONTACTLINK_FAULT={} mpirun -n {n} {}",
        fault.unwrap_or(""),
        args.join(" ")
    );
    let child = cmd
        .spawn()
        .expect("spawn mpirun (is openmpi-bin installed? `make deps`)");
    let pid = child.id();
    let (tx, rx) = mpsc::channel();
    std::thread::spawn(move || {
        let _ = tx.send(child.wait_with_output());
    });
    let started = Instant::now();
    match rx.recv_timeout(LIMIT) {
        Ok(out) => {
            let out = out.expect("wait for mpirun");
            Run {
                status: out.status,
                text: text(&out),
                args: described,
            }
        }
        Err(_) => {
            // mpirun passes SIGTERM on to its ranks; SIGKILL if it hangs too.
            let _ = Command::new("kill")
                .args(["-TERM", &pid.to_string()])
                .status();
            if rx.recv_timeout(Duration::from_secs(10)).is_err() {
                let _ = Command::new("kill")
                    .args(["-KILL", &pid.to_string()])
                    .status();
            }
            panic!(
                "{described}: still running after {:.0} s (a rank waits in a collective call?)",
                started.elapsed().as_secs_f64()
            );
        }
    }
}

/// Step indices in a history CSV (its first column), header skipped.
fn csv_steps(path: &Path) -> Vec<usize> {
    let text = std::fs::read_to_string(path).unwrap_or_default();
    text.lines()
        .skip(1)
        .filter_map(|l| l.split(',').next()?.parse().ok())
        .collect()
}

/// The result file opens, lists exactly the steps the CSV lists (every
/// completed step, nothing half-written), and each one's displacement reads
/// back finite. Returns the steps.
fn assert_file_holds_completed_steps(h5: &Path, what: &str) -> Vec<usize> {
    let steps = contactlink::output::list_steps(h5)
        .unwrap_or_else(|e| panic!("{what}: {} does not open: {e}", h5.display()));
    let listed = csv_steps(&h5.with_extension("csv"));
    assert_eq!(
        steps, listed,
        "{what}: steps in the file vs the history CSV"
    );
    for s in &steps {
        let (u, rows, cols) = contactlink::output::read_nodal(h5, *s, layout::DISPLACEMENT)
            .unwrap_or_else(|e| panic!("{what}: step {s} unreadable: {e}"));
        assert_eq!((u.len(), cols), (rows * 3, 3));
        assert!(
            u.iter().all(|v| v.is_finite()),
            "{what}: step {s} not finite"
        );
    }
    steps
}

fn load_factor(h5: &Path, step: usize) -> f64 {
    contactlink::output::read_step_attrs(h5, step)
        .expect("step attributes")
        .load_factor
}

/// A scratch directory with the pair scene in it.
fn pair_scene(name: &str) -> (PathBuf, PathBuf) {
    let dir = scratch(name);
    let scene = write(&dir, "pair.toml", PAIR);
    (dir, scene)
}

/// Newton and Uzawa iterations of the clean run's first step on `n` ranks
/// (how many visits of the Jacobian and the Uzawa update to let pass so
/// that the fault strikes in the second step). Run once per rank count and
/// kept: three tests ask at once, and each clearing the one scratch
/// directory under the others' runs made them fail at random.
fn first_step_iterations(n: usize) -> (usize, usize) {
    static CLEAN: std::sync::Mutex<Vec<(usize, (usize, usize))>> =
        std::sync::Mutex::new(Vec::new());
    let mut known = CLEAN.lock().unwrap_or_else(|e| e.into_inner());
    if let Some(&(_, counts)) = known.iter().find(|(ranks, _)| *ranks == n) {
        return counts;
    }
    let counts = clean_first_step(n);
    known.push((n, counts));
    counts
}

fn clean_first_step(n: usize) -> (usize, usize) {
    let (dir, scene) = pair_scene(&format!("fault-mpi-clean-{n}"));
    let out = dir.join("clean.h5");
    let r = bounded_run(
        n,
        None,
        &[
            "run",
            scene.to_str().unwrap(),
            "-q",
            "-o",
            out.to_str().unwrap(),
        ],
    );
    assert!(r.status.success(), "{}: {}", r.args, r.text);
    assert_eq!(assert_file_holds_completed_steps(&out, &r.args), [1, 2]);
    let info = contactlink::output::read_step_attrs(&out, 1).expect("step 1");
    (info.newton_iterations, info.uzawa_iterations)
}

/// The fault strikes once: the step is cut back on every rank and the run
/// recovers, reaching the full load; the cutback line names the phase and
/// the rank.
fn assert_recovers(phase: &str, name: &str) {
    for n in [2, 3] {
        let rank = n - 1;
        let (dir, scene) = pair_scene(&format!("fault-mpi-{phase}-once-{n}"));
        let out = dir.join("out.h5");
        let fault = format!("{rank}:{phase}:1");
        let r = bounded_run(
            n,
            Some(&fault),
            &[
                "run",
                scene.to_str().unwrap(),
                "-v",
                "-o",
                out.to_str().unwrap(),
            ],
        );
        assert!(
            r.status.success(),
            "{}: did not recover:\n{}",
            r.args,
            r.text
        );
        assert!(r.error_lines().is_empty(), "{}: {}", r.args, r.text);
        let cutbacks = r.cutback_lines();
        assert_eq!(
            cutbacks.len(),
            1,
            "{}: one cutback expected:\n{}",
            r.args,
            r.text
        );
        for needle in [name, &format!("rank {rank}")] {
            assert!(
                cutbacks[0].contains(needle),
                "{}: no {needle:?} in {}",
                r.args,
                cutbacks[0]
            );
        }
        let steps = assert_file_holds_completed_steps(&out, &r.args);
        let last = *steps.last().expect("steps");
        assert!(
            (load_factor(&out, last) - 1.0).abs() < 1e-12,
            "{}: {steps:?}",
            r.args
        );
    }
}

/// The fault strikes for good: a non-zero exit, exactly one error line that
/// names the phase and the rank, and a file with every completed step (at
/// least `min_steps`). `skip(n)` visits pass first.
fn assert_fails(
    phase: &str,
    name: &str,
    skip: impl Fn(usize) -> usize,
    min_steps: usize,
) -> Vec<(PathBuf, String)> {
    let mut outputs = Vec::new();
    for n in [2, 3] {
        let rank = n - 1;
        let (dir, scene) = pair_scene(&format!("fault-mpi-{phase}-{n}"));
        let out = dir.join("out.h5");
        let fault = format!("{rank}:{phase}:all:{}", skip(n));
        let r = bounded_run(
            n,
            Some(&fault),
            &[
                "run",
                scene.to_str().unwrap(),
                "-q",
                "-o",
                out.to_str().unwrap(),
            ],
        );
        assert!(!r.status.success(), "{}: succeeded:\n{}", r.args, r.text);
        let errors = r.error_lines();
        assert_eq!(
            errors.len(),
            1,
            "{}: one error line expected:\n{}",
            r.args,
            r.text
        );
        for needle in [name, &format!("rank {rank}")] {
            assert!(
                errors[0].contains(needle),
                "{}: no {needle:?} in {}",
                r.args,
                errors[0]
            );
        }
        assert!(!r.text.contains("panicked"), "{}", r.text);
        let steps = assert_file_holds_completed_steps(&out, &r.args);
        assert!(steps.len() >= min_steps, "{}: {steps:?}", r.args);
        outputs.push((out, errors[0].to_owned()));
    }
    outputs
}

#[test]
fn bulk_residual_fault_cuts_back_or_stops_on_every_rank() {
    assert_recovers("bulk-residual", "bulk residual");
    assert_fails("bulk-residual", "bulk residual", |_| 0, 0);
}

#[test]
fn jacobian_fault_cuts_back_or_stops_on_every_rank() {
    assert_recovers("jacobian", "Jacobian");
    let failed = assert_fails("jacobian", "Jacobian", |n| first_step_iterations(n).0, 1);
    // The second step fails at its first iterate, with the blocks pressed
    // together: the links are reported as they are there, not as zero.
    for (_, error) in failed {
        let pressed = error
            .split("at the failing iterate: ")
            .nth(1)
            .and_then(|t| t.split_whitespace().next())
            .and_then(|n| n.parse::<usize>().ok());
        assert!(pressed.is_some_and(|n| n > 0), "{error}");
    }
}

#[test]
fn contact_assembly_fault_cuts_back_or_stops_on_every_rank() {
    assert_recovers("contact-assembly", "contact assembly");
    assert_fails("contact-assembly", "contact assembly", |_| 0, 0);
}

#[test]
fn search_fault_stops_every_rank_after_the_first_step() {
    assert_fails("search", "contact search", |_| 1, 1);
}

#[test]
fn uzawa_update_fault_stops_every_rank_after_the_first_step() {
    assert_fails(
        "uzawa-update",
        "Uzawa update",
        |n| first_step_iterations(n).1,
        1,
    );
}

#[test]
fn linear_solve_fault_is_reported_as_a_linear_solve_failure() {
    // One rank's Jacobian row turns NaN: the solve fails on every rank, is
    // reported with its KSP reason (not as a NaN residual), and the rank
    // whose rows are not finite is named.
    assert_recovers("linear-solve", "linear solve failed");
    let outputs = assert_fails(
        "linear-solve",
        "linear solve failed",
        |n| first_step_iterations(n).0,
        1,
    );
    assert!(!outputs.is_empty());
    let (dir, scene) = pair_scene("fault-mpi-linear-text");
    let out = dir.join("out.h5");
    let r = bounded_run(
        2,
        Some("1:linear-solve"),
        &[
            "run",
            scene.to_str().unwrap(),
            "-q",
            "-o",
            out.to_str().unwrap(),
        ],
    );
    let errors = r.error_lines();
    assert_eq!(errors.len(), 1, "{}", r.text);
    assert!(errors[0].contains("KSP_DIVERGED_"), "{}", errors[0]);
    assert!(
        !errors[0].contains("NaN or Inf in the residual"),
        "{}",
        errors[0]
    );
}

#[test]
fn output_write_fault_stops_every_rank_and_keeps_the_written_steps() {
    let outputs = assert_fails("output-write", "output write", |_| 1, 1);
    for (out, _) in outputs {
        assert_eq!(contactlink::output::list_steps(&out).unwrap(), [1]);
    }
}

#[test]
fn restart_read_fault_stops_every_rank_before_any_solve() {
    for n in [2, 3] {
        let rank = n - 1;
        let (dir, scene) = pair_scene(&format!("fault-mpi-restart-{n}"));
        // A file that stopped after step 1 (load 0.5) to continue from.
        let from = dir.join("from.h5");
        let s = scene.to_str().unwrap();
        let r = bounded_run(
            n,
            Some("0:output-write:all:1"),
            &["run", s, "-q", "-o", from.to_str().unwrap()],
        );
        assert!(!r.status.success(), "{}", r.text);
        assert_eq!(assert_file_holds_completed_steps(&from, &r.args), [1]);
        let out = dir.join("continued.h5");
        let fault = format!("{rank}:restart-read");
        let args = [
            "run",
            s,
            "-q",
            "--restart",
            from.to_str().unwrap(),
            "-o",
            out.to_str().unwrap(),
        ];
        let r = bounded_run(n, Some(&fault), &args);
        assert!(!r.status.success(), "{}: {}", r.args, r.text);
        let errors = r.error_lines();
        assert_eq!(errors.len(), 1, "{}: {}", r.args, r.text);
        for needle in ["restart read", &format!("rank {rank}")] {
            assert!(
                errors[0].contains(needle),
                "{}: no {needle:?} in {}",
                r.args,
                errors[0]
            );
        }
        assert_eq!(
            assert_file_holds_completed_steps(&from, &r.args),
            [1],
            "the source must stay intact"
        );
        // Without the fault the same continuation works and ends at full load.
        let r = bounded_run(n, None, &args);
        assert!(r.status.success(), "{}: {}", r.args, r.text);
        assert_eq!(assert_file_holds_completed_steps(&out, &r.args), [2]);
    }
}

#[test]
fn malformed_fault_variable_is_one_clear_error() {
    let (dir, scene) = pair_scene("fault-mpi-malformed");
    let out = dir.join("out.h5");
    let r = bounded_run(
        2,
        Some("1:nowhere"),
        &[
            "run",
            scene.to_str().unwrap(),
            "-q",
            "-o",
            out.to_str().unwrap(),
        ],
    );
    assert!(!r.status.success());
    let errors = r.error_lines();
    assert_eq!(errors.len(), 1, "{}", r.text);
    assert!(
        errors[0].contains("CONTACTLINK_FAULT=1:nowhere") && errors[0].contains("unknown phase"),
        "{}",
        errors[0]
    );
}

#[path = "faults_mpi/hard_scenes.rs"]
mod hard_scenes;

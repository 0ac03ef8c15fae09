//! Faults a run must survive with a clear one-line error, a non-zero exit
//! code, no panic, and a result file that is never corrupt: tangled input
//! cells, an unwritable output path, Newton failure after every cutback, and
//! a run killed (SIGKILL of one rank, SIGTERM to mpirun) in the middle.
mod common;
use common::*;
use contactlink::output::layout;
use std::path::{Path, PathBuf};
use std::process::{Child, Command, Stdio};
use std::time::{Duration, Instant};

const TWO_BOXES: &str = r#"
[mesh]
generator = "gmsh"
file = "boxes.msh"

[[body]]
name = "lower"
material = "linear-elastic"
youngs = 100.0
poisson = 0.3

[[body]]
name = "upper"
material = "linear-elastic"
youngs = 100.0
poisson = 0.3

[[dirichlet]]
set = "lower.bottom"

[[contact]]
slave = "upper.bottom"
master = "lower.top"
"#;

/// The hex fixture with element 10's nodes replaced by `nodes`.
fn hex_fixture_with_element_10(nodes: &str) -> String {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/data/gmsh/hex.msh");
    let text = std::fs::read_to_string(path).expect("hex.msh fixture");
    let cell = "\n10 18 17 2 4 34 33 21 23 ";
    assert!(text.contains(cell), "fixture changed: element 10 not found");
    text.replace(cell, &format!("\n10 {nodes} "))
}

#[test]
fn tangled_gmsh_cell_is_named_before_any_solve() {
    // Nodes 17 and 18 swapped: the bottom face is a bow-tie, the Jacobian
    // changes sign inside the cell, and no renumbering can fix it.
    let dir = scratch("fault-tangled");
    write(
        &dir,
        "boxes.msh",
        &hex_fixture_with_element_10("17 18 2 4 34 33 21 23"),
    );
    let scene = write(&dir, "scene.toml", TWO_BOXES);
    for args in [
        vec!["check", scene.to_str().unwrap()],
        vec!["run", scene.to_str().unwrap(), "-v"],
    ] {
        let o = run(&args);
        let t = text(&o);
        assert!(
            !o.status.success(),
            "{args:?}: accepted a tangled cell:\n{t}"
        );
        for needle in ["scene.toml:4:", "boxes.msh, line", "element 10", "tangled"] {
            assert!(t.contains(needle), "{args:?}: no {needle:?} in:\n{t}");
        }
        assert!(!t.contains("panicked"), "{t}");
        assert!(!t.contains("DOFs"), "{args:?}: set up before failing:\n{t}");
    }
}

#[test]
fn fully_inverted_gmsh_cell_is_reoriented_and_reported_by_check() {
    let dir = scratch("fault-inverted");
    write(
        &dir,
        "boxes.msh",
        &hex_fixture_with_element_10("34 33 21 23 18 17 2 4"),
    );
    let scene = write(&dir, "scene.toml", TWO_BOXES);
    let o = run(&["check", scene.to_str().unwrap()]);
    let t = text(&o);
    assert!(o.status.success(), "{t}");
    assert!(t.contains("gmsh: 1 cells reoriented"), "{t}");
}

#[test]
fn output_under_proc_fails_before_set_up() {
    // -v prints the model header after set-up (partition, DOF numbering): its
    // absence shows the path was checked first.
    let o = mpirun(
        2,
        &[
            "run",
            "hertz-cylinder",
            "-v",
            "-o",
            "/proc/contactlink/x.h5",
        ],
    );
    let t = text(&o);
    assert!(!o.status.success(), "{t}");
    assert!(
        t.contains("cannot write the result file /proc/contactlink/x.h5"),
        "{t}"
    );
    assert!(!t.contains("DOFs"), "set up before failing:\n{t}");
    assert!(!t.contains("panicked"), "{t}");
}

#[test]
fn missing_output_directory_is_created() {
    let dir = scratch("fault-newdir");
    let out = dir.join("a/b/out.h5");
    let o = run(&["run", "uniaxial-stretch", "-o", out.to_str().unwrap()]);
    assert!(o.status.success(), "{}", text(&o));
    assert!(!contactlink::output::list_steps(&out).unwrap().is_empty());
}

/// Step indices in a history CSV (its first column), header skipped.
fn csv_steps(path: &Path) -> Vec<usize> {
    let text = std::fs::read_to_string(path).unwrap_or_default();
    text.lines()
        .skip(1)
        // A row being written when the run died may be cut short.
        .filter(|l| l.ends_with(|c: char| c.is_ascii_digit()))
        .filter_map(|l| l.split(',').next()?.parse().ok())
        .collect()
}

/// Every step the CSV lists is in the HDF5 file, and its displacement reads.
fn assert_file_holds(h5: &Path, csv_listed: &[usize]) {
    let steps = contactlink::output::list_steps(h5)
        .unwrap_or_else(|e| panic!("{} does not open after the fault: {e}", h5.display()));
    for s in csv_listed {
        assert!(
            steps.contains(s),
            "step {s} in the CSV but not in the file ({steps:?})"
        );
        let (u, rows, cols) = contactlink::output::read_nodal(h5, *s, layout::DISPLACEMENT)
            .unwrap_or_else(|e| panic!("step {s} unreadable: {e}"));
        assert_eq!((u.len(), cols), (rows * 3, 3));
        assert!(
            u.iter().all(|v| v.is_finite()),
            "step {s} holds non-finite values"
        );
    }
}

#[test]
fn newton_failure_keeps_every_converged_step() {
    // Two small steps converge, then the pressure jumps a millionfold: Newton
    // fails after every cutback. The file keeps the converged steps.
    let dir = scratch("fault-diverge");
    let scene = r#"
[mesh]
generator = "box"
size = [1.0, 1.0, 1.0]
divisions = [2, 2, 2]

[[body]]
name = "block"
material = "neo-hookean"
youngs = 100.0
poisson = 0.3

[[dirichlet]]
set = "block.bottom"

[[pressure]]
set = "block.top"
value = 1.0e6
amplitude = [[0.0, 0.0], [0.7, 1.0e-6], [1.0, 1.0]]

[steps]
count = 3

[solver]
max_cutbacks = 2
max_newton = 8
"#;
    let path = write(&dir, "scene.toml", scene);
    let out = dir.join("out.h5");
    let o = run(&["run", path.to_str().unwrap(), "-o", out.to_str().unwrap()]);
    let t = text(&o);
    assert_eq!(o.status.code(), Some(1), "{t}");
    assert!(t.contains("did not converge after 2 cutbacks"), "{t}");
    assert!(!t.contains("panicked"), "{t}");
    let listed = csv_steps(&out.with_extension("csv"));
    assert!(
        listed.len() >= 2,
        "expected the two small steps: {listed:?}\n{t}"
    );
    assert_file_holds(&out, &listed);
    assert_eq!(contactlink::output::list_steps(&out).unwrap(), listed);
}

/// `mpirun -n 2 contactlink run impact` long enough to be interrupted.
fn start_long_run(out: &Path) -> Child {
    Command::new("mpirun")
        .env("OMPI_ALLOW_RUN_AS_ROOT", "1")
        .env("OMPI_ALLOW_RUN_AS_ROOT_CONFIRM", "1")
        .env("OMPI_MCA_btl", "self,vader")
        .env("OMPI_MCA_btl_vader_single_copy_mechanism", "none")
        .env("OMPI_MCA_rmaps_base_oversubscribe", "1")
        .args([
            "--allow-run-as-root",
            "--oversubscribe",
            "-n",
            "2",
            binary(),
        ])
        .args(["run", "impact", "--set", "steps.count=2000", "-q", "-o"])
        .arg(out)
        .stdout(Stdio::null())
        .stderr(Stdio::null())
        .spawn()
        .expect("spawn mpirun")
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

/// Waits for mpirun to end (it aborts the job when a rank dies).
fn wait_exit(child: &mut Child) {
    let deadline = Instant::now() + Duration::from_secs(60);
    while child.try_wait().expect("wait mpirun").is_none() {
        if Instant::now() > deadline {
            let _ = child.kill();
            panic!("mpirun still running 60 s after the signal");
        }
        std::thread::sleep(Duration::from_millis(50));
    }
}

fn interrupted_run(name: &str, interrupt: impl FnOnce(&Child)) -> (PathBuf, Vec<usize>) {
    let dir = scratch(name);
    let out = dir.join("k.h5");
    let csv = out.with_extension("csv");
    let mut child = start_long_run(&out);
    let before = wait_for_rows(&csv, 3, &mut child);
    interrupt(&child);
    wait_exit(&mut child);
    // Rows written after `before` was read belong to steps flushed too.
    let listed = csv_steps(&csv);
    assert!(listed.starts_with(&before), "{before:?} vs {listed:?}");
    (out, listed)
}

#[test]
fn run_killed_midway_keeps_every_completed_step() {
    let (out, listed) = interrupted_run("fault-sigkill", |child| {
        let ranks = rank_pids(child.id());
        assert_eq!(ranks.len(), 2, "rank processes of mpirun: {ranks:?}");
        signal(ranks[1], "-KILL");
    });
    assert_file_holds(&out, &listed);
}

#[test]
fn run_terminated_keeps_every_completed_step() {
    let (out, listed) = interrupted_run("fault-sigterm", |child| signal(child.id(), "-TERM"));
    assert_file_holds(&out, &listed);
}

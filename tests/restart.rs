//! `run --restart`: a run cut short and continued from its last converged
//! step ends where the uninterrupted run ends (multipliers and friction
//! history included), and files that cannot be continued from are refused
//! with the reason.
mod common;
use common::*;
use contactlink::output::{layout, list_steps, read_nodal};
use std::path::Path;
use std::process::{Output, Stdio};
use std::time::{Duration, Instant};

fn run_ok(ranks: usize, args: &[&str]) -> String {
    let o = mpirun(ranks, args);
    let t = text(&o);
    assert!(o.status.success(), "{args:?} on {ranks} ranks failed:\n{t}");
    t
}

fn field(path: &Path, step: usize, name: &str) -> Vec<f64> {
    read_nodal(path, step, name).expect(name).0
}

/// Runs `scene` whole, cuts the file after `keep` steps, continues from it
/// on `ranks` ranks and compares the last steps. With the links unless
/// `extra` names a formulation (tests/restart_mortar.rs: the mortar's).
fn continued_run_matches(scene: &str, extra: &[&str], keep: usize, ranks: usize, pair: &str) {
    let dir = scratch(&format!("restart-{scene}-{ranks}"));
    let full = dir.join("full.h5");
    let mut args = vec!["run", scene, "-q", "-o", full.to_str().unwrap()];
    args.extend(links_unless_set(extra));
    run_ok(1, &args);
    let steps = list_steps(&full).unwrap();
    let last = *steps.last().unwrap();
    assert!(
        last > keep,
        "{scene}: {last} steps, cannot cut after {keep}"
    );

    let cut = cut_after(&full, keep, "cut.h5");
    let cont = dir.join("continued.h5");
    let mut args = vec!["run", scene, "-q", "-o", cont.to_str().unwrap()];
    args.extend(links_unless_set(extra));
    args.extend_from_slice(&["--restart", cut.to_str().unwrap()]);
    run_ok(ranks, &args);

    // The continued file numbers its steps on from the restart step.
    let cont_steps = list_steps(&cont).unwrap();
    assert_eq!(cont_steps.first(), Some(&(keep + 1)), "{scene}");
    assert_eq!(cont_steps.last(), Some(&last), "{scene}");
    for name in [layout::DISPLACEMENT, layout::REACTION] {
        let d = relative_difference(&field(&full, last, name), &field(&cont, last, name));
        assert!(d < 1e-9, "{scene}: final {name} differs by {d:e}");
    }
    let force = |p: &Path| field(p, last, &layout::pair_dataset(pair, layout::PAIR_FORCE));
    let d = relative_difference(&force(&full), &force(&cont));
    assert!(d < 1e-9, "{scene}: final contact force differs by {d:e}");
    eprintln!(
        "{scene}: continued after step {keep} of {last} on {ranks} rank(s): final fields match"
    );
}

#[test]
fn frictional_block_slide_continues_exactly() {
    // Cut in the sliding phase: λT and the slip origins must carry over.
    // Each rank reads its blocks of the file and receives its own rows: 1,
    // 2 and 3 ranks all end where the uninterrupted 1-rank run ends.
    for ranks in [1, 2, 3] {
        continued_run_matches("block-slide", &[], 14, ranks, "floor");
    }
}

#[test]
fn hertz_cylinder_continues_exactly() {
    let extra = ["--set", "mesh.fine_size=0.4", "--set", "steps.count=4"];
    continued_run_matches("hertz-cylinder", &extra, 2, 2, "hertz");
    continued_run_matches("hertz-cylinder", &extra, 2, 3, "hertz");
}

/// `mpirun -n N contactlink ARGS`, killed after `limit` (a rank that fails
/// alone must not leave the others waiting).
fn bounded_mpirun(n: usize, args: &[&str], limit: Duration) -> Output {
    let mut child = mpirun_command(n)
        .args(args)
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .expect("spawn mpirun");
    let started = Instant::now();
    while child.try_wait().expect("wait for mpirun").is_none() {
        if started.elapsed() > limit {
            let _ = child.kill();
            let o = child.wait_with_output().expect("collect mpirun");
            panic!("{args:?} on {n} ranks hung past {limit:?}:\n{}", text(&o));
        }
        std::thread::sleep(Duration::from_millis(100));
    }
    child.wait_with_output().expect("collect mpirun")
}

#[test]
fn a_node_moved_in_the_last_ranks_block_is_one_error_on_every_rank() {
    // Each rank checks only its own block of the file's nodes: a node near
    // the end of the list moved is seen by the last rank alone, and must
    // still stop every rank with the same single error, before any solve.
    let dir = scratch("restart-moved-node");
    let full = dir.join("full.h5");
    let extra = ["--set", "mesh.fine_size=0.4", "--set", "steps.count=2"];
    let mut args = vec!["run", "hertz-cylinder", "-q", "-o", full.to_str().unwrap()];
    args.extend_from_slice(&extra);
    run_ok(1, &args);
    let moved = cut_after(&full, 1, "moved.h5");
    let node = {
        let file = hdf5::File::open_rw(&moved).expect("open copy");
        let ds = file.dataset(layout::MESH_NODES).expect("/mesh/nodes");
        let mut nodes = ds.read_raw::<f64>().expect("read nodes");
        let n = nodes.len() / 3;
        nodes[3 * (n - 2)] += 1e-3;
        ds.write_raw(&nodes).expect("write nodes");
        n - 2
    };
    for ranks in [2, 3] {
        let out = dir.join(format!("continued-{ranks}.h5"));
        let mut args = vec!["run", "hertz-cylinder", "-q", "-o", out.to_str().unwrap()];
        args.extend_from_slice(&extra);
        args.extend_from_slice(&["--restart", moved.to_str().unwrap()]);
        let o = bounded_mpirun(ranks, &args, Duration::from_secs(300));
        let t = text(&o);
        assert!(!o.status.success(), "{ranks} ranks: should fail:\n{t}");
        let errors: Vec<&str> = t
            .lines()
            .filter(|l| l.starts_with("contactlink:") && !l.starts_with("contactlink: warning"))
            .collect();
        assert_eq!(
            errors.len(),
            1,
            "{ranks} ranks: one error line expected:\n{t}"
        );
        for needle in [
            format!("rank {}", ranks - 1),
            moved.display().to_string(),
            format!("written for another mesh: node {node} is elsewhere"),
        ] {
            assert!(
                errors[0].contains(&needle),
                "no {needle:?} in {}",
                errors[0]
            );
        }
        assert!(!t.contains("panicked"), "{t}");
        assert!(
            !out.exists(),
            "{ranks} ranks: a refused restart wrote {out:?}"
        );
    }
}

#[test]
fn a_raised_penalty_carries_over() {
    // Two Uzawa iterations allowed: the first step raises the penalty ×10,
    // and the continued run must go on with the raised one.
    let extra = [
        "--set",
        "mesh.fine_size=0.4",
        "--set",
        "steps.count=4",
        "--set",
        "contact.max_uzawa=2",
    ];
    continued_run_matches("hertz-cylinder", &extra, 2, 1, "hertz");
}

#[test]
fn files_that_cannot_be_continued_are_refused() {
    let dir = scratch("restart-refused");
    let full = dir.join("full.h5");
    let f = full.to_str().unwrap();
    run_ok(1, &["run", "patch-test", "-q", "-o", f]);

    let refused = |args: &[&str], why: &str| {
        let o = run(args);
        let t = text(&o);
        assert!(!o.status.success(), "{args:?} should fail");
        assert!(t.contains(why), "{args:?}: expected '{why}' in:\n{t}");
        assert!(!t.contains("panicked"), "{t}");
    };
    let other = dir.join("other.h5");
    let o = other.to_str().unwrap();
    refused(
        &["run", "patch-test", "-q", "-o", o, "--restart", f],
        "already reached the full load",
    );
    refused(
        &["run", "patch-test", "-q", "-o", f, "--restart", f],
        "would overwrite the file it continues from",
    );
    refused(
        &["run", "block-on-plane", "-q", "-o", o, "--restart", f],
        "written for another mesh",
    );
    refused(
        &[
            "run",
            "patch-test",
            "-q",
            "-o",
            o,
            "--restart",
            "/nonexistent/x.h5",
        ],
        "/nonexistent/x.h5",
    );
}

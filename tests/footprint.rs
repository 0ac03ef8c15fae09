//! Peak memory per rank and set-up time: the `memory:` summary line of
//! `run` and `run --setup-only`, the per-phase checkpoints of
//! CONTACTLINK_MEMORY=1, `/footprint` in the result file and its line in
//! `contactlink summary`.
mod common;
use common::*;
use std::process::Output;

/// `mpirun -n N contactlink ARGS` with the set-up checkpoints on.
fn mpirun_with_checkpoints(n: usize, args: &[&str]) -> Output {
    output(
        mpirun_command(n).env("CONTACTLINK_MEMORY", "1").args(args),
        "mpirun",
    )
}

/// The two MiB figures of the `memory: peak resident` summary line.
fn peaks(stdout: &str) -> (f64, f64) {
    let line = stdout
        .lines()
        .find(|l| l.contains("memory: peak resident"))
        .unwrap_or_else(|| panic!("no memory line in:\n{stdout}"));
    let mib: Vec<f64> = line
        .split_whitespace()
        .filter_map(|w| w.parse().ok())
        .collect();
    (mib[0], mib[1])
}

#[test]
fn setup_only_reports_memory_per_rank_and_checkpoints() {
    let o = mpirun_with_checkpoints(2, &["run", "block-compress", "--setup-only"]);
    let (out, err) = (
        String::from_utf8_lossy(&o.stdout),
        String::from_utf8_lossy(&o.stderr),
    );
    assert!(o.status.success(), "{out}\n{err}");
    assert!(
        out.contains("set-up only: ") && out.contains("2187 DOFs on 2 rank(s)"),
        "{out}"
    );
    let (largest, smallest) = peaks(&out);
    assert!(largest >= smallest && smallest > 1.0, "{out}");
    for rank in 0..2 {
        for phase in ["model build", "partition", "DOF map", "Jacobian allocation"] {
            let line = format!("memory: rank {rank} of 2 after {phase}: resident ");
            assert!(err.contains(&line), "no {line:?} in:\n{err}");
        }
    }
    // Set-up only: nothing was solved.
    assert!(
        !err.contains("after load step") && !err.contains("first Jacobian"),
        "{err}"
    );
}

#[test]
fn run_writes_its_footprint_and_summary_reads_it() {
    let dir = scratch("footprint");
    let h5 = dir.join("bc.h5");
    let o = mpirun(
        2,
        &[
            "run",
            "block-compress",
            "--set",
            "steps.count=1",
            "-o",
            h5.to_str().unwrap(),
        ],
    );
    let t = text(&o);
    assert!(o.status.success(), "{t}");
    // No checkpoints unless asked for.
    assert!(!t.contains("memory: rank"), "{t}");
    let (largest, smallest) = peaks(&t);
    let s = run(&["summary", h5.to_str().unwrap()]);
    let st = text(&s);
    assert!(s.status.success(), "{st}");
    assert_eq!(peaks(&st), (largest, smallest), "{st}");
    assert!(st.contains("(2 rank(s))"), "{st}");
}

#[test]
fn check_prints_the_model_memory() {
    let o = run(&["check", "block-compress"]);
    let t = text(&o);
    assert!(o.status.success(), "{t}");
    assert!(
        t.contains("memory: peak resident ") && t.contains("model only"),
        "{t}"
    );
}

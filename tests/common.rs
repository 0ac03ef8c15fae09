//! Helpers shared by the end-to-end tests: run the `contactlink` binary
//! (directly or under mpirun) and read its HDF5 output.
#![allow(dead_code)]
use std::path::{Path, PathBuf};
use std::process::{Command, Output};

/// `--set contact.formulation=links`: what a test of the links formulation
/// adds to a scene without `formulation` (the default is the mortar).
pub const LINKS: [&str; 2] = ["--set", "contact.formulation=links"];

/// `extra` with the links asked for, unless it names a formulation itself.
pub fn links_unless_set<'a>(extra: &[&'a str]) -> Vec<&'a str> {
    let mut args = extra.to_vec();
    if !extra.iter().any(|a| a.starts_with("contact.formulation=")) {
        args.extend(LINKS);
    }
    args
}

/// block-slide with `formulation`, two Newton iterations and no cutback,
/// one process without mpirun (so its output is the program's alone),
/// writing `out`: the first sliding step fails. Asserts that
/// the run failed without a panic; returns the one error's text.
pub fn failing_block_slide(out: &Path, formulation: &str) -> String {
    let set = format!("contact.formulation={formulation}");
    let o = run(&[
        "run",
        "block-slide",
        "-q",
        "-o",
        out.to_str().unwrap(),
        "--set",
        "solver.max_newton=2",
        "--set",
        "solver.max_cutbacks=0",
        "--set",
        &set,
    ]);
    let t = text(&o);
    assert!(!o.status.success(), "the run should fail:\n{t}");
    assert!(!t.contains("panicked"), "{t}");
    t
}

pub fn binary() -> &'static str {
    env!("CARGO_BIN_EXE_contactlink")
}

/// A fresh scratch directory for one test. A name is handed out once per
/// test binary: its tests run at once, and two asking for one name would
/// clear each other's files mid-run (a flaky failure, not a test of the
/// program).
pub fn scratch(name: &str) -> PathBuf {
    static HANDED_OUT: std::sync::Mutex<Vec<String>> = std::sync::Mutex::new(Vec::new());
    {
        let mut names = HANDED_OUT.lock().unwrap_or_else(|e| e.into_inner());
        assert!(
            !names.iter().any(|n| n == name),
            "scratch directory {name} asked for twice in this test binary"
        );
        names.push(name.to_string());
    }
    let dir = PathBuf::from(env!("CARGO_TARGET_TMPDIR")).join(name);
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).expect("create scratch dir");
    dir
}

pub fn mpi_env(cmd: &mut Command) -> &mut Command {
    cmd.env("OMPI_MCA_orte_tmpdir_base", session_base())
        .env("OMPI_ALLOW_RUN_AS_ROOT", "1")
        .env("OMPI_ALLOW_RUN_AS_ROOT_CONFIRM", "1")
        .env("OMPI_MCA_btl", "self,vader")
        .env("OMPI_MCA_btl_vader_single_copy_mechanism", "none")
        .env("OMPI_MCA_pml", "ob1")
        .env("OMPI_MCA_rmaps_base_oversubscribe", "1")
}

/// A directory of its own for each test thread's Open MPI session files. In the
/// shared default (/tmp/ompi.<host>.<uid>) a launch that ends removes the
/// directory another test thread's launch is just creating its own in, and
/// that one dies in orte_init ("mkdir ... No such file or directory",
/// seen in contact_scenes_same_on_1_3_4_8_ranks).
fn session_base() -> PathBuf {
    // Per test thread: a thread runs one launch at a time.
    let thread = format!("{:?}", std::thread::current().id());
    let thread: String = thread.chars().filter(char::is_ascii_digit).collect();
    let dir =
        std::env::temp_dir().join(format!("contactlink-ompi-{}-{thread}", std::process::id()));
    std::fs::create_dir_all(&dir).expect("create an Open MPI session directory");
    dir
}

/// `contactlink ARGS` without mpirun (one rank, MPI singleton).
pub fn run(args: &[&str]) -> Output {
    output(
        mpi_env(&mut Command::new(binary())).args(args),
        "contactlink",
    )
}

/// Runs `cmd` to its end, then removes its session directory (left empty by
/// Open MPI).
pub fn output(cmd: &mut Command, what: &str) -> Output {
    let o = cmd
        .output()
        .unwrap_or_else(|e| panic!("spawn {what}: {e} (is openmpi-bin installed? `make deps`)"));
    let base = cmd
        .get_envs()
        .find(|(k, _)| *k == "OMPI_MCA_orte_tmpdir_base")
        .and_then(|(_, v)| v);
    if let Some(dir) = base {
        let _ = std::fs::remove_dir_all(dir);
    }
    o
}

/// `mpirun -n N contactlink` in the test environment ([`mpi_env`]), for the
/// caller to add its arguments and environment to.
pub fn mpirun_command(n: usize) -> Command {
    let mut cmd = Command::new("mpirun");
    mpi_env(&mut cmd).args([
        "--allow-run-as-root",
        "--oversubscribe",
        "-n",
        &n.to_string(),
        binary(),
    ]);
    cmd
}

/// `mpirun -n N contactlink ARGS`.
pub fn mpirun(n: usize, args: &[&str]) -> Output {
    output(mpirun_command(n).args(args), "mpirun")
}

pub fn text(o: &Output) -> String {
    format!(
        "{}{}",
        String::from_utf8_lossy(&o.stdout),
        String::from_utf8_lossy(&o.stderr)
    )
}

/// Max |a − b| / max |a|.
pub fn relative_difference(a: &[f64], b: &[f64]) -> f64 {
    assert_eq!(a.len(), b.len(), "fields differ in length");
    let scale = a
        .iter()
        .fold(0.0f64, |m, v| m.max(v.abs()))
        .max(f64::MIN_POSITIVE);
    a.iter()
        .zip(b)
        .fold(0.0f64, |m, (x, y)| m.max((x - y).abs()))
        / scale
}

pub fn write(dir: &Path, name: &str, body: &str) -> PathBuf {
    let p = dir.join(name);
    std::fs::write(&p, body).expect("write scene");
    p
}

/// Step indices in a history CSV (its first column), header skipped.
pub fn csv_steps(path: &Path) -> Vec<usize> {
    let text = std::fs::read_to_string(path).unwrap_or_default();
    text.lines()
        .skip(1)
        // A row being written when the run died may be cut short.
        .filter(|l| l.ends_with(|c: char| c.is_ascii_digit()))
        .filter_map(|l| l.split(',').next()?.parse().ok())
        .collect()
}

/// The per-step history CSV written next to result file `h5`: one map of
/// column name to value per converged step.
pub fn history(h5: &Path) -> Vec<std::collections::HashMap<String, f64>> {
    let path = h5.with_extension("csv");
    let text = std::fs::read_to_string(&path)
        .unwrap_or_else(|e| panic!("history {}: {e}", path.display()));
    let mut lines = text.lines();
    let header: Vec<&str> = lines.next().expect("history header").split(',').collect();
    lines
        .map(|l| {
            header
                .iter()
                .zip(l.split(','))
                .map(|(k, v)| {
                    let value = v
                        .parse()
                        .unwrap_or_else(|_| panic!("{k} = {v:?} in {}", path.display()));
                    (k.to_string(), value)
                })
                .collect()
        })
        .collect()
}

/// A column of a history summed over its steps, as a count.
pub fn history_sum(rows: &[std::collections::HashMap<String, f64>], column: &str) -> usize {
    rows.iter()
        .map(|r| {
            r.get(column)
                .unwrap_or_else(|| panic!("no {column} column"))
        })
        .sum::<f64>() as usize
}

/// Every step the CSV lists is in the HDF5 file, and its displacement reads.
pub fn assert_file_holds(h5: &Path, csv_listed: &[usize]) {
    let steps = contactlink::output::list_steps(h5)
        .unwrap_or_else(|e| panic!("{} does not open after the fault: {e}", h5.display()));
    for s in csv_listed {
        assert!(
            steps.contains(s),
            "step {s} in the CSV but not in the file ({steps:?})"
        );
        let (u, rows, cols) =
            contactlink::output::read_nodal(h5, *s, contactlink::output::layout::DISPLACEMENT)
                .unwrap_or_else(|e| panic!("step {s} unreadable: {e}"));
        assert_eq!((u.len(), cols), (rows * 3, 3));
        assert!(
            u.iter().all(|v| v.is_finite()),
            "step {s} holds non-finite values"
        );
    }
}

/// A copy of `full` holding only its first `keep` steps: what a run killed
/// after step `keep` leaves behind.
pub fn cut_after(full: &Path, keep: usize, name: &str) -> PathBuf {
    use contactlink::output::{layout, list_steps};
    let cut = full.with_file_name(name);
    std::fs::copy(full, &cut).expect("copy result file");
    let file = hdf5::File::open_rw(&cut).expect("open copy");
    let steps = file.group(layout::STEPS_NAME).expect("/steps");
    for step in list_steps(full)
        .expect("steps")
        .into_iter()
        .filter(|&s| s > keep)
    {
        steps
            .unlink(&layout::step_group_name(step))
            .expect("unlink step");
    }
    cut
}

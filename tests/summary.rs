//! `contactlink summary` and `contactlink plot` on a real run: a coarse
//! Hertz line contact on 2 ranks. The summary must reproduce what the run
//! itself recorded (force, normal force, active points in its history CSV;
//! the fitted peak pressure on `/hertz`) and
//! the contact area must match the Hertz width 2·b·thickness.
mod common;
use common::*;
use std::collections::HashMap;
use std::path::Path;

/// The coarse Hertz line contact on 2 ranks; its result file, whose
/// history CSV and `/hertz` figures are the run's own record to compare
/// `summary` and `plot` with.
fn hertz_run(dir: &Path) -> std::path::PathBuf {
    let out = dir.join("hc.h5");
    let o = mpirun(
        2,
        &[
            "run",
            "hertz-cylinder",
            "-q",
            "-o",
            out.to_str().unwrap(),
            "--set",
            "mesh.fine_size=0.4",
            // Two steps, so the summary has more than one row.
            "--set",
            "steps.count=2",
        ],
    );
    let t = text(&o);
    assert!(o.status.success(), "hertz-cylinder failed:\n{t}");
    out
}

fn csv_rows(text: &str) -> Vec<HashMap<String, String>> {
    let mut lines = text.lines();
    let head: Vec<&str> = lines.next().expect("CSV header").split(',').collect();
    lines
        .map(|l| {
            head.iter()
                .zip(l.split(','))
                .map(|(k, v)| (k.to_string(), v.to_string()))
                .collect()
        })
        .collect()
}

fn close(a: f64, b: f64, rel: f64) -> bool {
    (a - b).abs() <= rel * b.abs()
}

#[test]
fn summary_and_plot_of_a_hertz_run() {
    let dir = scratch("summary-hertz");
    let h5 = hertz_run(&dir);
    let file = h5.to_str().unwrap();

    let o = run_cmd(&["summary", file, "--csv"]);
    let csv = String::from_utf8_lossy(&o.stdout).to_string();
    assert!(o.status.success(), "{}", text(&o));
    let rows = csv_rows(&csv);
    assert_eq!(rows.len(), 2, "{csv}");
    let last = rows.last().unwrap();
    let col = |k: &str| -> f64 {
        last[&format!("hertz.{k}")]
            .parse()
            .unwrap_or_else(|_| panic!("hertz.{k} in {csv}"))
    };
    println!("{csv}");

    // The run's own last-step record (its history CSV, 13 significant
    // digits): force z, normal force, active points.
    let history = history(&h5);
    let step = history.last().expect("history rows");
    let (fz, normal) = (step["hertz.fz"], step["hertz.normal"]);
    assert!(close(col("fz"), fz, 1e-6), "fz {} vs run {fz}", col("fz"));
    assert!(
        close(col("normal"), normal, 1e-6),
        "normal {} vs run {normal}",
        col("normal")
    );
    // Active slave nodes of the (default) mortar pair, in both.
    assert_eq!(col("active"), step["hertz.active"]);

    // The run's Hertz comparison of its last step (`/hertz`).
    let hertz = contactlink::output::read_hertz_record(&h5)
        .expect("read /hertz")
        .expect("the run's Hertz figures");
    let (p0, b_exact) = (hertz.p0, hertz.width_exact);
    // Peak nodal pressure against the p0 the run fitted to the same nodes.
    assert!(
        close(col("max_pressure"), p0, 0.05),
        "max p {} vs p0 {p0}",
        col("max_pressure")
    );
    // Area against the closed-form width 2·b·thickness (thickness 1): the
    // mortar's is that of its active slave nodes, 0.4 apart, so the width
    // is quantised to a node's share (h = 0.4) at each edge (measured 2.80
    // against 2b = 2.21).
    assert!(
        (col("area") - 2.0 * b_exact).abs() <= 2.0 * 0.4,
        "area {} vs 2b = {}",
        col("area"),
        2.0 * b_exact
    );

    // The table: the file named once, one row per step, then the run's
    // peak memory per rank and set-up time (`/footprint`).
    let o = run_cmd(&["summary", file]);
    let table = String::from_utf8_lossy(&o.stdout).to_string();
    assert!(o.status.success() && table.starts_with(file), "{table}");
    assert_eq!(table.lines().count(), 2 + 2 + 1, "{table}");
    assert!(
        table
            .lines()
            .last()
            .unwrap()
            .starts_with("memory: peak resident"),
        "{table}"
    );

    // The plot: a PNG (its eight magic bytes) next to the file by default.
    let png = dir.join("profile.png");
    let o = run_cmd(&["plot", file, "-o", png.to_str().unwrap()]);
    assert!(o.status.success(), "{}", text(&o));
    // Of the last step, as the run's Hertz figures: both readings, the
    // nodal-average one from the file's own slave facets (printed as the
    // run prints it).
    let (ep, ew) = hertz.averaged_errors.expect("nodal-average fit");
    let averaged = format!(
        "p0 {:+.3} %, half-width/radius {:+.3} %",
        100.0 * ep,
        100.0 * ew
    );
    assert!(
        text(&o).contains(&format!("(read as nodal averages: {averaged})")),
        "plot {:?} against the run's {averaged:?}",
        text(&o)
    );
    let bytes = std::fs::read(&png).expect("plot wrote no PNG");
    assert!(bytes.starts_with(b"\x89PNG\r\n\x1a\n"), "not a PNG");
    assert!(bytes.len() > 10_000, "suspiciously small PNG");
    let o = run_cmd(&["plot", file, "--step", "1"]);
    assert!(o.status.success(), "{}", text(&o));
    assert!(h5.with_extension("png").exists());
    let o = run_cmd(&["plot", file, "--step", "7"]);
    assert_eq!(o.status.code(), Some(1), "{}", text(&o));
}

/// `contactlink ARGS` without mpirun: summary and plot are serial.
fn run_cmd(args: &[&str]) -> std::process::Output {
    run(args)
}

/// One line naming the file, exit code 1, no panic.
fn assert_clean_failure(args: &[&str], file: &str, expect: &str) {
    let o = run_cmd(args);
    let t = text(&o);
    assert_eq!(o.status.code(), Some(1), "{args:?}:\n{t}");
    assert!(!t.contains("panicked"), "{t}");
    assert_eq!(t.trim_end().lines().count(), 1, "not one line:\n{t}");
    assert!(t.contains(file) && t.contains(expect), "{args:?}: {t}");
}

#[test]
fn bad_result_files_are_one_line_errors() {
    let dir = scratch("summary-bad");
    let missing = dir.join("missing.h5");
    let missing = missing.to_str().unwrap();
    assert_clean_failure(&["summary", missing], missing, "no such file");
    assert_clean_failure(&["plot", missing], missing, "no such file");
    let junk = write(&dir, "junk.h5", "not HDF5");
    let junk = junk.to_str().unwrap();
    assert_clean_failure(&["summary", junk, "--csv"], junk, "not an HDF5 file");

    // A contactlink file without a Hertz setup: plot says what it draws.
    let out = dir.join("cube.h5");
    let o = run_cmd(&[
        "run",
        "block-compress",
        "--set",
        "mesh.divisions=[2,2,2]",
        "-q",
        "-o",
        out.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", text(&o));
    assert!(text(&o).is_empty(), "-q printed:\n{}", text(&o));
    let out = out.to_str().unwrap();
    assert_clean_failure(
        &["plot", out],
        out,
        "has no Hertz setup; plot draws the Hertz pressure profile only",
    );
    let o = run_cmd(&["summary", out]);
    assert!(o.status.success(), "{}", text(&o));
    assert!(String::from_utf8_lossy(&o.stdout).contains("contact pair(s): none"));
}

#[test]
fn per_step_lines_need_a_terminal_or_verbose() {
    // The test's pipe is no terminal: the summary prints, the steps do not.
    let dir = scratch("summary-quiet");
    let out = dir.join("b.h5");
    let args = [
        "run",
        "block-compress",
        "--set",
        "mesh.divisions=[2,2,2]",
        "-o",
    ];
    let o = mpirun(2, &[&args[..], &[out.to_str().unwrap()]].concat());
    let t = text(&o);
    assert!(o.status.success(), "{t}");
    assert!(t.contains("done:") && t.contains("output:"), "{t}");
    assert!(!t.contains("step    1"), "per-step lines without -v:\n{t}");
    let o = mpirun(2, &[&args[..], &[out.to_str().unwrap(), "-v"]].concat());
    assert!(text(&o).contains("step    1"), "{}", text(&o));
}

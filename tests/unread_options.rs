//! An option that neither contactlink nor PETSc reads (a misspelled PETSc
//! option, a `--set key=value` passed as one word) is named in one warning
//! line on stderr, and the run still succeeds; options that are read, and
//! the program's own defaults, bring no warning.
mod common;
use common::*;

const WARNING: &str = "PETSc options nobody read";

/// `contactlink run cantilever -q ARGS` on one process: its stderr, after
/// asserting the run succeeded.
fn cantilever(args: &[&str]) -> String {
    let mut all = vec!["run", "cantilever", "-q"];
    all.extend_from_slice(args);
    let o = run(&all);
    assert!(o.status.success(), "{}", text(&o));
    String::from_utf8_lossy(&o.stderr).into_owned()
}

/// The warning lines of `stderr`.
fn warnings(stderr: &str) -> Vec<&str> {
    stderr.lines().filter(|l| l.contains(WARNING)).collect()
}

#[test]
fn a_misspelled_option_is_named_once() {
    let e = cantilever(&["-ksp_tpye", "gmres", "-snes_monitr"]);
    let w = warnings(&e);
    assert_eq!(w.len(), 1, "{e}");
    assert!(w[0].starts_with("contactlink: warning: "), "{e}");
    assert!(
        w[0].contains("-ksp_tpye gmres") && w[0].contains("-snes_monitr"),
        "{e}"
    );
}

#[test]
fn a_glued_set_says_what_was_meant() {
    let e = cantilever(&["--set solver.max_newton=30"]);
    let w = warnings(&e);
    assert_eq!(w.len(), 1, "{e}");
    assert!(w[0].contains("solver.max_newton=30"), "{e}");
    assert!(
        w[0].contains("pass --set and key=value as two words"),
        "{e}"
    );
}

#[test]
fn read_options_and_the_defaults_bring_no_warning() {
    for args in [&[][..], &["-ksp_type", "gmres", "-ksp_rtol", "1e-12"][..]] {
        let e = cantilever(args);
        assert!(warnings(&e).is_empty(), "{args:?}: {e}");
    }
}

#[test]
fn a_scene_option_nobody_reads_is_named() {
    let dir = scratch("unread-scene");
    let scene = std::fs::read_to_string("scenes/cantilever.toml").expect("the shipped scene");
    let scene = format!("{scene}\n[solver]\npetsc_options = \"-pc_tpye lu\"\n");
    let path = write(&dir, "scene.toml", &scene);
    let o = run(&["run", path.to_str().unwrap(), "-q"]);
    assert!(o.status.success(), "{}", text(&o));
    let e = String::from_utf8_lossy(&o.stderr);
    let w = warnings(&e);
    assert_eq!(w.len(), 1, "{e}");
    assert!(w[0].contains("-pc_tpye lu"), "{e}");
}

#[test]
fn two_ranks_print_one_line() {
    let o = mpirun(2, &["run", "cantilever", "-q", "-ksp_tpye", "gmres"]);
    assert!(o.status.success(), "{}", text(&o));
    let e = String::from_utf8_lossy(&o.stderr);
    assert_eq!(warnings(&e).len(), 1, "{e}");
}

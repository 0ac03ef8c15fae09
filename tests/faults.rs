//! Faults a run must survive with a clear one-line error, a non-zero exit
//! code, no panic, and a result file that is never corrupt: tangled input
//! cells, an unwritable output path, Newton failure after every cutback. Runs
//! killed or stopped by a signal are in tests/interrupt.rs.
mod common;
use common::*;
use std::path::Path;

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

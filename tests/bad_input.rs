//! Bad input gets a clear error naming the problem, a non-zero exit code, and
//! no solve; never a panic.
mod common;
use common::*;

const GOOD: &str = r#"
[mesh]
generator = "box"
size = [1.0, 1.0, 1.0]
divisions = [2, 2, 2]

[[body]]
name = "block"
material = "linear-elastic"
youngs = 100.0
poisson = 0.3

[[dirichlet]]
set = "block.bottom"

[[pressure]]
set = "block.top"
value = 1.0
"#;

fn check_fails(name: &str, scene: &str, expect: &[&str]) {
    let dir = scratch(&format!("bad-{name}"));
    let path = write(&dir, "scene.toml", scene);
    let o = run(&["check", path.to_str().unwrap()]);
    let t = text(&o);
    assert!(!o.status.success(), "{name}: accepted a bad scene:\n{t}");
    assert!(!t.contains("panicked"), "{name}: panicked:\n{t}");
    for e in expect {
        assert!(
            t.contains(e),
            "{name}: message does not mention {e:?}:\n{t}"
        );
    }
}

#[test]
fn good_scene_passes_check() {
    let dir = scratch("good");
    let path = write(&dir, "scene.toml", GOOD);
    let o = run(&["check", path.to_str().unwrap()]);
    assert!(o.status.success(), "{}", text(&o));
    assert!(text(&o).contains("DOFs 81"), "{}", text(&o));
}

#[test]
fn unknown_key_is_named() {
    check_fails(
        "unknown-key",
        &GOOD.replace("poisson = 0.3", "poisson = 0.3\nyoung = 5.0"),
        &["young"],
    );
}

#[test]
fn missing_set_is_named() {
    check_fails(
        "missing-set",
        &GOOD.replace("set = \"block.top\"", "set = \"block.roof\""),
        &["block.roof", "block.top"],
    );
}

#[test]
fn negative_modulus_is_rejected() {
    check_fails(
        "negative-e",
        &GOOD.replace("youngs = 100.0", "youngs = -5.0"),
        &["block", "-5"],
    );
}

#[test]
fn poisson_out_of_range_is_rejected() {
    check_fails(
        "nu",
        &GOOD.replace("poisson = 0.3", "poisson = 0.5"),
        &["0.5"],
    );
}

/// Reduced integration is hex20's; on other cells it names the body, the
/// key and its line. On hex20 the scene passes.
#[test]
fn reduced_integration_on_cells_without_a_reduced_rule_is_refused() {
    let reduced = GOOD.replace("poisson = 0.3", "poisson = 0.3\nintegration = \"reduced\"");
    let tet10 = reduced.replace(
        "divisions = [2, 2, 2]",
        "divisions = [2, 2, 2]\ncell_type = \"tet10\"",
    );
    check_fails_at(
        "reduced-tet10",
        &tet10,
        "integration = \"reduced\"",
        &["[[body]] 'block' integration = \"reduced\": tet10 cells have no reduced rule"],
    );
    let hex20 = reduced.replace(
        "divisions = [2, 2, 2]",
        "divisions = [2, 2, 2]\ncell_type = \"hex20\"",
    );
    let dir = scratch("reduced-hex20");
    let path = write(&dir, "scene.toml", &hex20);
    let o = run(&["check", path.to_str().unwrap()]);
    assert!(o.status.success(), "{}", text(&o));
    check_fails(
        "integration-name",
        &GOOD.replace(
            "poisson = 0.3",
            "poisson = 0.3\nintegration = \"selective\"",
        ),
        &["selective", "full", "reduced"],
    );
}

#[test]
fn body_without_material_is_named() {
    check_fails(
        "no-body",
        &GOOD.replace("name = \"block\"", "name = \"brick\""),
        &["block"],
    );
}

#[test]
fn syntax_error_names_the_line() {
    let scene = GOOD.replace("divisions = [2, 2, 2]", "divisions = [2, 2,");
    // toml reports the token where the array should have closed: the next
    // table header.
    let line = line_of(&scene, "[[body]]");
    check_fails("syntax", &scene, &[&format!("scene.toml:{line}:"), "array"]);
}

#[test]
fn bad_component_is_named() {
    check_fails(
        "component",
        &GOOD.replace(
            "set = \"block.bottom\"",
            "set = \"block.bottom\"\ncomponents = [\"w\"]",
        ),
        &["'w'"],
    );
}

#[test]
fn unknown_scene_lists_builtins() {
    let o = run(&["check", "no-such-scene"]);
    assert!(!o.status.success());
    assert!(text(&o).contains("block-compress"), "{}", text(&o));
}

#[test]
fn unwritable_output_fails_before_solving() {
    let dir = scratch("unwritable");
    let blocker = write(&dir, "file", "not a directory");
    let out = blocker.join("out.h5");
    // -v: per-step lines only print to a terminal or with -v, and the
    // check below needs them to be possible.
    let o = mpirun(
        2,
        &["run", "block-compress", "-v", "-o", out.to_str().unwrap()],
    );
    let t = text(&o);
    assert!(!o.status.success(), "{t}");
    assert!(
        t.contains(out.to_str().unwrap()),
        "error does not name the path:\n{t}"
    );
    assert!(!t.contains("step    1"), "solved before failing:\n{t}");
}

#[test]
fn newton_failure_is_reported_after_cutbacks() {
    // A pressure far beyond what the block can carry inverts elements at any
    // step size the cutbacks reach: a clear error, non-zero exit, and a file
    // that still holds the steps that converged.
    let dir = scratch("diverge");
    let scene = GOOD
        .replace(
            "material = \"linear-elastic\"",
            "material = \"neo-hookean\"",
        )
        .replace("value = 1.0", "value = 1.0e6")
        .replace(
            "[[dirichlet]]\nset = \"block.bottom\"",
            "[[dirichlet]]\nset = \"block.bottom\"\n[solver]\nmax_cutbacks = 2\nmax_newton = 8",
        );
    let path = write(&dir, "scene.toml", &scene);
    let out = dir.join("out.h5");
    let o = run(&["run", path.to_str().unwrap(), "-o", out.to_str().unwrap()]);
    let t = text(&o);
    assert!(!o.status.success(), "{t}");
    assert!(t.contains("did not converge after 2 cutbacks"), "{t}");
    assert!(!t.contains("panicked"), "{t}");
    assert!(
        contactlink::output::list_steps(&out).is_ok(),
        "the output file is not readable"
    );
}

const CONTACT: &str = r#"
[[contact]]
name = "c"
slave = "lower.top"
master = "upper.bottom"
"#;

fn stacked(extra: &str) -> String {
    format!(
        r#"
[mesh]
generator = "stacked-blocks"

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
{extra}
"#
    )
}

#[test]
fn contact_pair_on_missing_surface_is_named() {
    check_fails(
        "contact-missing",
        &stacked(&CONTACT.replace("upper.bottom", "upper.floor")),
        &["upper.floor", "master"],
    );
}

#[test]
fn contact_slave_equal_to_master_is_rejected() {
    check_fails(
        "contact-self",
        &stacked(&CONTACT.replace("upper.bottom", "lower.top")),
        &["same facet set", "lower.top"],
    );
}

#[test]
fn non_positive_penalty_is_rejected() {
    check_fails(
        "contact-penalty",
        &stacked(&format!("{CONTACT}penalty = -3.0")),
        &["penalty", "-3"],
    );
}

#[test]
fn rigid_and_master_together_are_rejected() {
    check_fails(
        "contact-both",
        &stacked(&format!("{CONTACT}rigid = {{ kind = \"plane\", point = [0.0, 0.0, 0.0], normal = [0.0, 0.0, 1.0] }}")),
        &["not both"],
    );
}

#[test]
fn good_contact_scene_passes_check() {
    let dir = scratch("contact-good");
    let path = write(&dir, "scene.toml", &stacked(CONTACT));
    let o = run(&["check", path.to_str().unwrap()]);
    assert!(o.status.success(), "{}", text(&o));
}

#[test]
fn negative_friction_coefficient_is_rejected() {
    check_fails(
        "friction-negative",
        &stacked(&format!("{CONTACT}friction = -0.2")),
        &["friction", "-0.2", "[[contact]] 'c'"],
    );
}

#[test]
fn non_positive_tangential_penalty_is_rejected() {
    check_fails(
        "friction-penalty",
        &stacked(&format!(
            "{CONTACT}friction = 0.3\ntangential_penalty = 0.0"
        )),
        &["tangential_penalty", "positive"],
    );
}

#[test]
fn tangential_penalty_without_friction_is_rejected() {
    check_fails(
        "friction-penalty-alone",
        &stacked(&format!("{CONTACT}tangential_penalty = 10.0")),
        &["tangential_penalty", "friction"],
    );
}

#[test]
fn dynamics_without_density_names_the_body() {
    let scene = GOOD.to_string() + "\n[dynamics]\ntime_step = 0.01\n";
    check_fails("dynamics-density", &scene, &["block", "density"]);
}

#[test]
fn dynamics_without_time_step_is_named() {
    let scene = GOOD.replace("poisson = 0.3", "poisson = 0.3\ndensity = 1.0")
        + "\n[dynamics]\ngamma = 0.6\n";
    check_fails("dynamics-dt", &scene, &["time_step"]);
}

#[test]
fn non_positive_time_step_is_rejected() {
    let scene = GOOD.replace("poisson = 0.3", "poisson = 0.3\ndensity = 1.0")
        + "\n[dynamics]\ntime_step = -0.1\n";
    check_fails("dynamics-dt-negative", &scene, &["time_step", "positive"]);
}

#[test]
fn unstable_newmark_parameters_are_rejected() {
    let scene = GOOD.replace("poisson = 0.3", "poisson = 0.3\ndensity = 1.0")
        + "\n[dynamics]\ntime_step = 0.1\nbeta = 0.1\ngamma = 0.5\n";
    check_fails("dynamics-newmark", &scene, &["dynamics", "beta", "gamma/2"]);
}

#[test]
fn density_in_a_static_scene_is_rejected() {
    let scene = GOOD.replace("poisson = 0.3", "poisson = 0.3\ndensity = 1.0");
    check_fails("static-density", &scene, &["density", "[dynamics]"]);
}

#[test]
fn bad_amplitude_is_named() {
    let scene = GOOD.replace(
        "value = 1.0",
        "value = 1.0\namplitude = [[0.0, 0.0], [0.5, 1.0], [0.4, 1.0]]",
    );
    check_fails(
        "amplitude",
        &scene,
        &["[[pressure]]", "block.top", "increase"],
    );
}

#[test]
fn too_strong_distortion_is_rejected() {
    let scene = GOOD.to_string() + "\n[distort]\nfraction = 0.5\n";
    check_fails("distort", &scene, &["[distort]", "fraction", "0.3"]);
}

/// 1-based line of the first occurrence of `needle` in `text`.
fn line_of(text: &str, needle: &str) -> usize {
    let at = text
        .find(needle)
        .unwrap_or_else(|| panic!("{needle:?} not in scene"));
    text[..at].matches('\n').count() + 1
}

/// `check` fails, its message names `scene.toml:LINE:` with LINE the line of
/// `at` in the scene, and it mentions each of `expect`.
fn check_fails_at(name: &str, scene: &str, at: &str, expect: &[&str]) {
    let located = format!("scene.toml:{}:", line_of(scene, at));
    let mut all = vec![located.as_str()];
    all.extend_from_slice(expect);
    check_fails(name, scene, &all);
}

#[path = "bad_input/limits_and_files.rs"]
mod limits_and_files;
#[path = "bad_input/scene_lines.rs"]
mod scene_lines;

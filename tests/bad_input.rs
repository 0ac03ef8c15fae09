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

// ---------------------------------------------------------------------------
// Every scene error names the key and its line in the scene file (or the
// `--set` override that supplied the value), as `scene.toml:LINE: ...`.

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

#[test]
fn unknown_key_names_its_line() {
    let scene = GOOD.replace("poisson = 0.3", "poisson = 0.3\nyoung = 5.0");
    check_fails_at(
        "line-unknown-key",
        &scene,
        "young =",
        &["unknown field `young`", "youngs"],
    );
}

#[test]
fn missing_mesh_section_is_named() {
    let scene = &GOOD[GOOD.find("[[body]]").unwrap()..];
    check_fails("line-no-mesh", scene, &["no [mesh] section"]);
}

#[test]
fn missing_body_section_is_named() {
    let body = GOOD.find("[[body]]").unwrap();
    let dirichlet = GOOD.find("[[dirichlet]]").unwrap();
    let scene = format!("{}{}", &GOOD[..body], &GOOD[dirichlet..]);
    check_fails("line-no-body", &scene, &["no [[body]] section"]);
}

#[test]
fn unknown_facet_set_names_its_line_and_the_known_sets() {
    let scene = GOOD.replace("set = \"block.top\"", "set = \"block.roof\"");
    check_fails_at(
        "line-facet-set",
        &scene,
        "block.roof",
        &["[[pressure]]", "block.roof", "block.top", "block.xmin"],
    );
}

#[test]
fn unknown_node_set_names_its_line() {
    let scene = GOOD.replace("set = \"block.bottom\"", "set = \"block.floor\"");
    check_fails_at(
        "line-node-set",
        &scene,
        "block.floor",
        &["[[dirichlet]]", "block.floor", "block.bottom"],
    );
}

#[test]
fn non_positive_youngs_names_its_line() {
    for (i, e) in ["0.0", "-5.0"].iter().enumerate() {
        let scene = GOOD.replace("youngs = 100.0", &format!("youngs = {e}"));
        check_fails_at(
            &format!("line-youngs-{i}"),
            &scene,
            "youngs",
            &["'block' youngs", e.trim_end_matches(".0")],
        );
    }
}

#[test]
fn poisson_outside_its_range_names_its_line() {
    for (i, nu) in ["0.5", "-1.0", "0.7"].iter().enumerate() {
        let scene = GOOD.replace("poisson = 0.3", &format!("poisson = {nu}"));
        check_fails_at(
            &format!("line-poisson-{i}"),
            &scene,
            "poisson",
            &["'block' poisson", "(-1, 0.5)"],
        );
    }
}

#[test]
fn overridden_value_names_the_override() {
    let dir = scratch("line-override");
    let path = write(&dir, "scene.toml", GOOD);
    let o = run(&["check", path.to_str().unwrap(), "--set", "body.poisson=0.6"]);
    let t = text(&o);
    assert!(!o.status.success(), "{t}");
    assert!(t.contains("--set body.poisson=0.6"), "{t}");
    assert!(t.contains("(-1, 0.5)"), "{t}");
    assert!(
        t.contains("scene.toml: --set body.poisson=0.6: "),
        "names a file line for a --set value:\n{t}"
    );
}

#[test]
fn contact_slave_equal_to_master_names_its_line() {
    let scene = stacked(&CONTACT.replace("upper.bottom", "lower.top"));
    check_fails_at(
        "line-contact-same-set",
        &scene,
        "master = ",
        &["same facet set", "lower.top"],
    );
}

#[test]
fn self_contact_on_one_body_is_rejected() {
    let scene = stacked(&CONTACT.replace("upper.bottom", "lower.bottom"));
    check_fails_at(
        "line-self-contact",
        &scene,
        "master = ",
        &["self-contact is not supported", "'lower'"],
    );
}

#[test]
fn scene_body_absent_from_the_mesh_names_its_line() {
    let extra =
        "[[body]]\nname = \"ghost\"\nmaterial = \"linear-elastic\"\nyoungs = 1.0\npoisson = 0.3\n";
    let scene = format!("{GOOD}\n{extra}");
    check_fails_at(
        "line-ghost-body",
        &scene,
        "\"ghost\"",
        &["'ghost' is not a body of the mesh", "block"],
    );
}

#[test]
fn mesh_body_without_material_names_the_mesh_line() {
    let scene = GOOD.replace("name = \"block\"", "name = \"brick\"");
    check_fails_at(
        "line-mesh-body",
        &scene,
        "[mesh]",
        &["the mesh has a body 'block'", "no [[body]]", "brick"],
    );
}

#[test]
fn unheld_static_body_is_named() {
    // No [[dirichlet]] and no contact: the stiffness would be singular.
    let d = GOOD.find("[[dirichlet]]").unwrap();
    let p = GOOD.find("[[pressure]]").unwrap();
    let scene = format!("{}{}", &GOOD[..d], &GOOD[p..]);
    check_fails_at(
        "unheld-body",
        &scene,
        "name = \"block\"",
        &["body 'block'", "singular"],
    );
}

#[test]
fn body_held_only_by_contact_or_dynamics_is_accepted() {
    // "upper" has no Dirichlet condition but a contact partner.
    let dir = scratch("held-by-contact");
    let path = write(&dir, "scene.toml", &stacked(CONTACT));
    let o = run(&["check", path.to_str().unwrap()]);
    assert!(o.status.success(), "{}", text(&o));
    // A free body in dynamics has a mass matrix: never singular.
    let d = GOOD.find("[[dirichlet]]").unwrap();
    let p = GOOD.find("[[pressure]]").unwrap();
    let free = format!("{}{}", &GOOD[..d], &GOOD[p..])
        .replace("poisson = 0.3", "poisson = 0.3\ndensity = 1.0")
        + "\n[dynamics]\ntime_step = 0.01\n";
    let path = write(&dir, "free.toml", &free);
    let o = run(&["check", path.to_str().unwrap()]);
    assert!(o.status.success(), "{}", text(&o));
}

#[test]
fn check_prints_sizes_conditions_and_pairs() {
    let o = run(&["check", "hertz-cylinder"]);
    let t = text(&o);
    assert!(o.status.success(), "{t}");
    for needle in [
        "DOFs 38760",
        "body block: linear-elastic, E = 1000, ν = 0.3; 3042 cells, 6320 nodes",
        "dirichlet block.bottom: 158 nodes, components x y z",
        "contact hertz: slave cylinder.curved (86 facets), master block.top (78 facets), frictionless",
        "quasi-static",
        "steps 1, output out/hertz-cylinder.h5",
    ] {
        assert!(t.contains(needle), "no {needle:?} in:\n{t}");
    }
    let o = run(&["check", "block-slide"]);
    assert!(
        text(&o).contains("Coulomb friction μ = 0.3"),
        "{}",
        text(&o)
    );
}

#[test]
fn check_of_a_gmsh_scene_counts_reoriented_cells() {
    let o = run(&["check", "scenes/sphere-block.toml"]);
    let t = text(&o);
    assert!(o.status.success(), "{t}");
    assert!(t.contains("gmsh: 0 cells reoriented"), "{t}");
}

#[test]
fn check_of_a_bad_scene_exits_1_with_the_line() {
    let dir = scratch("check-exit");
    let scene = GOOD.replace("youngs = 100.0", "youngs = -1.0");
    let path = write(&dir, "scene.toml", &scene);
    let o = run(&["check", path.to_str().unwrap()]);
    assert_eq!(o.status.code(), Some(1), "{}", text(&o));
    let stderr = String::from_utf8_lossy(&o.stderr);
    assert!(
        stderr.contains(&format!("scene.toml:{}:", line_of(&scene, "youngs"))),
        "{stderr}"
    );
    assert_eq!(stderr.trim().lines().count(), 1, "not one line:\n{stderr}");
}

#[test]
fn unknown_key_keeps_its_line_with_overrides_and_names_a_bad_override() {
    let dir = scratch("line-override-unknown");
    let scene = GOOD.replace("poisson = 0.3", "poisson = 0.3\nyoung = 5.0");
    let path = write(&dir, "scene.toml", &scene);
    let o = run(&["check", path.to_str().unwrap(), "--set", "steps.count=2"]);
    let located = format!("scene.toml:{}:", line_of(&scene, "young ="));
    assert!(text(&o).contains(&located), "{}", text(&o));
    let path = write(&dir, "good.toml", GOOD);
    let o = run(&["check", path.to_str().unwrap(), "--set", "body.young=2"]);
    let t = text(&o);
    assert!(!o.status.success(), "{t}");
    assert!(
        t.contains("--set body.young=2: unknown field `young`"),
        "{t}"
    );
}

// ---------------------------------------------------------------------------
// Values that would reach the solver as NaN or inf, counts far beyond any
// use, meshes too large to build, and bodies that float: each is refused by
// `check`, at its line, before anything is solved.

#[test]
fn non_finite_body_force_names_its_line() {
    for (i, v) in ["nan", "inf", "-inf"].iter().enumerate() {
        let scene =
            format!("{GOOD}\n[[body_force]]\nbody = \"block\"\nvector = [0.0, {v}, -1.0]\n");
        check_fails_at(
            &format!("body-force-{i}"),
            &scene,
            "vector = [0.0,",
            &["[[body_force]] body 'block'", "must be a finite number"],
        );
    }
}

#[test]
fn non_finite_load_and_condition_values_name_their_lines() {
    let cases = [
        (
            GOOD.replace("value = 1.0", "value = nan"),
            "value = nan",
            "[[pressure]] value",
        ),
        (
            GOOD.replace(
                "set = \"block.bottom\"",
                "set = \"block.bottom\"\ncomponents = [\"z\"]\nvalue = [inf]",
            ),
            "value = [inf]",
            "[[dirichlet]] value",
        ),
        (
            GOOD.to_string() + "\n[[traction]]\nset = \"block.xmax\"\nvector = [1.0, nan, 0.0]\n",
            "vector = [1.0, nan",
            "[[traction]] vector",
        ),
        (
            GOOD.replace(
                "value = 1.0",
                "value = 1.0\namplitude = [[0.0, 0.0], [1.0, inf]]",
            ),
            "amplitude = ",
            "not finite",
        ),
        (
            GOOD.replace(
                "poisson = 0.3",
                "poisson = 0.3\ndensity = 1.0\ninitial_velocity = [nan, 0.0, 0.0]",
            ) + "\n[dynamics]\ntime_step = 0.1\n",
            "initial_velocity",
            "initial_velocity must be a finite number",
        ),
        (
            GOOD.replace("poisson = 0.3", "poisson = 0.3\ndensity = 1.0")
                + "\n[dynamics]\ntime_step = inf\n",
            "time_step = inf",
            "time_step must be positive",
        ),
        (
            GOOD.replace("poisson = 0.3", "poisson = 0.3\ndensity = 1.0")
                + "\n[dynamics]\ntime_step = 0.1\nbeta = nan\n",
            "[dynamics]",
            "beta",
        ),
    ];
    for (i, (scene, at, expect)) in cases.iter().enumerate() {
        check_fails_at(&format!("non-finite-{i}"), scene, at, &[expect]);
    }
}

#[test]
fn non_finite_rigid_surface_and_motion_name_their_lines() {
    let rigid = |point: &str, motion: &str| {
        format!(
            "{GOOD}\n[[contact]]\nname = \"floor\"\nslave = \"block.bottom\"\nrigid = {{ kind = \"plane\", point = {point}, normal = [0.0, 0.0, 1.0] }}\nmotion = {motion}\n"
        )
    };
    check_fails_at(
        "rigid-point",
        &rigid("[0.0, nan, 0.0]", "[0.0, 0.0, 0.1]"),
        "rigid = ",
        &["[[contact]] 'floor'", "rigid point", "finite"],
    );
    check_fails_at(
        "rigid-motion",
        &rigid("[0.0, 0.0, 0.0]", "[0.0, 0.0, inf]"),
        "motion = ",
        &["[[contact]] 'floor'", "motion", "finite"],
    );
}

#[test]
fn absurd_counts_are_refused_with_the_limit() {
    let cases = [
        (
            GOOD.to_string() + "\n[steps]\ncount = 10000000\n",
            "count = ",
            "[steps] count = 10000000 is above the limit of 1000000",
        ),
        (
            GOOD.to_string() + "\n[solver]\nmax_newton = 100000000\n",
            "max_newton",
            "[solver] max_newton = 100000000 is above the limit of 10000",
        ),
        (
            GOOD.to_string() + "\n[solver]\nmax_cutbacks = 1000\n",
            "max_cutbacks",
            "[solver] max_cutbacks = 1000 is above the limit of 30",
        ),
        (
            GOOD.to_string() + "\n[solver]\nfirst_contact_softening = 0.5\n",
            "first_contact_softening",
            "[solver] first_contact_softening must be at least 1 (got 0.5)",
        ),
        (
            stacked(&format!("{CONTACT}max_uzawa = 5000000000")),
            "max_uzawa",
            "[[contact]] 'c' max_uzawa = 5000000000 is above the limit of 10000",
        ),
    ];
    for (i, (scene, at, expect)) in cases.iter().enumerate() {
        check_fails_at(&format!("count-{i}"), scene, at, &[expect]);
    }
}

#[test]
fn bad_petsc_options_string_names_its_line() {
    let scene = GOOD.to_string() + "\n[solver]\npetsc_options = \"ksp_type gmres\"\n";
    check_fails_at(
        "petsc-options-syntax",
        &scene,
        "petsc_options",
        &["[solver] petsc_options", "\"ksp_type\""],
    );
}

/// A scene with `mesh` as its [mesh] section and one body per name.
fn generated(mesh: &str, bodies: &[&str]) -> String {
    let mut s = format!("[mesh]\n{mesh}\n");
    for b in bodies {
        s += &format!(
            "\n[[body]]\nname = \"{b}\"\nmaterial = \"linear-elastic\"\nyoungs = 1.0\npoisson = 0.3\n"
        );
    }
    s
}

#[test]
fn too_large_generated_meshes_are_refused_before_allocating() {
    let cases = [
        (
            generated(
                "generator = \"hertz-cylinder\"\nlevel = 6",
                &["block", "cylinder"],
            ),
            "level = 6",
            "hertz_cylinder: invalid `level`: the mesh would have 25534464 hex8 cells",
        ),
        (
            generated(
                "generator = \"hertz-sphere\"\nlevel = 3",
                &["block", "sphere"],
            ),
            "level = 3",
            "hertz_sphere: invalid `level`: the mesh would have 34957312 hex8 cells",
        ),
        (
            generated(
                "generator = \"hertz-sphere\"\nfine_size = 0.01",
                &["block", "sphere"],
            ),
            "fine_size",
            "hertz_sphere: invalid `fine_size`: the mesh would have",
        ),
        (
            generated(
                "generator = \"box\"\nsize = [1.0, 1.0, 1.0]\ndivisions = [200, 200, 200]",
                &["block"],
            ),
            "divisions",
            "graded_box: invalid `divisions`: the mesh would have 8000000 hex8 cells and up to 8120601 nodes",
        ),
        (
            generated(
                "generator = \"box\"\nsize = [1.0, 1.0, 1.0]\ndivisions = [150, 150, 150]\ncell_type = \"tet4\"",
                &["block"],
            ),
            "divisions",
            "the mesh would have 20250000 tet4 cells",
        ),
        (
            generated(
                "generator = \"stacked-blocks\"\nupper_divisions = [300, 300, 100]",
                &["lower", "upper"],
            ),
            "upper_divisions",
            "stacked_blocks: invalid `upper_divisions`: the mesh would have 9000032 hex8 cells",
        ),
    ];
    for (i, (scene, at, expect)) in cases.iter().enumerate() {
        let start = std::time::Instant::now();
        check_fails_at(
            &format!("mesh-size-{i}"),
            scene,
            at,
            &[
                expect,
                "above the limit of 20000000 cells and 4000000 nodes",
            ],
        );
        // Refused from the node lines alone: building even a tenth of these
        // meshes takes seconds.
        assert!(
            start.elapsed().as_secs_f64() < 5.0,
            "case {i} took {:?}",
            start.elapsed()
        );
    }
}

#[test]
fn bodies_held_only_by_each_other_are_named() {
    // Two bodies in contact and nothing else: together they float.
    let scene = stacked(CONTACT).replace("[[dirichlet]]\nset = \"lower.bottom\"\n", "");
    check_fails_at(
        "held-by-each-other",
        &scene,
        "name = \"lower\"",
        &[
            "bodies 'lower', 'upper' are held only through contact with each other",
            "singular",
        ],
    );
    // Held on the master side works as well as on the slave side.
    let dir = scratch("held-master-side");
    let scene = stacked(CONTACT).replace("lower.bottom", "upper.top");
    let path = write(&dir, "scene.toml", &scene);
    let o = run(&["check", path.to_str().unwrap()]);
    assert!(o.status.success(), "{}", text(&o));
    // A rigid surface holds its slave.
    let floor = GOOD.replace("[[dirichlet]]\nset = \"block.bottom\"\n", "")
        + "\n[[contact]]\nslave = \"block.bottom\"\nrigid = { kind = \"plane\", point = [0.0, 0.0, 0.0], normal = [0.0, 0.0, 1.0] }\n";
    let path = write(&dir, "rigid.toml", &floor);
    let o = run(&["check", path.to_str().unwrap()]);
    assert!(o.status.success(), "{}", text(&o));
}

/// `run` with `args` fails before any solve, names `expect`, and leaves every
/// file in `keep` as it was.
fn run_refused(args: &[&str], keep: &[&std::path::Path], expect: &str) {
    let before: Vec<Vec<u8>> = keep.iter().map(|p| std::fs::read(p).unwrap()).collect();
    let o = run(args);
    let t = text(&o);
    assert!(!o.status.success(), "{args:?} accepted:\n{t}");
    assert!(t.contains(expect), "{args:?}: no {expect:?} in:\n{t}");
    assert!(!t.contains("done:"), "{args:?} solved:\n{t}");
    for (p, b) in keep.iter().zip(before) {
        assert_eq!(std::fs::read(p).unwrap(), b, "{} was changed", p.display());
    }
}

#[test]
fn output_over_an_input_is_refused() {
    let dir = scratch("output-over-input");
    let scene = write(&dir, "scene.toml", GOOD);
    let s = scene.to_str().unwrap();
    run_refused(
        &["run", s, "-o", s],
        &[&scene],
        "would overwrite the scene file",
    );
    // Spelled differently, through a directory that does not exist yet.
    let other = dir.join("new/../scene.toml");
    run_refused(
        &["run", s, "-o", other.to_str().unwrap()],
        &[&scene],
        "would overwrite the scene file",
    );
    // The scene's own [output] path; a result file named like its own
    // XDMF sidecar.
    let own_path = dir.join("own.toml");
    let own = write(
        &dir,
        "own.toml",
        &format!(
            "{GOOD}\n[output]\npath = {:?}\n",
            own_path.to_str().unwrap()
        ),
    );
    run_refused(
        &["run", own.to_str().unwrap()],
        &[&own],
        "would overwrite the scene file",
    );
    run_refused(
        &["run", s, "-o", dir.join("scene.xmf").to_str().unwrap()],
        &[&scene],
        "the result file and its XDMF sidecar would be the same file",
    );
    // A Gmsh mesh file, and the CSV history written next to `mesh.h5`
    // over a mesh named `mesh.csv`.
    let msh = env!("CARGO_MANIFEST_DIR").to_string() + "/scenes/sphere-block.msh";
    let mesh = dir.join("mesh.csv");
    std::fs::copy(&msh, &mesh).unwrap();
    let text = std::fs::read_to_string(
        env!("CARGO_MANIFEST_DIR").to_string() + "/scenes/sphere-block.toml",
    )
    .unwrap()
    .replace("sphere-block.msh", "mesh.csv");
    let gmsh = write(&dir, "gmsh.toml", &text);
    let g = gmsh.to_str().unwrap();
    run_refused(
        &["run", g, "-o", mesh.to_str().unwrap()],
        &[&mesh, &gmsh],
        "would overwrite the mesh file",
    );
    run_refused(
        &["run", g, "-o", dir.join("mesh.h5").to_str().unwrap()],
        &[&mesh, &gmsh],
        "its CSV history",
    );
}

#[test]
fn petsc_option_errors_name_the_option() {
    let dir = scratch("petsc-options");
    let scene = write(&dir, "scene.toml", GOOD);
    let s = scene.to_str().unwrap();
    let cases: [(&[&str], &str); 5] = [
        (
            &["-ksp_type", "nonsense"],
            "option -ksp_type nonsense: Unable to find requested KSP type nonsense",
        ),
        (
            &["-pc_type", "foo"],
            "option -pc_type foo: Unable to find requested PC type foo",
        ),
        (
            &["-ksp_rtol", "abc"],
            "option -ksp_rtol abc: Input string abc has no numeric value",
        ),
        (
            &["-snes_max_it", "1.5x"],
            "option -snes_max_it 1.5x: Input string 1.5x has no integer value",
        ),
        // From the scene: its options outrank the program's defaults, so a
        // bad one is used, and named.
        (
            &[
                "--set",
                "solver.petsc_options=\"-snes_linesearch_type bogus\"",
            ],
            "option -snes_linesearch_type bogus: Unable to find requested Line Search type bogus",
        ),
    ];
    for (extra, expect) in cases {
        let mut args = vec!["run", s, "-q"];
        args.extend_from_slice(extra);
        let o = run(&args);
        let stderr = String::from_utf8_lossy(&o.stderr);
        assert!(!o.status.success(), "{extra:?} accepted:\n{stderr}");
        assert!(
            stderr.contains(expect),
            "{extra:?}: no {expect:?} in:\n{stderr}"
        );
        assert_eq!(stderr.trim().lines().count(), 1, "not one line:\n{stderr}");
    }
}

#[test]
fn plot_over_its_result_file_is_refused() {
    let dir = scratch("plot-over-input");
    let out = dir.join("out.h5");
    let o = run(&["run", "uniaxial-stretch", "-q", "-o", out.to_str().unwrap()]);
    assert!(o.status.success(), "{}", text(&o));
    let before = std::fs::read(&out).unwrap();
    let same = dir.join("x/../out.h5");
    let o = run(&["plot", out.to_str().unwrap(), "-o", same.to_str().unwrap()]);
    let t = text(&o);
    assert!(!o.status.success(), "{t}");
    assert!(t.contains("would overwrite the result file"), "{t}");
    assert_eq!(
        std::fs::read(&out).unwrap(),
        before,
        "the result file changed"
    );
}

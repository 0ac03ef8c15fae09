//! Every scene error names the key and its line in the scene file (or the
//! `--set` override that supplied the value), as `scene.toml:LINE: ...`, and
//! `check` reports what it read.
use super::*;

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
        "contact hertz: mortar, slave cylinder.curved (86 facets), master block.top (78 facets), frictionless",
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

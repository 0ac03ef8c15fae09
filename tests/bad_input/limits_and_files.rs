//! Limits (absurd counts, oversized meshes), PETSc option strings, and files
//! an output would replace.
use super::*;

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
            GOOD.to_string() + "\n[solver]\nuzawa_acceleration = 4\n",
            "uzawa_acceleration",
            "[solver] uzawa_acceleration must be 0 (off) to 3 (got 4)",
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

//! The scenes that used to hang or take per-rank decisions: a Neo-Hookean
//! bar inverted by its first residual, a cantilever bent until a cell
//! inverts, and a patch test whose follower-pressure facets sit on one rank.
use super::*;

/// Box 4×1×1 of 8×1×1 Neo-Hookean cells, xmin held, xmax pushed −0.8 in x
/// in one load step: the first residual inverts cell 7.
const BAR: &str = r#"
[mesh]
generator = "box"
body = "bar"
size = [4.0, 1.0, 1.0]
divisions = [8, 1, 1]

[[body]]
name = "bar"
material = "neo-hookean"
youngs = 100.0
poisson = 0.3

[[dirichlet]]
set = "bar.xmin"

[[dirichlet]]
set = "bar.xmax"
components = ["x"]
value = [-0.8]

[steps]
count = 1
"#;

#[test]
fn neo_hookean_bar_inverted_by_its_first_residual_cuts_back_and_recovers() {
    let dir = scratch("fault-mpi-bar");
    let scene = write(&dir, "bar.toml", BAR);
    let mut reactions = Vec::new();
    for n in [1, 2, 3] {
        let out = dir.join(format!("bar-{n}.h5"));
        let r = bounded_run(
            n,
            None,
            &[
                "run",
                scene.to_str().unwrap(),
                "-v",
                "-o",
                out.to_str().unwrap(),
            ],
        );
        assert!(r.status.success(), "{}: {}", r.args, r.text);
        let cutbacks = r.cutback_lines();
        assert!(
            cutbacks
                .first()
                .is_some_and(|c| c.contains("first residual") && c.contains("det F")),
            "{}: the inverted first residual must be cut back:\n{}",
            r.args,
            r.text
        );
        let steps = assert_file_holds_completed_steps(&out, &r.args);
        let last = *steps.last().unwrap();
        assert!((load_factor(&out, last) - 1.0).abs() < 1e-12);
        // The last step's reaction on the pushed end, from the history CSV,
        // to the digits the run's summary prints.
        let rows = history(&out);
        let step = rows.last().expect("a converged step");
        let reaction: Vec<String> = ["rx", "ry", "rz"]
            .iter()
            .map(|k| format!("{:.6e}", step[&format!("dirichlet1:bar.xmax.{k}")]))
            .collect();
        reactions.push(reaction);
    }
    assert!(reactions.windows(2).all(|w| w[0] == w[1]), "{reactions:?}");
}

/// A Neo-Hookean cantilever whose tip is pushed back and down in one step,
/// far enough that cells near the root invert: the step is cut back until
/// the limit, then one error names the inverted cell and its rank.
const CANTILEVER: &str = r#"
[mesh]
generator = "box"
body = "beam"
size = [6.0, 1.0, 1.0]
divisions = [12, 2, 2]

[[body]]
name = "beam"
material = "neo-hookean"
youngs = 1000.0
poisson = 0.3

[[dirichlet]]
set = "beam.xmin"

[[dirichlet]]
set = "beam.xmax"
components = ["x", "z"]
value = [-3.0, -4.0]

[steps]
count = 1

[solver]
max_cutbacks = 3
"#;

#[test]
fn cantilever_with_an_inverted_cell_ends_with_one_error_on_every_rank_count() {
    let dir = scratch("fault-mpi-cantilever");
    let scene = write(&dir, "cantilever.toml", CANTILEVER);
    for n in [1, 2, 3] {
        let out = dir.join(format!("cantilever-{n}.h5"));
        let r = bounded_run(
            n,
            None,
            &[
                "run",
                scene.to_str().unwrap(),
                "-q",
                "-o",
                out.to_str().unwrap(),
            ],
        );
        assert!(!r.status.success(), "{}: {}", r.args, r.text);
        let errors = r.error_lines();
        assert_eq!(errors.len(), 1, "{}: {}", r.args, r.text);
        assert!(
            errors[0].contains("did not converge") && errors[0].contains("det F"),
            "{}",
            errors[0]
        );
        if n > 1 {
            assert!(errors[0].contains("rank "), "{}", errors[0]);
        }
        assert_file_holds_completed_steps(&out, &r.args);
    }
}

/// Contact patch test, non-matching 4×4 over 5×5 quads, loaded by a
/// follower pressure on the upper block's top: on 2 ranks METIS puts the
/// whole upper block on one rank, so only that rank has follower facets.
/// The slave is the lower block's top, four layers above its fixed bottom:
/// the partition spreads the slave facets over the ranks, and the upper
/// block (no slave facets, 16 of 116 cells) still fits on one side.
const FOLLOWER_PATCH: &str = r#"
[mesh]
generator = "stacked-blocks"
lower_divisions = [5, 5, 4]
upper_divisions = [4, 4, 1]

[[body]]
name = "lower"
material = "linear-elastic"
youngs = 1000.0
poisson = 0.3

[[body]]
name = "upper"
material = "linear-elastic"
youngs = 1000.0
poisson = 0.3

[[dirichlet]]
set = "lower.bottom"

[[dirichlet]]
set = "upper.xmin"
components = ["x"]

[[dirichlet]]
set = "upper.ymin"
components = ["y"]

[[pressure]]
set = "upper.top"
value = 10.0

[[contact]]
name = "interface"
slave = "lower.top"
master = "upper.bottom"
"#;

#[test]
fn follower_patch_test_with_its_loaded_facets_on_one_rank_matches_one_rank() {
    let dir = scratch("fault-mpi-follower-patch");
    let scene = write(&dir, "patch.toml", FOLLOWER_PATCH);
    let mut fields = Vec::new();
    for n in [1, 2] {
        let out = dir.join(format!("patch-{n}.h5"));
        let r = bounded_run(
            n,
            None,
            &[
                "run",
                scene.to_str().unwrap(),
                "-q",
                "-o",
                out.to_str().unwrap(),
            ],
        );
        assert!(r.status.success(), "{}: {}", r.args, r.text);
        let steps = assert_file_holds_completed_steps(&out, &r.args);
        let last = *steps.last().unwrap();
        if n == 2 {
            // The case this test is about: every upper cell (and so every
            // loaded facet) on one rank, none on the other.
            let (part, _) =
                contactlink::output::read_dataset::<i32>(&out, layout::MESH_PARTITION).unwrap();
            let upper = &part[100..];
            assert!(
                upper.iter().all(|r| *r == upper[0]),
                "upper block split: {part:?}"
            );
        }
        let (u, _, _) = contactlink::output::read_nodal(&out, last, layout::DISPLACEMENT).unwrap();
        fields.push(u);
    }
    let d = relative_difference(&fields[0], &fields[1]);
    assert!(d <= 1e-10, "2 ranks differ from 1 rank by {d:.3e}");
}

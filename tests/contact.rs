//! Contact verification against closed forms (docs/formulation.md §12) and the parallel
//! consistency of contact runs. Each test runs the binary (under mpirun where
//! it says so) and reads the HDF5 file it wrote.
mod common;
use common::*;
use contactlink::hertz::{self, HertzCheck, HertzKind};
use contactlink::output::{layout, list_steps, read_dataset, read_nodal};
use std::path::Path;

fn last_step(path: &Path) -> usize {
    *list_steps(path)
        .expect("steps")
        .last()
        .expect("at least one step")
}

fn dataset(path: &Path, step: usize, rel: &str) -> Vec<f64> {
    read_dataset::<f64>(path, &layout::step_dataset(step, rel))
        .expect(rel)
        .0
}

/// Runs `scene` with the links formulation unless `extra` names another:
/// this file checks the links end to end (tests/mortar*.rs the mortar, the
/// default).
fn run_scene(ranks: usize, scene: &str, out: &Path, extra: &[&str]) -> String {
    let mut args = vec!["run", scene, "-o", out.to_str().unwrap()];
    args.extend(links_unless_set(extra));
    let o = mpirun(ranks, &args);
    let t = text(&o);
    assert!(o.status.success(), "{scene} on {ranks} ranks failed:\n{t}");
    t
}

fn norm(v: [f64; 3]) -> f64 {
    (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt()
}

/// Total reaction on every node of the body that carries facet set `set`.
fn reaction_on_body_of(path: &Path, step: usize, set: &str) -> [f64; 3] {
    let (cell, _) = read_dataset::<i64>(
        path,
        &format!("{}/{}", layout::facet_set(set), layout::FACET_CELL),
    )
    .expect("facet set");
    let (cell_body, _) = read_dataset::<i32>(path, layout::MESH_CELL_BODY).expect("cell_body");
    let (cells, shape) = read_dataset::<i64>(path, layout::MESH_CELLS).expect("cells");
    let body = cell_body[cell[0] as usize];
    let mut nodes: Vec<usize> = cells
        .chunks_exact(shape[1])
        .zip(&cell_body)
        .filter(|(_, &b)| b == body)
        .flat_map(|(c, _)| c.iter().map(|&n| n as usize))
        .collect();
    nodes.sort_unstable();
    nodes.dedup();
    let (r, _, _) = read_nodal(path, step, layout::REACTION).expect("reaction");
    let mut f = [0.0; 3];
    for n in nodes {
        for c in 0..3 {
            f[c] += r[3 * n + c];
        }
    }
    f
}

/// The total contact force on the slave balances the reactions of the slave
/// body's supports: |F_c + R| ≤ 1e-7 |R|. The imbalance is the last Uzawa
/// update's multiplier change (the reaction is read at the solved state,
/// the force with the updated multipliers) plus the final residual: at most
/// 6e-10 on the direct path; on the Krylov path, whose non-final solves stop at
/// 1e-2 of their start, the coarse sphere's is 2.6e-8, four decades inside
/// the Uzawa test's own 1e-3.
fn assert_balance(path: &Path, pair: &str, slave_set: &str) {
    let step = last_step(path);
    let fc = dataset(path, step, &layout::pair_dataset(pair, layout::PAIR_FORCE));
    let r = reaction_on_body_of(path, step, slave_set);
    let support = format!("the body of {slave_set}");
    let residual = norm([fc[0] + r[0], fc[1] + r[1], fc[2] + r[2]]);
    println!(
        "{pair}: contact force {fc:?}, reaction of {support} {r:?}, imbalance {:.3e}",
        residual / norm(r)
    );
    assert!(norm(r) > 0.0);
    assert!(
        residual <= 1e-7 * norm(r),
        "contact force does not balance the load: {:.3e} relative",
        residual / norm(r)
    );
}

#[test]
fn block_on_rigid_plane_balances_and_does_not_penetrate() {
    let dir = scratch("contact-block-on-plane");
    let out = dir.join("out.h5");
    run_scene(2, "block-on-plane", &out, &[]);
    assert_balance(&out, "floor", "block.bottom");
    let step = last_step(&out);
    let gap = dataset(&out, step, &layout::pair_dataset("floor", layout::PAIR_GAP));
    let worst = gap.iter().fold(0.0f64, |m, g| m.max(-g));
    // Uzawa tolerance: 1e-4 of the slave facet size (0.25).
    assert!(worst <= 1e-4 * 0.25 + 1e-15, "penetration {worst:.3e}");
    // Uniform compression: all slave points carry pressure.
    let p = dataset(
        &out,
        step,
        &layout::pair_dataset("floor", layout::PAIR_PRESSURE),
    );
    assert!(p.iter().all(|&v| v > 0.0));
}

/// Nodal contact pressure at the nodes of a node set, with their reference
/// positions (small-strain closed forms are stated over the undeformed surface).
fn nodal_pressure_on(path: &Path, step: usize, set: &str) -> Vec<([f64; 3], f64)> {
    let (nodes, _) = read_dataset::<i64>(path, &layout::node_set(set)).expect("node set");
    let (x, _) = read_dataset::<f64>(path, layout::MESH_NODES).expect("nodes");
    let (p, _, _) = read_nodal(path, step, layout::CONTACT_PRESSURE).expect("contact_pressure");
    nodes
        .iter()
        .map(|&n| {
            let n = n as usize;
            ([x[3 * n], x[3 * n + 1], x[3 * n + 2]], p[n])
        })
        .collect()
}

#[test]
fn patch_test_pressure_is_uniform_up_to_the_measured_deviation() {
    let dir = scratch("contact-patch");
    let out = dir.join("out.h5");
    run_scene(2, "patch-test", &out, &[]);
    assert_balance(&out, "interface", "upper.bottom");
    let step = last_step(&out);
    let force = dataset(
        &out,
        step,
        &layout::pair_dataset("interface", layout::PAIR_FORCE),
    );
    let mean = force[2].abs(); // interface area 1 × 1
    let nodal = nodal_pressure_on(&out, step, "upper.bottom");
    let nodal_dev = nodal
        .iter()
        .fold(0.0f64, |m, (_, p)| m.max((p - mean).abs()))
        / mean;
    let points = dataset(
        &out,
        step,
        &layout::pair_dataset("interface", layout::PAIR_PRESSURE),
    );
    let point_dev = points.iter().fold(0.0f64, |m, v| m.max((v - mean).abs())) / mean;
    println!(
        "patch test: mean pressure {mean:.6e} (E·strain = 10), max deviation: nodal pressure {:.2} %, point multipliers {:.2} %",
        100.0 * nodal_dev,
        100.0 * point_dev
    );
    // The Gauss-point formulation does not pass the patch test on
    // non-matching meshes: slave points carry the load to master nodes with
    // the slave's quadrature, not the master's. See docs/verification.md for
    // the measured deviation; this bound guards against regressions.
    assert!(
        (mean - 10.0).abs() < 1e-2 * 10.0,
        "mean contact pressure {mean} is not E·strain = 10"
    );
    assert!(
        nodal_dev < NODAL_PATCH_BOUND,
        "nodal pressure deviates {:.2} %",
        100.0 * nodal_dev
    );
}

// Measured when written: 0.68 % (nodal), 36 % (individual Gauss-point multipliers).
const NODAL_PATCH_BOUND: f64 = 0.02;

fn hertz_line(out: &Path) -> hertz::HertzComparison {
    let step = last_step(out);
    let nodal: Vec<([f64; 3], f64)> = nodal_pressure_on(out, step, "cylinder.curved")
        .into_iter()
        .filter(|(_, p)| *p > 0.0)
        .collect();
    let pts: Vec<[f64; 3]> = nodal.iter().map(|(x, _)| *x).collect();
    let p: Vec<f64> = nodal.iter().map(|(_, p)| *p).collect();
    let f = dataset(
        out,
        step,
        &layout::pair_dataset("hertz", layout::PAIR_FORCE),
    );
    let check = HertzCheck {
        kind: HertzKind::Line { thickness: 1.0 },
        pair: "hertz".into(),
        radius: 10.0,
        effective_modulus: hertz::effective_modulus(1000.0, 0.3, 1000.0, 0.3),
    };
    hertz::compare(&check, &pts, &p, &[], [f[0], f[1], f[2]]).expect("a pressure profile")
}

#[test]
fn hertz_cylinder_matches_closed_form_and_improves_under_refinement() {
    let dir = scratch("contact-hertz-cylinder");
    let mut errors = Vec::new();
    for (level, h) in [(0, "0.2"), (1, "0.1")] {
        let out = dir.join(format!("h{level}.h5"));
        run_scene(
            2,
            "hertz-cylinder",
            &out,
            &["--set", &format!("mesh.fine_size={h}")],
        );
        assert_balance(&out, "hertz", "cylinder.curved");
        let c = hertz_line(&out);
        println!(
            "h = {h}: P = {:.5}, p0 {:.5} vs {:.5} ({:+.3} %), b {:.5} vs {:.5} ({:+.3} %)",
            c.load,
            c.p0,
            c.p0_exact,
            100.0 * c.p0_error(),
            c.width,
            c.width_exact,
            100.0 * c.width_error()
        );
        errors.push((c.p0_error().abs(), c.width_error().abs()));
    }
    let (p_fine, b_fine) = errors[1];
    assert!(
        p_fine < 0.01 && b_fine < 0.02,
        "Hertz errors at h = 0.1: p0 {:.3} %, b {:.3} %",
        100.0 * p_fine,
        100.0 * b_fine
    );
    assert!(
        errors[1].0 + errors[1].1 < errors[0].0 + errors[0].1,
        "errors did not fall under refinement: {errors:?}"
    );
}

#[test]
fn contact_scenes_same_on_1_2_3_ranks() {
    for (scene, pair, extra) in [
        ("patch-test", "interface", vec![]),
        ("block-on-plane", "floor", vec![]),
        (
            "hertz-cylinder",
            "hertz",
            vec!["--set", "mesh.fine_size=0.2"],
        ),
    ] {
        let dir = scratch(&format!("contact-ranks-{scene}"));
        let files: Vec<_> = [1, 2, 3]
            .iter()
            .map(|n| dir.join(format!("{n}.h5")))
            .collect();
        for (n, f) in [1, 2, 3].iter().zip(&files) {
            let mut args = vec!["-q"];
            args.extend(extra.iter().copied());
            run_scene(*n, scene, f, &args);
        }
        let step = last_step(&files[0]);
        let (u1, _, _) = read_nodal(&files[0], step, layout::DISPLACEMENT).unwrap();
        let p1 = dataset(
            &files[0],
            step,
            &layout::pair_dataset(pair, layout::PAIR_PRESSURE),
        );
        for (n, f) in [2, 3].iter().zip(&files[1..]) {
            let (u, _, _) = read_nodal(f, step, layout::DISPLACEMENT).unwrap();
            let p = dataset(f, step, &layout::pair_dataset(pair, layout::PAIR_PRESSURE));
            let (du, dp) = (relative_difference(&u1, &u), relative_difference(&p1, &p));
            println!("{scene}: {n} ranks vs 1: displacement {du:.3e}, pressure {dp:.3e}");
            assert!(
                du < 1e-8 && dp < 1e-8,
                "{scene}: {n} ranks differ from 1: displacement {du:.3e}, pressure {dp:.3e}"
            );
        }
    }
}

/// Each rank's mesh piece comes from rank 0's distribution: on 1, 3, 4 and
/// 8 ranks (8 oversubscribed; direct solver) displacement, contact pressure
/// (the mortar's nodal multipliers) and reactions agree to 1e-10.
#[test]
fn contact_scenes_same_on_1_3_4_8_ranks() {
    for (scene, pair, extra, pressure) in [
        ("patch-test", "interface", None, "pressure"),
        ("block-on-plane", "floor", None, "pressure"),
        (
            "patch-test",
            "interface",
            Some("contact.formulation=mortar"),
            "node_lambda",
        ),
        (
            "block-on-plane",
            "floor",
            Some("contact.formulation=mortar"),
            "node_lambda",
        ),
    ] {
        let label = format!("{scene}{}", if extra.is_some() { "-mortar" } else { "" });
        let dir = scratch(&format!("contact-ranks-1348-{label}"));
        let ranks = [1, 3, 4, 8];
        let files: Vec<_> = ranks.iter().map(|n| dir.join(format!("{n}.h5"))).collect();
        for (n, f) in ranks.iter().zip(&files) {
            let mut args = vec!["-q"];
            if let Some(set) = extra {
                args.extend(["--set", set]);
            }
            run_scene(*n, scene, f, &args);
        }
        let step = last_step(&files[0]);
        let field = |f: &std::path::Path, name: &str| read_nodal(f, step, name).unwrap().0;
        let (u1, r1) = (
            field(&files[0], "displacement"),
            field(&files[0], "reaction"),
        );
        let p1 = dataset(&files[0], step, &format!("contact/{pair}/{pressure}"));
        assert!(
            p1.iter().any(|&p| p > 0.0),
            "{label}: no contact pressure on 1 rank"
        );
        for (n, f) in ranks[1..].iter().zip(&files[1..]) {
            let du = relative_difference(&u1, &field(f, "displacement"));
            let dr = relative_difference(&r1, &field(f, "reaction"));
            let dp = relative_difference(
                &p1,
                &dataset(f, step, &format!("contact/{pair}/{pressure}")),
            );
            println!("{label}: {n} ranks vs 1: displacement {du:.3e}, pressure {dp:.3e}, reaction {dr:.3e}");
            assert!(
                du < 1e-10 && dp < 1e-10 && dr < 1e-10,
                "{label}: {n} ranks differ from 1: displacement {du:.3e}, pressure {dp:.3e}, reaction {dr:.3e}"
            );
        }
    }
}

#[test]
fn hertz_sphere_on_a_coarse_mesh_is_close_to_closed_form() {
    // Two elements per contact radius (fine_size 0.5): a smoke test of point
    // contact in 3D, with tolerances for that resolution; the default mesh's
    // figures are in docs/verification.md.
    let dir = scratch("contact-hertz-sphere");
    let out = dir.join("out.h5");
    run_scene(
        2,
        "hertz-sphere",
        &out,
        &["--set", "mesh.fine_size=0.5", "--set", "steps.count=1"],
    );
    assert_balance(&out, "hertz", "sphere.curved");
    let step = last_step(&out);
    let nodal: Vec<([f64; 3], f64)> = nodal_pressure_on(&out, step, "sphere.curved")
        .into_iter()
        .filter(|(_, p)| *p > 0.0)
        .collect();
    let pts: Vec<[f64; 3]> = nodal.iter().map(|(x, _)| *x).collect();
    let p: Vec<f64> = nodal.iter().map(|(_, p)| *p).collect();
    let f = dataset(
        &out,
        step,
        &layout::pair_dataset("hertz", layout::PAIR_FORCE),
    );
    let check = HertzCheck {
        kind: HertzKind::Point,
        pair: "hertz".into(),
        radius: 10.0,
        effective_modulus: hertz::effective_modulus(1000.0, 0.3, 1000.0, 0.3),
    };
    let c = hertz::compare(&check, &pts, &p, &[], [f[0], f[1], f[2]]).expect("a pressure profile");
    println!(
        "sphere: F = {:.5}, p0 {:.5} vs {:.5} ({:+.3} %), a {:.5} vs {:.5} ({:+.3} %)",
        c.load,
        c.p0,
        c.p0_exact,
        100.0 * c.p0_error(),
        c.width,
        c.width_exact,
        100.0 * c.width_error()
    );
    assert!(
        c.p0_error().abs() < 0.05 && c.width_error().abs() < 0.03,
        "sphere errors too large: p0 {:.2} %, a {:.2} %",
        100.0 * c.p0_error(),
        100.0 * c.width_error()
    );
}

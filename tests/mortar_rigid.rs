//! Mortar contact against rigid analytic masters end to end: a block pressed
//! onto a rigid plane (fixed and moving) carries a uniform pressure, hex and
//! tet, with the links measured on the same scenes; a block pulled over a
//! rigid plane, and a block held while the plane moves under it, transmit
//! exactly μN once every node slides (and end in the same state); a
//! frictional block on a moving rigid cylinder gives the same answers on 1,
//! 2 and 3 ranks; a frictional impact on a rigid plane (dynamics) never
//! creates energy and ends near the links' momentum; a block pushed past
//! the step's search margin is found by a search from the solved state.
mod common;
use common::*;
use contactlink::output::{layout, list_steps, read_dataset, read_nodal};
use std::collections::HashMap;
use std::path::{Path, PathBuf};

fn run_scene(dir: &Path, tag: &str, body: &str, ranks: usize) -> Result<PathBuf, String> {
    let path = write(dir, &format!("{tag}.toml"), body);
    let out = dir.join(format!("{tag}.h5"));
    let o = mpirun(
        ranks,
        &[
            "run",
            path.to_str().unwrap(),
            "-q",
            "-o",
            out.to_str().unwrap(),
        ],
    );
    if o.status.success() {
        Ok(out)
    } else {
        Err(text(&o))
    }
}

fn last_step(path: &Path) -> usize {
    *list_steps(path).expect("steps").last().expect("a step")
}

/// The per-step history CSV written next to the HDF5 file.
fn history(h5: &Path) -> Vec<HashMap<String, f64>> {
    let text = std::fs::read_to_string(h5.with_extension("csv")).expect("history csv");
    let mut lines = text.lines();
    let header: Vec<&str> = lines.next().expect("header").split(',').collect();
    lines
        .map(|l| {
            header
                .iter()
                .zip(l.split(','))
                .map(|(k, v)| (k.to_string(), v.parse().expect("number")))
                .collect()
        })
        .collect()
}

/// A 1 × 1 × 0.5 linear-elastic block (E = 1000, ν = 0.3, 4×4×2 cells of
/// `cell_type`), its top pushed down 0.01, on symmetry rollers, pressed onto
/// the rigid plane z = 0 that moves up `lift` (uniaxial stress: the exact
/// pressure is E (0.01 + lift) / 0.5 everywhere).
fn pressed_block(cell_type: &str, lift: f64, formulation: &str) -> String {
    format!(
        r#"title = "block pressed on a rigid plane"
[mesh]
generator = "box"
body = "block"
size = [1.0, 1.0, 0.5]
divisions = [4, 4, 2]
cell_type = "{cell_type}"

[[body]]
name = "block"
material = "linear-elastic"
youngs = 1000.0
poisson = 0.3

[[dirichlet]]
set = "block.xmin"
components = ["x"]

[[dirichlet]]
set = "block.ymin"
components = ["y"]

[[dirichlet]]
set = "block.top"
components = ["z"]
value = [-0.01]

[[contact]]
name = "floor"
slave = "block.bottom"
rigid = {{ kind = "plane", point = [0.0, 0.0, 0.0], normal = [0.0, 0.0, 1.0] }}
motion = [0.0, 0.0, {lift}]
formulation = "{formulation}"
penetration_tol = 1e-9
multiplier_tol = 1e-9
max_uzawa = 60
"#
    )
}

/// Nodal contact pressure at the slave nodes: (mean, max |p − mean| / mean).
fn pressure_deviation(out: &Path) -> (f64, f64) {
    let (nodes, _) = read_dataset::<i64>(out, &layout::node_set("block.bottom")).expect("set");
    let (p, _, _) = read_nodal(out, last_step(out), layout::CONTACT_PRESSURE).expect("pressure");
    let p: Vec<f64> = nodes.iter().map(|&n| p[n as usize]).collect();
    let mean = p.iter().sum::<f64>() / p.len() as f64;
    let dev = p.iter().fold(0.0f64, |m, v| m.max((v - mean).abs())) / mean;
    (mean, dev)
}

#[test]
fn block_on_a_rigid_plane_carries_a_uniform_pressure() {
    let dir = scratch("mortar-rigid-plane");
    let mut worst = 0.0f64;
    for cell_type in ["hex8", "tet4"] {
        for lift in [0.0, 0.005] {
            let tag = format!("{cell_type}-{lift}");
            let exact = 1000.0 * (0.01 + lift) / 0.5;
            let out = run_scene(
                &dir,
                &format!("{tag}-mortar"),
                &pressed_block(cell_type, lift, "mortar"),
                1,
            )
            .unwrap_or_else(|t| panic!("{tag}: {t}"));
            let (mean, dev) = pressure_deviation(&out);
            let links = match run_scene(
                &dir,
                &format!("{tag}-links"),
                &pressed_block(cell_type, lift, "links"),
                1,
            ) {
                Ok(o) => format!("{:.2e}", pressure_deviation(&o).1),
                Err(t) => format!("failed ({})", t.lines().last().unwrap_or("")),
            };
            println!(
                "{cell_type}, plane lifted {lift}: mortar mean {mean:.9} (exact {exact}), max deviation {dev:.2e}; links: {links}"
            );
            assert!((mean - exact).abs() < 1e-6 * exact, "{tag}: mean {mean}");
            let rows = history(&out);
            let fz = rows.last().expect("a row")["floor.fz"];
            assert!((fz - exact).abs() < 1e-6 * exact, "{tag}: force {fz}");
            worst = worst.max(dev);
        }
    }
    assert!(worst < 1e-6, "uniform pressure deviates by {worst:.2e}");
}

/// The `block-slide` scene (a 4×4×2 block pressed with N = 10 onto the
/// rigid plane z = 0, then its top pulled 0.01 in x; μ = 0.3) as a mortar
/// pair; `moving`: the top held instead and the plane moved −0.01 in x
/// along the same load path (the same relative motion).
fn slide(moving: bool, steps: usize) -> String {
    let (pull, motion) = if moving {
        (
            0.0,
            "motion = [-0.01, 0.0, 0.0]\nmotion_amplitude = [[0.0, 0.0], [0.25, 0.0], [1.0, 1.0]]",
        )
    } else {
        (0.01, "")
    };
    format!(
        r#"title = "block sliding on a rigid plane"
[mesh]
generator = "box"
body = "block"
size = [1.0, 1.0, 0.5]
divisions = [4, 4, 2]

[[body]]
name = "block"
material = "linear-elastic"
youngs = 1000.0
poisson = 0.0

[[dirichlet]]
set = "block.top"
components = ["x", "y"]
value = [{pull}, 0.0]
amplitude = [[0.0, 0.0], [0.25, 0.0], [1.0, 1.0]]

[[pressure]]
set = "block.top"
value = 10.0
amplitude = [[0.0, 0.0], [0.25, 1.0], [1.0, 1.0]]

[[contact]]
name = "floor"
slave = "block.bottom"
rigid = {{ kind = "plane", point = [0.0, 0.0, 0.0], normal = [0.0, 0.0, 1.0] }}
{motion}
formulation = "mortar"
friction = 0.3

[steps]
count = {steps}
"#
    )
}

/// Steps at which every active node slides, and the worst |T/N − μ|,
/// |Fx/Fz − μ| there; asserts Fz = N (flat) at every step and no sliding
/// while T ≤ μN/2. Returns (sticking steps, sliding steps, worst).
fn friction_history(rows: &[HashMap<String, f64>], mu: f64) -> (usize, usize, f64) {
    let (mut stuck, mut sliding, mut worst) = (0, 0, 0.0f64);
    for (i, row) in rows.iter().enumerate() {
        let (n, t, fx, fz) = (
            row["floor.normal"],
            row["floor.tangential"],
            row["floor.fx"],
            row["floor.fz"],
        );
        assert!((fz - n).abs() <= 1e-12 * n, "step {}: flat, Fz = N", i + 1);
        if t <= 0.5 * mu * n {
            assert_eq!(row["floor.sliding"], 0.0, "step {} slides", i + 1);
            stuck += 1;
        }
        if row["floor.sliding"] == row["floor.active"] && row["floor.active"] > 0.0 {
            worst = worst
                .max((fx.abs() / fz - mu).abs())
                .max((t / n - mu).abs());
            sliding += 1;
        }
    }
    (stuck, sliding, worst)
}

#[test]
fn block_on_a_rigid_plane_slides_at_exactly_mu_n() {
    let dir = scratch("mortar-rigid-slide");
    let mu = 0.3;
    let pulled = run_scene(&dir, "pulled", &slide(false, 20), 1).unwrap();
    let rows = history(&pulled);
    assert_eq!(rows.len(), 20);
    let (stuck, sliding, worst) = friction_history(&rows, mu);
    println!("pulled block: {stuck} sticking steps, {sliding} fully sliding steps, |T/N − μ| ≤ {worst:.1e}");
    assert!(worst <= 1e-12, "T/N off μ by {worst:e}");
    assert!(
        stuck >= 6 && sliding >= 5,
        "{stuck} stuck, {sliding} sliding"
    );

    // The plane moved under the held block: friction drags the block's
    // base along (−x) until it slides at μN. (Each step's trial slip is
    // the plane's whole move, far beyond what εT allows in stick, so the
    // load steps are cut back while the base sticks, as with the links.)
    let moved = run_scene(&dir, "moved", &slide(true, 20), 1).unwrap();
    let rows = history(&moved);
    let (_, sliding, worst) = friction_history(&rows, mu);
    let end = rows.last().unwrap();
    println!(
        "moving plane: {} steps, {sliding} fully sliding, |T/N − μ| ≤ {worst:.1e}, final Fx {:.12}",
        rows.len(),
        end["floor.fx"]
    );
    assert!(
        worst <= 1e-12 && sliding >= 5,
        "moving plane: {worst:e}, {sliding}"
    );
    assert!((end["floor.fx"] + mu * end["floor.normal"]).abs() <= 1e-12 * end["floor.normal"]);
    // Once fully sliding the state is unique (the top is held): the held
    // block is the pulled one translated back by the pull.
    let u = |out: &Path| read_nodal(out, last_step(out), "displacement").unwrap().0;
    let (up, um) = (u(&pulled), u(&moved));
    let shifted: Vec<f64> = up
        .iter()
        .enumerate()
        .map(|(i, v)| if i % 3 == 0 { v - 0.01 } else { *v })
        .collect();
    let d = relative_difference(&um, &shifted);
    println!("moving plane against the pulled block shifted back: displacement {d:.1e}");
    assert!(d < 1e-8, "moving plane: displacement differs by {d:e}");
}

/// A 2 × 1 × 0.5 block (8×4×2 hex8 or tet4) pressed down 0.03 onto a
/// rigid cylinder of radius 2 along y (its top at z = 0) while the cylinder
/// moves 0.05 in x; μ = 0.2.
fn on_cylinder(cell_type: &str) -> String {
    format!(
        r#"title = "block pressed on a moving rigid cylinder"
[mesh]
generator = "box"
body = "block"
size = [2.0, 1.0, 0.5]
divisions = [8, 4, 2]
cell_type = "{cell_type}"

[[body]]
name = "block"
material = "neo-hookean"
youngs = 1000.0
poisson = 0.3

[[dirichlet]]
set = "block.top"
value = [0.0, 0.0, -0.03]

[[contact]]
name = "roll"
slave = "block.bottom"
rigid = {{ kind = "cylinder", point = [1.0, 0.0, -2.0], axis = [0.0, 1.0, 0.0], radius = 2.0 }}
motion = [0.05, 0.0, 0.0]
formulation = "mortar"
friction = 0.2

[steps]
count = 4
"#
    )
}

#[test]
fn rigid_mortar_answers_agree_on_one_two_and_three_ranks() {
    let dir = scratch("mortar-rigid-ranks");
    for cell_type in ["hex8", "tet4"] {
        let body = on_cylinder(cell_type);
        let one = run_scene(&dir, &format!("{cell_type}-1"), &body, 1).unwrap();
        let last = last_step(&one);
        let read = |out: &Path| {
            let (u, _, _) = read_nodal(out, last, "displacement").expect("displacement");
            let forces: Vec<f64> = history(out)
                .iter()
                .flat_map(|r| {
                    [
                        "fx",
                        "fy",
                        "fz",
                        "normal",
                        "tangential",
                        "active",
                        "sliding",
                    ]
                    .map(|k| r[&format!("roll.{k}")])
                })
                .collect();
            (u, forces)
        };
        let (u1, f1) = read(&one);
        let rows = history(&one);
        let end = rows.last().unwrap();
        assert!(end["roll.active"] > 0.0 && end["roll.tangential"] > 0.0);
        for ranks in [2, 3] {
            let out = run_scene(&dir, &format!("{cell_type}-{ranks}"), &body, ranks).unwrap();
            let (u, f) = read(&out);
            let (du, df) = (relative_difference(&u1, &u), relative_difference(&f1, &f));
            println!(
                "{cell_type}, {ranks} ranks vs 1: displacement {du:.1e}, force history {df:.1e}"
            );
            assert!(
                du < 1e-10 && df < 1e-10,
                "{cell_type}: {ranks} ranks differ"
            );
        }
    }
}

/// A 1 × 1 × 0.5 block (2×2×2 hex8, ρ = 1, mass 0.5) flying at
/// (0.5, 0, −1) onto the rigid plane z = −0.01, μ = 0.3, Newmark β = ½, γ = 1.
fn drop(formulation: &str) -> String {
    format!(
        r#"title = "block flying onto a rigid plane"
[mesh]
generator = "box"
body = "block"
size = [1.0, 1.0, 0.5]
divisions = [2, 2, 2]

[[body]]
name = "block"
material = "neo-hookean"
youngs = 1000.0
poisson = 0.3
density = 1.0
initial_velocity = [0.5, 0.0, -1.0]

[[contact]]
name = "floor"
slave = "block.bottom"
rigid = {{ kind = "plane", point = [0.0, 0.0, -0.01], normal = [0.0, 0.0, 1.0] }}
formulation = "{formulation}"
friction = 0.3

[dynamics]
time_step = 0.002
beta = 0.5
gamma = 1.0

[steps]
count = 40
"#
    )
}

#[test]
fn frictional_impact_on_a_rigid_plane_never_creates_energy() {
    // Dynamics: the slip is Δt times the relative velocity and its damping
    // term enters the tangent.
    let dir = scratch("mortar-rigid-impact");
    let mortar = history(&run_scene(&dir, "mortar", &drop("mortar"), 1).unwrap());
    let links = history(&run_scene(&dir, "links", &drop("links"), 1).unwrap());
    let e0 = 0.5 * 0.5 * (0.25 + 1.0);
    let energy: Vec<f64> = mortar.iter().map(|r| r["kinetic"] + r["strain"]).collect();
    for w in energy.windows(2) {
        assert!(w[1] <= w[0] * (1.0 + 1e-9), "energy grew {w:?}");
    }
    let slid = mortar.iter().filter(|r| r["floor.sliding"] > 0.0).count();
    let (end, end_links) = (mortar.last().unwrap(), links.last().unwrap());
    println!(
        "mortar: E_end/E0 = {:.4}, px {:.5} (links {:.5}), pz {:.5} (links {:.5}), {slid} steps with sliding nodes",
        energy.last().unwrap() / e0,
        end["px"],
        end_links["px"],
        end["pz"],
        end_links["pz"]
    );
    assert!(slid >= 3, "only {slid} steps with sliding nodes");
    // It bounced (pz > 0) and friction took tangential momentum (0.25 at first).
    assert!(
        end["pz"] > 0.1 && end["px"] < 0.2,
        "px {}, pz {}",
        end["px"],
        end["pz"]
    );
    for k in ["px", "pz"] {
        assert!(
            (end[k] - end_links[k]).abs() < 0.05 * 0.25,
            "{k}: mortar {} against links {}",
            end[k],
            end_links[k]
        );
    }
}

/// `pressed_block` with the plane 0.05 below the block and the top pushed
/// down 0.06 in one step, the pair's search margin 0.01: the step's search,
/// at the undeformed state, finds no slave facet near the plane, so the
/// first solve pushes the block 0.01 through it; the run must search again
/// from there and end with the uniform pressure E · 0.01 / 0.5 = 20, on 1
/// and 2 ranks.
#[test]
fn rigid_mortar_search_follows_a_block_pushed_past_the_steps_margin() {
    let dir = scratch("mortar-rigid-far");
    let body = pressed_block("hex8", 0.0, "mortar")
        .replace("point = [0.0, 0.0, 0.0]", "point = [0.0, 0.0, -0.05]")
        .replace("value = [-0.01]", "value = [-0.06]")
        .replace("max_uzawa = 60", "max_uzawa = 60\nsearch_distance = 0.01");
    assert!(body.contains("search_distance = 0.01") && body.contains("-0.05]"));
    for ranks in [1, 2] {
        let out = run_scene(&dir, &format!("far-{ranks}"), &body, ranks)
            .unwrap_or_else(|t| panic!("{ranks} rank(s): {t}"));
        let (mean, dev) = pressure_deviation(&out);
        println!("{ranks} rank(s): mean pressure {mean:.9} (exact 20), max deviation {dev:.2e}");
        assert!((mean - 20.0).abs() < 1e-6 * 20.0, "mean pressure {mean}");
        assert!(dev < 1e-6, "pressure deviates by {dev:.2e}");
    }
}

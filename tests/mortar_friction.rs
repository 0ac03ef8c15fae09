//! Mortar contact with Coulomb friction end to end: a block pressed onto a
//! fixed flat block and pulled (stick below μN, exactly μN while every node
//! slides), a pull that stays below μN (stick throughout), the same
//! answers on 1, 2 and 3 ranks, and a frictional impact in dynamics.
mod common;
use common::*;
use contactlink::output::{list_steps, read_dataset, read_nodal};
use std::collections::HashMap;
use std::path::{Path, PathBuf};

/// An elastic block (1 × 1 × 0.5, 5×5×2 hex8, E = 1000, ν = 0) pressed by a
/// pressure of 10 (N = 10) during the first quarter of the load path onto a
/// 4×4 block whose top is held fixed (the slave: flat, so Fz = N exactly),
/// then its top pulled `pull` in x. (The fixed slave is the coarser side: a
/// fixed finer slave would ask more stick constraints of the master's nodes
/// than they have tangential DOFs, and the nodal λT would not be unique.)
fn scene(mu: f64, pull: f64, steps: usize, formulation: &str) -> String {
    format!(
        r#"title = "mortar block slide"
[mesh]
generator = "stacked-blocks"
length = 1.0
height = 0.5
gap = 0.0
lower_divisions = [4, 4, 2]
upper_divisions = [5, 5, 2]
cell_type = "hex8"

[[body]]
name = "lower"
material = "linear-elastic"
youngs = 1000.0
poisson = 0.0

[[body]]
name = "upper"
material = "linear-elastic"
youngs = 1000.0
poisson = 0.0

[[dirichlet]]
set = "lower.bottom"

[[dirichlet]]
set = "lower.top"

[[dirichlet]]
set = "upper.top"
components = ["x", "y"]
value = [{pull}, 0.0]
amplitude = [[0.0, 0.0], [0.25, 0.0], [1.0, 1.0]]

[[pressure]]
set = "upper.top"
value = 10.0
amplitude = [[0.0, 0.0], [0.25, 1.0], [1.0, 1.0]]

[[contact]]
name = "interface"
slave = "lower.top"
master = "upper.bottom"
formulation = "{formulation}"
friction = {mu}

[steps]
count = {steps}
"#
    )
}

fn run_scene(dir: &Path, tag: &str, body: &str, ranks: usize) -> PathBuf {
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
    assert!(o.status.success(), "{tag} on {ranks} ranks:\n{}", text(&o));
    out
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

/// Largest mean slip of the step at a slave node.
fn largest_slip(out: &Path, step: usize) -> f64 {
    read_dataset::<f64>(
        out,
        &format!("/steps/{step:06}/contact/interface/node_slip"),
    )
    .expect("node_slip")
    .0
    .chunks_exact(3)
    .map(|s| (s[0] * s[0] + s[1] * s[1] + s[2] * s[2]).sqrt())
    .fold(0.0, f64::max)
}

#[test]
fn mortar_block_sticks_below_mu_n_and_transmits_mu_n_while_sliding() {
    let dir = scratch("mortar-friction-slide");
    let (mu, h) = (0.3, 0.25);
    let out = run_scene(&dir, "slide", &scene(mu, 0.02, 20, "mortar"), 1);
    let steps = list_steps(&out).unwrap();
    let rows = history(&out);
    assert_eq!(rows.len(), steps.len());
    let (mut stuck, mut sliding, mut worst) = (0, 0, 0.0f64);
    for (row, &step) in rows.iter().zip(&steps) {
        let (n, t) = (row["interface.normal"], row["interface.tangential"]);
        let (fx, fz) = (row["interface.fx"], row["interface.fz"]);
        assert!(
            (fz.abs() - n).abs() <= 1e-12 * n,
            "step {step}: flat, Fz = N"
        );
        if t <= 0.5 * mu * n {
            assert_eq!(
                row["interface.sliding"], 0.0,
                "step {step} slides at T = {t}"
            );
            let slip = largest_slip(&out, step);
            assert!(
                slip <= 1e-3 * h,
                "step {step}: slip {slip:e} while sticking"
            );
            stuck += 1;
        }
        if row["interface.sliding"] == row["interface.active"] && row["interface.active"] > 0.0 {
            let ratio = fx.abs() / fz.abs();
            println!(
                "step {step}: sliding, Fx/Fz = {ratio:.12}, T/N = {:.12}",
                t / n
            );
            worst = worst.max((ratio - mu).abs()).max((t / n - mu).abs());
            sliding += 1;
        }
    }
    println!("{stuck} sticking steps, {sliding} sliding steps, |Fx/Fz − μ| ≤ {worst:.1e}");
    assert!(worst <= 1e-10, "Fx/Fz off μ by {worst:e}");
    assert!(stuck >= 6, "too few sticking steps ({stuck})");
    assert!(sliding >= 5, "too few fully sliding steps ({sliding})");
    // Every slave node in contact at the last step is sliding.
    let last = *steps.last().unwrap();
    let read = |name: &str| {
        read_dataset::<f64>(&out, &format!("/steps/{last:06}/contact/interface/{name}"))
            .expect(name)
            .0
    };
    for (s, l) in read("node_state").iter().zip(&read("node_lambda")) {
        assert_eq!(*s, if *l > 0.0 { 2.0 } else { 0.0 });
    }
}

#[test]
fn mortar_block_sticks_while_the_pull_stays_below_mu_n() {
    let dir = scratch("mortar-friction-stick");
    let (mu, h) = (1.0, 0.25);
    let out = run_scene(&dir, "stick", &scene(mu, 0.0035, 10, "mortar"), 1);
    let steps = list_steps(&out).unwrap();
    let rows = history(&out);
    let mut largest = 0.0f64;
    for (row, &step) in rows.iter().zip(&steps) {
        let (n, t) = (row["interface.normal"], row["interface.tangential"]);
        // Below a quarter of μN not even the rim slips.
        assert!(t < 0.25 * mu * n, "step {step}: T = {t}, N = {n}");
        assert_eq!(row["interface.sliding"], 0.0, "step {step} slides");
        let slip = largest_slip(&out, step);
        assert!(slip <= 1e-3 * h, "step {step}: slip {slip:e}");
        largest = largest.max(t / n);
    }
    println!("stick: largest T/N {largest:.4} (μ = {mu}), no node slides");
    assert!(largest > 0.1, "the pull transmits no friction ({largest})");
}

#[test]
fn frictional_mortar_answers_agree_on_one_two_and_three_ranks() {
    let dir = scratch("mortar-friction-ranks");
    let body = scene(0.3, 0.06, 10, "mortar");
    let one = run_scene(&dir, "ranks-1", &body, 1);
    let last = *list_steps(&one).unwrap().last().unwrap();
    let read = |out: &Path| {
        let (u, _, _) = read_nodal(out, last, "displacement").expect("displacement");
        let forces: Vec<f64> = history(out)
            .iter()
            .flat_map(|r| {
                ["fx", "fy", "fz", "normal", "tangential", "sliding"]
                    .map(|k| r[&format!("interface.{k}")])
            })
            .collect();
        (u, forces)
    };
    let (u1, f1) = read(&one);
    assert!(f1.iter().any(|&f| f > 0.0));
    for ranks in [2, 3] {
        let out = run_scene(&dir, &format!("ranks-{ranks}"), &body, ranks);
        let (u, f) = read(&out);
        let (du, df) = (relative_difference(&u1, &u), relative_difference(&f1, &f));
        println!("{ranks} ranks vs 1: displacement {du:.1e}, force history {df:.1e}");
        assert!(du < 1e-10 && df < 1e-10, "{ranks} ranks differ");
    }
}

#[test]
fn frictional_mortar_impact_conserves_momentum_and_never_creates_energy() {
    // The `impact` scene (Newmark, friction damping in the tangent) with a
    // mortar pair: the upper block (mass 0.5) flies at (0.5, 0, −1) onto
    // the lower one at rest.
    let dir = scratch("mortar-friction-impact");
    let out = dir.join("impact.h5");
    let o = mpirun(
        1,
        &[
            "run",
            "impact",
            "-q",
            "-o",
            out.to_str().unwrap(),
            "--set",
            "contact.formulation=mortar",
            "--set",
            "contact.friction=0.3",
        ],
    );
    assert!(o.status.success(), "{}", text(&o));
    let rows = history(&out);
    let p0 = [0.25, 0.0, -0.5];
    let e0 = 0.5 * 0.5 * (0.25 + 1.0);
    let slid = rows.iter().filter(|r| r["impact.sliding"] > 0.0).count();
    assert!(slid >= 3, "only {slid} steps with sliding nodes");
    let energy: Vec<f64> = rows.iter().map(|r| r["kinetic"] + r["strain"]).collect();
    for r in &rows {
        let drift = [r["px"], r["py"], r["pz"]]
            .iter()
            .zip(p0)
            .fold(0.0f64, |m, (a, b)| m.max((a - b).abs()));
        assert!(drift < 1e-10, "momentum drift {drift:e}");
    }
    for w in energy.windows(2) {
        assert!(w[1] <= w[0] * (1.0 + 1e-9), "energy grew {w:?}");
    }
    let last = *energy.last().unwrap();
    println!(
        "mortar impact μ = 0.3: E_end/E0 = {:.4} ({:.1} % dissipated), {slid} steps with sliding nodes",
        last / e0,
        100.0 * (1.0 - last / e0)
    );
    assert!(last < 0.75 * e0, "friction dissipates ({last} of {e0})");
}

/// A mortar pair's failed Newton solve reports its slave nodes (not links)
/// at the failing iterate: pressed, sliding, sticking and the deepest mean
/// penetration; and the file keeps every converged step.
#[test]
fn a_failed_step_reports_the_mortar_pairs_nodes() {
    let dir = scratch("mortar-friction-failure");
    let out = dir.join("fail.h5");
    let t = failing_block_slide(&out, "mortar");
    assert!(!t.contains("links of pair"), "{t}");
    for expect in [
        "slave nodes of mortar pair 'floor'",
        "pressed together (p > 0)",
        "sliding",
        "sticking",
        "max mean penetration",
    ] {
        assert!(t.contains(expect), "message lacks {expect:?}:\n{t}");
    }
    assert_eq!(t.trim().lines().count(), 1, "one error line:\n{t}");
    assert!(!list_steps(&out).expect("the file stays valid").is_empty());
}

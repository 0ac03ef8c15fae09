//! Coulomb friction and implicit dynamics end to end (docs/formulation.md §5, §8, §12):
//! block-slide (stick below μN, exactly μN while sliding), ironing (μ in
//! steady sliding), impact (momentum through contact, energy never created),
//! and the frictional scenes on 1 and 2 ranks.
mod common;
use common::*;
use contactlink::output::{layout, list_steps, read_dataset, read_nodal};
use std::collections::HashMap;
use std::path::Path;

/// Runs `scene` with the links formulation unless `extra` names another:
/// this file checks the links' friction and dynamics end to end
/// (tests/mortar_friction.rs the mortar's, the default).
fn run_scene(ranks: usize, scene: &str, out: &Path, extra: &[&str]) -> String {
    let mut args = vec!["run", scene, "-q", "-o", out.to_str().unwrap()];
    args.extend(links_unless_set(extra));
    let o = mpirun(ranks, &args);
    let t = text(&o);
    assert!(o.status.success(), "{scene} on {ranks} ranks failed:\n{t}");
    t
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

fn dataset(path: &Path, step: usize, rel: &str) -> Vec<f64> {
    read_dataset::<f64>(path, &layout::step_dataset(step, rel))
        .expect(rel)
        .0
}

#[test]
fn block_slide_sticks_below_mu_n_and_transmits_mu_n_while_sliding() {
    let dir = scratch("friction-block-slide");
    let out = dir.join("slide.h5");
    run_scene(1, "block-slide", &out, &[]);
    let mu = 0.3;
    let h = 0.25; // the block's element size
    let rows = history(&out);
    let steps = list_steps(&out).unwrap();
    assert_eq!(rows.len(), steps.len());
    let (mut stuck, mut sliding) = (0, 0);
    for (row, &step) in rows.iter().zip(&steps) {
        let (n, t) = (row["floor.normal"], row["floor.tangential"]);
        let (fx, fz) = (row["floor.fx"], row["floor.fz"]);
        assert!(
            (fz - n).abs() <= 1e-12 * n,
            "step {step}: flat plane, Fz = N"
        );
        if t <= 0.5 * mu * n {
            // Well below μN nothing slips: every point sticks and its slip
            // in the step is below the Uzawa tolerance (1e-3 h).
            assert_eq!(row["floor.sliding"], 0.0, "step {step} slides at T = {t}");
            let slip = dataset(
                &out,
                step,
                &layout::pair_dataset("floor", layout::PAIR_SLIP),
            );
            let worst = slip
                .chunks_exact(3)
                .map(|s| (s[0] * s[0] + s[1] * s[1] + s[2] * s[2]).sqrt())
                .fold(0.0, f64::max);
            assert!(
                worst <= 1e-3 * h,
                "step {step}: slip {worst:e} while sticking"
            );
            stuck += 1;
        }
        if row["floor.sliding"] == row["floor.active"] && row["floor.active"] > 0.0 {
            let ratio = fx.abs() / fz;
            println!(
                "step {step}: sliding, Fx/Fz = {ratio:.12}, T/N = {:.12}",
                t / n
            );
            assert!(
                (ratio - mu).abs() <= 1e-6 * mu,
                "step {step}: Fx/Fz = {ratio}"
            );
            assert!((t / n - mu).abs() <= 1e-6 * mu);
            sliding += 1;
        }
    }
    println!("{stuck} sticking steps, {sliding} sliding steps");
    assert!(stuck >= 6, "too few sticking steps ({stuck})");
    assert!(sliding >= 5, "too few fully sliding steps ({sliding})");
    // The state array says the same: 1 (stick) or 2 (slip) on every contact point.
    let last = *steps.last().unwrap();
    let state = dataset(
        &out,
        last,
        &layout::pair_dataset("floor", layout::PAIR_STATE),
    );
    let pressure = dataset(
        &out,
        last,
        &layout::pair_dataset("floor", layout::PAIR_PRESSURE),
    );
    for (s, p) in state.iter().zip(&pressure) {
        assert_eq!(*s, if *p > 0.0 { 2.0 } else { 0.0 });
    }
}

#[test]
fn ironing_transmits_mu_times_the_normal_force_in_steady_sliding() {
    let dir = scratch("friction-ironing");
    let out = dir.join("ironing.h5");
    run_scene(1, "ironing", &out, &[]);
    let mu = 0.3;
    let rows = history(&out);
    let drag: Vec<_> = rows
        .iter()
        .filter(|r| r["load_factor"] >= 0.3 - 1e-12)
        .collect();
    assert!(drag.len() >= 20, "{} drag steps", drag.len());
    let mut global = Vec::new();
    for r in &drag {
        let (n, t) = (r["ironing.normal"], r["ironing.tangential"]);
        assert!(n > 0.0);
        // Steady sliding: every active point slides, so the contact-frame
        // forces are in the ratio μ exactly (to the Newton tolerance).
        assert_eq!(r["ironing.sliding"], r["ironing.active"]);
        assert!((t / n - mu).abs() < 1e-6 * mu, "T/N = {}", t / n);
        global.push(r["ironing.fx"].abs() / r["ironing.fz"].abs());
    }
    // The die's global force ratio oscillates about μ as points cross
    // master facets (h = 0.2); its mean is within a few per cent of μ.
    let mean = global.iter().sum::<f64>() / global.len() as f64;
    let spread = global.iter().fold(0.0f64, |m, g| m.max((g - mean).abs()));
    println!("ironing: |Fx|/|Fz| mean {mean:.4}, largest deviation {spread:.4}");
    assert!((mean - mu).abs() < 0.03, "mean |Fx|/|Fz| = {mean}");
}

/// Kinetic + strain energy and momentum per step from the history.
fn energy_and_momentum(out: &Path) -> (Vec<f64>, Vec<[f64; 3]>) {
    let rows = history(out);
    (
        rows.iter().map(|r| r["kinetic"] + r["strain"]).collect(),
        rows.iter().map(|r| [r["px"], r["py"], r["pz"]]).collect(),
    )
}

#[test]
fn impact_conserves_momentum_and_never_creates_energy() {
    let dir = scratch("dynamics-impact");
    let (plain, rough) = (dir.join("plain.h5"), dir.join("rough.h5"));
    run_scene(1, "impact", &plain, &[]);
    run_scene(1, "impact", &rough, &["--set", "contact.friction=0.3"]);
    // Initial state: upper block (mass 0.5) at (0.5, 0, −1), lower at rest.
    let p0 = [0.25, 0.0, -0.5];
    let e0 = 0.5 * 0.5 * (0.25 + 1.0);
    let mut finals = Vec::new();
    for (name, out) in [("frictionless", &plain), ("μ = 0.3", &rough)] {
        let (energy, momentum) = energy_and_momentum(out);
        let rows = history(out);
        let contact_steps = rows.iter().filter(|r| r["impact.active"] > 0.0).count();
        assert!(contact_steps >= 3, "{name}: the blocks never met");
        for (k, p) in momentum.iter().enumerate() {
            let drift = p
                .iter()
                .zip(p0)
                .fold(0.0f64, |m, (a, b)| m.max((a - b).abs()));
            assert!(drift < 1e-10, "{name} step {}: momentum {p:?}", k + 1);
        }
        assert!((energy[0] - e0).abs() < 1e-12 * e0);
        for w in energy.windows(2) {
            assert!(w[1] <= w[0] * (1.0 + 1e-9), "{name}: energy grew {w:?}");
        }
        let last = *energy.last().unwrap();
        println!(
            "impact {name}: E0 = {e0:.6}, E_end = {last:.6} ({:.1} % dissipated), {contact_steps} steps in contact",
            100.0 * (1.0 - last / e0)
        );
        finals.push(last);
    }
    assert!(
        finals[1] < finals[0],
        "friction must dissipate more: {finals:?}"
    );
}

/// 1 and 2 ranks: same displacements and the same contact force history.
fn same_on_1_and_2_ranks(scene: &str, extra: &[&str], pair: &str) {
    let dir = scratch(&format!("friction-ranks-{scene}"));
    let files: Vec<_> = [1, 2]
        .iter()
        .map(|n| dir.join(format!("{scene}-{n}.h5")))
        .collect();
    for (n, f) in [1, 2].iter().zip(&files) {
        run_scene(*n, scene, f, extra);
    }
    let steps = list_steps(&files[0]).unwrap();
    assert_eq!(list_steps(&files[1]).unwrap(), steps);
    let last = *steps.last().unwrap();
    let (u1, _, _) = read_nodal(&files[0], last, layout::DISPLACEMENT).unwrap();
    let (u2, _, _) = read_nodal(&files[1], last, layout::DISPLACEMENT).unwrap();
    let d = relative_difference(&u1, &u2);
    let (h1, h2) = (history(&files[0]), history(&files[1]));
    let forces = |h: &[HashMap<String, f64>]| -> Vec<f64> {
        h.iter()
            .flat_map(|r| ["fx", "fy", "fz", "tangential"].map(|k| r[&format!("{pair}.{k}")]))
            .collect()
    };
    let df = relative_difference(&forces(&h1), &forces(&h2));
    let state1 = dataset(
        &files[0],
        last,
        &layout::pair_dataset(pair, layout::PAIR_STATE),
    );
    let state2 = dataset(
        &files[1],
        last,
        &layout::pair_dataset(pair, layout::PAIR_STATE),
    );
    println!("{scene}: 2 ranks vs 1: displacement {d:.2e}, contact forces {df:.2e}");
    assert!(d < 1e-8 && df < 1e-8, "{scene}: {d:e} {df:e}");
    assert_eq!(state1, state2, "{scene}: stick/slip states differ");
}

#[test]
fn frictional_scenes_same_on_1_and_2_ranks() {
    same_on_1_and_2_ranks("block-slide", &[], "floor");
    same_on_1_and_2_ranks("impact", &["--set", "contact.friction=0.3"], "impact");
}

#[test]
fn slip_heavy_step_that_cannot_converge_reports_its_link_states() {
    let dir = scratch("friction-failure");
    let out = dir.join("fail.h5");
    let t = failing_block_slide(&out, "links");
    for expect in [
        "did not converge",
        "links of pair 'floor'",
        "sliding",
        "sticking",
    ] {
        assert!(t.contains(expect), "message lacks {expect:?}:\n{t}");
    }
    // Every step before the failure is in the file and readable.
    let steps = list_steps(&out).expect("the file stays valid");
    assert!(!steps.is_empty());
    let rows = history(&out);
    assert_eq!(rows.len(), steps.len());
}

#[test]
fn a_frictionless_static_scene_carries_no_friction_or_dynamics_data() {
    let dir = scratch("pays-only-for-what-it-uses");
    let plain = dir.join("plain.h5");
    let rough = dir.join("rough.h5");
    // Every Newton solve tight and every multiplier update plain in both
    // runs (a frictionless model loosens its non-final solves and
    // accelerates its updates, a frictional one does neither), so the two
    // take the same iterations and must give the same force, not only one
    // within the Uzawa tolerance.
    run_scene(
        1,
        "patch-test",
        &plain,
        &[
            "--set",
            "solver.uzawa_forcing=0",
            "--set",
            "solver.uzawa_acceleration=0",
        ],
    );
    run_scene(1, "patch-test", &rough, &["--set", "contact.friction=0.3"]);
    let last = *list_steps(&plain).unwrap().last().unwrap();
    let has =
        |f: &Path, rel: &str| read_dataset::<f64>(f, &layout::step_dataset(last, rel)).is_ok();
    // μ absent: no friction state, hence no tangential arrays; static: no
    // mass matrix, hence no velocity, energy or momentum.
    for rel in [
        layout::pair_dataset("interface", layout::PAIR_TRACTION_T),
        layout::pair_dataset("interface", layout::PAIR_STATE),
        layout::VELOCITY.to_string(),
        layout::ENERGY.to_string(),
    ] {
        assert!(!has(&plain, &rel), "frictionless static run wrote {rel}");
    }
    assert!(has(
        &rough,
        &layout::pair_dataset("interface", layout::PAIR_TRACTION_T)
    ));
    assert!(!has(&rough, layout::VELOCITY));
    // Uniform compression: friction changes nothing here but must not break
    // the patch test (normal force identical to 1e-8).
    let (h0, h1) = (history(&plain), history(&rough));
    let (n0, n1) = (
        h0.last().unwrap()["interface.normal"],
        h1.last().unwrap()["interface.normal"],
    );
    assert!((n0 - n1).abs() < 1e-6 * n0, "{n0} vs {n1}");
}

#[test]
fn extrapolating_predictor_changes_iterations_not_the_answer() {
    let dir = scratch("friction-extrapolate");
    let (on, off) = (dir.join("on.h5"), dir.join("off.h5"));
    run_scene(1, "block-slide", &on, &["--set", "solver.extrapolate=true"]);
    run_scene(1, "block-slide", &off, &[]);
    let (a, b) = (history(&on), history(&off));
    assert_eq!(a.len(), b.len());
    let newton = |rows: &[HashMap<String, f64>]| rows.iter().map(|r| r["newton"]).sum::<f64>();
    assert!(
        newton(&a) < newton(&b),
        "extrapolation should save Newton iterations on block-slide ({} vs {})",
        newton(&a),
        newton(&b)
    );
    for k in ["floor.fx", "floor.fz", "floor.normal", "floor.tangential"] {
        let (x, y) = (a.last().unwrap()[k], b.last().unwrap()[k]);
        assert!((x - y).abs() <= 1e-9 * y.abs().max(1.0), "{k}: {x} vs {y}");
    }
}

//! `run --restart` of mortar pairs: a frictional mortar run cut short and
//! continued from its last converged step (nodal λ, λT and slip origins read
//! back) gives the uninterrupted run's steps, against a rigid plane and
//! against a deformable block, on 1, 2 and 3 ranks, and with a penalty the
//! first run raised; without λT, the slip origins or the raised penalty it
//! would not.
mod common;
use common::*;
use contactlink::output::{layout, list_steps, read_nodal};
use std::path::Path;

fn run_ok(ranks: usize, args: &[&str]) {
    let o = mpirun(ranks, args);
    assert!(
        o.status.success(),
        "{args:?} on {ranks} ranks failed:\n{}",
        text(&o)
    );
}

fn field(path: &Path, step: usize, name: &str) -> Vec<f64> {
    read_nodal(path, step, name).expect(name).0
}

/// The pair's fields compared between two files, at `step`.
fn fields(pair: &str) -> Vec<String> {
    let pair_field = |f: &str| layout::pair_dataset(pair, f);
    vec![
        layout::DISPLACEMENT.to_string(),
        layout::REACTION.to_string(),
        pair_field(layout::PAIR_FORCE),
        pair_field(layout::PAIR_NODE_LAMBDA),
        pair_field(layout::PAIR_NODE_LAMBDA_T),
    ]
}

/// The largest relative difference of the pair's fields over `steps`.
fn largest_difference(a: &Path, b: &Path, steps: &[usize], pair: &str) -> f64 {
    let mut worst = 0.0f64;
    for &step in steps {
        for name in fields(pair) {
            worst = worst.max(relative_difference(
                &field(a, step, &name),
                &field(b, step, &name),
            ));
        }
    }
    worst
}

/// Runs `scene` whole on one rank, cuts the file after `keep` steps,
/// continues from it on `ranks` ranks and compares every continued step:
/// the displacement, reactions, contact force and the pair's nodal λ and
/// λT. Then continues once more from the cut with the pair's `history`
/// dataset zeroed, which must move the next step by more than 1e-7: the
/// continued run does read it back.
fn continued_run_matches(
    label: &str,
    scene: &str,
    extra: &[&str],
    keep: usize,
    ranks: usize,
    pair: &str,
    history: &str,
) {
    let tag = Path::new(scene)
        .file_stem()
        .map_or(scene.to_string(), |s| s.to_string_lossy().into_owned());
    // One directory per calling test (`label`): the tests run at once, and
    // two of them continuing `block-slide` on 1 rank shared a directory,
    // each clearing it under the other.
    let dir = scratch(&format!("restart-mortar-{label}-{tag}-{ranks}"));
    let full = dir.join("full.h5");
    let mut args = vec!["run", scene, "-q", "-o", full.to_str().unwrap()];
    args.extend_from_slice(extra);
    run_ok(1, &args);
    let last = *list_steps(&full).unwrap().last().unwrap();
    assert!(
        last > keep,
        "{scene}: {last} steps, cannot cut after {keep}"
    );

    let cut = cut_after(&full, keep, "cut.h5");
    let continued = |from: &Path, name: &str| {
        let out = dir.join(name);
        let mut args = vec!["run", scene, "-q", "-o", out.to_str().unwrap()];
        args.extend_from_slice(extra);
        args.extend_from_slice(&["--restart", from.to_str().unwrap()]);
        run_ok(ranks, &args);
        out
    };
    let cont = continued(&cut, "continued.h5");
    let steps = list_steps(&cont).unwrap();
    assert_eq!(steps.first(), Some(&(keep + 1)), "{scene}");
    assert_eq!(steps.last(), Some(&last), "{scene}");
    let worst = largest_difference(&full, &cont, &steps, pair);
    assert!(
        worst < 1e-10,
        "{scene}: continued steps differ by {worst:e}"
    );

    let blind = cut_after(&full, keep, "blind.h5");
    {
        let file = hdf5::File::open_rw(&blind).expect("open copy");
        let name = format!(
            "{}/{}/{}",
            layout::STEPS_NAME,
            layout::step_group_name(keep),
            layout::pair_dataset(pair, history)
        );
        let ds = file.dataset(&name).expect(&name);
        ds.write_raw(&vec![0.0f64; ds.size()]).expect("zero it");
    }
    let forgot = continued(&blind, "forgot.h5");
    let off = largest_difference(&full, &forgot, &steps[..1], pair);
    println!(
        "{scene}: continued after step {keep} of {last} on {ranks} rank(s): every continued step within {worst:.1e}; with {history} zeroed step {} is {off:.1e} off",
        keep + 1
    );
    assert!(
        off > 1e-7,
        "{scene}: zeroing {history} changes nothing ({off:e})"
    );
}

#[test]
fn frictional_mortar_on_a_rigid_plane_continues_exactly() {
    // block-slide as a mortar pair, cut while part of the base still
    // sticks (step 12: 20 of 25 nodes slide).
    let extra = ["--set", "contact.formulation=mortar"];
    for (ranks, history) in [
        (1, layout::PAIR_NODE_LAMBDA_T),
        (2, layout::PAIR_NODE_SLIP_ORIGIN),
    ] {
        continued_run_matches("rigid", "block-slide", &extra, 11, ranks, "floor", history);
    }
}

#[test]
fn frictional_mortar_between_blocks_continues_exactly() {
    // The shipped block slide on a deformable block (a 5×5 block pressed
    // with N = 10 onto a held 4×4 slave and pulled; μ = 0.3), as a mortar
    // pair in 16 steps. Cut just before the interface starts to slide
    // (step 7: 10 of 25 nodes slide).
    let scene = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/scripts/scenes/block-slide-stacked.toml"
    );
    let extra = [
        "--set",
        "contact.formulation=mortar",
        "--set",
        "steps.count=16",
    ];
    for (ranks, history) in [
        (1, layout::PAIR_NODE_SLIP_ORIGIN),
        (2, layout::PAIR_NODE_LAMBDA_T),
        (3, layout::PAIR_NODE_SLIP_ORIGIN),
    ] {
        continued_run_matches("blocks", scene, &extra, 6, ranks, "interface", history);
    }
}

#[test]
fn a_raised_mortar_penalty_carries_over() {
    // Two Uzawa iterations allowed: the pulled block's steps raise the
    // penalty ×10, and the continued run must go on with the raised one.
    let extra = [
        "--set",
        "contact.formulation=mortar",
        "--set",
        "contact.max_uzawa=2",
    ];
    continued_run_matches(
        "raised",
        "block-slide",
        &extra,
        11,
        1,
        "floor",
        layout::PAIR_PENALTY,
    );
}

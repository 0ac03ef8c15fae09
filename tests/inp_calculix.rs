//! A mesh from a published CalculiX contact example, read from its `.inp`
//! and run with the example's physics written as a scene, against
//! CalculiX's own answer on the deck (tests/data/inp/calculix/README.md).
//! The deck is CalculiX's own, as Debian's `calculix-ccx-test` installs it
//! (`make deps` does); CalculiX itself is not needed: its figures are held
//! here.
mod common;
use common::*;
use contactlink::output::{layout, list_steps, read_nodal};
use std::path::Path;

/// CalculiX's contact pressure at the slave nodes of its test example
/// friction1 (node id, CSTRESS press), as the example's friction1.dat.ref
/// gives it (CalculiX 2.11; 2.20 writes the same digits).
const CCX_PRESSURE: [(usize, f64); 25] = [
    (126, 1.333483E+02),
    (127, 1.199761E+02),
    (130, 1.199778E+02),
    (131, 1.023619E+02),
    (146, 1.013096E+02),
    (147, 7.992117E+01),
    (156, 1.199780E+02),
    (157, 1.023626E+02),
    (166, 1.333565E+02),
    (167, 1.199780E+02),
    (176, 1.013077E+02),
    (178, 7.991957E+01),
    (186, 5.445570E+01),
    (191, 7.992117E+01),
    (196, 1.013096E+02),
    (201, 1.199740E+02),
    (203, 1.023594E+02),
    (211, 7.991957E+01),
    (216, 1.023619E+02),
    (221, 1.199778E+02),
    (226, 1.333510E+02),
    (228, 1.199740E+02),
    (236, 1.013077E+02),
    (241, 1.199761E+02),
    (246, 1.333483E+02),
];

/// CalculiX 2.20's vertical displacement of the loaded top (node id, U3) on
/// the same deck with `*NODE PRINT, NSET=Nload` added
/// (tests/data/inp/calculix/README.md).
const CCX_TOP_UZ: [(usize, f64); 25] = [
    (142, -3.945430E-04),
    (143, -3.774410E-04),
    (144, -4.123253E-04),
    (145, -3.945471E-04),
    (154, -4.153653E-04),
    (155, -3.975711E-04),
    (164, -4.123285E-04),
    (165, -3.945501E-04),
    (174, -3.945501E-04),
    (175, -3.774478E-04),
    (184, -3.975636E-04),
    (185, -4.153617E-04),
    (190, -4.182075E-04),
    (195, -4.153653E-04),
    (200, -3.975711E-04),
    (209, -3.945391E-04),
    (210, -4.123215E-04),
    (215, -4.153617E-04),
    (220, -4.123253E-04),
    (225, -3.945471E-04),
    (234, -3.774329E-04),
    (235, -3.945391E-04),
    (240, -3.975636E-04),
    (245, -3.945430E-04),
    (250, -3.774410E-04),
];

/// Where Debian's `calculix-ccx-test` puts the example (gzipped).
const DECK: &str = "/usr/share/doc/calculix-ccx-test/examples/test/friction1.inp.gz";

/// The scene, its wrapper `.inp` and the example's deck, unpacked, in `dir`.
fn friction1_in(dir: &Path) -> std::path::PathBuf {
    let data = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/data/inp/calculix");
    let deck = std::process::Command::new("gzip")
        .args(["-dc", DECK])
        .output()
        .expect("gzip");
    assert!(
        deck.status.success(),
        "cannot read {DECK}: install calculix-ccx-test (make deps)"
    );
    std::fs::write(dir.join("friction1-deck.inp"), deck.stdout).unwrap();
    for f in ["friction1.inp", "friction1.toml"] {
        std::fs::copy(data.join(f), dir.join(f)).unwrap();
    }
    dir.join("friction1.toml")
}

#[test]
fn calculix_example_friction1_runs_to_calculix_s_answer() {
    let dir = scratch("inp-calculix-friction1");
    let scene = friction1_in(&dir);
    let (model, _) = contactlink::pipeline::load_model(scene.to_str().unwrap(), &[]).unwrap();
    // Node ids 1..250 in file order, every one on a cell: id n is node n − 1.
    assert_eq!(model.mesh.num_nodes(), 250);
    assert_eq!(model.mesh.bodies, ["block", "cube"]);
    let out = dir.join("friction1.h5");
    let o = run(&[
        "run",
        scene.to_str().unwrap(),
        "-q",
        "-o",
        out.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", text(&o));
    let last = *list_steps(&out).unwrap().last().unwrap();
    let (u, _, _) = read_nodal(&out, last, layout::DISPLACEMENT).unwrap();
    let (p, _, _) = read_nodal(&out, last, layout::CONTACT_PRESSURE).unwrap();
    let p_max = CCX_PRESSURE.iter().fold(0.0f64, |m, (_, v)| m.max(*v));
    let dp = CCX_PRESSURE
        .iter()
        .map(|&(n, v)| (p[n - 1] - v).abs())
        .fold(0.0, f64::max)
        / p_max;
    let uz_max = CCX_TOP_UZ.iter().fold(0.0f64, |m, (_, v)| m.max(v.abs()));
    let du = CCX_TOP_UZ
        .iter()
        .map(|&(n, v)| (u[3 * (n - 1) + 2] - v).abs())
        .fold(0.0, f64::max)
        / uz_max;
    println!("friction1 against CalculiX: contact pressure within {dp:.2e} of its largest, top displacement within {du:.2e}");
    assert!(dp < 5e-3, "contact pressure off CalculiX's by {dp:.3e}");
    assert!(du < 5e-3, "top displacement off CalculiX's by {du:.3e}");
}

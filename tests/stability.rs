//! Numerical stability when pushed: the contact patch test under
//! penalties from 1e-3 to 1e6 times the default, an initial penetration of
//! half an element, slave points exactly on master nodes, edges and corners,
//! and nearly incompressible bodies. Each converges to the same answer
//! within the Uzawa tolerance, with finite output.
mod common;
use common::*;
use contactlink::output::{layout, list_steps, read_nodal};
use std::path::Path;

/// The patch test: E = 1000, a stack of height 1, the top pushed 0.01: the
/// exact normal force is E·(0.01 + overlap)/1 over the unit area.
const E: f64 = 1000.0;
const PUSH: f64 = 0.01;
/// Shortest edge of the slave (upper) facets, 3×3 over the unit square.
const H_SLAVE: f64 = 1.0 / 3.0;
const PENETRATION_TOL: f64 = 1e-3;

/// Runs the patch test with `extra` overrides (with the links, whose
/// figures docs/scaling.md tabulates, unless `extra` names a formulation);
/// returns the last step's
/// normal contact force and the iteration counts (Newton, Uzawa).
fn patch(name: &str, extra: &[&str]) -> (f64, usize, usize) {
    let dir = scratch(&format!("stability-{name}"));
    let out = dir.join("p.h5");
    let mut args = vec!["run", "patch-test", "-q", "-o", out.to_str().unwrap()];
    args.extend(links_unless_set(extra));
    let o = mpirun(1, &args);
    let t = text(&o);
    assert!(o.status.success(), "{name}: did not converge:\n{t}");
    assert_finite(&out);
    let csv = std::fs::read_to_string(out.with_extension("csv")).unwrap();
    let mut lines = csv.lines();
    let header: Vec<&str> = lines.next().unwrap().split(',').collect();
    let last: Vec<&str> = lines.last().unwrap().split(',').collect();
    let col = |k: &str| -> f64 {
        let i = header.iter().position(|h| *h == k).unwrap();
        last[i].parse().unwrap()
    };
    (
        col("interface.normal"),
        col("newton") as usize,
        col("uzawa") as usize,
    )
}

/// Every nodal field of the last step is finite.
fn assert_finite(out: &Path) {
    let last = *list_steps(out).unwrap().last().unwrap();
    for field in [
        layout::DISPLACEMENT,
        layout::REACTION,
        layout::CONTACT_PRESSURE,
    ] {
        let (v, _, _) = read_nodal(out, last, field).unwrap();
        assert!(
            v.iter().all(|x| x.is_finite()),
            "{field} has a non-finite value"
        );
    }
}

/// A penetration within the Uzawa tolerance (tol·h) relieves up to E·tol·h
/// of the force: that is how close "converged" is to exact.
fn assert_force(name: &str, n: f64, overlap: f64) {
    let exact = E * (PUSH + overlap);
    let bound = E * PENETRATION_TOL * H_SLAVE + 1e-9 * exact;
    assert!(
        (n - exact).abs() <= bound,
        "{name}: normal force {n} vs {exact} (bound {bound:e})"
    );
}

/// The patch test at each of `factors` times the default per-facet
/// penalty (10·E/h with h = 1/3, the shortest edge), with `extra`
/// overrides; each run's force within the Uzawa tolerance of exact.
fn penalty_sweep(label: &str, factors: &[f64], extra: &[&str]) {
    let base = 10.0 * E / H_SLAVE;
    for &k in factors {
        let penalty = format!("contact.penalty={}", k * base);
        let mut args = vec!["--set", &penalty, "--set", "contact.max_uzawa=300"];
        args.extend_from_slice(extra);
        let (n, newton, uzawa) = patch(&format!("{label}penalty-{k:e}"), &args);
        println!("{label}penalty ×{k:e}: normal force {n:.9}, Newton {newton}, Uzawa {uzawa}");
        assert_force(&format!("{label}penalty ×{k:e}"), n, 0.0);
    }
}

#[test]
fn penalty_over_nine_decades_gives_the_same_pressure() {
    penalty_sweep("", &[1e-3, 1e-2, 1e-1, 1.0, 1e1, 1e2, 1e4, 1e6], &[]);
}

/// The same with a mortar pair, whose non-symmetric tangent takes the
/// Schur path's LU branch: at 10⁶ times the default penalty its solve once
/// carried x_C's roundoff times |D|/σ into the interior, and the force came
/// out 9.589.
#[test]
fn mortar_penalty_over_nine_decades_gives_the_same_pressure() {
    penalty_sweep(
        "mortar, ",
        &[1e-3, 1.0, 1e2, 1e6],
        &["--set", "contact.formulation=mortar"],
    );
}

#[test]
fn initial_penetration_of_half_an_element_is_pushed_out() {
    // Upper elements are 0.25 high: start 0.125 inside the lower block.
    let (n, newton, uzawa) = patch("overlap", &["--set", "mesh.gap=-0.125"]);
    println!("overlap 0.125: normal force {n:.6}, Newton {newton}, Uzawa {uzawa}");
    assert_force("overlap", n, 0.125);
}

#[test]
fn slave_points_on_master_nodes_edges_and_corners() {
    // Matching meshes with the links at the slave nodes: every slave point
    // sits exactly on a master node (interior, edge or corner of the set).
    for quadrature in ["nodal", "gauss"] {
        let (n, newton, uzawa) = patch(
            &format!("matching-{quadrature}"),
            &[
                "--set",
                "mesh.upper_divisions=[4,4,2]",
                "--set",
                &format!("contact.quadrature={quadrature}"),
            ],
        );
        println!("matching meshes, {quadrature} points: normal force {n:.9}, Newton {newton}, Uzawa {uzawa}");
        assert_force(quadrature, n, 0.0);
    }
}

#[test]
fn nearly_incompressible_bodies_converge() {
    let (n, newton, uzawa) = patch(
        "incompressible",
        &[
            "--set",
            "body.0.poisson=0.49",
            "--set",
            "body.1.poisson=0.49",
        ],
    );
    println!("ν = 0.49: normal force {n:.9}, Newton {newton}, Uzawa {uzawa}");
    // Uniaxial stress (free sides): the force does not depend on ν.
    assert_force("ν = 0.49", n, 0.0);
}

#[test]
fn distorted_meshes_keep_the_patch_test() {
    // Interior nodes moved by up to 30 % of h, boundary nodes within their
    // faces (the contact surfaces stay flat, so the answer stays uniform).
    for seed in ["1", "7"] {
        let (n, newton, uzawa) = patch(
            &format!("distorted-{seed}"),
            &[
                "--set",
                "distort.fraction=0.3",
                "--set",
                &format!("distort.seed={seed}"),
            ],
        );
        println!(
            "distorted 30 % (seed {seed}): normal force {n:.9}, Newton {newton}, Uzawa {uzawa}"
        );
        assert_force("distorted", n, 0.0);
    }
}

/// The default formulation, the mortar, through the same stresses: half an
/// element of initial overlap, matching meshes (every slave node on a
/// master node), ν = 0.49 and 30 % distorted meshes; each run's force
/// within the Uzawa tolerance of exact.
#[test]
fn the_mortar_under_the_same_stresses() {
    const MORTAR: [&str; 2] = ["--set", "contact.formulation=mortar"];
    let cases: [(&str, &[&str], f64); 5] = [
        ("overlap", &["--set", "mesh.gap=-0.125"], 0.125),
        ("matching", &["--set", "mesh.upper_divisions=[4,4,2]"], 0.0),
        (
            "incompressible",
            &[
                "--set",
                "body.0.poisson=0.49",
                "--set",
                "body.1.poisson=0.49",
            ],
            0.0,
        ),
        (
            "distorted-1",
            &["--set", "distort.fraction=0.3", "--set", "distort.seed=1"],
            0.0,
        ),
        (
            "distorted-7",
            &["--set", "distort.fraction=0.3", "--set", "distort.seed=7"],
            0.0,
        ),
    ];
    for (name, extra, overlap) in cases {
        let args = [extra, &MORTAR[..]].concat();
        let (n, newton, uzawa) = patch(&format!("mortar-{name}"), &args);
        println!("mortar, {name}: normal force {n:.9}, Newton {newton}, Uzawa {uzawa}");
        assert_force(&format!("mortar, {name}"), n, overlap);
    }
}

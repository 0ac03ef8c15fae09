//! Mortar contact end to end: the contact patch test on non-matching
//! stacked blocks (either side as slave, stiffness ratio 1 and 100, a
//! distorted mesh, hex and tet cells) under a fixed-direction traction,
//! with the links measured on the same cases; 1, 2 and 3 ranks agree; bad
//! `formulation` input is one scene error naming the line; a contact zone
//! that grows past the step's search margin is searched again; Hertz
//! errors of both formulations in both readings of the nodal pressures.
mod common;
use common::*;
use contactlink::output::{layout, list_steps, read_dataset, read_nodal};
use std::path::Path;

/// One patch-test case: the stacked blocks with `upper` over `lower`
/// divisions in x and y, Young's moduli, cell type, distortion, and which
/// side is the slave.
struct Case {
    name: &'static str,
    upper: usize,
    lower: usize,
    youngs_upper: f64,
    youngs_lower: f64,
    tets: bool,
    distort: Option<f64>,
    upper_is_slave: bool,
}

const CASES: &[Case] = &[
    Case {
        name: "hex 4x4 over 5x5, coarse slave",
        upper: 4,
        lower: 5,
        youngs_upper: 1000.0,
        youngs_lower: 1000.0,
        tets: false,
        distort: None,
        upper_is_slave: true,
    },
    Case {
        name: "hex 4x4 over 5x5, fine slave",
        upper: 4,
        lower: 5,
        youngs_upper: 1000.0,
        youngs_lower: 1000.0,
        tets: false,
        distort: None,
        upper_is_slave: false,
    },
    Case {
        name: "hex 4x4 over 7x7, E 1000 on 10, coarse slave",
        upper: 4,
        lower: 7,
        youngs_upper: 1000.0,
        youngs_lower: 10.0,
        tets: false,
        distort: None,
        upper_is_slave: true,
    },
    Case {
        name: "hex 4x4 over 7x7, E 1000 on 10, fine slave",
        upper: 4,
        lower: 7,
        youngs_upper: 1000.0,
        youngs_lower: 10.0,
        tets: false,
        distort: None,
        upper_is_slave: false,
    },
    Case {
        name: "hex 4x4 over 5x5, 30 % distorted, coarse slave",
        upper: 4,
        lower: 5,
        youngs_upper: 1000.0,
        youngs_lower: 1000.0,
        tets: false,
        distort: Some(0.3),
        upper_is_slave: true,
    },
    Case {
        name: "tet 3x3 over 4x4, coarse slave",
        upper: 3,
        lower: 4,
        youngs_upper: 1000.0,
        youngs_lower: 1000.0,
        tets: true,
        distort: None,
        upper_is_slave: true,
    },
    Case {
        name: "tet 3x3 over 4x4, fine slave",
        upper: 3,
        lower: 4,
        youngs_upper: 1000.0,
        youngs_lower: 1000.0,
        tets: true,
        distort: None,
        upper_is_slave: false,
    },
];

impl Case {
    /// Poisson's ratio of a block of modulus `e`: 0.3 for the stiffer one,
    /// scaled with E for the softer, so both blocks expand sideways alike and
    /// the uniform stress state is the exact solution (with equal ratios the
    /// softer block overhangs the stiffer one and the pressure is not
    /// uniform near the edges, whatever the discretisation).
    fn poisson(&self, e: f64) -> f64 {
        0.3 * e / self.youngs_upper.max(self.youngs_lower)
    }

    /// A 1 % strain of the softer block.
    fn traction(&self) -> f64 {
        0.01 * self.youngs_upper.min(self.youngs_lower)
    }

    fn slave(&self) -> (&'static str, &'static str) {
        if self.upper_is_slave {
            ("upper.bottom", "lower.top")
        } else {
            ("lower.top", "upper.bottom")
        }
    }

    /// The scene; the top carries a downward traction of fixed direction,
    /// symmetry planes hold both blocks, the lower one sits on z = −h.
    fn scene(&self, formulation: &str) -> String {
        let (slave, master) = self.slave();
        let cell_type = if self.tets { "tet4" } else { "hex8" };
        let distort = self.distort.map_or(String::new(), |f| {
            format!("[distort]\nfraction = {f}\nseed = 3\n")
        });
        // A distorted mesh expands sideways unevenly at the blocks' edges, so
        // their outer edges would part by rounding-size amounts and the
        // overlap's boundary would jump from one Newton iterate to the next:
        // confine the blocks laterally (uniaxial strain, still a uniform
        // stress state) so the edges stay where they are.
        let confined = if self.distort.is_some() {
            ["lower.xmax", "upper.xmax", "lower.ymax", "upper.ymax"]
                .iter()
                .map(|set| {
                    let c = if set.ends_with("xmax") { "x" } else { "y" };
                    format!("[[dirichlet]]\nset = \"{set}\"\ncomponents = [\"{c}\"]\n\n")
                })
                .collect::<String>()
        } else {
            String::new()
        };
        format!(
            r#"title = "mortar patch test"
[mesh]
generator = "stacked-blocks"
length = 1.0
height = 0.5
gap = 0.0
lower_divisions = [{l}, {l}, 2]
upper_divisions = [{u}, {u}, 2]
cell_type = "{cell_type}"
{distort}
[[body]]
name = "lower"
material = "linear-elastic"
youngs = {el}
poisson = {nl}

[[body]]
name = "upper"
material = "linear-elastic"
youngs = {eu}
poisson = {nu}

[[dirichlet]]
set = "lower.bottom"
components = ["z"]

[[dirichlet]]
set = "lower.xmin"
components = ["x"]

[[dirichlet]]
set = "lower.ymin"
components = ["y"]

[[dirichlet]]
set = "upper.xmin"
components = ["x"]

[[dirichlet]]
set = "upper.ymin"
components = ["y"]

{confined}[[traction]]
set = "upper.top"
vector = [0.0, 0.0, -{t}]

[[contact]]
name = "interface"
slave = "{slave}"
master = "{master}"
formulation = "{formulation}"
penetration_tol = 1e-9
multiplier_tol = 1e-9
max_uzawa = 60
"#,
            l = self.lower,
            u = self.upper,
            el = self.youngs_lower,
            eu = self.youngs_upper,
            t = self.traction(),
            nl = self.poisson(self.youngs_lower),
            nu = self.poisson(self.youngs_upper),
        )
    }
}

fn last_step(path: &Path) -> usize {
    *list_steps(path).expect("steps").last().expect("a step")
}

/// Nodal contact pressure at the slave surface's nodes.
fn slave_pressures(path: &Path, node_set: &str) -> Vec<f64> {
    let (nodes, _) = read_dataset::<i64>(path, &layout::node_set(node_set)).expect("node set");
    let (p, _, _) = read_nodal(path, last_step(path), layout::CONTACT_PRESSURE).expect("pressure");
    nodes.iter().map(|&n| p[n as usize]).collect()
}

/// max |p_j − p̄| / p̄ over the slave nodes, p̄ their mean.
fn deviation(p: &[f64]) -> (f64, f64) {
    let mean = p.iter().sum::<f64>() / p.len() as f64;
    let dev = p.iter().fold(0.0f64, |m, v| m.max((v - mean).abs())) / mean;
    (mean, dev)
}

/// Where `try_case` writes a run's results (its scene beside them).
fn output_path(
    dir: &Path,
    case: &Case,
    formulation: &str,
    ranks: usize,
    extra: &[&str],
) -> std::path::PathBuf {
    dir.join(format!(
        "{}-{formulation}-{ranks}{}.h5",
        case.name.replace([' ', ','], "_"),
        extra.concat().replace(['.', '='], "_")
    ))
}

/// The slave's nodal pressures, the pair's force and the run's output
/// text, or the error text. `extra`: the run's further arguments.
fn try_case(
    dir: &Path,
    case: &Case,
    formulation: &str,
    ranks: usize,
    extra: &[&str],
) -> Result<(Vec<f64>, Vec<f64>, contactlink::output::RunRecord), String> {
    let out = output_path(dir, case, formulation, ranks, extra);
    let name = out.with_extension("toml");
    let name = name.file_name().expect("a file name").to_string_lossy();
    let scene = write(dir, &name, &case.scene(formulation));
    let o = mpirun(
        ranks,
        &[
            &["run", scene.to_str().unwrap(), "-o", out.to_str().unwrap()],
            extra,
        ]
        .concat(),
    );
    if !o.status.success() {
        return Err(text(&o));
    }
    let step = last_step(&out);
    let force = read_dataset::<f64>(
        &out,
        &layout::step_dataset(step, &layout::pair_dataset("interface", layout::PAIR_FORCE)),
    )
    .expect("force")
    .0;
    let record = contactlink::output::read_run_record(&out)
        .expect("read /run")
        .expect("the run's /run");
    Ok((slave_pressures(&out, case.slave().0), force, record))
}

/// The mortar pair's nodal datasets at the slave nodes: λ, g̃ and the traction.
fn mortar_fields(path: &Path, node_set: &str) -> Vec<(f64, f64, [f64; 3])> {
    let step = last_step(path);
    let (nodes, _) = read_dataset::<i64>(path, &layout::node_set(node_set)).expect("node set");
    let read = |name: &str| {
        read_dataset::<f64>(
            path,
            &layout::step_dataset(step, &layout::pair_dataset("interface", name)),
        )
        .expect(name)
        .0
    };
    let (lambda, gap, traction) = (
        read(layout::PAIR_NODE_LAMBDA),
        read(layout::PAIR_NODE_WEIGHTED_GAP),
        read(layout::PAIR_NODE_TRACTION),
    );
    nodes
        .iter()
        .map(|&n| {
            let n = n as usize;
            let t = [traction[3 * n], traction[3 * n + 1], traction[3 * n + 2]];
            (lambda[n], gap[n], t)
        })
        .collect()
}

fn run_case(dir: &Path, case: &Case, formulation: &str, ranks: usize) -> (Vec<f64>, Vec<f64>) {
    let (p, f, _) = try_case(dir, case, formulation, ranks, &["-q"])
        .unwrap_or_else(|t| panic!("{}: {t}", case.name));
    (p, f)
}

#[test]
fn mortar_passes_the_patch_test_where_the_links_do_not() {
    let dir = scratch("mortar-patch");
    let mut worst = 0.0f64;
    for case in CASES {
        let (p, force) = run_case(&dir, case, "mortar", 1);
        let (mean, dev) = deviation(&p);
        // The links on the same case, for comparison (their Uzawa loop may
        // not reach 1e-9 at all: then the figure is their failure).
        let links = match try_case(&dir, case, "links", 1, &["-q"]) {
            Ok((pl, _, _)) => format!("{:.2e}", deviation(&pl).1),
            Err(t) => format!("failed ({})", t.lines().last().unwrap_or("")),
        };
        println!(
            "{:<48} mortar: mean {mean:.9}, max deviation {dev:.2e}; links: {links}",
            case.name
        );
        // The traction balances the contact force (Newton tolerance).
        assert!(
            (force[2].abs() - case.traction()).abs() < 1e-6 * case.traction(),
            "{}: contact force {force:?}",
            case.name
        );
        assert!(p.iter().all(|&v| v > 0.0), "{}: open slave node", case.name);
        worst = worst.max(dev);
    }
    assert!(worst < 1e-6, "mortar patch test deviates {worst:.2e}");
}

#[test]
fn mortar_writes_nodal_multipliers_weighted_gaps_and_tractions() {
    let dir = scratch("mortar-output");
    let case = &CASES[0];
    let (p, _) = run_case(&dir, case, "mortar", 2);
    let fields = mortar_fields(
        &output_path(&dir, case, "mortar", 2, &["-q"]),
        case.slave().0,
    );
    assert_eq!(fields.len(), p.len());
    for ((lambda, gap, t), p) in fields.iter().zip(&p) {
        // λ is the nodal contact pressure; the upper block's bottom is
        // pushed up (+z); the weighted gap is closed to the Uzawa tolerance
        // (1e-9 h of a node's area, h = 0.25, area ≤ 1/16).
        assert!((lambda - p).abs() <= 1e-12 * p, "{lambda} vs {p}");
        assert!((t[2] - lambda).abs() <= 1e-9 * lambda && t[0].abs() + t[1].abs() < 1e-9);
        assert!(
            gap.abs() <= 1e-9 * 0.25 / 16.0 * 1.01,
            "weighted gap {gap:e}"
        );
    }
}

#[test]
fn mortar_answers_agree_on_one_two_and_three_ranks() {
    let dir = scratch("mortar-ranks");
    for case in [&CASES[0], &CASES[5]] {
        let (p1, f1) = run_case(&dir, case, "mortar", 1);
        for ranks in [2, 3] {
            let (p, f) = run_case(&dir, case, "mortar", ranks);
            let dp = relative_difference(&p1, &p);
            let df = relative_difference(&f1, &f);
            println!(
                "{}: {ranks} ranks vs 1: pressure {dp:.2e}, force {df:.2e}",
                case.name
            );
            assert!(
                dp < 1e-10 && df < 1e-10,
                "{}: {ranks} ranks differ",
                case.name
            );
        }
    }
}

/// On 2 ranks a mortar pair takes the several-rank contact Schur path (K's
/// factor with a low-rank update, `linsolve::low_rank`) and answers as the
/// full factorisation and the 1-rank run do, to 1e-10. In these cases the
/// upper block is held by the contact alone, so K is singular: the path's
/// shifted factor is what makes it work (its first solve diverged before).
#[test]
fn mortar_on_two_ranks_takes_the_low_rank_path_with_the_same_answer() {
    let dir = scratch("mortar-low-rank");
    for case in [&CASES[0], &CASES[5]] {
        let run = |ranks, extra: &[&str]| {
            try_case(&dir, case, "mortar", ranks, extra)
                .unwrap_or_else(|t| panic!("{}: {t}", case.name))
        };
        let (p1, f1, _) = run(1, &["-q"]);
        let (p, f, on) = run(2, &["-q"]);
        let (pf, ff, off) = run(2, &["-q", "--set", "solver.contact_schur=false"]);
        let low_rank = |r: &contactlink::output::RunRecord| r.schur.is_some_and(|s| s.low_rank);
        assert!(
            low_rank(&on) && !low_rank(&off),
            "{}: the low-rank path was not taken, or not only when on:\n{on:?}\n{off:?}",
            case.name
        );
        for (what, q, fq) in [("full factorisation", &pf, &ff), ("1 rank", &p1, &f1)] {
            let dp = relative_difference(q, &p);
            let df = relative_difference(fq, &f);
            println!(
                "{}: low-rank vs {what}: pressure {dp:.2e}, force {df:.2e}",
                case.name
            );
            assert!(
                dp < 1e-10 && df < 1e-10,
                "{}: differs from the {what}",
                case.name
            );
        }
    }
}

#[test]
fn bad_formulation_is_a_scene_error_naming_the_line() {
    let dir = scratch("mortar-bad");
    let case = &CASES[0];
    for (formulation, expect) in [
        (
            "penalty",
            "formulation 'penalty' is not \"links\" or \"mortar\"",
        ),
        (
            "mortar\"\nquadrature = \"nodal\"\n#\"",
            "quadrature places the links' points",
        ),
    ] {
        let scene = write(dir.as_path(), "bad.toml", &case.scene(formulation));
        let o = run(&["run", scene.to_str().unwrap(), "-q", "-o", "/dev/null"]);
        let t = text(&o);
        assert!(!o.status.success());
        assert!(t.contains(expect), "{t}");
        // One line naming the file and the line of the key.
        let line = t
            .lines()
            .find(|l| l.contains(expect))
            .expect("the error line");
        assert!(line.contains("bad.toml:"), "{line}");
    }
}

/// A pair without `formulation` is a mortar pair (nodal multipliers in the
/// file); one that sets `quadrature`, which places links, is a links pair.
#[test]
fn the_default_is_the_mortar_unless_the_pair_places_links() {
    let dir = scratch("mortar-default");
    for (extra, mortar) in [
        (&[][..], true),
        (&["--set", "contact.quadrature=nodal"][..], false),
        (&["--set", "contact.formulation=links"][..], false),
    ] {
        let out = dir.join("p.h5");
        let mut args = vec!["run", "patch-test", "-q", "-o", out.to_str().unwrap()];
        args.extend_from_slice(extra);
        let o = run(&args);
        assert!(o.status.success(), "{extra:?}: {}", text(&o));
        let step = *list_steps(&out).unwrap().last().unwrap();
        let nodal = layout::pair_dataset("interface", layout::PAIR_NODE_LAMBDA);
        assert_eq!(
            read_nodal(&out, step, &nodal).is_ok(),
            mortar,
            "{extra:?}: node_lambda present should be {mortar}"
        );
    }
}

/// The hertz-cylinder (h = 0.2) in one load step with the mortar pair's
/// search margin cut to 0.01: the step's search, at the undeformed state,
/// then finds master facets for the slave facets within 0.01 of the block
/// only, a fraction of the final contact zone. The run must search again
/// from the solution and end with the answer of the default margin, on 2
/// ranks against 1. (Before the search followed the solution, the facets
/// outside that band went through the block unconstrained: total force
/// 47.25 against 52.97, and no Hertz profile.)
#[test]
fn mortar_search_follows_a_contact_zone_that_grows_past_the_steps_margin() {
    let dir = scratch("mortar-growing-zone");
    let base = [
        "--set",
        "mesh.fine_size=0.2",
        "--set",
        "contact.formulation=mortar",
        "--set",
        "steps.count=1",
    ];
    let run = |ranks: usize, name: &str, extra: &[&str]| {
        let out = dir.join(name);
        let mut args = vec!["run", "hertz-cylinder", "-o", out.to_str().unwrap()];
        args.extend_from_slice(&base);
        args.extend_from_slice(extra);
        let o = mpirun(ranks, &args);
        assert!(o.status.success(), "{name} failed:\n{}", text(&o));
        let force = read_dataset::<f64>(
            &out,
            &layout::step_dataset(
                last_step(&out),
                &layout::pair_dataset("hertz", layout::PAIR_FORCE),
            ),
        )
        .expect("pair force")
        .0;
        (force[2], slave_pressures(&out, "cylinder.curved"))
    };
    let (f_default, p_default) = run(1, "default.h5", &[]);
    let (f_narrow, p_narrow) = run(2, "narrow.h5", &["--set", "contact.search_distance=0.01"]);
    let p_max = p_default.iter().fold(0.0f64, |m, p| m.max(*p));
    let p_diff = p_default
        .iter()
        .zip(&p_narrow)
        .fold(0.0f64, |m, (a, b)| m.max((a - b).abs()));
    println!(
        "force {f_default:.9e} (default margin) vs {f_narrow:.9e} (0.01); nodal pressure max difference {:.2e} of max",
        p_diff / p_max
    );
    assert!(
        ((f_narrow - f_default) / f_default).abs() < 1e-6,
        "force {f_narrow} with the narrow margin against {f_default}"
    );
    // The two runs reach the default Uzawa tolerances (1e-3) by different
    // paths: measured 1.6e-6 of the peak apart. (Tolerances of 1e-9 make
    // this scene's single step stall in Newton, with or without the search.)
    assert!(
        p_diff < 1e-5 * p_max,
        "nodal pressures differ by {p_diff:.3e} of {p_max:.3e}"
    );
}

/// The Hertz errors a run wrote on its result file's `/hertz` (the last
/// step's comparison), in percent: (p0, width) read as point values and
/// read as nodal averages.
fn hertz_errors(h5: &Path) -> [(f64, f64); 2] {
    let h = contactlink::output::read_hertz_record(h5)
        .unwrap_or_else(|e| panic!("{}: {e}", h5.display()))
        .unwrap_or_else(|| panic!("{}: no Hertz figures", h5.display()));
    let (ap, aw) = h.averaged_errors.expect("the nodal-average fit");
    [
        (100.0 * h.p0_error, 100.0 * h.width_error),
        (100.0 * ap, 100.0 * aw),
    ]
}

/// Hertz line contact (`hertz-cylinder`, h = 0.2, 1 rank), both
/// formulations converged (Uzawa tolerances 1e-6, so that the difference is
/// the discretisation's): the larger of the p0 and half-width errors of the
/// mortar agrees with the links' to 0.02 points, whether the nodal pressures
/// are read as point values or as what both formulations write, nodal
/// averages ∫N_j p dA / ∫N_j dA. Measured: point reading mortar +0.224 /
/// −0.549 %, links +0.219 / −0.561 %; nodal averages mortar +0.476 /
/// +0.272 %, links +0.471 / +0.260 % (so "no worse" holds in the first
/// reading and misses by 0.005 points in the second).
#[test]
fn mortar_hertz_line_errors_match_the_links() {
    let dir = scratch("mortar-hertz-line-errors");
    let errors = |formulation: &str| {
        let set = format!("contact.formulation={formulation}");
        let out = dir.join(format!("{formulation}.h5"));
        let o = run(&[
            "run",
            "hertz-cylinder",
            "--set",
            "mesh.fine_size=0.2",
            "--set",
            &set,
            "--set",
            "contact.multiplier_tol=1e-6",
            "--set",
            "contact.penetration_tol=1e-6",
            "-q",
            "-o",
            out.to_str().unwrap(),
        ]);
        assert!(o.status.success(), "{formulation} failed:\n{}", text(&o));
        hertz_errors(&out)
    };
    let (links, mortar) = (errors("links"), errors("mortar"));
    println!("point reading, nodal averages (p0 %, width %): links {links:?}, mortar {mortar:?}");
    let worst = |(p0, w): (f64, f64)| p0.abs().max(w.abs());
    for (reading, (l, m)) in ["point", "nodal average"]
        .iter()
        .zip(links.iter().zip(&mortar))
    {
        assert!(
            (worst(*m) - worst(*l)).abs() <= 0.02,
            "{reading} reading: mortar {m:?} against links {l:?}"
        );
        assert!(worst(*m) < 0.7 && worst(*l) < 0.7, "{reading}: {m:?} {l:?}");
    }
}

/// The nodal-average Hertz fit gathers each loaded node's shape-function
/// samples from the ranks that hold its facets: 1 and 3 ranks give the
/// same figures to the digits the run prints (0.001 points).
#[test]
fn nodal_average_hertz_fit_is_the_same_on_one_and_three_ranks() {
    let dir = scratch("mortar-hertz-fit-ranks");
    let errors = |ranks: usize| {
        let out = dir.join(format!("hc-{ranks}.h5"));
        let o = mpirun(
            ranks,
            &[
                "run",
                "hertz-cylinder",
                "--set",
                "mesh.fine_size=0.2",
                "-q",
                "-o",
                out.to_str().unwrap(),
            ],
        );
        assert!(o.status.success(), "{ranks} ranks failed:\n{}", text(&o));
        hertz_errors(&out).map(|(p0, w)| format!("{p0:+.3} / {w:+.3} %"))
    };
    let (one, three) = (errors(1), errors(3));
    println!("point reading, nodal averages: 1 rank {one:?}, 3 ranks {three:?}");
    assert_eq!(one, three);
}

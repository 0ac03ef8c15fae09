//! The contact Schur path on several ranks (`[solver] contact_schur`): K
//! factored once in parallel and each Jacobian solved through the low-rank
//! update on the contact DOFs (`linsolve::low_rank`; by default Newton on the
//! condensed contact system, `linsolve::low_rank::newton`), against the old path
//! (K + Kc factored whole at each rebuild). On one rank the same comparison
//! runs the one-rank Schur path.
use contactlink::pipeline;
use contactlink::runtime::Runtime;
use contactlink::solve::{RunReport, SchurSummary};

fn rel_err(a: &[f64], b: &[f64]) -> f64 {
    let d: f64 = a.iter().zip(b).map(|(x, y)| (x - y).powi(2)).sum();
    let n: f64 = b.iter().map(|y| y * y).sum();
    if n == 0.0 {
        d.sqrt()
    } else {
        (d / n).sqrt()
    }
}

fn newton(r: &RunReport) -> usize {
    r.steps.iter().map(|s| s.newton_iterations).sum()
}

/// The run report of `scene` with `overrides` (`--set` lines).
fn run_scene(rt: &Runtime, scene: &str, overrides: &[&str]) -> Result<RunReport, String> {
    let o: Vec<String> = overrides.iter().map(|s| s.to_string()).collect();
    let model = pipeline::load_model(scene, &o)
        .map_err(|e| e.to_string())?
        .0;
    pipeline::run_model(rt, &model, None, false)
        .map(|s| s.report)
        .map_err(|e| e.to_string())
}

/// Displacement (rank 0 holds it), reactions and contact forces with and
/// without the path, to `tol`; and that the path was the one this rank
/// count takes.
fn same_run(rt: &Runtime, scene: &str, overrides: &[&str], tol: f64) -> Result<(), String> {
    let run = |schur: bool| -> Result<RunReport, String> {
        let path = format!("solver.contact_schur={schur}");
        run_scene(rt, scene, &[overrides, &[path.as_str()]].concat())
    };
    let (on, off) = (run(true)?, run(false)?);
    let what = format!("{scene} {overrides:?}");
    let s = on
        .schur
        .ok_or(format!("{what}: the Schur path was not taken"))?;
    if off.schur.is_some() {
        return Err(format!("{what}: contact_schur = false ignored"));
    }
    if s.low_rank != (rt.size() > 1) {
        return Err(format!(
            "{what}: low-rank path {} on {} ranks",
            s.low_rank,
            rt.size()
        ));
    }
    let bulk = if s.low_rank { 1 } else { 1 + s.growths };
    if s.bulk_factorisations != bulk || s.schur_factorisations != newton(&on) {
        return Err(format!("{what}: {s:?}, {} Newton iterations", newton(&on)));
    }
    if s.low_rank {
        solves_match_the_newton_kind(&what, &s, &on, overrides)?;
    }
    if on.displacement.len() != off.displacement.len() {
        return Err(format!("{what}: displacement lengths differ"));
    }
    let e = rel_err(&on.displacement, &off.displacement);
    if e.is_nan() || e >= tol {
        return Err(format!("{what}: displacement differs by {e:.3e}"));
    }
    let (a, b) = match (on.steps.last(), off.steps.last()) {
        (Some(a), Some(b)) => (a, b),
        _ => return Err(format!("{what}: no steps")),
    };
    if a.reactions.len() != b.reactions.len() || a.contact.len() != b.contact.len() {
        return Err(format!("{what}: reaction or contact lists differ"));
    }
    // Relative to the largest reaction: a set's own may be rounding noise
    // (the patch test's symmetry planes carry none).
    let scale = b
        .reactions
        .iter()
        .flat_map(|(_, r)| r.iter())
        .map(|v| v.abs())
        .fold(1e-30, f64::max);
    for ((name, ra), (_, rb)) in a.reactions.iter().zip(&b.reactions) {
        if ra
            .iter()
            .zip(rb)
            .any(|(x, y)| (x - y).abs().is_nan() || (x - y).abs() > tol * scale)
        {
            return Err(format!("{what}: reaction on {name}: {ra:?} vs {rb:?}"));
        }
    }
    for (ca, cb) in a.contact.iter().zip(&b.contact) {
        let scale = cb.normal_force.abs();
        let dn = (ca.normal_force - cb.normal_force).abs();
        let dt = (ca.tangential_force - cb.tangential_force).abs();
        if !(dn <= tol * scale && dt <= tol * scale) || ca.active_points != cb.active_points {
            return Err(format!(
                "{what}: contact forces {} / {} vs {} / {}, active {} vs {}",
                ca.normal_force,
                ca.tangential_force,
                cb.normal_force,
                cb.tangential_force,
                ca.active_points,
                cb.active_points
            ));
        }
    }
    if newton(&on) != newton(&off) {
        return Err(format!(
            "{what}: Newton iterations {} vs {}",
            newton(&on),
            newton(&off)
        ));
    }
    Ok(())
}

/// Newton on the condensed system (the default) takes one dense step per
/// Newton iteration and K's factor only at each Uzawa round's start and
/// end and for G's columns it widens with; the whole-vector Newton solves
/// twice per iteration and never condenses. Every selected-inverse request
/// is probed by a whole solve, and on these healthy meshes passes.
fn solves_match_the_newton_kind(
    what: &str,
    s: &SchurSummary,
    on: &RunReport,
    overrides: &[&str],
) -> Result<(), String> {
    let uzawa: usize = on.steps.iter().map(|s| s.uzawa_iterations).sum();
    let (n, solves, steps) = (newton(on), s.sparse_solves, s.dense_solves);
    let ok = match overrides.contains(&"solver.condensed_newton=false") {
        true => steps == 0 && solves == 2 * n,
        false => steps == n && solves <= 2 * uzawa + s.solved_columns,
    };
    if s.inverse_redone != 0 || s.probe_solves < 1 {
        return Err(format!(
            "{what}: {} probe solves, {} requests redone",
            s.probe_solves, s.inverse_redone
        ));
    }
    match ok {
        true => Ok(()),
        false => Err(format!(
            "{what}: {solves} solves with K's factor and {steps} condensed steps \
             for {n} Newton iterations over {uzawa} Uzawa rounds"
        )),
    }
}

/// hertz-cylinder frictionless, and with Coulomb friction over two steps
/// (a second search and pattern; the contact tangent unsymmetric); the
/// stacked-blocks patch test with links and with mortar, its upper block
/// held by the contact alone (K singular: the path factors K shifted on C).
pub fn the_contact_schur_path_matches_the_full_factorisation(rt: &Runtime) -> Result<(), String> {
    same_run(rt, "hertz-cylinder", &["mesh.fine_size=0.4"], 1e-9)?;
    // The preconditioned whole-vector Newton, without the condensed one.
    same_run(
        rt,
        "hertz-cylinder",
        &["mesh.fine_size=0.4", "solver.condensed_newton=false"],
        1e-9,
    )?;
    same_run(
        rt,
        "hertz-cylinder",
        &[
            "mesh.fine_size=0.4",
            "contact.friction=0.2",
            "steps.count=2",
        ],
        1e-9,
    )?;
    for formulation in ["links", "mortar"] {
        let scene = floating_patch(rt, formulation)?;
        let r = same_run(rt, &scene, &[], 1e-10);
        let _ = std::fs::remove_file(&scene);
        r?;
    }
    Ok(())
}

/// The coarse-slave hex patch test of tests/mortar.rs (4 × 4 over 5 × 5
/// cells, a traction on top, no Dirichlet condition on the upper block in
/// z) as a scene file of this rank's own.
fn floating_patch(rt: &Runtime, formulation: &str) -> Result<String, String> {
    let path = std::env::temp_dir().join(format!(
        "contactlink-low-rank-patch-{formulation}-{}-{}.toml",
        std::process::id(),
        rt.rank()
    ));
    std::fs::write(&path, FLOATING_PATCH.replace("FORMULATION", formulation))
        .map_err(|e| format!("{}: {e}", path.display()))?;
    Ok(path.to_string_lossy().into_owned())
}

const FLOATING_PATCH: &str = r#"title = "patch test, upper block held by the contact alone"
[mesh]
generator = "stacked-blocks"
length = 1.0
height = 0.5
gap = 0.0
lower_divisions = [5, 5, 2]
upper_divisions = [4, 4, 2]
cell_type = "hex8"

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

[[traction]]
set = "upper.top"
vector = [0.0, 0.0, -10.0]

[[contact]]
name = "interface"
slave = "upper.bottom"
master = "lower.top"
formulation = "FORMULATION"
penetration_tol = 1e-9
multiplier_tol = 1e-9
max_uzawa = 60
"#;

/// The Hertz sphere at 79,773 DOFs on the direct low-rank path (2 ranks
/// only: about 10 s). With MUMPS's ScaLAPACK root the selected inverse gave
/// wrong entries of G here and every Newton iteration after the second
/// diverged; the factor is now made without it, and each request is probed
/// by whole solves. One step, no cutback, no request redone.
pub fn the_fine_sphere_solves_on_the_direct_low_rank_path(rt: &Runtime) -> Result<(), String> {
    if rt.size() != 2 {
        return Ok(());
    }
    let r = run_scene(
        rt,
        "hertz-sphere",
        &[
            "mesh.fine_size=0.42",
            "solver.direct_max_dofs=200000",
            "solver.max_cutbacks=0",
        ],
    )?;
    let s = r.schur.ok_or("the Schur path was not taken")?;
    let n = newton(&r);
    if !s.low_rank || s.inverse_redone != 0 || r.steps.len() != 1 || n > 25 {
        return Err(format!(
            "{} steps, {n} Newton iterations, {s:?}",
            r.steps.len()
        ));
    }
    Ok(())
}

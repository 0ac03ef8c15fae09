//! What a contact solve costs: against one plain elastic solve of the same
//! mesh, and what each reuse saves (each switched off in turn).
//!
//! An MPI program (harness = false; `make bench` runs it on 1 and 2 ranks).
//! The contact solves are the `hertz-cylinder` scene as shipped (one load
//! step, Uzawa around Newton, sparse direct solver) at two sizes and
//! `hertz-sphere` at h = 0.35 (97,803 DOFs, GMRES + GAMG; timed once, with
//! the default mortar pair and with the links). The
//! plain solve uses the same mesh, materials, conditions and solver without
//! the contact pair: one linear-elastic step. Both are timed in this one
//! process (median of 3, slowest rank), so the ratio does not depend on the
//! machine's load of the moment as much as two separate runs would.
//! `SOLVE_COSTS_SPHERE=0` leaves the sphere out, `SOLVE_COSTS_SAVINGS=0`
//! the reuse table.
use contactlink::model::Model;
use contactlink::pipeline;
use contactlink::runtime::Runtime;
use mpi::collective::SystemOperation;
use mpi::traits::*;
use std::time::Instant;

fn load(overrides: &[String]) -> Model {
    load_scene("hertz-cylinder", overrides)
}

fn load_scene(scene: &str, overrides: &[String]) -> Model {
    pipeline::load_model(scene, overrides)
        .expect("built-in scene loads")
        .0
}

/// The same mesh, materials and solver without the contact pair: each body
/// is already held by the scene's own conditions (block bottom fixed,
/// cylinder top pushed, plane strain), so this is one linear-elastic solve
/// of the same DOFs.
fn plain(scene: &str, overrides: &[String]) -> Model {
    let mut m = load_scene(scene, overrides);
    m.contact.clear();
    m.hertz = None;
    m.steps = 1;
    m
}

fn median(mut v: Vec<f64>) -> f64 {
    v.sort_by(|a, b| a.total_cmp(b));
    v[v.len() / 2]
}

fn timed(rt: &Runtime, model: &Model) -> (f64, usize) {
    timed_n(rt, model, 3)
}

fn timed_n(rt: &Runtime, model: &Model, repeats: usize) -> (f64, usize) {
    let mut newton = 0;
    let samples = (0..repeats)
        .map(|_| {
            rt.world().barrier();
            let t = Instant::now();
            let s = pipeline::run_model(rt, model, None, false).expect("solve");
            newton = s.report.steps.iter().map(|s| s.newton_iterations).sum();
            let mine = t.elapsed().as_secs_f64();
            let mut slowest = 0.0;
            rt.world()
                .all_reduce_into(&mine, &mut slowest, SystemOperation::max());
            slowest
        })
        .collect();
    (median(samples), newton)
}

/// Each reuse switched off in turn on the default hertz-cylinder, in this
/// one process: the ratio "without / with" is what it saves.
fn savings(rt: &Runtime) {
    if rt.rank() == 0 {
        println!("reuse,ranks,with_s,without_s,without/with");
    }
    let (base, _) = timed(rt, &load(&[]));
    for (label, key) in [
        (
            "linear stiffness assembled once",
            "solver.reuse_linear_stiffness=false",
        ),
        (
            "pattern kept while couplings unchanged",
            "solver.reuse_pattern=false",
        ),
        (
            "preconditioner lagged across Uzawa",
            "solver.lag_preconditioner=false",
        ),
        (
            "preconditioner rebuilt only on active-set changes",
            "solver.lag_active_set=false",
        ),
        (
            "non-final Uzawa iterations solved loosely",
            "solver.uzawa_forcing=0",
        ),
    ] {
        let (t, _) = timed(rt, &load(&[key.to_string()]));
        if rt.rank() == 0 {
            println!("{label},{},{base:.3},{t:.3},{:.2}", rt.size(), t / base);
        }
    }
}

fn main() {
    let rt = Runtime::start(&[]).expect("MPI and PETSc start");
    if std::env::var("SOLVE_COSTS_SAVINGS").map_or(true, |v| v != "0") {
        savings(&rt);
    }
    if rt.rank() == 0 {
        println!("mesh,dofs,ranks,contact_s,contact_newton,plain_s,plain_newton,ratio");
    }
    let sphere = std::env::var("SOLVE_COSTS_SPHERE").map_or(true, |v| v != "0");
    let mut cases = vec![
        (
            "cylinder h=0.2",
            "hertz-cylinder",
            vec!["mesh.fine_size=0.2".to_string()],
            3,
        ),
        ("cylinder h=0.1", "hertz-cylinder", vec![], 3),
    ];
    if sphere {
        cases.push((
            "sphere h=0.35",
            "hertz-sphere",
            vec!["mesh.fine_size=0.35".to_string()],
            1,
        ));
        // The same mesh on the direct path (MUMPS; the contact Schur or
        // low-rank path, Newton on the condensed contact system).
        cases.push((
            "sphere h=0.35 direct",
            "hertz-sphere",
            vec![
                "mesh.fine_size=0.35".to_string(),
                "solver.direct_max_dofs=200000".to_string(),
            ],
            1,
        ));
        cases.push((
            "sphere h=0.35 links",
            "hertz-sphere",
            vec![
                "mesh.fine_size=0.35".to_string(),
                "contact.formulation=links".to_string(),
            ],
            1,
        ));
    }
    for (label, scene, overrides, repeats) in cases {
        let contact = load_scene(scene, &overrides);
        let dofs = 3 * contact.mesh.num_nodes();
        let (tc, nc) = timed_n(&rt, &contact, repeats);
        let (tp, np) = timed_n(&rt, &plain(scene, &overrides), repeats);
        if rt.rank() == 0 {
            println!(
                "{label},{dofs},{},{tc:.3},{nc},{tp:.3},{np},{:.2}",
                rt.size(),
                tc / tp
            );
        }
    }
}

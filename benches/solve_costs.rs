//! What a contact solve costs: against one plain elastic solve of the same
//! mesh, and what each reuse saves (each switched off in turn).
//!
//! An MPI program (harness = false; `make bench` runs it on 1 and 2 ranks).
//! The contact solve is the `hertz-cylinder` scene as shipped (2 load
//! steps, Uzawa around Newton). The plain solve uses the same mesh,
//! materials, conditions and solver without the contact pair: one
//! linear-elastic step, one factorisation. Both are timed in this one process (median of 3,
//! slowest rank), so the ratio does not depend on the machine's load of the
//! moment as much as two separate runs would.
use contactlink::pipeline;
use contactlink::runtime::Runtime;
use contactlink::solve::Model;
use mpi::collective::SystemOperation;
use mpi::traits::*;
use std::time::Instant;

fn load(overrides: &[String]) -> Model {
    pipeline::load_model("hertz-cylinder", overrides)
        .expect("hertz-cylinder loads")
        .0
}

/// The same mesh, materials and solver without the contact pair: each body
/// is already held by the scene's own conditions (block bottom fixed,
/// cylinder top pushed, plane strain), so this is one linear-elastic solve
/// of the same DOFs.
fn plain(overrides: &[String]) -> Model {
    let mut m = load(overrides);
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
    let mut newton = 0;
    let samples = (0..3)
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
    ] {
        let (t, _) = timed(rt, &load(&[key.to_string()]));
        if rt.rank() == 0 {
            println!("{label},{},{base:.3},{t:.3},{:.2}", rt.size(), t / base);
        }
    }
}

fn main() {
    let rt = Runtime::start(&[]).expect("MPI and PETSc start");
    savings(&rt);
    if rt.rank() == 0 {
        println!("mesh,dofs,ranks,contact_s,contact_newton,plain_s,plain_newton,ratio");
    }
    for (label, overrides) in [
        ("h=0.2", vec!["mesh.fine_size=0.2".to_string()]),
        ("h=0.1", vec![]),
    ] {
        let contact = load(&overrides);
        let dofs = 3 * contact.mesh.num_nodes();
        let (tc, nc) = timed(&rt, &contact);
        let (tp, np) = timed(&rt, &plain(&overrides));
        if rt.rank() == 0 {
            println!(
                "{label},{dofs},{},{tc:.3},{nc},{tp:.3},{np},{:.2}",
                rt.size(),
                tc / tp
            );
        }
    }
}

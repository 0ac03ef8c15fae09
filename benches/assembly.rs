//! Assembly throughput and solve time against DOF count.
//!
//! An MPI program (harness = false): `make bench` runs it on 1 and 2 ranks.
//! Each figure is the median of several repetitions, maximised over ranks
//! (the slowest rank is what the run waits for). Output: CSV on rank 0.
use contactlink::assembly::BulkAssembler;
use contactlink::assembly::PatternBuilder;
use contactlink::dofs::{DofMap, DIM};
use contactlink::fem::{Integration, Material};
use contactlink::mesh::generate::{self, BoxSpec};
use contactlink::model::FacetLoad;
use contactlink::model::{DirichletSpec, Model, SolverSettings};
use contactlink::petsc::GhostedVector;
use contactlink::pipeline;
use contactlink::runtime::Runtime;
use mpi::collective::SystemOperation;
use mpi::traits::*;
use std::time::Instant;

fn median(mut v: Vec<f64>) -> f64 {
    v.sort_by(|a, b| a.total_cmp(b));
    v[v.len() / 2]
}

fn slowest(rt: &Runtime, t: f64) -> f64 {
    let mut m = 0.0;
    rt.world()
        .all_reduce_into(&t, &mut m, SystemOperation::max());
    m
}

fn time_it(rt: &Runtime, reps: usize, mut f: impl FnMut()) -> f64 {
    let samples = (0..reps)
        .map(|_| {
            rt.world().barrier();
            let t = Instant::now();
            f();
            slowest(rt, t.elapsed().as_secs_f64())
        })
        .collect();
    median(samples)
}

fn model(n: usize) -> Model {
    let mesh = generate::graded_box(&BoxSpec {
        size: [1.0; 3],
        divisions: [n; 3],
        ..Default::default()
    })
    .expect("box");
    let bottom = mesh.node_sets["block.bottom"].clone();
    Model {
        name: format!("box {n}^3"),
        materials: vec![Material::NeoHookean {
            youngs: 1000.0,
            poisson: 0.3,
        }],
        integration: vec![Integration::Full],
        dirichlet: vec![DirichletSpec::uniform(
            "block.bottom",
            bottom,
            vec![0, 1, 2],
            [0.0; 3],
        )],
        facet_loads: vec![(
            "block.top".into(),
            FacetLoad::Pressure(50.0),
            Default::default(),
        )],
        body_force: vec![[0.0; 3]],
        body_force_fn: None,
        contact: Vec::new(),
        hertz: None,
        steps: 1,
        solver: SolverSettings::default(),
        dynamics: None,
        mesh,
    }
}

fn main() {
    let rt = Runtime::start(&[]).expect("start MPI and PETSc");
    let sizes: Vec<usize> = std::env::var("BENCH_SIZES")
        .ok()
        .map(|s| s.split(',').filter_map(|v| v.trim().parse().ok()).collect())
        .unwrap_or_else(|| vec![8, 16, 24, 32]);
    if rt.rank() == 0 {
        println!(
            "ranks,dofs,cells,residual_s,tangent_s,tangent_cells_per_s,solve_s,newton,linear_its"
        );
    }
    for n in sizes {
        let m = model(n);
        let mut part =
            contactlink::partition::partition_cells(&m.mesh, rt.size(), &[]).expect("partition");
        rt.world().process_at_rank(0).broadcast_into(&mut part[..]);
        let wanted = contactlink::distribution::Wanted::default();
        let (dofs, local) = DofMap::with_mesh(&m.mesh, &part, rt.rank(), rt.size(), &wanted);
        let bulk = BulkAssembler::new(&local, &dofs, m.materials.clone(), m.integration.clone())
            .expect("bulk");
        let mut pattern = PatternBuilder::new(dofs.num_owned_dofs(), DIM).expect("pattern");
        bulk.add_pattern(&mut pattern).expect("pattern");
        let mut jac = pattern.build().expect("matrix");
        let mut r = GhostedVector::new(dofs.num_owned_dofs(), &dofs.ghost_dofs()).expect("vector");
        // A small non-zero state so the Neo-Hookean kernel does real work.
        let u: Vec<f64> = (0..DIM * dofs.num_local_nodes())
            .map(|i| 1e-3 * ((i % 7) as f64 - 3.0))
            .collect();
        let residual_s = time_it(&rt, 5, || {
            r.with_local_mut(|rl| {
                rl.fill(0.0);
                bulk.add_internal_force(&u, rl).expect("residual");
            })
            .expect("local form");
            r.accumulate_ghosts().expect("ghost exchange");
        });
        let tangent_s = time_it(&rt, 3, || {
            jac.zero_entries().expect("zero");
            bulk.add_tangent(&u, &mut jac).expect("tangent");
            jac.assemble().expect("assemble");
        });
        rt.world().barrier();
        let t = Instant::now();
        let summary = pipeline::run_model(&rt, &m, None, false).expect("solve");
        let solve_s = slowest(&rt, t.elapsed().as_secs_f64());
        let newton: usize = summary
            .report
            .steps
            .iter()
            .map(|s| s.newton_iterations)
            .sum();
        let linear: usize = summary
            .report
            .steps
            .iter()
            .map(|s| s.linear_iterations)
            .sum();
        if rt.rank() == 0 {
            println!(
                "{},{},{},{:.5},{:.5},{:.0},{:.3},{},{}",
                rt.size(),
                DIM * m.mesh.num_nodes(),
                m.mesh.num_cells(),
                residual_s,
                tangent_s,
                m.mesh.num_cells() as f64 / tangent_s,
                solve_s,
                newton,
                linear
            );
        }
    }
}

//! MPI test harness: every case asserts what must hold at any rank count.
//! `cargo test` runs it on one rank (singleton); `make test` runs it again
//! under `mpirun -n 2` and `-n 3`.
//!
//! Cases here need MPI and PETSc, which can be initialised once per process,
//! so this is one program (harness = false) rather than libtest threads.
use contactlink::dofs::{DofMap, LocalNode, DIM};
use contactlink::fem::{Integration, Material};
use contactlink::mesh::generate::{self, BoxSpec, Grading};
use contactlink::mesh::Mesh;
use contactlink::model::{DirichletSpec, Model, SolverSettings};
use contactlink::petsc::GhostedVector;
use contactlink::pipeline;
use contactlink::runtime::Runtime;
use mpi::collective::SystemOperation;
use mpi::traits::*;
use std::process::ExitCode;

mod lagging;
mod low_rank;
mod manufactured;
mod mortar_halo;
mod pattern;
mod rank0;

type Case = (&'static str, fn(&Runtime) -> Result<(), String>);

const CASES: &[Case] = &[
    (
        "the_pattern_holds_every_ranks_couplings",
        pattern::the_pattern_holds_every_ranks_couplings,
    ),
    (
        "halo_exchange_refreshes_ghosts",
        halo_exchange_refreshes_ghosts,
    ),
    (
        "dof_numbering_is_a_permutation",
        dof_numbering_is_a_permutation,
    ),
    ("bulk_patch_test_linear_elastic_distorted", |rt| {
        bulk_patch_test(rt, linear())
    }),
    ("bulk_patch_test_neo_hookean_distorted", |rt| {
        bulk_patch_test(rt, neo_hookean())
    }),
    (
        "manufactured_solution_converges_at_second_order",
        manufactured::manufactured_solution_converges,
    ),
    (
        "second_order_elements_converge_at_their_order",
        manufactured::second_order_elements_converge_at_their_order,
    ),
    (
        "neo_hookean_uniaxial_stretch_matches_closed_form",
        uniaxial_stretch_closed_form,
    ),
    (
        "block_slide_transmits_mu_n_while_sliding",
        block_slide_transmits_mu_n,
    ),
    (
        "frictional_impact_conserves_momentum_and_dissipates",
        frictional_impact_conserves_momentum,
    ),
    (
        "agreement_carries_the_lowest_failing_rank_everywhere",
        agreement_carries_the_lowest_failing_rank,
    ),
    (
        "a_rank_holds_a_share_of_the_mesh_after_set_up",
        a_rank_holds_a_share_of_the_mesh,
    ),
    (
        "only_rank_0_holds_the_mesh",
        rank0::only_rank_0_holds_the_mesh,
    ),
    (
        "a_scene_error_on_rank_0_is_every_ranks",
        rank0::a_scene_error_on_rank_0_is_every_ranks,
    ),
    (
        "the_watch_rebuilds_factors_on_a_change_and_amg_once_worn",
        lagging::the_watch_rebuilds_factors_on_a_change_and_amg_once_worn,
    ),
    (
        "the_contact_schur_path_matches_the_full_factorisation",
        low_rank::the_contact_schur_path_matches_the_full_factorisation,
    ),
    (
        "the_fine_sphere_solves_on_the_direct_low_rank_path",
        low_rank::the_fine_sphere_solves_on_the_direct_low_rank_path,
    ),
    (
        "a_mortar_pair_holds_only_the_master_near_its_slave_facets",
        mortar_halo::a_mortar_pair_holds_only_the_master_near_its_slave_facets,
    ),
];

/// Set up with the mesh moved out of the model: the set-up consumes it
/// (freed once the pieces are cut), and each rank's local mesh is its share
/// of the nodes plus one ghost layer, not the whole mesh: on P ranks at most
/// N/P + N/4 nodes (METIS on a 12³ box; the ghost layer of a piece is a few
/// planes of nodes), so on 4 ranks at most half the mesh.
fn a_rank_holds_a_share_of_the_mesh(rt: &Runtime) -> Result<(), String> {
    let mesh = generate::graded_box(&BoxSpec {
        divisions: [12, 12, 12],
        ..BoxSpec::default()
    })
    .map_err(|e| e.to_string())?;
    let n = mesh.num_nodes();
    let cells = mesh.num_cells();
    let mut model = model_with(mesh, linear(), Vec::new(), 1);
    let mesh = model.take_mesh();
    let sim = contactlink::solve::Simulation::setup_with_mesh(rt, &model, mesh)
        .map_err(|e| e.to_string())?;
    ensure(
        model.mesh.num_nodes() == 0 && model.mesh.num_cells() == 0,
        || "the model still holds a mesh after take_mesh".into(),
    )?;
    let local = sim.local_mesh();
    ensure(
        local.global_nodes == n && local.global_cells == cells,
        || {
            format!(
                "local mesh of {} nodes / {} cells, the mesh has {n} / {cells}",
                local.global_nodes, local.global_cells
            )
        },
    )?;
    let p = rt.size();
    let held = local.num_nodes();
    let bound = if p == 1 { n } else { n / p + n / 4 };
    ensure(held <= bound, || {
        format!(
            "rank {} of {p} holds {held} of {n} nodes (bound {bound})",
            rt.rank()
        )
    })?;
    ensure(local.block.nodes.len() <= n / p + 1, || {
        format!(
            "output block of {} nodes on {p} ranks",
            local.block.nodes.len()
        )
    })
}

fn main() -> ExitCode {
    let rt = match Runtime::start(&[]) {
        Ok(rt) => rt,
        Err(e) => {
            eprintln!("mpi-tests: start-up failed: {e}");
            return ExitCode::FAILURE;
        }
    };
    let filter: Option<String> = std::env::args().skip(1).find(|a| !a.starts_with('-'));
    let world = rt.world();
    let (mut passed, mut failed) = (0, 0);
    for (name, case) in CASES {
        if filter.as_deref().is_some_and(|f| !name.contains(f)) {
            continue;
        }
        let mine = case(&rt);
        let ok_here = i32::from(mine.is_ok());
        let mut ok_all = 0;
        world.all_reduce_into(&ok_here, &mut ok_all, SystemOperation::min());
        if let Err(msg) = &mine {
            eprintln!("[rank {}] {name}: {msg}", rt.rank());
        }
        if rt.rank() == 0 {
            println!(
                "test {name} ({} ranks) ... {}",
                rt.size(),
                if ok_all == 1 { "ok" } else { "FAILED" }
            );
        }
        if ok_all == 1 {
            passed += 1;
        } else {
            failed += 1;
        }
    }
    if rt.rank() == 0 {
        println!("mpi-tests: {passed} passed, {failed} failed");
    }
    drop(rt);
    if failed == 0 {
        ExitCode::SUCCESS
    } else {
        ExitCode::FAILURE
    }
}

fn linear() -> Material {
    Material::LinearElastic {
        youngs: 1000.0,
        poisson: 0.3,
    }
}

fn neo_hookean() -> Material {
    Material::NeoHookean {
        youngs: 1000.0,
        poisson: 0.3,
    }
}

fn ensure(cond: bool, msg: impl FnOnce() -> String) -> Result<(), String> {
    if cond {
        Ok(())
    } else {
        Err(msg())
    }
}

fn unit_box(n: usize, grading: Grading) -> Result<Mesh, String> {
    generate::graded_box(&BoxSpec {
        body: "block".into(),
        origin: [0.0; 3],
        size: [1.0; 3],
        divisions: [n; 3],
        grading: [grading; 3],
        ..Default::default()
    })
    .map_err(|e| e.to_string())
}

fn partition_for(rt: &Runtime, mesh: &Mesh) -> Result<Vec<i32>, String> {
    let mut part =
        contactlink::partition::partition_cells(mesh, rt.size(), &[]).map_err(|e| e.to_string())?;
    rt.world().process_at_rank(0).broadcast_into(&mut part[..]);
    Ok(part)
}

/// Ghost entries of a ghosted vector take their owners' values after the
/// exchange: the owned entry of every node holds its natural id, so every
/// ghost must read its own node's natural id.
fn halo_exchange_refreshes_ghosts(rt: &Runtime) -> Result<(), String> {
    let mesh = unit_box(6, Grading::Uniform)?;
    let part = partition_for(rt, &mesh)?;
    let dofs = DofMap::new(&mesh, &part, rt.rank(), rt.size(), &[]);
    let mut v =
        GhostedVector::new(dofs.num_owned_dofs(), &dofs.ghost_dofs()).map_err(|e| e.to_string())?;
    v.with_local_mut(|a| {
        a.fill(-1.0);
        for l in 0..dofs.num_owned_nodes() {
            for c in 0..DIM {
                a[DIM * l + c] = (DIM * dofs.natural(LocalNode::from_index(l)).0 + c) as f64;
            }
        }
    })
    .map_err(|e| e.to_string())?;
    v.update_ghosts().map_err(|e| e.to_string())?;
    let bad = v
        .with_local(|a| {
            (0..dofs.num_local_nodes())
                .flat_map(|l| (0..DIM).map(move |c| (l, c)))
                .filter(|&(l, c)| {
                    a[DIM * l + c] != (DIM * dofs.natural(LocalNode::from_index(l)).0 + c) as f64
                })
                .count()
        })
        .map_err(|e| e.to_string())?;
    ensure(bad == 0, || {
        format!("{bad} ghost entries hold the wrong value after the exchange")
    })?;
    // Reverse: every rank adds 1 into each local entry; owners then hold the
    // number of ranks that see the node.
    v.with_local_mut(|a| a.fill(1.0))
        .map_err(|e| e.to_string())?;
    v.accumulate_ghosts().map_err(|e| e.to_string())?;
    let total = v
        .global()
        .with_array(|a| a.iter().sum::<f64>())
        .map_err(|e| e.to_string())?;
    let mut sum = 0.0;
    rt.world()
        .all_reduce_into(&total, &mut sum, SystemOperation::sum());
    let mut local_entries = (DIM * dofs.num_local_nodes()) as f64;
    let mut expected = 0.0;
    rt.world()
        .all_reduce_into(&local_entries, &mut expected, SystemOperation::sum());
    local_entries = expected;
    ensure(sum == local_entries, || {
        format!("reverse exchange summed to {sum}, expected {local_entries}")
    })
}

/// Every natural node has exactly one owner and the owned ranges tile 0..N.
fn dof_numbering_is_a_permutation(rt: &Runtime) -> Result<(), String> {
    let mesh = unit_box(
        5,
        Grading::Toward {
            point: 0.0,
            ratio: 3.0,
        },
    )?;
    let part = partition_for(rt, &mesh)?;
    let dofs = DofMap::new(&mesh, &part, rt.rank(), rt.size(), &[]);
    let n = mesh.num_nodes();
    let block: Vec<u32> = dofs.output_block_petsc().to_vec();
    let counts: Vec<i32> = (0..rt.size())
        .map(|r| contactlink::dofs::even_block(n, r, rt.size()).len() as i32)
        .collect();
    let displs: Vec<i32> = counts
        .iter()
        .scan(0, |acc, &c| {
            let d = *acc;
            *acc += c;
            Some(d)
        })
        .collect();
    let mut all = vec![0u32; n];
    {
        let mut part = mpi::datatype::PartitionMut::new(&mut all[..], &counts[..], &displs[..]);
        rt.world().all_gather_varcount_into(&block[..], &mut part);
    }
    let mut seen = vec![0i32; n];
    for &p in &all {
        seen[p as usize] += 1;
    }
    let mut owned = dofs.num_owned_nodes() as u64;
    let mut total = 0u64;
    rt.world()
        .all_reduce_into(&owned, &mut total, SystemOperation::sum());
    ensure(total == n as u64, || {
        format!("owned nodes sum to {total}, mesh has {n}")
    })?;
    let start = dofs.owned_dof_start() as u64;
    let mut starts = vec![0u64; rt.size()];
    rt.world().all_gather_into(&start, &mut starts[..]);
    owned *= DIM as u64;
    ensure(starts.windows(2).all(|w| w[0] <= w[1]), || {
        format!("owned ranges out of order: {starts:?}")
    })?;
    ensure(start + owned <= DIM as u64 * n as u64, || {
        "owned range exceeds the DOF count".into()
    })
}

/// Boundary node ids of a box mesh: union of its six face sets.
fn boundary_nodes(mesh: &Mesh, body: &str) -> Vec<usize> {
    let mut nodes: Vec<usize> = ["xmin", "xmax", "ymin", "ymax", "zmin", "zmax"]
        .iter()
        .flat_map(|f| {
            mesh.node_sets
                .get(&format!("{body}.{f}"))
                .cloned()
                .unwrap_or_default()
        })
        .collect();
    nodes.sort_unstable();
    nodes.dedup();
    nodes
}

fn model_with(
    mesh: Mesh,
    material: Material,
    dirichlet: Vec<DirichletSpec>,
    steps: usize,
) -> Model {
    let bodies = mesh.bodies.len();
    Model {
        name: "mpi-test".into(),
        mesh,
        materials: vec![material; bodies],
        integration: vec![Integration::Full; bodies],
        dirichlet,
        facet_loads: Vec::new(),
        body_force: vec![[0.0; 3]; bodies],
        body_force_fn: None,
        contact: Vec::new(),
        hertz: None,
        steps,
        solver: SolverSettings {
            rtol: 1e-12,
            atol: Some(1e-11),
            ..Default::default()
        },
        dynamics: None,
    }
}

/// A linear displacement field prescribed on the boundary of a distorted mesh
/// is reproduced at every interior node to round-off (homogeneous deformation
/// is exact for both materials).
fn bulk_patch_test(rt: &Runtime, material: Material) -> Result<(), String> {
    let mesh = unit_box(4, Grading::Uniform)?;
    let mesh = generate::perturb_interior(&mesh, 0.3, 7).map_err(|e| e.to_string())?;
    let grad = [
        [0.05, 0.02, -0.01],
        [0.01, -0.03, 0.02],
        [-0.02, 0.01, 0.04],
    ];
    let exact = |x: [f64; 3]| -> [f64; 3] {
        let mut u = [1e-3, -2e-3, 5e-4];
        for i in 0..3 {
            for j in 0..3 {
                u[i] += grad[i][j] * x[j];
            }
        }
        u
    };
    let nodes = boundary_nodes(&mesh, "block");
    let values = nodes.iter().map(|&v| exact(mesh.nodes[v])).collect();
    let bc = DirichletSpec {
        set: "boundary".into(),
        nodes,
        components: vec![0, 1, 2],
        values,
        amplitude: Default::default(),
    };
    let interior_moved = mesh.nodes.clone();
    let model = model_with(mesh, material, vec![bc], 1);
    let summary = pipeline::run_model(rt, &model, None, false).map_err(|e| e.to_string())?;
    // The final displacement is on rank 0 only: no other rank holds an
    // array of the global node count.
    if rt.rank() != 0 {
        let held = summary.report.displacement.len();
        return ensure(held == 0, || {
            format!("rank {} holds {held} final displacement values", rt.rank())
        });
    }
    let u = &summary.report.displacement;
    ensure(u.len() == 3 * interior_moved.len(), || {
        format!("{} final displacement values on rank 0", u.len())
    })?;
    let mut worst: f64 = 0.0;
    for (v, x) in interior_moved.iter().enumerate() {
        let e = exact(*x);
        for c in 0..3 {
            worst = worst.max((u[3 * v + c] - e[c]).abs());
        }
    }
    ensure(worst < 1e-10, || {
        format!("patch test error {worst:.3e} (max |u_h − u|)")
    })
}

/// The built-in `uniaxial-stretch` scene: a Neo-Hookean cube stretched to
/// λ = 2 with free lateral faces. Closed form: μ(λt² − 1) + λ ln J = 0 with
/// J = λ λt², nominal stress P11 = μ(λ − 1/λ) + λ_L ln J / λ.
/// The uniaxial-stretch scene (a Neo-Hookean cube stretched to twice its
/// length) against the closed form, with its hex8 cells and as hex20 and
/// tet10 (whose straight-sided cells represent the homogeneous state
/// exactly too).
fn uniaxial_stretch_closed_form(rt: &Runtime) -> Result<(), String> {
    for cell in ["hex8", "hex20", "tet10"] {
        uniaxial_stretch_of(rt, cell)?;
    }
    Ok(())
}

fn uniaxial_stretch_of(rt: &Runtime, cell: &str) -> Result<(), String> {
    let overrides = [format!("mesh.cell_type={cell}")];
    let (model, _) =
        pipeline::load_model("uniaxial-stretch", &overrides).map_err(|e| e.to_string())?;
    let summary = pipeline::run_model(rt, &model, None, false).map_err(|e| e.to_string())?;
    let (lam_l, mu) = model.materials[0].lame();
    let stretch = 2.0;
    let residual = |t: f64| mu * (t * t - 1.0) + lam_l * (stretch * t * t).ln();
    let (mut lo, mut hi) = (1e-3, 1.0);
    for _ in 0..200 {
        let mid = 0.5 * (lo + hi);
        if residual(mid) > 0.0 {
            hi = mid;
        } else {
            lo = mid;
        }
    }
    let lateral = 0.5 * (lo + hi);
    let j = stretch * lateral * lateral;
    let p11 = mu * (stretch - 1.0 / stretch) + lam_l * j.ln() / stretch;
    // Lateral stretch from the displacement of the corner (1, 1, 1).
    let corner = model
        .mesh
        .nodes
        .iter()
        .position(|x| x == &[1.0, 1.0, 1.0])
        .ok_or("no corner node")?;
    // The final displacement is on rank 0 only.
    if rt.rank() != 0 {
        return Ok(());
    }
    let u = &summary.report.displacement;
    let computed_lateral = 1.0 + u[3 * corner + 1];
    let last = summary.report.steps.last().ok_or("no steps")?;
    let force = last
        .reactions
        .iter()
        .find(|(s, _)| s == "cube.xmax")
        .ok_or("no reaction on cube.xmax")?
        .1[0];
    let e_lat = (computed_lateral - lateral).abs() / lateral;
    let e_p = (force - p11).abs() / p11;
    if rt.rank() == 0 {
        println!("  uniaxial λ=2 on {cell}: λt {computed_lateral:.10} (exact {lateral:.10}), P11 {force:.8} (exact {p11:.8})");
    }
    ensure(e_lat < 1e-8 && e_p < 1e-8, || {
        format!("{cell}: lateral stretch error {e_lat:.2e}, stress error {e_p:.2e}")
    })
}

/// Friction on any rank count: once every contact point slides, the rigid
/// plane transmits exactly μN; before the pull nothing slides.
fn block_slide_transmits_mu_n(rt: &Runtime) -> Result<(), String> {
    let (model, _) = pipeline::load_model("block-slide", &[]).map_err(|e| e.to_string())?;
    let summary = pipeline::run_model(rt, &model, None, false).map_err(|e| e.to_string())?;
    let mut sliding_steps = 0;
    for step in &summary.report.steps {
        let c = step.contact.first().ok_or("no contact report")?;
        if c.active_points > 0 && c.sliding_points == c.active_points {
            let ratio = c.force[0].abs() / c.force[2];
            ensure((ratio - 0.3).abs() < 1e-6 * 0.3, || {
                format!("step {}: Fx/Fz = {ratio}", step.index)
            })?;
            sliding_steps += 1;
        }
        if step.load_factor <= 0.25 + 1e-12 {
            ensure(c.force[0].abs() < 1e-8 * c.force[2], || {
                format!("step {}: tangential force before the pull", step.index)
            })?;
        }
    }
    if rt.rank() == 0 {
        println!("  block-slide: {sliding_steps} fully sliding steps at Fx/Fz = 0.3");
    }
    ensure(sliding_steps >= 5, || {
        format!("{sliding_steps} sliding steps")
    })
}

/// Dynamics with friction on any rank count: momentum is conserved through
/// the impact and the energy never grows.
fn frictional_impact_conserves_momentum(rt: &Runtime) -> Result<(), String> {
    let (model, _) = pipeline::load_model("impact", &["contact.friction=0.3".to_string()])
        .map_err(|e| e.to_string())?;
    let summary = pipeline::run_model(rt, &model, None, false).map_err(|e| e.to_string())?;
    let p0 = [0.25, 0.0, -0.5];
    let mut energy = f64::INFINITY;
    let mut contact_steps = 0;
    for step in &summary.report.steps {
        let d = step.dynamics.ok_or("no dynamics report")?;
        let drift = d
            .momentum
            .iter()
            .zip(p0)
            .fold(0.0f64, |m, (p, q)| m.max((p - q).abs()));
        ensure(drift < 1e-10, || {
            format!("step {}: momentum {:?}", step.index, d.momentum)
        })?;
        let e = d.kinetic + d.strain;
        ensure(e <= energy * (1.0 + 1e-9), || {
            format!("step {}: energy grew to {e}", step.index)
        })?;
        energy = e;
        if step.contact.first().is_some_and(|c| c.active_points > 0) {
            contact_steps += 1;
        }
    }
    if rt.rank() == 0 {
        println!("  impact (μ = 0.3): final energy {energy:.6} of 0.3125, {contact_steps} steps in contact");
    }
    ensure(contact_steps >= 3 && energy < 0.3125, || {
        format!("{contact_steps} contact steps, energy {energy}")
    })
}

/// `parallel::agree`: when the last rank and (on 3+ ranks) rank 1 fail,
/// every rank returns the lowest failing rank's own message, category
/// included; when none fails, every rank keeps its own value.
fn agreement_carries_the_lowest_failing_rank(rt: &Runtime) -> Result<(), String> {
    use contactlink::parallel;
    let world = rt.world();
    let (rank, size) = (rt.rank(), rt.size());
    let fails = size > 1 && (rank == size - 1 || rank == 1);
    let lowest = (size > 1).then_some(1.min(size - 1));
    ensure(parallel::lowest_rank(&world, fails) == lowest, || {
        format!(
            "lowest failing rank {:?}, expected {lowest:?}",
            parallel::lowest_rank(&world, fails)
        )
    })?;
    let local = fails.then(|| (7 + rank as i32, format!("failure of rank {rank}")));
    let agreed = parallel::agree_failure(&world, local);
    let expected = lowest.map(|r| parallel::RankFailure {
        rank: r,
        code: 7 + r as i32,
        message: format!("failure of rank {r}"),
    });
    ensure(agreed == expected, || {
        format!("agreed {agreed:?}, expected {expected:?}")
    })?;
    let mine: contactlink::Result<usize> = if fails {
        Err(contactlink::Error::Fault("a test"))
    } else {
        Ok(rank)
    };
    match (parallel::agree(&world, mine), lowest) {
        (Ok(v), None) => ensure(v == rank, || format!("value {v} on rank {rank}")),
        (Err(e), Some(r)) => {
            let text = e.to_string();
            ensure(
                text == format!("rank {r}: injected fault at a test (CONTACTLINK_FAULT)"),
                || text.clone(),
            )
        }
        (other, _) => Err(format!("agree gave {other:?} on {size} ranks")),
    }?;
    ensure(
        parallel::all_ranks(&world, true) && !parallel::any_rank(&world, false),
        || "all_ranks/any_rank".into(),
    )?;
    let [total] = parallel::sum_usize(&world, [rank + 1]);
    ensure(total == size * (size + 1) / 2, || format!("sum {total}"))
}

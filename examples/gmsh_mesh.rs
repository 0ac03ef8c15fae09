//! A model on a mesh read from Gmsh: a half ball of linear tets (radius 1)
//! pushed 0.05 down onto an elastic block, from `scenes/sphere-block.msh`
//! (made by `scenes/sphere-block.geo`). The example shows the Gmsh reader
//! (`mesh::read_gmsh`: physical groups become bodies and `<body>.<face>`
//! sets, every facet set also a node set) and a model built on it in code.
//! It prints what the reader found, the contact force and the reaction on
//! the pushed face; the two must balance (the ball is held by nothing
//! else), and the example exits with status 1 when they do not within
//! 0.1 % or when the contact carries no load.
//!
//! ```text
//! cargo run --release --example gmsh_mesh -- [MESH.msh]
//! mpirun -n 2 target/release/examples/gmsh_mesh
//! ```
//!
//! Another MESH.msh (format 4.1) works when it has the same physical names:
//! volumes `block` and `sphere`, surfaces `block.bottom`, `block.top`,
//! `sphere.top` and `sphere.curved`.
use contactlink::fem::{Integration, Material};
use contactlink::mesh::{read_gmsh, Mesh};
use contactlink::model::{DirichletSpec, Model, SolverSettings};
use contactlink::model::{MasterSpec, PairSpec};
use contactlink::pipeline;
use contactlink::runtime::Runtime;
use std::path::{Path, PathBuf};
use std::process::ExitCode;

/// Downward displacement of the ball's flat top face (the initial gap is 0.01).
const PUSH: f64 = 0.05;
/// |contact force + reaction| / |reaction| accepted (measured: about 1e-9).
const BALANCE_TOL: f64 = 1e-3;

fn main() -> ExitCode {
    let args: Vec<String> = std::env::args().skip(1).collect();
    if args.len() > 1 {
        eprintln!("gmsh_mesh example: usage: gmsh_mesh [MESH.msh]");
        return ExitCode::FAILURE;
    }
    let path = args
        .first()
        .map(PathBuf::from)
        .unwrap_or_else(|| Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes/sphere-block.msh"));
    let rt = match Runtime::start(&[]) {
        Ok(rt) => rt,
        Err(e) => {
            eprintln!("gmsh_mesh example: {e}");
            return ExitCode::FAILURE;
        }
    };
    // Every rank reads the same file and runs the same collective solve,
    // so every rank fails or succeeds alike; rank 0 alone prints.
    match run(&rt, &path) {
        Ok(true) => ExitCode::SUCCESS,
        Ok(false) => ExitCode::FAILURE,
        Err(message) => {
            if rt.rank() == 0 {
                eprintln!("gmsh_mesh example: {message}");
            }
            ExitCode::FAILURE
        }
    }
}

/// Reads the mesh, runs the model; Ok(false) when the forces do not balance.
fn run(rt: &Runtime, path: &Path) -> Result<bool, String> {
    let (mesh, report) = read_gmsh(path).map_err(|e| e.to_string())?;
    if rt.rank() == 0 {
        println!(
            "gmsh_mesh: {}: {} {} cells, {} nodes, bodies {}; {} cell(s) reoriented, {} unused node(s) dropped",
            // The default file relative to the crate, as the docs name it.
            path.strip_prefix(env!("CARGO_MANIFEST_DIR"))
                .unwrap_or(path)
                .display(),
            mesh.num_cells(),
            mesh.cell_type.name(),
            mesh.num_nodes(),
            mesh.bodies.join(", "),
            report.reoriented,
            report.unused_nodes
        );
    }
    let model = model(mesh)?;
    let summary = pipeline::run_model(rt, &model, None, false).map_err(|e| e.to_string())?;
    let last = summary
        .report
        .steps
        .last()
        .ok_or("the run converged no step")?;
    let contact = last
        .contact
        .first()
        .ok_or("the step reports no contact pair")?;
    let (_, reaction) = last
        .reactions
        .iter()
        .find(|(set, _)| set == "sphere.top")
        .ok_or("no reaction reported for sphere.top")?;
    // On the ball: the contact force from the block and the reaction of the
    // pushed face are the only external forces.
    let norm = |v: [f64; 3]| v.iter().map(|x| x * x).sum::<f64>().sqrt();
    let imbalance = norm([0, 1, 2].map(|i| contact.force[i] + reaction[i])) / norm(*reaction);
    let loaded = norm(contact.force) > 0.0 && contact.active_points > 0;
    let ok = loaded && imbalance <= BALANCE_TOL;
    if rt.rank() == 0 {
        println!(
            "  {} rank(s), {} steps, {} Newton iterations",
            rt.size(),
            summary.report.steps.len(),
            summary
                .report
                .steps
                .iter()
                .map(|s| s.newton_iterations)
                .sum::<usize>()
        );
        println!(
            "  contact force on the ball [{:.5}, {:.5}, {:.5}], {} active {}, max penetration {:.2e}",
            contact.force[0],
            contact.force[1],
            contact.force[2],
            contact.active_points,
            contact.active_what,
            contact.max_penetration
        );
        println!(
            "  reaction on sphere.top    [{:.5}, {:.5}, {:.5}], imbalance {imbalance:.1e}",
            reaction[0], reaction[1], reaction[2]
        );
        if !ok {
            println!("  FAILED: the contact force does not balance the reaction (or is zero)");
        }
    }
    Ok(ok)
}

/// Two linear-elastic bodies, the block held at its bottom, the ball pushed
/// at its top, one contact pair from the ball's curved face to the block.
fn model(mesh: Mesh) -> Result<Model, String> {
    let node_set = |set: &str| -> Result<Vec<usize>, String> {
        Ok(mesh.node_set(set).map_err(|e| e.to_string())?.to_vec())
    };
    let dirichlet = vec![
        DirichletSpec::uniform(
            "block.bottom",
            node_set("block.bottom")?,
            vec![0, 1, 2],
            [0.0; 3],
        ),
        DirichletSpec::uniform(
            "sphere.top",
            node_set("sphere.top")?,
            vec![0, 1, 2],
            [0.0, 0.0, -PUSH],
        ),
    ];
    // The default formulation, the mortar: one multiplier per slave node on
    // quads and triangles alike.
    let pair = PairSpec::new(
        "sphere-block",
        "sphere.curved",
        MasterSpec::Surface {
            set: "block.top".into(),
        },
    );
    let bodies = mesh.bodies.len();
    Ok(Model {
        name: "gmsh_mesh example".into(),
        materials: vec![
            Material::LinearElastic {
                youngs: 1000.0,
                poisson: 0.3,
            };
            bodies
        ],
        dirichlet,
        facet_loads: Vec::new(),
        integration: vec![Integration::Full; bodies],
        body_force: vec![[0.0; 3]; bodies],
        body_force_fn: None,
        contact: vec![pair],
        hertz: None,
        steps: 2,
        solver: SolverSettings::default(),
        dynamics: None,
        mesh,
    })
}

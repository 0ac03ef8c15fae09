//! Frictional block slide, then its result file read back. An elastic block
//! (1 × 1 × 0.5, ν = 0) is pressed onto a rigid plane by a pressure of 10
//! (N = 10) over the first quarter of the load path, then its top is pulled
//! 0.01 in x. Coulomb friction (μ = 0.3) holds it while the pull needs less
//! than μN = 3 and lets it slide at Ft = μN once it needs more.
//!
//! The example shows a model with load amplitudes, a rigid master with
//! friction, and an HDF5 result file; after the run it reopens the file with
//! the `results` and `output` readers and prints, per step, the normal force
//! N and the tangential force Ft of the contact pair (from its total force
//! on the slave surface), Ft/N and the number of slipping constraints. It exits
//! with status 1 when Ft/N ever exceeds μ or the block does not end up
//! sliding with Ft/N = μ.
//!
//! ```text
//! cargo run --release --example block_slide -- [STEPS] [OUT.h5]
//! mpirun -n 2 target/release/examples/block_slide 20 out/examples/block_slide.h5
//! ```
use contactlink::amplitude::Amplitude;
use contactlink::fem::{Integration, Material};
use contactlink::mesh::generate::{graded_box, BoxSpec};
use contactlink::model::FacetLoad;
use contactlink::model::{DirichletSpec, Model, SolverSettings};
use contactlink::model::{FrictionSpec, MasterSpec, PairSpec, RigidSurface};
use contactlink::output::read_step_attrs;
use contactlink::pipeline;
use contactlink::results::{open_steps, PairPoints};
use contactlink::runtime::Runtime;
use std::path::{Path, PathBuf};
use std::process::ExitCode;

const MU: f64 = 0.3;
const PRESSURE: f64 = 10.0;
const PULL: f64 = 0.01;
const PAIR: &str = "floor";
/// The plane's outward normal: N is the force along it, Ft the rest.
const NORMAL: [f64; 3] = [0.0, 0.0, 1.0];
/// Ft/N may exceed μ by this much: the return map puts a slipping point's
/// traction on the cone to round-off (measured: 6e-17 above μ at most).
const CONE_SLACK: f64 = 1e-6;
/// At the last step the block slides: Ft/N = μ to this relative accuracy.
const SLIDE_TOL: f64 = 1e-3;

fn main() -> ExitCode {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let (steps, output) = match parse_args(&args) {
        Ok(a) => a,
        Err(message) => {
            eprintln!("block_slide example: {message}");
            return ExitCode::FAILURE;
        }
    };
    let rt = match Runtime::start(&[]) {
        Ok(rt) => rt,
        Err(e) => {
            eprintln!("block_slide example: {e}");
            return ExitCode::FAILURE;
        }
    };
    // The run is collective and every rank reads the same closed file, so
    // every rank takes the same decision; rank 0 alone prints.
    match run(&rt, steps, &output) {
        Ok(true) => ExitCode::SUCCESS,
        Ok(false) => ExitCode::FAILURE,
        Err(message) => {
            if rt.rank() == 0 {
                eprintln!("block_slide example: {message}");
            }
            ExitCode::FAILURE
        }
    }
}

/// `[STEPS] [OUT.h5]`: 20 load steps and out/examples/block_slide.h5 by default.
fn parse_args(args: &[String]) -> Result<(usize, PathBuf), String> {
    if args.len() > 2 {
        return Err("usage: block_slide [STEPS] [OUT.h5]".into());
    }
    let steps = match args.first() {
        Some(s) => s
            .parse::<usize>()
            .ok()
            .filter(|&n| n >= 4)
            .ok_or_else(|| format!("STEPS '{s}' is not a whole number of at least 4"))?,
        None => 20,
    };
    let output = args
        .get(1)
        .map(PathBuf::from)
        .unwrap_or_else(|| PathBuf::from("out/examples/block_slide.h5"));
    Ok((steps, output))
}

/// Runs the slide, reads the file back; Ok(false) when friction misbehaved.
fn run(rt: &Runtime, steps: usize, output: &Path) -> Result<bool, String> {
    let model = model(steps)?;
    let summary =
        pipeline::run_model(rt, &model, Some(output), false).map_err(|e| e.to_string())?;
    // run_model has closed the file: read it back like any other reader would.
    let rows = read_back(output)?;
    let ratios: Vec<f64> = rows.iter().map(|r| r.ft / r.n).collect();
    let within_cone = ratios.iter().all(|&q| q <= MU * (1.0 + CONE_SLACK));
    let slides = ratios
        .last()
        .is_some_and(|&q| (q - MU).abs() <= SLIDE_TOL * MU);
    if rt.rank() == 0 {
        println!(
            "block_slide: {} steps on {} rank(s), μ = {MU}, read back from {}",
            summary.report.steps.len(),
            rt.size(),
            output.display()
        );
        println!(
            "{:>5} {:>6} {:>10} {:>10} {:>8} {:>8}",
            "step", "load", "N", "Ft", "Ft/N", "slipping"
        );
        for (r, q) in rows.iter().zip(&ratios) {
            println!(
                "{:>5} {:>6.3} {:>10.5} {:>10.5} {:>8.5} {:>8}",
                r.step, r.load_factor, r.n, r.ft, q, r.slipping
            );
        }
        if !within_cone {
            println!("FAILED: Ft/N exceeds μ = {MU}");
        }
        if !slides {
            println!("FAILED: the last step does not slide with Ft/N = μ");
        }
    }
    Ok(within_cone && slides)
}

/// One step of the result file.
struct Row {
    step: usize,
    load_factor: f64,
    n: f64,
    ft: f64,
    slipping: usize,
}

/// Every step's contact force split into N and Ft, and the slipping
/// constraints (slave points or nodes, from the state field the pair's
/// formulation writes).
fn read_back(path: &Path) -> Result<Vec<Row>, String> {
    let mut rows = Vec::new();
    for step in open_steps(path).map_err(|e| e.to_string())? {
        let info = read_step_attrs(path, step).map_err(|e| e.to_string())?;
        let points = PairPoints::read(path, step, PAIR).map_err(|e| e.to_string())?;
        let f = points.force;
        let n = (0..3).map(|i| f[i] * NORMAL[i]).sum::<f64>();
        let ft = (0..3)
            .map(|i| (f[i] - n * NORMAL[i]).powi(2))
            .sum::<f64>()
            .sqrt();
        rows.push(Row {
            step,
            load_factor: info.load_factor,
            n,
            ft,
            slipping: points.friction.map_or(0, |f| f.slip),
        });
    }
    Ok(rows)
}

/// The block, its pull and pressure, and the frictional pair with the plane.
fn model(steps: usize) -> Result<Model, String> {
    let mesh = graded_box(&BoxSpec {
        body: "block".into(),
        size: [1.0, 1.0, 0.5],
        divisions: [4, 4, 2],
        ..BoxSpec::default()
    })
    .map_err(|e| e.to_string())?;
    // Pressure on over the first quarter of the load path, then held ...
    let press = Amplitude::from_table(&[[0.0, 0.0], [0.25, 1.0], [1.0, 1.0]])?;
    // ... and the pull after it.
    let pull = Amplitude::from_table(&[[0.0, 0.0], [0.25, 0.0], [1.0, 1.0]])?;
    let top = mesh.node_set("block.top").map_err(|e| e.to_string())?;
    let mut dirichlet =
        DirichletSpec::uniform("block.top", top.to_vec(), vec![0, 1], [PULL, 0.0, 0.0]);
    dirichlet.amplitude = pull;
    let mut pair = PairSpec::new(
        PAIR,
        "block.bottom",
        MasterSpec::Rigid(RigidSurface::Plane {
            point: [0.0; 3],
            normal: NORMAL,
        }),
    );
    // The tangential penalty defaults to the normal one.
    pair.friction = Some(FrictionSpec {
        mu: MU,
        penalty: None,
    });
    Ok(Model {
        name: "block_slide example".into(),
        materials: vec![Material::LinearElastic {
            youngs: 1000.0,
            // No lateral spreading under the pressure: every slip comes
            // from the pull.
            poisson: 0.0,
        }],
        integration: vec![Integration::Full],
        dirichlet: vec![dirichlet],
        facet_loads: vec![("block.top".into(), FacetLoad::Pressure(PRESSURE), press)],
        body_force: vec![[0.0; 3]],
        body_force_fn: None,
        contact: vec![pair],
        hertz: None,
        steps,
        solver: SolverSettings::default(),
        dynamics: None,
        mesh,
    })
}

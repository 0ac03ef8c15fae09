//! The `contactlink` command line: run a scene, list the built-in scenes,
//! check a scene without solving.
use contactlink::pipeline::{self, RunOptions};
use contactlink::runtime::Runtime;
use contactlink::scene::BUILTIN;
use std::path::PathBuf;
use std::process::ExitCode;

const USAGE: &str = "\
contactlink — parallel 3D contact mechanics on PETSc

usage:
  contactlink run SCENE [-o OUT.h5] [--set key=value]... [--restart FROM.h5] [-q] [PETSc options]
  contactlink check SCENE [--set key=value]...
  contactlink scenes
  contactlink help

SCENE is a scene file (TOML) or the name of a built-in scene (see `contactlink scenes`).
Run under MPI with e.g. `mpirun -n 2 contactlink run block-compress -o out.h5`.
--restart FROM.h5 continues a run of the same scene from the last converged step in
FROM.h5 (multipliers and friction history included) and writes the remaining steps to
OUT.h5 (which must be another file), numbered on from there.
Any other option starting with '-' goes to PETSc (e.g. -ksp_type gmres -snes_monitor);
PETSC_OPTIONS in the environment is read too. Options given here override the scene's
[solver] petsc_options and the program's defaults.
";

/// Parsed command line.
struct Cli {
    command: String,
    scene: Option<String>,
    run: RunOptions,
    petsc: Vec<String>,
}

fn parse_args(args: &[String]) -> Result<Cli, String> {
    let mut it = args.iter().peekable();
    let command = it.next().cloned().unwrap_or_else(|| "help".into());
    let mut cli = Cli {
        command,
        scene: None,
        run: RunOptions {
            echo: true,
            ..Default::default()
        },
        petsc: Vec::new(),
    };
    while let Some(a) = it.next() {
        match a.as_str() {
            "-o" | "--output" => {
                let p = it.next().ok_or("-o needs a file name")?;
                cli.run.output = Some(PathBuf::from(p));
            }
            "--set" => {
                let kv = it.next().ok_or("--set needs key=value")?;
                if !kv.contains('=') {
                    return Err(format!("--set {kv}: expected key=value"));
                }
                cli.run.overrides.push(kv.clone());
            }
            "-q" | "--quiet" => cli.run.echo = false,
            "--restart" => {
                let p = it.next().ok_or("--restart needs a result file")?;
                cli.run.restart = Some(PathBuf::from(p));
            }
            s if s.starts_with('-') && s.len() > 1 => {
                cli.petsc.push(s.to_owned());
                if let Some(v) = it.peek() {
                    if !v.starts_with('-') || v.parse::<f64>().is_ok() {
                        cli.petsc.push(it.next().cloned().unwrap_or_default());
                    }
                }
            }
            s => {
                if cli.scene.is_some() {
                    return Err(format!("unexpected argument '{s}'"));
                }
                cli.scene = Some(s.to_owned());
            }
        }
    }
    Ok(cli)
}

fn main() -> ExitCode {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let cli = match parse_args(&args) {
        Ok(c) => c,
        Err(e) => {
            eprintln!("contactlink: {e}\n\n{USAGE}");
            return ExitCode::from(2);
        }
    };
    match cli.command.as_str() {
        "help" | "--help" | "-h" => {
            print!("{USAGE}");
            ExitCode::SUCCESS
        }
        "scenes" => {
            for (name, about, _) in BUILTIN {
                println!("{name:20} {about}");
            }
            ExitCode::SUCCESS
        }
        "check" => match cli.scene.as_deref() {
            Some(scene) => check(scene, &cli.run.overrides),
            None => usage_error("check needs a SCENE"),
        },
        "run" => match cli.scene.as_deref() {
            Some(scene) => run(scene, &cli),
            None => usage_error("run needs a SCENE"),
        },
        other => usage_error(&format!("unknown command '{other}'")),
    }
}

fn usage_error(msg: &str) -> ExitCode {
    eprintln!("contactlink: {msg}\n\n{USAGE}");
    ExitCode::from(2)
}

fn check(scene: &str, overrides: &[String]) -> ExitCode {
    match pipeline::load_model(scene, overrides) {
        Ok((model, out)) => {
            let m = &model.mesh;
            println!("{}", model.name);
            println!(
                "  cells {} ({}), nodes {}, DOFs {}",
                m.num_cells(),
                m.cell_type.name(),
                m.num_nodes(),
                3 * m.num_nodes()
            );
            for (b, mat) in m.bodies.iter().zip(&model.materials) {
                println!("  body {b}: {mat:?}");
            }
            println!(
                "  dirichlet sets: {}",
                model
                    .dirichlet
                    .iter()
                    .map(|d| d.set.as_str())
                    .collect::<Vec<_>>()
                    .join(", ")
            );
            println!(
                "  loads: {}",
                model
                    .facet_loads
                    .iter()
                    .map(|(s, l, _)| format!("{s} {l:?}"))
                    .collect::<Vec<_>>()
                    .join(", ")
            );
            for p in &model.contact {
                let friction = match p.active_friction() {
                    Some(f) => format!(", Coulomb friction μ = {}", f.mu),
                    None => ", frictionless".into(),
                };
                println!(
                    "  contact {}: slave {} master {:?}{friction}",
                    p.name, p.slave, p.master
                );
            }
            match &model.dynamics {
                Some(d) => println!(
                    "  dynamics: Newmark β = {}, γ = {}, Δt = {}, t_end = {}, densities {:?}",
                    d.newmark.beta,
                    d.newmark.gamma,
                    d.time_step,
                    d.time_step * model.steps as f64,
                    d.density
                ),
                None => println!("  quasi-static (no mass matrix)"),
            }
            println!(
                "  steps {}, output {}",
                model.steps,
                out.unwrap_or_else(|| "(none)".into())
            );
            for w in model.warnings() {
                println!("  warning: {w}");
            }
            ExitCode::SUCCESS
        }
        Err(e) => {
            eprintln!("contactlink: {e}");
            ExitCode::FAILURE
        }
    }
}

fn run(scene: &str, cli: &Cli) -> ExitCode {
    let rt = match Runtime::start(&cli.petsc) {
        Ok(rt) => rt,
        Err(e) => {
            eprintln!("contactlink: start-up failed: {e}");
            return ExitCode::FAILURE;
        }
    };
    let rank = rt.rank();
    let result = pipeline::run_scene(&rt, scene, &cli.run);
    let code = match result {
        Ok(summary) => {
            // -q quiets the per-step lines; the summary always prints.
            if rank == 0 {
                let r = &summary.report;
                let newton: usize = r.steps.iter().map(|s| s.newton_iterations).sum();
                println!(
                    "done: {} steps, {} Newton iterations, {} DOFs on {} rank(s), {:.2} s",
                    r.steps.len(),
                    newton,
                    r.global_dofs,
                    rt.size(),
                    r.wall_seconds
                );
                println!("{}", phase_summary(&r.phases, r.wall_seconds));
                if rt.size() > 1 {
                    println!(
                        "  halo (all ranks): {} ghost displacement values per residual, {} ghost multiplier values per Uzawa update",
                        r.halo_displacements, r.halo_multipliers
                    );
                }
                if let Some(last) = r.steps.last() {
                    for (set, f) in &last.reactions {
                        println!(
                            "  reaction on {set}: [{:.6e}, {:.6e}, {:.6e}]",
                            f[0], f[1], f[2]
                        );
                    }
                }
                if let Some(h) = &summary.hertz {
                    println!(
                        "  Hertz: load {:.6e}; p0 computed {:.6e}, analytic {:.6e} ({:+.3} %); half-width/radius computed {:.6e}, analytic {:.6e} ({:+.3} %)",
                        h.load,
                        h.p0,
                        h.p0_exact,
                        100.0 * h.p0_error(),
                        h.width,
                        h.width_exact,
                        100.0 * h.width_error()
                    );
                }
                match &summary.output {
                    Some(p) => println!(
                        "output: {} (+ {}, per-step history {})",
                        p.display(),
                        p.with_extension("xmf").display(),
                        p.with_extension("csv").display()
                    ),
                    None => println!("output: none (give -o FILE.h5)"),
                }
            }
            ExitCode::SUCCESS
        }
        Err(e) => {
            eprintln!("contactlink (rank {rank}): {e}");
            ExitCode::FAILURE
        }
    };
    drop(rt);
    code
}

/// "where the time went" line: each phase's seconds and share of the run.
fn phase_summary(t: &contactlink::solve::phases::PhaseTimes, wall: f64) -> String {
    use contactlink::solve::phases::Phase;
    let share = |s: f64| if wall > 0.0 { 100.0 * s / wall } else { 0.0 };
    let mut parts: Vec<String> = Phase::ALL
        .iter()
        .map(|&p| format!("{} {:.3} s ({:.1} %)", p.name(), t.get(p), share(t.get(p))))
        .collect();
    let other = (wall - t.total()).max(0.0);
    parts.push(format!("other {other:.3} s ({:.1} %)", share(other)));
    format!(
        "  time per phase (largest over ranks): {}",
        parts.join(", ")
    )
}

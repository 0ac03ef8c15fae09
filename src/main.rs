//! The `contactlink` command line: run a scene, list the built-in scenes,
//! check a scene without solving, summarise or plot a result file.
use contactlink::memory::Footprint;
use contactlink::pipeline::{self, RunOptions};
use contactlink::runtime::Runtime;
use contactlink::scene::BUILTIN;
use std::io::IsTerminal;
use std::path::PathBuf;
use std::process::ExitCode;

const USAGE: &str = "\
contactlink — parallel 3D contact mechanics on PETSc

usage:
  contactlink run SCENE [-o OUT.h5] [--set key=value]... [--restart FROM.h5] [-v | -q] [PETSc options]
  contactlink run SCENE --setup-only [--set key=value]... [PETSc options]
  contactlink check SCENE [--set key=value]...
  contactlink summary OUT.h5 [--csv]
  contactlink plot OUT.h5 [-o profile.png] [--step N]
  contactlink scenes
  contactlink help

SCENE is a scene file (TOML) or the name of a built-in scene (see `contactlink scenes`).
Run under MPI with e.g. `mpirun -n 2 contactlink run block-compress -o out.h5`.
--restart FROM.h5 continues a run of the same scene from the last converged step in
FROM.h5 (multipliers and friction history included) and writes the remaining steps to
OUT.h5 (which must be another file), numbered on from there.
Any other option starting with '-' goes to PETSc (e.g. -ksp_type gmres -snes_monitor);
PETSC_OPTIONS in the environment is read too. Options given here override the scene's
[solver] petsc_options and the program's defaults; a run that ends names the ones
nobody read in one warning line.

run prints one line per load step when its output goes to a terminal (under mpirun:
when mpirun's does) or with -v (--verbose),
then a summary (`done:`, time per phase, peak memory per rank and set-up time,
Hertz, `output:`); -q (--quiet) prints nothing on success.
--setup-only stops before the first solve (scene, mesh, partition, DOFs and the
matrix are built) and prints the peak memory per rank and the set-up time.
CONTACTLINK_MEMORY=1 in the environment prints every rank's resident and peak
memory after each set-up phase and each load step to stderr.
summary prints one row per step of a result file: load, iterations, wall time and per
contact pair the force, normal force, contact area, peak pressure and active points
(--csv: the same as CSV).
plot draws a Hertz scene's contact pressure against the closed form to a PNG
(default: OUT.png next to OUT.h5; --step N: that step instead of the last).
";

/// Parsed command line.
struct Cli {
    command: String,
    scene: Option<String>,
    run: RunOptions,
    petsc: Vec<String>,
    /// -v/--verbose: per-step lines even when stdout is not a terminal.
    verbose: bool,
    /// summary --csv.
    csv: bool,
    /// plot --step N.
    step: Option<usize>,
    /// run --setup-only: stop before the first solve.
    setup_only: bool,
}

fn parse_args(args: &[String]) -> Result<Cli, String> {
    let mut it = args.iter().peekable();
    let command = it.next().cloned().unwrap_or_else(|| "help".into());
    let mut cli = Cli {
        command,
        scene: None,
        run: RunOptions::default(),
        petsc: Vec::new(),
        verbose: false,
        csv: false,
        step: None,
        setup_only: false,
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
            "-q" | "--quiet" => cli.run.quiet = true,
            "-v" | "--verbose" => cli.verbose = true,
            "--csv" => cli.csv = true,
            "--setup-only" => cli.setup_only = true,
            "--step" => {
                let n = it.next().ok_or("--step needs a step number")?;
                let n = n
                    .parse()
                    .map_err(|_| format!("--step {n}: expected a step number"))?;
                cli.step = Some(n);
            }
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
    if cli.run.quiet && cli.verbose {
        return Err("-q and -v contradict each other".into());
    }
    // Per-step lines are for a person watching; piped into a file or a
    // script they are noise (scripts parse the summary lines).
    cli.run.echo = !cli.run.quiet && (cli.verbose || output_reaches_terminal());
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
        "summary" | "plot" => match (cli.scene.as_deref(), cli.petsc.first()) {
            (_, Some(opt)) => usage_error(&format!("{}: unknown option '{opt}'", cli.command)),
            (Some(file), None) if cli.command == "summary" => summary(file, cli.csv),
            (Some(file), None) => plot(file, &cli),
            (None, None) => usage_error(&format!("{} needs a result file OUT.h5", cli.command)),
        },
        other => usage_error(&format!("unknown command '{other}'")),
    }
}

/// Whether what this process prints ends up on a terminal. Under Open MPI's
/// mpirun a rank's stdout is a pty the launcher creates even when mpirun's
/// own output goes to a pipe or file, so there the launcher's (the parent
/// process's) stdout decides; where that cannot be read, no.
fn output_reaches_terminal() -> bool {
    if std::env::var_os("OMPI_COMM_WORLD_SIZE").is_none() {
        return std::io::stdout().is_terminal();
    }
    let parent = std::os::unix::process::parent_id();
    std::fs::read_link(format!("/proc/{parent}/fd/1")).is_ok_and(|target| {
        let t = target.to_string_lossy();
        t.starts_with("/dev/pts/") || t.starts_with("/dev/tty")
    })
}

fn usage_error(msg: &str) -> ExitCode {
    eprintln!("contactlink: {msg}\n\n{USAGE}");
    ExitCode::from(2)
}

fn check(scene: &str, overrides: &[String]) -> ExitCode {
    let started = std::time::Instant::now();
    match contactlink::check::load(scene, overrides) {
        Ok(checked) => {
            let seconds = started.elapsed().as_secs_f64();
            print!("{}", contactlink::check::summary(&checked));
            // One process, no partition or matrix: what the model alone costs.
            println!(
                "memory: peak resident {:.1} MiB (this process, model only); scene and mesh built in {seconds:.2} s",
                contactlink::memory::peak_mib().unwrap_or(0.0)
            );
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
    if cli.setup_only {
        return setup_only(rt, scene, cli);
    }
    let rank = rt.rank();
    let result = pipeline::run_scene(&rt, scene, &cli.run);
    // Collective, on every rank whatever the outcome (failures are agreed).
    let footprint = Footprint::over_ranks(&rt.world());
    contactlink::memory::checkpoint("the run");
    // One error line under MPI: failures are agreed (every failing rank
    // holds the same text), so the lowest rank that has it prints it.
    let printer = contactlink::parallel::lowest_rank(&rt.world(), result.is_err());
    // Collective, whatever the outcome.
    let unread = rt.unread_options();
    let code = match result {
        Ok(summary) => {
            if let (0, Some(p)) = (rank, &summary.output) {
                record_footprint(p, &footprint);
            }
            // A run that failed may have stopped before it read them: only
            // a whole run's are reported.
            match &unread {
                Ok(unread) => {
                    if let (0, Some(line)) = (rank, unread_warning(unread)) {
                        eprintln!("{line}");
                    }
                }
                Err(e) if rank == 0 => {
                    eprintln!("contactlink: warning: the unread options: {e}")
                }
                Err(_) => {}
            }
            // The summary prints unless -q (scripts parse its `done:` and
            // `Hertz:` lines); the per-step lines were decided in parse_args.
            if rank == 0 && !cli.run.quiet {
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
                println!("{}", footprint.summary_line());
                if r.preconditioner_builds > 0 {
                    let linear: usize = r.steps.iter().map(|s| s.linear_iterations).sum();
                    println!(
                        "  solver: {} Uzawa iterations, {} linear iterations, preconditioner built {} times and kept {} times",
                        r.steps.iter().map(|s| s.uzawa_iterations).sum::<usize>(),
                        linear,
                        r.preconditioner_builds,
                        r.preconditioner_reuses
                    );
                }
                if let Some(s) = r.schur.as_ref().filter(|s| s.low_rank) {
                    let linear: usize = r.steps.iter().map(|s| s.linear_iterations).sum();
                    println!(
                        "  solver: {} Uzawa iterations, {} linear iterations, contact low-rank update on {} DOFs (MUMPS, {} ranks): bulk stiffness factored {} time(s), {} columns of G = PᵀK⁻¹P in {} request(s) (C grew {} time(s); {:.2} CPU s on rank 0), I + D·G factored {} time(s) ({:.2} CPU s on rank 0); {} solve(s) with K's factor, {} condensed Newton step(s); G's entries probed by {} whole solve(s), {} request(s) redone by whole solves",
                        r.steps.iter().map(|s| s.uzawa_iterations).sum::<usize>(),
                        linear,
                        s.dofs,
                        rt.size(),
                        s.bulk_factorisations,
                        s.inverse_columns,
                        s.inverse_blocks,
                        s.growths,
                        s.inverse_cpu_seconds,
                        s.schur_factorisations,
                        s.dense_cpu_seconds,
                        s.sparse_solves,
                        s.dense_solves,
                        s.probe_solves,
                        s.inverse_redone
                    );
                }
                if let Some(s) = r.schur.as_ref().filter(|s| !s.low_rank) {
                    let linear: usize = r.steps.iter().map(|s| s.linear_iterations).sum();
                    println!(
                        "  solver: {} Uzawa iterations, {} linear iterations, contact Schur complement on {} DOFs (MUMPS, 1 rank): bulk stiffness factored {} time(s) (C grew {} time(s)), Schur complement factored {} time(s) ({} of them on a trailing block alone, of at most {} DOFs, after {} factorisation(s) of S0's leading block); {} solve(s) with the sparse factor, {} with the dense Schur complement alone",
                        r.steps.iter().map(|s| s.uzawa_iterations).sum::<usize>(),
                        linear,
                        s.dofs,
                        s.bulk_factorisations,
                        s.growths,
                        s.schur_factorisations,
                        s.trailing_factorisations,
                        s.largest_trailing,
                        s.leading_factorisations,
                        s.sparse_solves,
                        s.dense_solves
                    );
                }
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
                    if let Some((ep, ew)) = h.averaged_errors() {
                        println!(
                            "  Hertz, nodal pressures read as nodal averages: p0 {:+.3} %, half-width/radius {:+.3} %",
                            100.0 * ep,
                            100.0 * ew
                        );
                    }
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
            if printer == Some(rank) {
                eprintln!("contactlink: {e}");
            }
            failure_code(&e)
        }
    };
    drop(rt);
    code
}

/// 1 for a failed run; 128 + the signal's number for a run stopped by
/// SIGTERM or SIGINT, the shell's convention batch systems look for.
fn failure_code(e: &contactlink::Error) -> ExitCode {
    match e {
        contactlink::Error::Stopped { signal, .. } => {
            ExitCode::from(u8::try_from(128 + signal).unwrap_or(1))
        }
        _ => ExitCode::FAILURE,
    }
}

/// The flags of `contactlink run` that take a value, and what the value is:
/// an option nobody read that starts with one of them and '=' or a space
/// is the flag glued to its value (`'--set output.path=x.h5'` as one word,
/// which starts with '-' and so went to PETSc).
const VALUE_FLAGS: [(&str, &str); 5] = [
    ("--set", "key=value"),
    ("--output", "the file name"),
    ("--restart", "the file name"),
    ("--step", "the step number"),
    ("-o", "the file name"),
];

/// The one warning line naming the options nobody read (name, value),
/// with what was meant where one is a flag of ours glued to its value.
fn unread_warning(unread: &[(String, String)]) -> Option<String> {
    if unread.is_empty() {
        return None;
    }
    let named: Vec<String> = unread
        .iter()
        .map(|(key, value)| {
            let word = if value.is_empty() {
                key.clone()
            } else {
                format!("{key} {value}")
            };
            let glued = VALUE_FLAGS.iter().find(|(flag, _)| {
                key.strip_prefix(flag)
                    .is_some_and(|rest| rest.starts_with(['=', ' ']))
            });
            match glued {
                Some((flag, what)) => {
                    format!("'{word}' (pass {flag} and {what} as two words)")
                }
                None => word,
            }
        })
        .collect();
    Some(format!(
        "contactlink: warning: PETSc options nobody read: {}",
        named.join(", ")
    ))
}

/// `/footprint` in the closed result file; a failure only warns (the
/// results are written; the other ranks have moved on).
fn record_footprint(path: &std::path::Path, footprint: &Footprint) {
    if let Err(e) = contactlink::results::footprint::write(path, footprint) {
        eprintln!("contactlink: warning: {e}");
    }
}

/// `contactlink run SCENE --setup-only`.
fn setup_only(rt: Runtime, scene: &str, cli: &Cli) -> ExitCode {
    let rank = rt.rank();
    let result = contactlink::setup_only::setup_only(&rt, scene, &cli.run.overrides);
    let footprint = Footprint::over_ranks(&rt.world());
    let printer = contactlink::parallel::lowest_rank(&rt.world(), result.is_err());
    let code = match result {
        Ok(s) => {
            if rank == 0 && !cli.run.quiet {
                println!(
                    "set-up only: {}: {} cells, {} nodes, {} DOFs on {} rank(s), {:.2} s",
                    s.model_name,
                    s.cells,
                    s.nodes,
                    s.global_dofs,
                    rt.size(),
                    footprint.setup_seconds
                );
                println!("{}", footprint.summary_line());
            }
            ExitCode::SUCCESS
        }
        Err(e) => {
            if printer == Some(rank) {
                eprintln!("contactlink: {e}");
            }
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

/// `contactlink summary OUT.h5 [--csv]`.
fn summary(file: &str, csv: bool) -> ExitCode {
    use contactlink::results::summary;
    let path = std::path::Path::new(file);
    match summary::summarize(path) {
        Ok(rows) if csv => {
            print!("{}", summary::csv(&rows));
            ExitCode::SUCCESS
        }
        Ok(rows) => {
            print!("{}", summary::table(path, &rows));
            match contactlink::results::footprint::read(path) {
                Ok(Some(fp)) => println!("{}", fp.summary_line().trim_start()),
                Ok(None) => {}
                Err(e) => eprintln!("contactlink: warning: {e}"),
            }
            ExitCode::SUCCESS
        }
        Err(e) => {
            eprintln!("contactlink: {e}");
            ExitCode::FAILURE
        }
    }
}

/// `contactlink plot OUT.h5 [-o profile.png] [--step N]`.
fn plot(file: &str, cli: &Cli) -> ExitCode {
    let path = std::path::Path::new(file);
    let output = cli
        .run
        .output
        .clone()
        .unwrap_or_else(|| path.with_extension("png"));
    let input = contactlink::output::paths::Input {
        what: "result file",
        path: path.to_path_buf(),
    };
    if let Err(e) = contactlink::output::paths::check_not_same(&output, &input) {
        eprintln!("contactlink: {e}");
        return ExitCode::FAILURE;
    }
    match contactlink::results::plot::plot(path, &output, cli.step) {
        Ok(r) => {
            let errors = r.comparison.map_or(String::new(), |c| {
                let averaged = c.averaged_errors().map_or(String::new(), |(p, w)| {
                    format!(
                        " (read as nodal averages: p0 {:+.3} %, half-width/radius {:+.3} %)",
                        100.0 * p,
                        100.0 * w
                    )
                });
                format!(
                    ": p0 {:+.3} %, half-width/radius {:+.3} % against the closed form{averaged}",
                    100.0 * c.p0_error(),
                    100.0 * c.width_error()
                )
            });
            println!("plot: step {} → {}{errors}", r.step, r.output.display());
            ExitCode::SUCCESS
        }
        Err(e) => {
            eprintln!("contactlink: {e}");
            ExitCode::FAILURE
        }
    }
}

#[cfg(test)]
mod tests {
    use super::unread_warning;

    fn pairs(p: &[(&str, &str)]) -> Vec<(String, String)> {
        p.iter()
            .map(|(k, v)| (k.to_string(), v.to_string()))
            .collect()
    }

    #[test]
    fn the_unread_options_make_one_line() {
        assert_eq!(unread_warning(&[]), None);
        assert_eq!(
            unread_warning(&pairs(&[("-ksp_tpye", "gmres"), ("-snes_monitr", "")])).unwrap(),
            "contactlink: warning: PETSc options nobody read: -ksp_tpye gmres, -snes_monitr"
        );
    }

    #[test]
    fn a_flag_glued_to_its_value_is_told_apart() {
        let line = unread_warning(&pairs(&[
            ("--set output.path=x.h5", ""),
            ("-o=out.h5", ""),
            ("-options_file", "x"),
        ]))
        .unwrap();
        assert!(
            line.contains("'--set output.path=x.h5' (pass --set and key=value as two words)"),
            "{line}"
        );
        assert!(
            line.contains("'-o=out.h5' (pass -o and the file name as two words)"),
            "{line}"
        );
        assert!(line.ends_with(", -options_file x"), "{line}");
    }
}

//! One run end to end: scene → model → set-up (partition, DOFs) → output file
//! created (so an unwritable path fails before any solve) → load steps → summary.
//! A run of a scene reads the mesh on rank 0 only (`load`).
pub mod load;

use crate::error::Result;
use crate::hertz::{HertzCheck, HertzComparison, NodalSample};
use crate::model::Model;
use crate::output::paths::{check_not_input, Input};
use crate::output::{create_result_file, Hdf5Sink, HistoryCsv, Provenance, Tee};
use crate::parallel::gather_all;
use crate::petsc::Vector;
use crate::runtime::Runtime;
use crate::scene::{self, SceneSource};
use crate::solve::{PairFields, RunReport, Simulation, StepReport, StepSink};
use mpi::traits::CommunicatorCollectives;
use std::collections::HashSet;
use std::path::{Path, PathBuf};

/// How to run a scene.
#[derive(Debug, Clone, Default)]
pub struct RunOptions {
    /// Output file; when None, the scene's [output] path; when neither, no file.
    pub output: Option<PathBuf>,
    /// `--set key=value` overrides of scene keys.
    pub overrides: Vec<String>,
    /// Print one line per step (and per cutback) on rank 0.
    pub echo: bool,
    /// Continue from the last converged step of this result file.
    pub restart: Option<PathBuf>,
    /// Print nothing on success, not even the model's header line.
    pub quiet: bool,
}

/// What a run prints on rank 0.
#[derive(Debug, Clone, Copy)]
struct Printing {
    /// The one-line model summary before the first step.
    header: bool,
    /// One line per step and per cutback.
    steps: bool,
}

/// What a run produced.
pub struct RunSummary {
    pub model_name: String,
    pub report: RunReport,
    /// Hertz comparison at the last step, when the scene asks for one.
    pub hertz: Option<HertzComparison>,
    pub output: Option<PathBuf>,
    pub cells: usize,
    pub nodes: usize,
}

/// Loads a scene by built-in name or path and builds its model.
pub fn load_model(name_or_path: &str, overrides: &[String]) -> Result<(Model, Option<String>)> {
    let src = SceneSource::resolve(name_or_path)?;
    let built = build_model(&src, overrides)?;
    Ok((built.model, built.output))
}

/// A scene's model, its `[output] path`, the files it reads (scene, mesh
/// and what the mesh includes), which no output may replace, and the notes
/// about the mesh a run prints once.
struct Built {
    model: Model,
    output: Option<String>,
    inputs: Vec<Input>,
    notes: Vec<String>,
}

/// Builds the model of a resolved scene.
fn build_model(src: &SceneSource, overrides: &[String]) -> Result<Built> {
    let parsed = scene::parse(src, overrides)?;
    let (model, report) = parsed.build_with_report(&src.origin)?;
    let scene_file = src.path.clone().map(|path| Input {
        what: "scene file",
        path,
    });
    let mesh_files = parsed
        .mesh_file(&src.origin)
        .into_iter()
        .chain(report.included_files())
        .map(|path| Input {
            what: "mesh file",
            path,
        });
    Ok(Built {
        model,
        output: parsed.output_path().map(str::to_owned),
        inputs: scene_file.into_iter().chain(mesh_files).collect(),
        notes: report.notes(),
    })
}

/// Runs a scene on all ranks of the runtime.
pub fn run_scene(rt: &Runtime, name_or_path: &str, opts: &RunOptions) -> Result<RunSummary> {
    crate::parallel::fault::arm(rt.rank())?;
    // Rank 0 alone builds the mesh; a restart needs none of it (the file is
    // checked against each rank's piece after set-up).
    let mut loaded = load::on_root(&rt.world(), name_or_path, &opts.overrides)?;
    let output = opts
        .output
        .clone()
        .or(loaded.output.take().map(PathBuf::from));
    let restart = opts
        .restart
        .as_ref()
        .map(|from| read_restart(from, output.as_deref(), &loaded.model))
        .transpose()?;
    if rt.rank() == 0 && !opts.quiet {
        for note in &loaded.notes {
            eprintln!("contactlink: note: {note}");
        }
    }
    let mut inputs = std::mem::take(&mut loaded.inputs);
    if let Some(out) = &output {
        // Every rank sees the same paths and files: the same answer.
        inputs.extend(opts.restart.clone().map(|path| Input {
            what: "restart file",
            path,
        }));
        check_not_input(out, &inputs).map_err(std::io::Error::other)?;
    }
    let provenance = Provenance {
        scene: std::mem::take(&mut loaded.scene_text),
        overrides: opts.overrides.clone(),
    };
    let printing = Printing {
        header: !opts.quiet,
        steps: opts.echo && !opts.quiet,
    };
    // The set-up frees the mesh once each rank has its piece.
    let mesh = loaded.take_mesh();
    run_model_with(
        rt,
        &loaded.model,
        Some(mesh),
        output.as_deref(),
        printing,
        Some(&provenance),
        restart.as_ref(),
    )
}

/// The file to continue from, checked before set-up (what needs no mesh);
/// its rows are read after set-up, by each rank for its piece.
fn read_restart(
    from: &Path,
    output: Option<&Path>,
    model: &Model,
) -> Result<crate::restart::RestartFile> {
    let same = |out: &Path| match (out.canonicalize(), from.canonicalize()) {
        (Ok(a), Ok(b)) => a == b,
        _ => out == from,
    };
    if output.is_some_and(same) {
        return Err(crate::Error::Restart(format!(
            "{}: the continued run would overwrite the file it continues from; give another output file with -o",
            from.display()
        )));
    }
    // Every rank reads the file on its own: one rank's failure (a read
    // error, a file system hiccup) is every rank's, named by that rank.
    let world = mpi::topology::SimpleCommunicator::world();
    let read = crate::parallel::fault::check(crate::parallel::fault::FaultPhase::RestartRead)
        .and_then(|()| crate::restart::open(from, model));
    crate::parallel::agree(&world, read)
}

/// Runs an already built model, writing `output` when given.
pub fn run_model(
    rt: &Runtime,
    model: &Model,
    output: Option<&Path>,
    echo: bool,
) -> Result<RunSummary> {
    let printing = Printing {
        header: echo,
        steps: echo,
    };
    run_model_with(rt, model, None, output, printing, None, None)
}

/// `mesh`: the model's mesh moved out of it (freed after the distribution),
/// or None to set up from `model.mesh`.
fn run_model_with(
    rt: &Runtime,
    model: &Model,
    mesh: Option<crate::mesh::Mesh>,
    output: Option<&Path>,
    printing: Printing,
    provenance: Option<&Provenance>,
    restart: Option<&crate::restart::RestartFile>,
) -> Result<RunSummary> {
    let echo = printing.steps;
    if rt.rank() == 0 {
        for w in model.warnings() {
            eprintln!("contactlink: warning: {w}");
        }
    }
    if let Some(path) = output {
        // Before the partition and any solve: an unwritable result path
        // would otherwise show up only after set-up.
        check_output_writable(rt, path)?;
    }
    let mut sim = match mesh {
        Some(mesh) => Simulation::setup_with_mesh(rt, model, mesh)?,
        None => Simulation::setup(rt, model)?,
    };
    // Each rank reads its rows of the file, now that it has its piece
    // (before the result file exists: a mismatch leaves nothing behind).
    let restart = restart
        .map(|file| crate::restart::read(file, &sim))
        .transpose()?;
    let restart = restart.as_ref();
    if printing.header && rt.rank() == 0 {
        println!(
            "{}: {} cells, {} nodes, {} DOFs, {} rank(s), {} load step(s)",
            model.name,
            sim.local_mesh().global_cells,
            sim.local_mesh().global_nodes,
            3 * sim.local_mesh().global_nodes,
            rt.size(),
            model.steps
        );
    }
    let mut hertz = HertzObserver::new(rt, model);
    let report = match output {
        Some(path) => {
            if rt.rank() == 0 {
                if let Some(dir) = path.parent().filter(|d| !d.as_os_str().is_empty()) {
                    // A missing directory is created; a failure shows up as the
                    // file-creation error below, on every rank.
                    let _ = std::fs::create_dir_all(dir);
                }
            }
            rt.world().barrier();
            let file = create_result_file(rt, &sim, path, provenance)?;
            let history = HistoryCsv::create(rt, &path.with_extension("csv"))?;
            // HDF5 first: its step is flushed before the CSV row appears, so
            // a run killed at any moment has every step the CSV lists.
            let mut sink = Tee(history, &mut hertz);
            let mut sink = Tee(Hdf5Sink::new(file, &sim)?, &mut sink);
            sim.run(rt, &mut sink, echo, restart)?
        }
        None => sim.run(rt, &mut hertz, echo, restart)?,
    };
    if let Some(path) = output {
        // The file is closed (its sinks are gone): rank 0 adds the run's
        // totals and the last Hertz comparison, which tests and benchmark
        // scripts read instead of the printed summary.
        let written = if rt.rank() == 0 {
            let record = crate::output::RunRecord::of(&report, rt.size());
            crate::output::write_run_record(path, &record, hertz.last.as_ref()).map_err(Into::into)
        } else {
            Ok(())
        };
        crate::parallel::agree(&rt.world(), written)?;
    }
    Ok(RunSummary {
        model_name: model.name.clone(),
        report,
        hertz: hertz.last,
        output: output.map(Path::to_path_buf),
        cells: sim.local_mesh().global_cells,
        nodes: sim.local_mesh().global_nodes,
    })
}

/// Compares the named pair against Hertz after every step (all ranks take
/// part: the pair's points are gathered from every rank).
struct HertzObserver {
    world: mpi::topology::SimpleCommunicator,
    check: Option<HertzCheck>,
    last: Option<HertzComparison>,
}

impl HertzObserver {
    fn new(rt: &Runtime, model: &Model) -> Self {
        HertzObserver {
            world: rt.world(),
            check: model.hertz.clone(),
            last: None,
        }
    }
}

impl HertzObserver {
    /// Collective: the shape-function samples of every loaded slave node
    /// (pressure > 0), from all ranks, for the nodal-average fit.
    fn loaded_node_samples(
        &self,
        pair: &crate::contact::ContactPair,
        points: &[[f64; 3]],
        pressure: &[f64],
    ) -> Vec<NodalSample> {
        let key = |x: &[f64; 3]| x.map(f64::to_bits);
        let loaded: HashSet<[u64; 3]> = points
            .iter()
            .zip(pressure)
            .filter(|(_, &p)| p > 0.0)
            .map(|(x, _)| key(x))
            .collect();
        let mine: Vec<f64> = pair
            .nodal_samples(&|x| loaded.contains(&key(x)))
            .iter()
            .flat_map(|s| s.node.into_iter().chain(s.at).chain([s.weight]))
            .collect();
        gather_all(&self.world, &mine)
            .chunks_exact(7)
            .map(|c| NodalSample {
                node: [c[0], c[1], c[2]],
                at: [c[3], c[4], c[5]],
                weight: c[6],
            })
            .collect()
    }
}

impl StepSink for HertzObserver {
    fn step(
        &mut self,
        report: &StepReport,
        _: &Vector,
        _: &Vector,
        contact: &[PairFields],
        _: &[f64],
        _: Option<&Vector>,
    ) -> Result<()> {
        let Some(check) = &self.check else {
            return Ok(());
        };
        let Some((i, fields)) = contact
            .iter()
            .enumerate()
            .find(|(_, f)| f.pair.spec.name == check.pair)
        else {
            return Ok(());
        };
        // Nodal pressures: the point multipliers of an over-constrained slave
        // surface are not unique, the nodal forces they add up to are.
        let points: Vec<f64> = fields
            .output
            .nodes
            .iter()
            .flat_map(|(x, _)| x.iter().copied())
            .collect();
        let pressure: Vec<f64> = fields.output.nodes.iter().map(|(_, p)| *p).collect();
        let points = gather_all(&self.world, &points);
        let pressure = gather_all(&self.world, &pressure);
        let points: Vec<[f64; 3]> = points.chunks_exact(3).map(|c| [c[0], c[1], c[2]]).collect();
        let samples = self.loaded_node_samples(fields.pair, &points, &pressure);
        let force = report.contact.get(i).map_or([0.0; 3], |c| c.force);
        self.last = crate::hertz::compare(check, &points, &pressure, &samples, force);
        Ok(())
    }
}

/// Collective: fails on every rank with rank 0's message, naming the path,
/// when rank 0 cannot create the result file (or its directory). Only rank 0
/// tries, as only one process should create directories and probe files.
fn check_output_writable(rt: &Runtime, path: &Path) -> Result<()> {
    let mine = match rt.rank() {
        0 => probe_writable(path).err().unwrap_or_default(),
        _ => String::new(),
    };
    let message = crate::parallel::broadcast_text(&rt.world(), 0, &mine);
    if message.is_empty() {
        return Ok(());
    }
    Err(std::io::Error::other(message).into())
}

/// Whether `path` can be written: its directory is created if missing, an
/// existing file is opened for writing (not truncated), a new one is created
/// and removed again, so a failed run leaves no empty result file behind.
fn probe_writable(path: &Path) -> std::result::Result<(), String> {
    let fail = |e: std::io::Error| format!("cannot write the result file {}: {e}", path.display());
    if let Some(dir) = path.parent().filter(|d| !d.as_os_str().is_empty()) {
        std::fs::create_dir_all(dir).map_err(|e| {
            format!(
                "cannot write the result file {}: cannot create its directory {}: {e}",
                path.display(),
                dir.display()
            )
        })?;
    }
    if path.is_dir() {
        return Err(format!("the result file {} is a directory", path.display()));
    }
    if path.exists() {
        std::fs::OpenOptions::new()
            .write(true)
            .open(path)
            .map_err(fail)?;
        return Ok(());
    }
    std::fs::OpenOptions::new()
        .write(true)
        .create_new(true)
        .open(path)
        .map_err(fail)?;
    std::fs::remove_file(path).map_err(fail)
}

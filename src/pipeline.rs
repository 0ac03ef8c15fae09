//! One run end to end: scene → model → set-up (partition, DOFs) → output file
//! created (so an unwritable path fails before any solve) → load steps → summary.
use crate::dofs::even_block;
use crate::error::Result;
use crate::mesh::Mesh;
use crate::output::paths::{check_not_input, Input};
use crate::output::{BlockRows, FacetSetOut, MeshHeader, ResultFile, StepInfo};
use crate::petsc::Vector;
use crate::runtime::Runtime;
use crate::scene::{self, SceneSource};
use crate::solve::phases::Phase;
use crate::solve::{Model, NaturalOrder, PairFields, RunReport, Simulation, StepReport, StepSink};
use crate::verify::{HertzCheck, HertzComparison, HertzKind};
use mpi::traits::{Communicator, CommunicatorCollectives};
use std::collections::BTreeMap;
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

/// Where a run came from, stored in the result file (`/scene`,
/// `/scene_overrides`) so a result can be traced to its input.
#[derive(Debug, Clone, Default)]
pub struct Provenance {
    /// The scene's TOML text as loaded (before overrides).
    pub scene: String,
    /// The `--set key=value` overrides, in order.
    pub overrides: Vec<String>,
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
    let (model, output, _) = build_model(&src, overrides)?;
    Ok((model, output))
}

/// Builds the model of a resolved scene; returns its [output] path and the
/// files it reads (scene, mesh), which no output may replace.
fn build_model(
    src: &SceneSource,
    overrides: &[String],
) -> Result<(Model, Option<String>, Vec<Input>)> {
    let parsed = scene::parse(src, overrides)?;
    let model = parsed.build(&src.origin)?;
    let scene_file = src.path.clone().map(|path| Input {
        what: "scene file",
        path,
    });
    let mesh_file = parsed.mesh_file(&src.origin).map(|path| Input {
        what: "mesh file",
        path,
    });
    let inputs = scene_file.into_iter().chain(mesh_file).collect();
    Ok((model, parsed.output_path().map(str::to_owned), inputs))
}

/// Runs a scene on all ranks of the runtime.
pub fn run_scene(rt: &Runtime, name_or_path: &str, opts: &RunOptions) -> Result<RunSummary> {
    crate::parallel::fault::arm(rt.rank())?;
    let src = SceneSource::resolve(name_or_path)?;
    let (model, scene_out, mut inputs) = build_model(&src, &opts.overrides)?;
    let output = opts.output.clone().or(scene_out.map(PathBuf::from));
    let restart = match &opts.restart {
        Some(from) => Some(read_restart(from, output.as_deref(), &model)?),
        None => None,
    };
    if let Some(out) = &output {
        // Every rank sees the same paths and files: the same answer.
        inputs.extend(opts.restart.clone().map(|path| Input {
            what: "restart file",
            path,
        }));
        check_not_input(out, &inputs).map_err(std::io::Error::other)?;
    }
    let provenance = Provenance {
        scene: src.text,
        overrides: opts.overrides.clone(),
    };
    let printing = Printing {
        header: !opts.quiet,
        steps: opts.echo && !opts.quiet,
    };
    run_model_with(
        rt,
        &model,
        output.as_deref(),
        printing,
        Some(&provenance),
        restart.as_ref(),
    )
}

/// The state to continue from, read before anything is solved or written.
fn read_restart(
    from: &Path,
    output: Option<&Path>,
    model: &Model,
) -> Result<crate::solve::RestartState> {
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
        .and_then(|()| crate::restart::read(from, model));
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
    run_model_with(rt, model, output, printing, None, None)
}

fn run_model_with(
    rt: &Runtime,
    model: &Model,
    output: Option<&Path>,
    printing: Printing,
    provenance: Option<&Provenance>,
    restart: Option<&crate::solve::RestartState>,
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
    let mut sim = Simulation::setup(rt, model)?;
    if printing.header && rt.rank() == 0 {
        println!(
            "{}: {} cells, {} nodes, {} DOFs, {} rank(s), {} load step(s)",
            model.name,
            model.mesh.num_cells(),
            model.mesh.num_nodes(),
            3 * model.mesh.num_nodes(),
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
    Ok(RunSummary {
        model_name: model.name.clone(),
        report,
        hertz: hertz.last,
        output: output.map(Path::to_path_buf),
        cells: model.mesh.num_cells(),
        nodes: model.mesh.num_nodes(),
    })
}

/// Per-step history as CSV next to the HDF5 file (rank 0 writes it): load
/// factor, time, iterations, each pair's contact force (vector, normal and
/// tangential parts, active and sliding points), each Dirichlet set's
/// reaction, and in dynamics the energies and momentum. One row per
/// converged step, flushed as it goes.
struct HistoryCsv {
    out: Option<std::io::BufWriter<std::fs::File>>,
    path: PathBuf,
    header_written: bool,
}

impl HistoryCsv {
    fn create(rt: &Runtime, path: &Path) -> Result<Self> {
        let out = if rt.rank() == 0 {
            let f = std::fs::File::create(path).map_err(|e| {
                std::io::Error::new(e.kind(), format!("cannot create {}: {e}", path.display()))
            });
            Some(f.map(std::io::BufWriter::new))
        } else {
            None
        };
        let out = crate::parallel::agree(&rt.world(), out.transpose().map_err(Into::into))?;
        Ok(HistoryCsv {
            out,
            path: path.to_path_buf(),
            header_written: false,
        })
    }

    fn header(report: &StepReport) -> Vec<String> {
        let mut h: Vec<String> = ["step", "load_factor", "time", "newton", "uzawa"]
            .iter()
            .map(|s| s.to_string())
            .collect();
        for c in &report.contact {
            for k in [
                "fx",
                "fy",
                "fz",
                "normal",
                "tangential",
                "active",
                "sliding",
            ] {
                h.push(format!("{}.{k}", c.name));
            }
        }
        for (i, (set, _)) in report.reactions.iter().enumerate() {
            for k in ["rx", "ry", "rz"] {
                h.push(format!("dirichlet{i}:{set}.{k}"));
            }
        }
        if report.dynamics.is_some() {
            for k in ["kinetic", "strain", "px", "py", "pz"] {
                h.push(k.to_string());
            }
        }
        h.extend(Phase::ALL.iter().map(|p| p.key().to_string()));
        h
    }

    fn row(report: &StepReport) -> Vec<String> {
        let time = report.dynamics.map_or(report.load_factor, |d| d.time);
        let mut r = vec![
            report.index.to_string(),
            format!("{:.12e}", report.load_factor),
            format!("{time:.12e}"),
            report.newton_iterations.to_string(),
            report.uzawa_iterations.to_string(),
        ];
        let num = |v: f64| format!("{v:.12e}");
        for c in &report.contact {
            r.extend(c.force.iter().map(|v| num(*v)));
            r.push(num(c.normal_force));
            r.push(num(c.tangential_force));
            r.push(c.active_points.to_string());
            r.push(c.sliding_points.to_string());
        }
        for (_, f) in &report.reactions {
            r.extend(f.iter().map(|v| num(*v)));
        }
        if let Some(d) = &report.dynamics {
            r.push(num(d.kinetic));
            r.push(num(d.strain));
            r.extend(d.momentum.iter().map(|v| num(*v)));
        }
        r.extend(
            Phase::ALL
                .iter()
                .map(|&p| format!("{:.6e}", report.phases.get(p))),
        );
        r
    }
}

impl StepSink for HistoryCsv {
    fn step(
        &mut self,
        report: &StepReport,
        _: &Vector,
        _: &Vector,
        _: &[PairFields],
        _: &[f64],
        _: Option<&Vector>,
    ) -> Result<()> {
        use std::io::Write;
        let Some(out) = &mut self.out else {
            return Ok(());
        };
        let mut write = || -> std::io::Result<()> {
            if !self.header_written {
                writeln!(out, "{}", Self::header(report).join(","))?;
            }
            writeln!(out, "{}", Self::row(report).join(","))?;
            out.flush()
        };
        // Only rank 0 writes, so a failure here must not end the run (the
        // other ranks would wait in the next collective): warn and stop.
        match write() {
            Ok(()) => self.header_written = true,
            Err(e) => {
                eprintln!(
                    "contactlink: warning: writing {} failed ({e}); no further history rows",
                    self.path.display()
                );
                self.out = None;
            }
        }
        Ok(())
    }
}

/// Two sinks in a row.
struct Tee<'a, A: StepSink>(A, &'a mut dyn StepSink);

impl<A: StepSink> StepSink for Tee<'_, A> {
    fn step(
        &mut self,
        report: &StepReport,
        u: &Vector,
        r: &Vector,
        contact: &[PairFields],
        nodal: &[f64],
        velocity: Option<&Vector>,
    ) -> Result<()> {
        self.0.step(report, u, r, contact, nodal, velocity)?;
        self.1.step(report, u, r, contact, nodal, velocity)
    }
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
            .values
            .nodes
            .iter()
            .flat_map(|(x, _)| x.iter().copied())
            .collect();
        let pressure: Vec<f64> = fields.values.nodes.iter().map(|(_, p)| *p).collect();
        let points = gather_all(&self.world, &points);
        let pressure = gather_all(&self.world, &pressure);
        let points: Vec<[f64; 3]> = points.chunks_exact(3).map(|c| [c[0], c[1], c[2]]).collect();
        let force = report.contact.get(i).map_or([0.0; 3], |c| c.force);
        self.last = crate::verify::compare(check, &points, &pressure, force);
        Ok(())
    }
}

/// Concatenates every rank's slice, in rank order, on every rank.
fn gather_all(world: &mpi::topology::SimpleCommunicator, local: &[f64]) -> Vec<f64> {
    use mpi::datatype::PartitionMut;
    let n = local.len() as i32;
    let mut counts = vec![0i32; world.size() as usize];
    world.all_gather_into(&n, &mut counts[..]);
    let displs: Vec<i32> = counts
        .iter()
        .scan(0, |acc, &c| {
            let d = *acc;
            *acc += c;
            Some(d)
        })
        .collect();
    let mut all = vec![0.0; counts.iter().sum::<i32>() as usize];
    let mut partition = PartitionMut::new(&mut all[..], counts, displs);
    world.all_gather_varcount_into(local, &mut partition);
    all
}

/// Scatters of one contact pair's point arrays into output order.
struct PairOrder {
    scalar: NaturalOrder,
    vector: NaturalOrder,
    rows: usize,
}

/// Writes every converged step to the HDF5 file, in natural (input) order.
struct Hdf5Sink {
    file: ResultFile,
    natural: NaturalOrder,
    natural_scalar: NaturalOrder,
    pairs: Vec<PairOrder>,
    nodes: usize,
}

impl Hdf5Sink {
    fn new(file: ResultFile, sim: &Simulation) -> Result<Self> {
        let dofs = sim.dofs();
        let mut pairs = Vec::new();
        for p in sim.contact() {
            let nqp = p.slave.nqp;
            let rows = p.slave.global_facets * nqp;
            let petsc_row = |nat: usize| p.multipliers.global_point(nat / nqp, nat % nqp, nqp);
            let owned = p.slave.num_qps();
            pairs.push(PairOrder {
                scalar: NaturalOrder::new(rows, 1, owned, petsc_row, dofs.rank, dofs.nranks)?,
                vector: NaturalOrder::new(rows, 3, owned, petsc_row, dofs.rank, dofs.nranks)?,
                rows,
            });
        }
        Ok(Hdf5Sink {
            file,
            natural: NaturalOrder::nodal(dofs)?,
            natural_scalar: NaturalOrder::nodal_scalar(dofs)?,
            pairs,
            nodes: sim.model().mesh.num_nodes(),
        })
    }

    fn write_pair(
        &mut self,
        step: usize,
        i: usize,
        fields: &PairFields,
        report: &StepReport,
    ) -> Result<()> {
        let name = &fields.pair.spec.name;
        let v = &fields.values;
        let flat = |a: &[[f64; 3]]| -> Vec<f64> { a.iter().flatten().copied().collect() };
        let mut vectors = vec![("points", flat(&v.points))];
        let mut scalars = vec![
            ("pressure", v.pressure.clone()),
            ("gap", v.gap.clone()),
            ("lambda_n", v.lambda.clone()),
            ("weight", v.weight.clone()),
        ];
        // Decided by the pair, not by this rank's points: a rank may own no
        // slave point, and every rank must write the same datasets.
        if fields.pair.has_friction() {
            vectors.push(("traction_t", flat(&v.traction)));
            vectors.push(("slip", flat(&v.slip)));
            // 0 open, 1 stick, 2 slip (stored as f64 like every step array).
            scalars.push(("state", v.state.iter().map(|&s| f64::from(s)).collect()));
            // The friction history, so `run --restart` continues exactly.
            let records = &v.records;
            vectors.push((
                "lambda_t",
                flat(&records.iter().map(|r| r.lambda).collect::<Vec<_>>()),
            ));
            vectors.push((
                "slip_origin",
                flat(&records.iter().map(|r| r.origin).collect::<Vec<_>>()),
            ));
            vectors.push((
                "history_ids",
                flat(&records.iter().map(|r| r.ids).collect::<Vec<_>>()),
            ));
        }
        let order = &mut self.pairs[i];
        let rows = order.rows;
        for (cols, label, values) in vectors
            .iter()
            .map(|(l, d)| (3, l, d))
            .chain(scalars.iter().map(|(l, d)| (1, l, d)))
        {
            let scatter = if cols == 3 {
                &mut order.vector
            } else {
                &mut order.scalar
            };
            let (start, data) = scatter.block_of_owned(values)?;
            self.file.write_step_block(
                step,
                &format!("contact/{name}/{label}"),
                BlockRows {
                    global_rows: rows,
                    start,
                    cols,
                    data: &data,
                },
            )?;
        }
        if let Some(m) = &v.mortar {
            self.write_mortar_nodes(step, name, m)?;
        }
        let force = report.contact.get(i).map_or([0.0; 3], |c| c.force);
        self.file
            .write_step_small(step, &format!("contact/{name}/force"), &force)?;
        // The pair's penalty (raised when Uzawa was slow), for a restart.
        self.file.write_step_small(
            step,
            &format!("contact/{name}/penalty"),
            &[fields.pair.penalty],
        )?;
        Ok(())
    }
}

impl Hdf5Sink {
    /// A mortar pair's nodal fields, mesh-node rows in input order (zero off
    /// the slave surface): `node_lambda`, `node_weighted_gap`, `node_traction`.
    fn write_mortar_nodes(
        &mut self,
        step: usize,
        name: &str,
        m: &crate::contact::mortar::pair::NodeFields,
    ) -> Result<()> {
        let traction: Vec<f64> = m.traction.iter().flatten().copied().collect();
        for (label, cols, values) in [
            ("node_lambda", 1, &m.lambda),
            ("node_weighted_gap", 1, &m.weighted_gap),
            ("node_traction", 3, &traction),
        ] {
            let order = if cols == 3 {
                &mut self.natural
            } else {
                &mut self.natural_scalar
            };
            let (start, data) = order.block_of_owned(values)?;
            self.file.write_step_block(
                step,
                &format!("contact/{name}/{label}"),
                BlockRows {
                    global_rows: self.nodes,
                    start,
                    cols,
                    data: &data,
                },
            )?;
        }
        Ok(())
    }
}

impl StepSink for Hdf5Sink {
    fn step(
        &mut self,
        report: &StepReport,
        displacement: &Vector,
        reaction: &Vector,
        contact: &[PairFields],
        nodal_pressure: &[f64],
        velocity: Option<&Vector>,
    ) -> Result<()> {
        let (start, u) = self.natural.block_of(displacement)?;
        let (_, r) = self.natural.block_of(reaction)?;
        let v = velocity.map(|v| self.natural.block_of(v)).transpose()?;
        let info = StepInfo {
            index: report.index,
            time: report.dynamics.map_or(report.load_factor, |d| d.time),
            load_factor: report.load_factor,
            newton_iterations: report.newton_iterations,
            uzawa_iterations: report.uzawa_iterations,
            converged: true,
            wall_seconds: report.wall_seconds,
        };
        let nodal = |data| BlockRows {
            global_rows: self.nodes,
            start,
            cols: 3,
            data,
        };
        let mut fields = vec![("displacement", nodal(&u)), ("reaction", nodal(&r))];
        if let Some((_, v)) = &v {
            fields.push(("velocity", nodal(v)));
        }
        let p = if contact.is_empty() {
            None
        } else {
            Some(self.natural_scalar.block_of_owned(nodal_pressure)?)
        };
        if let Some((pstart, p)) = &p {
            fields.push((
                "contact_pressure",
                BlockRows {
                    global_rows: self.nodes,
                    start: *pstart,
                    cols: 1,
                    data: p,
                },
            ));
        }
        self.file.write_step(&info, &fields, &[])?;
        if let Some(d) = &report.dynamics {
            self.file
                .write_step_small(report.index, "energy", &[d.kinetic, d.strain])?;
            self.file
                .write_step_small(report.index, "momentum", &d.momentum)?;
        }
        for (i, fields) in contact.iter().enumerate() {
            self.write_pair(report.index, i, fields, report)?;
        }
        self.file.flush()?;
        Ok(())
    }
}

fn create_result_file(
    rt: &Runtime,
    sim: &Simulation,
    path: &Path,
    provenance: Option<&Provenance>,
) -> Result<ResultFile> {
    let model = sim.model();
    let mesh = &model.mesh;
    let (rank, size) = (rt.rank(), rt.size());
    let node_block = even_block(mesh.num_nodes(), rank, size);
    let cell_block = even_block(mesh.num_cells(), rank, size);
    let nodes: Vec<f64> = mesh.nodes[node_block.clone()]
        .iter()
        .flatten()
        .copied()
        .collect();
    let npc = mesh.cell_type.nodes();
    let cells: Vec<i64> = cell_block
        .clone()
        .flat_map(|c| mesh.cell(c).iter().map(|&v| v as i64))
        .collect();
    let partition: Vec<i32> = sim.partition()[cell_block.clone()].to_vec();
    let cell_body: Vec<i32> = mesh.cell_body[cell_block.clone()]
        .iter()
        .map(|&b| b as i32)
        .collect();
    let facet_sets = facet_sets_out(mesh)?;
    let header = MeshHeader {
        cell_type: mesh.cell_type.name(),
        facet_type: mesh.cell_type.facet_type().name(),
        nodes: BlockRows {
            global_rows: mesh.num_nodes(),
            start: node_block.start,
            cols: 3,
            data: &nodes,
        },
        cells: BlockRows {
            global_rows: mesh.num_cells(),
            start: cell_block.start,
            cols: npc,
            data: &cells,
        },
        partition: BlockRows {
            global_rows: mesh.num_cells(),
            start: cell_block.start,
            cols: 1,
            data: &partition,
        },
        cell_body: BlockRows {
            global_rows: mesh.num_cells(),
            start: cell_block.start,
            cols: 1,
            data: &cell_body,
        },
        bodies: &mesh.bodies,
        node_sets: &mesh.node_sets,
        facet_sets: &facet_sets,
    };
    let mut file = ResultFile::create(&rt.world(), path, &header)?;
    if let Some(p) = provenance {
        let overrides = p.overrides.join("\n");
        file.write_attributes(
            "/",
            &[("scene", &p.scene), ("scene_overrides", &overrides)],
            &[],
        )?;
    }
    if !model.contact.is_empty() {
        // Pair name → slave facet set: lets a reader pick a pair's nodes out
        // of the nodal contact_pressure field (`contactlink summary`).
        let slaves: Vec<(&str, &str)> = model
            .contact
            .iter()
            .map(|p| (p.name.as_str(), p.slave.as_str()))
            .collect();
        file.write_attributes("/contact_pairs", &slaves, &[])?;
    }
    if let Some(h) = &model.hertz {
        write_hertz_setup(&mut file, h)?;
    }
    Ok(file)
}

/// `/hertz`: what `contactlink plot` needs to draw the closed-form profile
/// (the load comes from each step's contact force).
fn write_hertz_setup(file: &mut ResultFile, h: &HertzCheck) -> Result<()> {
    let (kind, thickness) = match h.kind {
        HertzKind::Line { thickness } => ("line", Some(thickness)),
        HertzKind::Point => ("point", None),
    };
    let mut numbers = vec![
        ("radius", h.radius),
        ("effective_modulus", h.effective_modulus),
    ];
    numbers.extend(thickness.map(|t| ("thickness", t)));
    file.write_attributes("/hertz", &[("kind", kind), ("pair", &h.pair)], &numbers)?;
    Ok(())
}

fn facet_sets_out(mesh: &Mesh) -> Result<BTreeMap<String, FacetSetOut>> {
    let k = mesh.cell_type.facet_type().nodes();
    let mut out = BTreeMap::new();
    for (name, facets) in &mesh.facet_sets {
        let mut nodes = Vec::with_capacity(facets.len() * k);
        for f in facets {
            nodes.extend(mesh.facet_nodes(f)?.into_iter().map(|v| v as i64));
        }
        out.insert(
            name.clone(),
            FacetSetOut {
                nodes,
                k,
                cell: facets.iter().map(|f| f.cell as i64).collect(),
                face: facets.iter().map(|f| f.face as i8).collect(),
            },
        );
    }
    Ok(out)
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

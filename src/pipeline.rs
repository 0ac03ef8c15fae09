//! One run end to end: scene → model → set-up (partition, DOFs) → output file
//! created (so an unwritable path fails before any solve) → load steps → summary.
use crate::dofs::even_block;
use crate::error::Result;
use crate::mesh::Mesh;
use crate::output::{BlockRows, FacetSetOut, MeshHeader, ResultFile, StepInfo};
use crate::petsc::Vector;
use crate::runtime::Runtime;
use crate::scene::{self, SceneSource};
use crate::solve::{Model, NaturalOrder, RunReport, Simulation, StepReport, StepSink};
use mpi::traits::CommunicatorCollectives;
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

/// How to run a scene.
#[derive(Debug, Clone, Default)]
pub struct RunOptions {
    /// Output file; when None, the scene's [output] path; when neither, no file.
    pub output: Option<PathBuf>,
    /// `--set key=value` overrides of scene keys.
    pub overrides: Vec<String>,
    /// Print one line per step on rank 0.
    pub echo: bool,
}

/// What a run produced.
pub struct RunSummary {
    pub model_name: String,
    pub report: RunReport,
    pub output: Option<PathBuf>,
    pub cells: usize,
    pub nodes: usize,
}

/// Loads a scene by built-in name or path and builds its model.
pub fn load_model(name_or_path: &str, overrides: &[String]) -> Result<(Model, Option<String>)> {
    let src = SceneSource::resolve(name_or_path)?;
    let parsed = scene::parse(&src, overrides)?;
    let model = parsed.build(&src.origin)?;
    Ok((model, parsed.output_path().map(str::to_owned)))
}

/// Runs a scene on all ranks of the runtime.
pub fn run_scene(rt: &Runtime, name_or_path: &str, opts: &RunOptions) -> Result<RunSummary> {
    let (model, scene_out) = load_model(name_or_path, &opts.overrides)?;
    let output = opts.output.clone().or(scene_out.map(PathBuf::from));
    run_model(rt, &model, output.as_deref(), opts.echo)
}

/// Runs an already built model, writing `output` when given.
pub fn run_model(
    rt: &Runtime,
    model: &Model,
    output: Option<&Path>,
    echo: bool,
) -> Result<RunSummary> {
    let mut sim = Simulation::setup(rt, model)?;
    if echo && rt.rank() == 0 {
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
            let file = create_result_file(rt, &sim, path)?;
            let mut sink = Hdf5Sink {
                file,
                natural: NaturalOrder::new(sim.dofs())?,
                nodes: model.mesh.num_nodes(),
            };
            sim.run(rt, &mut sink, echo)?
        }
        None => sim.run(rt, &mut NoOutput, echo)?,
    };
    Ok(RunSummary {
        model_name: model.name.clone(),
        report,
        output: output.map(Path::to_path_buf),
        cells: model.mesh.num_cells(),
        nodes: model.mesh.num_nodes(),
    })
}

struct NoOutput;

impl StepSink for NoOutput {
    fn step(&mut self, _: &StepReport, _: &Vector, _: &Vector) -> Result<()> {
        Ok(())
    }
}

/// Writes every converged step to the HDF5 file, in natural node order.
struct Hdf5Sink {
    file: ResultFile,
    natural: NaturalOrder,
    nodes: usize,
}

impl StepSink for Hdf5Sink {
    fn step(
        &mut self,
        report: &StepReport,
        displacement: &Vector,
        reaction: &Vector,
    ) -> Result<()> {
        let (start, u) = self.natural.block_of(displacement)?;
        let (_, r) = self.natural.block_of(reaction)?;
        let info = StepInfo {
            index: report.index,
            time: report.load_factor,
            load_factor: report.load_factor,
            newton_iterations: report.newton_iterations,
            uzawa_iterations: 0,
            converged: true,
            wall_seconds: report.wall_seconds,
        };
        let ub = BlockRows {
            global_rows: self.nodes,
            start,
            cols: 3,
            data: &u,
        };
        let rb = BlockRows {
            global_rows: self.nodes,
            start,
            cols: 3,
            data: &r,
        };
        self.file
            .write_step(&info, &[("displacement", ub), ("reaction", rb)], &[])?;
        Ok(())
    }
}

fn create_result_file(rt: &Runtime, sim: &Simulation, path: &Path) -> Result<ResultFile> {
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
    Ok(ResultFile::create(&rt.world(), path, &header)?)
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

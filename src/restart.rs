//! `run --restart OUT.h5`: the last converged step of a result file read back
//! (displacement, every pair's λN and friction history) so that a run
//! continues from it and ends where an uninterrupted run ends.
//!
//! Two stages. [`open`], before set-up: the file is a result file with a
//! step, and the scene can be continued at all (no mesh is needed). [`read`],
//! after set-up, collectively, from the distributed data alone (no rank holds
//! the global mesh then): each rank reads one contiguous block of every
//! natural-order array it needs (serial HDF5, read-only, one hyperslab) and a
//! scatter brings each row to the rank that uses it ([`fetch`]). So per rank
//! the restart holds O(N / ranks) of the file plus its own rows:
//! - the mesh check: the rank's output block of `/mesh/nodes` against the
//!   coordinates it has of that block; node and cell counts from the
//!   datasets' shapes. Any rank's mismatch is every rank's error, naming the
//!   first node that moved;
//! - the displacement of its owned nodes;
//! - every contact pair's fields its formulation asks for
//!   (`ContactPair::restart_request`: a links pair's λN and friction
//!   history of its own slave points, a mortar pair's nodal λ, λT and slip
//!   origins of the pair nodes it holds).
//!
//! The file must come from the same scene: same mesh (node count and
//! coordinates, cell count), same contact pairs; anything else is an error
//! naming the file and what differs, raised before any solve.
mod fetch;

use crate::contact::fields::{RestartRows, RowSpace};
use crate::contact::ContactPair;
use crate::distribution::LocalMesh;
use crate::dofs::{even_block, LocalNode, DIM};
use crate::error::{Error, Result};
use crate::model::Model;
use crate::output::{
    dataset_shape, layout, read_nodal, read_rows, read_step_attrs, OutputError, StepInfo,
};
use crate::parallel;
use crate::solve::{RestartState, Simulation};
use fetch::Fetch;
use mpi::topology::SimpleCommunicator;
use std::path::{Path, PathBuf};

/// A result file that passed the checks needing no mesh: what [`read`]
/// continues from once the ranks have their pieces.
#[derive(Debug, Clone)]
pub struct RestartFile {
    path: PathBuf,
    /// The file's steps, ascending (never empty).
    steps: Vec<usize>,
}

impl RestartFile {
    pub fn path(&self) -> &Path {
        &self.path
    }
}

/// Before set-up (any rank, on its own): `path` is a result file with a
/// step, and `model` is one a restart can continue. Reads no array.
pub fn open(path: &Path, model: &Model) -> Result<RestartFile> {
    if model.dynamics.is_some() {
        return Err(Error::Restart(format!(
            "{}: continuing a dynamic scene is not supported (the file holds no accelerations)",
            path.display()
        )));
    }
    // The same checks as `summary`: a missing file, not a result file, or
    // one without a converged step each get one plain sentence.
    let steps = crate::results::open_steps(path).map_err(|e| Error::Restart(e.to_string()))?;
    Ok(RestartFile {
        path: path.to_path_buf(),
        steps,
    })
}

/// After set-up, collective: this rank's share of the last step of `file`
/// for `sim`. Fails on every rank with the same error if it fails on one.
pub fn read(file: &RestartFile, sim: &Simulation) -> Result<RestartState> {
    let world = SimpleCommunicator::world();
    let reader = Reader {
        world: &world,
        path: &file.path,
        rank: sim.dofs().rank,
        nranks: sim.dofs().nranks,
        nodes: sim.dofs().num_global_nodes(),
    };
    let local = sim.local_mesh();
    let (step, info) = parallel::agree(&world, reader.check(file, local))?;
    let displacement = reader.displacement(step, sim)?;
    let pairs = sim
        .contact()
        .iter()
        .map(|p| reader.pair(step, p, info.load_factor))
        .collect::<Result<Vec<_>>>()?;
    Ok(RestartState {
        path: file.path.clone(),
        step,
        load_factor: info.load_factor,
        displacement,
        pairs,
    })
}

/// The collective reading context.
struct Reader<'a> {
    world: &'a SimpleCommunicator,
    path: &'a Path,
    rank: usize,
    nranks: usize,
    /// Mesh nodes (the rows of every nodal dataset).
    nodes: usize,
}

impl Reader<'_> {
    fn fail(&self, message: impl std::fmt::Display) -> Error {
        Error::Restart(format!("{}: {message}", self.path.display()))
    }

    /// Rank-local: the mesh check of this rank's block, then the step to
    /// continue from (the same on every rank).
    fn check(&self, file: &RestartFile, local: &LocalMesh) -> Result<(usize, StepInfo)> {
        self.check_mesh(local).map_err(|m| self.fail(m))?;
        let step = *file
            .steps
            .last()
            .ok_or_else(|| self.fail("the file holds no converged step to continue from"))?;
        let info = read_step_attrs(self.path, step).map_err(|e| self.fail(e))?;
        if info.load_factor >= 1.0 - 1e-12 {
            return Err(self.fail(format!(
                "step {step} already reached the full load (load factor {}); nothing to continue",
                info.load_factor
            )));
        }
        Ok((step, info))
    }

    /// The file's mesh must be the scene's: same cell and node counts (the
    /// datasets' shapes) and, in this rank's output block of nodes, the same
    /// coordinates. The blocks tile the nodes in rank order, so the lowest
    /// rank that finds a moved node names the first one of the mesh.
    fn check_mesh(&self, local: &LocalMesh) -> std::result::Result<(), String> {
        let shape = dataset_shape(self.path, layout::MESH_NODES).map_err(|e| e.to_string())?;
        if shape != [local.global_nodes, 3] {
            return Err(format!(
                "written for another mesh: {} nodes, this scene has {}",
                shape.first().copied().unwrap_or(0),
                local.global_nodes
            ));
        }
        let cells = dataset_shape(self.path, layout::MESH_CELLS).map_err(|e| e.to_string())?;
        if cells.first() != Some(&local.global_cells) {
            return Err(format!(
                "written for another mesh: {} cells, this scene has {}",
                cells.first().copied().unwrap_or(0),
                local.global_cells
            ));
        }
        let block = even_block(local.global_nodes, self.rank, self.nranks);
        let nodes =
            read_rows(self.path, layout::MESH_NODES, block.clone()).map_err(|e| e.to_string())?;
        let scale = local
            .bounding_box
            .map_or(1.0, |b| b.diagonal())
            .max(f64::MIN_POSITIVE);
        let moved = local
            .block
            .nodes
            .iter()
            .flatten()
            .zip(&nodes)
            .position(|(a, b)| (a - b).abs() > 1e-12 * scale);
        match moved {
            Some(i) => Err(format!(
                "written for another mesh: node {} is elsewhere (another scene, or other --set mesh values?)",
                block.start + i / 3
            )),
            None => Ok(()),
        }
    }

    /// Rank-local: the row count of `/steps/<step>/<name>` (checked against
    /// `rows` when given, and its column count against `cols`) and this
    /// rank's block of it.
    fn read_block(
        &self,
        step: usize,
        name: &str,
        rows: Option<usize>,
        cols: usize,
    ) -> Result<(usize, Vec<f64>)> {
        let object = layout::step_dataset(step, name);
        let missing = |e: OutputError| {
            self.fail(format!(
                "{e} (a file written before restarts existed, or by another scene?)"
            ))
        };
        let shape = dataset_shape(self.path, &object).map_err(missing)?;
        let (have, c) = match shape[..] {
            [r] => (r, 1),
            [r, c] => (r, c),
            _ => return Err(self.fail(format!("{object} has shape {shape:?}"))),
        };
        if c != cols {
            return Err(self.fail(format!(
                "step {step} {name} has {c} columns, expected {cols}"
            )));
        }
        if let Some(rows) = rows.filter(|&r| r != have) {
            return Err(self.fail(format!(
                "step {step} {name} has {have} rows, expected {rows}"
            )));
        }
        let block = even_block(have, self.rank, self.nranks);
        let data = read_rows(self.path, &object, block).map_err(|e| self.fail(e))?;
        Ok((have, data))
    }

    /// Collective: the rows `wanted` of `/steps/<step>/<name>` (`cols` values
    /// each), every rank reading its block; and the dataset's row count.
    /// Rows the file lacks come back as NaN.
    fn fetch(
        &self,
        step: usize,
        name: &str,
        rows: Option<usize>,
        cols: usize,
        wanted: &[usize],
    ) -> Result<(usize, Vec<f64>)> {
        let (have, block) = parallel::agree(self.world, self.read_block(step, name, rows, cols))?;
        let mut fetch = Fetch::new(have, cols, wanted, self.rank, self.nranks)?;
        Ok((have, fetch.fetch(&block)?))
    }

    /// Collective: the displacement of this rank's owned DOFs, PETSc order.
    fn displacement(&self, step: usize, sim: &Simulation) -> Result<Vec<f64>> {
        let dofs = sim.dofs();
        let owned: Vec<LocalNode> = (0..dofs.num_local_nodes())
            .map(LocalNode::from_index)
            .filter(|&l| dofs.is_owned(l))
            .collect();
        let natural: Vec<usize> = owned.iter().map(|&l| dofs.natural(l).0).collect();
        let (_, values) =
            self.fetch(step, layout::DISPLACEMENT, Some(self.nodes), DIM, &natural)?;
        let start = dofs.owned_dof_start();
        let mut x = vec![0.0; dofs.num_owned_dofs()];
        for (k, &l) in owned.iter().enumerate() {
            for c in 0..DIM {
                x[dofs.dof(l, c).0 as usize - start] = values[DIM * k + c];
            }
        }
        Ok(x)
    }

    /// Collective: this rank's rows of one pair, the fields its
    /// formulation asks for (`ContactPair::restart_request`).
    fn pair(&self, step: usize, pair: &ContactPair, load_factor: f64) -> Result<RestartRows> {
        let field = |f: &str| layout::pair_dataset(pair.name(), f);
        // Files from before penalties were written have none: keep the
        // scene's. Agreed (a rank whose read failed alone takes the others'
        // value), since every rank must go on with the same penalty.
        let penalty = read_nodal(self.path, step, &field(layout::PAIR_PENALTY))
            .ok()
            .and_then(|(v, _, _)| v.first().copied())
            .filter(|p| p.is_finite() && *p > 0.0);
        let [agreed] = parallel::max(self.world, [penalty.unwrap_or(-1.0)]);
        let penalty = (agreed > 0.0).then_some(agreed);
        // Point fields have the dataset's own row count, the first one read
        // fixes it for the rest; nodal fields one row per mesh node.
        let mut point_rows = None;
        let mut fields = Vec::new();
        for f in pair.restart_request().fields {
            let rows = match f.space {
                RowSpace::Points => point_rows,
                RowSpace::Nodes => Some(self.nodes),
            };
            let (have, values) = self.fetch(step, &field(f.name), rows, f.cols, &f.rows)?;
            if f.space == RowSpace::Points {
                point_rows = Some(have);
            }
            fields.push(values);
        }
        Ok(RestartRows {
            penalty,
            load_factor,
            fields,
        })
    }
}

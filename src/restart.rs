//! `run --restart OUT.h5`: the last converged step of a result file read back
//! (displacement, every pair's λN and friction history) so that a run
//! continues from it and ends where an uninterrupted run ends.
//!
//! Every rank reads the file on its own (serial HDF5, read-only): the arrays
//! are in natural order, and each rank picks its own rows. The file must come
//! from the same scene: same mesh (node count and coordinates, cell count),
//! same contact pairs; anything else is an error naming the file and what
//! differs, raised before any solve.
use crate::contact::multipliers::FrictionRecord;
use crate::contact::pair_state::{FrictionRows, MortarRows, RestartRows};
use crate::error::{Error, Result};
use crate::model::Model;
use crate::output::{layout, read_dataset, read_nodal, read_step_attrs, OutputError};
use crate::solve::RestartState;
use std::path::Path;

/// Reads the last step of `path` for `model`.
pub fn read(path: &Path, model: &Model) -> Result<RestartState> {
    let fail = |message: String| Error::Restart(format!("{}: {message}", path.display()));
    let h5 = |e: OutputError| fail(e.to_string());
    if model.dynamics.is_some() {
        return Err(fail(
            "continuing a dynamic scene is not supported (the file holds no accelerations)".into(),
        ));
    }
    // The same checks as `summary`: a missing file, not a result file, or
    // one without a converged step each get one plain sentence.
    let steps = crate::results::open_steps(path).map_err(|e| Error::Restart(e.to_string()))?;
    check_mesh(path, model).map_err(fail)?;
    let step = *steps
        .last()
        .ok_or_else(|| fail("the file holds no converged step to continue from".into()))?;
    let info = read_step_attrs(path, step).map_err(h5)?;
    if info.load_factor >= 1.0 - 1e-12 {
        return Err(fail(format!(
            "step {step} already reached the full load (load factor {}); nothing to continue",
            info.load_factor
        )));
    }
    let n = model.mesh.num_nodes();
    let displacement = read_columns(path, step, layout::DISPLACEMENT, n, 3)?;
    let pairs = model
        .contact
        .iter()
        .map(|p| {
            let mut rows = read_pair(path, step, &p.name, p.active_friction().is_some())?;
            if p.formulation == crate::model::Formulation::Mortar {
                let friction = p.active_friction().is_some();
                rows.mortar = Some(read_mortar(
                    path,
                    step,
                    &p.name,
                    n,
                    friction,
                    info.load_factor,
                )?);
            }
            Ok(rows)
        })
        .collect::<Result<Vec<_>>>()?;
    Ok(RestartState {
        path: path.to_path_buf(),
        step,
        load_factor: info.load_factor,
        displacement,
        pairs,
    })
}

/// The file's mesh must be the model's: same cells and nodes, same places.
fn check_mesh(path: &Path, model: &Model) -> std::result::Result<(), String> {
    let mesh = &model.mesh;
    let (nodes, shape) =
        read_dataset::<f64>(path, layout::MESH_NODES).map_err(|e| e.to_string())?;
    if shape != [mesh.num_nodes(), 3] {
        return Err(format!(
            "written for another mesh: {} nodes, this scene has {}",
            shape.first().copied().unwrap_or(0),
            mesh.num_nodes()
        ));
    }
    let (_, cells) = read_dataset::<i64>(path, layout::MESH_CELLS).map_err(|e| e.to_string())?;
    if cells.first() != Some(&mesh.num_cells()) {
        return Err(format!(
            "written for another mesh: {} cells, this scene has {}",
            cells.first().copied().unwrap_or(0),
            mesh.num_cells()
        ));
    }
    let scale = mesh
        .bounding_box()
        .map_or(1.0, |b| b.diagonal())
        .max(f64::MIN_POSITIVE);
    let moved = mesh
        .nodes
        .iter()
        .flatten()
        .zip(&nodes)
        .position(|(a, b)| (a - b).abs() > 1e-12 * scale);
    match moved {
        Some(i) => Err(format!(
            "written for another mesh: node {} is elsewhere (another scene, or other --set mesh values?)",
            i / 3
        )),
        None => Ok(()),
    }
}

fn read_pair(path: &Path, step: usize, name: &str, friction: bool) -> Result<RestartRows> {
    let field = |f: &str| layout::pair_dataset(name, f);
    let lambda = read_any_rows(path, step, &field(layout::PAIR_LAMBDA_N), 1)?;
    let friction = if friction {
        let rows = lambda.len();
        let triples = |f: &str| -> Result<Vec<[f64; 3]>> {
            let v = read_columns(path, step, &field(f), rows, 3)?;
            Ok(v.chunks_exact(3).map(|c| [c[0], c[1], c[2]]).collect())
        };
        let (lambda_t, origin, ids) = (
            triples(layout::PAIR_LAMBDA_T)?,
            triples(layout::PAIR_SLIP_ORIGIN)?,
            triples(layout::PAIR_HISTORY_IDS)?,
        );
        let records = lambda_t
            .into_iter()
            .zip(origin)
            .zip(ids)
            .map(|((lambda, origin), ids)| FrictionRecord {
                lambda,
                origin,
                ids,
            })
            .collect();
        Some(FrictionRows {
            records,
            state: read_columns(path, step, &field(layout::PAIR_STATE), rows, 1)?,
            traction: triples(layout::PAIR_TRACTION_T)?,
        })
    } else {
        None
    };
    // Files from before penalties were written have none: keep the scene's.
    let penalty = read_nodal(path, step, &field(layout::PAIR_PENALTY))
        .ok()
        .and_then(|(v, _, _)| v.first().copied());
    Ok(RestartRows {
        penalty,
        lambda,
        friction,
        mortar: None,
    })
}

/// A mortar pair's nodal datasets (`nodes` rows each).
fn read_mortar(
    path: &Path,
    step: usize,
    name: &str,
    nodes: usize,
    friction: bool,
    load_factor: f64,
) -> Result<MortarRows> {
    let field = |f: &str| layout::pair_dataset(name, f);
    let triples = |f: &str| -> Result<Vec<[f64; 3]>> {
        let v = read_columns(path, step, &field(f), nodes, 3)?;
        Ok(v.chunks_exact(3).map(|c| [c[0], c[1], c[2]]).collect())
    };
    let (lambda_t, slip_origin) = if friction {
        (
            Some(triples(layout::PAIR_NODE_LAMBDA_T)?),
            Some(triples(layout::PAIR_NODE_SLIP_ORIGIN)?),
        )
    } else {
        (None, None)
    };
    Ok(MortarRows {
        lambda: read_columns(path, step, &field(layout::PAIR_NODE_LAMBDA), nodes, 1)?,
        lambda_t,
        slip_origin,
        load_factor,
    })
}

/// `/steps/<step>/<name>` with `cols` columns, any number of rows.
fn read_any_rows(path: &Path, step: usize, name: &str, cols: usize) -> Result<Vec<f64>> {
    let (data, _, c) = read_nodal(path, step, name).map_err(|e| {
        Error::Restart(format!(
            "{}: {e} (a file written before restarts existed, or by another scene?)",
            path.display()
        ))
    })?;
    if c != cols {
        return Err(Error::Restart(format!(
            "{}: step {step} {name} has {c} columns, expected {cols}",
            path.display()
        )));
    }
    Ok(data)
}

/// As [`read_any_rows`], with the row count checked too.
fn read_columns(
    path: &Path,
    step: usize,
    name: &str,
    rows: usize,
    cols: usize,
) -> Result<Vec<f64>> {
    let data = read_any_rows(path, step, name, cols)?;
    if data.len() != rows * cols {
        return Err(Error::Restart(format!(
            "{}: step {step} {name} has {} rows, expected {rows}",
            path.display(),
            data.len() / cols
        )));
    }
    Ok(data)
}

//! Reading a finished run back: `contactlink summary` (a table of the steps
//! and each contact pair's force, area and peak pressure) and
//! `contactlink plot` (the Hertz pressure profile against the closed form).
//! Serial and read-only: any process can run them on a closed result file.
pub mod footprint;
pub mod plot;
pub mod summary;

use crate::dofs::NaturalNode;
use crate::output::{layout, list_steps, read_nodal, OutputError};
use std::path::{Path, PathBuf};

/// Why a result file could not be summarised or plotted. Each message is one
/// line naming the file.
#[derive(Debug, thiserror::Error)]
pub enum ResultsError {
    #[error("{}: {message}", .path.display())]
    File { path: PathBuf, message: String },
    /// A sentence that names the file itself.
    #[error("{0}")]
    Sentence(String),
    #[error(transparent)]
    Output(#[from] OutputError),
}

impl ResultsError {
    pub fn file(path: &Path, message: impl Into<String>) -> Self {
        ResultsError::File {
            path: path.to_path_buf(),
            message: message.into(),
        }
    }
}

/// Checks that `path` is a contactlink result file with at least one step
/// and returns its step indices (ascending). The checks come first so a
/// wrong argument gets a plain sentence instead of an HDF5 error stack.
pub fn open_steps(path: &Path) -> Result<Vec<usize>, ResultsError> {
    if !path.exists() {
        return Err(ResultsError::file(path, "no such file"));
    }
    let file = hdf5::File::open(path)
        .map_err(|_| ResultsError::file(path, "not an HDF5 file (or not readable)"))?;
    if !(file.link_exists(layout::MESH_NAME) && file.link_exists(layout::STEPS_NAME)) {
        return Err(ResultsError::file(
            path,
            "not a contactlink result file (no /mesh and /steps groups)",
        ));
    }
    drop(file);
    let steps = list_steps(path)?;
    if steps.is_empty() {
        return Err(ResultsError::file(
            path,
            "holds no steps (the run stopped before its first step converged)",
        ));
    }
    Ok(steps)
}

/// The contact pairs written at `step` (the members of
/// `/steps/<step>/contact`), sorted; none when the model has no contact.
pub fn pair_names(path: &Path, step: usize) -> Result<Vec<String>, ResultsError> {
    let object = layout::step_dataset(step, layout::CONTACT);
    let file = hdf5::File::open(path).map_err(|source| OutputError::Open {
        path: path.to_path_buf(),
        source,
    })?;
    if !file.link_exists(&object) {
        return Ok(Vec::new());
    }
    let mut names = file
        .group(&object)
        .and_then(|g| g.member_names())
        .map_err(|e| OutputError::hdf5(path, &object, "list", e))?;
    names.sort();
    Ok(names)
}

/// One contact pair's point arrays at one step.
pub struct PairPoints {
    /// Current positions of the slave quadrature points.
    pub points: Vec<[f64; 3]>,
    pub pressure: Vec<f64>,
    /// Area weights; None in files written before the weight was stored.
    pub weight: Option<Vec<f64>>,
    /// Total contact force on the slave surface.
    pub force: [f64; 3],
    /// A mortar pair's active slave nodes (λ_j > 0), the constraints its
    /// Uzawa loop counts; None for a links pair, whose points are those.
    pub active_nodes: Option<ActiveNodes>,
    /// A frictional pair's constraints sticking and slipping, from the
    /// state its formulation writes (a links pair's points, `state`; a
    /// mortar pair's slave nodes, `node_state`); None without friction.
    pub friction: Option<StickSlip>,
}

/// Constraints in contact that stick, and that slip.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct StickSlip {
    pub stick: usize,
    pub slip: usize,
}

impl StickSlip {
    /// Counts a state field (0 open, 1 stick, 2 slip).
    pub fn count(state: &[f64]) -> Self {
        let n = |v: f64| state.iter().filter(|&&s| s == v).count();
        StickSlip {
            stick: n(crate::contact::fields::STICK),
            slip: n(crate::contact::fields::SLIP),
        }
    }
}

/// A mortar pair's active slave nodes: how many, and the slave area they
/// carry, Σ A_j (NaN in files written before `node_area` was).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ActiveNodes {
    pub count: usize,
    pub area: f64,
}

impl PairPoints {
    pub fn read(path: &Path, step: usize, pair: &str) -> Result<Self, ResultsError> {
        let rel = |name: &str| layout::pair_dataset(pair, name);
        let (flat, rows, cols) = read_nodal(path, step, &rel(layout::PAIR_POINTS))?;
        let (pressure, prow, _) = read_nodal(path, step, &rel(layout::PAIR_PRESSURE))?;
        let (force, _, _) = read_nodal(path, step, &rel(layout::PAIR_FORCE))?;
        let weight = if has_dataset(path, step, &rel(layout::PAIR_WEIGHT)) {
            let (w, wrows, _) = read_nodal(path, step, &rel(layout::PAIR_WEIGHT))?;
            Some((w, wrows))
        } else {
            None
        };
        let inconsistent = cols != 3
            || prow != rows
            || force.len() != 3
            || weight.as_ref().is_some_and(|(_, r)| *r != rows);
        if inconsistent {
            return Err(ResultsError::file(
                path,
                format!(
                    "step {step}, pair '{pair}': points, pressure, weight and force have inconsistent shapes"
                ),
            ));
        }
        let active_nodes = if has_dataset(path, step, &rel(layout::PAIR_NODE_LAMBDA)) {
            let (lambda, _, _) = read_nodal(path, step, &rel(layout::PAIR_NODE_LAMBDA))?;
            let area = if has_dataset(path, step, &rel(layout::PAIR_NODE_AREA)) {
                let (a, _, _) = read_nodal(path, step, &rel(layout::PAIR_NODE_AREA))?;
                let active = lambda.iter().zip(&a).filter(|(&l, _)| l > 0.0);
                active.map(|(_, a)| a).sum()
            } else {
                f64::NAN
            };
            Some(ActiveNodes {
                count: lambda.iter().filter(|&&l| l > 0.0).count(),
                area,
            })
        } else {
            None
        };
        let friction = [layout::PAIR_NODE_STATE, layout::PAIR_STATE]
            .into_iter()
            .find(|name| has_dataset(path, step, &rel(name)))
            .map(|name| read_nodal(path, step, &rel(name)))
            .transpose()?
            .map(|(state, _, _)| StickSlip::count(&state));
        Ok(PairPoints {
            friction,
            points: flat.chunks_exact(3).map(|c| [c[0], c[1], c[2]]).collect(),
            pressure,
            weight: weight.map(|(w, _)| w),
            force: [force[0], force[1], force[2]],
            active_nodes,
        })
    }

    /// Points carrying pressure (pN > 0): the contact zone.
    pub fn is_active(&self, i: usize) -> bool {
        self.pressure.get(i).is_some_and(|&p| p > 0.0)
    }
}

/// The nodal contact pressure of `step` (one value per mesh node); None
/// when the step has none (a model without contact).
pub fn nodal_pressure(path: &Path, step: usize) -> Result<Option<Vec<f64>>, ResultsError> {
    if !has_dataset(path, step, layout::CONTACT_PRESSURE) {
        return Ok(None);
    }
    Ok(Some(read_nodal(path, step, layout::CONTACT_PRESSURE)?.0))
}

/// The nodes of a pair's slave surface (sorted, unique), from the
/// `/contact_pairs` map to its facet set; None in files without the map.
pub fn slave_nodes(path: &Path, pair: &str) -> Result<Option<Vec<NaturalNode>>, ResultsError> {
    let Some(set) = crate::output::read_string_attr(path, layout::CONTACT_PAIRS, pair)? else {
        return Ok(None);
    };
    let object = format!("{}/{}", layout::facet_set(&set), layout::FACET_NODES);
    let (ids, _) = crate::output::read_dataset::<i64>(path, &object)?;
    let mut nodes = ids
        .into_iter()
        .map(|id| usize::try_from(id).map(NaturalNode))
        .collect::<Result<Vec<_>, _>>()
        .map_err(|_| ResultsError::file(path, format!("{object} holds a negative node id")))?;
    nodes.sort_unstable();
    nodes.dedup();
    Ok(Some(nodes))
}

/// Shape-function samples of the nodes `wanted` picks (by reference
/// position), over the facets of the pair's slave set that have one of
/// them as a corner, as `run` gathers them for its nodal-average Hertz fit
/// (the same rule, on the file's reference nodes). None for a file without
/// the pair → slave set map.
pub fn nodal_samples(
    path: &Path,
    pair: &str,
    wanted: &dyn Fn(&[f64; 3]) -> bool,
) -> Result<Option<Vec<crate::hertz::NodalSample>>, ResultsError> {
    use crate::fem::FacetType;
    let Some(set) = crate::output::read_string_attr(path, layout::CONTACT_PAIRS, pair)? else {
        return Ok(None);
    };
    let object = format!("{}/{}", layout::facet_set(&set), layout::FACET_NODES);
    let (ids, shape) = crate::output::read_dataset::<i64>(path, &object)?;
    let (coords, _) = crate::output::read_dataset::<f64>(path, layout::MESH_NODES)?;
    let facet_type = match shape.get(1) {
        Some(4) => FacetType::Quad4,
        Some(3) => FacetType::Tri3,
        _ => {
            return Err(ResultsError::file(
                path,
                format!("{object} has shape {shape:?}"),
            ))
        }
    };
    let position = |id: &i64| -> Option<[f64; 3]> {
        let n = usize::try_from(*id).ok()?;
        let x = coords.get(3 * n..3 * n + 3)?;
        Some([x[0], x[1], x[2]])
    };
    let facets = ids
        .chunks_exact(facet_type.nodes())
        .enumerate()
        .map(|(f, corners)| {
            corners
                .iter()
                .map(position)
                .collect::<Option<Vec<_>>>()
                .ok_or_else(|| {
                    ResultsError::file(
                        path,
                        format!("{object}: facet {f} names a node the mesh lacks"),
                    )
                })
        })
        .collect::<Result<Vec<_>, _>>()?;
    let out = crate::hertz::facet_samples(facet_type, facets.iter().map(Vec::as_slice), wanted)
        .map_err(|(f, e)| ResultsError::file(path, format!("{object}: facet {f}: {e}")))?;
    Ok(Some(out))
}

/// Whether `/steps/<step>/<rel>` exists (optional datasets).
fn has_dataset(path: &Path, step: usize, rel: &str) -> bool {
    let object = layout::step_dataset(step, rel);
    hdf5::File::open(path).is_ok_and(|f| f.link_exists(&object))
}

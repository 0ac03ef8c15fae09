//! Serial read-back of a result file (any process, any rank; the file
//! should be closed by the writer or at least flushed).

use std::path::Path;

use hdf5::types::VarLenUnicode;
use hdf5::{File, H5Type};

use super::{layout, OutputError, StepInfo};

fn open(path: &Path) -> Result<File, OutputError> {
    File::open(path).map_err(|source| OutputError::Open {
        path: path.to_path_buf(),
        source,
    })
}

/// Reads any dataset as a flat row-major `Vec<T>` and its shape.
pub fn read_dataset<T: H5Type>(
    path: &Path,
    dataset: &str,
) -> Result<(Vec<T>, Vec<usize>), OutputError> {
    let file = open(path)?;
    let ds = file
        .dataset(dataset)
        .map_err(|e| OutputError::hdf5(path, dataset, "open", e))?;
    let data = ds
        .read_raw::<T>()
        .map_err(|e| OutputError::hdf5(path, dataset, "read", e))?;
    Ok((data, ds.shape()))
}

/// Reads `/steps/<NNNNNN>/<name>` (`name` may be a relative path such as
/// `contact/pair/gap`) as `(values, rows, cols)`; a 1-D dataset has 1 column.
pub fn read_nodal(
    path: &Path,
    step: usize,
    name: &str,
) -> Result<(Vec<f64>, usize, usize), OutputError> {
    let object = layout::step_dataset(step, name);
    let (data, shape) = read_dataset::<f64>(path, &object)?;
    match shape[..] {
        [rows] => Ok((data, rows, 1)),
        [rows, cols] => Ok((data, rows, cols)),
        _ => Err(OutputError::invalid(
            path,
            &object,
            format!("has shape {shape:?}, expected 1 or 2 dimensions"),
        )),
    }
}

/// The shape of a dataset, read from its header alone (no values).
pub fn dataset_shape(path: &Path, dataset: &str) -> Result<Vec<usize>, OutputError> {
    let file = open(path)?;
    let ds = file
        .dataset(dataset)
        .map_err(|e| OutputError::hdf5(path, dataset, "open", e))?;
    Ok(ds.shape())
}

/// Rows `rows` of a 1- or 2-D f64 dataset, flat row-major: one hyperslab
/// read, so a rank reading its block holds only that block (the rest of
/// the dataset is never read). An empty range reads nothing.
pub fn read_rows(
    path: &Path,
    dataset: &str,
    rows: std::ops::Range<usize>,
) -> Result<Vec<f64>, OutputError> {
    let file = open(path)?;
    let ds = file
        .dataset(dataset)
        .map_err(|e| OutputError::hdf5(path, dataset, "open", e))?;
    let shape = ds.shape();
    if shape.first().is_none_or(|&n| rows.end > n) || shape.len() > 2 {
        return Err(OutputError::invalid(
            path,
            dataset,
            format!("has shape {shape:?}, rows {rows:?} asked for"),
        ));
    }
    if rows.is_empty() {
        return Ok(Vec::new());
    }
    let read = |e| OutputError::hdf5(path, dataset, "read rows of", e);
    if shape.len() == 1 {
        let v = ds.read_slice_1d::<f64, _>(rows).map_err(read)?;
        Ok(v.iter().copied().collect())
    } else {
        let v = ds.read_slice_2d::<f64, _>((rows, ..)).map_err(read)?;
        Ok(v.iter().copied().collect())
    }
}

/// The step indices in the file, ascending.
pub fn list_steps(path: &Path) -> Result<Vec<usize>, OutputError> {
    let file = open(path)?;
    let names = file
        .group(layout::STEPS_NAME)
        .and_then(|g| g.member_names())
        .map_err(|e| OutputError::hdf5(path, layout::STEPS, "list", e))?;
    let mut steps = names
        .iter()
        .map(|n| {
            n.parse::<usize>().map_err(|_| {
                OutputError::invalid(
                    path,
                    &format!("{}/{n}", layout::STEPS),
                    "is not a step index",
                )
            })
        })
        .collect::<Result<Vec<_>, _>>()?;
    steps.sort_unstable();
    Ok(steps)
}

/// Opens attribute `name` of group `object` (`"/"` for the root); None when
/// the group or the attribute does not exist (optional run metadata).
fn optional_attr(
    path: &Path,
    object: &str,
    name: &str,
) -> Result<Option<hdf5::Attribute>, OutputError> {
    let file = open(path)?;
    let inner = object.trim_start_matches('/');
    if !inner.is_empty() && !file.link_exists(inner) {
        return Ok(None);
    }
    let g = file
        .group(object)
        .map_err(|e| OutputError::hdf5(path, object, "open", e))?;
    let names = g
        .attr_names()
        .map_err(|e| OutputError::hdf5(path, object, "list attributes of", e))?;
    if !names.iter().any(|n| n == name) {
        return Ok(None);
    }
    g.attr(name)
        .map(Some)
        .map_err(|e| OutputError::hdf5(path, object, "read attributes of", e))
}

/// A string attribute of a group (see [`ResultFile::write_attributes`]),
/// None when absent.
pub fn read_string_attr(
    path: &Path,
    object: &str,
    name: &str,
) -> Result<Option<String>, OutputError> {
    optional_attr(path, object, name)?
        .map(|a| {
            a.read_scalar::<VarLenUnicode>()
                .map(|s| s.as_str().to_owned())
                .map_err(|e| OutputError::hdf5(path, object, "read attributes of", e))
        })
        .transpose()
}

/// An f64 attribute of a group, None when absent.
pub fn read_f64_attr(path: &Path, object: &str, name: &str) -> Result<Option<f64>, OutputError> {
    optional_attr(path, object, name)?
        .map(|a| {
            a.read_scalar::<f64>()
                .map_err(|e| OutputError::hdf5(path, object, "read attributes of", e))
        })
        .transpose()
}

/// The attributes of `/steps/<NNNNNN>` as a [`StepInfo`].
pub fn read_step_attrs(path: &Path, step: usize) -> Result<StepInfo, OutputError> {
    let object = layout::step_group(step);
    let file = open(path)?;
    let g = file
        .group(&object)
        .map_err(|e| OutputError::hdf5(path, &object, "open", e))?;
    let h = |e| OutputError::hdf5(path, &object, "read attributes of", e);
    let f64_attr = |n: &str| g.attr(n).and_then(|a| a.read_scalar::<f64>()).map_err(h);
    let count = |n: &str| -> Result<usize, OutputError> {
        let v = g.attr(n).and_then(|a| a.read_scalar::<i64>()).map_err(h)?;
        usize::try_from(v)
            .map_err(|_| OutputError::invalid(path, &object, format!("{n} = {v} is negative")))
    };
    Ok(StepInfo {
        index: step,
        time: f64_attr(layout::TIME_ATTR)?,
        load_factor: f64_attr(layout::LOAD_FACTOR_ATTR)?,
        newton_iterations: count(layout::NEWTON_ATTR)?,
        uzawa_iterations: count(layout::UZAWA_ATTR)?,
        converged: g
            .attr(layout::CONVERGED_ATTR)
            .and_then(|a| a.read_scalar::<u8>())
            .map_err(h)?
            != 0,
        wall_seconds: f64_attr(layout::WALL_SECONDS_ATTR)?,
    })
}

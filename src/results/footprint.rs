//! The run's footprint in its result file: `/footprint` with the attributes
//! `peak_memory_largest_mib`, `peak_memory_smallest_mib` (peak resident
//! memory of the largest and smallest rank), `setup_seconds` (scene, mesh,
//! partition, DOFs, matrix; the largest over the ranks) and `ranks`.
//! Written by rank 0 alone once the run has closed the file (the peak is
//! known only then), read back by `contactlink summary`.
use super::ResultsError;
use crate::memory::Footprint;
use crate::output::read_f64_attr;
use std::path::Path;

const GROUP: &str = "footprint";
const LARGEST: &str = "peak_memory_largest_mib";
const SMALLEST: &str = "peak_memory_smallest_mib";
const SETUP: &str = "setup_seconds";
const RANKS: &str = "ranks";

/// Adds `/footprint` to a closed result file (serial: one process only).
pub fn write(path: &Path, fp: &Footprint) -> Result<(), ResultsError> {
    let fail = |e: hdf5::Error| ResultsError::file(path, format!("writing /{GROUP}: {e}"));
    let file = hdf5::File::open_rw(path).map_err(fail)?;
    let group = match file.group(GROUP) {
        Ok(g) => g,
        Err(_) => file.create_group(GROUP).map_err(fail)?,
    };
    for (name, value) in [
        (LARGEST, fp.peak_largest_mib),
        (SMALLEST, fp.peak_smallest_mib),
        (SETUP, fp.setup_seconds),
        (RANKS, fp.ranks as f64),
    ] {
        if group.attr(name).is_ok() {
            group.delete_attr(name).map_err(fail)?;
        }
        group
            .new_attr::<f64>()
            .create(name)
            .and_then(|a| a.write_scalar(&value))
            .map_err(fail)?;
    }
    Ok(())
}

/// `/footprint` of a result file; None in files written without it.
pub fn read(path: &Path) -> Result<Option<Footprint>, ResultsError> {
    let object = format!("/{GROUP}");
    let get = |name| read_f64_attr(path, &object, name);
    let (Some(largest), Some(smallest), Some(setup), Some(ranks)) =
        (get(LARGEST)?, get(SMALLEST)?, get(SETUP)?, get(RANKS)?)
    else {
        return Ok(None);
    };
    Ok(Some(Footprint {
        peak_largest_mib: largest,
        peak_smallest_mib: smallest,
        setup_seconds: setup,
        ranks: ranks as usize,
    }))
}

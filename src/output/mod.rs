//! Result output: one parallel HDF5 file per run plus an XDMF sidecar.
//!
//! Every rank holds a contiguous block of rows of each nodal or cell array in
//! the global (input) order; [`ResultFile`] writes those blocks through
//! MPI-IO into one dataset per array, so files written by 1, 2 or N ranks hold
//! the same datasets with the same values and compare directly.
//!
//! # File layout
//!
//! ```text
//! /mesh/nodes                      (N,3) f64  reference coordinates
//! /mesh/cells                      (M,k) i64  connectivity in VTK node order (see
//!                                             `fem::CellType::vtk_order`: ours but for
//!                                             wedges); attr cell_type ("hex8" | "tet4" |
//!                                             "tet10" | "hex20" | "hex27" | "wedge6" |
//!                                             "wedge15" | "pyramid5")
//! /mesh/partition                  (M,)  i32  owning rank of each cell
//! /mesh/cell_body                  (M,)  i32  body index of each cell;
//!                                             attr bodies = 1-D string array (body names)
//! /mesh/node_sets/<name>           (n,)  i64  node ids
//! /mesh/facet_sets/<name>/         group; attr cell_type ("quad4" | "tri3" | "tri6" |
//!                                  "quad8" | "quad9", or "mixed" for a set of a wedge's
//!                                  or pyramid's triangles and quadrilaterals)
//!     nodes                        (F,k) i64  facet node connectivity (our facet order;
//!                                             "mixed": k the largest, rows padded with −1)
//!     cell                         (F,)  i64  cell owning each facet
//!     face                         (F,)  i8   local face number of the facet in that cell
//! /steps/<NNNNNN>/                 attrs: time f64, load_factor f64,
//!                                  newton_iterations i64, uzawa_iterations i64,
//!                                  converged u8 (0 | 1), wall_seconds f64
//!     displacement                 (N,3) f64
//!     reaction                     (N,3) f64
//!     <nodal field>                (N,c) f64
//!     <cell field>                 (M,c) f64
//!     <any relative path>          (K,) or (K,c) f64 from [`ResultFile::write_step_block`],
//!                                  (n,) f64 from [`ResultFile::write_step_small`]
//! /run                             attrs written once the run has ended (rank 0, file
//!                                  closed; [`write_run_record`]): ranks, dofs, steps,
//!                                  newton_iterations, uzawa_iterations, linear_iterations,
//!                                  cutbacks, bulk_tangent_assemblies, pattern_builds,
//!                                  preconditioner_builds, preconditioner_reuses (i64),
//!                                  wall_seconds (f64), schur_path ("none" | "schur" |
//!                                  "low-rank") and on a Schur path schur_dofs,
//!                                  bulk_factorisations, schur_factorisations,
//!                                  schur_growths, sparse_solves, dense_solves (i64)
//! /hertz                           (scenes with [hertz]) the set-up attrs, and at the end
//!                                  of the run the last step's comparison: load, p0,
//!                                  p0_exact, width, width_exact, p0_error, width_error,
//!                                  p0_error_nodal_average, width_error_nodal_average (f64)
//! ```
//!
//! A facet set is a group rather than a single `(F,k)` dataset because each
//! facet needs three arrays of different types and widths (nodes, owning cell,
//! local face); keeping them side by side under the set's name means one name
//! finds all three, and a reader that only wants connectivity reads `nodes`.
//!
//! String attributes are HDF5 variable-length UTF-8 strings (h5py returns
//! `str`); `bodies` is a 1-D array of them rather than a comma-joined string so
//! body names may contain commas. `converged` is `u8` rather than HDF5's
//! enum-based bool because every reader (h5py, h5dump, ParaView) shows it as a
//! plain number.
//!
//! `<NNNNNN>` is the step index zero-padded to six digits (more digits past
//! 999999), so the groups sort in step order under a plain name sort.
//!
//! # XDMF sidecar
//!
//! `out.xmf` next to `out.h5` (same stem) is written by rank 0 after the
//! mesh and extended after every step (the new grid written over the closing
//! tags, which follow it again), so it is always a complete document listing
//! exactly the steps in the file; see [`xdmf`] for its shape.
//!
//! # Collective calls
//!
//! Every method of [`ResultFile`] is collective over the communicator given
//! to [`ResultFile::create`]: all ranks call it, in the same order, with the
//! same names, shapes and set data (only the row blocks differ). The module
//! checks this (a fingerprint of the call is compared across ranks) and every
//! failure is agreed on, so when one rank fails all ranks return an error
//! instead of leaving the others blocked in the next collective call.

mod collective;
mod fingerprint;
mod header;
mod history_csv;
pub mod layout;
pub mod paths;
mod reader;
mod result_sink;
mod run_record;
mod tee;
mod writer;
pub mod xdmf;

use std::path::{Path, PathBuf};

pub use history_csv::HistoryCsv;
pub use reader::{
    dataset_shape, list_steps, read_dataset, read_f64_attr, read_nodal, read_rows, read_step_attrs,
    read_string_attr,
};
pub use result_sink::{create_result_file, Hdf5Sink, Provenance};
pub use run_record::{
    read_hertz_record, read_run_record, write_run_record, HertzRecord, RunRecord, SchurRecord,
};
pub use tee::Tee;
pub use writer::ResultFile;

/// One rank's contiguous block `[start, start + data.len() / cols)` of the rows
/// of a `(global_rows, cols)` array, row-major.
///
/// The blocks of all ranks must tile `0..global_rows` in rank order (rank 0
/// first); a rank with no rows passes an empty `data` and `start` equal to
/// where its block would begin.
#[derive(Debug, Clone, Copy)]
pub struct BlockRows<'a, T> {
    pub global_rows: usize,
    pub start: usize,
    pub cols: usize,
    pub data: &'a [T],
}

impl<'a, T> BlockRows<'a, T> {
    /// The whole array held by one rank (the serial case, or a rank that owns
    /// everything while the others pass [`BlockRows::empty`]).
    pub fn whole(data: &'a [T], cols: usize) -> Self {
        let global_rows = data.len().checked_div(cols).unwrap_or(0);
        Self {
            global_rows,
            start: 0,
            cols,
            data,
        }
    }

    /// No rows on this rank; `start` is where this rank's block would begin.
    pub fn empty(global_rows: usize, start: usize, cols: usize) -> Self {
        Self {
            global_rows,
            start,
            cols,
            data: &[],
        }
    }
}

/// Mesh-level data written once by [`ResultFile::create`].
///
/// `nodes`, `cells`, `partition` and `cell_body` are row blocks; everything
/// else must be identical on every rank (rank 0's copy is what gets written).
#[derive(Debug, Clone, Copy)]
pub struct MeshHeader<'a> {
    /// A cell type's name (`fem::CellType::name`).
    pub cell_type: &'a str,
    /// (N,3) reference coordinates.
    pub nodes: BlockRows<'a, f64>,
    /// (M,k) connectivity, 0-based global node ids, VTK node order (XDMF uses it as is;
    /// `fem::CellType::vtk_order`).
    pub cells: BlockRows<'a, i64>,
    /// (M,1) owning rank of each cell.
    pub partition: BlockRows<'a, i32>,
    /// (M,1) index into `bodies` of each cell.
    pub cell_body: BlockRows<'a, i32>,
    pub bodies: &'a [String],
    pub node_sets: &'a std::collections::BTreeMap<String, Vec<usize>>,
    pub facet_sets: &'a std::collections::BTreeMap<String, FacetSetOut>,
}

/// One facet set: `F = cell.len()` facets of `k` nodes each.
#[derive(Debug, Clone, PartialEq, Eq, Default)]
pub struct FacetSetOut {
    /// A facet type's name (`fem::FacetType::name`), or [`MIXED_FACETS`].
    pub facet_type: String,
    /// F*k node ids, row-major; a mixed set's shorter rows end in −1.
    pub nodes: Vec<i64>,
    pub k: usize,
    /// Global cell id owning each facet.
    pub cell: Vec<i64>,
    /// Local face number of each facet within its cell.
    pub face: Vec<i8>,
}

/// Per-step metadata, written as attributes of `/steps/<NNNNNN>`.
///
/// All fields except `wall_seconds` must be equal on every rank; the
/// attribute gets the maximum `wall_seconds` over the ranks (the step ends
/// when its slowest rank does).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct StepInfo {
    pub index: usize,
    pub time: f64,
    pub load_factor: f64,
    pub newton_iterations: usize,
    pub uzawa_iterations: usize,
    pub converged: bool,
    pub wall_seconds: f64,
}

/// Errors of this module. Each names the file and the HDF5 object concerned.
#[derive(Debug, thiserror::Error)]
pub enum OutputError {
    #[error("cannot create result file {}: {source}", .path.display())]
    Create { path: PathBuf, source: hdf5::Error },

    #[error("cannot open result file {}: {source}", .path.display())]
    Open { path: PathBuf, source: hdf5::Error },

    #[error("HDF5 failed to {action} '{object}' in {}: {source}", .path.display())]
    Hdf5 {
        path: PathBuf,
        object: String,
        action: &'static str,
        source: hdf5::Error,
    },

    #[error("invalid data for '{object}' in {}: {reason}", .path.display())]
    Invalid {
        path: PathBuf,
        object: String,
        reason: String,
    },

    #[error("ranks disagree on '{object}' in {}: {reason}", .path.display())]
    RankMismatch {
        path: PathBuf,
        object: String,
        reason: String,
    },

    /// A rank failed on a collective operation: every rank returns this,
    /// with the lowest failing rank's own message.
    #[error("rank {rank}: {message}")]
    PeerFailed {
        path: PathBuf,
        object: String,
        rank: i32,
        message: String,
    },

    #[error("cannot write XDMF sidecar {}: {source}", .path.display())]
    Xdmf {
        path: PathBuf,
        source: std::io::Error,
    },
}

impl From<OutputError> for crate::error::Error {
    fn from(e: OutputError) -> Self {
        crate::error::Error::Output(Box::new(e))
    }
}

impl OutputError {
    pub(crate) fn invalid(path: &Path, object: &str, reason: impl Into<String>) -> Self {
        Self::Invalid {
            path: path.to_path_buf(),
            object: object.to_string(),
            reason: reason.into(),
        }
    }

    pub(crate) fn hdf5(
        path: &Path,
        object: &str,
        action: &'static str,
        source: hdf5::Error,
    ) -> Self {
        Self::Hdf5 {
            path: path.to_path_buf(),
            object: object.to_string(),
            action,
            source,
        }
    }
}

pub use layout::step_group_name;

/// The `cell_type` of a facet set that holds facets of several types.
pub const MIXED_FACETS: &str = "mixed";

/// Number of nodes per row of a facet set of this type: the type's, or
/// `None` for an unknown name (a mixed set's rows are as long as its
/// largest facet's, which the set itself says).
pub(crate) fn facet_nodes(facet_type: &str) -> Option<usize> {
    crate::fem::FacetType::from_name(facet_type).map(|f| f.nodes())
}

/// Checks that `name` can be one HDF5 link name (one path component).
pub(crate) fn check_name(path: &Path, object: &str, name: &str) -> Result<(), OutputError> {
    if name.is_empty() || name == "." || name == ".." || name.contains(['/', '\0']) {
        return Err(OutputError::invalid(
            path,
            object,
            format!("'{name}' is not a valid HDF5 name (empty, '.', '..', or contains '/' or NUL)"),
        ));
    }
    Ok(())
}

#[cfg(test)]
mod tests;

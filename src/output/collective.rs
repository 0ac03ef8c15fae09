//! The collective context of a result file: agreeing on every rank's
//! outcome, checking that all ranks make the same call, and writing row
//! blocks through parallel HDF5.
//!
//! How the parallel writes are done (hdf5-metno 0.15.1):
//! - the file is opened with the MPI-IO driver
//!   (`FileAccessBuilder::mpio(comm.as_raw(), None)`) on a duplicate of the
//!   caller's communicator, so our own agreement messages never mix with the
//!   caller's traffic;
//! - every dataset and attribute is created by all ranks with identical
//!   arguments (HDF5 metadata operations are collective);
//! - datasets are contiguous (no chunking, no filters) with fill time
//!   `Never`: parallel HDF5 allocates contiguous storage at creation, and
//!   skipping the fill means each element is written exactly once;
//! - each rank writes its row block with `Container::write_slice` and a
//!   `(start..end, ..)` hyperslab. hdf5-metno 0.15.1 has no dataset-transfer
//!   property list wrapper, so `H5Dwrite` runs with the default transfer
//!   mode, i.e. independent MPI-IO. Every rank's block is one contiguous
//!   byte range of the file, the pattern for which independent I/O is
//!   already a single large write per rank (two-phase collective buffering
//!   exists to merge small interleaved pieces, which do not occur here).
//!   Ranks with no rows, and ranks other than 0 for rank-0 data, simply do
//!   not call `H5Dwrite`, which independent mode allows;
//! - `H5Fflush` (collective; the MPI-IO driver follows it with
//!   `MPI_File_sync`) ends every step.

use std::path::Path;
use std::str::FromStr;

use hdf5::dataset::FillTime;
use hdf5::types::VarLenUnicode;
use hdf5::{File, Group, H5Type, Location};
use mpi::topology::SimpleCommunicator;
use mpi::traits::Communicator;
use ndarray::{ArrayView1, ArrayView2};

use super::{BlockRows, OutputError};

/// The collective context: the communicator plus the file path for errors.
pub(super) struct Coll<'a> {
    pub(super) comm: &'a SimpleCommunicator,
    pub(super) path: &'a Path,
}

impl Coll<'_> {
    pub(super) fn size(&self) -> usize {
        usize::try_from(self.comm.size()).unwrap_or(1)
    }

    pub(super) fn is_root(&self) -> bool {
        self.comm.rank() == 0
    }

    /// Collective: every rank learns whether all ranks succeeded. If one
    /// failed, every rank returns `PeerFailed` with the lowest failing rank's
    /// message (agreed in [`crate::parallel`]). Without this, a rank that
    /// failed alone would return while the others wait forever in the next
    /// collective HDF5 call.
    pub(super) fn agree<T>(
        &self,
        object: &str,
        local: Result<T, OutputError>,
    ) -> Result<T, OutputError> {
        if self.size() == 1 {
            return local;
        }
        let (value, failure) = match local {
            Ok(v) => (Some(v), None),
            Err(e) => (None, Some((0, e.to_string()))),
        };
        match (crate::parallel::agree_failure(self.comm, failure), value) {
            (None, Some(v)) => Ok(v),
            (Some(f), _) => Err(self.peer_failed(object, f.rank, f.message)),
            (None, None) => Err(OutputError::invalid(
                self.path,
                object,
                "agreement lost a value",
            )),
        }
    }

    pub(super) fn peer_failed(&self, object: &str, rank: usize, message: String) -> OutputError {
        OutputError::PeerFailed {
            path: self.path.to_path_buf(),
            object: object.to_string(),
            rank: i32::try_from(rank).unwrap_or(i32::MAX),
            message,
        }
    }

    /// Collective: checks that every rank was called with the same structure
    /// (names, shapes, set contents) by comparing fingerprints. Differing
    /// arguments would otherwise corrupt the file's metadata or deadlock.
    pub(super) fn same_everywhere(
        &self,
        object: &str,
        fingerprint: u64,
    ) -> Result<(), OutputError> {
        let all = crate::parallel::gather_equal(self.comm, &[fingerprint]);
        let first = all.first().copied().unwrap_or(fingerprint);
        match all.iter().position(|&f| f != first) {
            None => Ok(()),
            Some(rank) => Err(OutputError::RankMismatch {
                path: self.path.to_path_buf(),
                object: object.to_string(),
                reason: format!(
                    "rank {rank} was called with different names, shapes, step metadata or \
                     set data than rank 0"
                ),
            }),
        }
    }

    /// Collective: checks that the row blocks of all ranks tile
    /// `0..global_rows` in rank order with the same `cols`, and returns this
    /// rank's `(start, rows)`. Every rank sees the same gathered table, so all
    /// reach the same verdict. Empty blocks may carry any `start`.
    pub(super) fn block_layout<T>(
        &self,
        object: &str,
        rows: &BlockRows<T>,
        expect_rows: Option<usize>,
        expect_cols: Option<usize>,
    ) -> Result<(usize, usize), OutputError> {
        let local = local_rows(self.path, object, rows);
        let mine = [
            rows.start as u64,
            local.as_ref().map_or(0, |&n| n as u64),
            rows.global_rows as u64,
            rows.cols as u64,
            u64::from(local.is_ok()),
        ];
        let table = crate::parallel::gather_equal(self.comm, &mine);
        let local = self.agree_from_table(object, local, &table)?;

        let invalid = |reason: String| Err(OutputError::invalid(self.path, object, reason));
        let global = rows.global_rows as u64;
        let cols = rows.cols as u64;
        let mut next = 0_u64;
        for (rank, entry) in table.chunks_exact(5).enumerate() {
            if let [start, n, g, c, _] = *entry {
                if g != global || c != cols {
                    return Err(OutputError::RankMismatch {
                        path: self.path.to_path_buf(),
                        object: object.to_string(),
                        reason: format!(
                            "rank {rank} has a ({g},{c}) array, rank {} has ({global},{cols})",
                            self.comm.rank()
                        ),
                    });
                }
                if n > 0 && start != next {
                    return invalid(format!(
                        "rank {rank}'s block starts at row {start}, expected {next} \
                         (blocks must tile 0..{global} in rank order)"
                    ));
                }
                next += n;
            }
        }
        if next != global {
            return invalid(format!(
                "the blocks of all ranks cover {next} rows, the array has {global}"
            ));
        }
        if let Some(want) = expect_rows {
            if rows.global_rows != want {
                return invalid(format!("has {} rows, expected {want}", rows.global_rows));
            }
        }
        if let Some(want) = expect_cols {
            if rows.cols != want {
                return invalid(format!("has {} columns, expected {want}", rows.cols));
            }
        }
        Ok((rows.start, local))
    }

    /// Like [`Coll::agree`] but reads the success flags from an already
    /// gathered layout table (saves a second collective).
    pub(super) fn agree_from_table(
        &self,
        object: &str,
        local: Result<usize, OutputError>,
        table: &[u64],
    ) -> Result<usize, OutputError> {
        match table.chunks_exact(5).position(|e| e.get(4) != Some(&1)) {
            None => local,
            Some(_) if self.size() == 1 => local,
            Some(rank) => {
                // Every rank saw the same table: all take this branch.
                let mine = local.err().map(|e| e.to_string()).unwrap_or_default();
                let message = crate::parallel::broadcast_text(self.comm, rank, &mine);
                Err(self.peer_failed(object, rank, message))
            }
        }
    }

    /// Collective: checks the layout, then creates and writes the dataset
    /// (for callers with nothing to do between the two).
    pub(super) fn write_block<T: H5Type>(
        &self,
        group: &Group,
        group_path: &str,
        name: &str,
        rows: &BlockRows<T>,
        one_d: bool,
        expect_rows: Option<usize>,
    ) -> Result<(), OutputError> {
        let object = format!("{group_path}/{name}");
        let layout = self.block_layout(&object, rows, expect_rows, one_d.then_some(1))?;
        self.write_checked_block(group, &object, name, rows, one_d, layout)
    }

    /// Collective: creates `group/name` as a `(global,)` or `(global, cols)`
    /// dataset and writes every rank's row block into it. `layout` comes
    /// from [`Coll::block_layout`] on the same `rows`.
    pub(super) fn write_checked_block<T: H5Type>(
        &self,
        group: &Group,
        object: &str,
        name: &str,
        rows: &BlockRows<T>,
        one_d: bool,
        (start, n): (usize, usize),
    ) -> Result<(), OutputError> {
        let shape = if one_d {
            vec![rows.global_rows]
        } else {
            vec![rows.global_rows, rows.cols]
        };
        let created = create_dataset::<T>(group, name, &shape)
            .map_err(|e| OutputError::hdf5(self.path, object, "create dataset", e));
        let ds = self.agree(object, created)?;
        let wrote = if n == 0 {
            Ok(())
        } else if one_d {
            ds.write_slice(ArrayView1::from(rows.data), start..start + n)
                .map_err(|e| OutputError::hdf5(self.path, object, "write rows of", e))
        } else {
            match ArrayView2::from_shape((n, rows.cols), rows.data) {
                Ok(view) => ds
                    .write_slice(view, (start..start + n, ..))
                    .map_err(|e| OutputError::hdf5(self.path, object, "write rows of", e)),
                Err(e) => Err(OutputError::invalid(self.path, object, e.to_string())),
            }
        };
        self.agree(object, wrote)
    }

    /// Collective: creates `group/name` with `shape` on every rank; rank 0
    /// writes `data` (which every rank holds), the others write nothing.
    pub(super) fn write_root<T: H5Type>(
        &self,
        group: &Group,
        group_path: &str,
        name: &str,
        shape: &[usize],
        data: &[T],
    ) -> Result<hdf5::Dataset, OutputError> {
        let object = format!("{group_path}/{name}");
        let created = create_dataset::<T>(group, name, shape)
            .map_err(|e| OutputError::hdf5(self.path, &object, "create dataset", e));
        let ds = self.agree(&object, created)?;
        let wrote = if self.is_root() && !data.is_empty() {
            ds.write_raw(data)
                .map_err(|e| OutputError::hdf5(self.path, &object, "write", e))
        } else {
            Ok(())
        };
        self.agree(&object, wrote)?;
        Ok(ds)
    }

    /// Collective: opens `parent/name`, creating it if it does not exist yet.
    /// `link_exists` reads metadata every rank holds identically, so all ranks
    /// take the same branch.
    pub(super) fn open_or_create_group(
        &self,
        parent: &Group,
        object: &str,
        name: &str,
    ) -> Result<Group, OutputError> {
        let res = if parent.link_exists(name) {
            parent
                .group(name)
                .map_err(|e| OutputError::hdf5(self.path, object, "open group", e))
        } else {
            parent
                .create_group(name)
                .map_err(|e| OutputError::hdf5(self.path, object, "create group", e))
        };
        self.agree(object, res)
    }

    pub(super) fn flush(&self, file: &File) -> Result<(), OutputError> {
        let res = file
            .flush()
            .map_err(|e| OutputError::hdf5(self.path, "/", "flush", e));
        self.agree("/", res)
    }
}

/// Rows this rank holds, after local shape checks.
pub(super) fn local_rows<T>(
    path: &Path,
    object: &str,
    rows: &BlockRows<T>,
) -> Result<usize, OutputError> {
    if rows.cols == 0 {
        return Err(OutputError::invalid(path, object, "cols is 0"));
    }
    if !rows.data.len().is_multiple_of(rows.cols) {
        return Err(OutputError::invalid(
            path,
            object,
            format!(
                "{} values are not a whole number of rows of {} columns",
                rows.data.len(),
                rows.cols
            ),
        ));
    }
    let n = rows.data.len() / rows.cols;
    if n > 0
        && rows
            .start
            .checked_add(n)
            .is_none_or(|end| end > rows.global_rows)
    {
        return Err(OutputError::invalid(
            path,
            object,
            format!(
                "block [{}, {}+{n}) exceeds the {} global rows",
                rows.start, rows.start, rows.global_rows
            ),
        ));
    }
    Ok(n)
}

pub(super) fn create_dataset<T: H5Type>(
    group: &Group,
    name: &str,
    shape: &[usize],
) -> hdf5::Result<hdf5::Dataset> {
    group
        .new_dataset::<T>()
        .shape(shape)
        .fill_time(FillTime::Never)
        .create(name)
}

pub(super) fn attr_scalar<T: H5Type>(loc: &Location, name: &str, value: &T) -> hdf5::Result<()> {
    loc.new_attr::<T>().create(name)?.write_scalar(value)
}

pub(super) fn to_h5_string(
    path: &Path,
    object: &str,
    s: &str,
) -> Result<VarLenUnicode, OutputError> {
    VarLenUnicode::from_str(s).map_err(|e| OutputError::invalid(path, object, e.to_string()))
}

pub(super) fn attr_string(
    path: &Path,
    loc: &Location,
    object: &str,
    name: &str,
    value: &str,
) -> Result<(), OutputError> {
    let v = to_h5_string(path, object, value)?;
    attr_scalar(loc, name, &v).map_err(|e| OutputError::hdf5(path, object, "write attribute of", e))
}

pub(super) fn to_i64(path: &Path, object: &str, v: usize) -> Result<i64, OutputError> {
    i64::try_from(v)
        .map_err(|_| OutputError::invalid(path, object, format!("{v} does not fit in i64")))
}

//! The parallel HDF5 writer ([`ResultFile`]) and serial read-back helpers.
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

use std::path::{Path, PathBuf};
use std::str::FromStr;

use hdf5::dataset::FillTime;
use hdf5::types::VarLenUnicode;
use hdf5::{File, Group, H5Type, Location};
use mpi::topology::SimpleCommunicator;
use mpi::traits::{AsRaw, Communicator, CommunicatorCollectives};
use ndarray::{ArrayView1, ArrayView2};

use super::xdmf::{self, Center, FieldDesc, MeshDesc, StepDesc};
use super::{
    check_name, facet_nodes, step_group_name, BlockRows, CellKind, MeshHeader, OutputError,
    StepInfo,
};

/// An open result file. All methods are collective (see the module docs).
///
/// Drop (or [`ResultFile::close`]) it on every rank before MPI is finalized:
/// closing a parallel HDF5 file is itself a collective MPI-IO call.
pub struct ResultFile {
    comm: SimpleCommunicator,
    file: File,
    path: PathBuf,
    xdmf_path: PathBuf,
    mesh: MeshDesc,
    /// Group names of the steps written, to refuse a step twice.
    written: std::collections::BTreeSet<String>,
    /// The open sidecar, on rank 0 (set by [`ResultFile::create`]).
    sidecar: Option<xdmf::Sidecar>,
}

/// A dataset under a step: `/steps/<group>/<dirs...>/<name>` = `object`.
struct StepTarget {
    group: String,
    dirs: Vec<String>,
    name: String,
    object: String,
}

/// The collective context: the communicator plus the file path for errors.
struct Coll<'a> {
    comm: &'a SimpleCommunicator,
    path: &'a Path,
}

impl Coll<'_> {
    fn size(&self) -> usize {
        usize::try_from(self.comm.size()).unwrap_or(1)
    }

    fn is_root(&self) -> bool {
        self.comm.rank() == 0
    }

    /// Collective: every rank learns whether all ranks succeeded. If one
    /// failed, every rank returns `PeerFailed` with the lowest failing rank's
    /// message (agreed in [`crate::parallel`]). Without this, a rank that
    /// failed alone would return while the others wait forever in the next
    /// collective HDF5 call.
    fn agree<T>(&self, object: &str, local: Result<T, OutputError>) -> Result<T, OutputError> {
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

    fn peer_failed(&self, object: &str, rank: usize, message: String) -> OutputError {
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
    fn same_everywhere(&self, object: &str, fingerprint: u64) -> Result<(), OutputError> {
        let mut all = vec![0_u64; self.size()];
        self.comm.all_gather_into(&fingerprint, &mut all[..]);
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
    fn block_layout<T>(
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
        let mut table = vec![0_u64; 5 * self.size()];
        self.comm.all_gather_into(&mine[..], &mut table[..]);
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
    fn agree_from_table(
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
    fn write_block<T: H5Type>(
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
    fn write_checked_block<T: H5Type>(
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
    fn write_root<T: H5Type>(
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
    fn open_or_create_group(
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

    fn flush(&self, file: &File) -> Result<(), OutputError> {
        let res = file
            .flush()
            .map_err(|e| OutputError::hdf5(self.path, "/", "flush", e));
        self.agree("/", res)
    }
}

/// Rows this rank holds, after local shape checks.
fn local_rows<T>(path: &Path, object: &str, rows: &BlockRows<T>) -> Result<usize, OutputError> {
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

fn create_dataset<T: H5Type>(
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

fn attr_scalar<T: H5Type>(loc: &Location, name: &str, value: &T) -> hdf5::Result<()> {
    loc.new_attr::<T>().create(name)?.write_scalar(value)
}

fn to_h5_string(path: &Path, object: &str, s: &str) -> Result<VarLenUnicode, OutputError> {
    VarLenUnicode::from_str(s).map_err(|e| OutputError::invalid(path, object, e.to_string()))
}

fn attr_string(
    path: &Path,
    loc: &Location,
    object: &str,
    name: &str,
    value: &str,
) -> Result<(), OutputError> {
    let v = to_h5_string(path, object, value)?;
    attr_scalar(loc, name, &v).map_err(|e| OutputError::hdf5(path, object, "write attribute of", e))
}

fn to_i64(path: &Path, object: &str, v: usize) -> Result<i64, OutputError> {
    i64::try_from(v)
        .map_err(|_| OutputError::invalid(path, object, format!("{v} does not fit in i64")))
}

/// FNV-1a over a length-prefixed encoding: a cheap, deterministic summary of
/// the arguments of a collective call, compared across ranks.
struct Fingerprint(u64);

impl Fingerprint {
    fn new() -> Self {
        Self(0xcbf2_9ce4_8422_2325)
    }
    fn bytes(&mut self, b: &[u8]) {
        for &x in b {
            self.0 ^= u64::from(x);
            self.0 = self.0.wrapping_mul(0x0100_0000_01b3);
        }
    }
    fn u64(&mut self, v: u64) {
        self.bytes(&v.to_le_bytes());
    }
    fn usize(&mut self, v: usize) {
        self.u64(v as u64);
    }
    fn str(&mut self, s: &str) {
        self.usize(s.len());
        self.bytes(s.as_bytes());
    }
    fn i64s(&mut self, v: &[i64]) {
        self.usize(v.len());
        v.iter().for_each(|&x| self.bytes(&x.to_le_bytes()));
    }
    fn f64s(&mut self, v: &[f64]) {
        self.usize(v.len());
        v.iter().for_each(|&x| self.u64(x.to_bits()));
    }
}

/// Everything of a header that must be equal on all ranks (the block data
/// is excluded: it differs by design; its global shape is included).
fn header_fingerprint(mesh: &MeshHeader) -> u64 {
    let mut f = Fingerprint::new();
    f.str(mesh.cell_type);
    f.str(mesh.facet_type);
    for (rows, cols) in [
        (mesh.nodes.global_rows, mesh.nodes.cols),
        (mesh.cells.global_rows, mesh.cells.cols),
        (mesh.partition.global_rows, mesh.partition.cols),
        (mesh.cell_body.global_rows, mesh.cell_body.cols),
    ] {
        f.usize(rows);
        f.usize(cols);
    }
    f.usize(mesh.bodies.len());
    mesh.bodies.iter().for_each(|b| f.str(b));
    f.usize(mesh.node_sets.len());
    for (name, ids) in mesh.node_sets {
        f.str(name);
        f.usize(ids.len());
        ids.iter().for_each(|&i| f.usize(i));
    }
    f.usize(mesh.facet_sets.len());
    for (name, fs) in mesh.facet_sets {
        f.str(name);
        f.usize(fs.k);
        f.i64s(&fs.nodes);
        f.i64s(&fs.cell);
        f.usize(fs.face.len());
        fs.face.iter().for_each(|&x| f.bytes(&x.to_le_bytes()));
    }
    f.0
}

/// What the XDMF writer needs, after all local checks of the header.
fn validate_header(path: &Path, mesh: &MeshHeader) -> Result<MeshDesc, OutputError> {
    let invalid = |object: &str, reason: String| Err(OutputError::invalid(path, object, reason));
    let Some(kind) = CellKind::parse(mesh.cell_type) else {
        return invalid(
            "/mesh/cells",
            format!("cell_type '{}' is not hex8 or tet4", mesh.cell_type),
        );
    };
    let Some(facet_k) = facet_nodes(mesh.facet_type) else {
        return invalid(
            "/mesh/facet_sets",
            format!("facet_type '{}' is not quad4 or tri3", mesh.facet_type),
        );
    };
    let n_nodes = mesh.nodes.global_rows;
    let n_cells = mesh.cells.global_rows;
    if mesh.nodes.cols != 3 {
        return invalid(
            "/mesh/nodes",
            format!("has {} columns, expected 3", mesh.nodes.cols),
        );
    }
    if mesh.cells.cols != kind.nodes() {
        return invalid(
            "/mesh/cells",
            format!(
                "has {} columns, {} cells have {}",
                mesh.cells.cols,
                kind.name(),
                kind.nodes()
            ),
        );
    }
    for (object, b) in [
        ("/mesh/partition", &mesh.partition),
        ("/mesh/cell_body", &mesh.cell_body),
    ] {
        if b.cols != 1 || b.global_rows != n_cells {
            return invalid(
                object,
                format!("is ({},{}), expected ({n_cells},1)", b.global_rows, b.cols),
            );
        }
    }
    let h5_name = match path.file_name().and_then(|n| n.to_str()) {
        Some(n) => n.to_string(),
        None => return invalid("/", "the file name is empty or not UTF-8".into()),
    };
    if xdmf::sidecar_path(path) == path {
        return invalid(
            "/",
            "the result file must not end in .xmf (the sidecar's name)".into(),
        );
    }

    // Local block contents: node ids in range, body and rank indices valid.
    if let Some(bad) = mesh
        .cells
        .data
        .iter()
        .find(|&&id| usize::try_from(id).map_or(true, |i| i >= n_nodes))
    {
        return invalid(
            "/mesh/cells",
            format!("node id {bad} is outside 0..{n_nodes}"),
        );
    }
    let n_bodies = mesh.bodies.len();
    if let Some(bad) = mesh
        .cell_body
        .data
        .iter()
        .find(|&&b| usize::try_from(b).map_or(true, |i| i >= n_bodies))
    {
        return invalid(
            "/mesh/cell_body",
            format!("body index {bad} is outside 0..{n_bodies} (the bodies list)"),
        );
    }
    if let Some(bad) = mesh.partition.data.iter().find(|&&r| r < 0) {
        return invalid("/mesh/partition", format!("negative rank {bad}"));
    }
    for body in mesh.bodies {
        to_h5_string(path, "/mesh/cell_body", body)?;
    }

    for (name, ids) in mesh.node_sets {
        let object = format!("/mesh/node_sets/{name}");
        check_name(path, &object, name)?;
        if let Some(bad) = ids.iter().find(|&&i| i >= n_nodes) {
            return invalid(&object, format!("node id {bad} is outside 0..{n_nodes}"));
        }
    }
    for (name, fs) in mesh.facet_sets {
        let object = format!("/mesh/facet_sets/{name}");
        check_name(path, &object, name)?;
        let f = fs.cell.len();
        if fs.k != facet_k {
            return invalid(
                &object,
                format!(
                    "k = {}, but {} facets have {facet_k} nodes",
                    fs.k, mesh.facet_type
                ),
            );
        }
        if fs.nodes.len() != f * fs.k || fs.face.len() != f {
            return invalid(
                &object,
                format!(
                    "{} cells, {} faces and {} node ids do not describe {f} facets of {} nodes",
                    f,
                    fs.face.len(),
                    fs.nodes.len(),
                    fs.k
                ),
            );
        }
        if let Some(bad) = fs
            .nodes
            .iter()
            .find(|&&id| usize::try_from(id).map_or(true, |i| i >= n_nodes))
        {
            return invalid(&object, format!("node id {bad} is outside 0..{n_nodes}"));
        }
        if let Some(bad) = fs
            .cell
            .iter()
            .find(|&&c| usize::try_from(c).map_or(true, |i| i >= n_cells))
        {
            return invalid(&object, format!("cell id {bad} is outside 0..{n_cells}"));
        }
    }
    Ok(MeshDesc {
        h5_name,
        cell_kind: kind,
        n_nodes,
        n_cells,
    })
}

/// The step metadata and field structure that must match on all ranks.
fn step_fingerprint(
    info: &StepInfo,
    nodal: &[(&str, BlockRows<f64>)],
    cell: &[(&str, BlockRows<f64>)],
) -> u64 {
    let mut f = Fingerprint::new();
    f.usize(info.index);
    f.u64(info.time.to_bits());
    f.u64(info.load_factor.to_bits());
    f.usize(info.newton_iterations);
    f.usize(info.uzawa_iterations);
    f.u64(u64::from(info.converged));
    for fields in [nodal, cell] {
        f.usize(fields.len());
        for (name, rows) in fields {
            f.str(name);
            f.usize(rows.global_rows);
            f.usize(rows.cols);
        }
    }
    f.0
}

impl ResultFile {
    /// Collective. Creates (or truncates) `path` with the MPI-IO driver on all
    /// ranks of `comm`, writes `/mesh`, flushes, and writes the sidecar with no
    /// steps (replacing any stale one). Fails on every rank, with an error
    /// naming `path`, if the file cannot be created, so call it before any
    /// solve.
    pub fn create(
        comm: &SimpleCommunicator,
        path: &Path,
        mesh: &MeshHeader,
    ) -> Result<Self, OutputError> {
        let comm = comm.duplicate();
        let coll = Coll { comm: &comm, path };
        let desc = coll.agree("/mesh", validate_header(path, mesh))?;
        coll.same_everywhere("/mesh", header_fingerprint(mesh))?;

        let created = File::with_options()
            .with_fapl(|p| p.mpio(comm.as_raw(), None))
            .create(path)
            .map_err(|source| OutputError::Create {
                path: path.to_path_buf(),
                source,
            });
        let file = coll.agree("/", created)?;

        let mut out = Self {
            xdmf_path: xdmf::sidecar_path(path),
            path: path.to_path_buf(),
            comm,
            file,
            mesh: desc,
            written: Default::default(),
            sidecar: None,
        };
        out.write_mesh(mesh)?;
        out.flush()?;
        out.create_xdmf()?;
        Ok(out)
    }

    fn coll(&self) -> Coll<'_> {
        Coll {
            comm: &self.comm,
            path: &self.path,
        }
    }

    fn write_mesh(&mut self, mesh: &MeshHeader) -> Result<(), OutputError> {
        let c = self.coll();
        let p = c.path;
        let root: &Group = &self.file;
        let gmesh = c.open_or_create_group(root, "/mesh", "mesh")?;
        let gnode_sets = c.open_or_create_group(&gmesh, "/mesh/node_sets", "node_sets")?;
        let gfacet_sets = c.open_or_create_group(&gmesh, "/mesh/facet_sets", "facet_sets")?;
        c.open_or_create_group(root, "/steps", "steps")?;

        let n_nodes = self.mesh.n_nodes;
        let n_cells = self.mesh.n_cells;
        c.write_block(&gmesh, "/mesh", "nodes", &mesh.nodes, false, Some(n_nodes))?;
        c.write_block(&gmesh, "/mesh", "cells", &mesh.cells, false, Some(n_cells))?;
        c.write_block(
            &gmesh,
            "/mesh",
            "partition",
            &mesh.partition,
            true,
            Some(n_cells),
        )?;
        c.write_block(
            &gmesh,
            "/mesh",
            "cell_body",
            &mesh.cell_body,
            true,
            Some(n_cells),
        )?;

        let attrs = (|| {
            let cells = gmesh
                .dataset("cells")
                .map_err(|e| OutputError::hdf5(p, "/mesh/cells", "open", e))?;
            attr_string(
                p,
                &cells,
                "/mesh/cells",
                "cell_type",
                self.mesh.cell_kind.name(),
            )?;
            let body = gmesh
                .dataset("cell_body")
                .map_err(|e| OutputError::hdf5(p, "/mesh/cell_body", "open", e))?;
            let names = mesh
                .bodies
                .iter()
                .map(|b| to_h5_string(p, "/mesh/cell_body", b))
                .collect::<Result<Vec<_>, _>>()?;
            body.new_attr::<VarLenUnicode>()
                .shape([names.len()])
                .create("bodies")
                .and_then(|a| a.write_raw(&names))
                .map_err(|e| {
                    OutputError::hdf5(p, "/mesh/cell_body", "write attribute 'bodies' of", e)
                })
        })();
        c.agree("/mesh/cells", attrs)?;

        for (name, ids) in mesh.node_sets {
            let object = format!("/mesh/node_sets/{name}");
            let ids = c.agree(
                &object,
                ids.iter()
                    .map(|&i| to_i64(p, &object, i))
                    .collect::<Result<Vec<_>, _>>(),
            )?;
            c.write_root(&gnode_sets, "/mesh/node_sets", name, &[ids.len()], &ids)?;
        }
        for (name, fs) in mesh.facet_sets {
            let object = format!("/mesh/facet_sets/{name}");
            let g = c.open_or_create_group(&gfacet_sets, &object, name)?;
            let f = fs.cell.len();
            c.write_root(&g, &object, "nodes", &[f, fs.k], &fs.nodes)?;
            c.write_root(&g, &object, "cell", &[f], &fs.cell)?;
            c.write_root(&g, &object, "face", &[f], &fs.face)?;
            let a = attr_string(p, &g, &object, "cell_type", mesh.facet_type);
            c.agree(&object, a)?;
        }
        Ok(())
    }

    /// Collective. Writes `/steps/<NNNNNN>` with its attributes, then the
    /// nodal fields (`(N,c)`, must include `displacement` and `reaction` with
    /// c = 3) and cell fields (`(M,c)`), then flushes the file so that a run
    /// killed after this returns leaves a readable file holding this step;
    /// then rank 0 rewrites the XDMF sidecar.
    ///
    /// Field datasets are always 2-D, even for c = 1, so their shape says
    /// which kind of field they are.
    pub fn write_step(
        &mut self,
        info: &StepInfo,
        nodal: &[(&str, BlockRows<f64>)],
        cell: &[(&str, BlockRows<f64>)],
    ) -> Result<(), OutputError> {
        let group = step_group_name(info.index);
        let gpath = format!("/steps/{group}");
        let c = self.coll();
        let p = c.path;
        let checked = self.check_step(&gpath, info, nodal, cell).and_then(|()| {
            use crate::parallel::fault::{self, FaultPhase};
            if fault::fires(FaultPhase::OutputWrite) {
                let why = crate::Error::Fault(FaultPhase::OutputWrite.name()).to_string();
                return Err(OutputError::invalid(p, &gpath, why));
            }
            Ok(())
        });
        c.agree(&gpath, checked)?;
        c.same_everywhere(&gpath, step_fingerprint(info, nodal, cell))?;

        // Check every field's block layout before anything is created, so a
        // rejected call leaves no trace in the file.
        let mut layouts = Vec::with_capacity(nodal.len() + cell.len());
        for (list, center, expect) in [
            (nodal, Center::Node, self.mesh.n_nodes),
            (cell, Center::Cell, self.mesh.n_cells),
        ] {
            for (name, block) in list {
                let object = format!("{gpath}/{name}");
                let layout = c.block_layout(&object, block, Some(expect), None)?;
                layouts.push((object, *name, block, center, layout));
            }
        }

        // The slowest rank's time is the step's time; every rank must write
        // the same attribute value, so reduce first.
        let [wall] = crate::parallel::max(&self.comm, [info.wall_seconds]);

        let gsteps = self
            .file
            .group("steps")
            .map_err(|e| OutputError::hdf5(p, "/steps", "open group", e));
        let gsteps = c.agree("/steps", gsteps)?;
        let g = gsteps
            .create_group(&group)
            .map_err(|e| OutputError::hdf5(p, &gpath, "create group", e));
        let g = c.agree(&gpath, g)?;
        let written = (|| {
            let attrs = (|| {
                let h = |e| OutputError::hdf5(p, &gpath, "write attributes of", e);
                let newton = to_i64(p, &gpath, info.newton_iterations)?;
                let uzawa = to_i64(p, &gpath, info.uzawa_iterations)?;
                attr_scalar(&g, "time", &info.time).map_err(h)?;
                attr_scalar(&g, "load_factor", &info.load_factor).map_err(h)?;
                attr_scalar(&g, "newton_iterations", &newton).map_err(h)?;
                attr_scalar(&g, "uzawa_iterations", &uzawa).map_err(h)?;
                attr_scalar(&g, "converged", &u8::from(info.converged)).map_err(h)?;
                attr_scalar(&g, "wall_seconds", &wall).map_err(h)
            })();
            c.agree(&gpath, attrs)?;
            for (object, name, block, _, layout) in &layouts {
                c.write_checked_block(&g, object, name, block, false, *layout)?;
            }
            Ok(())
        })();
        if let Err(e) = written {
            // Every rank got the same verdict (each step above ends in an
            // agreement), so all ranks unlink together: the file keeps only
            // complete steps, matching the sidecar. Best effort: the
            // original error is the one worth reporting.
            drop(g);
            let _ = gsteps.unlink(&group);
            return Err(e);
        }
        c.flush(&self.file)?;
        let fields = layouts
            .iter()
            .map(|(_, name, block, center, _)| FieldDesc {
                name: (*name).to_string(),
                cols: block.cols,
                center: *center,
            })
            .collect();
        let step = StepDesc {
            group: group.clone(),
            time: info.time,
            fields,
        };
        self.written.insert(group);
        self.append_xdmf(&step)
    }

    /// Local checks of a `write_step` call (same verdict on every rank for
    /// everything but the block shapes, which `block_layout` checks).
    fn check_step(
        &self,
        gpath: &str,
        info: &StepInfo,
        nodal: &[(&str, BlockRows<f64>)],
        cell: &[(&str, BlockRows<f64>)],
    ) -> Result<(), OutputError> {
        let p = self.path.as_path();
        if self.written.contains(&step_group_name(info.index)) {
            return Err(OutputError::invalid(
                p,
                gpath,
                "this step was already written",
            ));
        }
        let mut seen = std::collections::BTreeSet::new();
        for (name, _) in nodal.iter().chain(cell) {
            check_name(p, gpath, name)?;
            if !seen.insert(*name) {
                return Err(OutputError::invalid(
                    p,
                    gpath,
                    format!("field '{name}' given twice"),
                ));
            }
        }
        for required in ["displacement", "reaction"] {
            match nodal.iter().find(|(n, _)| *n == required) {
                Some((_, b)) if b.cols == 3 => {}
                Some((_, b)) => {
                    return Err(OutputError::invalid(
                        p,
                        &format!("{gpath}/{required}"),
                        format!("has {} columns, expected 3", b.cols),
                    ))
                }
                None => {
                    return Err(OutputError::invalid(
                        p,
                        gpath,
                        format!("nodal field '{required}' is missing"),
                    ))
                }
            }
        }
        Ok(())
    }

    /// Collective. Writes `/steps/<NNNNNN>/<rel_path>` (intermediate groups
    /// are created) from per-rank contiguous row blocks: a `(K,)` dataset for
    /// `cols == 1`, `(K,cols)` otherwise. The step must have been written by
    /// [`ResultFile::write_step`]. Not flushed: call [`ResultFile::flush`]
    /// after the step's last contact array (one sync for all of them).
    pub fn write_step_block(
        &mut self,
        step: usize,
        rel_path: &str,
        rows: BlockRows<f64>,
    ) -> Result<(), OutputError> {
        let target = self.check_step_path(step, rel_path, |f| {
            f.usize(rows.global_rows);
            f.usize(rows.cols);
        })?;
        let c = self.coll();
        let one_d = rows.cols == 1;
        let layout = c.block_layout(&target.object, &rows, None, None)?;
        let parent = self.open_parent(&target)?;
        c.write_checked_block(&parent, &target.object, &target.name, &rows, one_d, layout)
    }

    /// Collective. Writes a small `(n,)` f64 array at
    /// `/steps/<NNNNNN>/<rel_path>`; every rank passes the same `data`, rank 0
    /// writes it. Not flushed (see [`ResultFile::write_step_block`]).
    pub fn write_step_small(
        &mut self,
        step: usize,
        rel_path: &str,
        data: &[f64],
    ) -> Result<(), OutputError> {
        let target = self.check_step_path(step, rel_path, |f| f.f64s(data))?;
        let parent = self.open_parent(&target)?;
        let gpath = target
            .object
            .rsplit_once('/')
            .map_or(target.object.as_str(), |(g, _)| g);
        self.coll()
            .write_root(&parent, gpath, &target.name, &[data.len()], data)
            .map(|_| ())
    }

    /// Collective. Writes string and f64 attributes on `group` (`"/"` for the
    /// file's root; a top-level group is created when missing). Every rank
    /// passes the same values. For run metadata that belongs to no step: the
    /// scene text and the closed-form setup a post-processor needs.
    pub fn write_attributes(
        &mut self,
        group: &str,
        strings: &[(&str, &str)],
        numbers: &[(&str, f64)],
    ) -> Result<(), OutputError> {
        let c = self.coll();
        let p = c.path;
        let name = group.trim_start_matches('/');
        let local = if name.is_empty() {
            Ok(())
        } else {
            check_name(p, group, name)
        };
        c.agree(group, local)?;
        let mut f = Fingerprint::new();
        f.str(group);
        for (k, v) in strings {
            f.str(k);
            f.str(v);
        }
        for (k, v) in numbers {
            f.str(k);
            f.f64s(&[*v]);
        }
        c.same_everywhere(group, f.0)?;
        let root: &Group = &self.file;
        let g = if name.is_empty() {
            root.clone()
        } else {
            c.open_or_create_group(root, group, name)?
        };
        let res = (|| {
            for (k, v) in strings {
                attr_string(p, &g, group, k, v)?;
            }
            for (k, v) in numbers {
                attr_scalar(&g, k, v)
                    .map_err(|e| OutputError::hdf5(p, group, "write attribute of", e))?;
            }
            Ok(())
        })();
        c.agree(group, res)
    }

    /// Collective, no side effects: checks that the step exists, that
    /// `rel_path` is a valid relative HDF5 path, and that all ranks make the
    /// same call (`extra` adds the call's shape or data to the fingerprint).
    fn check_step_path(
        &self,
        step: usize,
        rel_path: &str,
        extra: impl FnOnce(&mut Fingerprint),
    ) -> Result<StepTarget, OutputError> {
        let c = self.coll();
        let p = c.path;
        let group = step_group_name(step);
        let object = format!("/steps/{group}/{rel_path}");
        let mut dirs: Vec<String> = rel_path.split('/').map(str::to_string).collect();
        let name = dirs.pop().unwrap_or_default();
        let local = (|| {
            if !self.written.contains(&group) {
                return Err(OutputError::invalid(
                    p,
                    &object,
                    "the step has not been written by write_step on this file",
                ));
            }
            check_name(p, &object, &name)?;
            dirs.iter().try_for_each(|d| check_name(p, &object, d))
        })();
        c.agree(&object, local)?;
        let mut f = Fingerprint::new();
        f.usize(step);
        f.str(rel_path);
        extra(&mut f);
        c.same_everywhere(&object, f.0)?;
        Ok(StepTarget {
            group,
            dirs,
            name,
            object,
        })
    }

    /// Collective: opens the step group and opens or creates the
    /// intermediate groups of `target`, returning the dataset's parent.
    fn open_parent(&self, target: &StepTarget) -> Result<Group, OutputError> {
        let c = self.coll();
        let mut gpath = format!("/steps/{}", target.group);
        let g = self
            .file
            .group(&gpath)
            .map_err(|e| OutputError::hdf5(c.path, &target.object, "open step group for", e));
        let mut g = c.agree(&target.object, g)?;
        for dir in &target.dirs {
            gpath = format!("{gpath}/{dir}");
            g = c.open_or_create_group(&g, &gpath, dir)?;
        }
        Ok(g)
    }

    /// Collective `H5Fflush`: everything written so far is on disk in a
    /// consistent state when this returns.
    pub fn flush(&mut self) -> Result<(), OutputError> {
        self.coll().flush(&self.file)
    }

    /// Collective: flushes and closes the file (also what dropping does,
    /// minus the error report).
    pub fn close(self) -> Result<(), OutputError> {
        let res = self
            .file
            .close()
            .map_err(|e| OutputError::hdf5(&self.path, "/", "close", e));
        Coll {
            comm: &self.comm,
            path: &self.path,
        }
        .agree("/", res)
    }

    /// The HDF5 file's path, as given to [`ResultFile::create`].
    pub fn path(&self) -> &Path {
        &self.path
    }

    /// The XDMF sidecar's path.
    pub fn xdmf_path(&self) -> &Path {
        &self.xdmf_path
    }

    /// Rank 0 writes the sidecar with no steps and keeps it open; all ranks
    /// learn whether it worked.
    fn create_xdmf(&mut self) -> Result<(), OutputError> {
        let res = if self.coll().is_root() {
            xdmf::Sidecar::create(&self.xdmf_path, &self.mesh).map(|s| self.sidecar = Some(s))
        } else {
            Ok(())
        };
        self.agree_xdmf(res)
    }

    /// Rank 0 appends one step to the sidecar; all ranks learn whether it
    /// worked.
    fn append_xdmf(&mut self, step: &StepDesc) -> Result<(), OutputError> {
        let res = match &mut self.sidecar {
            Some(s) => s.append(&self.mesh, step).map(drop),
            None => Ok(()),
        };
        self.agree_xdmf(res)
    }

    fn agree_xdmf(&self, res: std::io::Result<()>) -> Result<(), OutputError> {
        let res = res.map_err(|source| OutputError::Xdmf {
            path: self.xdmf_path.clone(),
            source,
        });
        let object = self.xdmf_path.display().to_string();
        self.coll().agree(&object, res)
    }
}

// ---------------------------------------------------------------------------
// Serial read-back (any process, any rank; the file should be closed by the
// writer or at least flushed).

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
    let object = format!("/steps/{}/{name}", step_group_name(step));
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

/// The step indices in the file, ascending.
pub fn list_steps(path: &Path) -> Result<Vec<usize>, OutputError> {
    let file = open(path)?;
    let names = file
        .group("steps")
        .and_then(|g| g.member_names())
        .map_err(|e| OutputError::hdf5(path, "/steps", "list", e))?;
    let mut steps = names
        .iter()
        .map(|n| {
            n.parse::<usize>().map_err(|_| {
                OutputError::invalid(path, &format!("/steps/{n}"), "is not a step index")
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
    let object = format!("/steps/{}", step_group_name(step));
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
        time: f64_attr("time")?,
        load_factor: f64_attr("load_factor")?,
        newton_iterations: count("newton_iterations")?,
        uzawa_iterations: count("uzawa_iterations")?,
        converged: g
            .attr("converged")
            .and_then(|a| a.read_scalar::<u8>())
            .map_err(h)?
            != 0,
        wall_seconds: f64_attr("wall_seconds")?,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn local_rows_checks_shape() {
        let p = Path::new("t.h5");
        let d = [0.0; 6];
        let ok = BlockRows {
            global_rows: 4,
            start: 2,
            cols: 3,
            data: &d,
        };
        assert_eq!(local_rows(p, "x", &ok).ok(), Some(2));
        let ragged = BlockRows {
            global_rows: 4,
            start: 0,
            cols: 4,
            data: &d,
        };
        assert!(local_rows(p, "x", &ragged).is_err());
        let past = BlockRows {
            global_rows: 3,
            start: 2,
            cols: 3,
            data: &d,
        };
        assert!(local_rows(p, "x", &past).is_err());
        let zero = BlockRows {
            global_rows: 3,
            start: 0,
            cols: 0,
            data: &d,
        };
        assert!(local_rows(p, "x", &zero).is_err());
        let empty: BlockRows<f64> = BlockRows::empty(3, 99, 3);
        assert_eq!(local_rows(p, "x", &empty).ok(), Some(0));
    }

    /// A file in the module's layout written serially with plain hdf5 calls
    /// (no MPI in unit tests), read back through the helpers.
    fn serial_file(name: &str) -> PathBuf {
        let path = std::env::temp_dir().join(format!("{name}_{}.h5", std::process::id()));
        let build = || -> hdf5::Result<()> {
            let f = File::create(&path)?;
            let steps = f.create_group("steps")?;
            for (i, t) in [(10_usize, 2.0_f64), (2, 1.0)] {
                let g = steps.create_group(&step_group_name(i))?;
                attr_scalar(&g, "time", &t)?;
                attr_scalar(&g, "load_factor", &(t / 2.0))?;
                attr_scalar(&g, "newton_iterations", &(i as i64))?;
                attr_scalar(&g, "uzawa_iterations", &1_i64)?;
                attr_scalar(&g, "converged", &1_u8)?;
                attr_scalar(&g, "wall_seconds", &0.25_f64)?;
                g.new_dataset_builder()
                    .with_data(&ndarray::arr2(&[[1.0, 2.0, 3.0], [4.0, 5.0, 6.0]]))
                    .create("displacement")?;
                g.create_group("contact")?
                    .new_dataset_builder()
                    .with_data(&[0.5, -0.5])
                    .create("gap")?;
            }
            Ok(())
        };
        assert!(build().is_ok(), "could not build {}", path.display());
        path
    }

    #[test]
    fn read_helpers_round_trip() {
        let path = serial_file("read_helpers");
        assert_eq!(list_steps(&path).ok(), Some(vec![2, 10]));
        let info = read_step_attrs(&path, 10).ok();
        assert_eq!(
            info,
            Some(StepInfo {
                index: 10,
                time: 2.0,
                load_factor: 1.0,
                newton_iterations: 10,
                uzawa_iterations: 1,
                converged: true,
                wall_seconds: 0.25,
            })
        );
        let d = read_nodal(&path, 2, "displacement").ok();
        assert_eq!(d, Some((vec![1.0, 2.0, 3.0, 4.0, 5.0, 6.0], 2, 3)));
        let g = read_nodal(&path, 2, "contact/gap").ok();
        assert_eq!(g, Some((vec![0.5, -0.5], 2, 1)));

        let missing = read_nodal(&path, 2, "reaction")
            .err()
            .map(|e| e.to_string());
        let msg = missing.unwrap_or_default();
        assert!(
            msg.contains(&path.display().to_string()) && msg.contains("/steps/000002/reaction"),
            "{msg}"
        );
        let _ = std::fs::remove_file(&path);
    }

    #[test]
    fn read_errors_name_the_path() {
        let path = Path::new("/no/such/dir/out.h5");
        for msg in [
            list_steps(path).err().map(|e| e.to_string()),
            read_step_attrs(path, 1).err().map(|e| e.to_string()),
            read_nodal(path, 1, "displacement")
                .err()
                .map(|e| e.to_string()),
        ] {
            let msg = msg.unwrap_or_default();
            assert!(msg.contains("/no/such/dir/out.h5"), "{msg}");
        }
    }

    #[test]
    fn stray_step_names_are_reported() {
        let path = std::env::temp_dir().join(format!("stray_{}.h5", std::process::id()));
        let made = File::create(&path).and_then(|f| f.create_group("steps")?.create_group("notes"));
        assert!(made.is_ok());
        let msg = list_steps(&path)
            .err()
            .map(|e| e.to_string())
            .unwrap_or_default();
        assert!(msg.contains("/steps/notes"), "{msg}");
        let _ = std::fs::remove_file(&path);
    }

    #[test]
    fn fingerprints_see_differences() {
        let d = [0.0; 3];
        let b = BlockRows::whole(&d, 3);
        let info = StepInfo {
            index: 1,
            time: 0.5,
            load_factor: 0.5,
            newton_iterations: 3,
            uzawa_iterations: 2,
            converged: true,
            wall_seconds: 1.0,
        };
        let base = step_fingerprint(&info, &[("displacement", b)], &[]);
        let other_rank_wall = StepInfo {
            wall_seconds: 7.0,
            ..info
        };
        assert_eq!(
            base,
            step_fingerprint(&other_rank_wall, &[("displacement", b)], &[])
        );
        let later = StepInfo { time: 0.6, ..info };
        assert_ne!(base, step_fingerprint(&later, &[("displacement", b)], &[]));
        assert_ne!(base, step_fingerprint(&info, &[("reaction", b)], &[]));
        assert_ne!(base, step_fingerprint(&info, &[], &[("displacement", b)]));
    }
}

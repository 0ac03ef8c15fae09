//! The parallel HDF5 writer, [`ResultFile`]: creates the file and its
//! `/mesh`, writes steps, step arrays and run attributes, flushes, closes,
//! and keeps the XDMF sidecar in step with the file.

use std::path::{Path, PathBuf};

use hdf5::types::VarLenUnicode;
use hdf5::{File, Group};
use mpi::topology::SimpleCommunicator;
use mpi::traits::{AsRaw, Communicator};

use super::collective::{attr_scalar, attr_string, to_h5_string, to_i64, Coll};
use super::fingerprint::{header_fingerprint, step_fingerprint, Fingerprint};
use super::header::validate_header;
use super::layout;
use super::xdmf::{self, Center, FieldDesc, MeshDesc, StepDesc};
use super::{check_name, step_group_name, BlockRows, MeshHeader, OutputError, StepInfo};

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
        let desc = coll.agree(layout::MESH, validate_header(path, mesh))?;
        coll.same_everywhere(layout::MESH, header_fingerprint(mesh))?;

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
        let gmesh = c.open_or_create_group(root, layout::MESH, layout::MESH_NAME)?;
        let gnode_sets =
            c.open_or_create_group(&gmesh, layout::MESH_NODE_SETS, layout::NODE_SETS)?;
        let gfacet_sets =
            c.open_or_create_group(&gmesh, layout::MESH_FACET_SETS, layout::FACET_SETS)?;
        c.open_or_create_group(root, layout::STEPS, layout::STEPS_NAME)?;

        let n_nodes = self.mesh.n_nodes;
        let n_cells = self.mesh.n_cells;
        c.write_block(
            &gmesh,
            layout::MESH,
            layout::NODES,
            &mesh.nodes,
            false,
            Some(n_nodes),
        )?;
        c.write_block(
            &gmesh,
            layout::MESH,
            layout::CELLS,
            &mesh.cells,
            false,
            Some(n_cells),
        )?;
        c.write_block(
            &gmesh,
            layout::MESH,
            layout::PARTITION,
            &mesh.partition,
            true,
            Some(n_cells),
        )?;
        c.write_block(
            &gmesh,
            layout::MESH,
            layout::CELL_BODY,
            &mesh.cell_body,
            true,
            Some(n_cells),
        )?;

        let attrs = (|| {
            let cells = gmesh
                .dataset(layout::CELLS)
                .map_err(|e| OutputError::hdf5(p, layout::MESH_CELLS, "open", e))?;
            attr_string(
                p,
                &cells,
                layout::MESH_CELLS,
                layout::CELL_TYPE_ATTR,
                self.mesh.cell_type.name(),
            )?;
            let body = gmesh
                .dataset(layout::CELL_BODY)
                .map_err(|e| OutputError::hdf5(p, layout::MESH_CELL_BODY, "open", e))?;
            let names = mesh
                .bodies
                .iter()
                .map(|b| to_h5_string(p, layout::MESH_CELL_BODY, b))
                .collect::<Result<Vec<_>, _>>()?;
            body.new_attr::<VarLenUnicode>()
                .shape([names.len()])
                .create(layout::BODIES_ATTR)
                .and_then(|a| a.write_raw(&names))
                .map_err(|e| {
                    OutputError::hdf5(p, layout::MESH_CELL_BODY, "write attribute 'bodies' of", e)
                })
        })();
        c.agree(layout::MESH_CELLS, attrs)?;

        for (name, ids) in mesh.node_sets {
            let object = layout::node_set(name);
            let ids = c.agree(
                &object,
                ids.iter()
                    .map(|&i| to_i64(p, &object, i))
                    .collect::<Result<Vec<_>, _>>(),
            )?;
            c.write_root(
                &gnode_sets,
                layout::MESH_NODE_SETS,
                name,
                &[ids.len()],
                &ids,
            )?;
        }
        for (name, fs) in mesh.facet_sets {
            let object = layout::facet_set(name);
            let g = c.open_or_create_group(&gfacet_sets, &object, name)?;
            let f = fs.cell.len();
            c.write_root(&g, &object, layout::FACET_NODES, &[f, fs.k], &fs.nodes)?;
            c.write_root(&g, &object, layout::FACET_CELL, &[f], &fs.cell)?;
            c.write_root(&g, &object, layout::FACET_FACE, &[f], &fs.face)?;
            let a = attr_string(p, &g, &object, layout::CELL_TYPE_ATTR, &fs.facet_type);
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
        let gpath = layout::step_group(info.index);
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
            .group(layout::STEPS_NAME)
            .map_err(|e| OutputError::hdf5(p, layout::STEPS, "open group", e));
        let gsteps = c.agree(layout::STEPS, gsteps)?;
        let g = gsteps
            .create_group(&group)
            .map_err(|e| OutputError::hdf5(p, &gpath, "create group", e));
        let g = c.agree(&gpath, g)?;
        let written = (|| {
            let attrs = (|| {
                let h = |e| OutputError::hdf5(p, &gpath, "write attributes of", e);
                let newton = to_i64(p, &gpath, info.newton_iterations)?;
                let uzawa = to_i64(p, &gpath, info.uzawa_iterations)?;
                attr_scalar(&g, layout::TIME_ATTR, &info.time).map_err(h)?;
                attr_scalar(&g, layout::LOAD_FACTOR_ATTR, &info.load_factor).map_err(h)?;
                attr_scalar(&g, layout::NEWTON_ATTR, &newton).map_err(h)?;
                attr_scalar(&g, layout::UZAWA_ATTR, &uzawa).map_err(h)?;
                attr_scalar(&g, layout::CONVERGED_ATTR, &u8::from(info.converged)).map_err(h)?;
                attr_scalar(&g, layout::WALL_SECONDS_ATTR, &wall).map_err(h)
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
        for required in [layout::DISPLACEMENT, layout::REACTION] {
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
        let object = layout::step_dataset(step, rel_path);
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
        let mut gpath = format!("{}/{}", layout::STEPS, target.group);
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

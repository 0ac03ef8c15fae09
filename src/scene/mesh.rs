//! The scene's mesh: generated from a `[mesh]` generator or read from a
//! Gmsh or Abaqus/CalculiX file, and what reading it found ([`MeshReport`]).
use super::lines::{self, Seg};
use super::sections::{MeshSection, Scene};
use super::source::BUILTIN;
use crate::error::{Error, Result};
use crate::fem::CellType;
use crate::mesh::generate::{
    self, BoxSpec, Grading, HertzCylinderSpec, HertzSphereSpec, StackedSpec,
};
use crate::mesh::{InpErrorKind, InpRequest, Mesh};
use std::path::Path;

impl Scene {
    /// The mesh file the scene reads, if any (a Gmsh or `.inp` `[mesh] file`;
    /// the files an `.inp` includes are in its [`MeshReport`]).
    pub fn mesh_file(&self, origin: &str) -> Option<std::path::PathBuf> {
        match &self.mesh {
            MeshSection::Gmsh(g) => Some(mesh_path(&g.file, origin)),
            MeshSection::Inp(i) => Some(mesh_path(&i.file, origin)),
            _ => None,
        }
    }

    pub(super) fn build_mesh(&self, origin: &str) -> Result<(Mesh, MeshReport)> {
        self.generate_mesh(origin).map_err(|e| match e {
            Error::Mesh(m) => {
                let key = lines::mesh_key(&m);
                let at: Vec<Seg> = std::iter::once(Seg::Key("mesh"))
                    .chain(key.map(Seg::Key))
                    .collect();
                self.error_at(origin, &at, format!("[mesh] {m}"))
            }
            other => other,
        })
    }

    pub(super) fn generate_mesh(&self, origin: &str) -> Result<(Mesh, MeshReport)> {
        let mut report = MeshReport::default();
        let mesh = match &self.mesh {
            MeshSection::Box(b) => generate::graded_box(&BoxSpec {
                body: b.body.clone(),
                origin: b.origin,
                size: b.size,
                divisions: b.divisions,
                grading: b.grading.map(Grading::from),
                cell_type: b.cell_type.into(),
            })?,
            MeshSection::HertzCylinder(h) => {
                let d = HertzCylinderSpec::default();
                generate::hertz_cylinder(&HertzCylinderSpec {
                    radius: h.radius.unwrap_or(d.radius),
                    block_width: h.block_width.unwrap_or(d.block_width),
                    block_height: h.block_height.unwrap_or(d.block_height),
                    thickness: h.thickness.unwrap_or(d.thickness),
                    gap: h.gap.unwrap_or(d.gap),
                    fine_size: h.fine_size.unwrap_or(d.fine_size),
                    fine_half_width: h.fine_half_width.unwrap_or(d.fine_half_width),
                    growth: h.growth.unwrap_or(d.growth),
                    level: h.level.unwrap_or(d.level),
                    cell_type: h.cell_type.map(CellType::from).unwrap_or(d.cell_type),
                })?
            }
            MeshSection::HertzSphere(h) => {
                let d = HertzSphereSpec::default();
                generate::hertz_sphere(&HertzSphereSpec {
                    radius: h.radius.unwrap_or(d.radius),
                    block_width: h.block_width.unwrap_or(d.block_width),
                    block_height: h.block_height.unwrap_or(d.block_height),
                    gap: h.gap.unwrap_or(d.gap),
                    fine_size: h.fine_size.unwrap_or(d.fine_size),
                    fine_half_width: h.fine_half_width.unwrap_or(d.fine_half_width),
                    growth: h.growth.unwrap_or(d.growth),
                    level: h.level.unwrap_or(d.level),
                    cell_type: h.cell_type.map(CellType::from).unwrap_or(d.cell_type),
                })?
            }
            MeshSection::StackedBlocks(s) => {
                let d = StackedSpec::default();
                generate::stacked_blocks(&StackedSpec {
                    length: s.length.unwrap_or(d.length),
                    height: s.height.unwrap_or(d.height),
                    gap: s.gap.unwrap_or(d.gap),
                    lower_divisions: s.lower_divisions.unwrap_or(d.lower_divisions),
                    upper_divisions: s.upper_divisions.unwrap_or(d.upper_divisions),
                    cell_type: s.cell_type.map(CellType::from).unwrap_or(d.cell_type),
                    ..d
                })?
            }
            MeshSection::Gmsh(g) => {
                let (mesh, gmsh) =
                    crate::mesh::read_gmsh(&mesh_path(&g.file, origin)).map_err(|e| {
                        let at = [Seg::Key("mesh"), Seg::Key("file")];
                        self.error_at(origin, &at, format!("[mesh] gmsh: {e}"))
                    })?;
                report.gmsh = Some(gmsh);
                mesh
            }
            MeshSection::Inp(i) => {
                let path = mesh_path(&i.file, origin);
                let (mesh, inp) =
                    crate::mesh::read_inp(&path, &self.inp_request()).map_err(|e| {
                        // A body the file has no element set for is the
                        // [[body]]'s error.
                        let body = match &e.kind {
                            InpErrorKind::UnknownBodySet { name, .. } => {
                                self.bodies.iter().position(|b| &b.name == name)
                            }
                            _ => None,
                        };
                        let at = match body {
                            Some(b) => [Seg::Key("body"), Seg::Index(b), Seg::Key("name")].to_vec(),
                            None => [Seg::Key("mesh"), Seg::Key("file")].to_vec(),
                        };
                        self.error_at(origin, &at, format!("[mesh] inp: {e}"))
                    })?;
                report.inp = Some(inp);
                mesh
            }
        };
        Ok((mesh, report))
    }

    /// What an `.inp` file is asked for: the `[[body]]` names are its
    /// element sets, and the sets the scene names keep the scene's spelling.
    fn inp_request(&self) -> InpRequest {
        let bodies = self.bodies.iter().map(|b| b.name.clone()).collect();
        let sets = self.dirichlet.iter().map(|d| &d.set);
        let sets = sets.chain(self.pressure.iter().map(|p| &p.set));
        let sets = sets.chain(self.traction.iter().map(|t| &t.set));
        let sets = sets.chain(self.contact.iter().map(|c| &c.slave));
        let sets = sets.chain(self.contact.iter().filter_map(|c| c.master.as_ref()));
        InpRequest {
            bodies,
            names: sets.cloned().collect(),
        }
    }
}

/// A mesh `file` as a path: relative to the scene's directory. `origin`
/// is the scene's path, or names a built-in scene, which is compiled in
/// from the crate's scenes/ directory.
pub(super) fn mesh_path(file: &str, origin: &str) -> std::path::PathBuf {
    let builtin = BUILTIN
        .iter()
        .any(|(n, _, _)| origin == format!("built-in scene '{n}'"));
    let base = match Path::new(origin).parent() {
        _ if builtin => Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes"),
        Some(dir) => dir.to_path_buf(),
        None => Default::default(),
    };
    base.join(file)
}

/// What reading the mesh found besides the mesh (for `check` to print).
#[derive(Debug, Clone, Default)]
pub struct MeshReport {
    /// The Gmsh reader's report (reoriented cells, skipped sections), for a
    /// `generator = "gmsh"` mesh.
    pub gmsh: Option<crate::mesh::GmshReport>,
    /// The `.inp` reader's report (keywords not read, included files,
    /// reoriented cells), for a `generator = "inp"` mesh.
    pub inp: Option<crate::mesh::InpReport>,
}

impl MeshReport {
    /// What a run prints once about the mesh read (the keywords of an
    /// `.inp` file that were not read).
    pub fn notes(&self) -> Vec<String> {
        self.inp.iter().map(crate::mesh::InpReport::note).collect()
    }

    /// The files read besides the `[mesh] file` (an `.inp`'s includes).
    pub fn included_files(&self) -> Vec<std::path::PathBuf> {
        self.inp
            .as_ref()
            .map_or_else(Vec::new, |i| i.included.clone())
    }
}

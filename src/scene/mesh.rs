//! The scene's mesh: generated from a `[mesh]` generator or read from a
//! Gmsh file, and what reading it found ([`MeshReport`]).
use super::lines::{self, Seg};
use super::sections::{GmshSection, MeshSection, Scene};
use super::source::BUILTIN;
use crate::error::{Error, Result};
use crate::fem::CellType;
use crate::mesh::generate::{
    self, BoxSpec, Grading, HertzCylinderSpec, HertzSphereSpec, StackedSpec,
};
use crate::mesh::Mesh;
use std::path::Path;

impl Scene {
    /// The mesh file the scene reads, if any (a Gmsh `[mesh] file`).
    pub fn mesh_file(&self, origin: &str) -> Option<std::path::PathBuf> {
        match &self.mesh {
            MeshSection::Gmsh(g) => Some(gmsh_path(g, origin)),
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
                let (mesh, gmsh) = crate::mesh::read_gmsh(&gmsh_path(g, origin)).map_err(|e| {
                    let at = [Seg::Key("mesh"), Seg::Key("file")];
                    self.error_at(origin, &at, format!("[mesh] gmsh: {e}"))
                })?;
                report.gmsh = Some(gmsh);
                mesh
            }
        };
        Ok((mesh, report))
    }
}

/// A Gmsh `file` as a path: relative to the scene's directory. `origin`
/// is the scene's path, or names a built-in scene, which is compiled in
/// from the crate's scenes/ directory.
pub(super) fn gmsh_path(g: &GmshSection, origin: &str) -> std::path::PathBuf {
    let builtin = BUILTIN
        .iter()
        .any(|(n, _, _)| origin == format!("built-in scene '{n}'"));
    let base = match Path::new(origin).parent() {
        _ if builtin => Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes"),
        Some(dir) => dir.to_path_buf(),
        None => Default::default(),
    };
    base.join(&g.file)
}

/// What reading the mesh found besides the mesh (for `check` to print).
#[derive(Debug, Clone, Default)]
pub struct MeshReport {
    /// The Gmsh reader's report (reoriented cells, skipped sections), for a
    /// `generator = "gmsh"` mesh.
    pub gmsh: Option<crate::mesh::GmshReport>,
}

//! Bulk (volume) contributions: internal force and stiffness of every local cell.
use super::{element_dofs, gather_nodal, scatter_add};
use crate::dofs::DofMap;
use crate::error::{Error, Result};
use crate::fem::{self, CellType, ElementGeometry, FemError, Material, QuadRule};
use crate::mesh::Mesh;
use crate::petsc::{Matrix, PatternBuilder, PetscInt};

/// Everything a rank needs to evaluate its cells, computed once: reference
/// geometry (shape gradients at the quadrature points), materials and DOFs.
pub struct BulkAssembler {
    cell_type: CellType,
    geometry: Vec<ElementGeometry>,
    /// Material of each local cell, as an index into `materials`.
    cell_material: Vec<u32>,
    materials: Vec<Material>,
    /// Local node indices per local cell, flat.
    cell_nodes: Vec<u32>,
    /// PETSc DOFs per local cell, flat (3 per node).
    cell_dofs: Vec<PetscInt>,
    /// Natural cell ids, for error messages.
    natural_cell: Vec<usize>,
}

impl BulkAssembler {
    /// `materials[b]` is the material of body b. Fails naming the cell when an
    /// element is inverted in the reference configuration.
    pub fn new(mesh: &Mesh, dofs: &DofMap, materials: Vec<Material>) -> Result<Self> {
        let cell_type = mesh.cell_type;
        let npc = cell_type.nodes();
        let rule = quadrature_rule(cell_type);
        let mut geometry = Vec::with_capacity(dofs.local_cells.len());
        let mut cell_nodes = Vec::with_capacity(dofs.local_cells.len() * npc);
        let mut cell_dofs = Vec::with_capacity(dofs.local_cells.len() * npc * 3);
        let mut cell_material = Vec::with_capacity(dofs.local_cells.len());
        let mut scratch = Vec::new();
        for (i, &c) in dofs.local_cells.iter().enumerate() {
            let x_ref: Vec<[f64; 3]> = mesh.cell(c).iter().map(|&v| mesh.nodes[v]).collect();
            let geom = ElementGeometry::new(cell_type, &x_ref, &rule).map_err(|e| match e {
                FemError::InvertedElement { qp, det_j } => {
                    Error::InvertedCell { cell: c, qp, det_j }
                }
                other => Error::Element {
                    cell: c,
                    source: other,
                },
            })?;
            geometry.push(geom);
            let nodes = dofs.cell_local_nodes(i, npc);
            cell_nodes.extend_from_slice(nodes);
            element_dofs(dofs, nodes, &mut scratch);
            cell_dofs.extend_from_slice(&scratch);
            cell_material.push(mesh.cell_body[c]);
        }
        Ok(BulkAssembler {
            cell_type,
            geometry,
            cell_material,
            materials,
            cell_nodes,
            cell_dofs,
            natural_cell: dofs.local_cells.clone(),
        })
    }

    /// True when every body is linear elastic: the stiffness is then constant
    /// and can be assembled once.
    pub fn is_linear(&self) -> bool {
        self.materials.iter().all(Material::is_linear)
    }

    fn npc(&self) -> usize {
        self.cell_type.nodes()
    }

    fn nodes(&self, i: usize) -> &[u32] {
        let n = self.npc();
        &self.cell_nodes[i * n..(i + 1) * n]
    }

    fn dofs(&self, i: usize) -> &[PetscInt] {
        let n = 3 * self.npc();
        &self.cell_dofs[i * n..(i + 1) * n]
    }

    fn cell_error(&self, i: usize, e: FemError) -> Error {
        Error::Element {
            cell: self.natural_cell[i],
            source: e,
        }
    }

    /// Adds the internal force f_int(u) of every local cell into `r_local`.
    pub fn add_internal_force(&self, u_local: &[f64], r_local: &mut [f64]) -> Result<()> {
        let n = self.npc();
        let mut u = [[0.0; 3]; 8];
        let mut r = [0.0; 24];
        for (i, geom) in self.geometry.iter().enumerate() {
            let nodes = self.nodes(i);
            gather_nodal(u_local, nodes, &mut u[..n]);
            let mat = &self.materials[self.cell_material[i] as usize];
            fem::internal_force(mat, geom, &u[..n], &mut r[..3 * n])
                .map_err(|e| self.cell_error(i, e))?;
            scatter_add(r_local, nodes, &r[..3 * n], 1.0);
        }
        Ok(())
    }

    /// Adds the consistent tangent of every local cell into `k` (not assembled).
    pub fn add_tangent(&self, u_local: &[f64], k: &mut Matrix) -> Result<()> {
        let n = self.npc();
        let mut u = [[0.0; 3]; 8];
        let mut r = [0.0; 24];
        let mut ke = [0.0; 24 * 24];
        for (i, geom) in self.geometry.iter().enumerate() {
            let nodes = self.nodes(i);
            gather_nodal(u_local, nodes, &mut u[..n]);
            let mat = &self.materials[self.cell_material[i] as usize];
            fem::internal_force_and_tangent(
                mat,
                geom,
                &u[..n],
                &mut r[..3 * n],
                &mut ke[..9 * n * n],
            )
            .map_err(|e| self.cell_error(i, e))?;
            let d = self.dofs(i);
            k.add_block(d, d, &ke[..9 * n * n])?;
        }
        Ok(())
    }

    /// Records the entries every local cell couples.
    pub fn add_pattern(&self, pattern: &mut PatternBuilder) -> Result<()> {
        for i in 0..self.geometry.len() {
            pattern.add_square(self.dofs(i))?;
        }
        Ok(())
    }

    /// Adds ∫ N b dV for a constant body force per body (`b[body]`, per unit
    /// reference volume) scaled by `factor`, into the external force `f_local`.
    pub fn add_body_force(&self, b: &[[f64; 3]], factor: f64, f_local: &mut [f64]) -> Result<()> {
        let n = self.npc();
        let mut fe = [0.0; 24];
        for (i, geom) in self.geometry.iter().enumerate() {
            let bb = b[self.cell_material[i] as usize];
            if bb == [0.0; 3] {
                continue;
            }
            fem::body_force(geom, bb, &mut fe[..3 * n]).map_err(|e| self.cell_error(i, e))?;
            scatter_add(f_local, self.nodes(i), &fe[..3 * n], factor);
        }
        Ok(())
    }

    /// Adds ∫ N b(X) dV for a body force given as a function of the reference
    /// position (manufactured solutions), into `f_local`.
    pub fn add_body_force_fn(
        &self,
        mesh_nodes: &[[f64; 3]],
        natural: impl Fn(u32) -> usize,
        b: &dyn Fn([f64; 3]) -> [f64; 3],
        f_local: &mut [f64],
    ) -> Result<()> {
        let n = self.npc();
        let mut fe = [0.0; 24];
        for (i, geom) in self.geometry.iter().enumerate() {
            let nodes = self.nodes(i);
            let x_ref: Vec<[f64; 3]> = nodes.iter().map(|&l| mesh_nodes[natural(l)]).collect();
            fem::body_force_fn(geom, &x_ref, b, &mut fe[..3 * n])
                .map_err(|e| self.cell_error(i, e))?;
            scatter_add(f_local, nodes, &fe[..3 * n], 1.0);
        }
        Ok(())
    }

    /// Local cells' geometry, for post-processing (L2 errors, volumes).
    pub fn geometry(&self) -> &[ElementGeometry] {
        &self.geometry
    }

    pub fn cell_nodes_of(&self, i: usize) -> &[u32] {
        self.nodes(i)
    }
}

/// The default rule: full Gauss integration for the element.
fn quadrature_rule(cell_type: CellType) -> QuadRule {
    match cell_type {
        CellType::Hex8 => QuadRule::hex_2x2x2(),
        CellType::Tet4 => QuadRule::tet_1(),
    }
}

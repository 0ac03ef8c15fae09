//! Bulk (volume) contributions of every local cell: internal force, stiffness,
//! consistent mass and stored energy.
use super::{element_dofs, gather_nodal, scatter_add};
use super::{MatrixSink, PatternSink};
use crate::distribution::LocalMesh;
use crate::dofs::{DofMap, GlobalDof, LocalNode, DIM};
use crate::error::{Error, Result};
use crate::fem::{self, CellType, ElementGeometry, FemError, Integration, Material, QuadRule};

/// Everything a rank needs to evaluate its cells, computed once: reference
/// geometry (shape gradients at the quadrature points), materials and DOFs.
pub struct BulkAssembler {
    cell_type: CellType,
    geometry: Vec<ElementGeometry>,
    /// Material of each local cell, as an index into `materials`.
    cell_material: Vec<u32>,
    materials: Vec<Material>,
    /// Stiffness integration of each body.
    integration: Vec<Integration>,
    /// Local node indices per local cell, flat.
    cell_nodes: Vec<LocalNode>,
    /// Global DOFs per local cell, flat (3 per node).
    cell_dofs: Vec<GlobalDof>,
    /// Natural cell ids, for error messages.
    natural_cell: Vec<usize>,
}

impl BulkAssembler {
    /// `materials[b]` and `integration[b]` are the material and the
    /// stiffness integration of body b. Fails naming the cell when an
    /// element is inverted in the reference configuration, and naming the
    /// body when its cell type has no reduced rule.
    pub fn new(
        mesh: &LocalMesh,
        dofs: &DofMap,
        materials: Vec<Material>,
        integration: Vec<Integration>,
    ) -> Result<Self> {
        let cell_type = mesh.cell_type;
        let npc = cell_type.nodes();
        if integration.len() != materials.len() {
            return Err(Error::Internal(format!(
                "{} integration choices for {} bodies",
                integration.len(),
                materials.len()
            )));
        }
        let rules = integration
            .iter()
            .enumerate()
            .map(|(b, &i)| {
                QuadRule::for_cell(cell_type, i).ok_or_else(|| {
                    Error::scene(
                        "integration",
                        format!(
                            "body {b}: {} cells have no {} integration (only hex20 has a reduced rule)",
                            cell_type.name(),
                            i.name()
                        ),
                    )
                })
            })
            .collect::<Result<Vec<_>>>()?;
        let mut geometry = Vec::with_capacity(dofs.local_cells.len());
        let mut cell_nodes = Vec::with_capacity(dofs.local_cells.len() * npc);
        let mut cell_dofs = Vec::with_capacity(dofs.local_cells.len() * npc * 3);
        let mut cell_material = Vec::with_capacity(dofs.local_cells.len());
        let mut scratch = Vec::new();
        for (i, &c) in dofs.local_cells.iter().enumerate() {
            let nodes = dofs.cell_local_nodes(i, npc);
            let x_ref: Vec<[f64; 3]> = nodes.iter().map(|&l| mesh.nodes[l.index()]).collect();
            let rule = rules
                .get(mesh.cell_body[i] as usize)
                .ok_or_else(|| Error::Internal(format!("cell {c} has no body")))?;
            let geom = ElementGeometry::new(cell_type, &x_ref, rule).map_err(|e| match e {
                FemError::InvertedElement { qp, det_j } => {
                    Error::InvertedCell { cell: c, qp, det_j }
                }
                other => Error::Element {
                    cell: c,
                    source: other,
                },
            })?;
            geometry.push(geom);
            cell_nodes.extend_from_slice(nodes);
            element_dofs(dofs, nodes, &mut scratch);
            cell_dofs.extend_from_slice(&scratch);
            cell_material.push(mesh.cell_body[i]);
        }
        Ok(BulkAssembler {
            cell_type,
            geometry,
            cell_material,
            materials,
            integration,
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

    fn nodes(&self, i: usize) -> &[LocalNode] {
        let n = self.npc();
        &self.cell_nodes[i * n..(i + 1) * n]
    }

    fn dofs(&self, i: usize) -> &[GlobalDof] {
        let n = 3 * self.npc();
        &self.cell_dofs[i * n..(i + 1) * n]
    }

    /// Body (index into `materials`) of the i-th local cell.
    fn body(&self, i: usize) -> usize {
        self.cell_material[i] as usize
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
        let (mut u, mut r) = (vec![[0.0; 3]; n], vec![0.0; 3 * n]);
        for (i, geom) in self.geometry.iter().enumerate() {
            let nodes = self.nodes(i);
            gather_nodal(u_local, nodes, &mut u[..n]);
            let mat = &self.materials[self.body(i)];
            fem::internal_force(mat, geom, &u[..n], &mut r[..3 * n])
                .map_err(|e| self.cell_error(i, e))?;
            scatter_add(r_local, nodes, &r[..3 * n], 1.0);
        }
        Ok(())
    }

    /// Adds the consistent tangent of every local cell into `k` (not assembled).
    pub fn add_tangent(&self, u_local: &[f64], k: &mut dyn MatrixSink) -> Result<()> {
        let n = self.npc();
        let (mut u, mut r) = (vec![[0.0; 3]; n], vec![0.0; 3 * n]);
        let mut ke = vec![0.0; 9 * n * n];
        for (i, geom) in self.geometry.iter().enumerate() {
            let nodes = self.nodes(i);
            gather_nodal(u_local, nodes, &mut u[..n]);
            let mat = &self.materials[self.body(i)];
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

    /// Adds the consistent mass `∫ ρ N_a N_b dV` of every local cell into `m`
    /// (not assembled); `density[b]` is the reference density of body b, as
    /// `materials[b]` is its material. The blocks land on the tangent's
    /// pattern, so `m` may be a matrix built from [`Self::add_pattern`] or the
    /// tangent itself. A body of density 0 adds nothing.
    ///
    /// `local_nodes` are the local mesh's coordinates: the types whose
    /// default rule is too weak for `N_a N_b` (tet10, wedge15, pyramid5)
    /// integrate their mass with [`QuadRule::mass_for_cell`] on a geometry
    /// built here, once per run.
    pub fn add_mass(
        &self,
        local_nodes: &[[f64; 3]],
        density: &[f64],
        m: &mut dyn MatrixSink,
    ) -> Result<()> {
        self.for_each_cell_mass(local_nodes, density, |dofs, me| m.add_block(dofs, dofs, me))
    }

    /// Calls `add(dofs, mass)` for every local cell of non-zero density;
    /// split from [`Self::add_mass`] so the sums can be checked without PETSc.
    fn for_each_cell_mass(
        &self,
        local_nodes: &[[f64; 3]],
        density: &[f64],
        mut add: impl FnMut(&[GlobalDof], &[f64]) -> Result<()>,
    ) -> Result<()> {
        // Checked up front rather than per cell: a rank without cells must
        // fail as well, or the others would wait for it in assembly.
        self.check_densities(density)?;
        let n = self.npc();
        let mut me = vec![0.0; 9 * n * n];
        // The full rule integrates `N_a N_b` exactly where the mass has no
        // rule of its own: a reduced body takes it.
        let full_rule = QuadRule::default_for_cell(self.cell_type);
        let mass_rule = QuadRule::mass_for_cell(self.cell_type);
        for (i, stiffness_geom) in self.geometry.iter().enumerate() {
            let body = self.body(i);
            let rho = *density.get(body).ok_or_else(|| {
                self.cell_error(
                    i,
                    FemError::LengthMismatch {
                        what: "density (one per body)",
                        expected: body + 1,
                        got: density.len(),
                    },
                )
            })?;
            if rho == 0.0 {
                continue;
            }
            let own;
            let reduced = self.integration.get(body) == Some(&Integration::Reduced);
            let rule = mass_rule.as_ref().or(reduced.then_some(&full_rule));
            let geom = match rule {
                Some(rule) => {
                    let x_ref: Vec<[f64; 3]> = self
                        .nodes(i)
                        .iter()
                        .map(|&l| local_nodes[l.index()])
                        .collect();
                    own = ElementGeometry::new(self.cell_type, &x_ref, rule)
                        .map_err(|e| self.cell_error(i, e))?;
                    &own
                }
                None => stiffness_geom,
            };
            fem::mass_matrix(geom, rho, &mut me[..9 * n * n]).map_err(|e| self.cell_error(i, e))?;
            add(self.dofs(i), &me[..9 * n * n])?;
        }
        Ok(())
    }

    fn check_densities(&self, density: &[f64]) -> Result<()> {
        if density.len() != self.materials.len() {
            return Err(Error::scene(
                "density",
                format!(
                    "{} values given for {} bodies (one per body)",
                    density.len(),
                    self.materials.len()
                ),
            ));
        }
        match density
            .iter()
            .enumerate()
            .find(|(_, rho)| !(rho.is_finite() && **rho >= 0.0))
        {
            Some((body, rho)) => Err(Error::scene(
                "density",
                format!("body {body}: {rho} is not a finite, non-negative density"),
            )),
            None => Ok(()),
        }
    }

    /// Stored energy `Σ ∫ W(F) dV` of this rank's cells at the local-form
    /// displacement `u_local`. Every cell lives on exactly one rank, so the
    /// sum over ranks (the caller's reduction) is the total, with no double
    /// counting of cells on partition boundaries.
    pub fn strain_energy(&self, u_local: &[f64]) -> Result<f64> {
        let n = self.npc();
        let mut u = vec![[0.0; 3]; n];
        let mut energy = 0.0;
        for (i, geom) in self.geometry.iter().enumerate() {
            let nodes = self.nodes(i);
            self.check_local_len(i, u_local)?;
            gather_nodal(u_local, nodes, &mut u[..n]);
            let body = self.body(i);
            let mat = self.materials.get(body).ok_or_else(|| {
                self.cell_error(
                    i,
                    FemError::LengthMismatch {
                        what: "materials (one per body)",
                        expected: body + 1,
                        got: self.materials.len(),
                    },
                )
            })?;
            energy += fem::strain_energy(mat, geom, &u[..n]).map_err(|e| self.cell_error(i, e))?;
        }
        Ok(energy)
    }

    /// A local-form array too short for a cell's nodes is an error, not an
    /// out-of-bounds panic in `gather_nodal`.
    fn check_local_len(&self, i: usize, local: &[f64]) -> Result<()> {
        let needed = self.nodes(i).iter().map(|&l| l.vec_index(DIM)).max();
        match needed {
            Some(needed) if needed > local.len() => Err(self.cell_error(
                i,
                FemError::LengthMismatch {
                    what: "local displacement array",
                    expected: needed,
                    got: local.len(),
                },
            )),
            _ => Ok(()),
        }
    }

    /// Records the entries every local cell couples.
    pub fn add_pattern(&self, pattern: &mut dyn PatternSink) -> Result<()> {
        for i in 0..self.geometry.len() {
            pattern.add_square(self.dofs(i))?;
        }
        Ok(())
    }

    /// Adds ∫ N b dV for a constant body force per body (`b[body]`, per unit
    /// reference volume) scaled by `factor`, into the external force `f_local`.
    pub fn add_body_force(&self, b: &[[f64; 3]], factor: f64, f_local: &mut [f64]) -> Result<()> {
        let n = self.npc();
        let mut fe = vec![0.0; 3 * n];
        for (i, geom) in self.geometry.iter().enumerate() {
            let bb = b[self.body(i)];
            if bb == [0.0; 3] {
                continue;
            }
            fem::body_force(geom, bb, &mut fe[..3 * n]).map_err(|e| self.cell_error(i, e))?;
            scatter_add(f_local, self.nodes(i), &fe[..3 * n], factor);
        }
        Ok(())
    }

    /// Adds ∫ N b(X) dV for a body force given as a function of the reference
    /// position (manufactured solutions), into `f_local`; `local_nodes` are
    /// the local mesh's coordinates.
    pub fn add_body_force_fn(
        &self,
        local_nodes: &[[f64; 3]],
        b: &dyn Fn([f64; 3]) -> [f64; 3],
        f_local: &mut [f64],
    ) -> Result<()> {
        let n = self.npc();
        let mut fe = vec![0.0; 3 * n];
        for (i, geom) in self.geometry.iter().enumerate() {
            let nodes = self.nodes(i);
            let x_ref: Vec<[f64; 3]> = nodes.iter().map(|&l| local_nodes[l.index()]).collect();
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

    pub fn cell_nodes_of(&self, i: usize) -> &[LocalNode] {
        self.nodes(i)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::dofs::LocalNode;
    use crate::mesh::{stacked_blocks, Mesh, Perturbation, StackedSpec};

    const RANKS: usize = 2;

    /// The default stacked blocks (`lower` and `upper`, each 1 × 1 × 0.5),
    /// distorted so the hexes are not parallelepipeds.
    fn two_bodies(cell_type: CellType) -> Mesh {
        stacked_blocks(&StackedSpec {
            cell_type,
            perturbation: Some(Perturbation {
                fraction: 0.2,
                seed: 5,
            }),
            ..Default::default()
        })
        .unwrap()
    }

    /// One assembler per pretend rank, cells dealt out alternately, so the
    /// sums below also check that no cell is counted twice across ranks.
    fn assemblers(mesh: &Mesh, materials: &[Material]) -> Vec<(DofMap, BulkAssembler)> {
        let partition: Vec<i32> = (0..mesh.num_cells()).map(|c| (c % RANKS) as i32).collect();
        (0..RANKS)
            .map(|rank| {
                let wanted = crate::distribution::Wanted::default();
                let (dofs, local) = DofMap::with_mesh(mesh, &partition, rank, RANKS, &wanted);
                let full = vec![Integration::Full; materials.len()];
                let bulk = BulkAssembler::new(&local, &dofs, materials.to_vec(), full).unwrap();
                (dofs, bulk)
            })
            .collect()
    }

    /// Body-indexed materials of different stiffness, so a mix-up of bodies
    /// changes the energy.
    fn materials(mesh: &Mesh) -> Vec<Material> {
        let mut m = vec![
            Material::LinearElastic {
                youngs: 1.0,
                poisson: 0.0
            };
            mesh.bodies.len()
        ];
        m[mesh.body_id("lower").unwrap() as usize] = Material::LinearElastic {
            youngs: 1000.0,
            poisson: 0.3,
        };
        m[mesh.body_id("upper").unwrap() as usize] = Material::LinearElastic {
            youngs: 50.0,
            poisson: 0.2,
        };
        m
    }

    fn body_density(mesh: &Mesh, lower: f64, upper: f64) -> Vec<f64> {
        let mut d = vec![0.0; mesh.bodies.len()];
        d[mesh.body_id("lower").unwrap() as usize] = lower;
        d[mesh.body_id("upper").unwrap() as usize] = upper;
        d
    }

    /// Σ of every entry of every cell's mass block over all ranks, and the
    /// number of cells that contributed.
    fn mass_sum(
        mesh: &Mesh,
        all: &[(DofMap, BulkAssembler)],
        density: &[f64],
    ) -> Result<(f64, usize)> {
        let mut total = 0.0;
        let mut cells = 0;
        for (dofs, bulk) in all {
            let local_nodes: Vec<[f64; 3]> = (0..dofs.num_local_nodes())
                .map(|l| mesh.nodes[dofs.natural(LocalNode::from_index(l)).0])
                .collect();
            bulk.for_each_cell_mass(&local_nodes, density, |dofs, me| {
                assert_eq!(me.len(), dofs.len() * dofs.len());
                total += me.iter().sum::<f64>();
                cells += 1;
                Ok(())
            })?;
        }
        Ok((total, cells))
    }

    #[test]
    fn mass_sums_to_density_times_volume_per_body() {
        // Both blocks are 1 × 1 × 0.5; the perturbation keeps the boundary.
        let volume = 0.5;
        for cell_type in [CellType::Hex8, CellType::Tet4] {
            let mesh = two_bodies(cell_type);
            let all = assemblers(&mesh, &materials(&mesh));
            let lower_cells = mesh.body_cells(mesh.body_id("lower").unwrap()).count();
            for (lower, upper) in [(2.0, 0.0), (0.0, 3.0), (2.0, 3.0)] {
                let (total, cells) =
                    mass_sum(&mesh, &all, &body_density(&mesh, lower, upper)).unwrap();
                // Each of the three components carries the full mass.
                let expected = 3.0 * volume * (lower + upper);
                assert!(
                    (total - expected).abs() < 1e-12 * expected,
                    "{} ({lower}, {upper}): {total} vs {expected}",
                    cell_type.name()
                );
                let expected_cells = match (lower > 0.0, upper > 0.0) {
                    (true, true) => mesh.num_cells(),
                    (true, false) => lower_cells,
                    _ => mesh.num_cells() - lower_cells,
                };
                assert_eq!(cells, expected_cells, "massless cells must add nothing");
            }
        }
    }

    #[test]
    fn bad_densities_are_errors() {
        let mesh = two_bodies(CellType::Hex8);
        let all = assemblers(&mesh, &materials(&mesh));
        for density in [
            vec![1.0],
            vec![1.0; mesh.bodies.len() + 1],
            body_density(&mesh, 1.0, -1.0),
            body_density(&mesh, f64::NAN, 1.0),
            body_density(&mesh, 1.0, f64::INFINITY),
        ] {
            let err = mass_sum(&mesh, &all, &density).unwrap_err();
            assert!(err.to_string().contains("density"), "{err}");
        }
    }

    /// Local-form displacement u = g(X) on one pretend rank.
    fn local_field(mesh: &Mesh, dofs: &DofMap, g: impl Fn([f64; 3]) -> [f64; 3]) -> Vec<f64> {
        (0..dofs.num_local_nodes())
            .flat_map(|l| g(mesh.nodes[dofs.natural(LocalNode::from_index(l)).0]))
            .collect()
    }

    /// u_x = ε X is a uniaxial strain, which linear elements reproduce
    /// exactly on any mesh: W = ½ (λ + 2μ) ε² per unit volume.
    #[test]
    fn strain_energy_of_uniaxial_strain_is_exact() {
        let eps = 1e-3;
        let volume = 0.5;
        for cell_type in [CellType::Hex8, CellType::Tet4] {
            let mesh = two_bodies(cell_type);
            let mats = materials(&mesh);
            let all = assemblers(&mesh, &mats);
            let energy: f64 = all
                .iter()
                .map(|(dofs, bulk)| {
                    let u = local_field(&mesh, dofs, |x| [eps * x[0], 0.0, 0.0]);
                    bulk.strain_energy(&u).unwrap()
                })
                .sum();
            let expected: f64 = ["lower", "upper"]
                .iter()
                .map(|b| {
                    let (lambda, mu) = mats[mesh.body_id(b).unwrap() as usize].lame();
                    0.5 * (lambda + 2.0 * mu) * eps * eps * volume
                })
                .sum();
            let err = (energy - expected).abs() / expected;
            assert!(err < 1e-12, "{}: {energy} vs {expected}", cell_type.name());
        }
    }

    #[test]
    fn strain_energy_of_rigid_motion_is_zero_and_short_arrays_fail() {
        let mesh = two_bodies(CellType::Hex8);
        let all = assemblers(&mesh, &materials(&mesh));
        for (dofs, bulk) in &all {
            let u = local_field(&mesh, dofs, |_| [0.3, -0.2, 1.0]);
            assert!(bulk.strain_energy(&u).unwrap().abs() < 1e-20);
            let err = bulk.strain_energy(&u[..u.len() - 1]).unwrap_err();
            assert!(matches!(
                err,
                Error::Element {
                    source: FemError::LengthMismatch { .. },
                    ..
                }
            ));
        }
    }
}

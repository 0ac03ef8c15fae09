//! Surface loads on facet sets: dead tractions and follower pressures.
use super::{element_dofs, gather_nodal, scatter_add, MatrixSink, PatternSink};
use crate::amplitude::Amplitude;
use crate::distribution::{LocalFacetSet, LocalMesh};
use crate::dofs::{DofMap, GlobalDof, LocalNode};
use crate::error::{Error, Result};
use crate::fem::{self, FacetType, MAX_FACET_NODES};
use crate::model::FacetLoad;

struct LocalFacet {
    /// Natural id of the cell the facet belongs to (for error messages).
    cell: usize,
    /// Its type (a wedge's set may hold triangles and quadrilaterals).
    facet_type: FacetType,
    nodes: Vec<LocalNode>,
    x_ref: Vec<[f64; 3]>,
    dofs: Vec<GlobalDof>,
    load: FacetLoad,
    amplitude: Amplitude,
}

impl LocalFacet {
    fn error(&self, source: fem::FemError) -> Error {
        Error::Element {
            cell: self.cell,
            source,
        }
    }
}

/// The facet loads this rank evaluates: those on facets of its own cells, so
/// every facet is counted exactly once over all ranks.
pub struct SurfaceLoads {
    facets: Vec<LocalFacet>,
    /// Most nodes of any of the facets: sizes the element buffers.
    max_nodes: usize,
}

impl SurfaceLoads {
    /// `loads` pairs this rank's facets of a facet set with the load applied
    /// to them and its amplitude.
    pub fn new(
        mesh: &LocalMesh,
        dofs: &DofMap,
        loads: &[(&LocalFacetSet, FacetLoad, Amplitude)],
    ) -> Result<Self> {
        let mut facets = Vec::new();
        for (set, load, amplitude) in loads {
            for f in &set.facets {
                let facet_type = mesh.facet_type(f);
                let nodes: Vec<LocalNode> = f.nodes[..facet_type.nodes()]
                    .iter()
                    .map(|&l| LocalNode::from_u32(l))
                    .collect();
                let x_ref = mesh.facet_x_ref(f);
                let mut d = Vec::new();
                element_dofs(dofs, &nodes, &mut d);
                facets.push(LocalFacet {
                    cell: f.cell,
                    facet_type,
                    nodes,
                    x_ref,
                    dofs: d,
                    load: load.clone(),
                    amplitude: amplitude.clone(),
                });
            }
        }
        let max_nodes = facets.iter().map(|f| f.nodes.len()).max().unwrap_or(0);
        Ok(SurfaceLoads { facets, max_nodes })
    }

    pub fn is_empty(&self) -> bool {
        self.facets.is_empty()
    }

    /// True when some load follows the deformation (and so has a tangent).
    pub fn has_follower(&self) -> bool {
        self.facets
            .iter()
            .any(|f| matches!(f.load, FacetLoad::Pressure(_)))
    }

    /// Adds `scale` times the external force at load factor `factor` (each
    /// load at its own amplitude) into `f_local`.
    pub fn add_external_force(
        &self,
        u_local: &[f64],
        factor: f64,
        scale: f64,
        f_local: &mut [f64],
    ) -> Result<()> {
        let mut u = [[0.0; 3]; MAX_FACET_NODES];
        let mut fe = [0.0; 3 * MAX_FACET_NODES];
        for facet in &self.facets {
            let n = facet.nodes.len();
            match facet.load {
                FacetLoad::Traction(t) => {
                    fem::dead_traction(facet.facet_type, &facet.x_ref, t, &mut fe[..3 * n])
                        .map_err(|e| facet.error(e))?;
                }
                FacetLoad::Pressure(p) => {
                    gather_nodal(u_local, &facet.nodes, &mut u[..n]);
                    fem::follower_pressure(
                        facet.facet_type,
                        &facet.x_ref,
                        &u[..n],
                        p,
                        &mut fe[..3 * n],
                        None,
                    )
                    .map_err(|e| facet.error(e))?;
                }
            }
            let a = scale * facet.amplitude.at(factor);
            scatter_add(f_local, &facet.nodes, &fe[..3 * n], a);
        }
        Ok(())
    }

    /// Records the entries follower loads couple.
    pub fn add_pattern(&self, pattern: &mut dyn PatternSink) -> Result<()> {
        for facet in self
            .facets
            .iter()
            .filter(|f| matches!(f.load, FacetLoad::Pressure(_)))
        {
            pattern.add_square(&facet.dofs)?;
        }
        Ok(())
    }

    /// Adds −a(factor)·∂f_ext/∂u of follower loads into the tangent `k`.
    pub fn add_tangent(&self, u_local: &[f64], factor: f64, k: &mut dyn MatrixSink) -> Result<()> {
        let mut u = [[0.0; 3]; MAX_FACET_NODES];
        let mut fe = [0.0; 3 * MAX_FACET_NODES];
        // Sized by the largest facet loaded here: 144 entries for quad4.
        let mut ke = vec![0.0; 9 * self.max_nodes * self.max_nodes];
        for facet in &self.facets {
            let n = facet.nodes.len();
            if let FacetLoad::Pressure(p) = facet.load {
                gather_nodal(u_local, &facet.nodes, &mut u[..n]);
                fem::follower_pressure(
                    facet.facet_type,
                    &facet.x_ref,
                    &u[..n],
                    p,
                    &mut fe[..3 * n],
                    Some(&mut ke[..9 * n * n]),
                )
                .map_err(|e| facet.error(e))?;
                let a = facet.amplitude.at(factor);
                for v in &mut ke[..9 * n * n] {
                    *v *= -a;
                }
                k.add_block(&facet.dofs, &facet.dofs, &ke[..9 * n * n])?;
            }
        }
        Ok(())
    }
}

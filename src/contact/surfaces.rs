//! The slave side of a contact pair as one rank sees it.
//!
//! Slave facets belong to the rank that owns their cell; that rank evaluates
//! their links. The master facets a rank holds are `held_master`'s.
use super::kernel::reference_weights;
use crate::distribution::{LocalFacetSet, LocalMesh, SlaveSetPiece};
use crate::dofs::{DofMap, GlobalDof, LocalNode, DIM};
use crate::error::{Error, Result};
use crate::fem::{shape::facet_shape, FacetType, QuadRule};

/// A slave facet this rank evaluates.
#[derive(Debug, Clone)]
pub struct SlaveFacet {
    /// Position in the slave facet set: output rows are ordered by it.
    pub set_index: usize,
    pub nodes: Vec<LocalNode>,
    pub x_ref: Vec<[f64; 3]>,
    pub dofs: Vec<GlobalDof>,
    /// Shortest edge: the local element size for the penalty and tolerance.
    pub h: f64,
}

/// The slave side: this rank's facets and their quadrature points.
#[derive(Debug, Clone)]
pub struct SlaveSurface {
    /// Name of the slave facet set.
    pub set: String,
    pub facet_type: FacetType,
    pub facets: Vec<SlaveFacet>,
    /// Quadrature points per facet (same rule on every facet).
    pub nqp: usize,
    /// Per local quadrature point (facet-major): facet coordinates and
    /// reference area weight.
    pub qp_zeta: Vec<[f64; 2]>,
    pub qp_weight: Vec<f64>,
    /// Facets in the whole set (all ranks).
    pub global_facets: usize,
    /// Mean shortest edge of the set's facets (identical on every rank): the
    /// element size the penalty and the penetration tolerance scale with.
    /// The shortest edge, not √area, so one-cell-thick plane-strain slabs
    /// get their in-plane size.
    pub h: f64,
}

impl SlaveSurface {
    /// This rank's facets of `set` (those of its cells); `piece` carries
    /// the set-wide mean edge. A degenerate facet fails on the rank that
    /// holds it (the caller agrees the outcome over the ranks).
    pub fn new(
        mesh: &LocalMesh,
        dofs: &DofMap,
        set: &str,
        piece: &SlaveSetPiece,
        rule: &QuadRule,
    ) -> Result<Self> {
        let local_set = facet_set(mesh, set)?;
        let facet_type = mesh.cell_type.facet_type();
        let mut facets = Vec::new();
        let (mut qp_zeta, mut qp_weight) = (Vec::new(), Vec::new());
        for f in &local_set.facets {
            let set_index = f.set_index;
            let x_ref = mesh.facet_x_ref(f);
            let weights = reference_weights(facet_type, &x_ref, rule);
            if weights.is_empty() {
                return Err(Error::scene(
                    "contact",
                    format!(
                        "slave facet {set_index} of '{set}' (cell {}) is degenerate",
                        f.cell
                    ),
                ));
            }
            for (zeta, w) in &weights {
                qp_zeta.push(*zeta);
                qp_weight.push(*w);
            }
            let nodes: Vec<LocalNode> = f.nodes[..facet_type.nodes()]
                .iter()
                .map(|&l| LocalNode::from_u32(l))
                .collect();
            let facet_dofs = nodes.iter().flat_map(|&l| dofs.node_dofs(l)).collect();
            facets.push(SlaveFacet {
                set_index,
                nodes,
                h: shortest_edge(&x_ref),
                x_ref,
                dofs: facet_dofs,
            });
        }
        let global_facets = local_set.global_len;
        Ok(SlaveSurface {
            set: set.to_owned(),
            facet_type,
            facets,
            nqp: rule.len(),
            qp_zeta,
            qp_weight,
            global_facets,
            h: piece.mean_edge,
        })
    }

    pub fn num_qps(&self) -> usize {
        self.qp_weight.len()
    }

    /// Current position of local quadrature point `q`.
    pub fn qp_position(&self, q: usize, u_local: &[f64]) -> [f64; 3] {
        let facet = &self.facets[q / self.nqp];
        let s = facet_shape(self.facet_type, self.qp_zeta[q]);
        let mut x = [0.0; 3];
        for (a, (&l, xr)) in facet.nodes.iter().zip(&facet.x_ref).enumerate() {
            for c in 0..DIM {
                x[c] += s.n[a] * (xr[c] + u_local[l.vec_index(c)]);
            }
        }
        x
    }

    /// Current nodal positions of a facet.
    pub fn facet_positions(&self, facet: usize, u_local: &[f64], out: &mut [[f64; 3]]) {
        current_positions(
            &self.facets[facet].nodes,
            &self.facets[facet].x_ref,
            u_local,
            out,
        );
    }
}

fn shortest_edge(x: &[[f64; 3]]) -> f64 {
    (0..x.len())
        .map(|i| {
            let (a, b) = (x[i], x[(i + 1) % x.len()]);
            ((a[0] - b[0]).powi(2) + (a[1] - b[1]).powi(2) + (a[2] - b[2]).powi(2)).sqrt()
        })
        .fold(f64::INFINITY, f64::min)
}

/// `nodes`: local nodes, stored as such or in the compact `u32` form.
fn current_positions<N: Copy + Into<LocalNode>>(
    nodes: &[N],
    x_ref: &[[f64; 3]],
    u_local: &[f64],
    out: &mut [[f64; 3]],
) {
    for ((o, &l), xr) in out.iter_mut().zip(nodes).zip(x_ref) {
        let u = l.into().value(u_local);
        *o = [xr[0] + u[0], xr[1] + u[1], xr[2] + u[2]];
    }
}

fn facet_set<'m>(mesh: &'m LocalMesh, set: &str) -> Result<&'m LocalFacetSet> {
    mesh.facet_set(set)
        .ok_or_else(|| unknown_set(set, mesh.facet_set_names()))
}

fn unknown_set(set: &str, known: Vec<&str>) -> Error {
    Error::scene(
        "contact",
        format!(
            "facet set '{set}' does not exist (facet sets: {})",
            known.join(", ")
        ),
    )
}

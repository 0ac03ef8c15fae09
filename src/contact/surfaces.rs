//! The slave side of a contact pair as one rank sees it.
//!
//! Slave facets belong to the rank that owns their cell; that rank evaluates
//! their links. The master facets a rank holds are `held_master`'s.
use super::autodiff;
use crate::contact::{facet_shape, MAX_FACET_NODES};
use crate::distribution::{LocalFacetSet, LocalMesh, SlaveSetPiece};
use crate::dofs::{DofMap, GlobalDof, LocalNode, DIM};
use crate::error::{Error, Result};
use crate::fem::{FacetType, QuadRule};

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
    /// Global number of every slave facet of the set (by set index):
    /// contiguous per rank, like the DOFs; points are numbered facet-major
    /// after it (the rows of the pair's point output).
    pub global_facet: Vec<usize>,
    /// Mean shortest edge of the set's facets (identical on every rank): the
    /// element size the penalty and the penetration tolerance scale with.
    /// The shortest edge, not √area, so one-cell-thick plane-strain slabs
    /// get their in-plane size.
    pub h: f64,
}

/// The one facet type of a contact facet set (any order; the scene refuses
/// second-order facets for the mortar formulation, `scene/contact.rs`, and
/// mixed sets for both).
pub fn contact_facet_type(mesh: &LocalMesh, set: &str) -> Result<FacetType> {
    mesh.set_facet_type(set).ok_or_else(|| {
        Error::scene(
            "contact",
            format!("facet set '{set}' mixes facet types or does not exist; contact needs one type (tri3, quad4, tri6, quad8 or quad9) per surface"),
        )
    })
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
        let facet_type = contact_facet_type(mesh, set)?;
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
                h: shortest_edge(&x_ref, facet_type.corners()),
                x_ref,
                dofs: facet_dofs,
            });
        }
        let global_facets = local_set.global_len;
        if piece.owners.len() != global_facets {
            return Err(Error::Internal(format!(
                "slave set '{set}' has {global_facets} facets but {} facet owners",
                piece.owners.len()
            )));
        }
        let owner: Vec<usize> = piece.owners.iter().map(|&o| o as usize).collect();
        Ok(SlaveSurface {
            set: set.to_owned(),
            facet_type,
            facets,
            nqp: rule.len(),
            qp_zeta,
            qp_weight,
            global_facets,
            global_facet: contiguous_numbering(&owner, dofs.nranks),
            h: piece.mean_edge,
        })
    }

    /// Global number of slave point `q` of facet `set_index` (contiguous
    /// per rank), for redistribution to output order.
    pub fn global_point(&self, set_index: usize, q: usize) -> usize {
        self.global_facet[set_index] * self.nqp + q
    }

    pub fn num_qps(&self) -> usize {
        self.qp_weight.len()
    }

    /// Current position of local quadrature point `q`.
    pub fn qp_position(&self, q: usize, u_local: &[f64]) -> [f64; 3] {
        let facet = &self.facets[q / self.nqp];
        let s = facet_shape::<MAX_FACET_NODES>(self.facet_type, self.qp_zeta[q]);
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

/// Shortest corner-to-corner edge (the corners come first on every facet
/// type, so a second-order facet's size is its chords', as the mesh's
/// `mean_shortest_edge` measures it).
fn shortest_edge(x: &[[f64; 3]], corners: usize) -> f64 {
    let x = &x[..corners.min(x.len())];
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

/// Slave quadrature points and their reference weights: Gauss weight ×
/// `|∂X/∂ζ₁ × ∂X/∂ζ₂|` on the reference (undeformed) slave facet `x_ref`.
/// Empty for bad input (wrong node count, non-finite values, malformed rule).
pub fn reference_weights(
    facet: FacetType,
    x_ref: &[[f64; 3]],
    rule: &QuadRule,
) -> Vec<([f64; 2], f64)> {
    let usable = x_ref.len() == facet.nodes() && x_ref.as_flattened().iter().all(|v| v.is_finite());
    if !usable || rule.check().is_err() {
        return Vec::new();
    }
    rule.points
        .iter()
        .zip(&rule.weights)
        .map(|(p, w)| {
            let zeta = [p[0], p[1]];
            let s = facet_shape::<MAX_FACET_NODES>(facet, zeta);
            let mut t = [[0.0; 3]; 2];
            for (xa, da) in x_ref.iter().zip(&s.dn) {
                t[0] = autodiff::axpy(&t[0], da[0], xa);
                t[1] = autodiff::axpy(&t[1], da[1], xa);
            }
            (zeta, w * autodiff::norm(&autodiff::cross(&t[0], &t[1])))
        })
        .collect()
}

/// Numbers items rank by rank (each rank's in their given order), the same
/// way `DofMap` numbers nodes.
fn contiguous_numbering(owner: &[usize], nranks: usize) -> Vec<usize> {
    let mut count = vec![0usize; nranks];
    for &o in owner {
        count[o] += 1;
    }
    let mut next: Vec<usize> = count
        .iter()
        .scan(0, |acc, &c| {
            let start = *acc;
            *acc += c;
            Some(start)
        })
        .collect();
    owner
        .iter()
        .map(|&o| {
            let n = next[o];
            next[o] += 1;
            n
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn numbering_is_contiguous_per_rank() {
        assert_eq!(
            contiguous_numbering(&[1, 0, 1, 0, 2], 3),
            vec![2, 0, 3, 1, 4]
        );
    }
}

//! Slave facets their segments cover whole. By biorthogonality of the dual
//! basis, `Σ_segments D_jk = ∫ Φ_j N_k dA₀ = δ_jk ∫ N_j dA₀` over such a
//! facet: a constant diagonal. The facet carries it instead of the
//! segments' integrals (on its first segment, the others none), so its
//! slave-side forces are exact and local (`p_j A_j ν` at node `j` alone)
//! and neither the residual nor the tangent integrates `D` there (16 of the
//! 36 dual-number products a segment point took). A facet the master
//! covers in part (at the master's edge) keeps its segments' `D`, the part
//! that matches `M` there.
use super::segment::{nodal_areas, MortarRules};
use super::system::{Interface, Segment};
use crate::contact::dual::Scalar;
use crate::fem::MAX_FACET_NODES;

/// Relative tolerance on a slave facet's area for its segments to cover it
/// whole: far above the segment rules' error on bent facets, far below a
/// sliver a master edge would leave.
pub const COVERED_TOL: f64 = 1e-6;

/// Per slave facet: whether its segments cover it whole, i.e. their
/// reference areas sum to the facet's to [`COVERED_TOL`]. `segments` in
/// candidate order (a facet's segments consecutive).
pub fn covered_facets<T: Scalar>(
    interface: &Interface,
    rules: &MortarRules,
    segments: &[Segment<T>],
) -> Vec<bool> {
    let mut covered = vec![false; interface.slave_facets.len()];
    let mut i = 0;
    while i < segments.len() {
        let f = segments[i].slave;
        let mut area = 0.0;
        while i < segments.len() && segments[i].slave == f {
            area += segments[i].terms.area.re();
            i += 1;
        }
        let whole: f64 = slave_nodal_areas(interface, f, rules).iter().sum();
        covered[f as usize] = (area - whole).abs() <= COVERED_TOL * whole;
    }
    covered
}

/// `∫ N_j dA₀` of slave facet `f` (reference positions, the dual basis' rule).
pub(super) fn slave_nodal_areas(
    interface: &Interface,
    f: u32,
    rules: &MortarRules,
) -> [f64; MAX_FACET_NODES] {
    let ns = interface.slave_type.nodes();
    let mut x_ref = [[0.0; 3]; MAX_FACET_NODES];
    for (r, &n) in x_ref
        .iter_mut()
        .zip(&interface.slave_facets[f as usize][..ns])
    {
        *r = interface.reference[n as usize];
    }
    nodal_areas(interface.slave_type, &x_ref[..ns], rules)
}

/// Sets the `D` of the covered facets' segments: the facet's diagonal on
/// its first segment, zero on the others (constants, so in dual numbers
/// their derivatives vanish, as those of the sum do).
pub fn set_covered_diagonals<T: Scalar>(
    interface: &Interface,
    rules: &MortarRules,
    covered: &[bool],
    segments: &mut [Segment<T>],
) {
    let zero = T::from_f64(0.0);
    let ns = interface.slave_type.nodes();
    let mut last = None;
    for seg in segments.iter_mut().filter(|s| covered[s.slave as usize]) {
        let first = last != Some(seg.slave);
        last = Some(seg.slave);
        let areas = first.then(|| slave_nodal_areas(interface, seg.slave, rules));
        for (j, row) in seg.terms.d.iter_mut().enumerate().take(ns) {
            for (k, djk) in row.iter_mut().enumerate().take(ns) {
                *djk = match areas {
                    Some(a) if j == k => T::from_f64(a[j]),
                    _ => zero,
                };
            }
        }
    }
}

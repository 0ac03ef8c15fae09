//! Slave facets their segments cover whole. By biorthogonality of the dual
//! basis, `Σ_segments D_jk = ∫ Φ_j N_k dA₀ = δ_jk ∫ N_j dA₀` over such a
//! facet: a constant diagonal. The facet carries it instead of the
//! segments' integrals (on its first segment, the others none), so its
//! slave-side forces are exact and local (`p_j A_j ν` at node `j` alone)
//! and neither the residual nor the tangent integrates `D` there (16 of the
//! 36 dual-number products a segment point took). A facet the master
//! covers in part (at the master's edge) keeps its segments' `D`, the part
//! that matches `M` there.
use super::segment::SegmentTerms;
use super::MAX_FACET_NODES;
use crate::contact::autodiff::Scalar;

/// Relative tolerance on a slave facet's area for its segments to cover it
/// whole: far above the segment rules' error on bent facets, far below a
/// sliver a master edge would leave.
pub const COVERED_TOL: f64 = 1e-6;

/// Per slave facet (`facets` of them): whether its segments cover it
/// whole, i.e. their reference areas sum to the facet's (`facet_area`) to
/// [`COVERED_TOL`]. `segments` are (slave facet, reference area) in
/// candidate order, a facet's segments consecutive.
pub fn covered_facets(
    facets: usize,
    segments: impl Iterator<Item = (u32, f64)>,
    facet_area: impl Fn(u32) -> f64,
) -> Vec<bool> {
    let mut covered = vec![false; facets];
    let mut sums: Vec<(u32, f64)> = Vec::new();
    for (f, area) in segments {
        match sums.last_mut() {
            Some((g, sum)) if *g == f => *sum += area,
            _ => sums.push((f, area)),
        }
    }
    for (f, area) in sums {
        let whole = facet_area(f);
        covered[f as usize] = (area - whole).abs() <= COVERED_TOL * whole;
    }
    covered
}

/// Sets the `D` of the covered facets' segments (slave facet, terms; in
/// candidate order): the facet's diagonal `nodal_areas` on its first
/// segment, zero on the others (constants, so in dual numbers their
/// derivatives vanish, as those of the sum do). `ns`: slave facet nodes.
pub fn set_diagonals<'a, T: Scalar + 'a>(
    covered: &[bool],
    segments: impl Iterator<Item = (u32, &'a mut SegmentTerms<T>)>,
    nodal_areas: impl Fn(u32) -> [f64; MAX_FACET_NODES],
    ns: usize,
) {
    let zero = T::from_f64(0.0);
    let mut last = None;
    for (f, terms) in segments.filter(|s| covered[s.0 as usize]) {
        let first = last != Some(f);
        last = Some(f);
        let areas = first.then(|| nodal_areas(f));
        for (j, row) in terms.d.iter_mut().enumerate().take(ns) {
            for (k, djk) in row.iter_mut().enumerate().take(ns) {
                *djk = match areas {
                    Some(a) if j == k => T::from_f64(a[j]),
                    _ => zero,
                };
            }
        }
    }
}

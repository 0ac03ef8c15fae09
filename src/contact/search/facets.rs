//! The facets of a master surface as the search sees them: the usable
//! ones, their nodes and neighbours, and distances to their boundary.

use super::grid::Rows;
use super::{is_finite3, SearchSurface};
use crate::contact::MAX_FACET_NODES;
use crate::fem::FacetType;
use crate::vec3::{distance, distance2, dot, sub};

/// A facet whose node ids are in range and whose coordinates are finite.
pub(super) struct UsableFacet {
    pub(super) id: u32,
    pub(super) ids: [u32; MAX_FACET_NODES],
    pub(super) nodes: [[f64; 3]; MAX_FACET_NODES],
    pub(super) k: usize,
}

pub(super) fn facet_nodes(surface: &SearchSurface, f: u32) -> Option<UsableFacet> {
    let k = surface.facet_type.nodes();
    let ids = *surface.facet(f)?;
    let mut nodes = [[0.0; 3]; MAX_FACET_NODES];
    for (slot, &n) in nodes.iter_mut().zip(&ids[..k]) {
        let p = surface.position(n)?;
        if !is_finite3(p) {
            return None;
        }
        *slot = p;
    }
    Some(UsableFacet {
        id: f,
        ids,
        nodes,
        k,
    })
}

/// The usable facets in id order (ids beyond `u32` cannot be named and are
/// left out).
pub(super) fn usable_facets(surface: &SearchSurface) -> Vec<UsableFacet> {
    let n = surface.facets.len().min(u32::MAX as usize);
    (0..n as u32)
        .filter_map(|f| facet_nodes(surface, f))
        .collect()
}

/// Nodes of usable facets, ascending. Only these are searched: a node on no
/// facet has no facet to project onto.
pub(super) fn used_nodes(surface: &SearchSurface, facets: &[UsableFacet]) -> Vec<u32> {
    let mut used = vec![false; surface.positions.len()];
    for f in facets {
        for &n in &f.ids[..f.k] {
            used[n as usize] = true;
        }
    }
    (0..used.len() as u32)
        .filter(|&n| used[n as usize])
        .collect()
}

/// For every facet id, the facets sharing a node with it (itself
/// included), merged from the node rows; empty for unusable facets.
pub(super) fn facet_neighbours(surface: &SearchSurface, node_facets: &Rows) -> Rows {
    let k = surface.facet_type.nodes();
    let mut start = Vec::with_capacity(surface.facets.len() + 1);
    let mut items = Vec::new();
    start.push(0);
    for (f, conn) in surface.facets.iter().enumerate() {
        // Usable facets are exactly those listed at their nodes.
        let usable =
            u32::try_from(f).is_ok_and(|id| node_facets.row_of(conn[0]).binary_search(&id).is_ok());
        if usable {
            let mut rows: [&[u32]; MAX_FACET_NODES] = [&[]; MAX_FACET_NODES];
            for (row, &n) in rows.iter_mut().zip(&conn[..k]) {
                *row = node_facets.row_of(n);
            }
            merge_sorted_unique(&mut rows[..k], &mut items);
        }
        start.push(items.len());
    }
    Rows { start, items }
}

/// Appends the union of the sorted, repeat-free `lists` to `out`, sorted and
/// each id once: a merge that always takes the smallest head. The lists are
/// short and few, so scanning the heads beats any heap.
pub(super) fn merge_sorted_unique(lists: &mut [&[u32]], out: &mut Vec<u32>) {
    loop {
        let Some(min) = lists.iter().filter_map(|l| l.first()).min().copied() else {
            return;
        };
        out.push(min);
        for l in lists.iter_mut() {
            if let Some((&head, rest)) = l.split_first() {
                if head == min {
                    *l = rest;
                }
            }
        }
    }
}

/// Mean corner-to-corner edge (the corners come first on every facet type).
pub(super) fn mean_edge_length(facet_type: FacetType, facets: &[UsableFacet]) -> f64 {
    let k = facet_type.corners();
    let (sum, count) = facets.iter().fold((0.0, 0usize), |(s, c), f| {
        let x = &f.nodes[..k.min(f.k)];
        let edges = (0..x.len()).map(|i| distance(x[i], x[(i + 1) % x.len()]));
        (s + edges.sum::<f64>(), c + x.len())
    });
    sum / count.max(1) as f64
}

/// Longest corner-to-corner edge: the length scale for the tie and pruning
/// tolerances.
pub(super) fn facet_size(facet_type: FacetType, x: &[[f64; 3]]) -> f64 {
    let x = &x[..facet_type.corners().min(x.len())];
    (0..x.len())
        .map(|i| distance2(x[i], x[(i + 1) % x.len()]))
        .fold(0.0, f64::max)
        .sqrt()
}

/// The facet's boundary as a closed polygon of node indices: the corners,
/// with each edge's mid-side node between its ends on a second-order facet
/// (corner `k`'s edge to corner `k + 1` holds node `corners + k`).
fn boundary_loop(facet_type: FacetType, out: &mut [usize; 2 * 4]) -> usize {
    let k = facet_type.corners();
    if facet_type.is_linear() {
        for (i, o) in out.iter_mut().enumerate().take(k) {
            *o = i;
        }
        return k;
    }
    for i in 0..k {
        out[2 * i] = i;
        out[2 * i + 1] = k + i;
    }
    2 * k
}

/// Distance from `p` to the facet's boundary polygon (its straight edges on
/// tri3 and the bilinear quad4; on a second-order facet the polygon through
/// the mid-side nodes, within the edges' sag of the curved edge): where
/// the clamped projection of a point lies that projects outside the facet.
pub(super) fn boundary_distance(facet_type: FacetType, x: &[[f64; 3]], p: [f64; 3]) -> f64 {
    let mut ring = [0; 2 * 4];
    let n = if x.len() == facet_type.nodes() {
        boundary_loop(facet_type, &mut ring)
    } else {
        0
    };
    let ring = &ring[..n];
    (0..n)
        .map(|i| segment_distance(x[ring[i]], x[ring[(i + 1) % n]], p))
        .fold(f64::INFINITY, f64::min)
}

fn segment_distance(a: [f64; 3], b: [f64; 3], p: [f64; 3]) -> f64 {
    let ab = sub(b, a);
    let len2 = dot(ab, ab);
    let t = if len2 > 0.0 {
        (dot(sub(p, a), ab) / len2).clamp(0.0, 1.0)
    } else {
        0.0
    };
    distance(p, [a[0] + t * ab[0], a[1] + t * ab[1], a[2] + t * ab[2]])
}

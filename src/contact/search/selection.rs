//! Selection among projected facets: the rule of the module documentation
//! (nearest valid projection, ties by facet id).

use super::facets::{boundary_distance, facet_nodes, facet_size};
use super::{is_finite3, SearchSurface, INSIDE_TOL, PRUNE_REL, TIE_REL};
use crate::contact::projection::{project, Projection};
use crate::vec3::distance;

pub(super) struct Candidate {
    pub(super) facet: u32,
    distance: f64,
    valid: bool,
    tie: f64,
    pub(super) projection: Projection,
}

/// The facets projected so far for one query: the smallest distance, the
/// ids looked at (so none is projected twice) and the candidates that can
/// still win. Kept off the heap in the common case (one candidate, a few
/// ids), since `find` runs once per slave point.
pub(super) struct Selection {
    pub(super) best: f64,
    seen: [u32; SEEN_BUF],
    n_seen: usize,
    /// The candidate with the smallest distance so far; `rest` holds others
    /// within their tie tolerance of it (only at edges, nodes, ties).
    first: Option<Candidate>,
    rest: Vec<Candidate>,
}

/// Ids remembered per query; beyond this a facet may be projected twice,
/// which costs time but changes nothing.
const SEEN_BUF: usize = 32;

impl Selection {
    pub(super) fn new() -> Self {
        Selection {
            best: f64::INFINITY,
            seen: [0; SEEN_BUF],
            n_seen: 0,
            first: None,
            rest: Vec::new(),
        }
    }

    pub(super) fn contains(&self, facet: u32) -> bool {
        self.seen[..self.n_seen].contains(&facet)
    }

    fn push(&mut self, c: Candidate) {
        if self.n_seen < SEEN_BUF {
            self.seen[self.n_seen] = c.facet;
            self.n_seen += 1;
        }
        if c.distance > self.best + c.tie {
            // Can never join the tie group: the best only decreases.
            return;
        }
        if c.distance < self.best {
            // A new best: the old one becomes a runner-up, and runners-up
            // now out of tie range drop out.
            let best = c.distance;
            self.best = best;
            self.rest.extend(self.first.replace(c));
            self.rest.retain(|r| r.distance <= best + r.tie);
        } else {
            self.rest.push(c);
        }
    }

    /// Smallest distance, then among those within their tie tolerance of it:
    /// valid before invalid, then smaller id. Every candidate that could be
    /// in that group is still held, so the answer does not depend on the
    /// order the facets were projected in.
    pub(super) fn into_winner(self) -> Option<Candidate> {
        let first = self.first?;
        let key = |c: &Candidate| (!c.valid, c.facet);
        let best = self.best;
        let tied = self.rest.into_iter().filter(|c| c.distance <= best + c.tie);
        Some(tied.fold(first, |w, c| if key(&c) < key(&w) { c } else { w }))
    }
}

/// Projects `x` onto facet `f` unless it was already projected or its
/// bounding box (at squared distance `lower_bound2`) is too far to win or
/// tie.
pub(super) fn consider(
    surface: &SearchSurface,
    f: u32,
    lower_bound2: f64,
    x: [f64; 3],
    start: Option<[f64; 2]>,
    sel: &mut Selection,
) {
    if sel.contains(f) {
        return;
    }
    let Some(facet) = facet_nodes(surface, f) else {
        return;
    };
    let nodes = &facet.nodes[..facet.k];
    let size = facet_size(surface.facet_type, nodes);
    let reach = sel.best + PRUNE_REL * size;
    if lower_bound2 > reach * reach {
        return;
    }
    let projection = project(surface.facet_type, nodes, x, start);
    let valid =
        projection.converged && projection.outside <= INSIDE_TOL && is_finite3(projection.point);
    let distance = if valid {
        distance(x, projection.point)
    } else {
        boundary_distance(surface.facet_type, nodes, x)
    };
    sel.push(Candidate {
        facet: f,
        distance,
        valid,
        tie: TIE_REL * size,
        projection,
    });
}

//! Contact search: which master facet, and which point on it, a slave point
//! sees (docs/formulation.md §9).
//!
//! Two stages:
//!
//! - **outer search**: the master node closest to the slave point, from a
//!   uniform bucket grid over the master nodes. It is exact: grid shells are
//!   searched outward until no unvisited cell can hold a closer node.
//! - **inner search**: closest-point projection onto the facets around that
//!   node, keeping the one the point projects into.
//!
//! # Which facet wins
//!
//! Every facet that is looked at gets a distance `d`: `|x − point|` when the
//! projection is valid (converged, `outside ≤ INSIDE_TOL`), otherwise the
//! distance from `x` to the facet's boundary edges, which is where its
//! clamped projection lies (exact for flat facets). The winner minimises `d`;
//! facets within a tie tolerance (`TIE_REL` × facet size) of the minimum form
//! a tie group, in which a valid projection beats an invalid one and then the
//! smaller facet id wins. In practice this reads: the facet the point projects
//! into (the nearest if several, e.g. on the concave side of a curved
//! master); if none (convex edge or corner, or beyond the master's border) the
//! facet whose clamped projection is nearest. The one case where it differs
//! from "any valid projection first" is on purpose: a valid projection that
//! is farther than another facet's nearest point is not the closest point
//! (the opposite side of a cylinder, the valley behind a ridge).
//!
//! # Exactness and determinism
//!
//! On a distorted mesh the closest node need not be a corner of the facet
//! holding the closest point, so after the facets around the closest node
//! `find` sweeps a second grid (facets bucketed by bounding box) for any
//! facet whose box lies within the best distance so far and looks at those
//! too. Usually that is one cell and no extra projection. The result is then
//! the exact winner over all facets of the surface under the rule above, so it
//! depends only on the geometry and the ids, never on the grid layout (cell
//! size, bounding box), on the evaluation order or on the rank count. Ties
//! between nodes go to the smaller node id, ties between facets as above.
//! No hash map is used anywhere.
//!
//! Nothing here panics on bad input: facets with out-of-range node ids or
//! non-finite coordinates are ignored, non-finite query points find nothing,
//! and a surface that does not match the index (other sizes or facet type)
//! finds nothing.
//!
//! # Cost
//!
//! Building is O(nodes + facets). A query is O(1) on a mesh of even
//! density: about 10 grid cells, usually one projection, and the patch
//! merged from precomputed facet-neighbour rows; nothing is allocated but
//! the returned patch. What dominates on a large master is memory, not
//! arithmetic: queries in mesh order (how a slave surface is walked) reuse
//! cache lines, queries in random order miss on every one, which costs
//! several times more. [`SearchIndex::find_many`] reorders a batch by grid
//! cell to get the former from the latter.

#[cfg(test)]
mod edge_tests;
mod facets;
mod grid;
mod selection;
#[cfg(test)]
mod tests;

use crate::contact::projection::Projection;
use crate::contact::MAX_FACET_NODES;
use crate::fem::FacetType;
use crate::vec3::distance2;
use facets::{
    facet_neighbours, facet_nodes, facet_size, mean_edge_length, merge_sorted_unique,
    usable_facets, used_nodes,
};
use grid::{Grid, NearestNode, Rows};
use selection::{consider, Selection};
use std::cmp::Ordering;

/// Tolerance on `Projection::outside` (reference coordinates) under which a
/// projection counts as inside its facet. Large against round-off, so a
/// point exactly on an edge or a node is inside every facet sharing it, and
/// small against the facet, so no point is claimed by a facet it is clearly
/// beside.
pub const INSIDE_TOL: f64 = 1e-6;

/// Distances that differ by less than this times the facet size are a tie.
/// It absorbs round-off (a point above a shared edge is equally far from
/// both facets up to the last bits), so ties go by facet id, not by which
/// facet's arithmetic happened to round down.
pub const TIE_REL: f64 = 1e-9;

/// A facet is skipped without projecting when its bounding box is farther
/// than the best distance so far plus this times its size. It must cover the
/// tie tolerance plus how far a valid projection may lie outside the facet
/// (`INSIDE_TOL` in reference coordinates is at most two edge lengths of
/// physical distance per unit), or a skipped facet could have joined a tie.
const PRUNE_REL: f64 = 4.0 * INSIDE_TOL + TIE_REL;

/// Upper bound on grid cells per indexed node. A curved surface fills only
/// a thin layer of its bounding box; capping the dense grid keeps memory
/// linear in the surface size (cells grow instead).
const CELLS_PER_NODE: usize = 4;

/// Cells fixed in every grid so tiny surfaces still get a few.
const MIN_CELLS: usize = 64;

/// Slack (times the cell size) on every grid-geometry bound: a node is
/// bucketed by `(p − origin) / cell` rounded down, which can land across a
/// cell face by a few ulps; the slack keeps the pruning conservative.
const GRID_PAD_REL: f64 = 1e-7;

/// The ring around the closest node is sorted on the stack up to this many
/// facets (ample for any sane mesh); a larger ring is still searched, the
/// excess in id order.
const RING_BUF: usize = 16;

type Aabb = ([f64; 3], [f64; 3]);

const EMPTY_BOX: Aabb = ([f64::INFINITY; 3], [f64::NEG_INFINITY; 3]);

/// The surface a search looks in: a master surface in its current
/// configuration, node positions and facets (indices into `positions`).
#[derive(Debug, Clone, Copy)]
pub struct SearchSurface<'a> {
    pub facet_type: FacetType,
    pub positions: &'a [[f64; 3]],
    /// The facet type's node count used (tri3 the first 3 entries).
    pub facets: &'a [[u32; MAX_FACET_NODES]],
}

impl SearchSurface<'_> {
    /// Position of node `n`; None past the end.
    pub fn position(&self, n: u32) -> Option<[f64; 3]> {
        self.positions.get(n as usize).copied()
    }

    /// Position of node `n`, which must be in range (a node of a usable
    /// facet).
    fn node(&self, n: u32) -> [f64; 3] {
        self.positions[n as usize]
    }

    /// Node ids of facet `f`; None past the end.
    pub fn facet(&self, f: u32) -> Option<&[u32; MAX_FACET_NODES]> {
        self.facets.get(f as usize)
    }
}

/// The result of [`SearchIndex::find`] for one slave point.
pub struct Found {
    /// The chosen master facet.
    pub facet: u32,
    /// The projection onto it (as `project` returned it; `outside > 0` when
    /// the point lies beyond a convex edge or the master's border).
    pub projection: Projection,
    /// The master node closest to the slave point (outer search).
    pub closest_node: u32,
    /// Facets a link may move within during Newton iterations (large
    /// sliding): every facet sharing a node with a facet around
    /// `closest_node` or with `facet` itself. Sorted, contains `facet`.
    pub patch: Vec<u32>,
}

impl std::fmt::Debug for Found {
    // By hand so that nothing is asked of `Projection` beyond its fields.
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let p = &self.projection;
        f.debug_struct("Found")
            .field("facet", &self.facet)
            .field("xi", &p.xi)
            .field("point", &p.point)
            .field("normal", &p.normal)
            .field("gap", &p.gap)
            .field("converged", &p.converged)
            .field("outside", &p.outside)
            .field("closest_node", &self.closest_node)
            .field("patch", &self.patch)
            .finish()
    }
}

/// Search structure over one master surface, built once per load step (the
/// surface passed to the queries must be the one it was built from).
#[derive(Debug, Clone)]
pub struct SearchIndex {
    facet_type: FacetType,
    n_positions: usize,
    n_facets: usize,
    grid: Grid,
    /// Cell → indexed nodes, ascending ids.
    cell_nodes: Rows,
    /// Coordinates parallel to `cell_nodes.items`, so scanning a cell reads
    /// one contiguous run of memory.
    cell_node_pos: Vec<[f64; 3]>,
    /// Cell → facets whose bounding box meets the cell, ascending ids.
    cell_facets: Rows,
    /// Node → facets containing it, ascending ids.
    node_facets: Rows,
    /// Facet → facets sharing a node with it (itself included), ascending
    /// ids: the patch of a query is the union of a few of these rows.
    facet_neighbours: Rows,
    /// Per facet id; `EMPTY_BOX` for ignored facets, so they are never near.
    facet_box: Vec<Aabb>,
    /// Largest pruning margin of any facet (see `PRUNE_REL`): sizes the
    /// sweep and screens facets before their nodes are read. One number
    /// rather than one per facet, to touch one cache line less per facet.
    max_margin: f64,
    bbox: Aabb,
}

impl SearchIndex {
    /// Buckets the master nodes that belong to a usable facet into a uniform
    /// grid (cells about the mean edge length), the facets by bounding box
    /// into the same cells, and records node → facets adjacency.
    pub fn build(surface: &SearchSurface) -> Self {
        let facets = usable_facets(surface);
        let used = used_nodes(surface, &facets);
        let bbox =
            points_bounding_box_of(used.iter().map(|&n| surface.node(n))).unwrap_or(EMPTY_BOX);
        let grid = if used.is_empty() {
            Grid::single_cell()
        } else {
            let cap = CELLS_PER_NODE
                .saturating_mul(used.len())
                .saturating_add(MIN_CELLS);
            Grid::new(bbox, mean_edge_length(surface.facet_type, &facets), cap)
        };
        let n_cells = grid.n_cells();

        let node_pairs: Vec<(usize, u32)> = used
            .iter()
            .map(|&n| (grid.index(grid.cell_of(surface.node(n))), n))
            .collect();
        let cell_nodes = Rows::build(n_cells, &node_pairs);
        let cell_node_pos = cell_nodes.items.iter().map(|&n| surface.node(n)).collect();

        let mut facet_box = vec![EMPTY_BOX; surface.facets.len()];
        let mut facet_pairs = Vec::new();
        let mut node_pairs = Vec::new();
        let mut max_size: f64 = 0.0;
        for f in &facets {
            let b = self::facet_box(surface.facet_type, &f.nodes[..f.k]);
            let size = facet_size(surface.facet_type, &f.nodes[..f.k]);
            facet_box[f.id as usize] = b;
            max_size = max_size.max(size);
            if let Some(range) = grid.cell_range(b.0, b.1) {
                grid.for_each_cell(range, |cell| facet_pairs.push((cell, f.id)));
            }
            for (i, &n) in f.ids[..f.k].iter().enumerate() {
                // A collapsed facet may repeat a node; list it once.
                if !f.ids[..i].contains(&n) {
                    node_pairs.push((n as usize, f.id));
                }
            }
        }

        let node_facets = Rows::build(surface.positions.len(), &node_pairs);
        SearchIndex {
            facet_type: surface.facet_type,
            n_positions: surface.positions.len(),
            n_facets: surface.facets.len(),
            cell_facets: Rows::build(n_cells, &facet_pairs),
            facet_neighbours: facet_neighbours(surface, &node_facets),
            node_facets,
            grid,
            cell_nodes,
            cell_node_pos,
            facet_box,
            max_margin: PRUNE_REL * max_size,
            bbox,
        }
    }

    /// Bounding box of the indexed master nodes (which contains every usable
    /// facet). An empty surface gives the empty box `(+∞, −∞)`, which
    /// overlaps nothing in [`boxes_overlap`].
    pub fn bounding_box(&self) -> ([f64; 3], [f64; 3]) {
        self.bbox
    }

    /// Outer search: the master node closest to `x` and its distance (exact
    /// nearest; equal distances go to the smaller node id), searching grid
    /// shells outward until no closer node can exist. `None` if the surface
    /// is empty, does not match the index, or `x` is not finite.
    pub fn closest_node(&self, surface: &SearchSurface, x: [f64; 3]) -> Option<(u32, f64)> {
        if !self.matches(surface) || !is_finite3(x) {
            return None;
        }
        self.nearest_node(x)
    }

    /// Outer + inner search for one slave point: the closest node, then the
    /// facets around it (and any other facet that could be closer, see the
    /// module doc) under the selection rule of the module doc. `None` when
    /// the closest node is farther than `max_distance` (or as for
    /// [`closest_node`](Self::closest_node)).
    pub fn find(&self, surface: &SearchSurface, x: [f64; 3], max_distance: f64) -> Option<Found> {
        let (node, distance) = self.closest_node(surface, x)?;
        // A NaN `max_distance` (unordered) finds nothing.
        if distance
            .partial_cmp(&max_distance)
            .is_none_or(Ordering::is_gt)
        {
            return None;
        }
        let mut sel = Selection::new();
        self.search_ring(surface, node, x, &mut sel);
        self.sweep_near_facets(surface, x, &mut sel);
        let win = sel.into_winner()?;
        let patch = self.patch(node, win.facet);
        Some(Found {
            facet: win.facet,
            projection: win.projection,
            closest_node: node,
            patch,
        })
    }

    /// [`find`](Self::find) for many slave points at once, answers in the
    /// order of `points`, identical to calling `find` on each. The points are
    /// taken in grid-cell order (a counting sort), so consecutive queries
    /// touch the same few cache lines and pages of the index: on points in
    /// random order this is several times faster than `find` point by point
    /// (the search itself is memory-bound there), on points already in mesh
    /// order it costs one sort.
    pub fn find_many(
        &self,
        surface: &SearchSurface,
        points: &[[f64; 3]],
        max_distance: f64,
    ) -> Vec<Option<Found>> {
        let mut found: Vec<Option<Found>> =
            std::iter::repeat_with(|| None).take(points.len()).collect();
        for i in self.cell_order(points) {
            found[i] = self.find(surface, points[i], max_distance);
        }
        found
    }

    /// Indices of `points` ordered by the grid cell holding them (stable;
    /// points outside the grid go to the nearest cell, non-finite ones to
    /// cell 0).
    fn cell_order(&self, points: &[[f64; 3]]) -> Vec<usize> {
        let cells: Vec<usize> = points
            .iter()
            .map(|&p| self.grid.index(self.grid.cell_of(p)))
            .collect();
        let mut start = vec![0usize; self.grid.n_cells() + 1];
        for &c in &cells {
            start[c + 1] += 1;
        }
        for c in 0..self.grid.n_cells() {
            start[c + 1] += start[c];
        }
        let mut order = vec![0usize; points.len()];
        for (i, &c) in cells.iter().enumerate() {
            order[start[c]] = i;
            start[c] += 1;
        }
        order
    }

    fn matches(&self, surface: &SearchSurface) -> bool {
        surface.facet_type == self.facet_type
            && surface.positions.len() == self.n_positions
            && surface.facets.len() == self.n_facets
    }

    fn nearest_node(&self, x: [f64; 3]) -> Option<(u32, f64)> {
        if self.cell_node_pos.is_empty() {
            return None;
        }
        let c0 = self.grid.cell_of(x);
        let outside2 = self.grid.outside_gap2(x);
        let mut best = NearestNode::new(GRID_PAD_REL * self.grid.cell);
        for k in 0.. {
            self.visit_shell(c0, k, x, &mut best);
            match self.grid.unvisited_distance2(c0, k, x, outside2) {
                Some(bound2) if !best.beats(bound2) => {}
                _ => break,
            }
        }
        best.result()
    }

    /// Scans the cells at Chebyshev distance exactly `k` from `c0`, skipping
    /// those that cannot beat the best node so far. The squared distance to a
    /// cell is summed from per-axis gaps, so whole rows are skipped at once.
    fn visit_shell(&self, c0: [usize; 3], k: usize, x: [f64; 3], best: &mut NearestNode) {
        let g = &self.grid;
        let lo = [
            c0[0].saturating_sub(k),
            c0[1].saturating_sub(k),
            c0[2].saturating_sub(k),
        ];
        let hi = [
            (c0[0] + k).min(g.dims[0] - 1),
            (c0[1] + k).min(g.dims[1] - 1),
            (c0[2] + k).min(g.dims[2] - 1),
        ];
        for l in lo[2]..=hi[2] {
            let gap_z = g.gap2(2, l, x[2]);
            let rim_z = l.abs_diff(c0[2]) == k;
            for j in lo[1]..=hi[1] {
                let gap_yz = gap_z + g.gap2(1, j, x[1]);
                if !best.may_hold(gap_yz) {
                    continue;
                }
                let row = (l * g.dims[1] + j) * g.dims[0];
                let mut visit = |i: usize| {
                    if best.may_hold(gap_yz + g.gap2(0, i, x[0])) {
                        self.scan_cell(row + i, x, best);
                    }
                };
                if rim_z || j.abs_diff(c0[1]) == k {
                    (lo[0]..=hi[0]).for_each(&mut visit);
                } else {
                    // Inside the shell only its two x ends are new.
                    if c0[0] >= k {
                        visit(c0[0] - k);
                    }
                    if c0[0] + k < g.dims[0] {
                        visit(c0[0] + k);
                    }
                }
            }
        }
    }

    fn scan_cell(&self, cell: usize, x: [f64; 3], best: &mut NearestNode) {
        let range = self.cell_nodes.range(cell);
        let ids = &self.cell_nodes.items[range.clone()];
        for (&id, p) in ids.iter().zip(&self.cell_node_pos[range]) {
            best.offer(id, distance2(*p, x));
        }
    }

    /// Projects onto the facets around the closest node, nearest bounding
    /// box first: on a smooth mesh the first one holds the point and its
    /// distance lets the others be skipped without projecting.
    fn search_ring(&self, surface: &SearchSurface, node: u32, x: [f64; 3], sel: &mut Selection) {
        let ring = self.node_facets.row_of(node);
        let mut order = [(0.0, 0u32); RING_BUF];
        let n = ring.len().min(RING_BUF);
        for (slot, &f) in order.iter_mut().zip(ring) {
            *slot = (self.facet_lower_bound2(f, x), f);
        }
        order[..n].sort_unstable_by(|a, b| a.0.total_cmp(&b.0).then(a.1.cmp(&b.1)));
        for &(lb, f) in &order[..n] {
            self.consider(surface, f, lb, x, sel);
        }
        for &f in &ring[n..] {
            self.consider(surface, f, self.facet_lower_bound2(f, x), x, sel);
        }
    }

    /// Looks at every facet whose bounding box lies within the best distance
    /// so far (plus margin): those are the only ones that could still win or
    /// tie, and the ring around the closest node need not hold them all.
    fn sweep_near_facets(&self, surface: &SearchSurface, x: [f64; 3], sel: &mut Selection) {
        let r = sel.best + self.max_margin;
        let lo = x.map(|v| v - r);
        let hi = x.map(|v| v + r);
        let Some(range) = self.grid.cell_range(lo, hi) else {
            return;
        };
        // Only cells within r: a facet box within r of x has its point
        // nearest x in one of them (the cube of the range is about twice
        // the ball, and a curved master fills many of its cells).
        self.grid.for_each_cell_within(range, x, r, |cell| {
            for &f in self.cell_facets.row(cell) {
                self.consider(surface, f, self.facet_lower_bound2(f, x), x, sel);
            }
        });
    }

    /// `consider`, but dismissing far facets by their stored box before
    /// their nodes are even read.
    fn consider(
        &self,
        surface: &SearchSurface,
        f: u32,
        lower_bound2: f64,
        x: [f64; 3],
        sel: &mut Selection,
    ) {
        let reach = sel.best + self.max_margin;
        if lower_bound2 <= reach * reach {
            consider(surface, f, lower_bound2, x, None, sel);
        }
    }

    /// Squared distance from `x` to the facet's bounding box.
    fn facet_lower_bound2(&self, f: u32, x: [f64; 3]) -> f64 {
        self.facet_box
            .get(f as usize)
            .map_or(f64::INFINITY, |b| box_distance2(b, x))
    }

    /// The facets around `node` and `chosen`, and every facet sharing a node
    /// with one of them: the union of their neighbour rows.
    fn patch(&self, node: u32, chosen: u32) -> Vec<u32> {
        let ring = self.node_facets.row_of(node);
        let extra = (!ring.contains(&chosen)).then_some(&chosen);
        let seeds = ring.iter().chain(extra);
        let mut rows: [&[u32]; RING_BUF + 1] = [&[]; RING_BUF + 1];
        if ring.len() + 1 > rows.len() {
            // A huge ring: sort the lot instead.
            let mut patch: Vec<u32> = seeds
                .flat_map(|&f| self.facet_neighbours.row_of(f))
                .copied()
                .collect();
            patch.sort_unstable();
            patch.dedup();
            return patch;
        }
        let mut n = 0;
        for &f in seeds {
            rows[n] = self.facet_neighbours.row_of(f);
            n += 1;
        }
        let mut patch = Vec::with_capacity(rows[..n].iter().map(|r| r.len()).sum());
        merge_sorted_unique(&mut rows[..n], &mut patch);
        patch
    }
}

/// The inner search alone, reused during Newton iterations: among
/// `candidates`, the facet onto which `x` projects validly (nearest if
/// several; nearest clamped if none), under the selection rule of the module
/// doc. `previous` (facet, ξ) is projected first, from that ξ, when it is
/// among the candidates. Unusable candidate ids are ignored; `None` when no
/// candidate is usable or `x` is not finite.
pub fn select_facet(
    surface: &SearchSurface,
    candidates: &[u32],
    x: [f64; 3],
    previous: Option<(u32, [f64; 2])>,
) -> Option<(u32, Projection)> {
    if !is_finite3(x) {
        return None;
    }
    let mut sel = Selection::new();
    if let Some((f, xi)) = previous.filter(|(f, _)| candidates.contains(f)) {
        let start = is_finite2(xi).then_some(xi);
        // Lower bound 0: the previous facet is always projected; it is the
        // likely winner and its distance prunes the rest.
        consider(surface, f, 0.0, x, start, &mut sel);
    }
    // The rest nearest box first, and only those whose box could still win
    // or tie against the previous facet (during Newton usually none).
    let mut order: Vec<(f64, u32)> = Vec::new();
    for &f in candidates {
        let Some(facet) = facet_nodes(surface, f) else {
            continue;
        };
        let nodes = &facet.nodes[..facet.k];
        let b = facet_box(surface.facet_type, nodes);
        if b == EMPTY_BOX {
            continue;
        }
        let lb2 = box_distance2(&b, x);
        let reach = sel.best + PRUNE_REL * facet_size(surface.facet_type, nodes);
        if lb2 <= reach * reach && !sel.contains(f) {
            order.push((lb2, f));
        }
    }
    order.sort_unstable_by(|a, b| a.0.total_cmp(&b.0).then(a.1.cmp(&b.1)));
    for (lb2, f) in order {
        consider(surface, f, lb2, x, None, &mut sel);
    }
    sel.into_winner().map(|c| (c.facet, c.projection))
}

/// Whether two bounding boxes come within `margin` of each other along every
/// axis (equivalently: one box grown by `margin` on all sides overlaps the
/// other). Bodies whose (slave, master) boxes do not need no search at all.
/// An empty box `(+∞, −∞)` overlaps nothing; a NaN anywhere answers `true`,
/// the safe side (the search then runs and copes).
pub fn boxes_overlap(a: ([f64; 3], [f64; 3]), b: ([f64; 3], [f64; 3]), margin: f64) -> bool {
    // Comparisons with NaN are false, so NaN never counts as separated.
    let separated = |i: usize| a.0[i] - margin > b.1[i] || b.0[i] - margin > a.1[i];
    !(0..3).any(separated)
}

/// Bounding box of the finite points (non-finite ones are skipped); `None`
/// if there are none.
pub fn points_bounding_box(points: &[[f64; 3]]) -> Option<([f64; 3], [f64; 3])> {
    points_bounding_box_of(points.iter().copied())
}

/// A box that holds the whole facet with nodes `x` (finite ones; empty if
/// none): the nodes' box for a first-order facet (flat or bilinear, so
/// inside its corners' hull). A quadratic facet can bulge past its nodes
/// (an edge whose mid-side node sits off-centre overshoots its end node),
/// so its box is that of its Bézier control points, which hold the facet
/// (convex-hull property): on each edge with ends `a`, `b` and mid-side
/// node `m` the control point `2m − (a + b)/2`; on quad8 / quad9 the
/// surface is the biquadratic one through the nine nodes (quad8's centre
/// is its value `−¼ Σ corners + ½ Σ mid-sides` there), whose centre
/// control point is `4c − Σ mid-sides + ¼ Σ corners`.
pub fn facet_box(facet_type: FacetType, x: &[[f64; 3]]) -> Aabb {
    let pts = x.iter().copied();
    if facet_type.is_linear() || x.len() != facet_type.nodes() {
        return points_bounding_box_of(pts).unwrap_or(EMPTY_BOX);
    }
    let corners = facet_type.corners();
    let lin = |a: [f64; 3], ca: f64, b: [f64; 3], cb: f64| [0, 1, 2].map(|i| ca * a[i] + cb * b[i]);
    let mut control = [[0.0; 3]; MAX_FACET_NODES];
    control[..corners].copy_from_slice(&x[..corners]);
    for k in 0..corners {
        let (a, b, m) = (x[k], x[(k + 1) % corners], x[corners + k]);
        control[corners + k] = lin(m, 2.0, lin(a, 0.5, b, 0.5), -1.0);
    }
    let mut n = 2 * corners;
    if facet_type.linear() == FacetType::Quad4 {
        let sum = |r: std::ops::Range<usize>| {
            x[r].iter()
                .fold([0.0; 3], |s, p| [0, 1, 2].map(|i| s[i] + p[i]))
        };
        let (sc, sm) = (sum(0..4), sum(4..8));
        let centre = if x.len() == 9 {
            x[8]
        } else {
            lin(sc, -0.25, sm, 0.5)
        };
        control[8] = [0, 1, 2].map(|i| 4.0 * centre[i] - sm[i] + 0.25 * sc[i]);
        n = 9;
    }
    points_bounding_box_of(control[..n].iter().copied()).unwrap_or(EMPTY_BOX)
}

fn points_bounding_box_of(points: impl Iterator<Item = [f64; 3]>) -> Option<Aabb> {
    let mut b = EMPTY_BOX;
    let mut any = false;
    for p in points.filter(|p| is_finite3(*p)) {
        for (i, v) in p.into_iter().enumerate() {
            b.0[i] = b.0[i].min(v);
            b.1[i] = b.1[i].max(v);
        }
        any = true;
    }
    any.then_some(b)
}

// ---------------------------------------------------------------------------
// Small vector helpers

fn is_finite3(p: [f64; 3]) -> bool {
    p.iter().all(|v| v.is_finite())
}

fn is_finite2(p: [f64; 2]) -> bool {
    p.iter().all(|v| v.is_finite())
}

/// Squared distance from `x` to a box (0 inside, +∞ for the empty box).
/// Squared, so the hot loops compare without a square root.
fn box_distance2(b: &Aabb, x: [f64; 3]) -> f64 {
    let gap2 = |((lo, hi), v): ((&f64, &f64), &f64)| {
        let g = (lo - v).max(v - hi).max(0.0);
        g * g
    };
    b.0.iter().zip(&b.1).zip(&x).map(gap2).sum::<f64>()
}

//! Contact search: which master facet, and which point on it, a slave point
//! sees (DESIGN §2 "Search", seed "Contact Search").
//!
//! Two stages, as in the seed:
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

use crate::contact::projection::{project, Projection};
use crate::fem::FacetType;
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

/// A master surface in its current configuration: node positions and facets
/// (indices into `positions`).
#[derive(Debug, Clone, Copy)]
pub struct MasterSurface<'a> {
    pub facet_type: FacetType,
    pub positions: &'a [[f64; 3]],
    /// Tri3 uses the first 3 entries.
    pub facets: &'a [[u32; 4]],
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
    pub fn build(surface: &MasterSurface) -> Self {
        let facets = usable_facets(surface);
        let used = used_nodes(surface, &facets);
        let bbox = points_bounding_box_of(used.iter().map(|&n| surface.positions[n as usize]))
            .unwrap_or(EMPTY_BOX);
        let grid = if used.is_empty() {
            Grid::single_cell()
        } else {
            let cap = CELLS_PER_NODE
                .saturating_mul(used.len())
                .saturating_add(MIN_CELLS);
            Grid::new(bbox, mean_edge_length(&facets), cap)
        };
        let n_cells = grid.n_cells();

        let node_pairs: Vec<(usize, u32)> = used
            .iter()
            .map(|&n| (grid.index(grid.cell_of(surface.positions[n as usize])), n))
            .collect();
        let cell_nodes = Rows::build(n_cells, &node_pairs);
        let cell_node_pos = cell_nodes
            .items
            .iter()
            .map(|&n| surface.positions[n as usize])
            .collect();

        let mut facet_box = vec![EMPTY_BOX; surface.facets.len()];
        let mut facet_pairs = Vec::new();
        let mut node_pairs = Vec::new();
        let mut max_size: f64 = 0.0;
        for f in &facets {
            let b = points_bounding_box_of(f.nodes[..f.k].iter().copied()).unwrap_or(EMPTY_BOX);
            let size = facet_size(&f.nodes[..f.k]);
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
    pub fn closest_node(&self, surface: &MasterSurface, x: [f64; 3]) -> Option<(u32, f64)> {
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
    pub fn find(&self, surface: &MasterSurface, x: [f64; 3], max_distance: f64) -> Option<Found> {
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
        surface: &MasterSurface,
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

    fn matches(&self, surface: &MasterSurface) -> bool {
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
    fn search_ring(&self, surface: &MasterSurface, node: u32, x: [f64; 3], sel: &mut Selection) {
        let ring = self.node_facets.row(node as usize);
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
    fn sweep_near_facets(&self, surface: &MasterSurface, x: [f64; 3], sel: &mut Selection) {
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
        surface: &MasterSurface,
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
        let ring = self.node_facets.row(node as usize);
        let extra = (!ring.contains(&chosen)).then_some(&chosen);
        let seeds = ring.iter().chain(extra);
        let mut rows: [&[u32]; RING_BUF + 1] = [&[]; RING_BUF + 1];
        if ring.len() + 1 > rows.len() {
            // A huge ring: sort the lot instead.
            let mut patch: Vec<u32> = seeds
                .flat_map(|&f| self.facet_neighbours.row(f as usize))
                .copied()
                .collect();
            patch.sort_unstable();
            patch.dedup();
            return patch;
        }
        let mut n = 0;
        for &f in seeds {
            rows[n] = self.facet_neighbours.row(f as usize);
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
    surface: &MasterSurface,
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
        let Some(b) = points_bounding_box_of(nodes.iter().copied()) else {
            continue;
        };
        let lb2 = box_distance2(&b, x);
        let reach = sel.best + PRUNE_REL * facet_size(nodes);
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
// Facets

/// A facet whose node ids are in range and whose coordinates are finite.
struct UsableFacet {
    id: u32,
    ids: [u32; 4],
    nodes: [[f64; 3]; 4],
    k: usize,
}

fn facet_nodes(surface: &MasterSurface, f: u32) -> Option<UsableFacet> {
    let k = surface.facet_type.nodes();
    let ids = *surface.facets.get(f as usize)?;
    let mut nodes = [[0.0; 3]; 4];
    for (slot, &n) in nodes.iter_mut().zip(&ids[..k]) {
        let p = *surface.positions.get(n as usize)?;
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
fn usable_facets(surface: &MasterSurface) -> Vec<UsableFacet> {
    let n = surface.facets.len().min(u32::MAX as usize);
    (0..n as u32)
        .filter_map(|f| facet_nodes(surface, f))
        .collect()
}

/// Nodes of usable facets, ascending. Only these are searched: a node on no
/// facet has no facet to project onto.
fn used_nodes(surface: &MasterSurface, facets: &[UsableFacet]) -> Vec<u32> {
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
fn facet_neighbours(surface: &MasterSurface, node_facets: &Rows) -> Rows {
    let k = surface.facet_type.nodes();
    let mut start = Vec::with_capacity(surface.facets.len() + 1);
    let mut items = Vec::new();
    start.push(0);
    for (f, conn) in surface.facets.iter().enumerate() {
        // Usable facets are exactly those listed at their nodes.
        let usable = u32::try_from(f)
            .is_ok_and(|id| node_facets.row(conn[0] as usize).binary_search(&id).is_ok());
        if usable {
            let mut rows: [&[u32]; 4] = [&[]; 4];
            for (row, &n) in rows.iter_mut().zip(&conn[..k]) {
                *row = node_facets.row(n as usize);
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
fn merge_sorted_unique(lists: &mut [&[u32]], out: &mut Vec<u32>) {
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

fn mean_edge_length(facets: &[UsableFacet]) -> f64 {
    let (sum, count) = facets.iter().fold((0.0, 0usize), |(s, c), f| {
        let x = &f.nodes[..f.k];
        let edges = (0..f.k).map(|i| distance(x[i], x[(i + 1) % f.k]));
        (s + edges.sum::<f64>(), c + f.k)
    });
    sum / count.max(1) as f64
}

/// Longest edge: the length scale for the tie and pruning tolerances.
fn facet_size(x: &[[f64; 3]]) -> f64 {
    (0..x.len())
        .map(|i| distance2(x[i], x[(i + 1) % x.len()]))
        .fold(0.0, f64::max)
        .sqrt()
}

/// Distance from `x` to the facet's boundary edges (straight for both tri3
/// and the bilinear quad4): where the clamped projection of a point lies
/// that projects outside a flat facet.
fn boundary_distance(x: &[[f64; 3]], p: [f64; 3]) -> f64 {
    (0..x.len())
        .map(|i| segment_distance(x[i], x[(i + 1) % x.len()], p))
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

// ---------------------------------------------------------------------------
// Selection among projected facets

struct Candidate {
    facet: u32,
    distance: f64,
    valid: bool,
    tie: f64,
    projection: Projection,
}

/// The facets projected so far for one query: the smallest distance, the
/// ids looked at (so none is projected twice) and the candidates that can
/// still win. Kept off the heap in the common case (one candidate, a few
/// ids), since `find` runs once per slave point.
struct Selection {
    best: f64,
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
    fn new() -> Self {
        Selection {
            best: f64::INFINITY,
            seen: [0; SEEN_BUF],
            n_seen: 0,
            first: None,
            rest: Vec::new(),
        }
    }

    fn contains(&self, facet: u32) -> bool {
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
    fn into_winner(self) -> Option<Candidate> {
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
fn consider(
    surface: &MasterSurface,
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
    let size = facet_size(nodes);
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
        boundary_distance(nodes, x)
    };
    sel.push(Candidate {
        facet: f,
        distance,
        valid,
        tie: TIE_REL * size,
        projection,
    });
}

// ---------------------------------------------------------------------------
// Grid

/// A uniform grid of cubic cells over a bounding box.
#[derive(Debug, Clone)]
struct Grid {
    origin: [f64; 3],
    cell: f64,
    inv: f64,
    dims: [usize; 3],
}

impl Grid {
    fn single_cell() -> Self {
        Grid {
            origin: [0.0; 3],
            cell: 1.0,
            inv: 1.0,
            dims: [1; 3],
        }
    }

    /// Cells of about `target` size (grown until at most `max_cells`).
    fn new(bbox: Aabb, target: f64, max_cells: usize) -> Self {
        let extent = [0, 1, 2].map(|a| bbox.1[a] - bbox.0[a]);
        let largest = extent.iter().copied().fold(0.0, f64::max);
        let mut cell = if target > 0.0 && target.is_finite() {
            target
        } else if largest > 0.0 && largest.is_finite() {
            largest
        } else {
            1.0
        };
        let cells_along = |cell: f64| extent.map(|e| (e / cell).floor() + 1.0);
        // Each round shrinks the cell count by at least the excess factor,
        // so a handful of rounds suffice; the bound only guards absurd
        // coordinates (an infinite extent), which end in one cell.
        let mut rounds = 0;
        loop {
            let n = cells_along(cell);
            let total = n[0] * n[1] * n[2];
            if total <= max_cells as f64 {
                break;
            }
            rounds += 1;
            if rounds > 64 || (!total.is_finite() && rounds > 8) {
                return Grid {
                    origin: bbox.0,
                    cell: if largest.is_finite() {
                        largest.max(1.0)
                    } else {
                        f64::MAX
                    },
                    inv: 0.0,
                    dims: [1; 3],
                };
            }
            cell *= (total / max_cells as f64).cbrt().clamp(1.01, 1e6);
        }
        Grid {
            origin: bbox.0,
            cell,
            inv: 1.0 / cell,
            dims: cells_along(cell).map(|n| n as usize),
        }
    }

    fn n_cells(&self) -> usize {
        self.dims[0] * self.dims[1] * self.dims[2]
    }

    fn index(&self, c: [usize; 3]) -> usize {
        (c[2] * self.dims[1] + c[1]) * self.dims[0] + c[0]
    }

    /// Position along `axis` in cell units from the origin, not floored.
    /// Bucketing and range queries both go through it and `clamp`, which
    /// are monotone in `v`: that is what makes them agree.
    fn coord(&self, v: f64, axis: usize) -> f64 {
        (v - self.origin[axis]) * self.inv
    }

    /// Cell index from `coord`, clamped into the grid. Truncation is the
    /// floor for `t ≥ 0`, and smaller `t` (or NaN from absurd coordinates)
    /// clamps to 0 anyway, so no `floor` call (a library call on baseline
    /// x86-64) is needed.
    fn clamp(&self, t: f64, axis: usize) -> usize {
        if t >= 0.0 {
            (t as usize).min(self.dims[axis] - 1)
        } else {
            0
        }
    }

    /// The cell holding `p`, or the nearest cell when `p` is outside.
    fn cell_of(&self, p: [f64; 3]) -> [usize; 3] {
        [
            self.clamp(self.coord(p[0], 0), 0),
            self.clamp(self.coord(p[1], 1), 1),
            self.clamp(self.coord(p[2], 2), 2),
        ]
    }

    /// Inclusive cell ranges meeting the box `[lo, hi]`; `None` if the box
    /// misses the grid.
    fn cell_range(&self, lo: [f64; 3], hi: [f64; 3]) -> Option<[[usize; 2]; 3]> {
        let mut range = [[0; 2]; 3];
        for (a, r) in range.iter_mut().enumerate() {
            let (l, h) = (self.coord(lo[a], a), self.coord(hi[a], a));
            if h < 0.0 || l >= self.dims[a] as f64 {
                return None;
            }
            *r = [self.clamp(l, a), self.clamp(h, a)];
        }
        Some(range)
    }

    /// Squared gap along `axis` between `v` and cell `c`'s extent.
    fn gap2(&self, axis: usize, c: usize, v: f64) -> f64 {
        let lo = self.origin[axis] + c as f64 * self.cell;
        let g = (lo - v).max(v - lo - self.cell).max(0.0);
        g * g
    }

    /// Squared gaps along each axis between `x` and the grid's extent.
    fn outside_gap2(&self, x: [f64; 3]) -> [f64; 3] {
        let (lo, hi) = self.bounds();
        [0, 1, 2].map(|a| {
            let g = (lo[a] - x[a]).max(x[a] - hi[a]).max(0.0);
            g * g
        })
    }

    /// [`Grid::for_each_cell`] restricted to the cells within distance `r`
    /// of `x` (with the grid's rounding slack), skipping whole rows at once.
    fn for_each_cell_within(
        &self,
        range: [[usize; 2]; 3],
        x: [f64; 3],
        r: f64,
        mut f: impl FnMut(usize),
    ) {
        let reach = r + GRID_PAD_REL * self.cell;
        let r2 = reach * reach;
        for l in range[2][0]..=range[2][1] {
            let gap_z = self.gap2(2, l, x[2]);
            if gap_z > r2 {
                continue;
            }
            for j in range[1][0]..=range[1][1] {
                let gap_yz = gap_z + self.gap2(1, j, x[1]);
                if gap_yz > r2 {
                    continue;
                }
                for i in range[0][0]..=range[0][1] {
                    if gap_yz + self.gap2(0, i, x[0]) <= r2 {
                        f(self.index([i, j, l]));
                    }
                }
            }
        }
    }

    fn for_each_cell(&self, range: [[usize; 2]; 3], mut f: impl FnMut(usize)) {
        for l in range[2][0]..=range[2][1] {
            for j in range[1][0]..=range[1][1] {
                for i in range[0][0]..=range[0][1] {
                    f(self.index([i, j, l]));
                }
            }
        }
    }

    fn bounds(&self) -> Aabb {
        let hi = [0, 1, 2].map(|a| self.origin[a] + self.dims[a] as f64 * self.cell);
        (self.origin, hi)
    }

    /// Lower bound on the squared distance from `x` to any cell not yet visited
    /// after shells `0..=k` around `c0` (the cells outside the box
    /// `c0 ± k`); `None` once every cell is visited. Each side of the box
    /// that does not reach the grid's edge leaves a slab of the grid beyond
    /// it; the distance to the nearest such slab is the bound (using the
    /// grid's full extent on the other axes, which keeps the bound tight for
    /// points far outside the grid). `outside2` is [`Self::outside_gap2`].
    fn unvisited_distance2(
        &self,
        c0: [usize; 3],
        k: usize,
        x: [f64; 3],
        outside2: [f64; 3],
    ) -> Option<f64> {
        let total: f64 = outside2.iter().sum();
        let (grid_lo, grid_hi) = self.bounds();
        let mut bound: Option<f64> = None;
        for (a, (&c, &n)) in c0.iter().zip(&self.dims).enumerate() {
            // The slab's gap replaces the grid's gap along its own axis.
            let others = total - outside2[a];
            let mut take = |gap: f64| {
                let d = others + gap.max(0.0).powi(2);
                bound = Some(bound.map_or(d, |b| b.min(d)));
            };
            if c + k + 1 < n {
                let start = self.origin[a] + (c + k + 1) as f64 * self.cell;
                take((start - x[a]).max(x[a] - grid_hi[a]));
            }
            if c > k {
                let end = self.origin[a] + (c - k) as f64 * self.cell;
                take((x[a] - end).max(grid_lo[a] - x[a]));
            }
        }
        bound
    }
}

/// Compressed rows: the items of row `r` are `items[start[r]..start[r + 1]]`.
#[derive(Debug, Clone)]
struct Rows {
    start: Vec<usize>,
    items: Vec<u32>,
}

impl Rows {
    /// Counting sort of `(row, item)` pairs; stable, so items keep the order
    /// of `pairs` within a row. Rows out of range are dropped.
    fn build(n_rows: usize, pairs: &[(usize, u32)]) -> Self {
        let mut start = vec![0usize; n_rows + 1];
        for &(r, _) in pairs.iter().filter(|(r, _)| *r < n_rows) {
            start[r + 1] += 1;
        }
        for r in 0..n_rows {
            start[r + 1] += start[r];
        }
        let mut next = start.clone();
        let mut items = vec![0u32; start[n_rows]];
        for &(r, item) in pairs.iter().filter(|(r, _)| *r < n_rows) {
            items[next[r]] = item;
            next[r] += 1;
        }
        Rows { start, items }
    }

    fn range(&self, r: usize) -> std::ops::Range<usize> {
        match (self.start.get(r), self.start.get(r + 1)) {
            (Some(&a), Some(&b)) => a..b,
            _ => 0..0,
        }
    }

    fn row(&self, r: usize) -> &[u32] {
        &self.items[self.range(r)]
    }
}

/// Running nearest node: smaller squared distance wins, equal distance goes
/// to the smaller id. Works on squared distances so scanning needs no square
/// root; `limit2` (the best distance plus the grid slack, squared) is only
/// recomputed when the best improves.
struct NearestNode {
    id: u32,
    d2: f64,
    pad: f64,
    limit2: f64,
}

impl NearestNode {
    fn new(pad: f64) -> Self {
        NearestNode {
            id: u32::MAX,
            d2: f64::INFINITY,
            pad,
            limit2: f64::INFINITY,
        }
    }

    fn offer(&mut self, id: u32, d2: f64) {
        if d2 < self.d2 || (d2 == self.d2 && id < self.id) {
            self.id = id;
            self.d2 = d2;
            let reach = d2.sqrt() + self.pad;
            self.limit2 = reach * reach;
        }
    }

    /// Whether a cell at squared box distance `box2` may hold a node as close
    /// as the best (ties included, for the smaller id).
    fn may_hold(&self, box2: f64) -> bool {
        box2 <= self.limit2
    }

    /// Whether the best is strictly closer than anything at squared distance
    /// `bound2` or beyond, slack included. Equal distance could still hide a
    /// smaller id, so that does not count.
    fn beats(&self, bound2: f64) -> bool {
        let reach = bound2.sqrt() - self.pad;
        reach > 0.0 && self.d2 < reach * reach
    }

    fn result(&self) -> Option<(u32, f64)> {
        (self.d2.is_finite()).then(|| (self.id, self.d2.sqrt()))
    }
}

// ---------------------------------------------------------------------------
// Small vector helpers

fn is_finite3(p: [f64; 3]) -> bool {
    p.iter().all(|v| v.is_finite())
}

fn is_finite2(p: [f64; 2]) -> bool {
    p.iter().all(|v| v.is_finite())
}

fn sub(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}

fn dot(a: [f64; 3], b: [f64; 3]) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

fn distance2(a: [f64; 3], b: [f64; 3]) -> f64 {
    let d = sub(a, b);
    dot(d, d)
}

fn distance(a: [f64; 3], b: [f64; 3]) -> f64 {
    distance2(a, b).sqrt()
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

#[cfg(test)]
mod tests {
    use super::*;
    use crate::fem::test_util::Lcg;

    type Mesh = (Vec<[f64; 3]>, Vec<[u32; 4]>);

    fn surface<'a>(facet_type: FacetType, mesh: &'a Mesh) -> MasterSurface<'a> {
        MasterSurface {
            facet_type,
            positions: &mesh.0,
            facets: &mesh.1,
        }
    }

    /// Uniform in [0, 1).
    fn unit(rng: &mut Lcg) -> f64 {
        0.5 * (rng.next() + 1.0)
    }

    /// `nx × ny` cells of size `h` in the xy plane, node (i, j) at
    /// `(i h, j h, z(i h, j h))` plus in-plane jitter; quads counter-clockwise
    /// seen from +z, or each quad split into two triangles (alternating
    /// diagonals).
    fn plane_grid(
        nx: usize,
        ny: usize,
        h: f64,
        jitter: f64,
        z: impl Fn(f64, f64) -> f64,
        tri: bool,
        rng: &mut Lcg,
    ) -> Mesh {
        let mut pos = Vec::new();
        for j in 0..=ny {
            for i in 0..=nx {
                let on_rim = i == 0 || j == 0 || i == nx || j == ny;
                let (dx, dy) = if on_rim {
                    (0.0, 0.0)
                } else {
                    (jitter * h * rng.next(), jitter * h * rng.next())
                };
                let (x, y) = (i as f64 * h + dx, j as f64 * h + dy);
                pos.push([x, y, z(x, y)]);
            }
        }
        let node = |i: usize, j: usize| (j * (nx + 1) + i) as u32;
        let mut facets = Vec::new();
        for j in 0..ny {
            for i in 0..nx {
                let (a, b, c, d) = (
                    node(i, j),
                    node(i + 1, j),
                    node(i + 1, j + 1),
                    node(i, j + 1),
                );
                if !tri {
                    facets.push([a, b, c, d]);
                } else if (i + j) % 2 == 0 {
                    facets.push([a, b, c, 0]);
                    facets.push([a, c, d, 0]);
                } else {
                    facets.push([a, b, d, 0]);
                    facets.push([b, c, d, 0]);
                }
            }
        }
        (pos, facets)
    }

    /// Open cylinder of radius `r` around the z axis, outward normals.
    fn cylinder(n_theta: usize, n_z: usize, r: f64, length: f64) -> Mesh {
        let mut pos = Vec::new();
        for j in 0..=n_z {
            for i in 0..n_theta {
                let t = 2.0 * std::f64::consts::PI * i as f64 / n_theta as f64;
                pos.push([r * t.cos(), r * t.sin(), length * j as f64 / n_z as f64]);
            }
        }
        let node = |i: usize, j: usize| (j * n_theta + i % n_theta) as u32;
        let mut facets = Vec::new();
        for j in 0..n_z {
            for i in 0..n_theta {
                facets.push([
                    node(i, j),
                    node(i + 1, j),
                    node(i + 1, j + 1),
                    node(i, j + 1),
                ]);
            }
        }
        (pos, facets)
    }

    struct Brute {
        facet: u32,
        distance: f64,
        valid: bool,
    }

    /// Reference inner search: every facet of the surface projected, then the
    /// selection rule of the module doc written out directly.
    fn brute_force(s: &MasterSurface, facets: &[u32], x: [f64; 3]) -> Option<Brute> {
        let mut all = Vec::new();
        for &f in facets {
            let Some(conn) = s.facets.get(f as usize) else {
                continue;
            };
            let k = s.facet_type.nodes();
            let Some(nodes) = conn[..k]
                .iter()
                .map(|&n| s.positions.get(n as usize).copied())
                .collect::<Option<Vec<_>>>()
            else {
                continue;
            };
            let p = project(s.facet_type, &nodes, x, None);
            let valid = p.converged && p.outside <= INSIDE_TOL;
            let d = if valid {
                distance(x, p.point)
            } else {
                boundary_distance(&nodes, x)
            };
            all.push((f, d, valid, facet_size(&nodes)));
        }
        let dmin = all.iter().map(|a| a.1).fold(f64::INFINITY, f64::min);
        all.iter()
            .filter(|a| a.1 <= dmin + TIE_REL * a.3)
            .min_by_key(|a| (!a.2, a.0))
            .map(|a| Brute {
                facet: a.0,
                distance: a.1,
                valid: a.2,
            })
    }

    fn all_facets(s: &MasterSurface) -> Vec<u32> {
        (0..s.facets.len() as u32).collect()
    }

    fn ring_of(s: &MasterSurface, node: u32) -> Vec<u32> {
        let k = s.facet_type.nodes();
        (0..s.facets.len() as u32)
            .filter(|&f| s.facets[f as usize][..k].contains(&node))
            .collect()
    }

    fn closest_node_brute(s: &MasterSurface, x: [f64; 3]) -> Option<(u32, f64)> {
        let k = s.facet_type.nodes();
        let mut best: Option<(u32, f64)> = None;
        for (n, p) in s.positions.iter().enumerate() {
            let on_facet = s.facets.iter().any(|f| f[..k].contains(&(n as u32)));
            if !on_facet {
                continue;
            }
            let d = distance(*p, x);
            if best.is_none_or(|(_, bd)| d < bd) {
                best = Some((n as u32, d));
            }
        }
        best
    }

    /// Runs `find` against the brute force for `n` random points from
    /// `sample`; returns how often the winner was not around the closest
    /// node (so a test can insist the exactness sweep was exercised).
    fn check_find_against_brute(
        s: &MasterSurface,
        n: usize,
        rng: &mut Lcg,
        mut sample: impl FnMut(&mut Lcg) -> [f64; 3],
    ) -> usize {
        let index = SearchIndex::build(s);
        let facets = all_facets(s);
        let mut outside_ring = 0;
        for q in 0..n {
            let x = sample(rng);
            let found = index.find(s, x, f64::INFINITY).expect("non-empty surface");
            let brute = brute_force(s, &facets, x).unwrap();
            assert_eq!(
                found.facet, brute.facet,
                "query {q} x={x:?}: find {found:?}, brute facet {} d {} valid {}",
                brute.facet, brute.distance, brute.valid
            );
            let (node, _) = closest_node_brute(s, x).unwrap();
            assert_eq!(found.closest_node, node, "query {q}");
            if !ring_of(s, node).contains(&found.facet) {
                outside_ring += 1;
            }
            check_patch(s, &found);
        }
        outside_ring
    }

    /// The patch is sorted, unique, holds the facet and every facet sharing
    /// a node with it, and is exactly the 2-ring of the closest node plus the
    /// chosen facet's neighbours.
    fn check_patch(s: &MasterSurface, found: &Found) {
        let k = s.facet_type.nodes();
        let p = &found.patch;
        assert!(p.windows(2).all(|w| w[0] < w[1]), "patch not sorted/unique");
        assert!(p.contains(&found.facet));
        let mut expect = Vec::new();
        let mut seeds = ring_of(s, found.closest_node);
        seeds.push(found.facet);
        for f in seeds {
            for &n in &s.facets[f as usize][..k] {
                expect.extend(ring_of(s, n));
            }
        }
        expect.sort_unstable();
        expect.dedup();
        assert_eq!(p, &expect);
        for &n in &s.facets[found.facet as usize][..k] {
            for f in ring_of(s, n) {
                assert!(p.contains(&f), "neighbour {f} missing");
            }
        }
    }

    #[test]
    fn closest_node_equals_brute_force_on_random_clouds() {
        let mut rng = Lcg::new(11);
        // Uniform cloud of triangles, one stray node on no facet.
        let mut pos: Vec<[f64; 3]> = (0..600)
            .map(|_| {
                [
                    10.0 * unit(&mut rng),
                    10.0 * unit(&mut rng),
                    10.0 * unit(&mut rng),
                ]
            })
            .collect();
        let facets: Vec<[u32; 4]> = (0..200).map(|i| [3 * i, 3 * i + 1, 3 * i + 2, 0]).collect();
        pos.push([5.0, 5.0, 5.0]);
        let uniform = (pos, facets);
        // Strongly clustered cloud: most nodes in a tiny ball, a few spread
        // wide, so the grid is capped and cells are very uneven.
        let mut pos: Vec<[f64; 3]> = (0..450)
            .map(|_| {
                [
                    1.0 + 0.01 * rng.next(),
                    1.0 + 0.01 * rng.next(),
                    1.0 + 0.01 * rng.next(),
                ]
            })
            .collect();
        pos.extend((0..150).map(|_| {
            [
                100.0 * unit(&mut rng),
                100.0 * unit(&mut rng),
                100.0 * unit(&mut rng),
            ]
        }));
        let facets: Vec<[u32; 4]> = (0..200).map(|i| [i, i + 200, i + 400, 0]).collect();
        let clustered = (pos, facets);
        for (mesh, scale) in [(&uniform, 10.0), (&clustered, 100.0)] {
            let s = surface(FacetType::Tri3, mesh);
            let index = SearchIndex::build(&s);
            for q in 0..1000 {
                let x = match q % 10 {
                    // Far outside, including along one axis only.
                    0 => rng.vec3(1e4),
                    1 => [0.5 * scale, 0.5 * scale, 1e3 * scale * rng.next()],
                    // Exactly on a node.
                    2 => mesh.0[q % 600],
                    _ => [
                        scale * (1.5 * rng.next() + 0.5),
                        scale * (1.5 * rng.next() + 0.5),
                        scale * (1.5 * rng.next() + 0.5),
                    ],
                };
                let got = index.closest_node(&s, x);
                let want = closest_node_brute(&s, x);
                assert_eq!(got.map(|g| g.0), want.map(|w| w.0), "query {q} x={x:?}");
                assert_eq!(got.unwrap().1, want.unwrap().1);
            }
        }
    }

    #[test]
    fn closest_node_ties_go_to_smaller_id() {
        // Node 4 duplicates node 1; a query midway between nodes 0 and 1.
        let mesh: Mesh = (
            vec![
                [0.0, 0.0, 0.0],
                [1.0, 0.0, 0.0],
                [0.0, 1.0, 0.0],
                [1.0, 1.0, 0.0],
                [1.0, 0.0, 0.0],
            ],
            vec![[4, 3, 2, 0], [0, 1, 2, 0]],
        );
        let s = surface(FacetType::Tri3, &mesh);
        let index = SearchIndex::build(&s);
        assert_eq!(index.closest_node(&s, [1.0, 0.0, 0.3]).unwrap().0, 1);
        assert_eq!(index.closest_node(&s, [0.5, -0.2, 0.0]).unwrap().0, 0);
        // Equidistant from all four corners.
        assert_eq!(index.closest_node(&s, [0.5, 0.5, 0.0]).unwrap().0, 0);
    }

    #[test]
    fn find_equals_brute_force_flat_quad_grid() {
        let mut rng = Lcg::new(21);
        let mesh = plane_grid(16, 12, 1.0, 0.0, |_, _| 0.0, false, &mut rng);
        let s = surface(FacetType::Quad4, &mesh);
        check_find_against_brute(&s, 1000, &mut rng, |r| {
            [17.0 * unit(r) - 0.5, 13.0 * unit(r) - 0.5, 0.6 * r.next()]
        });
    }

    #[test]
    fn find_equals_brute_force_warped_quad_grid() {
        let mut rng = Lcg::new(22);
        let z = |x: f64, y: f64| 0.8 * (0.5 * x).sin() * (0.4 * y).cos();
        let mesh = plane_grid(14, 14, 1.0, 0.3, z, false, &mut rng);
        // Graded (neighbouring columns and rows differ in width by up to a
        // factor 3) and non-planar quads.
        let mut mesh = mesh;
        let grade = |v: f64| v + 0.3 * (std::f64::consts::PI * v).sin();
        for p in mesh.0.iter_mut() {
            let (x, y) = (grade(p[0]), grade(p[1]));
            *p = [x, y, z(x, y) + 0.1 * rng.next()];
        }
        let s = surface(FacetType::Quad4, &mesh);
        let outside_ring = check_find_against_brute(&s, 1000, &mut rng, |r| {
            let (x, y) = (15.0 * unit(r) - 0.5, 15.0 * unit(r) - 0.5);
            [x, y, z(x, y) + 0.6 * r.next()]
        });
        // The distorted mesh must produce winners away from the closest
        // node, or this test would not exercise the exactness sweep.
        eprintln!("warped quads: {outside_ring} winners away from the closest node");
        assert!(outside_ring > 0, "sweep never needed");
    }

    #[test]
    fn find_equals_brute_force_triangulated_grid() {
        let mut rng = Lcg::new(23);
        let z = |x: f64, y: f64| 0.3 * (0.7 * x + 0.2 * y).sin();
        let mesh = plane_grid(12, 12, 1.0, 0.25, z, true, &mut rng);
        let s = surface(FacetType::Tri3, &mesh);
        let outside_ring = check_find_against_brute(&s, 1000, &mut rng, |r| {
            let (x, y) = (13.0 * unit(r) - 0.5, 13.0 * unit(r) - 0.5);
            [x, y, z(x, y) + 0.6 * r.next()]
        });
        assert!(outside_ring > 0, "sweep never needed");
    }

    #[test]
    fn find_equals_brute_force_cylinder() {
        let mut rng = Lcg::new(24);
        let mesh = cylinder(24, 10, 10.0, 20.0);
        let s = surface(FacetType::Quad4, &mesh);
        check_find_against_brute(&s, 1000, &mut rng, |r| {
            let t = std::f64::consts::PI * r.next();
            let rad = 10.0 + 5.0 * r.next();
            [rad * t.cos(), rad * t.sin(), 22.0 * unit(r) - 1.0]
        });
    }

    #[test]
    fn find_many_equals_find() {
        let mut rng = Lcg::new(26);
        let z = |x: f64, y: f64| 0.4 * (0.5 * x).sin() * (0.4 * y).cos();
        let mesh = plane_grid(12, 9, 1.0, 0.3, z, true, &mut rng);
        let s = surface(FacetType::Tri3, &mesh);
        let index = SearchIndex::build(&s);
        let mut points: Vec<[f64; 3]> = (0..500)
            .map(|_| {
                let (x, y) = (14.0 * unit(&mut rng) - 1.0, 11.0 * unit(&mut rng) - 1.0);
                [x, y, z(x, y) + 0.8 * rng.next()]
            })
            .collect();
        points.push([f64::NAN, 0.0, 0.0]);
        points.push([1e5, -1e5, 3.0]);
        let many = index.find_many(&s, &points, 1.0);
        assert_eq!(many.len(), points.len());
        for (p, m) in points.iter().zip(&many) {
            let one = index.find(&s, *p, 1.0);
            assert_eq!(
                one.as_ref().map(|f| (f.facet, f.closest_node, &f.patch)),
                m.as_ref().map(|f| (f.facet, f.closest_node, &f.patch))
            );
            assert_eq!(
                one.map(|f| f.projection.xi),
                m.as_ref().map(|f| f.projection.xi)
            );
        }
        assert!(many[500].is_none() && many[501].is_none());
        assert!(many.iter().filter(|m| m.is_some()).count() > 400);
    }

    #[test]
    fn large_ring_fan() {
        // 40 triangles around node 0 (more than the stack buffers hold),
        // a cone so the facets are not coplanar.
        let n = 40;
        let mut pos = vec![[0.0, 0.0, 1.0]];
        for i in 0..n {
            let t = 2.0 * std::f64::consts::PI * i as f64 / n as f64;
            pos.push([3.0 * t.cos(), 3.0 * t.sin(), 0.0]);
        }
        let facets: Vec<[u32; 4]> = (0..n as u32)
            .map(|i| [0, 1 + i, 1 + (i + 1) % n as u32, 0])
            .collect();
        let mesh = (pos, facets);
        let s = surface(FacetType::Tri3, &mesh);
        let mut rng = Lcg::new(27);
        check_find_against_brute(&s, 300, &mut rng, |r| {
            [1.5 * r.next(), 1.5 * r.next(), 0.8 + 0.5 * r.next()]
        });
        let index = SearchIndex::build(&s);
        let f = index.find(&s, [0.0, 0.0, 1.2], 10.0).unwrap();
        assert_eq!((f.facet, f.closest_node, f.patch.len()), (0, 0, n));
        // Every facet holds the apex: the inner search alone agrees.
        let all: Vec<u32> = (0..n as u32).rev().collect();
        assert_eq!(
            select_facet(&s, &all, [0.0, 0.0, 1.0], Some((39, [0.0, 0.0])))
                .unwrap()
                .0,
            0
        );
    }

    #[test]
    fn cylinder_concave_side_picks_nearest_of_two_valid() {
        let mesh = cylinder(24, 4, 10.0, 8.0);
        let s = surface(FacetType::Quad4, &mesh);
        let index = SearchIndex::build(&s);
        let dt = 2.0 * std::f64::consts::PI / 24.0;
        // Facets 2 and 3 (first row) share the node line at angle 3 dt.
        let at = |t: f64, r: f64| [r * t.cos(), r * t.sin(), 1.0];
        for (t, want) in [(3.0 * dt, 2), (3.0 * dt - 0.01, 2), (3.0 * dt + 0.01, 3)] {
            let x = at(t, 9.0);
            // Both project validly: the situation under test.
            for f in [2u32, 3] {
                let nodes: Vec<_> = mesh.1[f as usize]
                    .iter()
                    .map(|&n| mesh.0[n as usize])
                    .collect();
                let p = project(FacetType::Quad4, &nodes, x, None);
                assert!(p.converged && p.outside <= INSIDE_TOL, "facet {f} at t={t}");
            }
            let found = index.find(&s, x, 100.0).unwrap();
            assert_eq!(found.facet, want, "t={t}");
            assert!(found.projection.outside <= INSIDE_TOL);
            assert!(found.projection.gap < 0.0, "inside the body");
        }
        // Outside over the convex edge: no facet holds the projection; the
        // edge is equally near both, so the smaller id.
        let found = index.find(&s, at(3.0 * dt, 11.0), 100.0).unwrap();
        assert_eq!(found.facet, 2);
        assert!(found.projection.outside > INSIDE_TOL);
        // Near the axis every facet of the row holds a valid projection, the
        // nearest is the one facing the point.
        let found = index.find(&s, at(5.5 * dt, 0.5), 100.0).unwrap();
        assert_eq!(found.facet, 5);
    }

    #[test]
    fn flat_master_points_across_whole_plane() {
        let mut rng = Lcg::new(25);
        let mesh = plane_grid(40, 40, 0.5, 0.0, |_, _| 2.0, false, &mut rng);
        let s = surface(FacetType::Quad4, &mesh);
        let index = SearchIndex::build(&s);
        for _ in 0..2000 {
            let (x, y, dz) = (
                20.0 * unit(&mut rng),
                20.0 * unit(&mut rng),
                0.4 * rng.next(),
            );
            let found = index.find(&s, [x, y, 2.0 + dz], 1.0).unwrap();
            let (i, j) = ((x / 0.5).floor(), (y / 0.5).floor());
            assert_eq!(found.facet, (j * 40.0 + i) as u32);
            let p = &found.projection;
            assert!(p.outside <= INSIDE_TOL);
            assert!((p.gap - dz).abs() < 1e-12);
            assert!((p.xi[0] - (4.0 * (x - 0.5 * i) - 1.0)).abs() < 1e-9);
            assert!((p.xi[1] - (4.0 * (y - 0.5 * j) - 1.0)).abs() < 1e-9);
        }
    }

    /// 4 × 4 unit quads at z = 0: facet (i, j) has id 4 j + i, node (i, j)
    /// id 5 j + i.
    fn small_flat() -> Mesh {
        plane_grid(4, 4, 1.0, 0.0, |_, _| 0.0, false, &mut Lcg::new(0))
    }

    #[test]
    fn edges_corners_and_nodes() {
        let mesh = small_flat();
        let s = surface(FacetType::Quad4, &mesh);
        let index = SearchIndex::build(&s);
        let find = |x: [f64; 3]| index.find(&s, x, 10.0).unwrap();
        // Exactly on interior node 12 = (2, 2): facets 5, 6, 9, 10 all hold
        // it at distance 0; the smallest id wins. Same above it.
        for z in [0.0, 0.5, -0.5] {
            let f = find([2.0, 2.0, z]);
            assert_eq!((f.facet, f.closest_node), (5, 12), "z={z}");
            assert!(f.projection.outside <= INSIDE_TOL);
            assert!((f.projection.gap - z).abs() < 1e-12);
        }
        // On the edge between facets 5 and 9 (y = 2), and above it.
        assert_eq!(find([1.5, 2.0, 0.0]).facet, 5);
        assert_eq!(find([1.5, 2.0, 0.3]).facet, 5);
        // Just off it on either side.
        assert_eq!(find([1.5, 2.0 + 1e-3, 0.3]).facet, 9);
        assert_eq!(find([1.5, 2.0 - 1e-3, 0.3]).facet, 5);
        // Inside a facet.
        let f = find([1.3, 1.6, 0.2]);
        assert_eq!(f.facet, 5);
        assert!(
            (f.projection.xi[0] + 0.4).abs() < 1e-12 && (f.projection.xi[1] - 0.2).abs() < 1e-12
        );
        // Beyond the outer corner and beyond the border: only clamped
        // projections exist.
        let f = find([-0.5, -0.5, 0.3]);
        assert_eq!((f.facet, f.closest_node), (0, 0));
        assert!(f.projection.outside > INSIDE_TOL);
        let f = find([-0.5, 2.0, 0.1]);
        assert_eq!(f.facet, 4, "edge shared by facets 4 and 8 at the border");
        assert!(f.projection.outside > INSIDE_TOL);
        // Corner node of the master exactly.
        assert_eq!(find([4.0, 4.0, 0.0]).facet, 15);
        // The inner search alone keeps the same ties even when it starts on
        // the larger id (the previous facet is projected first).
        let ring = [5, 6, 9, 10];
        for x in [[2.0, 2.0, 0.0], [2.0, 2.0, 0.4], [1.5, 2.0, 0.3]] {
            let (f, _) = select_facet(&s, &ring, x, Some((10, [-1.0, -1.0]))).unwrap();
            assert_eq!(f, 5, "x={x:?}");
        }
    }

    #[test]
    fn far_points_and_max_distance() {
        let mesh = small_flat();
        let s = surface(FacetType::Quad4, &mesh);
        let index = SearchIndex::build(&s);
        let far = [1e3, 2e3, 5e2];
        assert!(index.find(&s, far, 10.0).is_none());
        let f = index.find(&s, far, f64::INFINITY).unwrap();
        assert_eq!((f.facet, f.closest_node), (15, 24));
        assert!(index.find(&s, far, f64::NAN).is_none());
        // Straight above the middle of the grid, far up.
        let f = index.find(&s, [2.2, 1.7, 1e3], f64::INFINITY).unwrap();
        assert_eq!(f.closest_node, 12);
        assert_eq!(f.facet, 6);
        // max_distance limits the closest NODE: above a facet centre the
        // nodes are 0.707 away.
        assert!(index.find(&s, [1.5, 1.5, 0.0], 0.7).is_none());
        assert!(index.find(&s, [1.5, 1.5, 0.0], 0.71).is_some());
    }

    #[test]
    fn bad_input_finds_nothing_and_never_panics() {
        let mesh = small_flat();
        let s = surface(FacetType::Quad4, &mesh);
        let index = SearchIndex::build(&s);
        for x in [[f64::NAN, 0.0, 0.0], [0.0, f64::INFINITY, 0.0]] {
            assert!(index.closest_node(&s, x).is_none());
            assert!(index.find(&s, x, 1.0).is_none());
            assert!(select_facet(&s, &[0, 1], x, None).is_none());
        }
        // A surface that is not the one indexed.
        let other = small_flat();
        let short = MasterSurface {
            facets: &other.1[..3],
            ..surface(FacetType::Quad4, &other)
        };
        assert!(index.find(&short, [1.0, 1.0, 0.0], 1.0).is_none());
        let tri = surface(FacetType::Tri3, &other);
        assert!(index.find(&tri, [1.0, 1.0, 0.0], 1.0).is_none());

        // Empty surface.
        let empty: Mesh = (vec![], vec![]);
        let e = surface(FacetType::Quad4, &empty);
        let index = SearchIndex::build(&e);
        assert!(index.closest_node(&e, [0.0; 3]).is_none());
        assert!(index.find(&e, [0.0; 3], 1.0).is_none());
        assert!(!boxes_overlap(
            index.bounding_box(),
            ([-1.0; 3], [1.0; 3]),
            10.0
        ));

        // Broken facets are ignored, the good one still works.
        let mut mesh = small_flat();
        mesh.1[0] = [0, 1, 999, 5];
        mesh.1[1][2] = u32::MAX;
        mesh.0[20] = [f64::NAN, 0.0, 0.0]; // node of facet 12
        let s = surface(FacetType::Quad4, &mesh);
        let index = SearchIndex::build(&s);
        let f = index.find(&s, [0.5, 0.5, 0.1], 10.0).unwrap();
        assert!(![0, 1, 12].contains(&f.facet));
        assert!(![0, 1, 12].iter().any(|b| f.patch.contains(b)));
        assert!(index.find(&s, [0.5, 3.5, 0.1], 10.0).is_some());
        assert!(select_facet(&s, &[0, 1, 12, 77], [0.5, 0.5, 0.1], None).is_none());
        // Degenerate facet (all nodes equal) and a collapsed quad.
        let mesh: Mesh = (
            vec![[0.0; 3], [0.0; 3], [1.0, 0.0, 0.0], [1.0, 1.0, 0.0]],
            vec![[0, 1, 0, 1], [0, 2, 3, 3]],
        );
        let s = surface(FacetType::Quad4, &mesh);
        let index = SearchIndex::build(&s);
        let f = index.find(&s, [0.7, 0.2, 0.1], 10.0).unwrap();
        assert_eq!(f.facet, 1);
    }

    #[test]
    fn result_does_not_depend_on_grid_layout() {
        // The same surface with a far-away extra facet appended: different
        // bounding box and (capped) cell size, identical answers.
        let mut rng = Lcg::new(31);
        let z = |x: f64, y: f64| 0.5 * (0.6 * x).sin() * (0.3 * y).sin();
        let mesh = plane_grid(10, 10, 1.0, 0.3, z, false, &mut rng);
        let mut wide = mesh.clone();
        let base = wide.0.len() as u32;
        wide.0.extend([
            [500.0, 0.0, 300.0],
            [501.0, 0.0, 300.0],
            [501.0, 1.0, 300.0],
            [500.0, 1.0, 300.0],
        ]);
        wide.1.push([base, base + 1, base + 2, base + 3]);
        let (a, b) = (
            surface(FacetType::Quad4, &mesh),
            surface(FacetType::Quad4, &wide),
        );
        let (ia, ib) = (SearchIndex::build(&a), SearchIndex::build(&b));
        assert_ne!(ia.grid.cell, ib.grid.cell);
        for _ in 0..500 {
            let (x, y) = (11.0 * unit(&mut rng) - 0.5, 11.0 * unit(&mut rng) - 0.5);
            let p = [x, y, z(x, y) + 0.4 * rng.next()];
            let (fa, fb) = (ia.find(&a, p, 5.0).unwrap(), ib.find(&b, p, 5.0).unwrap());
            assert_eq!(
                (fa.facet, fa.closest_node, &fa.patch),
                (fb.facet, fb.closest_node, &fb.patch)
            );
            assert_eq!(fa.projection.xi, fb.projection.xi);
        }
    }

    #[test]
    fn select_facet_matches_brute_force_on_candidates() {
        let mut rng = Lcg::new(41);
        let z = |x: f64, y: f64| 0.6 * (0.5 * x).sin() * (0.5 * y).cos();
        let mesh = plane_grid(12, 12, 1.0, 0.25, z, false, &mut rng);
        let s = surface(FacetType::Quad4, &mesh);
        let index = SearchIndex::build(&s);
        for q in 0..500 {
            let (x, y) = (2.0 + 8.0 * unit(&mut rng), 2.0 + 8.0 * unit(&mut rng));
            let x0 = [x, y, z(x, y) + 0.3 * rng.next()];
            let found = index.find(&s, x0, 5.0).unwrap();
            // Newton moves the slave point (large sliding) within the patch.
            let x1 = [
                x0[0] + 1.2 * rng.next(),
                x0[1] + 1.2 * rng.next(),
                x0[2] + 0.2 * rng.next(),
            ];
            let previous = Some((found.facet, found.projection.xi));
            let (f, p) = select_facet(&s, &found.patch, x1, previous).unwrap();
            let brute = brute_force(&s, &found.patch, x1).unwrap();
            assert_eq!(f, brute.facet, "query {q}");
            assert_eq!(p.outside <= INSIDE_TOL, brute.valid);
            let (g, _) = select_facet(&s, &found.patch, x1, None).unwrap();
            assert_eq!(g, f, "start must not change the choice");
            // When the patch holds the global winner, it agrees with find.
            let global = index.find(&s, x1, 5.0).unwrap();
            if found.patch.contains(&global.facet) {
                assert_eq!(f, global.facet);
            }
        }
        assert!(select_facet(&s, &[], [1.0, 1.0, 0.0], None).is_none());
        assert!(select_facet(&s, &[9999], [1.0, 1.0, 0.0], None).is_none());
        // A previous facet that is not a candidate is ignored.
        let (f, _) = select_facet(&s, &[0, 1], [0.5, 0.5, 0.0], Some((50, [0.0, 0.0]))).unwrap();
        assert_eq!(f, 0);
        // Non-finite previous ξ falls back to the default start.
        let (f, _) =
            select_facet(&s, &[0, 1], [0.5, 0.5, 0.0], Some((0, [f64::NAN, 0.0]))).unwrap();
        assert_eq!(f, 0);
    }

    #[test]
    fn boxes_overlap_cases() {
        let unit_box = ([0.0; 3], [1.0; 3]);
        let shifted = |d: [f64; 3]| (d, [d[0] + 1.0, d[1] + 1.0, d[2] + 1.0]);
        assert!(boxes_overlap(unit_box, shifted([0.5, 0.5, 0.5]), 0.0));
        assert!(
            boxes_overlap(unit_box, shifted([1.0, 0.0, 0.0]), 0.0),
            "touching"
        );
        assert!(!boxes_overlap(unit_box, shifted([1.2, 0.0, 0.0]), 0.1));
        assert!(boxes_overlap(unit_box, shifted([1.2, 0.0, 0.0]), 0.2));
        assert!(
            !boxes_overlap(unit_box, shifted([-1.3, 0.0, 0.0]), 0.2),
            "other side"
        );
        assert!(
            !boxes_overlap(unit_box, shifted([0.0, 0.0, 1.5]), 0.2),
            "z only"
        );
        assert!(!boxes_overlap(unit_box, shifted([1.5, 1.5, 1.5]), 0.4));
        // Each axis within the margin: overlap, though the corners are
        // farther apart than the margin (boxes, not balls).
        assert!(boxes_overlap(unit_box, shifted([1.3, 1.3, 1.3]), 0.3));
        assert!(
            boxes_overlap(shifted([5.0, 5.0, 5.0]), shifted([5.0, 5.0, 5.0]), 0.0),
            "same box"
        );
        assert!(!boxes_overlap(unit_box, EMPTY_BOX, 1e9), "empty box");
        assert!(
            boxes_overlap(unit_box, shifted([9.0, 9.0, 9.0]), f64::NAN),
            "NaN: search anyway"
        );
        assert_eq!(points_bounding_box(&[]), None);
        assert_eq!(points_bounding_box(&[[f64::NAN, 0.0, 0.0]]), None);
        assert_eq!(
            points_bounding_box(&[[1.0, 2.0, 3.0], [f64::NAN, 9.0, 9.0], [-1.0, 5.0, 0.0]]),
            Some(([-1.0, 2.0, 0.0], [1.0, 5.0, 3.0]))
        );
        let mesh = small_flat();
        let index = SearchIndex::build(&surface(FacetType::Quad4, &mesh));
        assert_eq!(index.bounding_box(), ([0.0; 3], [4.0, 4.0, 0.0]));
    }
}

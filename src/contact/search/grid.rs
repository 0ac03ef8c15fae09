//! The uniform bucket grids of the search and the compressed rows they
//! fill, and the nearest-node tracker of the outer search.

use super::{Aabb, GRID_PAD_REL};

/// A uniform grid of cubic cells over a bounding box.
#[derive(Debug, Clone)]
pub(super) struct Grid {
    origin: [f64; 3],
    pub(super) cell: f64,
    inv: f64,
    pub(super) dims: [usize; 3],
}

impl Grid {
    pub(super) fn single_cell() -> Self {
        Grid {
            origin: [0.0; 3],
            cell: 1.0,
            inv: 1.0,
            dims: [1; 3],
        }
    }

    /// Cells of about `target` size (grown until at most `max_cells`).
    pub(super) fn new(bbox: Aabb, target: f64, max_cells: usize) -> Self {
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

    pub(super) fn n_cells(&self) -> usize {
        self.dims[0] * self.dims[1] * self.dims[2]
    }

    pub(super) fn index(&self, c: [usize; 3]) -> usize {
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
    pub(super) fn cell_of(&self, p: [f64; 3]) -> [usize; 3] {
        [
            self.clamp(self.coord(p[0], 0), 0),
            self.clamp(self.coord(p[1], 1), 1),
            self.clamp(self.coord(p[2], 2), 2),
        ]
    }

    /// Inclusive cell ranges meeting the box `[lo, hi]`; `None` if the box
    /// misses the grid.
    pub(super) fn cell_range(&self, lo: [f64; 3], hi: [f64; 3]) -> Option<[[usize; 2]; 3]> {
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
    pub(super) fn gap2(&self, axis: usize, c: usize, v: f64) -> f64 {
        let lo = self.origin[axis] + c as f64 * self.cell;
        let g = (lo - v).max(v - lo - self.cell).max(0.0);
        g * g
    }

    /// Squared gaps along each axis between `x` and the grid's extent.
    pub(super) fn outside_gap2(&self, x: [f64; 3]) -> [f64; 3] {
        let (lo, hi) = self.bounds();
        [0, 1, 2].map(|a| {
            let g = (lo[a] - x[a]).max(x[a] - hi[a]).max(0.0);
            g * g
        })
    }

    /// [`Grid::for_each_cell`] restricted to the cells within distance `r`
    /// of `x` (with the grid's rounding slack), skipping whole rows at once.
    pub(super) fn for_each_cell_within(
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

    pub(super) fn for_each_cell(&self, range: [[usize; 2]; 3], mut f: impl FnMut(usize)) {
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
    pub(super) fn unvisited_distance2(
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
pub(super) struct Rows {
    pub(super) start: Vec<usize>,
    pub(super) items: Vec<u32>,
}

impl Rows {
    /// Counting sort of `(row, item)` pairs; stable, so items keep the order
    /// of `pairs` within a row. Rows out of range are dropped.
    pub(super) fn build(n_rows: usize, pairs: &[(usize, u32)]) -> Self {
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

    pub(super) fn range(&self, r: usize) -> std::ops::Range<usize> {
        match (self.start.get(r), self.start.get(r + 1)) {
            (Some(&a), Some(&b)) => a..b,
            _ => 0..0,
        }
    }

    pub(super) fn row(&self, r: usize) -> &[u32] {
        &self.items[self.range(r)]
    }

    /// The row of node or facet `id` (rows keyed by surface ids).
    pub(super) fn row_of(&self, id: u32) -> &[u32] {
        self.row(id as usize)
    }
}

/// Running nearest node: smaller squared distance wins, equal distance goes
/// to the smaller id. Works on squared distances so scanning needs no square
/// root; `limit2` (the best distance plus the grid slack, squared) is only
/// recomputed when the best improves.
pub(super) struct NearestNode {
    pub(super) id: u32,
    d2: f64,
    pad: f64,
    limit2: f64,
}

impl NearestNode {
    pub(super) fn new(pad: f64) -> Self {
        NearestNode {
            id: u32::MAX,
            d2: f64::INFINITY,
            pad,
            limit2: f64::INFINITY,
        }
    }

    pub(super) fn offer(&mut self, id: u32, d2: f64) {
        if d2 < self.d2 || (d2 == self.d2 && id < self.id) {
            self.id = id;
            self.d2 = d2;
            let reach = d2.sqrt() + self.pad;
            self.limit2 = reach * reach;
        }
    }

    /// Whether a cell at squared box distance `box2` may hold a node as close
    /// as the best (ties included, for the smaller id).
    pub(super) fn may_hold(&self, box2: f64) -> bool {
        box2 <= self.limit2
    }

    /// Whether the best is strictly closer than anything at squared distance
    /// `bound2` or beyond, slack included. Equal distance could still hide a
    /// smaller id, so that does not count.
    pub(super) fn beats(&self, bound2: f64) -> bool {
        let reach = bound2.sqrt() - self.pad;
        reach > 0.0 && self.d2 < reach * reach
    }

    pub(super) fn result(&self) -> Option<(u32, f64)> {
        (self.d2.is_finite()).then(|| (self.id, self.d2.sqrt()))
    }
}

//! The mortar tangent as the solver gets it: its entries gathered into
//! matrix rows, and its active-set signature.
//!
//! The kernels emit `(row, column, value)` triples, many per matrix entry
//! (every segment of a node adds to the same couplings). They are bucketed
//! by row in emission order, then each row is merged through a dense
//! scatter: the cost is linear in the entries (one sort of all of them took
//! a quarter of a frictional run), and each entry's sum keeps the emission
//! order.
use super::friction::NodeFriction;
use super::system::{NodalData, NodeDof, NodeState, Segment};
use super::MAX_FACET_NODES;
use crate::assembly::MatrixSink;
use crate::dofs::{GlobalDof, DIM};
use crate::error::Result;

/// A pair of at most this many DOFs (on a rank) sums its tangent in a
/// dense matrix over them (4.5 MB at most): a small pair's tangent is
/// nearly dense, and summing each entry where it lands is cheaper than
/// bucketing and merging it (on the 183-DOF frictional block slide every
/// coupling is emitted five times over).
const DENSE_MAX_DOFS: usize = 768;

/// Entries by pair DOF `3 id + c`.
pub(super) struct Rows {
    entries: Entries,
}

enum Entries {
    /// Per row, `(column, value)` in emission order (large pairs).
    Bucketed(Vec<Vec<(u32, f64)>>),
    /// Row-major `n × n` sums and which rows have any (small pairs,
    /// [`DENSE_MAX_DOFS`]).
    Dense {
        n: usize,
        sums: Vec<f64>,
        rows: Vec<bool>,
    },
}

thread_local! {
    /// The last tangent's row vectors, emptied, kept for the next one: their
    /// growth was 3 % of a frictional mortar run's instructions.
    static SPARE: std::cell::RefCell<Vec<Vec<(u32, f64)>>> =
        const { std::cell::RefCell::new(Vec::new()) };
    /// The last dense sums, zeroed, kept for the next one (a fresh matrix
    /// per tangent was paged in every time).
    static SPARE_DENSE: std::cell::RefCell<Vec<f64>> = const { std::cell::RefCell::new(Vec::new()) };
}

impl Drop for Rows {
    fn drop(&mut self) {
        match &mut self.entries {
            Entries::Bucketed(rows) => {
                let mut rows = std::mem::take(rows);
                rows.iter_mut().for_each(Vec::clear);
                SPARE.with(|s| *s.borrow_mut() = rows);
            }
            Entries::Dense { n, sums, rows } => {
                // Only the rows written to hold anything.
                let mut sums = std::mem::take(sums);
                for r in (0..*n).filter(|&r| rows[r]) {
                    sums[r * *n..(r + 1) * *n].fill(0.0);
                }
                SPARE_DENSE.with(|s| *s.borrow_mut() = sums);
            }
        }
    }
}

fn pair_dof(d: NodeDof) -> usize {
    DIM * d.0 as usize + d.1
}

impl Rows {
    /// For node ids `0..nodes`.
    pub(super) fn new(nodes: usize) -> Self {
        let n = DIM * nodes;
        let entries = if n <= DENSE_MAX_DOFS {
            let mut sums = SPARE_DENSE.with(|s| std::mem::take(&mut *s.borrow_mut()));
            sums.resize(n * n, 0.0);
            Entries::Dense {
                n,
                sums,
                rows: vec![false; n],
            }
        } else {
            let mut rows = SPARE.with(|s| std::mem::take(&mut *s.borrow_mut()));
            rows.resize_with(n, Vec::new);
            Entries::Bucketed(rows)
        };
        Rows { entries }
    }

    pub(super) fn add(&mut self, row: NodeDof, col: NodeDof, value: f64) {
        let (r, c) = (pair_dof(row), pair_dof(col));
        match &mut self.entries {
            Entries::Bucketed(rows) => rows[r].push((c as u32, value)),
            Entries::Dense { n, sums, rows } => {
                sums[r * *n + c] += value;
                rows[r] = true;
            }
        }
    }

    /// Adds every row into `k`; `dof_of(id, c)` is the global DOF of a node
    /// component (entries whose columns share a global DOF are summed).
    pub(super) fn add_to(
        &self,
        dof_of: impl Fn(u32, usize) -> GlobalDof,
        k: &mut dyn MatrixSink,
    ) -> Result<()> {
        match &self.entries {
            Entries::Bucketed(rows) => add_bucketed(rows, dof_of, k),
            Entries::Dense { n, sums, rows } => add_dense(*n, sums, rows, dof_of, k),
        }
    }
}

/// [`Rows::add_to`] of bucketed rows: each merged through a dense scatter.
fn add_bucketed(
    rows: &[Vec<(u32, f64)>],
    dof_of: impl Fn(u32, usize) -> GlobalDof,
    k: &mut dyn MatrixSink,
) -> Result<()> {
    let n = rows.len();
    let global = |p: usize| dof_of((p / DIM) as u32, p % DIM);
    let mut sum = vec![0.0; n];
    let mut seen = vec![false; n];
    let mut touched: Vec<u32> = Vec::new();
    let mut row_entries = RowEntries::default();
    for (row, entries) in rows.iter().enumerate().filter(|r| !r.1.is_empty()) {
        touched.clear();
        for &(c, v) in entries {
            let c_us = c as usize;
            if !seen[c_us] {
                seen[c_us] = true;
                touched.push(c);
            }
            sum[c_us] += v;
        }
        sort_columns(&mut touched, &seen);
        row_entries.clear();
        for &c in &touched {
            let c_us = c as usize;
            row_entries.push(global(c_us), sum[c_us]);
            sum[c_us] = 0.0;
            seen[c_us] = false;
        }
        k.add_block(&[global(row)], &row_entries.cols, &row_entries.vals)?;
    }
    Ok(())
}

/// [`Rows::add_to`] of the dense sums: a row's nonzero entries in column
/// order.
fn add_dense(
    n: usize,
    sums: &[f64],
    rows: &[bool],
    dof_of: impl Fn(u32, usize) -> GlobalDof,
    k: &mut dyn MatrixSink,
) -> Result<()> {
    let global = |p: usize| dof_of((p / DIM) as u32, p % DIM);
    let mut row_entries = RowEntries::default();
    for row in (0..n).filter(|&r| rows[r]) {
        row_entries.clear();
        for (c, &v) in sums[row * n..(row + 1) * n].iter().enumerate() {
            if v != 0.0 {
                row_entries.push(global(c), v);
            }
        }
        k.add_block(&[global(row)], &row_entries.cols, &row_entries.vals)?;
    }
    Ok(())
}

/// One row's global columns and values, in pair-DOF order; consecutive
/// columns that share a global DOF are summed.
#[derive(Default)]
struct RowEntries {
    cols: Vec<GlobalDof>,
    vals: Vec<f64>,
}

impl RowEntries {
    fn clear(&mut self) {
        self.cols.clear();
        self.vals.clear();
    }

    fn push(&mut self, g: GlobalDof, v: f64) {
        if self.cols.last() == Some(&g) {
            *self.vals.last_mut().unwrap_or(&mut 0.0) += v;
        } else {
            self.cols.push(g);
            self.vals.push(v);
        }
    }
}

/// Sorts a row's touched columns (`seen[c]` set for each): a row that
/// touches at least one in 16 of the pair's columns reads them off `seen`
/// in order, cheaper than a sort (a small pair's tangent is nearly dense:
/// the sorts were 2 % of a frictional block slide).
fn sort_columns(touched: &mut Vec<u32>, seen: &[bool]) {
    if 16 * touched.len() >= seen.len() {
        touched.clear();
        touched.extend((0..seen.len() as u32).filter(|&c| seen[c as usize]));
    } else {
        touched.sort_unstable();
    }
}

/// See `MortarPair::add_tangent`. Only the segments of facets with a closed
/// node enter: the others add nothing to the tangent, and overlaps
/// appearing or vanishing away from the contact (the flank of a curved
/// slave projected onto the master moves with every iterate) would
/// otherwise force new factors of an unchanged matrix structure.
pub(super) fn signature<T>(
    segments: &[Segment<T>],
    states: &[NodeState],
    frictions: &[NodeFriction],
    slave_facets: &[[u32; MAX_FACET_NODES]],
    nodes: usize,
    nodal: &NodalData,
) -> u64 {
    use std::hash::{Hash, Hasher};
    let closed = |f: u32| {
        slave_facets[f as usize][..nodes]
            .iter()
            .any(|&n| nodal.slot_of(n).is_some_and(|j| states[j].closed))
    };
    let mut h = std::collections::hash_map::DefaultHasher::new();
    for s in segments.iter().filter(|s| closed(s.slave)) {
        (s.slave, s.master).hash(&mut h);
    }
    for s in states {
        s.closed.hash(&mut h);
    }
    for f in frictions {
        f.sliding.hash(&mut h);
    }
    h.finish()
}

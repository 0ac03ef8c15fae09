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
use crate::assembly::MatrixSink;
use crate::dofs::{GlobalDof, DIM};
use crate::error::Result;
use crate::fem::MAX_FACET_NODES;

/// Entries by pair DOF `3 id + c`.
pub(super) struct Rows {
    rows: Vec<Vec<(u32, f64)>>,
}

thread_local! {
    /// The last tangent's row vectors, emptied, kept for the next one: their
    /// growth was 3 % of a frictional mortar run's instructions.
    static SPARE: std::cell::RefCell<Vec<Vec<(u32, f64)>>> =
        const { std::cell::RefCell::new(Vec::new()) };
}

impl Drop for Rows {
    fn drop(&mut self) {
        let mut rows = std::mem::take(&mut self.rows);
        rows.iter_mut().for_each(Vec::clear);
        SPARE.with(|s| *s.borrow_mut() = rows);
    }
}

fn pair_dof(d: NodeDof) -> usize {
    DIM * d.0 as usize + d.1
}

impl Rows {
    /// For node ids `0..nodes`.
    pub(super) fn new(nodes: usize) -> Self {
        let mut rows = SPARE.with(|s| std::mem::take(&mut *s.borrow_mut()));
        rows.resize_with(DIM * nodes, Vec::new);
        Rows { rows }
    }

    pub(super) fn add(&mut self, row: NodeDof, col: NodeDof, value: f64) {
        self.rows[pair_dof(row)].push((pair_dof(col) as u32, value));
    }

    /// Adds every row into `k`; `dof_of(id, c)` is the global DOF of a node
    /// component (entries whose columns share a global DOF are summed).
    pub(super) fn add_to(
        &self,
        dof_of: impl Fn(u32, usize) -> GlobalDof,
        k: &mut dyn MatrixSink,
    ) -> Result<()> {
        let n = self.rows.len();
        let global = |p: usize| dof_of((p / DIM) as u32, p % DIM);
        let mut sum = vec![0.0; n];
        let mut seen = vec![false; n];
        let mut touched: Vec<u32> = Vec::new();
        let (mut cols, mut vals): (Vec<GlobalDof>, Vec<f64>) = (Vec::new(), Vec::new());
        for (row, entries) in self.rows.iter().enumerate().filter(|r| !r.1.is_empty()) {
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
            cols.clear();
            vals.clear();
            for &c in &touched {
                let c_us = c as usize;
                let (g, v) = (global(c_us), sum[c_us]);
                sum[c_us] = 0.0;
                seen[c_us] = false;
                if cols.last() == Some(&g) {
                    *vals.last_mut().unwrap_or(&mut 0.0) += v;
                } else {
                    cols.push(g);
                    vals.push(v);
                }
            }
            k.add_block(&[global(row)], &cols, &vals)?;
        }
        Ok(())
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

//! The non-zero pattern of a distributed matrix, recorded before any value
//! exists (the symbolic half of assembly), and the matrix created exactly
//! preallocated for it.
//!
//! The record is kept here, not in PETSc: couplings of whole nodes (a block
//! of `bs` consecutive DOFs starting at a multiple of `bs`) in global node
//! numbers, single entries for anything else. A hex8 block is 64 node pairs
//! instead of PETSc MATPREALLOCATOR's 576 hashed entries. Rows other ranks
//! own are sent to them when the matrix is built; each rank then gives
//! PETSc exact row counts and fills its own rows with zeros (one rank: the
//! column indices in one copy).
use crate::petsc::{to_petsc_int, Matrix, PetscError, PetscInt, Result};
use mpi::topology::SimpleCommunicator;
use mpi::traits::{Communicator, CommunicatorCollectives};

/// Records the non-zero pattern of a matrix, including entries in rows other
/// ranks own, and then creates the matrix exactly preallocated for it.
pub struct PatternBuilder {
    world: SimpleCommunicator,
    /// First global row of every rank, and the total, in rank order.
    row_starts: Vec<usize>,
    block_size: usize,
    record: NodePattern,
}

impl PatternBuilder {
    /// A pattern for a matrix with `local_rows` rows on this rank (its
    /// rows follow those of the lower ranks). Collective.
    pub fn new(local_rows: usize, block_size: usize) -> Result<Self> {
        let world = SimpleCommunicator::world();
        let mut counts = vec![0_u64; world.size() as usize];
        world.all_gather_into(&(local_rows as u64), &mut counts[..]);
        let mut row_starts = Vec::with_capacity(counts.len() + 1);
        row_starts.push(0);
        for c in &counts {
            row_starts.push(row_starts.last().copied().unwrap_or(0) + *c as usize);
        }
        let bs = block_size.max(1);
        // Node couplings need every rank's rows to be whole nodes, so that
        // a node's rows have one owner.
        let whole = row_starts.iter().all(|s| s.is_multiple_of(bs));
        let total = row_starts.last().copied().unwrap_or(0);
        Ok(PatternBuilder {
            world,
            row_starts,
            block_size,
            record: NodePattern::new(total, if whole { bs } else { 1 }),
        })
    }

    /// Records the couplings of `dofs` with themselves (a square element block).
    pub fn add_square(&mut self, dofs: &[PetscInt]) -> Result<()> {
        self.record.add_square(dofs)
    }

    /// Records the entries of a dense block at global (rows, cols); the
    /// values are only checked for their count.
    pub fn add_block(
        &mut self,
        rows: &[PetscInt],
        cols: &[PetscInt],
        values: &[f64],
    ) -> Result<()> {
        Matrix::check_block(rows, cols, values)?;
        self.record.add_entries(rows, cols)
    }

    /// Creates the AIJ matrix with this pattern, filled with explicit zeros so
    /// the pattern is fixed from the start. Collective.
    pub fn build(self) -> Result<Matrix> {
        let rank = self.world.rank() as usize;
        let (start, end) = (self.row_starts[rank], self.row_starts[rank + 1]);
        let record = self.record.gather_owned(&self.world, &self.row_starts)?;
        if self.world.size() == 1 {
            // Exact row lengths, then the column indices in one copy (the
            // record freed before PETSc allocates).
            let (lengths, mut cols) = record.compressed_rows(start, end)?;
            return Matrix::with_compressed_rows(end - start, self.block_size, &lengths, &mut cols);
        }
        // Several ranks: exact counts of each row's columns inside and
        // outside the diagonal block, then a row at a time (a whole local
        // copy of the column indices, what PETSc's two local blocks would
        // take in one go, raises the largest rank's set-up peak).
        let (first, stop) = (to_petsc_int(start)?, to_petsc_int(end)?);
        let rows = end - start;
        let mut on = Vec::with_capacity(rows);
        let mut off = Vec::with_capacity(rows);
        record.for_each_row(start, end, |_, cols| {
            let inside = cols.partition_point(|&c| c < stop) - cols.partition_point(|&c| c < first);
            on.push(to_petsc_int(inside)?);
            off.push(to_petsc_int(cols.len() - inside)?);
            Ok(())
        })?;
        Matrix::with_rows(rows, self.block_size, (&on, &off), |set| {
            record.for_each_row(start, end, |row, cols| set(to_petsc_int(row)?, cols))
        })
    }
}

/// The record: couplings of whole nodes (`bs` consecutive DOFs from a
/// multiple of `bs`) and single entries for blocks that are not made of
/// whole nodes; negative indices are skipped, as MatSetValues does.
struct NodePattern {
    /// Global rows (and columns) of the matrix.
    rows: usize,
    bs: usize,
    /// (row node, column node), with repeats until `compact`.
    nodes: Vec<(u32, u32)>,
    /// (row, column) entries outside whole-node blocks.
    entries: Vec<(PetscInt, PetscInt)>,
    /// `nodes`' length after the last `compact`.
    compacted: usize,
    scratch: Vec<u32>,
}

/// Repeats are removed once the node record has grown past this many
/// pairs and twice its last compacted size, which bounds it by about twice
/// the distinct couplings.
const COMPACT_FROM: usize = 1 << 20;

impl NodePattern {
    fn new(rows: usize, bs: usize) -> Self {
        NodePattern {
            rows,
            bs,
            nodes: Vec::new(),
            entries: Vec::new(),
            compacted: 0,
            scratch: Vec::new(),
        }
    }

    fn out_of_range(&self, d: PetscInt) -> PetscError {
        PetscError {
            call: "MatSetValues",
            code: -1,
            message: format!("index {d} outside the {} rows of the pattern", self.rows),
        }
    }

    /// Whether `dofs` is made of whole nodes, each node's DOFs consecutive
    /// and in order; their node numbers are then in `scratch`.
    fn whole_nodes(&mut self, dofs: &[PetscInt]) -> Result<bool> {
        let bs = self.bs;
        self.scratch.clear();
        if !dofs.len().is_multiple_of(bs) {
            return Ok(false);
        }
        for chunk in dofs.chunks_exact(bs) {
            let first = chunk[0];
            let whole = first >= 0
                && (first as usize).is_multiple_of(bs)
                && chunk
                    .iter()
                    .enumerate()
                    .all(|(c, &d)| d == first + c as PetscInt);
            if !whole {
                return Ok(false);
            }
            if first as usize >= self.rows {
                return Err(self.out_of_range(first));
            }
            let node = u32::try_from(first as usize / bs).map_err(|_| self.out_of_range(first))?;
            self.scratch.push(node);
        }
        Ok(true)
    }

    fn add_square(&mut self, dofs: &[PetscInt]) -> Result<()> {
        if !self.whole_nodes(dofs)? {
            return self.add_entries(dofs, dofs);
        }
        let nodes = &self.scratch;
        self.nodes.reserve(nodes.len() * nodes.len());
        for &a in nodes {
            for &b in nodes {
                self.nodes.push((a, b));
            }
        }
        if self.nodes.len() > COMPACT_FROM.max(2 * self.compacted) {
            self.compact();
        }
        Ok(())
    }

    fn add_entries(&mut self, rows: &[PetscInt], cols: &[PetscInt]) -> Result<()> {
        for &d in rows.iter().chain(cols) {
            if d >= 0 && d as usize >= self.rows {
                return Err(self.out_of_range(d));
            }
        }
        for &r in rows.iter().filter(|&&r| r >= 0) {
            for &c in cols.iter().filter(|&&c| c >= 0) {
                self.entries.push((r, c));
            }
        }
        Ok(())
    }

    /// Sorts both records and drops repeats.
    fn compact(&mut self) {
        self.nodes.sort_unstable();
        self.nodes.dedup();
        self.entries.sort_unstable();
        self.entries.dedup();
        self.compacted = self.nodes.len();
    }

    /// The record of this rank's own rows: its own couplings there and
    /// those every other rank recorded there. Collective.
    fn gather_owned(mut self, world: &SimpleCommunicator, row_starts: &[usize]) -> Result<Self> {
        self.compact();
        if world.size() == 1 {
            return Ok(self);
        }
        let bs = self.bs;
        let ranks = row_starts.len() - 1;
        let mut nodes: Vec<Vec<u32>> = vec![Vec::new(); ranks];
        let mut entries: Vec<Vec<PetscInt>> = vec![Vec::new(); ranks];
        // Both records are sorted by row, so each rank's share is one run.
        let (mut ni, mut ei) = (0, 0);
        for (r, end) in row_starts[1..].iter().enumerate() {
            let stop = ni + self.nodes[ni..].partition_point(|&(a, _)| (a as usize) * bs < *end);
            nodes[r].extend(self.nodes[ni..stop].iter().flat_map(|&(a, b)| [a, b]));
            ni = stop;
            let stop = ei + self.entries[ei..].partition_point(|&(a, _)| (a as usize) < *end);
            entries[r].extend(self.entries[ei..stop].iter().flat_map(|&(a, b)| [a, b]));
            ei = stop;
        }
        let nodes = crate::exchange::all_to_all(world, &nodes);
        let entries = crate::exchange::all_to_all(world, &entries);
        self.nodes = nodes.chunks_exact(2).map(|p| (p[0], p[1])).collect();
        self.entries = entries.chunks_exact(2).map(|p| (p[0], p[1])).collect();
        self.compact();
        Ok(self)
    }

    /// Calls `f` with each row of `start..end` and its sorted, distinct
    /// global column indices, from a compacted record that holds only rows
    /// of `start..end`.
    fn for_each_row(
        &self,
        start: usize,
        end: usize,
        mut f: impl FnMut(usize, &[PetscInt]) -> Result<()>,
    ) -> Result<()> {
        let bs = self.bs;
        let (mut ni, mut ei) = (0, 0);
        let mut row_nodes: &[(u32, u32)] = &[];
        let mut cols: Vec<PetscInt> = Vec::new();
        for row in start..end {
            if row.is_multiple_of(bs) {
                let node = (row / bs) as u32;
                let first = ni;
                while ni < self.nodes.len() && self.nodes[ni].0 == node {
                    ni += 1;
                }
                row_nodes = &self.nodes[first..ni];
            }
            let first = ei;
            while ei < self.entries.len() && self.entries[ei].0 == row as PetscInt {
                ei += 1;
            }
            let extra = &self.entries[first..ei];
            cols.clear();
            cols.extend(
                row_nodes
                    .iter()
                    .flat_map(|&(_, m)| (0..bs).map(move |c| (m as usize * bs + c) as PetscInt)),
            );
            if !extra.is_empty() {
                cols.extend(extra.iter().map(|&(_, c)| c));
                cols.sort_unstable();
                cols.dedup();
            }
            f(row, &cols)?;
        }
        Ok(())
    }

    /// Row lengths and the rows' column indices one after another (as
    /// `for_each_row` gives them); the record is freed before PETSc
    /// allocates.
    fn compressed_rows(self, start: usize, end: usize) -> Result<(Vec<PetscInt>, Vec<PetscInt>)> {
        let mut lengths = Vec::with_capacity(end - start);
        let mut all: Vec<PetscInt> = Vec::with_capacity(self.nodes.len() * self.bs * self.bs);
        self.for_each_row(start, end, |_, cols| {
            lengths.push(to_petsc_int(cols.len())?);
            all.extend_from_slice(cols);
            Ok(())
        })?;
        Ok((lengths, all))
    }
}

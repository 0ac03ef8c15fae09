//! The contact tangent D on C, on rank 0, as compressed rows.
use crate::petsc::{Matrix, PetscError, PetscInt, Result};

/// D on rank 0 in compressed rows: D[i, col[k]] = val[k] for k in
/// start[i]..start[i + 1] (positions in C; constrained rows and columns
/// dropped).
#[derive(Default)]
pub(super) struct Sparse {
    start: Vec<usize>,
    col: Vec<usize>,
    val: Vec<f64>,
}

impl Sparse {
    pub(super) fn row(&self, i: usize) -> impl Iterator<Item = (usize, f64)> + '_ {
        let r = self.start[i]..self.start[i + 1];
        self.col[r.clone()]
            .iter()
            .copied()
            .zip(self.val[r].iter().copied())
    }

    /// The positions with an entry in their row or column (sorted).
    pub(super) fn touched(&self) -> Vec<usize> {
        let rows = self.start.len().saturating_sub(1);
        let mut t: Vec<usize> = (0..rows)
            .filter(|&i| self.start[i + 1] > self.start[i])
            .chain(self.col.iter().copied())
            .collect();
        t.sort_unstable();
        t.dedup();
        t
    }

    /// D − diag(`shift`) (`shift` empty: D).
    pub(super) fn shifted(&self, shift: &[f64]) -> Sparse {
        let rows = self.start.len().saturating_sub(1);
        let mut out = Sparse {
            start: vec![0],
            ..Sparse::default()
        };
        for i in 0..rows {
            out.col.extend(self.row(i).map(|(k, _)| k));
            out.val.extend(self.row(i).map(|(_, v)| v));
            let s = shift.get(i).copied().unwrap_or(0.0);
            if s != 0.0 {
                out.add_to_last_row(i, -s);
            }
            out.start.push(out.col.len());
        }
        out
    }

    /// Adds `v` at column `col` of the row being built (after its last
    /// `start`).
    fn add_to_last_row(&mut self, col: usize, v: f64) {
        let from = self.start.last().copied().unwrap_or(0);
        match self.col[from..].iter().position(|&c| c == col) {
            Some(k) => self.val[from + k] += v,
            None => {
                self.col.push(col);
                self.val.push(v);
            }
        }
    }
}

/// D from the parallel contact tangent `m` onto rank 0 (empty elsewhere):
/// each rank reads its own rows of C, keeps their entries at columns in C
/// (not `fixed`, non-zero) as (row, column, value) triplets in positions,
/// and rank 0 concatenates them in rank order. Ranks own ascending row
/// ranges and MatGetRow gives a row's columns ascending, so the rows come
/// out as a submatrix on C would give them, with only the non-zero
/// entries moved (MatCreateSubMatrices moved the whole contact pattern, most
/// of it the zeros of open links). `c` sorted. Collective: a rank whose
/// reading failed still takes part in the gather, with no entries, and
/// returns its error after it.
pub(super) fn gather_sparse(m: &Matrix, c: &[PetscInt], fixed: &[bool]) -> Result<Sparse> {
    use mpi::traits::{Communicator, Root};
    let local = own_rows(m, c, fixed).and_then(|t| match i32::try_from(t.len()) {
        Ok(_) => Ok(t),
        Err(_) => Err(PetscError::new(
            "gather_sparse",
            format!(
                "{} values of the contact tangent exceed one gather",
                t.len()
            ),
        )),
    });
    let sent: &[f64] = local.as_deref().unwrap_or(&[]);
    let world = mpi::topology::SimpleCommunicator::world();
    let root = world.process_at_rank(0);
    // Fits: checked above (0 when this rank failed).
    let n = sent.len() as i32;
    if world.rank() != 0 {
        root.gather_into(&n);
        root.gather_varcount_into(sent);
        return local.map(|_| Sparse::default());
    }
    let mut counts = vec![0i32; world.size() as usize];
    root.gather_into_root(&n, &mut counts[..]);
    let displs: Vec<i32> = counts
        .iter()
        .scan(0, |acc, &k| {
            let d = *acc;
            *acc += k;
            Some(d)
        })
        .collect();
    let mut all = vec![0.0; counts.iter().map(|&k| k as usize).sum()];
    let mut part = mpi::datatype::PartitionMut::new(&mut all[..], counts, displs);
    root.gather_varcount_into_root(sent, &mut part);
    local?;
    Ok(from_triplets(&all, c.len()))
}

/// This rank's triplets (row, column, value; positions in C stored as f64,
/// exact below 2⁵³) of `m`'s owned rows of C.
fn own_rows(m: &Matrix, c: &[PetscInt], fixed: &[bool]) -> Result<Vec<f64>> {
    let (lo, hi) = m.ownership_range()?;
    let from = c.partition_point(|&d| d < lo);
    let to = c.partition_point(|&d| d < hi);
    let mut out = Vec::new();
    let rows = (from..to).filter(|&i| !fixed[i]).map(|i| c[i]);
    m.for_rows(rows, |row, cols, vals| {
        // C is sorted: a row's position in it is found again.
        let Ok(i) = c.binary_search(&row) else {
            return Ok(());
        };
        for (&col, &v) in cols.iter().zip(vals) {
            if let Ok(k) = c.binary_search(&col) {
                if !fixed[k] && v != 0.0 {
                    out.extend_from_slice(&[i as f64, k as f64, v]);
                }
            }
        }
        Ok(())
    })?;
    Ok(out)
}

/// Compressed rows of `n` rows from triplets sorted by row, then column.
fn from_triplets(t: &[f64], n: usize) -> Sparse {
    let mut d = Sparse {
        start: vec![0],
        ..Sparse::default()
    };
    let mut row = 0;
    for e in t.chunks_exact(3) {
        let i = e[0] as usize;
        while row < i {
            d.start.push(d.col.len());
            row += 1;
        }
        d.col.push(e[1] as usize);
        d.val.push(e[2]);
    }
    while row < n {
        d.start.push(d.col.len());
        row += 1;
    }
    d
}

#[cfg(test)]
mod tests {
    use super::Sparse;

    /// Rows 0 and 2 of a 4 × 4 D: (0, 0) = 2, (0, 3) = 1, (2, 1) = −1.
    fn d() -> Sparse {
        Sparse {
            start: vec![0, 2, 2, 3, 3],
            col: vec![0, 3, 1],
            val: vec![2.0, 1.0, -1.0],
        }
    }

    fn dense(s: &Sparse, n: usize) -> Vec<f64> {
        let mut out = vec![0.0; n * n];
        for i in 0..n {
            for (k, v) in s.row(i) {
                out[i * n + k] += v;
            }
        }
        out
    }

    #[test]
    fn triplets_become_the_same_rows() {
        let t = [0.0, 0.0, 2.0, 0.0, 3.0, 1.0, 2.0, 1.0, -1.0];
        let s = super::from_triplets(&t, 4);
        assert_eq!(s.start, d().start);
        assert_eq!(s.col, d().col);
        assert_eq!(s.val, d().val);
        let empty = super::from_triplets(&[], 3);
        assert_eq!(empty.start, vec![0, 0, 0, 0]);
    }

    #[test]
    fn touched_takes_rows_and_columns_with_an_entry() {
        assert_eq!(d().touched(), vec![0, 1, 2, 3]);
        let one = Sparse {
            start: vec![0, 0, 1, 1],
            col: vec![1],
            val: vec![5.0],
        };
        assert_eq!(one.touched(), vec![1]);
    }

    #[test]
    fn shifted_subtracts_on_the_diagonal_whether_or_not_it_had_an_entry() {
        let s = d().shifted(&[0.5, 0.0, 0.25, 3.0]);
        let mut want = dense(&d(), 4);
        for (i, a) in [0.5, 0.0, 0.25, 3.0].iter().enumerate() {
            want[i * 4 + i] -= a;
        }
        assert_eq!(dense(&s, 4), want);
        assert_eq!(s.touched(), vec![0, 1, 2, 3]);
        assert_eq!(dense(&d().shifted(&[]), 4), dense(&d(), 4));
    }
}

//! The contact tangent D on C, on rank 0, as compressed rows.
use super::super::{petsc_call, sys, PetscInt, Result};

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

/// A sequential |C| × |C| matrix's rows, without the `fixed` rows and
/// columns.
pub(super) fn read_sparse(m: sys::Mat, fixed: &[bool]) -> Result<Sparse> {
    let mut d = Sparse {
        start: vec![0],
        ..Sparse::default()
    };
    for (row, &skip) in fixed.iter().enumerate() {
        if !skip {
            let mut nz: PetscInt = 0;
            let mut cols: *const PetscInt = std::ptr::null();
            let mut vals: *const f64 = std::ptr::null();
            // SAFETY: `m` is a valid assembled sequential matrix with
            // fixed.len() rows; the row's pointers are read only between
            // MatGetRow and the paired MatRestoreRow, `nz` entries each.
            unsafe {
                let r = row as PetscInt;
                petsc_call!(MatGetRow(m, r, &mut nz, &mut cols, &mut vals))?;
                if nz > 0 && !cols.is_null() && !vals.is_null() {
                    let cs = std::slice::from_raw_parts(cols, nz as usize);
                    let vs = std::slice::from_raw_parts(vals, nz as usize);
                    for (&c, &v) in cs.iter().zip(vs) {
                        if !fixed[c as usize] && v != 0.0 {
                            d.col.push(c as usize);
                            d.val.push(v);
                        }
                    }
                }
                petsc_call!(MatRestoreRow(m, r, &mut nz, &mut cols, &mut vals))?;
            }
        }
        d.start.push(d.col.len());
    }
    Ok(d)
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

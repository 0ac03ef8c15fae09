//! G = Pᵀ K⁻¹ P by MUMPS's selected inverse entries, a column once U
//! first takes it.
use super::{AnyRank, LowRankPreconditioner};
use crate::petsc::{
    options, to_petsc_int, DenseMatrix, Factor, Matrix, PetscError, PetscInt, Result,
};

/// Columns of the inverse MUMPS computes together. Its default blocking
/// (32 here) made the entries cost twice as much: graded line b/40 on 2
/// ranks, 332 columns, 2.41-2.43 CPU s on rank 0 against 0.98 s with
/// blocks of 256 or 1024 (1.26 s with 128, 5.35 s with 16), the same peak
/// memory (455 MiB).
const INVERSE_BLOCK: PetscInt = 1024;

/// Up to this many columns of G that a condensed Newton step finds missing
/// come from whole solves with K's factor: there MUMPS's selected inverse
/// was slow (hertz-cylinder h = 0.2, 2 ranks, all 972 rows of C: one column
/// 1.5 s, seven 0.24 s, against 0.016 and 0.088 s by whole solves), while
/// on the set-up's requests it is the faster (line b/5, 2 ranks, 52 columns
/// at 366 rows in two requests: 0.02 CPU s against 0.14 s by whole solves).
/// Also the most right-hand sides of one solve with K's factor when
/// columns are redone by whole solves (a dense block of N × 32 per solve).
const WHOLE_SOLVES: usize = 32;

/// The selected inverse's entries must match a whole solve to this
/// fraction of the probe's largest entry (both are the same factor's;
/// they differ by rounding, 1e-15 or so, when right).
const PROBE_TOLERANCE: f64 = 1e-8;

impl LowRankPreconditioner {
    /// G valid on U × U: the columns of U not yet known. Rank 0 decides
    /// whether any column is new, agreed; whether any was. Collective.
    pub(super) fn complete_inverse(&mut self) -> Result<bool> {
        let new: Vec<usize> = match self.root {
            true => self.u.iter().copied().filter(|&i| !self.known[i]).collect(),
            false => Vec::new(),
        };
        if !(self.any_rank)(!new.is_empty()) {
            return Ok(false);
        }
        self.request_columns(&new, false)?;
        Ok(true)
    }

    /// G's columns at the positions `new` (rank 0's; some on every rank's
    /// word): at the rows of every known position and theirs, or at every
    /// row of C for the condensed Newton; K being symmetric, G is too, so
    /// the same entries fill the new rows of the known columns. A
    /// condensed Newton step's few new columns (`in_step`) come from whole
    /// solves (see [`WHOLE_SOLVES`]). Collective.
    pub(super) fn request_columns(&mut self, new: &[usize], in_step: bool) -> Result<()> {
        for &i in new {
            if let Some(k) = self.known.get_mut(i) {
                *k = true;
            }
        }
        let every_row = self.reduced.is_some();
        let many = (self.any_rank)(new.len() > WHOLE_SOLVES);
        if every_row && in_step && !many {
            self.solved_columns(new)?;
        } else {
            let rows: Vec<usize> = (0..self.known.len())
                .filter(|&i| every_row || self.known[i])
                .collect();
            self.inverse_entries(new, &rows)?;
            if !self.entries_pass_probe(new, &rows)? {
                self.inverse_redone += 1;
                self.solved_columns(new)?;
            }
        }
        self.inverse_blocks += 1;
        self.inverse_columns += new.len();
        Ok(())
    }

    /// G's entries at `rows` × `cols` (positions in C, rank 0's; empty
    /// elsewhere) by MUMPS's selected inverse (ICNTL(30)): the entries
    /// requested on rank 0 as the transpose of a sparse right-hand side, so
    /// MUMPS prunes its solves to the tree paths of them (whole solves with
    /// |C| unit right-hand sides cost 1.99e11 flops per rank at
    /// hertz-cylinder h = 0.2, against 4.9e9 for the 14 solves of the run).
    /// The request is an N × N matrix held on rank 0 whose row C[c] lists
    /// C[rows]: K⁻¹'s column C[c] at those rows. Collective.
    fn inverse_entries(&mut self, cols: &[usize], rows: &[usize]) -> Result<()> {
        let (size, _) = self.k.size()?;
        let here = if self.root { size } else { 0 };
        let nr = to_petsc_int(rows.len())?;
        let at: Vec<PetscInt> = rows.iter().map(|&r| self.c[r]).collect();
        let lengths: Vec<PetscInt> = if self.root {
            let mut l = vec![0; size as usize];
            for &c in cols {
                l[self.c[c] as usize] = nr;
            }
            l
        } else {
            Vec::new()
        };
        let ones = vec![1.0; rows.len()];
        // Rank 0 owns every row and column of the request; MUMPS writes the
        // entries into its values. ICNTL(30) and ICNTL(21) are put back to
        // what MatSolve expects (PETSc leaves the selected-inverse mode and
        // a centralised solution set).
        let per_row = self.root.then_some(lengths.as_slice());
        let mut bt = Matrix::new_aij(here, size, per_row)?;
        let set = cols
            .iter()
            .try_for_each(|&c| bt.set_block(&[self.c[c]], &at, &ones));
        all_or_none(&self.any_rank, set, "requesting G's entries")?;
        bt.assemble()?;
        let blocking = self.inverse_blocking()?;
        let factor = self.factor_mut()?;
        let got = factor.inverse_entries(&mut bt);
        factor.set_icntl(30, 0)?;
        factor.set_icntl(21, 1)?;
        if let Some(before) = blocking {
            factor.set_icntl(27, before)?;
        }
        got?;
        let local = self.read_entries(&bt, cols, rows);
        let failed = (self.any_rank)(local.is_err());
        local?;
        if failed {
            return Err(PetscError::new(
                "MatMumpsGetInverseTranspose",
                "reading the inverse entries failed on rank 0".into(),
            ));
        }
        Ok(())
    }

    /// G's columns `new` (rank 0's) at every row of C by whole solves
    /// K⁻¹ e, by symmetry also G's rows `new`; [`WHOLE_SOLVES`] of them in
    /// one solve with several right-hand sides, which reads K's factor once
    /// (graded line b/40, 2 ranks: three columns 0.12 s one at a time).
    /// Collective.
    fn solved_columns(&mut self, new: &[usize]) -> Result<()> {
        let n = self.c.len();
        for part in self.agreed_chunks(new) {
            let rhs: Vec<Vec<(usize, f64)>> = part.iter().map(|&j| vec![(j, 1.0)]).collect();
            let count = agreed_count(&self.any_rank, part.len());
            let columns = self.solve_at_c(&rhs, count)?;
            self.sparse_solves += 1;
            self.solved_columns += part.len();
            for (&j, values) in part.iter().zip(&columns) {
                for (r, &v) in values.iter().enumerate() {
                    self.g[j * n + r] = v;
                    self.g[r * n + j] = v;
                }
            }
        }
        Ok(())
    }

    /// `new` cut into pieces of at most [`WHOLE_SOLVES`] (rank 0's; empty
    /// elsewhere), as many on every rank (agreed). Collective.
    fn agreed_chunks<'a>(&self, new: &'a [usize]) -> Vec<&'a [usize]> {
        let mine: Vec<&[usize]> = new.chunks(WHOLE_SOLVES).collect();
        let count = agreed_count(&self.any_rank, mine.len());
        (0..count)
            .map(|i| mine.get(i).copied().unwrap_or(&[]))
            .collect()
    }

    /// K'⁻¹ b at C's positions for each right-hand side b (rank 0's
    /// entries at positions in C; `count` right-hand sides on every rank,
    /// the others empty there, and no result elsewhere), one solve with
    /// `count` right-hand sides. Collective.
    fn solve_at_c(&mut self, rhs: &[Vec<(usize, f64)>], count: usize) -> Result<Vec<Vec<f64>>> {
        let Some(small) = &mut self.small else {
            return Err(PetscError::new("G's columns", "no work vector".into()));
        };
        if count == 0 {
            return Ok(Vec::new());
        }
        let (Some(pick), Some(factor)) = (&self.pick, &self.factor) else {
            return Err(PetscError::new("G's columns", "K is not factored".into()));
        };
        // Both laid out as K's rows with `count` columns; rank 0 sets
        // entries of the rows it names (PETSc stashes off-process ones
        // until assembly).
        let (rows, _) = self.k.local_size()?;
        let mut b = DenseMatrix::new_mpi(rows.max(0) as usize, count)?;
        let set = rhs.iter().enumerate().try_for_each(|(i, entries)| {
            let col = to_petsc_int(i)?;
            entries
                .iter()
                .try_for_each(|&(j, v)| b.set(self.c[j], col, v))
        });
        all_or_none(&self.any_rank, set, "setting G's right-hand sides")?;
        b.assemble()?;
        let mut x = b.duplicate_layout()?;
        factor.solve_many(&b, &mut x)?;
        let mut out = Vec::with_capacity(count);
        for i in 0..count {
            x.with_column(i, |v| pick.forward(v, small))??;
            out.push(small.with_array(|a| a.to_vec())?);
        }
        Ok(out)
    }

    /// Whether the selected inverse's columns `new` (at `rows`) agree with
    /// a whole solve of the sum of the first and the last of them, to
    /// [`PROBE_TOLERANCE`] of the sum's largest entry. On the Hertz sphere
    /// at 80k DOFs on 2 ranks (`fine_size` 0.42) MUMPS's entries were
    /// wrong (every Newton iteration after the second diverged; whole
    /// solves converged in 18), so every request is probed; one solve
    /// checks both ends (two wrong columns cancelling to rounding at every
    /// row is not a failure to fear). Agreed. Collective.
    fn entries_pass_probe(&mut self, new: &[usize], rows: &[usize]) -> Result<bool> {
        let n = self.c.len();
        let mut ends: Vec<usize> = new.first().into_iter().chain(new.last()).copied().collect();
        ends.dedup();
        let rhs: Vec<(usize, f64)> = ends.iter().map(|&j| (j, 1.0)).collect();
        let values = self.solve_at_c(&[rhs], 1)?.pop().unwrap_or_default();
        self.probe_solves += 1;
        let mut bad = false;
        if !ends.is_empty() {
            let summed = |r: usize| ends.iter().map(|&j| self.g[j * n + r]).sum::<f64>();
            let scale = values.iter().fold(0.0f64, |m, v| m.max(v.abs()));
            let off = rows
                .iter()
                .map(|&r| (summed(r) - values[r]).abs())
                .fold(0.0f64, f64::max);
            // f64::max drops NaN: non-finite entries are their own test.
            let finite =
                values.iter().all(|v| v.is_finite()) && rows.iter().all(|&r| summed(r).is_finite());
            bad = !finite || off > PROBE_TOLERANCE * scale;
        }
        Ok(!(self.any_rank)(bad))
    }

    /// MUMPS's blocking of right-hand sides (ICNTL(27)) for a request:
    /// [`INVERSE_BLOCK`] columns at once, unless the user set
    /// `-mat_mumps_icntl_27`. Returns the value to put back (single solves
    /// do not depend on it). Collective (every rank sets the same value).
    fn inverse_blocking(&mut self) -> Result<Option<PetscInt>> {
        if options::has("-mat_mumps_icntl_27")? {
            return Ok(None);
        }
        let factor = self.factor_mut()?;
        let before = factor.icntl(27)?;
        factor.set_icntl(27, INVERSE_BLOCK)?;
        Ok(Some(before))
    }

    /// Rank 0: the answered request's rows into G, and by symmetry into
    /// the rows `cols` of the columns `rows`.
    fn read_entries(&mut self, bt: &Matrix, cols: &[usize], rows: &[usize]) -> Result<()> {
        let n = self.c.len();
        let (c, g) = (&self.c, &mut self.g);
        let mut at = cols.iter();
        bt.for_rows(cols.iter().map(|&p| c[p]), |d, _, vals| {
            let Some(&col) = at.next() else {
                return Ok(());
            };
            if vals.len() != rows.len() {
                return Err(PetscError::new(
                    "MatMumpsGetInverseTranspose",
                    format!(
                        "row {d} of the inverse entries has {} of {} entries",
                        vals.len(),
                        rows.len()
                    ),
                ));
            }
            for (&r, &v) in rows.iter().zip(vals) {
                g[col * n + r] = v;
                g[r * n + col] = v;
            }
            Ok(())
        })
    }

    /// K's factor (made at the first set-up).
    fn factor_mut(&mut self) -> Result<&mut Factor> {
        self.factor
            .as_mut()
            .ok_or_else(|| PetscError::new("G's columns", "K is not factored".into()))
    }
}

/// Rank 0's own work before a collective call, agreed: every rank goes on,
/// or every rank returns an error (the failing rank its own), so none waits
/// in the collective for a rank that left. Collective.
fn all_or_none(any_rank: &AnyRank, local: Result<()>, what: &'static str) -> Result<()> {
    if !any_rank(local.is_err()) {
        return Ok(());
    }
    local?;
    Err(PetscError::new(what, "failed on another rank".into()))
}

/// Rank 0's `local` (< 2^32) on every rank (the others pass 0): its bits
/// OR-ed over the ranks, one agreement each, as `any_rank` is the
/// preconditioner's only collective (32 reductions of a flag cost
/// microseconds against a solve's tens of milliseconds). Collective.
fn agreed_count(any_rank: &AnyRank, local: usize) -> usize {
    (0..32).fold(0, |k, b| {
        k | usize::from(any_rank(local >> b & 1 == 1)) << b
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_count_survives_its_agreement_bit_by_bit() {
        // One rank: the agreement is the flag itself.
        let alone: AnyRank = Box::new(|f| f);
        for k in [0, 1, 2, 31, 32, 33, 1686, (1 << 32) - 1] {
            assert_eq!(agreed_count(&alone, k), k);
        }
        // A rank passing ones everywhere would set every bit.
        let with_ones: AnyRank = Box::new(|_| true);
        assert_eq!(agreed_count(&with_ones, 37), (1 << 32) - 1);
    }

    #[test]
    fn a_failure_on_one_rank_stops_every_rank() {
        let alone: AnyRank = Box::new(|f| f);
        assert!(all_or_none(&alone, Ok(()), "x").is_ok());
        let own = all_or_none(
            &alone,
            Err(PetscError::new("MatSetValues", "bad row".into())),
            "x",
        );
        assert!(own.unwrap_err().to_string().contains("bad row"));
        // Another rank failed: this one's Ok turns into an error too.
        let other_failed: AnyRank = Box::new(|_| true);
        let e = all_or_none(&other_failed, Ok(()), "requesting G's entries").unwrap_err();
        assert!(e.to_string().contains("another rank"), "{e}");
    }
}

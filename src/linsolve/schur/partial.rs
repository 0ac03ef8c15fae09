//! Dense factorisations through LAPACK (`petsc::lapack`) for the contact
//! Schur complement: a Cholesky factor of S0's leading
//! block kept once, so that a change confined to the trailing block costs
//! a factorisation of that block alone: Cholesky for a symmetric change
//! ([`PartialCholesky::factor_into`]), LU with row pivots for any other
//! ([`PartialLu`], whose solve is ours: PETSc keeps a dense LU's pivots
//! private, so its Schur solve cannot read this one).
//!
//! With S = [A Bᵀ; B E] (A the leading `split` × `split` block), the lower
//! Cholesky factor of S is [L11 0; L21 L22] with L11 L11ᵀ = A,
//! L21 = B L11⁻ᵀ and L22 L22ᵀ = E − L21 L21ᵀ. A new S = S0 + D with D zero
//! outside the trailing block keeps L11 and L21: only E − L21 L21ᵀ + D_EE
//! is factored, (n − split)³/3 flops instead of n³/3, and the result is
//! the factor LAPACK's dpotrf would give for the whole matrix (dpotrs
//! reads it as such).
use crate::petsc::lapack;

/// S0's leading block factored and its Schur complement in the trailing
/// block, for S0 n × n symmetric (column-major; the lower triangle is read).
pub struct PartialCholesky {
    n: usize,
    split: usize,
    /// Columns 0..split: L11 and L21 (lower); the trailing block's lower
    /// triangle: E − L21 L21ᵀ.
    a: Vec<f64>,
}

impl PartialCholesky {
    /// None when S0's leading `split` × `split` block is not positive
    /// definite (or the sizes do not fit LAPACK's integers).
    pub fn new(s0: &[f64], n: usize, split: usize) -> Option<Self> {
        if s0.len() != n * n || split > n {
            return None;
        }
        let mut a = s0.to_vec();
        let m = n - split;
        if !lapack::fits(n) || !lapack::potrf_lower(&mut a, n, 0, split) {
            return None;
        }
        // In the column-major n × n buffer: L11 its leading split × split
        // block, B (then L21) the m × split block at row `split`, E the
        // m × m block at (split, split); all with leading dimension n.
        // L21 = B L11⁻ᵀ, then E − L21 L21ᵀ in E's lower triangle.
        if split > 0
            && m > 0
            && !(lapack::trsm_right_lower_t(&mut a, n, 0, split, m, split)
                && lapack::syrk_lower_minus(&mut a, n, split, split * n + split, m, split))
        {
            return None;
        }
        Some(PartialCholesky { n, split, a })
    }

    /// The first position of the trailing block.
    pub fn split(&self) -> usize {
        self.split
    }

    /// Writes into `out` (n × n, column-major) the lower Cholesky factor of
    /// S0 + D, where D is given by its entries (row, column, value) in the
    /// trailing block (entries elsewhere are a caller's bug: false). With
    /// `leading`, also the leading columns (else `out` holds them from an
    /// earlier call). False when S0 + D is not positive definite; `out`'s
    /// trailing block is then spoilt.
    pub fn factor_into(&self, d: &[(usize, usize, f64)], out: &mut [f64], leading: bool) -> bool {
        let (n, p) = (self.n, self.split);
        if out.len() != n * n {
            return false;
        }
        if leading {
            for j in 0..p {
                out[j * n + j..(j + 1) * n].copy_from_slice(&self.a[j * n + j..(j + 1) * n]);
            }
        }
        for j in p..n {
            out[j * n + j..(j + 1) * n].copy_from_slice(&self.a[j * n + j..(j + 1) * n]);
        }
        for &(r, c, v) in d {
            if r < p || c < p || r >= n || c >= n {
                return false;
            }
            // Both triangles' entries come: the lower one's are used.
            if r >= c {
                out[c * n + r] += v;
            }
        }
        lapack::potrf_lower(out, n, p * n + p, n - p)
    }

    /// Factors S0 + D into `out`, for D given by its entries (row, column,
    /// value; any pattern, not symmetric) in the trailing block: S0's
    /// leading columns as they are here, the trailing block's Schur
    /// complement E − L21 L21ᵀ + D_EE by LU with row pivots. False for an
    /// entry outside the trailing block (a caller's bug) or a singular
    /// S0 + D; `out` cannot solve until a later call succeeds.
    pub fn factor_lu_into(&self, d: &[(usize, usize, f64)], out: &mut PartialLu) -> bool {
        let (n, p) = (self.n, self.split);
        out.factored = false;
        if out.a.len() != n * n {
            out.a = vec![0.0; n * n];
            out.leading = None;
        }
        out.n = n;
        out.split = p;
        if out.leading != Some(p) {
            for j in 0..p {
                out.a[j * n + j..(j + 1) * n].copy_from_slice(&self.a[j * n + j..(j + 1) * n]);
            }
            out.leading = Some(p);
        }
        // The trailing block whole: LU reads both triangles, and `self`
        // holds the lower one.
        for j in p..n {
            for i in p..n {
                out.a[j * n + i] = if i >= j {
                    self.a[j * n + i]
                } else {
                    self.a[i * n + j]
                };
            }
        }
        for &(r, c, v) in d {
            if r < p || c < p || r >= n || c >= n {
                return false;
            }
            out.a[c * n + r] += v;
        }
        let m = n - p;
        out.ipiv.resize(m, 0);
        if m > 0 && !lapack::getrf(&mut out.a, n, p * n + p, m, &mut out.ipiv) {
            return false;
        }
        out.factored = true;
        true
    }
}

/// S = S0 + D factored as [L11 0; L21 I] [L11ᵀ L21ᵀ; 0 E − L21 L21ᵀ + D_EE]
/// with the last block LU-factored (P L U): what
/// [`PartialCholesky::factor_lu_into`] writes.
#[derive(Default)]
pub struct PartialLu {
    n: usize,
    split: usize,
    /// Column-major n × n: L11 and L21 in the leading columns' lower part,
    /// the trailing block's L and U.
    a: Vec<f64>,
    ipiv: Vec<lapack::Int>,
    /// The split whose leading columns `a` holds.
    leading: Option<usize>,
    factored: bool,
}

impl PartialLu {
    /// Overwrites `b` (n entries) with S⁻¹ b: forward through the leading
    /// block, the trailing block's LU solve, back through the leading
    /// block. False when nothing is factored or `b` has the wrong length.
    pub fn solve(&self, b: &mut [f64]) -> bool {
        let (n, p) = (self.n, self.split);
        if !self.factored || b.len() != n || self.a.len() != n * n {
            return false;
        }
        let m = n - p;
        if !lapack::fits(n) {
            return false;
        }
        // `a` is n × n column-major: L11 its leading p × p block, L21 the
        // m × p block at row p, the trailing LU the m × m block at (p, p),
        // all with leading dimension n; b's first p and last m entries are
        // x_1 and x_2.
        let a = &self.a;
        let (x1, x2) = b.split_at_mut(p);
        if p > 0 {
            // x_1 ← L11⁻¹ x_1, x_2 ← x_2 − L21 x_1.
            if !lapack::trsv_lower(false, a, n, p, x1)
                || (m > 0 && !lapack::gemv_minus(false, a, n, p, m, p, x1, x2))
            {
                return false;
            }
        }
        if m > 0 && !lapack::getrs(a, n, p * n + p, m, &self.ipiv, x2) {
            return false;
        }
        if p > 0 {
            // x_1 ← L11⁻ᵀ (x_1 − L21ᵀ x_2).
            if (m > 0 && !lapack::gemv_minus(true, a, n, p, m, p, x2, x1))
                || !lapack::trsv_lower(true, a, n, p, x1)
            {
                return false;
            }
        }
        true
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A deterministic SPD matrix, column-major.
    fn spd(n: usize) -> Vec<f64> {
        let mut a = vec![0.0; n * n];
        for j in 0..n {
            for i in 0..n {
                let x = 1.0 / (1.0 + (i + 2 * j) as f64) + 1.0 / (1.0 + (2 * i + j) as f64);
                a[j * n + i] = x;
            }
            a[j * n + j] += n as f64;
        }
        a
    }

    /// The lower triangle of `l` times its transpose.
    fn llt(l: &[f64], n: usize) -> Vec<f64> {
        let mut s = vec![0.0; n * n];
        for i in 0..n {
            for j in 0..n {
                s[j * n + i] = (0..=i.min(j)).map(|k| l[k * n + i] * l[k * n + j]).sum();
            }
        }
        s
    }

    /// The largest entry-wise difference.
    fn max_diff(a: &[f64], b: &[f64]) -> f64 {
        a.iter()
            .zip(b)
            .map(|(x, y)| (x - y).abs())
            .fold(0.0, f64::max)
    }

    #[test]
    fn partial_factor_is_the_whole_factor() {
        let n = 40;
        let s0 = spd(n);
        for split in [0, 1, 17, 39, 40] {
            let p = PartialCholesky::new(&s0, n, split).expect("SPD");
            let mut d = Vec::new();
            for r in split..n {
                for c in split..n {
                    d.push((
                        r,
                        c,
                        0.3 / (1.0 + (r + c) as f64) + if r == c { 2.0 } else { 0.0 },
                    ));
                }
            }
            let mut s = s0.clone();
            for &(r, c, v) in &d {
                s[c * n + r] += v;
            }
            let mut out = vec![f64::NAN; n * n];
            assert!(p.factor_into(&d, &mut out, true), "split {split}");
            let err = max_diff(&llt(&out, n), &s);
            assert!(err < 1e-12 * n as f64, "split {split}: {err:e}");
            // A second tangent reuses the leading columns already in `out`.
            let d2: Vec<_> = d.iter().map(|&(r, c, v)| (r, c, 2.0 * v)).collect();
            assert!(p.factor_into(&d2, &mut out, false));
            for &(r, c, v) in &d {
                s[c * n + r] += v;
            }
            let err = max_diff(&llt(&out, n), &s);
            assert!(err < 1e-12 * n as f64, "split {split}, again: {err:e}");
        }
    }

    #[test]
    fn partial_lu_solves_a_non_symmetric_change() {
        let n = 37;
        let s0 = spd(n);
        for split in [0, 1, 20, 36, 37] {
            let p = PartialCholesky::new(&s0, n, split).expect("SPD");
            let mut lu = PartialLu::default();
            for round in 0..2 {
                let mut d = Vec::new();
                for r in split..n {
                    for c in split..n {
                        let v = (0.7 + round as f64) / (1.0 + (3 * r + c) as f64)
                            - 0.2 / (2.0 + (r + 5 * c) as f64);
                        d.push((r, c, v));
                    }
                }
                let mut s = s0.clone();
                for &(r, c, v) in &d {
                    s[c * n + r] += v;
                }
                assert!(p.factor_lu_into(&d, &mut lu), "split {split}");
                let b: Vec<f64> = (0..n).map(|i| (i as f64 * 0.37).sin() + 0.5).collect();
                let mut x = b.clone();
                assert!(lu.solve(&mut x), "split {split}");
                let err = (0..n)
                    .map(|i| ((0..n).map(|j| s[j * n + i] * x[j]).sum::<f64>() - b[i]).abs())
                    .fold(0.0, f64::max);
                assert!(
                    err < 1e-12 * n as f64,
                    "split {split}, round {round}: {err:e}"
                );
            }
        }
    }

    #[test]
    fn partial_lu_refuses_singular_and_misplaced() {
        let n = 10;
        let s0 = spd(n);
        let p = PartialCholesky::new(&s0, n, 4).expect("SPD");
        let mut lu = PartialLu::default();
        assert!(!p.factor_lu_into(&[(2, 8, 1.0)], &mut lu));
        assert!(!lu.solve(&mut [0.0; 10]));
        // D cancels the trailing block's Schur complement: S is singular.
        let mut e = PartialLu::default();
        assert!(p.factor_lu_into(&[], &mut e));
        let d: Vec<_> = (4..n)
            .flat_map(|c| (4..n).map(move |r| (r, c)))
            .map(|(r, c)| (r, c, -e_entry(&p, r, c)))
            .collect();
        assert!(!p.factor_lu_into(&d, &mut lu));
    }

    /// The trailing Schur complement E − L21 L21ᵀ that `p` holds.
    fn e_entry(p: &PartialCholesky, r: usize, c: usize) -> f64 {
        let (i, j) = if r >= c { (r, c) } else { (c, r) };
        p.a[j * p.n + i]
    }

    #[test]
    fn indefinite_and_misplaced_are_refused() {
        let n = 12;
        let s0 = spd(n);
        let p = PartialCholesky::new(&s0, n, 4).expect("SPD");
        let mut out = vec![0.0; n * n];
        assert!(!p.factor_into(&[(8, 8, -1e3)], &mut out, true));
        assert!(!p.factor_into(&[(2, 8, 1.0)], &mut out, true));
        let mut bad = s0.clone();
        bad[0] = -1.0;
        assert!(PartialCholesky::new(&bad, n, 4).is_none());
    }
}

//! Dense factorisations through LAPACK (the system's, Debian's OpenBLAS),
//! for the contact Schur complement: a Cholesky factor of S0's leading
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
use std::os::raw::{c_char, c_int};

// Fortran LAPACK/BLAS with 32-bit integers (Debian's liblapack.so.3 and
// libblas.so.3, OpenBLAS where installed); the trailing lengths are the
// hidden lengths of the one-character arguments.
extern "C" {
    fn dpotrf_(
        uplo: *const c_char,
        n: *const c_int,
        a: *mut f64,
        lda: *const c_int,
        info: *mut c_int,
        uplo_len: usize,
    );
    #[allow(clippy::too_many_arguments)]
    fn dtrsm_(
        side: *const c_char,
        uplo: *const c_char,
        transa: *const c_char,
        diag: *const c_char,
        m: *const c_int,
        n: *const c_int,
        alpha: *const f64,
        a: *const f64,
        lda: *const c_int,
        b: *mut f64,
        ldb: *const c_int,
        side_len: usize,
        uplo_len: usize,
        transa_len: usize,
        diag_len: usize,
    );
    #[allow(clippy::too_many_arguments)]
    fn dtrsv_(
        uplo: *const c_char,
        trans: *const c_char,
        diag: *const c_char,
        n: *const c_int,
        a: *const f64,
        lda: *const c_int,
        x: *mut f64,
        incx: *const c_int,
        uplo_len: usize,
        trans_len: usize,
        diag_len: usize,
    );
    #[allow(clippy::too_many_arguments)]
    fn dgemv_(
        trans: *const c_char,
        m: *const c_int,
        n: *const c_int,
        alpha: *const f64,
        a: *const f64,
        lda: *const c_int,
        x: *const f64,
        incx: *const c_int,
        beta: *const f64,
        y: *mut f64,
        incy: *const c_int,
        trans_len: usize,
    );
    fn dgetrf_(
        m: *const c_int,
        n: *const c_int,
        a: *mut f64,
        lda: *const c_int,
        ipiv: *mut c_int,
        info: *mut c_int,
    );
    #[allow(clippy::too_many_arguments)]
    fn dgetrs_(
        trans: *const c_char,
        n: *const c_int,
        nrhs: *const c_int,
        a: *const f64,
        lda: *const c_int,
        ipiv: *const c_int,
        b: *mut f64,
        ldb: *const c_int,
        info: *mut c_int,
        trans_len: usize,
    );
    #[allow(clippy::too_many_arguments)]
    fn dsyrk_(
        uplo: *const c_char,
        trans: *const c_char,
        n: *const c_int,
        k: *const c_int,
        alpha: *const f64,
        a: *const f64,
        lda: *const c_int,
        beta: *const f64,
        c: *mut f64,
        ldc: *const c_int,
        uplo_len: usize,
        trans_len: usize,
    );
}

const L: c_char = b'L' as c_char;
const R: c_char = b'R' as c_char;
const T: c_char = b'T' as c_char;
const N: c_char = b'N' as c_char;

fn int(n: usize) -> Option<c_int> {
    c_int::try_from(n).ok()
}

/// Lower Cholesky factor, in place, of the m × m block of the column-major
/// `a` (leading dimension `lda`) that starts at `offset`; false when the
/// block is not positive definite (LAPACK's info > 0).
fn potrf_block(a: &mut [f64], lda: usize, offset: usize, m: usize) -> bool {
    if m == 0 {
        return true;
    }
    let (Some(mi), Some(ld)) = (int(m), int(lda)) else {
        return false;
    };
    if lda < m || offset + (m - 1) * lda + m > a.len() {
        return false;
    }
    let mut info: c_int = 0;
    // SAFETY: the block's m columns of m entries, lda apart from `offset`,
    // lie inside `a` (checked above); dpotrf reads and writes only them.
    unsafe { dpotrf_(&L, &mi, a.as_mut_ptr().add(offset), &ld, &mut info, 1) };
    info == 0
}

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
        let (nn, p, mi) = (int(n)?, int(split)?, int(m)?);
        if !potrf_block(&mut a, n, 0, split) {
            return None;
        }
        if split > 0 && m > 0 {
            let (one, minus) = (1.0f64, -1.0f64);
            let base = a.as_mut_ptr();
            // SAFETY: column-major n × n buffer of n² entries: L11 is its
            // leading split × split block, B (then L21) the m × split block
            // at row `split`, E the m × m block at (split, split); all with
            // leading dimension n. dtrsm reads L11 and overwrites B; dsyrk
            // reads L21 and updates E's lower triangle; the blocks do not
            // overlap.
            unsafe {
                dtrsm_(
                    &R,
                    &L,
                    &T,
                    &N,
                    &mi,
                    &p,
                    &one,
                    base,
                    &nn,
                    base.add(split),
                    &nn,
                    1,
                    1,
                    1,
                    1,
                );
                dsyrk_(
                    &L,
                    &N,
                    &mi,
                    &p,
                    &minus,
                    base.add(split),
                    &nn,
                    &one,
                    base.add(split * n + split),
                    &nn,
                    1,
                    1,
                );
            }
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
        potrf_block(out, n, p * n + p, n - p)
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
        if m > 0 {
            let (Some(mi), Some(ld)) = (int(m), int(n)) else {
                return false;
            };
            let mut info: c_int = 0;
            // SAFETY: `out.a` holds n × n entries (resized above); the
            // trailing m × m block starts at p·n + p with leading dimension
            // n and ends at the buffer's end; `ipiv` holds m entries.
            unsafe {
                dgetrf_(
                    &mi,
                    &mi,
                    out.a.as_mut_ptr().add(p * n + p),
                    &ld,
                    out.ipiv.as_mut_ptr(),
                    &mut info,
                )
            };
            if info != 0 {
                return false;
            }
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
    ipiv: Vec<c_int>,
    /// The split whose leading columns `a` holds.
    leading: Option<usize>,
    factored: bool,
}

impl PartialLu {
    /// The first position of the trailing block.
    pub fn split(&self) -> usize {
        self.split
    }

    /// Overwrites `b` (n entries) with S⁻¹ b: forward through the leading
    /// block, the trailing block's LU solve, back through the leading
    /// block. False when nothing is factored or `b` has the wrong length.
    pub fn solve(&self, b: &mut [f64]) -> bool {
        let (n, p) = (self.n, self.split);
        if !self.factored || b.len() != n || self.a.len() != n * n {
            return false;
        }
        let m = n - p;
        let (Some(nn), Some(pi), Some(mi)) = (int(n), int(p), int(m)) else {
            return false;
        };
        let (one, minus, inc) = (1.0f64, -1.0f64, 1 as c_int);
        let a = self.a.as_ptr();
        let x = b.as_mut_ptr();
        // SAFETY: `a` is n × n column-major (checked above): L11 its
        // leading p × p block, L21 the m × p block at row p, the trailing
        // LU the m × m block at (p, p), all with leading dimension n; `ipiv`
        // holds m pivots from dgetrf; `b` holds n entries, its first p
        // (x) and last m (x + p) are disjoint ranges.
        unsafe {
            if p > 0 {
                dtrsv_(&L, &N, &N, &pi, a, &nn, x, &inc, 1, 1, 1);
                if m > 0 {
                    dgemv_(
                        &N,
                        &mi,
                        &pi,
                        &minus,
                        a.add(p),
                        &nn,
                        x,
                        &inc,
                        &one,
                        x.add(p),
                        &inc,
                        1,
                    );
                }
            }
            if m > 0 {
                let mut info: c_int = 0;
                dgetrs_(
                    &N,
                    &mi,
                    &inc,
                    a.add(p * n + p),
                    &nn,
                    self.ipiv.as_ptr(),
                    x.add(p),
                    &mi,
                    &mut info,
                    1,
                );
                if info != 0 {
                    return false;
                }
            }
            if p > 0 {
                if m > 0 {
                    dgemv_(
                        &T,
                        &mi,
                        &pi,
                        &minus,
                        a.add(p),
                        &nn,
                        x.add(p),
                        &inc,
                        &one,
                        x,
                        &inc,
                        1,
                    );
                }
                dtrsv_(&L, &T, &N, &pi, a, &nn, x, &inc, 1, 1, 1);
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

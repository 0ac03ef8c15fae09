//! Dense symmetric factorisations through LAPACK (the system's, Debian's
//! OpenBLAS), for the contact Schur complement: a Cholesky factor of S0's
//! leading block kept once, so that a change confined to the trailing
//! block costs a factorisation of that block alone.
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
            let back = llt(&out, n);
            let err = back
                .iter()
                .zip(&s)
                .map(|(a, b)| (a - b).abs())
                .fold(0.0, f64::max);
            assert!(err < 1e-12 * n as f64, "split {split}: {err:e}");
            // A second tangent reuses the leading columns already in `out`.
            let d2: Vec<_> = d.iter().map(|&(r, c, v)| (r, c, 2.0 * v)).collect();
            assert!(p.factor_into(&d2, &mut out, false));
            for &(r, c, v) in &d {
                s[c * n + r] += v;
            }
            let err = llt(&out, n)
                .iter()
                .zip(&s)
                .map(|(a, b)| (a - b).abs())
                .fold(0.0, f64::max);
            assert!(err < 1e-12 * n as f64, "split {split}, again: {err:e}");
        }
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

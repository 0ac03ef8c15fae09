//! Safe wrappers of the LAPACK and BLAS routines the program calls (the
//! system's: Debian's liblapack.so.3 and libblas.so.3, OpenBLAS where
//! installed), on column-major blocks of `f64` slices. Each wrapper checks
//! that the block it names lies inside its slice and that the sizes fit
//! LAPACK's 32-bit integers, and calls nothing (returning false) when not.
use std::os::raw::{c_char, c_int};

/// LAPACK's integer: row pivots are held in these.
pub type Int = c_int;

// Fortran LAPACK/BLAS with 32-bit integers; the trailing lengths are the
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
const ONE: f64 = 1.0;
const MINUS: f64 = -1.0;
const INC: c_int = 1;

/// `n` as LAPACK's integer.
fn int(n: usize) -> Option<c_int> {
    c_int::try_from(n).ok()
}

/// Whether `n` fits LAPACK's integers.
pub fn fits(n: usize) -> bool {
    int(n).is_some()
}

/// Whether the `rows` × `cols` block at `at` of a column-major buffer of
/// `len` entries with leading dimension `ld` lies inside it.
fn inside(len: usize, ld: usize, at: usize, rows: usize, cols: usize) -> bool {
    rows == 0 || cols == 0 || (ld >= rows && at + (cols - 1) * ld + rows <= len)
}

/// Lower Cholesky factor (dpotrf), in place, of the m × m block at `at` of
/// the column-major `a` (leading dimension `lda`); false when the block is
/// not positive definite (LAPACK's info > 0) or does not fit.
pub fn potrf_lower(a: &mut [f64], lda: usize, at: usize, m: usize) -> bool {
    if m == 0 {
        return true;
    }
    let (Some(mi), Some(ld)) = (int(m), int(lda)) else {
        return false;
    };
    if !inside(a.len(), lda, at, m, m) {
        return false;
    }
    let mut info: c_int = 0;
    // SAFETY: the block's m columns of m entries, lda apart from `at`, lie
    // inside `a` (checked above); dpotrf reads and writes only them.
    unsafe { dpotrf_(&L, &mi, a.as_mut_ptr().add(at), &ld, &mut info, 1) };
    info == 0
}

/// B ← B L⁻ᵀ (dtrsm, right side, lower, transposed) in the column-major
/// `buf` (leading dimension `ld`): L the p × p lower triangle at `l_at`, B
/// the m × p block at `b_at`. False (nothing done) when a block does not
/// fit.
pub fn trsm_right_lower_t(
    buf: &mut [f64],
    ld: usize,
    l_at: usize,
    b_at: usize,
    m: usize,
    p: usize,
) -> bool {
    let (Some(mi), Some(pi), Some(ldi)) = (int(m), int(p), int(ld)) else {
        return false;
    };
    if !inside(buf.len(), ld, l_at, p, p) || !inside(buf.len(), ld, b_at, m, p) {
        return false;
    }
    let base = buf.as_mut_ptr();
    // SAFETY: both blocks lie inside `buf` (checked above); dtrsm reads L
    // and overwrites B.
    unsafe {
        dtrsm_(
            &R,
            &L,
            &T,
            &N,
            &mi,
            &pi,
            &ONE,
            base.add(l_at),
            &ldi,
            base.add(b_at),
            &ldi,
            1,
            1,
            1,
            1,
        )
    };
    true
}

/// C ← C − A Aᵀ on C's lower triangle (dsyrk) in the column-major `buf`
/// (leading dimension `ld`): A the m × p block at `a_at`, C the m × m block
/// at `c_at`. False (nothing done) when a block does not fit.
pub fn syrk_lower_minus(
    buf: &mut [f64],
    ld: usize,
    a_at: usize,
    c_at: usize,
    m: usize,
    p: usize,
) -> bool {
    let (Some(mi), Some(pi), Some(ldi)) = (int(m), int(p), int(ld)) else {
        return false;
    };
    if !inside(buf.len(), ld, a_at, m, p) || !inside(buf.len(), ld, c_at, m, m) {
        return false;
    }
    let base = buf.as_mut_ptr();
    // SAFETY: both blocks lie inside `buf` (checked above); dsyrk reads A
    // and updates C's lower triangle.
    unsafe {
        dsyrk_(
            &L,
            &N,
            &mi,
            &pi,
            &MINUS,
            base.add(a_at),
            &ldi,
            &ONE,
            base.add(c_at),
            &ldi,
            1,
            1,
        )
    };
    true
}

/// LU factors with row pivots (dgetrf), in place, of the m × m block at
/// `at` of the column-major `a` (leading dimension `lda`), the pivots into
/// `ipiv` (at least m entries); false when the block is singular (info >
/// 0) or does not fit.
pub fn getrf(a: &mut [f64], lda: usize, at: usize, m: usize, ipiv: &mut [Int]) -> bool {
    let (Some(mi), Some(ld)) = (int(m), int(lda)) else {
        return false;
    };
    if !inside(a.len(), lda, at, m, m) || ipiv.len() < m {
        return false;
    }
    let mut info: c_int = 0;
    // SAFETY: the block lies inside `a` and `ipiv` holds m entries (checked
    // above); dgetrf writes only them.
    unsafe {
        dgetrf_(
            &mi,
            &mi,
            a.as_mut_ptr().add(at),
            &ld,
            ipiv.as_mut_ptr(),
            &mut info,
        )
    };
    info == 0
}

/// x ← A⁻¹ x for one right-hand side (dgetrs) with the LU factors `getrf`
/// left in the n × n block at `at` of `a` (leading dimension `lda`) and
/// their pivots; false when a block does not fit or LAPACK refuses.
pub fn getrs(a: &[f64], lda: usize, at: usize, n: usize, ipiv: &[Int], x: &mut [f64]) -> bool {
    let (Some(ni), Some(ld)) = (int(n), int(lda)) else {
        return false;
    };
    if !inside(a.len(), lda, at, n, n) || ipiv.len() < n || x.len() < n {
        return false;
    }
    let mut info: c_int = 0;
    // SAFETY: the factors lie inside `a`, `ipiv` holds n pivots and `x` n
    // entries (checked above); dgetrs reads the first two and overwrites x.
    unsafe {
        dgetrs_(
            &N,
            &ni,
            &INC,
            a.as_ptr().add(at),
            &ld,
            ipiv.as_ptr(),
            x.as_mut_ptr(),
            &ni,
            &mut info,
            1,
        )
    };
    info == 0
}

/// x ← L⁻¹ x, or L⁻ᵀ x when `transposed` (dtrsv), L the lower triangle of
/// the n × n block at the start of `a` (leading dimension `lda`); false
/// when a block does not fit.
pub fn trsv_lower(transposed: bool, a: &[f64], lda: usize, n: usize, x: &mut [f64]) -> bool {
    let (Some(ni), Some(ld)) = (int(n), int(lda)) else {
        return false;
    };
    if !inside(a.len(), lda, 0, n, n) || x.len() < n {
        return false;
    }
    let trans = if transposed { T } else { N };
    // SAFETY: L lies inside `a` and `x` holds n entries (checked above).
    unsafe {
        dtrsv_(
            &L,
            &trans,
            &N,
            &ni,
            a.as_ptr(),
            &ld,
            x.as_mut_ptr(),
            &INC,
            1,
            1,
            1,
        )
    };
    true
}

/// y ← y − A x, or y − Aᵀ x when `transposed` (dgemv), A the m × n block
/// at `at` of `a` (leading dimension `lda`); false when a block does not
/// fit.
#[allow(clippy::too_many_arguments)]
pub fn gemv_minus(
    transposed: bool,
    a: &[f64],
    lda: usize,
    at: usize,
    m: usize,
    n: usize,
    x: &[f64],
    y: &mut [f64],
) -> bool {
    let (Some(mi), Some(ni), Some(ld)) = (int(m), int(n), int(lda)) else {
        return false;
    };
    let (xs, ys) = if transposed { (m, n) } else { (n, m) };
    if !inside(a.len(), lda, at, m, n) || x.len() < xs || y.len() < ys {
        return false;
    }
    let trans = if transposed { T } else { N };
    // SAFETY: A lies inside `a`, `x` and `y` hold the entries op(A) reads
    // and writes (checked above), and they are distinct slices.
    unsafe {
        dgemv_(
            &trans,
            &mi,
            &ni,
            &MINUS,
            a.as_ptr().add(at),
            &ld,
            x.as_ptr(),
            &INC,
            &ONE,
            y.as_mut_ptr(),
            &INC,
            1,
        )
    };
    true
}

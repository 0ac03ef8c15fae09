//! The bulk stiffness factored once with a MUMPS Schur complement on the
//! contact DOFs, which solves (K + Kc) x = b exactly when Kc is non-zero
//! only on those DOFs.
//!
//! With C the contact candidate DOFs and I the rest, MUMPS factors K_II
//! and returns S0 = K_CC − K_CI K_II⁻¹ K_IC (dense). A Jacobian J = K + Kc
//! has the Schur complement S0 + Kc_CC, so each new contact tangent Kc
//! costs a dense factorisation of |C|² entries instead of a sparse one of
//! the whole matrix; MatSolve on the MUMPS factor then condenses the
//! right-hand side on C, solves with the dense factors held in the factor
//! matrix, and expands back. The preconditioner is set up from Kc alone
//! (the operator SNES hands it holds only the contact tangent; K is in the
//! factor), so nothing of the size of K is copied per Jacobian. PETSc
//! supports Schur complements of MUMPS on one process only.
//!
//! A symmetric Jacobian's dense part costs less than |C|³/3 flops: C is
//! ordered by a key the caller gives (decreasing; the solve layer's is the
//! distance to the other body, so the contact zone comes last), S0's
//! leading block up to a little before the first DOF a tangent touches is
//! factored once ([`PartialCholesky`], `partial.rs`), and each later tangent factors the
//! trailing block alone, in place in the Schur matrix PETSc solves with. A
//! tangent that makes S indefinite falls back to LDLᵀ of the whole S
//! (LAPACK's dsytrf, as every factorisation did before; the first one too).
//!
//! A non-symmetric tangent (friction, a mortar pair on a deformable
//! master) keeps K's symmetric factor (the Schur path's bodies are linear
//! elastic) and the same split, with the trailing block LU-factored
//! ([`PartialLu`]). PETSc's Schur solve reads only its own dense factors,
//! so that solve is ours, and the factor matrix's Schur array holds a
//! reference S_ref = S0 + σ I (σ the mean of S0's diagonal), factored once:
//! MatSolve then gives x_ref = J_ref⁻¹ b for J_ref = K + σ P Pᵀ (P the
//! columns of the identity on C), and J x = b is
//!
//!   (S0 + D) x_C = S_ref x_ref,C,  x = x_ref + J_ref⁻¹ P S_ref (x_C − x_ref,C)
//!
//! (both sides' condensed right-hand side is b_C − K_CI K_II⁻¹ b_I, and
//! J_ref⁻¹ P S_ref v is [−K_II⁻¹ K_IC v; v]): two sparse solves and one
//! dense. The correction's right-hand side holds S_ref, never D: with the
//! equivalent J_ref⁻¹ (b − P (D − σ I) x_C) a penalty 10⁶ times the
//! default made D x_C carry x_C's roundoff times |D|/σ into the soft
//! J_ref⁻¹ (the mortar patch test's force 4 % off). S_ref is positive
//! definite where S0 is only semi-definite (a body held by contact alone).
use super::layout::Layout;
use super::partial::{PartialCholesky, PartialLu};
use crate::petsc::{Factor, Matrix, PetscError, PetscInt, Result, Vector};
use std::rc::Rc;

/// K factored with a dense Schur complement on the DOFs `c`.
pub struct SchurFactor {
    factor: Factor,
    /// C, its Schur order and S0 (shared with the condensed Newton state).
    layout: Rc<Layout>,
    /// The contact tangent is symmetric (else the LU path, see the module).
    symmetric: bool,
    /// The entries of the last tangent (Schur positions): S = S0 + these.
    tangent: Vec<(usize, usize, f64)>,
    /// Symmetric only: S0's leading block factored, once per split.
    partial: Option<PartialCholesky>,
    /// Non-symmetric only: S = S0 + D factored, and σ of the reference
    /// S_ref = S0 + σ I in the factor matrix's Schur array (None: not yet
    /// factored).
    lu: PartialLu,
    reference: Option<f64>,
    /// S0's leading block was not positive definite: LDLᵀ from now on.
    partial_refused: bool,
    /// The split whose leading columns the factor matrix's Schur array
    /// holds now (so a new tangent writes the trailing block only).
    in_array: Option<usize>,
    pub counts: DenseCounts,
}

/// How the dense Schur complements were factored.
#[derive(Debug, Clone, Copy, Default)]
pub struct DenseCounts {
    /// Factorisations of the trailing block alone (Cholesky; LU for a
    /// non-symmetric tangent).
    pub trailing: usize,
    /// The largest trailing block, in DOFs.
    pub largest_trailing: usize,
    /// Factorisations of S0's leading block (one per split).
    pub leading: usize,
    /// Factorisations of the whole S by PETSc (LDLᵀ: the first, and where
    /// the trailing block was not positive definite; the reference S_ref
    /// of a non-symmetric tangent).
    pub whole: usize,
}

impl DenseCounts {
    pub fn add(&mut self, o: DenseCounts) {
        self.trailing += o.trailing;
        self.largest_trailing = self.largest_trailing.max(o.largest_trailing);
        self.leading += o.leading;
        self.whole += o.whole;
    }
}

/// The Schur order of the sorted DOFs `c` by decreasing `key` (DOFs
/// without a key first, in DOF order; ties in DOF order).
fn by_key(c: &[PetscInt], key: &[(PetscInt, f64)]) -> Vec<PetscInt> {
    let of = |d: PetscInt| {
        key.binary_search_by_key(&d, |e| e.0)
            .map_or(f64::INFINITY, |i| key[i].1)
    };
    let mut order: Vec<(f64, PetscInt)> = c.iter().map(|&d| (of(d), d)).collect();
    order.sort_by(|a, b| b.0.total_cmp(&a.0).then(a.1.cmp(&b.1)));
    order.into_iter().map(|e| e.1).collect()
}

impl SchurFactor {
    /// Factors `k` (assembled, sequential, symmetric, the rows and columns
    /// of the sorted DOFs `constrained` replaced by the identity) as LDLᵀ
    /// with the Schur complement on the sorted, distinct DOFs `c`, for
    /// contact tangents that are `symmetric` or not. `key` (sorted by DOF)
    /// orders C for the partial dense factorisations: the DOFs a contact
    /// tangent is likely to touch should have the smallest keys.
    pub fn new(
        k: &Matrix,
        c: Vec<PetscInt>,
        constrained: &[PetscInt],
        symmetric: bool,
        key: &[(PetscInt, f64)],
    ) -> Result<Self> {
        if c.is_empty() || c.windows(2).any(|w| w[0] >= w[1]) {
            return Err(PetscError::new(
                "SchurFactor::new",
                "the Schur DOFs must be sorted, distinct and not empty".into(),
            ));
        }
        let n = c.len();
        let fixed_sorted: Vec<bool> = c
            .iter()
            .map(|d| constrained.binary_search(d).is_ok())
            .collect();
        let order = by_key(&c, key);
        let mut pos = vec![0; n];
        let mut fixed = vec![false; n];
        for (p, d) in order.iter().enumerate() {
            let i = c.binary_search(d).map_err(|_| {
                PetscError::new("SchurFactor::new", "the Schur order lost a DOF".into())
            })?;
            pos[i] = p;
            fixed[p] = fixed_sorted[i];
        }
        let factor = Factor::cholesky_with_schur(k, &order)?;
        let mut me = SchurFactor {
            factor,
            layout: Rc::new(Layout {
                c,
                pos,
                fixed,
                base: Vec::new(),
            }),
            symmetric,
            tangent: Vec::new(),
            partial: None,
            lu: PartialLu::default(),
            reference: None,
            partial_refused: false,
            in_array: None,
            counts: DenseCounts::default(),
        };
        me.factor.factor(k)?;
        me.check_factor_error()?;
        let mut base = me.factor.schur_complement()?;
        symmetrise(&mut base, n);
        if let Some(layout) = Rc::get_mut(&mut me.layout) {
            layout.base = base;
        }
        Ok(me)
    }

    /// MUMPS reports a failed factorisation (a singular K_II, say) through
    /// the factor's error type, not the call's code.
    fn check_factor_error(&self) -> Result<()> {
        if let Some(err) = self.factor.error_type()? {
            return Err(PetscError::new(
                "MatFactorGetError",
                format!("the MUMPS factorisation of the bulk stiffness with a Schur complement on {} contact DOFs failed (error type {err})", self.layout.c.len()),
            ));
        }
        Ok(())
    }

    /// The Schur DOFs (sorted).
    pub fn dofs(&self) -> &[PetscInt] {
        &self.layout.c
    }

    /// C, its Schur order and S0.
    pub fn layout(&self) -> &Rc<Layout> {
        &self.layout
    }

    /// `(S0 + D) v` for `v` in Schur positions, D the last tangent.
    pub fn times_schur(&self, v: &[f64]) -> Vec<f64> {
        let mut out = self.layout.times_base(v);
        for &(r, c, d) in &self.tangent {
            out[r] += d * v[c];
        }
        out
    }

    /// Solves with the factored dense Schur complement alone: `rhs` and
    /// `sol` in Schur positions (vectors of |C| entries).
    pub fn solve_schur(&self, rhs: &Vector, sol: &mut Vector) -> Result<()> {
        if !self.symmetric {
            let mut v = rhs.with_array(<[f64]>::to_vec)?;
            self.solve_lu(&mut v)?;
            return sol.with_array_mut(|a| a.copy_from_slice(&v));
        }
        // The Schur complement the last `update` factored (PETSc factors
        // it first otherwise).
        self.factor.solve_schur(rhs, sol)
    }

    /// The contact tangent's entries in C × C as (row, column, value) in
    /// Schur positions, without constrained rows and columns and zeros.
    fn tangent_entries(&self, kc: &Matrix) -> Result<Vec<(usize, usize, f64)>> {
        let mut out = Vec::new();
        let l = &*self.layout;
        let (c, pos, fixed) = (&l.c, &l.pos, &l.fixed);
        kc.for_rows(c.iter().copied(), |row, cols, vals| {
            let Ok(i) = c.binary_search(&row) else {
                return Ok(());
            };
            let r = pos[i];
            if fixed[r] {
                return Ok(());
            }
            for (&col, &v) in cols.iter().zip(vals) {
                if v == 0.0 {
                    continue;
                }
                if let Ok(j) = c.binary_search(&col) {
                    if !fixed[pos[j]] {
                        out.push((r, pos[j], v));
                    }
                }
            }
            Ok(())
        })?;
        Ok(out)
    }

    /// Sets the dense Schur complement to that of K + `kc` and factors it:
    /// `kc` is the contact tangent alone (non-zero only in C × C; its
    /// entries in constrained rows and columns are ignored, as the
    /// Jacobian's Dirichlet replacement would drop them).
    pub fn update(&mut self, kc: &Matrix) -> Result<()> {
        let d = self.tangent_entries(kc)?;
        if !self.symmetric {
            self.lu_update(&d)?;
            self.tangent = d;
            return Ok(());
        }
        if self.trailing_update(&d)? {
            self.tangent = d;
            return Ok(());
        }
        let n = self.layout.c.len();
        let mut dense = self.layout.base.clone();
        for &(r, c, v) in &d {
            dense[c * n + r] += v;
        }
        // Not known to be definite: LDLᵀ (or LU) of the whole matrix.
        self.factor_whole(&dense)?;
        self.counts.whole += 1;
        self.tangent = d;
        Ok(())
    }

    /// The symmetric fast path: S0's leading block factored (again only
    /// when a tangent touches a DOF before its split), the trailing block
    /// with the tangent factored into the Schur matrix's array. False when
    /// it does not apply: the first factorisation (PETSc has not installed
    /// its solve yet), a tangent without entries, or an S that is not
    /// positive definite.
    fn trailing_update(&mut self, d: &[(usize, usize, f64)]) -> Result<bool> {
        let n = self.layout.c.len();
        // The first factorisation is PETSc's own (it installs the dense
        // solve); the first contact tangent is often a first touch, smaller
        // than the zone the later ones settle on, so the split waits for
        // the second. Without contact coupling S is S0: factored whole.
        if !self.factor.schur_is_factored() || self.partial_refused || d.is_empty() {
            return Ok(false);
        }
        let first = d.iter().map(|&(r, c, _)| r.min(c)).min().unwrap_or(n);
        if self.partial.as_ref().is_none_or(|p| p.split() > first) {
            let split = split_before(first, n);
            self.in_array = None;
            self.partial = PartialCholesky::new(&self.layout.base, n, split);
            self.partial_refused = self.partial.is_none();
            self.counts.leading += 1;
        }
        let Some(partial) = &self.partial else {
            return Ok(false);
        };
        let split = partial.split();
        let leading = self.in_array != Some(split);
        let mut ok = false;
        // PETSc's dense solve reads the array as the Cholesky factor.
        self.factor.write_schur_cholesky(|arr| {
            ok = partial.factor_into(d, arr, leading);
        })?;
        if !ok {
            self.in_array = None;
            return Ok(false);
        }
        self.in_array = Some(split);
        self.counts.trailing += 1;
        self.counts.largest_trailing = self.counts.largest_trailing.max(n - split);
        Ok(true)
    }

    /// PETSc's factorisation of the whole dense S = `dense`: LDLᵀ (dsytrf,
    /// S need not be definite), its old factors cleared (also the fast
    /// path's Cholesky ones).
    fn factor_whole(&mut self, dense: &[f64]) -> Result<()> {
        self.in_array = None;
        self.factor.set_schur_complement(dense)
    }

    /// x = (K + Kc)⁻¹ b with the Kc of the last [`Self::update`] (K with
    /// its Dirichlet replacement, Kc without the constrained rows and
    /// columns).
    pub fn solve(&self, b: &Vector, x: &mut Vector) -> Result<()> {
        let Some(sigma) = self.reference.filter(|_| !self.symmetric) else {
            return self.sparse_solve(b, x);
        };
        // The reference solve, then the correction (see the module).
        self.sparse_solve(b, x)?;
        let l = &*self.layout;
        let x_ref = x.with_array(|a| l.gather(a))?;
        let times_reference = |v: &[f64]| {
            let mut out = l.times_base(v);
            for (p, o) in out.iter_mut().enumerate() {
                if !l.fixed[p] {
                    *o += sigma * v[p];
                }
            }
            out
        };
        let mut x_c = times_reference(&x_ref);
        self.solve_lu(&mut x_c)?;
        let delta: Vec<f64> = x_c.iter().zip(&x_ref).map(|(a, r)| a - r).collect();
        let w = times_reference(&delta);
        let mut rhs = b.duplicate()?;
        rhs.set_all(0.0)?;
        rhs.with_array_mut(|a| {
            for (&d, &p) in l.c.iter().zip(&l.pos) {
                a[d as usize] = w[p];
            }
        })?;
        let mut y = b.duplicate()?;
        self.sparse_solve(&rhs, &mut y)?;
        x.axpy(1.0, &y)
    }

    /// MatSolve with the factor: J⁻¹ b for the Jacobian whose Schur
    /// complement the factor matrix's array holds.
    fn sparse_solve(&self, b: &Vector, x: &mut Vector) -> Result<()> {
        // Its Schur complement set and factored by `update` (MatSolve
        // factors it first otherwise).
        self.factor.solve(b, x)
    }

    /// The non-symmetric path's set-up: the reference factored into the
    /// factor matrix once, then S0 + D by [`PartialLu`] with the split
    /// chosen as on the symmetric path.
    fn lu_update(&mut self, d: &[(usize, usize, f64)]) -> Result<()> {
        let n = self.layout.c.len();
        if self.reference.is_none() {
            let sigma = self.layout.mean_free_diagonal();
            let mut dense = self.layout.base.clone();
            for p in (0..n).filter(|&p| !self.layout.fixed[p]) {
                dense[p * n + p] += sigma;
            }
            self.factor_whole(&dense)?;
            self.counts.whole += 1;
            self.reference = Some(sigma);
        }
        let first = d.iter().map(|&(r, c, _)| r.min(c)).min().unwrap_or(n);
        if self.partial.as_ref().is_none_or(|p| p.split() > first) {
            let split = split_before(first, n);
            let base = &self.layout.base;
            self.partial =
                PartialCholesky::new(base, n, split).or_else(|| PartialCholesky::new(base, n, 0));
            self.counts.leading += 1;
        }
        let Some(partial) = &self.partial else {
            return Err(PetscError::new(
                "SchurFactor::update",
                format!("the contact Schur complement's order ({n} DOFs) does not fit LAPACK"),
            ));
        };
        if !partial.factor_lu_into(d, &mut self.lu) {
            return Err(PetscError::new(
                "SchurFactor::update",
                format!("the contact Schur complement on {n} DOFs is singular (LU of its trailing {} DOFs)", n - partial.split()),
            ));
        }
        self.counts.trailing += 1;
        self.counts.largest_trailing = self.counts.largest_trailing.max(n - partial.split());
        Ok(())
    }

    /// `v` (Schur positions) ← S⁻¹ v with the non-symmetric path's factor.
    fn solve_lu(&self, v: &mut [f64]) -> Result<()> {
        if self.lu.solve(v) {
            return Ok(());
        }
        Err(PetscError::new(
            "SchurFactor::solve",
            "the dense Schur complement is not factored".into(),
        ))
    }
}

/// Where S0's leading block ends for a tangent whose first touched Schur
/// position is `first` (of `n`): room for the touched tail t to grow by a
/// quarter before the leading block must be factored again. A first touch
/// grows (hertz line b/40: the tail from 324 to 504 DOFs between the first
/// two tangents), which costs a refactorisation of the leading block, but
/// every Jacobian pays the trailing block's (1.25 t)³: with room to double,
/// sphere-block's mortar pair (t ≈ 600 of 1,317 DOFs) factored 1,188 DOFs
/// per Newton iteration, 742 now, and took 1.28 against 1.12 CPU s; the
/// line meshes and hertz-cylinder did not move (docs/performance.md).
fn split_before(first: usize, n: usize) -> usize {
    first.saturating_sub((n - first) / 4)
}

/// The Schur complement of an LDLᵀ factorisation may come with one
/// triangle filled and the other zero: the zero one becomes the mirror of
/// the other (the dense Cholesky reads the lower one, and the contact part
/// added later is added to both).
fn symmetrise(a: &mut [f64], n: usize) {
    let (mut lower, mut upper) = (false, false);
    for j in 0..n {
        for i in 0..n {
            let filled = a[j * n + i] != 0.0;
            lower |= filled && i > j;
            upper |= filled && i < j;
        }
    }
    if lower == upper {
        return;
    }
    for j in 0..n {
        for i in (j + 1)..n {
            if lower {
                a[i * n + j] = a[j * n + i];
            } else {
                a[j * n + i] = a[i * n + j];
            }
        }
    }
}

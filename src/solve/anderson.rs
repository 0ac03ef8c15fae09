//! Anderson acceleration of the Uzawa fixed-point iteration λ ← G(λ),
//! G(λ) = ⟨λ − εN gN(u(λ))⟩ (`[solver] uzawa_acceleration`).
//!
//! Uzawa contracts the multipliers by a nearly fixed factor an iteration
//! (hertz-sphere h = 0.35: relative change 2.4e-2, 1.1e-2, 4.4e-3, 1.4e-3,
//! 3.2e-4), which is what a secant method removes: with the residuals
//! f_i = G(λ_i) − λ_i of the last `depth` + 1 iterates, the next iterate is
//! G(λ_k) − Σ γ_i ΔG_i, γ minimising |f_k − Σ γ_i Δf_i| (type II, depth 1
//! is the secant / Irons–Tuck step). The result is projected as the plain
//! update is: a point the plain update opened (G_j = 0) stays open, every
//! other multiplier is kept non-negative; so the active set is always the
//! plain update's.
//!
//! Safeguard: when the residual at an accelerated iterate is not below the
//! last one, the history is dropped and the plain update stands. The
//! kernel is pure: the global sums it needs come through `reduce`, which
//! sums its argument over the ranks (every rank then takes the same γ).

/// Largest depth the settings accept: the reduction carries the Gram
/// matrix, 1 + depth + depth (depth + 1) / 2 numbers.
pub const MAX_DEPTH: usize = 3;
/// Numbers of one reduction at `MAX_DEPTH`.
pub const REDUCED: usize = 1 + MAX_DEPTH + MAX_DEPTH * (MAX_DEPTH + 1) / 2;

/// Largest |γ_i| taken. Depth 1 on a contraction by ρ gives γ = −ρ / (1 − ρ):
/// the sphere's updates gave −0.12 to −0.19, but where Uzawa stalls (graded
/// line b/40, ρ ≈ 0.8 near the tolerance) γ reached −3.4, the jump changed
/// the active set and its Newton solve took 6 iterations instead of 1
/// (11 → 15 Newton in all); b/5 −10.2. The bound keeps the extrapolation
/// within one plain update's length per history entry.
pub const MAX_GAMMA: f64 = 1.0;

/// The history of one Uzawa loop's multiplier sequence.
#[derive(Debug, Clone, Default)]
pub struct Anderson {
    depth: usize,
    /// G and f of the last iterate.
    last: Option<(Vec<f64>, Vec<f64>)>,
    /// ΔG_i and Δf_i, oldest first.
    dg: Vec<Vec<f64>>,
    df: Vec<Vec<f64>>,
    /// |f| of the last iterate (global).
    last_norm: f64,
    /// Accelerated iterates taken and safeguard resets, for the report.
    pub taken: usize,
    pub resets: usize,
}

impl Anderson {
    /// `depth` 0: off (`next` always keeps the plain update).
    pub fn new(depth: usize) -> Self {
        Anderson {
            depth: depth.min(MAX_DEPTH),
            ..Anderson::default()
        }
    }

    pub fn is_on(&self) -> bool {
        self.depth > 0
    }

    /// Forgets the history: the map G changed (a penalty was raised, the
    /// soft first iteration ended).
    pub fn forget(&mut self) {
        self.last = None;
        self.dg.clear();
        self.df.clear();
    }

    /// One Uzawa update: `lambda` the iterate the Newton solve used, `g`
    /// its plain update G(λ), `counted` whether an entry enters the global
    /// sums (owned by this rank). Returns the accelerated next iterate, or
    /// None when the plain update `g` stands.
    pub fn next(
        &mut self,
        lambda: &[f64],
        g: &[f64],
        counted: &[bool],
        reduce: &mut dyn FnMut([f64; REDUCED]) -> [f64; REDUCED],
    ) -> Option<Vec<f64>> {
        if self.depth == 0 {
            return None;
        }
        let f: Vec<f64> = g.iter().zip(lambda).map(|(g, l)| g - l).collect();
        match self.last.take() {
            Some((g0, f0)) if g0.len() == g.len() => {
                self.dg
                    .push(g.iter().zip(&g0).map(|(a, b)| a - b).collect());
                self.df
                    .push(f.iter().zip(&f0).map(|(a, b)| a - b).collect());
                if self.df.len() > self.depth {
                    self.dg.remove(0);
                    self.df.remove(0);
                }
            }
            _ => self.forget(),
        }
        let m = self.df.len();
        // One reduction: |f|², Δf_i·f, Δf_i·Δf_j (i ≤ j).
        let mut local = [0.0; REDUCED];
        let dot = |a: &[f64], b: &[f64]| -> f64 {
            a.iter()
                .zip(b)
                .zip(counted)
                .filter(|(_, c)| **c)
                .map(|((x, y), _)| x * y)
                .sum()
        };
        local[0] = dot(&f, &f);
        let mut n = 1 + m;
        for i in 0..m {
            local[1 + i] = dot(&self.df[i], &f);
            for j in i..m {
                local[n] = dot(&self.df[i], &self.df[j]);
                n += 1;
            }
        }
        let total = reduce(local);
        let norm = total[0].sqrt();
        let grew = m > 0 && (norm.is_nan() || norm >= self.last_norm);
        self.last_norm = norm;
        self.last = Some((g.to_vec(), f));
        if grew {
            // The last step (accelerated or not) did not reduce the
            // residual: restart from the plain update.
            self.dg.clear();
            self.df.clear();
            self.resets += 1;
            return None;
        }
        let mut gamma = least_squares(m, &total)?;
        let largest = gamma.iter().fold(0.0_f64, |a, g| a.max(g.abs()));
        if largest > MAX_GAMMA {
            gamma.iter_mut().for_each(|g| *g *= MAX_GAMMA / largest);
        }
        let next: Vec<f64> = g
            .iter()
            .enumerate()
            .map(|(j, &gj)| {
                if gj <= 0.0 {
                    return 0.0;
                }
                let shift: f64 = gamma.iter().zip(&self.dg).map(|(c, d)| c * d[j]).sum();
                (gj - shift).max(0.0)
            })
            .collect();
        self.taken += 1;
        Some(next)
    }
}

/// γ of the normal equations H γ = b (H_ij = Δf_i·Δf_j, b_i = Δf_i·f) from
/// the reduced numbers; None with no history, or when H is singular to
/// working precision (the plain update stands then).
// Index loops read as the textbook Cholesky factorisation they are.
#[allow(clippy::needless_range_loop)]
fn least_squares(m: usize, total: &[f64; REDUCED]) -> Option<Vec<f64>> {
    if m == 0 {
        return None;
    }
    let mut h = vec![vec![0.0; m]; m];
    let mut n = 1 + m;
    for i in 0..m {
        for j in i..m {
            h[i][j] = total[n];
            h[j][i] = total[n];
            n += 1;
        }
    }
    let mut b: Vec<f64> = total[1..=m].to_vec();
    // Cholesky in place; a pivot below 1e-12 of its diagonal means the
    // differences are (nearly) dependent.
    for i in 0..m {
        let diag = h[i][i];
        for k in 0..i {
            h[i][i] -= h[i][k] * h[i][k];
        }
        if h[i][i].is_nan() || h[i][i] <= 1e-12 * diag {
            return None;
        }
        h[i][i] = h[i][i].sqrt();
        for r in i + 1..m {
            for k in 0..i {
                h[r][i] -= h[r][k] * h[i][k];
            }
            h[r][i] /= h[i][i];
        }
    }
    for i in 0..m {
        for k in 0..i {
            b[i] -= h[i][k] * b[k];
        }
        b[i] /= h[i][i];
    }
    for i in (0..m).rev() {
        for k in i + 1..m {
            b[i] -= h[k][i] * b[k];
        }
        b[i] /= h[i][i];
    }
    b.iter().all(|v| v.is_finite()).then_some(b)
}

#[cfg(test)]
mod tests;

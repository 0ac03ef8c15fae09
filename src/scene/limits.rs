//! Upper bounds on the counts a scene gives. Each count sets a loop length
//! or an allocation; far beyond any useful value it is a typo (an extra
//! zero, a number pasted into the wrong key), and accepting it would turn
//! into hours of solving, an out-of-memory abort, or an integer that PETSc
//! (32-bit indices here) wraps to a negative value.

/// Load steps: every step is a full nonlinear solve and one entry in the
/// result file, its XDMF sidecar and its CSV history; a million steps of the
/// smallest scene already take days. A load increment of 1e-6 of the total
/// is below anything a load path needs.
pub const MAX_STEPS: usize = 1_000_000;

/// Newton iterations per attempt: a Newton solve that has not converged in
/// ten thousand iterations will not (it converges quadratically near the
/// answer; the defaults need fewer than 30).
pub const MAX_NEWTON: usize = 10_000;

/// Uzawa rounds per step: each round is a full Newton solve (default 30).
pub const MAX_UZAWA: usize = 10_000;

/// Cutbacks: each halves the load increment. With at most [`MAX_STEPS`]
/// steps, 30 halvings leave an increment of 1e-6 · 2⁻³⁰ ≈ 9e-16, still
/// above the spacing of doubles near a load factor of 1 (2.2e-16); more
/// would make steps that no longer move the load factor at all.
pub const MAX_CUTBACKS: usize = 30;

/// `what = value` must not exceed `limit`.
pub fn at_most(what: &str, value: usize, limit: usize) -> Result<(), String> {
    if value <= limit {
        Ok(())
    } else {
        Err(format!("{what} = {value} is above the limit of {limit}"))
    }
}

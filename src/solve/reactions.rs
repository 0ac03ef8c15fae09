//! Support reactions of a converged step: the total force of every
//! Dirichlet set, and the reaction field with the unconstrained rows zeroed
//! (what the output writes).
use super::boundary::Dirichlet;
use crate::error::Result;
use crate::parallel;
use crate::petsc::Vector;
use mpi::traits::*;

/// Collective: the total reaction of each Dirichlet set, summed over ranks,
/// from the raw residual `raw` (owned rows, starting at global DOF `start`).
fn reaction_totals(
    world: &impl Communicator,
    dirichlet: &Dirichlet,
    raw: &Vector,
    start: usize,
) -> Result<Vec<(String, [f64; 3])>> {
    let local = raw.with_array(|a| dirichlet.reaction_sums(a, start))?;
    let total: Vec<f64> = local
        .iter()
        .flat_map(|s| parallel::sum(world, *s))
        .collect();
    Ok(dirichlet
        .set_names
        .iter()
        .enumerate()
        .map(|(i, n)| {
            (
                n.clone(),
                [total[3 * i], total[3 * i + 1], total[3 * i + 2]],
            )
        })
        .collect())
}

/// Collective: [`reaction_totals`] of the raw residual `reaction`, which is
/// then cut to its constrained rows ([`zero_unconstrained`]).
pub(super) fn support_reactions(
    world: &impl Communicator,
    dirichlet: &Dirichlet,
    reaction: &mut Vector,
    start: usize,
) -> Result<Vec<(String, [f64; 3])>> {
    let totals = reaction_totals(world, dirichlet, reaction, start)?;
    zero_unconstrained(reaction, dirichlet)?;
    Ok(totals)
}

/// Keeps the constrained rows of `reaction` only (the rest is the
/// equilibrium residual, zero up to the tolerance).
fn zero_unconstrained(reaction: &mut Vector, dirichlet: &Dirichlet) -> Result<()> {
    reaction.with_array_mut(|a| {
        let mut keep = vec![false; a.len()];
        for d in &dirichlet.dofs {
            keep[d.owned_index] = true;
        }
        for (v, k) in a.iter_mut().zip(keep) {
            if !k {
                *v = 0.0;
            }
        }
    })?;
    Ok(())
}

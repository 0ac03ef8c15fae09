//! What a run tells its caller: the report of every converged step and of
//! the whole run, the contact fields a step hands to its `StepSink`, and
//! the step line `-v` prints.
use super::dynamics::DynamicsReport;
use super::phases::PhaseTimes;
use crate::contact::fields::PairOutput;
use crate::contact::PairForce;
use crate::contact::{ContactPair, UzawaStats};
use crate::dofs::DofMap;
use crate::error::Result;
use crate::parallel;
use crate::petsc::Vector;
use mpi::traits::*;

/// What a contact pair did in one converged step (figures over all ranks).
#[derive(Debug, Clone)]
pub struct ContactReport {
    pub name: String,
    /// Total contact force on the slave surface.
    pub force: [f64; 3],
    /// Normal force Σ pN w and tangential force Σ |tT| w (contact frame).
    pub normal_force: f64,
    pub tangential_force: f64,
    pub max_penetration: f64,
    /// Active constraints (what the pair's formulation counts).
    pub active_points: usize,
    /// What `active_points` counts (`contact::Traits::unit`): "points" or
    /// "nodes".
    pub active_what: &'static str,
    /// Active points that slide (friction).
    pub sliding_points: usize,
    pub penalty: f64,
    /// A pair with a deformable master: facets held per rank (min, max
    /// over ranks), facets received per rank (max) and the whole master.
    pub master_held: Option<[usize; 4]>,
}

/// What one converged load increment did.
#[derive(Debug, Clone)]
pub struct StepReport {
    pub index: usize,
    pub load_factor: f64,
    pub newton_iterations: usize,
    pub uzawa_iterations: usize,
    pub linear_iterations: usize,
    pub residual_norm: f64,
    /// Residual norms of every Newton iteration of the step's last solve.
    pub residual_history: Vec<f64>,
    pub cutbacks: usize,
    pub wall_seconds: f64,
    /// Total reaction force of each Dirichlet set (summed over ranks).
    pub reactions: Vec<(String, [f64; 3])>,
    pub contact: Vec<ContactReport>,
    /// Time, energy and momentum (dynamics only).
    pub dynamics: Option<DynamicsReport>,
    /// Seconds per phase in this step on this rank (the output phase of
    /// the step itself is booked to the next step's report).
    pub phases: PhaseTimes,
}

/// The result of a run: per-step reports and the final displacement.
pub struct RunReport {
    pub steps: Vec<StepReport>,
    pub global_dofs: usize,
    pub wall_seconds: f64,
    /// Final displacement in natural node order (N×3 flat) on rank 0; empty
    /// on the other ranks, so that no rank but 0 holds an array of the
    /// global node count.
    pub displacement: Vec<f64>,
    pub bulk_tangent_assemblies: usize,
    pub pattern_builds: usize,
    /// Preconditioner rebuilds and reuses decided by the active-set watch
    /// (`lagging`; both 0 when it is off).
    pub preconditioner_builds: usize,
    pub preconditioner_reuses: usize,
    /// The contact Schur path's figures (None: not taken).
    pub schur: Option<crate::linsolve::SchurSummary>,
    /// Seconds per phase over the run, the largest over the ranks.
    pub phases: PhaseTimes,
    /// Halo volume, summed over ranks: ghost displacement values refreshed
    /// before every residual/Jacobian, and ghost multiplier values refreshed
    /// after every Uzawa update.
    pub halo_displacements: usize,
    pub halo_multipliers: usize,
}

/// This rank's contact values of one pair at a converged step, for output.
pub struct PairFields<'a> {
    pub pair: &'a ContactPair,
    pub output: PairOutput,
}

/// Receives every converged step (the output file, a progress printer, ...).
pub trait StepSink {
    fn step(
        &mut self,
        report: &StepReport,
        displacement: &Vector,
        reaction: &Vector,
        contact: &[PairFields],
        nodal_pressure: &[f64],
        velocity: Option<&Vector>,
    ) -> Result<()>;
}

/// Collective: each pair's report of a converged step, forces summed over ranks.
pub(super) fn contact_reports(
    world: &impl Communicator,
    pairs: &[ContactPair],
    forces: &[PairForce],
    stats: &[UzawaStats],
) -> Vec<ContactReport> {
    pairs
        .iter()
        .zip(forces)
        .enumerate()
        .map(|(i, (p, f))| {
            let total = PairForce::from_array(parallel::sum(world, f.to_array()));
            let s = stats.get(i).copied().unwrap_or_default();
            let master_held = p.held_facets().map(|h| {
                let (held, whole, received) = (h.held, h.whole, h.received as f64);
                let [neg_min, max, max_received] =
                    parallel::max(world, [-(held as f64), held as f64, received]);
                [
                    -neg_min as usize,
                    max as usize,
                    max_received as usize,
                    whole,
                ]
            });
            ContactReport {
                master_held,
                name: p.spec.name.clone(),
                force: total.force,
                normal_force: total.normal,
                tangential_force: total.tangential,
                max_penetration: s.max_penetration,
                active_points: s.active,
                active_what: p.traits().unit,
                sliding_points: s.sliding,
                penalty: p.penalty(),
            }
        })
        .collect()
}

/// Nodal contact pressure of the owned nodes (all pairs), PETSc node order.
pub(super) fn nodal_pressure(dofs: &DofMap, pairs: &[ContactPair]) -> Result<Vec<f64>> {
    let n = dofs.num_owned_nodes();
    let (mut num, mut den) = (vec![0.0; n], vec![0.0; n]);
    for p in pairs {
        p.add_nodal_pressure(&mut num, &mut den)?;
    }
    Ok(num
        .iter()
        .zip(&den)
        .map(|(a, b)| if *b > 0.0 { a / b } else { 0.0 })
        .collect())
}

/// The `-v` line of a converged step (rank 0 prints it).
pub(super) fn print_step(s: &StepReport) {
    let hist: Vec<String> = s
        .residual_history
        .iter()
        .map(|r| format!("{r:.2e}"))
        .collect();
    println!(
        "step {:4}  load {:.4}  newton {:2}  uzawa {:2}  ksp {:4}  |R| {:.3e}  {:.2}s  [{}]",
        s.index,
        s.load_factor,
        s.newton_iterations,
        s.uzawa_iterations,
        s.linear_iterations,
        s.residual_norm,
        s.wall_seconds,
        hist.join(" ")
    );
    if let Some(d) = &s.dynamics {
        println!(
            "     t = {:.6e}: kinetic {:.6e}, strain {:.6e}, total {:.6e}, momentum [{:.6e}, {:.6e}, {:.6e}]",
            d.time, d.kinetic, d.strain, d.kinetic + d.strain, d.momentum[0], d.momentum[1], d.momentum[2]
        );
    }
    for c in &s.contact {
        println!(
            "     contact {}: force [{:.6e}, {:.6e}, {:.6e}], normal {:.6e}, tangential {:.6e}, {} active {} ({} sliding), max penetration {:.3e} h, penalty {:.3e}",
            c.name, c.force[0], c.force[1], c.force[2], c.normal_force, c.tangential_force, c.active_points, c.active_what, c.sliding_points, c.max_penetration, c.penalty
        );
        if let Some([min, max, received, whole]) = c.master_held {
            println!(
                "     master of {}: facets held per rank {min}..{max} of {whole} (received at most {received})",
                c.name
            );
        }
    }
}

//! What a run starts from: the residual and Jacobian callbacks with the
//! reuse choices the model allows, the time stepper of a dynamic run, the
//! initial state (zero or a restart file's step), and each time step's
//! Newmark set-up.
use super::boundary::Dirichlet;
use super::dynamics::TimeStepper;
use super::lagging::PreconditionerLag;
use super::mechanics::Mechanics;
use super::newmark::Coefficients;
use super::setup::TangentKind;
use super::stiffness::KeepStiffness;
use super::RestartState;
use crate::assembly::{BulkAssembler, SurfaceLoads};
use crate::contact::ContactPair;
use crate::distribution::LocalMesh;
use crate::dofs::{DofMap, DIM};
use crate::error::{Error, Result};
use crate::model::Model;
use crate::parallel;
use crate::petsc::{Matrix, Vector};
use mpi::topology::SimpleCommunicator;

/// The parts of a `Simulation` the residual and Jacobian read.
pub(super) struct Parts<'a> {
    pub(super) dofs: &'a DofMap,
    pub(super) bulk: &'a BulkAssembler,
    pub(super) loads: &'a SurfaceLoads,
    pub(super) dirichlet: &'a Dirichlet,
}

/// The residual and Jacobian callbacks of the model, with the
/// preconditioner watch and the fixed body force b(X) when they apply.
pub(super) fn mechanics<'a>(
    model: &Model,
    tangent: TangentKind,
    parts: Parts<'a>,
    contact: &'a mut [ContactPair],
    jac: &Matrix,
    local: &LocalMesh,
) -> Result<Mechanics<'a>> {
    let Parts {
        dofs,
        bulk,
        loads,
        dirichlet,
    } = parts;
    // Nothing is ever added to K (no contact, inertia or follower load):
    // the Jacobian is K itself, no second matrix. A pressure set may lie on
    // some ranks only, and the choice decides collective calls: agreed.
    let follower = parallel::any_rank(&SimpleCommunicator::world(), loads.has_follower());
    let constant = contact.is_empty() && model.dynamics.is_none() && !follower;
    let keep = match (model.solver.reuse.linear_stiffness, constant) {
        (false, _) => KeepStiffness::No,
        // The first contact search builds the Jacobian its own pattern, so
        // set-up's, of the bulk pattern and still without values, can hold
        // K (line b/10: 1.1e8 of 1.95e9 instructions in the solve were
        // K's own pattern).
        (true, false) if !contact.is_empty() => KeepStiffness::SeparateIn(jac),
        (true, false) => KeepStiffness::Separate,
        (true, true) => KeepStiffness::InJacobian(jac),
    };
    let mut mech = Mechanics::new(
        dofs,
        bulk,
        loads,
        dirichlet,
        contact,
        model.body_force.clone(),
        keep,
    )?;
    // Above the direct limit the preconditioner is GMRES + AMG.
    let iterative = DIM * dofs.num_global_nodes() > model.solver.direct_max_dofs;
    // Linear bodies on the direct path take the contact Schur path, whose
    // Newton runs on the condensed system (no step end positions at hand):
    // shortened steps would part it from the whole-vector Newton it must
    // match (frictional hertz-cylinder: 25 against 24 iterations).
    mech.state_change_steps = !tangent.linear_bulk || iterative;
    // Only with linear bodies is the tangent fixed while the active set
    // is (a hyperelastic tangent changes every iteration anyway).
    if !mech.contact.is_empty()
        && tangent.linear_bulk
        && model.solver.reuse.preconditioner
        && model.solver.reuse.active_set
    {
        mech.lag = Some(if iterative {
            PreconditionerLag::iterative()
        } else {
            PreconditionerLag::default()
        });
    }
    if let Some(b) = &model.body_force_fn {
        let mut f = vec![0.0; DIM * dofs.num_local_nodes()];
        bulk.add_body_force_fn(&local.nodes, b.as_ref(), &mut f)?;
        mech.fixed_external = Some(f);
    }
    Ok(mech)
}

/// Implicit dynamics: the time stepper, and the inertia term it hands to
/// the callbacks (None: quasi-static load stepping).
pub(super) fn time_stepper(
    model: &Model,
    mech: &mut Mechanics,
    local: &LocalMesh,
) -> Result<Option<TimeStepper>> {
    let Some(spec) = &model.dynamics else {
        return Ok(None);
    };
    let (stepper, inertia) = TimeStepper::new(spec, model.steps, local, mech.dofs, mech.bulk)?;
    mech.inertia = Some(inertia);
    Ok(Some(stepper))
}

/// Collective: the displacement the run starts from, the index of the last
/// step done and its load factor: zero, or a restart file's step taken over
/// (with every pair's multipliers and friction history).
pub(super) fn initial_state(
    world: &SimpleCommunicator,
    dofs: &DofMap,
    restart: Option<&RestartState>,
    pairs: &mut [ContactPair],
) -> Result<(Vector, usize, f64)> {
    let mut x = Vector::new_mpi(dofs.num_owned_dofs())?;
    x.set_block_size(DIM)?;
    x.set_all(0.0)?;
    let (first_step, done) = match restart {
        Some(state) => {
            parallel::agree(world, state.take_over(dofs, &mut x, pairs))?;
            (state.step, state.load_factor)
        }
        None => (0, 0.0),
    };
    Ok((x, first_step, done))
}

/// Sets up one time step from load factor `from` to `to`: the Newmark
/// coefficients for its Δt, the inertia term, and the slip rate of every
/// frictional pair.
pub(super) fn prepare_time_step(
    stepper: &mut TimeStepper,
    mech: &mut Mechanics,
    from: f64,
    to: f64,
) -> Result<Coefficients> {
    let dt = (to - from) * stepper.t_end;
    let c = stepper.coefficients(to - from);
    let inertia = mech
        .inertia
        .as_mut()
        .ok_or_else(|| Error::Internal("dynamics without inertia".into()))?;
    stepper.prepare(&c, inertia)?;
    for pair in mech.contact.iter_mut().filter(|p| p.has_friction()) {
        let (a, b) = (pair.rigid_shift(from), pair.rigid_shift(to));
        let rigid_velocity = [0, 1, 2].map(|i| (b[i] - a[i]) / dt);
        pair.set_slip_rate(Some(stepper.slip_rate(&c, dt, rigid_velocity)?));
    }
    Ok(c)
}

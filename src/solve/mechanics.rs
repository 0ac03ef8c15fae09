//! The discrete equilibrium R(u) = f_int(u) − f_ext(u) + r_contact(u; λ) = 0
//! that SNES solves at one load factor with the contact multipliers λ fixed,
//! with Dirichlet rows replaced by u − ū.
use super::boundary::Dirichlet;
use super::dynamics::Inertia;
use super::lagging::PreconditionerLag;
use super::master_tail::{extended, MasterTail};
use super::phases::{Phase, PhaseTimes, Stages};
use super::state_change;
use super::stiffness::{self, KeepStiffness, LiftWork, LinearStiffness};
use crate::assembly::{BulkAssembler, SurfaceLoads};
use crate::contact::ContactPair;
use crate::dofs::{DofMap, DIM};
use crate::error::{Error, Result};
use crate::linsolve::Condensed;
use crate::parallel::{self, fault, fault::FaultPhase};
use crate::petsc::snes::CallbackError;
use crate::petsc::{GhostedVector, Matrix, NonlinearProblem, Vector};
use mpi::topology::SimpleCommunicator;
use mpi::traits::Communicator;

/// Everything the residual and Jacobian need, plus the work vectors that hold
/// the ghosted state between callbacks.
pub struct Mechanics<'a> {
    pub dofs: &'a DofMap,
    pub bulk: &'a BulkAssembler,
    pub loads: &'a SurfaceLoads,
    pub dirichlet: &'a Dirichlet,
    pub contact: &'a mut [ContactPair],
    /// Constant body force per body (per unit reference volume) at full load.
    pub body_force: Vec<[f64; 3]>,
    /// A fixed external force (local form) at full load, e.g. a manufactured
    /// body force; scaled by the load factor.
    pub fixed_external: Option<Vec<f64>>,
    pub factor: f64,
    /// Dynamics: the inertia term of the current time step (None: static).
    pub inertia: Option<Inertia>,
    /// Time spent per phase in these callbacks (this rank).
    pub times: PhaseTimes,
    /// Rebuild the preconditioner only on active-set changes (None: SNES's
    /// own lag setting decides).
    pub lag: Option<PreconditionerLag>,
    /// Rebuild the preconditioner at every Jacobian (the contact Schur
    /// path, where a rebuild is a small dense factorisation): each linear
    /// solve is then exact. Set exactly when the Schur preconditioner is
    /// installed, so the Jacobian matrix then holds only the contact
    /// tangent: K is in the preconditioner's factor, and nothing else
    /// reads the operator (the linear solve is the preconditioner alone).
    pub always_rebuild: bool,
    /// End backtracking steps where the last contact constraint changes
    /// between open and closed (`state_change`): with hyperelastic bodies,
    /// or on the Krylov path.
    pub state_change_steps: bool,
    /// Newton on the condensed contact system (the Schur paths'; see
    /// `linsolve`): while its step is active
    /// the SNES vector is the condensed one and so is the residual.
    pub condensed: Option<Condensed>,
    stages: Stages,
    /// The callbacks agree their outcome over these ranks (PETSc's world).
    world: SimpleCommunicator,
    u: GhostedVector,
    r: GhostedVector,
    /// Bulk stiffness when every body is linear: assembled once, reused.
    linear_k: Option<LinearStiffness>,
    /// With a separate K: the Jacobian matrix last seen and K on its pattern.
    k_on_pattern: Option<(Matrix, Matrix)>,
    work: Vector,
    /// Held master nodes this rank does not see, and their displacements at
    /// the last loaded state.
    tail: MasterTail,
    u_tail: Vec<f64>,
    /// Counters, for reports and for checking what is (not) recomputed.
    pub residual_evaluations: usize,
    pub jacobian_evaluations: usize,
    pub bulk_tangent_assemblies: usize,
}

impl<'a> Mechanics<'a> {
    pub fn new(
        dofs: &'a DofMap,
        bulk: &'a BulkAssembler,
        loads: &'a SurfaceLoads,
        dirichlet: &'a Dirichlet,
        contact: &'a mut [ContactPair],
        body_force: Vec<[f64; 3]>,
        keep: KeepStiffness<'_>,
    ) -> Result<Self> {
        let ghosts = dofs.ghost_dofs();
        let u = GhostedVector::new(dofs.num_owned_dofs(), &ghosts)?;
        let r = GhostedVector::new(dofs.num_owned_dofs(), &ghosts)?;
        let work = u.global().duplicate()?;
        let mut me = Mechanics {
            dofs,
            bulk,
            loads,
            dirichlet,
            contact,
            body_force,
            fixed_external: None,
            factor: 0.0,
            inertia: None,
            times: PhaseTimes::default(),
            lag: None,
            always_rebuild: false,
            state_change_steps: false,
            condensed: None,
            stages: Stages::register()?,
            world: SimpleCommunicator::world(),
            u,
            r,
            linear_k: None,
            k_on_pattern: None,
            work,
            tail: MasterTail::new(dofs.num_owned_dofs()),
            u_tail: Vec::new(),
            residual_evaluations: 0,
            jacobian_evaluations: 0,
            bulk_tangent_assemblies: 0,
        };
        if bulk.is_linear() {
            me.linear_k = match keep {
                KeepStiffness::No => None,
                KeepStiffness::InJacobian(j) => Some(LinearStiffness::Shared(stiffness::shared(
                    j,
                    me.u.global(),
                )?)),
                KeepStiffness::Separate => {
                    me.bulk_tangent_assemblies += 1;
                    Some(LinearStiffness::Separate(stiffness::separate(dofs, bulk)?))
                }
                KeepStiffness::SeparateIn(fresh) => {
                    me.bulk_tangent_assemblies += 1;
                    Some(LinearStiffness::Separate(stiffness::separate_in(
                        fresh, dofs, bulk,
                    )?))
                }
            };
        }
        Ok(me)
    }

    /// The linear bulk stiffness K when it is kept in a matrix of its own.
    pub fn separate_stiffness(&self) -> Option<&Matrix> {
        match &self.linear_k {
            Some(LinearStiffness::Separate(k)) => Some(k),
            _ => None,
        }
    }

    fn load_state(&mut self, x: &Vector) -> Result<()> {
        let u = &mut self.u;
        self.stages.time(Phase::HaloExchange, &mut self.times, || {
            u.global_mut().copy_from(x)?;
            u.update_ghosts()
        })?;
        let tail = &mut self.tail;
        self.u_tail = self
            .stages
            .time(Phase::HaloExchange, &mut self.times, || tail.values(x))?;
        Ok(())
    }

    /// The master exchange of every pair at `x`, then the tail
    /// scatter for the facets now held. Collective.
    pub fn exchange_masters(&mut self, x: &Vector) -> Result<()> {
        let dofs = self.dofs;
        let ranks = crate::assembly::MpiRanks(SimpleCommunicator::world());
        self.with_state(x, |u, pairs| {
            let u = &u[..DIM * dofs.num_local_nodes()];
            let mut base = 0;
            for p in pairs.iter_mut() {
                base += p.exchange_master(u, dofs, base, &ranks);
            }
            Ok(())
        })?;
        self.tail.refresh(&self.world, self.contact)?;
        self.load_state(x)
    }

    /// Dynamics: extends each frictional pair's velocity map over the tail,
    /// from `offset` (the map's offset in the DOF layout). Collective.
    pub fn extend_slip_rates(&mut self, offset: &Vector) -> Result<()> {
        let tail = self.tail.values(offset)?;
        let n = DIM * self.dofs.num_local_nodes();
        for pair in self.contact.iter_mut() {
            if let Some(rate) = pair.slip_rate_mut() {
                rate.offset.truncate(n);
                rate.offset.extend_from_slice(&tail);
            }
        }
        Ok(())
    }

    /// Runs `f` on the ghosted local form of `x` (owned + ghost displacements)
    /// and the contact pairs: searches, Uzawa updates and output use it.
    pub fn with_state<T>(
        &mut self,
        x: &Vector,
        f: impl FnOnce(&[f64], &mut [ContactPair]) -> Result<T>,
    ) -> Result<T> {
        self.load_state(x)?;
        let contact = &mut *self.contact;
        let tail = &self.u_tail;
        self.u.with_local(|u| f(&extended(u, tail), contact))?
    }

    /// f_int − f_ext + r_contact at `x`, without the Dirichlet replacement
    /// (its constrained entries are the reactions).
    ///
    /// Collective, and never left early past a collective call: when this
    /// rank's assembly fails (an inverted cell, non-finite values) it still
    /// takes part in the ghost accumulation and the products after it, and
    /// returns its local failure at the end (not agreed: callers agree it).
    pub fn raw_residual(&mut self, x: &Vector, out: &mut Vector) -> Result<()> {
        self.bulk_residual(x, out, false)
    }

    /// [`Self::raw_residual`]; `free_rows_only`: its constrained entries
    /// may be anything (the Dirichlet replacement follows), which lets a
    /// Jacobian that is K give the bulk term.
    fn bulk_residual(&mut self, x: &Vector, out: &mut Vector, free_rows_only: bool) -> Result<()> {
        let lift_local = self.prepare_shared(x, free_rows_only)?;
        self.load_state(x)?;
        let (bulk, loads, factor) = (self.bulk, self.loads, self.factor);
        let linear = match &self.linear_k {
            Some(LinearStiffness::Separate(_)) => true,
            Some(LinearStiffness::Shared(_)) => free_rows_only,
            None => false,
        };
        let body_force = &self.body_force;
        let fixed = self.fixed_external.as_deref();
        let contact = &mut *self.contact;
        let u = &self.u;
        let u_tail = &self.u_tail;
        let mut r_tail = vec![0.0; u_tail.len()];
        let (stages, times) = (self.stages, &mut self.times);
        let local = self.r.with_local_mut(|r_local| -> Result<()> {
            r_local.fill(0.0);
            u.with_local(|u_local| -> Result<()> {
                stages.time(Phase::BulkAssembly, times, || -> Result<()> {
                    fault::check(FaultPhase::BulkResidual)?;
                    if !linear {
                        bulk.add_internal_force(u_local, r_local)?;
                    }
                    loads.add_external_force(u_local, factor, -1.0, r_local)?;
                    bulk.add_body_force(body_force, -factor, r_local)?;
                    if let Some(f) = fixed {
                        for (r, f) in r_local.iter_mut().zip(f) {
                            *r -= factor * f;
                        }
                    }
                    Ok(())
                })?;
                stages.time(Phase::ContactAssembly, times, || -> Result<()> {
                    fault::check(FaultPhase::ContactAssembly)?;
                    if u_tail.is_empty() {
                        for pair in contact.iter_mut() {
                            pair.add_residual(u_local, factor, r_local)?;
                        }
                        return Ok(());
                    }
                    // Held master nodes this rank does not see: their
                    // entries go to their owners after the ghost sum.
                    let u_ext = extended(u_local, u_tail);
                    let mut r_ext = extended(r_local, &r_tail);
                    for pair in contact.iter_mut() {
                        pair.add_residual(&u_ext, factor, &mut r_ext)?;
                    }
                    let n = r_local.len();
                    r_local.copy_from_slice(&r_ext[..n]);
                    r_tail.copy_from_slice(&r_ext[n..]);
                    Ok(())
                })
            })?
        })?;
        // Non-finite local values (a NaN load, an overflowing material law)
        // are this rank's failure too, found before they spread to others.
        let local = local.and_then(|()| {
            self.r
                .with_local(|r_local| first_nonfinite(r_local, "residual"))?
        });
        let r = &mut self.r;
        stages.time(Phase::HaloExchange, times, || r.accumulate_ghosts())?;
        out.copy_from(self.r.global())?;
        let tail = &self.tail;
        stages.time(Phase::HaloExchange, times, || tail.add_into(&r_tail, out))?;
        let (linear_k, work, inertia) = (&mut self.linear_k, &mut self.work, &mut self.inertia);
        stages.time(Phase::BulkAssembly, times, || -> Result<()> {
            match linear_k {
                Some(LinearStiffness::Separate(k)) => {
                    k.mult(x, work)?;
                    out.axpy(1.0, work)?;
                }
                Some(LinearStiffness::Shared(k)) if free_rows_only => {
                    k.add_product(x, out, work)?;
                }
                _ => {}
            }
            if let Some(inertia) = inertia {
                inertia.add_force(x, out)?;
            }
            Ok(())
        })?;
        local.and(lift_local)
    }

    /// Collective, with a Jacobian that is K and `free_rows_only`: K in
    /// place, and the lift formed again when some rank's constrained values
    /// moved since (agreed: forming it is collective). It overwrites the
    /// ghosted pair, so it comes before the state is loaded; its local
    /// failure is returned inside.
    fn prepare_shared(&mut self, x: &Vector, free_rows_only: bool) -> Result<Result<()>> {
        let Some(LinearStiffness::Shared(k)) = &mut self.linear_k else {
            return Ok(Ok(()));
        };
        if !free_rows_only {
            return Ok(Ok(()));
        }
        if k.ensure(self.dofs, self.bulk, self.dirichlet)? {
            self.bulk_tangent_assemblies += 1;
        }
        let stale = k.lift_stale(x, self.dirichlet)?;
        if !parallel::any_rank(&self.world, stale) {
            return Ok(Ok(()));
        }
        let work = LiftWork {
            dirichlet: self.dirichlet,
            bulk: self.bulk,
            u: &mut self.u,
            r: &mut self.r,
        };
        k.form_lift(x, work)
    }

    /// ‖R(x)‖ with the Dirichlet rows replaced, as SNES sees it: the first
    /// residual of a load step. The outcome is agreed over all ranks; a
    /// domain error (an inverted cell on any rank) sends the step to the
    /// cutback path like a failed Newton solve.
    pub fn residual_norm(
        &mut self,
        x: &Vector,
        work: &mut Vector,
    ) -> std::result::Result<f64, CallbackError> {
        let local = self.residual_impl(x, work);
        let norm = work
            .norm2()
            .map_err(|e| CallbackError::Fatal(e.to_string()));
        self.agree(local)?;
        norm
    }

    fn residual_impl(&mut self, x: &Vector, r: &mut Vector) -> Result<()> {
        self.residual_evaluations += 1;
        if let Some(c) = self.condensed.clone() {
            if c.is_active() {
                return self.condensed_residual(&c, x, r);
            }
        }
        let local = self.bulk_residual(x, r, true);
        let factor = self.factor;
        let dirichlet = self.dirichlet;
        x.with_array(|xa| r.with_array_mut(|ra| dirichlet.constrain_residual(xa, ra, factor)))??;
        local
    }

    /// The residual at the condensed vector `x`: the contact residual
    /// assembled as in [`Self::bulk_residual`], the rest from the
    /// condensed state (dense work on C where the whole vector needs a
    /// product with K). Collective.
    fn condensed_residual(&mut self, c: &Condensed, x: &Vector, r: &mut Vector) -> Result<()> {
        if let Some(x0) = c.base_wanted() {
            let x0 = x0?;
            let mut rc0 = x0.duplicate()?;
            // Not a residual of its own: no fault visit.
            let local = self.contact_residual(&x0, &mut rc0, false);
            c.set_base_contact(&rc0)?;
            local?;
        }
        let (stages, times) = (self.stages, &mut self.times);
        let bulk = stages.time(Phase::BulkAssembly, times, || {
            fault::check(FaultPhase::BulkResidual)
        });
        let mut rc = x.duplicate()?;
        let contact = self.contact_residual(x, &mut rc, true);
        let (stages, times) = (self.stages, &mut self.times);
        let condensed = stages.time(Phase::BulkAssembly, times, || c.residual(x, &rc, r));
        bulk.and(contact).and(condensed.map_err(Into::into))?;
        r.with_array(|a| first_nonfinite(a, "residual"))?
    }

    /// The contact pairs' residual alone at `x`, summed over the ranks
    /// (held master nodes a rank does not see go to their owners);
    /// `faults`: a visit of the contact-assembly fault phase. Collective:
    /// a local failure is returned after the sums.
    fn contact_residual(&mut self, x: &Vector, out: &mut Vector, faults: bool) -> Result<()> {
        self.load_state(x)?;
        let factor = self.factor;
        let (u, u_tail, contact) = (&self.u, &self.u_tail, &mut *self.contact);
        let mut r_tail = vec![0.0; u_tail.len()];
        let (stages, times) = (self.stages, &mut self.times);
        let local = stages.time(Phase::ContactAssembly, times, || {
            self.r.with_local_mut(|r_local| -> Result<()> {
                r_local.fill(0.0);
                u.with_local(|u_local| -> Result<()> {
                    if faults {
                        fault::check(FaultPhase::ContactAssembly)?;
                    }
                    let u_ext = extended(u_local, u_tail);
                    let mut r_ext = extended(r_local, &r_tail);
                    for pair in contact.iter_mut() {
                        pair.add_residual(&u_ext, factor, &mut r_ext)?;
                    }
                    let n = r_local.len();
                    r_local.copy_from_slice(&r_ext[..n]);
                    r_tail.copy_from_slice(&r_ext[n..]);
                    Ok(())
                })?
            })?
        });
        let r = &mut self.r;
        stages.time(Phase::HaloExchange, times, || r.accumulate_ghosts())?;
        out.copy_from(self.r.global())?;
        let tail = &self.tail;
        stages.time(Phase::HaloExchange, times, || tail.add_into(&r_tail, out))?;
        local
    }

    /// The Jacobian at `x`. Collective, and like [`Self::raw_residual`] never
    /// left early past a collective call (the whole-matrix additions and the
    /// final assembly run on every rank whatever this rank's part did).
    fn jacobian_impl(&mut self, x: &Vector, j: &mut Matrix) -> Result<()> {
        self.jacobian_evaluations += 1;
        if let Some(LinearStiffness::Shared(_)) = self.linear_k {
            return self.shared_jacobian(j);
        }
        if self.always_rebuild {
            return self.contact_jacobian(x, j);
        }
        self.load_state(x)?;
        self.stages.time(Phase::BulkAssembly, &mut self.times, || {
            stiffness_on_pattern(&self.linear_k, &mut self.k_on_pattern, j)
        })?;
        let (bulk, loads, dofs, factor) = (self.bulk, self.loads, self.dofs, self.factor);
        let (stages, times) = (self.stages, &mut self.times);
        let (u, inertia, linear_k) = (&self.u, &self.inertia, &self.linear_k);
        let k_on_pattern = &self.k_on_pattern;
        let u_tail = &self.u_tail;
        let bulk_part = stages.time(Phase::BulkAssembly, times, || -> Result<Result<bool>> {
            // K copied in on the Jacobian's own pattern (a copy of values,
            // where adding K of a smaller pattern went entry by entry).
            match k_on_pattern {
                Some((_, kj)) => j.copy_from(kj)?,
                None => j.zero_entries()?,
            }
            // Whole-matrix additions (MatAXPY, collective) need the assembled
            // matrix, so they come before any element values are set.
            if let Some(inertia) = inertia {
                j.add_scaled_subset(inertia.a_u, &inertia.mass)?;
            }
            // From here on only this rank's values: a failure is kept for the end.
            let mut local = || -> Result<bool> {
                fault::check(FaultPhase::Jacobian)?;
                let assembled = linear_k.is_none();
                if assembled {
                    u.with_local(|u_local| bulk.add_tangent(u_local, j))??;
                }
                if loads.has_follower() {
                    u.with_local(|u_local| loads.add_tangent(u_local, factor, j))??;
                }
                Ok(assembled)
            };
            Ok(local())
        })?;
        let contact = &mut *self.contact;
        let local = match bulk_part {
            Ok(assembled) => {
                if assembled {
                    self.bulk_tangent_assemblies += 1;
                }
                stages.time(Phase::ContactAssembly, times, || {
                    u.with_local(|u_local| -> Result<()> {
                        fault::check(FaultPhase::ContactAssembly)?;
                        let u_ext = extended(u_local, u_tail);
                        for pair in contact.iter_mut() {
                            pair.add_tangent(&u_ext, factor, j)?;
                        }
                        Ok(())
                    })?
                })
            }
            Err(e) => Err(e),
        };
        if fault::fires(FaultPhase::LinearSolve) {
            // A NaN on one of this rank's diagonal entries: the linear solve
            // itself fails, on every rank, as with a broken material tangent.
            poison_diagonal(dofs, self.dirichlet, j)?;
        }
        let rows = self.dirichlet.global_rows();
        stages.time(Phase::BulkAssembly, times, || -> Result<()> {
            j.assemble()?;
            j.zero_rows_columns_identity(&rows)?;
            Ok(())
        })?;
        local
    }

    /// The contact Schur path's operator: the contact tangent alone, on the
    /// Jacobian's pattern, without the Dirichlet replacement (the
    /// preconditioner drops constrained rows and columns itself). Collective
    /// like [`Self::jacobian_impl`].
    fn contact_jacobian(&mut self, x: &Vector, j: &mut Matrix) -> Result<()> {
        self.load_state(x)?;
        let (dofs, factor) = (self.dofs, self.factor);
        let (stages, times) = (self.stages, &mut self.times);
        let (u, u_tail, contact) = (&self.u, &self.u_tail, &mut *self.contact);
        stages.time(Phase::BulkAssembly, times, || j.zero_entries())?;
        let local = stages.time(Phase::ContactAssembly, times, || {
            u.with_local(|u_local| -> Result<()> {
                fault::check(FaultPhase::Jacobian)?;
                fault::check(FaultPhase::ContactAssembly)?;
                let u_ext = extended(u_local, u_tail);
                for pair in contact.iter_mut() {
                    pair.add_tangent(&u_ext, factor, j)?;
                }
                Ok(())
            })?
        });
        if fault::fires(FaultPhase::LinearSolve) {
            poison_diagonal(dofs, self.dirichlet, j)?;
        }
        stages.time(Phase::BulkAssembly, times, || j.assemble())?;
        local
    }

    /// The Jacobian when it is K: already in place (and left untouched, so
    /// the preconditioner sees an unchanged operator), unless an injected
    /// fault spoiled it, which every rank then assembles again.
    fn shared_jacobian(&mut self, j: &mut Matrix) -> Result<()> {
        let Some(LinearStiffness::Shared(k)) = &mut self.linear_k else {
            return Ok(());
        };
        let local = fault::check(FaultPhase::Jacobian);
        if k.ensure(self.dofs, self.bulk, self.dirichlet)? {
            self.bulk_tangent_assemblies += 1;
        }
        let poison = fault::fires(FaultPhase::LinearSolve);
        if parallel::any_rank(&self.world, poison) {
            if poison {
                poison_diagonal(self.dofs, self.dirichlet, j)?;
            }
            j.assemble()?;
            k.ready = false;
        }
        local
    }

    /// Collective: this rank's callback outcome made every rank's. Local
    /// assembly failures (inverted cells, non-finite values, injected
    /// faults) are domain errors, which cut the step back; anything else
    /// stops the run. The message names the lowest failing rank.
    fn agree(&self, local: Result<()>) -> std::result::Result<(), CallbackError> {
        const DOMAIN: i32 = 1;
        const FATAL: i32 = 2;
        let failure = local.err().map(|e| {
            let code = match e {
                Error::Element { .. } | Error::NonFinite(_) | Error::Fault(_) => DOMAIN,
                _ => FATAL,
            };
            (code, e.to_string())
        });
        let Some(f) = parallel::agree_failure(&self.world, failure) else {
            return Ok(());
        };
        let message = if self.world.size() > 1 {
            format!("rank {}: {}", f.rank, f.message)
        } else {
            f.message
        };
        Err(match f.code {
            DOMAIN => CallbackError::Domain(message),
            _ => CallbackError::Fatal(message),
        })
    }
}

/// Collective: K on the pattern of the Jacobian `j` (kept with a handle on
/// `j`, so a new Jacobian matrix is told apart from the old one), formed
/// again when `j` is a new matrix; None without a separate K.
fn stiffness_on_pattern(
    linear_k: &Option<LinearStiffness>,
    slot: &mut Option<(Matrix, Matrix)>,
    j: &Matrix,
) -> Result<()> {
    let Some(LinearStiffness::Separate(k)) = linear_k else {
        *slot = None;
        return Ok(());
    };
    if slot.as_ref().is_some_and(|(for_j, _)| for_j.same_as(j)) {
        return Ok(());
    }
    *slot = None;
    let mut kj = j.duplicate()?;
    kj.zero_entries()?;
    kj.add_scaled_subset(1.0, k)?;
    *slot = Some((j.share()?, kj));
    Ok(())
}

/// Adds NaN to the diagonal of this rank's first unconstrained row.
fn poison_diagonal(dofs: &DofMap, dirichlet: &Dirichlet, j: &mut Matrix) -> Result<()> {
    let constrained: std::collections::HashSet<usize> =
        dirichlet.dofs.iter().map(|d| d.owned_index).collect();
    let free = (0..dofs.num_owned_dofs()).find(|i| !constrained.contains(i));
    if let Some(i) = free {
        let row = crate::petsc::to_petsc_int(dofs.owned_dof_start() + i)?;
        j.add_block(&[row], &[row], &[f64::NAN])?;
    }
    Ok(())
}

/// `Err` naming the first non-finite entry of this rank's local `values`.
fn first_nonfinite(values: &[f64], what: &str) -> Result<()> {
    match values.iter().position(|v| !v.is_finite()) {
        None => Ok(()),
        Some(i) => Err(Error::NonFinite(format!(
            "{what} (local DOF {i}: {})",
            values[i]
        ))),
    }
}

impl Mechanics<'_> {
    /// [`state_change::fraction`] of the Newton step `x → x − y` on this
    /// rank. Collective (ghost updates of both states).
    fn state_change_step(&mut self, x: &Vector, y: &Vector) -> Result<Option<f64>> {
        let u0 = self.with_state(x, |u, _| Ok(u.to_vec()))?;
        let mut x1 = x.duplicate()?;
        x1.copy_from(x)?;
        x1.axpy(-1.0, y)?;
        let factor = self.factor;
        self.with_state(&x1, |u1, pairs| {
            Ok(state_change::fraction(pairs, &u0, u1, factor))
        })
    }
}

impl NonlinearProblem for Mechanics<'_> {
    fn residual(&mut self, x: &Vector, r: &mut Vector) -> std::result::Result<(), CallbackError> {
        let local = self.residual_impl(x, r);
        self.agree(local)
    }

    fn jacobian(&mut self, x: &Vector, j: &mut Matrix) -> std::result::Result<(), CallbackError> {
        let local = self.jacobian_impl(x, j);
        if self.jacobian_evaluations == 1 {
            // Before the first preconditioner set-up, which comes next.
            crate::memory::checkpoint("first Jacobian");
        }
        self.agree(local)
    }

    /// See [`state_change`].
    fn step_fraction(
        &mut self,
        x: &Vector,
        y: &Vector,
    ) -> std::result::Result<Option<f64>, CallbackError> {
        // The same on every rank: the pairs are the scene's, the condensed
        // state is switched collectively.
        let condensed = self.condensed.as_ref().is_some_and(|c| c.is_active());
        if condensed
            || !self.state_change_steps
            || !self.contact.iter().any(|p| p.traits().state_change_steps)
        {
            return Ok(None);
        }
        let local = self.state_change_step(x, y);
        let fraction = match &local {
            Ok(Some(f)) => *f,
            _ => -1.0,
        };
        self.agree(local.map(|_| ()))?;
        let [agreed] = crate::parallel::agree::max(&self.world, [fraction]);
        Ok((agreed >= 0.0).then_some(state_change::past(agreed)))
    }

    fn rebuild_preconditioner(&mut self, last_linear_iterations: usize) -> Option<bool> {
        if self.always_rebuild {
            return Some(true);
        }
        let lag = self.lag.as_mut()?;
        let signatures: Vec<u64> = self
            .contact
            .iter()
            .map(ContactPair::tangent_signature)
            .collect();
        let world = mpi::topology::SimpleCommunicator::world();
        Some(lag.decide(&world, &signatures, last_linear_iterations))
    }
}

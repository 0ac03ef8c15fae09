//! Implicit dynamics around the same step: Newmark in displacement form
//! (see `newmark`), so each time step is a load step whose residual gains
//! the inertia `M a(u)` and whose tangent gains `M/(βΔt²)`. The consistent
//! mass matrix is assembled once; a static scene never builds it.
//!
//! Friction in dynamics measures slip from the relative velocity, which the
//! integrator makes affine in `u` (`v = γ/(βΔt) u + …`): the pairs get that
//! map ([`SlipRate`]) and their tangent then carries the friction damping
//! contribution `γ/(βΔt) ∂f/∂v` (docs/formulation.md §8).
use super::newmark::Coefficients;
use crate::assembly::BulkAssembler;
use crate::assembly::PatternBuilder;
use crate::contact::SlipRate;
use crate::distribution::LocalMesh;
use crate::dofs::{DofMap, DIM};
use crate::error::{Error, Result};
use crate::model::DynamicsSpec;
use crate::petsc::{GhostedVector, Matrix, Vector};
use mpi::traits::*;

/// The inertia term of the current step: `M (a_u u + offset)` with
/// `offset = a_v v_n + a_a a_n − a_u u_n`.
pub struct Inertia {
    pub mass: Matrix,
    pub a_u: f64,
    pub offset: Vector,
    pub work: Vector,
    /// a(x), kept so every residual evaluation reuses one vector.
    acceleration: Vector,
}

impl Inertia {
    /// Adds `M a(x)` to `out`.
    pub fn add_force(&mut self, x: &Vector, out: &mut Vector) -> Result<()> {
        let acc = &mut self.acceleration;
        acc.copy_from(x)?;
        acc.scale(self.a_u)?;
        acc.axpy(1.0, &self.offset)?;
        self.mass.mult(acc, &mut self.work)?;
        out.axpy(1.0, &self.work)?;
        Ok(())
    }
}

/// Energy and momentum after a step (totals over all ranks).
#[derive(Debug, Clone, Copy, Default)]
pub struct DynamicsReport {
    pub time: f64,
    pub kinetic: f64,
    /// Stored elastic energy of the bodies (contact penalty energy excluded).
    pub strain: f64,
    /// Total linear momentum `Σ M v`.
    pub momentum: [f64; 3],
}

/// The integrator's state between steps: displacement, velocity and
/// acceleration of the last converged step (owned parts).
pub struct TimeStepper {
    pub spec: DynamicsSpec,
    /// `t_end = steps × Δt`: the load factor is `t / t_end`.
    pub t_end: f64,
    u_n: Vector,
    v_n: Vector,
    a_n: Vector,
    ghosted: GhostedVector,
}

impl TimeStepper {
    /// Assembles the mass matrix and the initial state: u = 0, v = each
    /// body's initial velocity, a = 0 (the scene starts unloaded: loads and
    /// amplitudes start from zero, so M a₀ = f(0) − f_int(0) = 0).
    pub fn new(
        spec: &DynamicsSpec,
        steps: usize,
        mesh: &LocalMesh,
        dofs: &DofMap,
        bulk: &BulkAssembler,
    ) -> Result<(Self, Inertia)> {
        let mut pattern = PatternBuilder::new(dofs.num_owned_dofs(), DIM)?;
        bulk.add_pattern(&mut pattern)?;
        let mut mass = pattern.build()?;
        bulk.add_mass(&mesh.nodes, &spec.density, &mut mass)?;
        mass.assemble()?;
        let mut u_n = Vector::new_mpi(dofs.num_owned_dofs())?;
        u_n.set_block_size(DIM)?;
        u_n.set_all(0.0)?;
        let a_n = u_n.duplicate()?;
        let mut v_n = u_n.duplicate()?;
        v_n.with_array_mut(|v| {
            for (l, &b) in mesh.owned_body.iter().enumerate() {
                if let Some(v0) = spec.initial_velocity.get(b as usize) {
                    v[DIM * l..DIM * l + DIM].copy_from_slice(v0);
                }
            }
        })?;
        let mut a0 = a_n.duplicate()?;
        a0.set_all(0.0)?;
        let ghosted = GhostedVector::new(dofs.num_owned_dofs(), &dofs.ghost_dofs())?;
        let inertia = Inertia {
            a_u: 0.0,
            offset: u_n.duplicate()?,
            work: u_n.duplicate()?,
            acceleration: u_n.duplicate()?,
            mass,
        };
        Ok((
            TimeStepper {
                spec: spec.clone(),
                t_end: spec.time_step * steps as f64,
                u_n,
                v_n,
                a_n: a0,
                ghosted,
            },
            inertia,
        ))
    }

    pub fn coefficients(&self, load_increment: f64) -> Coefficients {
        Coefficients::new(&self.spec.newmark, load_increment * self.t_end)
    }

    /// Sets the inertia term for a step with coefficients `c`.
    pub fn prepare(&self, c: &Coefficients, inertia: &mut Inertia) -> Result<()> {
        inertia.a_u = c.a_u;
        combine(
            &mut inertia.offset,
            [(-c.a_u, &self.u_n), (c.a_v, &self.v_n), (c.a_a, &self.a_n)],
        )
    }

    /// The velocity map `v = v_u u + offset` in local (owned + ghost) form,
    /// for frictional pairs; `rigid_velocity` is a rigid master's velocity.
    pub fn slip_rate(
        &mut self,
        c: &Coefficients,
        dt: f64,
        rigid_velocity: [f64; 3],
    ) -> Result<SlipRate> {
        let (u_n, v_n, a_n) = (&self.u_n, &self.v_n, &self.a_n);
        combine(
            self.ghosted.global_mut(),
            [(-c.v_u, u_n), (c.v_v, v_n), (c.v_a, a_n)],
        )?;
        self.ghosted.update_ghosts()?;
        let offset = self.ghosted.with_local(|a| a.to_vec())?;
        Ok(SlipRate {
            dt,
            dv_du: c.v_u,
            offset,
            rigid_velocity,
        })
    }

    /// The offset of the last [`Self::slip_rate`] in the DOF layout.
    pub fn slip_offset(&self) -> &Vector {
        self.ghosted.global()
    }

    /// The step converged at `x`: velocity and acceleration from the
    /// Newmark update, then `x` becomes the last converged displacement.
    pub fn advance(&mut self, x: &Vector, c: &Coefficients) -> Result<()> {
        let mut a = x.duplicate()?;
        let mut v = x.duplicate()?;
        x.with_array(|xa| -> Result<()> {
            self.u_n.with_array(|un| -> Result<()> {
                self.v_n.with_array(|vn| -> Result<()> {
                    self.a_n.with_array(|an| -> Result<()> {
                        a.with_array_mut(|out| c.accelerations(xa, un, vn, an, out))?
                            .map_err(Error::Internal)?;
                        v.with_array_mut(|out| c.velocities(xa, un, vn, an, out))?
                            .map_err(Error::Internal)?;
                        Ok(())
                    })?
                })?
            })?
        })??;
        self.a_n = a;
        self.v_n = v;
        self.u_n.copy_from(x)?;
        Ok(())
    }

    /// Kinetic energy, momentum and stored energy after a step.
    pub fn report(
        &self,
        world: &impl Communicator,
        inertia: &mut Inertia,
        strain_local: f64,
        time: f64,
    ) -> Result<DynamicsReport> {
        inertia.mass.mult(&self.v_n, &mut inertia.work)?;
        let kinetic = 0.5 * self.v_n.dot(&inertia.work)?;
        let local = inertia.work.with_array(|mv| {
            let mut p = [0.0; 4];
            for node in mv.chunks_exact(DIM) {
                for (pi, m) in p.iter_mut().zip(node) {
                    *pi += m;
                }
            }
            p[3] = strain_local;
            p
        })?;
        let total = crate::parallel::sum(world, local);
        Ok(DynamicsReport {
            time,
            kinetic,
            strain: total[3],
            momentum: [total[0], total[1], total[2]],
        })
    }

    pub fn velocity(&self) -> &Vector {
        &self.v_n
    }
}

/// `out = Σ cᵢ vᵢ` over owned entries.
fn combine(out: &mut Vector, terms: [(f64, &Vector); 3]) -> Result<()> {
    out.set_all(0.0)?;
    for (c, v) in terms {
        out.axpy(c, v)?;
    }
    Ok(())
}

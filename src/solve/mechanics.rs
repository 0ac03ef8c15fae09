//! The discrete equilibrium R(u) = f_int(u) − f_ext(u) = 0 that SNES solves at
//! one load factor, with Dirichlet rows replaced by u − ū.
use super::boundary::Dirichlet;
use crate::assembly::{BulkAssembler, SurfaceLoads};
use crate::dofs::{DofMap, DIM};
use crate::error::{Error, Result};
use crate::petsc::snes::CallbackError;
use crate::petsc::{GhostedVector, Matrix, NonlinearProblem, Preallocation, Vector};

/// Everything the residual and Jacobian need, plus the work vectors that hold
/// the ghosted state between callbacks.
pub struct Mechanics<'a> {
    pub bulk: &'a BulkAssembler,
    pub loads: &'a SurfaceLoads,
    pub dirichlet: &'a Dirichlet,
    /// Constant body force per body (per unit reference volume) at full load.
    pub body_force: Vec<[f64; 3]>,
    /// A fixed external force (local form) at full load, e.g. a manufactured
    /// body force; scaled by the load factor.
    pub fixed_external: Option<Vec<f64>>,
    pub factor: f64,
    u: GhostedVector,
    r: GhostedVector,
    /// Bulk stiffness when every body is linear: assembled once, reused.
    linear_k: Option<Matrix>,
    work: Vector,
    /// Counters, for reports and for checking what is (not) recomputed.
    pub residual_evaluations: usize,
    pub jacobian_evaluations: usize,
    pub bulk_tangent_assemblies: usize,
}

impl<'a> Mechanics<'a> {
    pub fn new(
        dofs: &DofMap,
        bulk: &'a BulkAssembler,
        loads: &'a SurfaceLoads,
        dirichlet: &'a Dirichlet,
        body_force: Vec<[f64; 3]>,
        prealloc: &Preallocation,
    ) -> Result<Self> {
        let ghosts = dofs.ghost_dofs();
        let u = GhostedVector::new(dofs.num_owned_dofs(), &ghosts)?;
        let r = GhostedVector::new(dofs.num_owned_dofs(), &ghosts)?;
        let work = u.global().duplicate()?;
        let mut me = Mechanics {
            bulk,
            loads,
            dirichlet,
            body_force,
            fixed_external: None,
            factor: 0.0,
            u,
            r,
            linear_k: None,
            work,
            residual_evaluations: 0,
            jacobian_evaluations: 0,
            bulk_tangent_assemblies: 0,
        };
        if bulk.is_linear() {
            let mut k = Matrix::new_aij(dofs.num_owned_dofs(), prealloc, DIM)?;
            let zero = vec![0.0; me.u.with_local(|l| l.len())?];
            bulk.add_tangent(&zero, &mut k)?;
            k.assemble()?;
            me.bulk_tangent_assemblies += 1;
            me.linear_k = Some(k);
        }
        Ok(me)
    }

    fn load_state(&mut self, x: &Vector) -> Result<()> {
        self.u.global_mut().copy_from(x)?;
        self.u.update_ghosts()?;
        Ok(())
    }

    /// f_int − f_ext at `x`, without the Dirichlet replacement (its constrained
    /// entries are the reactions).
    pub fn raw_residual(&mut self, x: &Vector, out: &mut Vector) -> Result<()> {
        self.load_state(x)?;
        let (bulk, loads, factor) = (self.bulk, self.loads, self.factor);
        let linear = self.linear_k.is_some();
        let body_force = &self.body_force;
        let fixed = self.fixed_external.as_deref();
        let u = &self.u;
        let status: Result<()> = self.r.with_local_mut(|r_local| {
            r_local.fill(0.0);
            u.with_local(|u_local| -> Result<()> {
                if !linear {
                    bulk.add_internal_force(u_local, r_local)?;
                }
                loads.add_external_force(u_local, -factor, r_local)
            })??;
            bulk.add_body_force(body_force, -factor, r_local)?;
            if let Some(f) = fixed {
                for (r, f) in r_local.iter_mut().zip(f) {
                    *r -= factor * f;
                }
            }
            Ok(())
        })?;
        status?;
        self.r.accumulate_ghosts()?;
        out.copy_from(self.r.global())?;
        if let Some(k) = &self.linear_k {
            k.mult(x, &mut self.work)?;
            out.axpy(1.0, &self.work)?;
        }
        Ok(())
    }

    fn residual_impl(&mut self, x: &Vector, r: &mut Vector) -> Result<()> {
        self.residual_evaluations += 1;
        self.raw_residual(x, r)?;
        let factor = self.factor;
        let dirichlet = self.dirichlet;
        x.with_array(|xa| r.with_array_mut(|ra| dirichlet.constrain_residual(xa, ra, factor)))??;
        Ok(())
    }

    fn jacobian_impl(&mut self, x: &Vector, j: &mut Matrix) -> Result<()> {
        self.jacobian_evaluations += 1;
        self.load_state(x)?;
        j.zero_entries()?;
        let (bulk, loads, factor) = (self.bulk, self.loads, self.factor);
        match &self.linear_k {
            Some(k) => j.add_scaled_subset(1.0, k)?,
            None => {
                self.u
                    .with_local(|u_local| bulk.add_tangent(u_local, j))??;
                self.bulk_tangent_assemblies += 1;
            }
        }
        if loads.has_follower() {
            self.u
                .with_local(|u_local| loads.add_tangent(u_local, factor, j))??;
        }
        j.assemble()?;
        j.zero_rows_columns_identity(&self.dirichlet.global_rows())?;
        Ok(())
    }
}

fn classify(e: Error) -> CallbackError {
    match e {
        Error::Element { .. } => CallbackError::Domain(e.to_string()),
        other => CallbackError::Fatal(other.to_string()),
    }
}

impl NonlinearProblem for Mechanics<'_> {
    fn residual(&mut self, x: &Vector, r: &mut Vector) -> std::result::Result<(), CallbackError> {
        self.residual_impl(x, r).map_err(classify)
    }

    fn jacobian(&mut self, x: &Vector, j: &mut Matrix) -> std::result::Result<(), CallbackError> {
        self.jacobian_impl(x, j).map_err(classify)
    }
}

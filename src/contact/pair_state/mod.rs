//! A contact pair at run time ([`ContactPair`]): what one rank holds of a
//! pair between load steps and how the solver drives it. The duties are split
//! by concept:
//! - `links`: the links of a load step ([`Link`], one per linked slave
//!   quadrature point), the step's search and the following of sliding;
//! - `assemble`: the Jacobian pattern, residual and tangent of the links;
//! - `slip_history`: the friction history of each point in the terms of its
//!   current master facet (carried over when a link changes facet);
//! - `uzawa`: the multiplier update and the penalty;
//! - `snapshot`: cutback snapshots, step commit, restart from a result file;
//! - `output`: point and nodal values for the result file.
//!
//! A mortar pair hands each of these duties to `contact::mortar`.
mod assemble;
mod links;
mod output;
mod slip_history;
mod snapshot;
mod uzawa;

pub use super::outcome::{PairForce, UzawaStats};
pub use links::Link;
pub use output::PointValues;
pub use snapshot::{FrictionRows, MortarRows, PairSnapshot, RestartRows};

use super::autodiff::{norm, sub};
use super::held_master::HeldMaster;
use super::mortar::pair::{MortarMaster, MortarPair};
use super::multipliers::Multipliers;
use super::surfaces::SlaveSurface;
use crate::assembly::{HaloFactory, RankExchange};
use crate::distribution::{LocalMesh, SlaveSetPiece};
use crate::dofs::DofMap;
use crate::error::{Error, Result};
use crate::model::{Formulation, MasterSpec, PairSpec, RigidSurface};

/// The master side at run time.
pub enum MasterSide {
    /// The master facets this rank holds (see `contact::held_master`).
    Deformable(Box<HeldMaster>),
    Rigid(RigidSurface),
}

/// Friction of a pair at run time: μ and εT per slave facet.
struct PairFriction {
    mu: f64,
    penalty: Vec<f64>,
}

/// Dynamics: the time integrator's velocity, affine in the displacement,
/// `v = dv_du · u + offset` (local form, per DOF), for the slip rate.
pub struct SlipRateMap {
    pub dt: f64,
    pub dv_du: f64,
    pub offset: Vec<f64>,
    /// Velocity of a rigid master (its motion per unit time).
    pub rigid_velocity: [f64; 3],
}

pub struct ContactPair {
    pub spec: PairSpec,
    pub slave: SlaveSurface,
    pub master: MasterSide,
    pub multipliers: Multipliers,
    /// The pair's penalty as reported: the user's εN, or 10·E/h with h the
    /// mean element size; with no user value each slave facet uses its own
    /// h (`facet_penalty`), so graded meshes get a local penalty.
    pub penalty: f64,
    /// The penalty the pair was built with: what the Uzawa test's force
    /// floor is measured in, so that raising (or softening) the penalty
    /// does not move the test's resolution.
    built_penalty: f64,
    facet_penalty: Vec<f64>,
    pub search_distance: f64,
    links: Vec<Link>,
    pattern_key: u64,
    /// Master node positions of the last evaluation (deformable masters).
    positions: Vec<[f64; 3]>,
    friction: Option<PairFriction>,
    /// Set by the solver in dynamics (slip from velocities); None: quasi-static.
    pub rate: Option<SlipRateMap>,
    /// `formulation = "mortar"`: the pair's constraint is the mortar one and
    /// the links above stay empty (the slave surface still gives the output
    /// its points).
    pub mortar: Option<MortarPair>,
    /// See `tangent_signature`.
    tangent_signature: u64,
    /// See `set_main_part_tangent`.
    main_part_tangent: bool,
}

impl ContactPair {
    /// Resolves a pair on this rank. `slave_piece` is what the rank holds of
    /// the slave set beyond its own facets (every facet's owner, the mean
    /// edge, ghost facets); `softest_youngs` sets the default penalty.
    pub fn new(
        mesh: &LocalMesh,
        dofs: &DofMap,
        slave_piece: &SlaveSetPiece,
        spec: &PairSpec,
        softest_youngs: f64,
        halos: &dyn HaloFactory,
        ranks: &dyn RankExchange,
    ) -> Result<Self> {
        let rule = spec.quadrature.rule(mesh.cell_type.facet_type());
        let slave = SlaveSurface::new(mesh, dofs, &spec.slave, slave_piece, &rule)?;
        let master = match &spec.master {
            // Both formulations hold the master facets near their slave
            // side, exchanged by boxes (`contact::held_master`).
            MasterSpec::Surface { set } => {
                MasterSide::Deformable(Box::new(HeldMaster::new(mesh, dofs, set, ranks)?))
            }
            MasterSpec::Rigid(r) => MasterSide::Rigid(*r),
        };
        let friction_spec = spec.active_friction();
        let multipliers = Multipliers::new(
            dofs,
            slave_piece,
            &slave,
            &rule,
            friction_spec.is_some(),
            halos,
        )?;
        let penalty = spec.penalty.unwrap_or(10.0 * softest_youngs / slave.h);
        let facet_penalty: Vec<f64> = slave
            .facets
            .iter()
            .map(|f| spec.penalty.unwrap_or(10.0 * softest_youngs / f.h))
            .collect();
        if !(penalty.is_finite() && penalty > 0.0) {
            return Err(Error::scene(
                "contact",
                format!(
                    "pair '{}': penalty must be positive (got {penalty})",
                    spec.name
                ),
            ));
        }
        let search_distance = spec
            .search_distance
            .unwrap_or_else(|| default_search_distance(mesh, &master, slave.h));
        let mortar = match (&spec.formulation, &spec.master) {
            (Formulation::Links, _) => None,
            (Formulation::Mortar, master) => Some(MortarPair::new(
                mesh,
                dofs,
                spec,
                (
                    match master {
                        MasterSpec::Surface { set } => MortarMaster::Facets(set),
                        MasterSpec::Rigid(r) => MortarMaster::Rigid(*r),
                    },
                    ranks,
                ),
                |h| spec.penalty.unwrap_or(10.0 * softest_youngs / h),
                // Candidates are fixed for a step and every one widens the
                // Jacobian pattern: one element size of margin, not the
                // links' search distance, which only reserves contact DOFs.
                (search_distance.min(slave.h), search_distance),
                friction_spec,
            )?),
        };
        let friction = friction_spec.map(|f| PairFriction {
            mu: f.mu,
            penalty: match f.penalty {
                Some(p) => vec![p; slave.facets.len()],
                None => facet_penalty.clone(),
            },
        });
        Ok(ContactPair {
            spec: spec.clone(),
            slave,
            master,
            multipliers,
            penalty,
            built_penalty: penalty,
            facet_penalty,
            tangent_signature: 0,
            main_part_tangent: false,
            search_distance,
            links: Vec::new(),
            pattern_key: 0,
            positions: Vec::new(),
            friction,
            rate: None,
            mortar,
        })
    }

    pub fn links(&self) -> &[Link] {
        &self.links
    }

    /// The smallest nodal force the Uzawa test resolves: the force of a
    /// penetration at the tolerance on one facet (εN · tol·h · h²). Below it
    /// a change in the multipliers cannot move the solution by more than the
    /// penetration tolerance already allows, so a near-empty contact (a
    /// grazing touch) is not iterated to relative precision.
    pub fn force_floor(&self) -> f64 {
        let h = self.slave.h;
        self.built_penalty * self.spec.penetration_tol * h * h * h
    }

    /// Translation of a rigid master at load factor `factor`.
    pub fn rigid_shift(&self, factor: f64) -> [f64; 3] {
        let a = self.spec.motion_amplitude.at(factor);
        self.spec.motion.map(|c| c * a)
    }

    /// Whether the frictionless links' tangent keeps only its main part
    /// (see `kernel::LinkInput::main_part_tangent`; the residual is the
    /// same either way; the mortar pair's analogue is
    /// `mortar::main_part`). Friction and a rigid mortar master ignore it.
    pub fn set_main_part_tangent(&mut self, on: bool) {
        self.main_part_tangent = on;
    }

    /// Whether the pair is a mortar pair (`formulation = "mortar"`).
    pub fn is_mortar(&self) -> bool {
        self.mortar.is_some()
    }

    /// Whether the pair computes friction.
    pub fn has_friction(&self) -> bool {
        self.friction.is_some()
    }

    /// Whether the pair's tangent is symmetric: frictionless links (the
    /// Hessian of a potential). The mortar residual is not a gradient (the
    /// forces hold D, M and ν fixed), so its exact tangent is not symmetric;
    /// against a rigid master it is (−p_j ∂g̃_j/∂x exactly, nothing held
    /// fixed: docs/formulation.md §13.5), symmetric to rounding.
    pub fn tangent_is_symmetric(&self) -> bool {
        !self.has_friction() && self.mortar.as_ref().is_none_or(MortarPair::is_rigid)
    }
}

/// Default search distance: generous enough that bodies approaching within a
/// load step are linked (an open link costs only its evaluation).
fn default_search_distance(mesh: &LocalMesh, master: &MasterSide, h: f64) -> f64 {
    let diag = match master {
        MasterSide::Deformable(m) => m.reference_box.map_or(0.0, |(lo, hi)| norm(&sub(&hi, &lo))),
        MasterSide::Rigid(_) => mesh.bounding_box.map_or(0.0, |b| b.diagonal()),
    };
    (10.0 * h).max(0.1 * diag)
}

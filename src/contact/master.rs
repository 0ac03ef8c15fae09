//! The master side of a pair as a rank holds it, for every formulation:
//! the facets of a deformable body near this rank's slave side
//! ([`HeldMaster`]), or a rigid analytic surface with its prescribed
//! translation ([`RigidMaster`]).
use super::autodiff::{norm, sub};
use super::held_master::HeldMaster;
use crate::amplitude::Amplitude;
use crate::assembly::RankExchange;
use crate::distribution::LocalMesh;
use crate::dofs::DofMap;
use crate::error::Result;
use crate::model::{MasterSpec, PairSpec, RigidSurface};

/// A rigid analytic master: the surface as given (at load factor 0),
/// translated by `amplitude(factor) · motion`.
#[derive(Debug, Clone)]
pub struct RigidMaster {
    pub surface: RigidSurface,
    motion: [f64; 3],
    amplitude: Amplitude,
}

impl RigidMaster {
    pub fn new(surface: RigidSurface, spec: &PairSpec) -> Self {
        RigidMaster {
            surface,
            motion: spec.motion,
            amplitude: spec.motion_amplitude.clone(),
        }
    }

    /// The surface's translation at load factor `factor`.
    pub fn shift(&self, factor: f64) -> [f64; 3] {
        let a = self.amplitude.at(factor);
        self.motion.map(|c| c * a)
    }

    /// The surface placed at load factor `factor` (unit normal / axis).
    pub fn placed(&self, factor: f64) -> RigidSurface {
        self.surface.moved(self.motion, self.amplitude.at(factor))
    }
}

/// The master side at run time.
pub enum MasterSide {
    /// The master facets this rank holds (see `contact::held_master`).
    Facets(Box<HeldMaster>),
    Rigid(RigidMaster),
}

impl MasterSide {
    /// The pair's master on this rank. Collective (a facet set's sizes are
    /// agreed over the ranks).
    pub fn new(
        mesh: &LocalMesh,
        dofs: &DofMap,
        spec: &PairSpec,
        ranks: &dyn RankExchange,
    ) -> Result<Self> {
        Ok(match &spec.master {
            MasterSpec::Surface { set } => {
                MasterSide::Facets(Box::new(HeldMaster::new(mesh, dofs, set, ranks)?))
            }
            MasterSpec::Rigid(r) => MasterSide::Rigid(RigidMaster::new(*r, spec)),
        })
    }

    /// Default search distance: generous enough that bodies approaching
    /// within a load step are found (ten element sizes `h`, at least a
    /// tenth of the master's extent, or of this rank's mesh against a rigid
    /// master).
    pub fn default_search_distance(&self, mesh: &LocalMesh, h: f64) -> f64 {
        let diag = match self {
            MasterSide::Facets(m) => m.reference_box.map_or(0.0, |(lo, hi)| norm(&sub(&hi, &lo))),
            MasterSide::Rigid(_) => mesh.bounding_box.map_or(0.0, |b| b.diagonal()),
        };
        (10.0 * h).max(0.1 * diag)
    }
}

//! The rigid analytic master of a mortar pair: the surface as given, its
//! prescribed motion, and the step's candidate slave facets.
use crate::amplitude::Amplitude;
use crate::model::{PairSpec, RigidSurface};

/// The rigid master of a mortar pair.
#[derive(Debug, Clone)]
pub struct RigidMaster {
    /// As given (at load factor 0) ...
    pub(super) surface: RigidSurface,
    /// ... translated by `amplitude(factor) · motion`.
    pub(super) motion: [f64; 3],
    pub(super) amplitude: Amplitude,
    /// Per slot: how many facets this rank evaluates hold the node (all of
    /// them must be integrated for its weighted gap to be whole).
    pub(super) expected: Vec<u32>,
    /// The step's candidate facets: every evaluated facet with a node within
    /// the search distance of the surface at the search (ascending).
    pub(super) candidates: Vec<u32>,
    /// Load factor of the last converged step and of the last Uzawa update:
    /// the quasi-static slip measures the master's translation from the first.
    pub(super) start_factor: f64,
    pub(super) last_factor: f64,
}

impl RigidMaster {
    /// `slots`: the pair's slave node per slot; `facet_count`: per slave
    /// node, the evaluated facets that hold it.
    pub(super) fn new(
        surface: RigidSurface,
        spec: &PairSpec,
        slots: &[u32],
        facet_count: &[usize],
    ) -> Self {
        RigidMaster {
            surface,
            motion: spec.motion,
            amplitude: spec.motion_amplitude.clone(),
            expected: slots
                .iter()
                .map(|&n| facet_count[n as usize] as u32)
                .collect(),
            candidates: Vec::new(),
            start_factor: 0.0,
            last_factor: 0.0,
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

//! The master side of a mortar pair at run time, one variant per kind of
//! master: the facets of a deformable body this rank holds, or a rigid
//! analytic surface with its prescribed motion. Each variant's run-time
//! duties are in its own module (`facet_side`, `rigid_side`).
use super::MAX_FACET_NODES;
use crate::contact::held_master::HeldMaster;
use crate::contact::master::RigidMaster;

/// The master side of a mortar pair at run time.
pub(super) enum Master {
    /// Facets of a deformable body, held near this rank's slave nodes.
    Facets(FacetSide),
    /// A rigid analytic surface with its prescribed motion.
    Rigid(RigidSide),
}

impl Master {
    /// The master facet `m`'s position in its set (0 for a rigid master).
    pub fn set_index(&self, m: u32) -> u32 {
        match self {
            Master::Facets(f) => f.set_index[m as usize],
            Master::Rigid(_) => 0,
        }
    }
}

/// The master facets this rank holds, as pair node ids.
pub(super) struct FacetSide {
    /// The held facets of the master set (see `contact::held_master`).
    pub held: Box<HeldMaster>,
    /// Held facets as pair node ids (after the slave nodes).
    pub facets: Vec<[u32; MAX_FACET_NODES]>,
    /// Each held facet's position in the master set (the numbering of
    /// held facets changes with each exchange, this one does not).
    pub set_index: Vec<u32>,
}

/// The rigid master of a mortar pair.
#[derive(Debug, Clone)]
pub(super) struct RigidSide {
    pub master: RigidMaster,
    /// Per slot: how many facets this rank evaluates hold the node (all of
    /// them must be integrated for its weighted gap to be whole).
    pub expected: Vec<u32>,
    /// Load factor of the last converged step and of the last Uzawa update:
    /// the quasi-static slip measures the master's translation from the first.
    pub start_factor: f64,
    pub last_factor: f64,
}

impl RigidSide {
    /// `slots`: the pair's slave node per slot; `facet_count`: per slave
    /// node, the evaluated facets that hold it.
    pub fn new(master: RigidMaster, slots: &[u32], facet_count: &[usize]) -> Self {
        RigidSide {
            master,
            expected: slots
                .iter()
                .map(|&n| facet_count[n as usize] as u32)
                .collect(),
            start_factor: 0.0,
            last_factor: 0.0,
        }
    }
}

//! Boundary conditions as a scene states them: prescribed displacements on
//! node sets and loads on facet sets, at full load.
use crate::amplitude::Amplitude;

/// One Dirichlet condition: a node set, the components it fixes, and their
/// displacement at full load (ramped with the load factor), per node.
#[derive(Debug, Clone)]
pub struct DirichletSpec {
    pub set: String,
    pub nodes: Vec<usize>,
    pub components: Vec<usize>,
    /// Full-load displacement of each node in `nodes` (only `components` used).
    pub values: Vec<[f64; 3]>,
    /// How the values follow the load factor (default: linear ramp).
    pub amplitude: Amplitude,
}

impl DirichletSpec {
    /// The same displacement for every node of the set.
    pub fn uniform(set: &str, nodes: Vec<usize>, components: Vec<usize>, value: [f64; 3]) -> Self {
        let values = vec![value; nodes.len()];
        DirichletSpec {
            set: set.to_owned(),
            nodes,
            components,
            values,
            amplitude: Amplitude::ramp(),
        }
    }
}

/// One load on a facet set, at full load factor.
#[derive(Debug, Clone)]
pub enum FacetLoad {
    /// Pressure p > 0 pushes into the body, normal to the deformed facet.
    Pressure(f64),
    /// Force per unit reference area, fixed in direction.
    Traction([f64; 3]),
}

//! Contact pairs as a scene states them: which surfaces meet, the penalty, and
//! the Uzawa tolerances.

/// The master side of a pair: a facet set of a deformable body, or a rigid
/// analytic surface (no DOFs) that moves by a prescribed translation.
#[derive(Debug, Clone, PartialEq)]
pub enum MasterSpec {
    Surface {
        set: String,
    },
    /// Half-space below `point` with outward `normal` (the slave stays on the normal side).
    Plane {
        point: [f64; 3],
        normal: [f64; 3],
    },
    /// Rigid ball; the slave stays outside.
    Sphere {
        centre: [f64; 3],
        radius: f64,
    },
    /// Rigid infinite cylinder; the slave stays outside.
    Cylinder {
        point: [f64; 3],
        axis: [f64; 3],
        radius: f64,
    },
}

impl MasterSpec {
    pub fn is_rigid(&self) -> bool {
        !matches!(self, MasterSpec::Surface { .. })
    }
}

/// Where a slave facet's contact links sit.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum SlaveQuadrature {
    /// At the facet's Gauss points (2×2 / 3-point), as the seed does. There are
    /// more points than slave nodes, so where the Uzawa loop enforces the
    /// constraint exactly the multipliers are not unique; the loop therefore
    /// judges convergence by the nodal contact forces, which are.
    #[default]
    Gauss,
    /// At the facet's nodes (Lobatto / vertex rule): one constraint per slave
    /// node (node-to-surface like). Where slave nodes sit exactly over master
    /// nodes (matching meshes) it chatters between facets.
    Nodal,
    /// One point per facet, at its centre: one constraint per facet, about
    /// one per slave node, never over a master node in matching meshes.
    Centroid,
}

impl SlaveQuadrature {
    pub fn rule(self, facet: crate::fem::FacetType) -> crate::fem::QuadRule {
        match self {
            SlaveQuadrature::Nodal => crate::fem::QuadRule::nodal_for_facet(facet),
            SlaveQuadrature::Gauss => crate::fem::QuadRule::default_for_facet(facet),
            SlaveQuadrature::Centroid => match facet {
                crate::fem::FacetType::Quad4 => crate::fem::QuadRule::quad_gauss(1)
                    .unwrap_or_else(|_| crate::fem::QuadRule::quad_2x2()),
                crate::fem::FacetType::Tri3 => crate::fem::QuadRule::tri_1(),
            },
        }
    }
}

/// One contact pair.
#[derive(Debug, Clone)]
pub struct PairSpec {
    pub name: String,
    /// Facet set of the slave surface (its quadrature points carry the links).
    pub slave: String,
    pub master: MasterSpec,
    pub quadrature: SlaveQuadrature,
    /// Translation of a rigid master at full load (ramped with the load factor).
    pub motion: [f64; 3],
    /// εN; None: 10·E/h with E the softest body's modulus and h the mean slave facet size.
    pub penalty: Option<f64>,
    /// Uzawa stops when every link's penetration is at most this fraction of its facet's size ...
    pub penetration_tol: f64,
    /// ... and the largest multiplier change is at most this fraction of the largest multiplier.
    pub multiplier_tol: f64,
    pub max_uzawa: usize,
    /// Slave points farther than this from the master get no link; None: the
    /// larger of 10·h and a tenth of the master's bounding-box diagonal.
    pub search_distance: Option<f64>,
}

impl PairSpec {
    pub fn new(name: &str, slave: &str, master: MasterSpec) -> Self {
        PairSpec {
            name: name.to_owned(),
            slave: slave.to_owned(),
            master,
            quadrature: SlaveQuadrature::default(),
            motion: [0.0; 3],
            penalty: None,
            penetration_tol: 1e-3,
            multiplier_tol: 1e-3,
            max_uzawa: 30,
            search_distance: None,
        }
    }
}

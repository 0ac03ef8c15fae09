//! Contact pairs as a scene states them: which surfaces meet (facet sets or
//! rigid analytic surfaces), the formulation, the penalty, friction and the
//! Uzawa tolerances. The pair at run time is `contact::pair::ContactPair`.
use crate::amplitude::Amplitude;
use crate::fem::{FacetType, QuadRule};
use crate::vec3::{dot, norm, sub};

/// A rigid analytic master surface (no DOFs), as given at load factor 0.
#[derive(Debug, Clone, Copy, PartialEq, serde::Deserialize)]
#[serde(tag = "kind", rename_all = "lowercase", deny_unknown_fields)]
pub enum RigidSurface {
    /// Half-space below `point` with outward `normal` (the slave stays on the normal side).
    Plane { point: [f64; 3], normal: [f64; 3] },
    /// Rigid ball; the slave stays outside.
    Sphere { centre: [f64; 3], radius: f64 },
    /// Rigid infinite cylinder; the slave stays outside.
    Cylinder {
        point: [f64; 3],
        axis: [f64; 3],
        radius: f64,
    },
}

impl RigidSurface {
    /// Why the surface is unusable, if it is.
    pub fn validate(&self) -> Result<(), String> {
        let nonzero = |v: [f64; 3], key: &str| {
            let n = norm(v);
            if n > 0.0 && n.is_finite() {
                Ok(())
            } else {
                Err(format!("rigid {key} must be a non-zero vector"))
            }
        };
        let positive = |r: f64| {
            if r > 0.0 && r.is_finite() {
                Ok(())
            } else {
                Err(format!("rigid radius must be positive (got {r})"))
            }
        };
        match *self {
            RigidSurface::Plane { normal, .. } => nonzero(normal, "normal"),
            RigidSurface::Sphere { radius, .. } => positive(radius),
            RigidSurface::Cylinder { axis, radius, .. } => {
                nonzero(axis, "axis").and(positive(radius))
            }
        }
    }

    /// The surface translated by `factor · motion`, with unit normal or axis.
    pub fn moved(&self, motion: [f64; 3], factor: f64) -> Self {
        let shift = |p: [f64; 3]| {
            [
                p[0] + factor * motion[0],
                p[1] + factor * motion[1],
                p[2] + factor * motion[2],
            ]
        };
        match *self {
            RigidSurface::Plane { point, normal } => RigidSurface::Plane {
                point: shift(point),
                normal: unit(normal),
            },
            RigidSurface::Sphere { centre, radius } => RigidSurface::Sphere {
                centre: shift(centre),
                radius,
            },
            RigidSurface::Cylinder {
                point,
                axis,
                radius,
            } => RigidSurface::Cylinder {
                point: shift(point),
                axis: unit(axis),
                radius,
            },
        }
    }

    /// The point of the surface nearest `x` (for a surface placed by `moved`;
    /// `x` itself where the nearest point is not unique).
    pub fn closest_point(&self, x: [f64; 3]) -> [f64; 3] {
        let d = self.distance(x);
        let n = match *self {
            RigidSurface::Plane { normal, .. } => normal,
            RigidSurface::Sphere { centre, .. } => sub(x, centre),
            RigidSurface::Cylinder { point, axis, .. } => {
                let v = sub(x, point);
                let along = dot(v, axis);
                sub(v, axis.map(|a| along * a))
            }
        };
        let len = norm(n);
        if len.partial_cmp(&0.0) != Some(std::cmp::Ordering::Greater) {
            return x;
        }
        [0, 1, 2].map(|i| x[i] - d * n[i] / len)
    }

    /// Signed distance of `x` from the surface (negative inside the rigid body),
    /// for a surface placed by `moved`.
    pub fn distance(&self, x: [f64; 3]) -> f64 {
        match *self {
            RigidSurface::Plane { point, normal } => dot(sub(x, point), normal),
            RigidSurface::Sphere { centre, radius } => norm(sub(x, centre)) - radius,
            RigidSurface::Cylinder {
                point,
                axis,
                radius,
            } => {
                let d = sub(x, point);
                let along = dot(d, axis);
                norm(sub(d, axis.map(|a| along * a))) - radius
            }
        }
    }
}

fn unit(v: [f64; 3]) -> [f64; 3] {
    let n = norm(v);
    [v[0] / n, v[1] / n, v[2] / n]
}

/// The master side of a pair: a facet set of a deformable body, or a rigid
/// analytic surface that moves by a prescribed translation.
#[derive(Debug, Clone, PartialEq)]
pub enum MasterSpec {
    Surface { set: String },
    Rigid(RigidSurface),
}

impl MasterSpec {
    pub fn is_rigid(&self) -> bool {
        matches!(self, MasterSpec::Rigid(_))
    }
}

/// Where a slave facet's contact links sit.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum SlaveQuadrature {
    /// At the facet's Gauss points (2×2 / 3-point; docs/formulation.md §2.4). There are
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
    pub fn rule(self, facet: FacetType) -> QuadRule {
        match self {
            SlaveQuadrature::Nodal => QuadRule::nodal_for_facet(facet),
            SlaveQuadrature::Gauss => QuadRule::default_for_facet(facet),
            SlaveQuadrature::Centroid => match facet.linear() {
                FacetType::Tri3 => QuadRule::tri_1(),
                _ => QuadRule::quad_gauss(1).unwrap_or_else(|_| QuadRule::quad_2x2()),
            },
        }
    }
}

/// How a pair discretises the contact constraint.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Formulation {
    /// One link (and one multiplier) per slave quadrature point.
    Links,
    /// Multipliers at the slave nodes with dual shape functions, integrated
    /// over the slave–master overlaps (segment-based mortar). The default:
    /// it passes the contact patch test and slides without force
    /// oscillation, at the links' cost or less (docs/verification.md, "The
    /// default formulation").
    #[default]
    Mortar,
}

impl Formulation {
    /// Whether the formulation handles slave and master facets of this type.
    pub fn supports(self, facet: FacetType) -> bool {
        match self {
            Formulation::Links => true,
            Formulation::Mortar => matches!(facet, FacetType::Quad4 | FacetType::Tri3),
        }
    }
}

/// Coulomb friction of a pair.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct FrictionSpec {
    /// Friction coefficient μ ≥ 0 (μ = 0 is the same as no friction).
    pub mu: f64,
    /// Tangential penalty εT > 0; None: the pair's normal penalty εN.
    pub penalty: Option<f64>,
}

/// One contact pair.
#[derive(Debug, Clone)]
pub struct PairSpec {
    pub name: String,
    /// Facet set of the slave surface (its quadrature points carry the links).
    pub slave: String,
    pub master: MasterSpec,
    pub formulation: Formulation,
    pub quadrature: SlaveQuadrature,
    /// Translation of a rigid master at full amplitude ...
    pub motion: [f64; 3],
    /// ... and how it follows the load factor (default: a linear ramp).
    pub motion_amplitude: Amplitude,
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
    /// Coulomb friction; None (or μ = 0): frictionless, no tangential terms.
    pub friction: Option<FrictionSpec>,
}

impl PairSpec {
    /// The pair's friction if it has any to compute (μ > 0).
    pub fn active_friction(&self) -> Option<FrictionSpec> {
        self.friction.filter(|f| f.mu > 0.0)
    }
}

impl PairSpec {
    pub fn new(name: &str, slave: &str, master: MasterSpec) -> Self {
        PairSpec {
            name: name.to_owned(),
            slave: slave.to_owned(),
            master,
            formulation: Formulation::default(),
            quadrature: SlaveQuadrature::default(),
            motion: [0.0; 3],
            motion_amplitude: Amplitude::ramp(),
            penalty: None,
            penetration_tol: 1e-3,
            multiplier_tol: 1e-3,
            max_uzawa: 30,
            search_distance: None,
            friction: None,
        }
    }
}

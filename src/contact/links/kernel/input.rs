//! What one link evaluation takes ([`LinkInput`]) and reports
//! ([`LinkState`]), the checks of that input, the reference area weights of
//! the slave quadrature points, and the nodal positions as f64 or as dual
//! variables for the tangent pass.

use thiserror::Error;

use crate::contact::autodiff::{self, Dual, Scalar, Vec3};
use crate::fem::FacetType;
use crate::model::RigidSurface;

/// The master as one link's kernel sees it: the current nodes of its master
/// facet, or a rigid analytic surface (`pair::RigidSurface` placed for the
/// load step).
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum LinkMaster<'a> {
    /// Deformable master facet, CURRENT nodal positions (these are DOFs).
    Facet { facet: FacetType, x: &'a [[f64; 3]] },
    /// Rigid half-space, no DOFs; `normal` (any length) points out of the
    /// rigid body.
    Plane { point: [f64; 3], normal: [f64; 3] },
    /// Rigid ball; the slave is outside it.
    Sphere { centre: [f64; 3], radius: f64 },
    /// Rigid infinite cylinder (`axis` any length); the slave is outside it.
    Cylinder {
        point: [f64; 3],
        axis: [f64; 3],
        radius: f64,
    },
}

// The scene's rigid surface is plain data in `model`; its view as a link
// master belongs beside `LinkMaster`, which `model` must not know.
impl RigidSurface {
    /// The link kernel's view of the surface.
    pub fn as_master(&self) -> LinkMaster<'static> {
        match *self {
            RigidSurface::Plane { point, normal } => LinkMaster::Plane { point, normal },
            RigidSurface::Sphere { centre, radius } => LinkMaster::Sphere { centre, radius },
            RigidSurface::Cylinder {
                point,
                axis,
                radius,
            } => LinkMaster::Cylinder {
                point,
                axis,
                radius,
            },
        }
    }
}

/// Where slip is measured from, and the tangential multiplier λT (held
/// fixed during Newton). The variant must match the master kind.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum SlipHistory {
    /// Deformable master: `ξ̄ₙ` on the link's facet (the master point of the
    /// last converged step) and λT's covariant components `λT·τ_α` there.
    Convected { xi_n: [f64; 2], lambda: [f64; 2] },
    /// Rigid master: the last converged contact point, moved with the
    /// master to its current placement, and λT as a vector (a rigid master
    /// only translates, so a fixed frame is its convected frame).
    Spatial { point_n: [f64; 3], lambda: [f64; 3] },
}

/// Nodal velocities for the dynamic slip rate `ΔgT = Δt · vT`. The time
/// integrator makes the velocity affine in the displacement, `v = v̄ +
/// dv_dx · (x − x̄)` about the current state, which is how the damping
/// contribution `∂r/∂v` enters the tangent.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SlipRate<'a> {
    pub slave_v: &'a [[f64; 3]],
    /// Master facet node velocities (one per master node), or one entry: the
    /// velocity of a rigid master.
    pub master_v: &'a [[f64; 3]],
    pub dt: f64,
    /// `∂v/∂u` of the integrator (`γ/(βΔt)` for Newmark).
    pub dv_dx: f64,
}

/// Coulomb friction of one link.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Friction<'a> {
    pub mu: f64,
    /// Tangential penalty εT > 0.
    pub penalty: f64,
    pub history: SlipHistory,
    /// Dynamics: slip from the relative velocity instead of `ξ̄ − ξ̄ₙ`.
    pub rate: Option<SlipRate<'a>>,
}

/// Friction values of a closed link (f64).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct FrictionState {
    /// Tangential traction on the slave per reference area (`−tT`).
    pub traction: [f64; 3],
    /// Slip increment ΔgT of the step (slave relative to master, in space).
    pub slip: [f64; 3],
    pub sliding: bool,
    /// What the Uzawa update stores: λT ← tT (same variant as the input)
    /// with the current master point as the next `ξ̄ₙ` / `point_n`.
    pub updated: SlipHistory,
}

/// Everything one link evaluation needs.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LinkInput<'a> {
    pub slave_facet: FacetType,
    /// CURRENT slave facet positions (DOFs).
    pub slave_x: &'a [[f64; 3]],
    /// Slave quadrature point in facet coordinates.
    pub zeta: [f64; 2],
    /// Reference area weight of that point (see [`reference_weights`]).
    pub weight: f64,
    pub master: LinkMaster<'a>,
    /// Start for the projection (the last ξ̄).
    pub xi_start: [f64; 2],
    /// Uzawa multiplier, fixed during Newton (≥ 0).
    pub lambda_n: f64,
    /// Penalty εN > 0.
    pub penalty: f64,
    /// Coulomb friction; `None` is frictionless (no tangential work at all).
    pub friction: Option<Friction<'a>>,
    /// Frictionless only: the tangent keeps its main part `εN (N ν)(N ν)ᵀ`
    /// and drops the terms in `pN` times the derivatives of ν and of the
    /// master shape values (the residual is unchanged). See
    /// `solve::uzawa::main_part_tangent`.
    pub main_part_tangent: bool,
}

/// What a link evaluation reports (f64 values, no derivatives).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LinkState {
    /// `gN = (x¹ − x²)·ν`, > 0 apart. `f64::INFINITY` when there is no
    /// closest point at all (bad input, degenerate geometry); finite but
    /// not to be used when only the projection failed to converge.
    pub gap: f64,
    pub normal: [f64; 3],
    /// ξ̄ on a master facet; `[0, 0]` for rigid masters.
    pub xi: [f64; 2],
    /// `pN = ⟨λN − εN gN⟩`; 0 when the link is open or invalid. This is the
    /// value the Uzawa update stores as the new λN.
    pub pressure: f64,
    /// `λN − εN gN ≥ 0`: the link is in contact and contributes its tangent.
    /// Closed with `pN = 0` is exact touching (gN = λN/εN): no force yet,
    /// but the penalty stiffness, so a body held only by contact is not
    /// singular at first touch.
    pub closed: bool,
    pub slave_point: [f64; 3],
    pub master_point: [f64; 3],
    /// False when no valid closest point exists; `r`, `k` and `pressure` are
    /// then zero and the caller should drop the link.
    pub projection_converged: bool,
    /// How far ξ̄ lies outside the master facet (see
    /// [`projection::Projection::outside`]); 0 for rigid masters.
    pub outside: f64,
    /// Present when the input has friction and the link is closed.
    pub friction: Option<FrictionState>,
}

impl LinkState {
    /// The link without force: no usable closest point after all.
    pub(super) fn dropped(self) -> Self {
        LinkState {
            projection_converged: false,
            closed: false,
            pressure: 0.0,
            friction: None,
            ..self
        }
    }

    /// "No link": far apart, no force. Finite where possible so output stays
    /// readable.
    pub(super) fn invalid() -> Self {
        LinkState {
            gap: f64::INFINITY,
            normal: [0.0; 3],
            xi: [0.0; 2],
            pressure: 0.0,
            closed: false,
            slave_point: [0.0; 3],
            master_point: [0.0; 3],
            projection_converged: false,
            outside: f64::INFINITY,
            friction: None,
        }
    }
}

/// Why a [`LinkInput`] or an output buffer is unusable.
#[derive(Debug, Clone, PartialEq, Error)]
pub enum LinkError {
    #[error("{what}: expected {expected} nodes, got {got}")]
    NodeCount {
        what: &'static str,
        expected: usize,
        got: usize,
    },
    #[error("{what} contains a non-finite value")]
    NonFinite { what: &'static str },
    #[error("{what} = {value:e} out of range: must be {must}")]
    OutOfRange {
        what: &'static str,
        value: f64,
        must: &'static str,
    },
    #[error("{what}: expected length {expected}, got {got}")]
    BufferLength {
        what: &'static str,
        expected: usize,
        got: usize,
    },
}

/// Both of the link's facets are first-order (a rigid master has none):
/// the kernel then runs in holders of `contact::LINEAR_FACET_NODES` nodes.
pub(super) fn first_order(input: &LinkInput) -> bool {
    input.slave_facet.is_linear()
        && match input.master {
            LinkMaster::Facet { facet, .. } => facet.is_linear(),
            _ => true,
        }
}

/// Number of link DOFs `n = 3 (n_s + n_m)`.
pub fn dof_count(input: &LinkInput) -> usize {
    3 * (input.slave_facet.nodes() + master_nodes(&input.master))
}

pub(super) fn master_nodes(master: &LinkMaster) -> usize {
    match master {
        LinkMaster::Facet { facet, .. } => facet.nodes(),
        _ => 0,
    }
}

fn finite(what: &'static str, v: &[f64]) -> Result<(), LinkError> {
    if v.iter().all(|c| c.is_finite()) {
        Ok(())
    } else {
        Err(LinkError::NonFinite { what })
    }
}

/// `value > 0` (`strict`) or `value >= 0`, and finite.
fn non_negative(what: &'static str, value: f64, strict: bool) -> Result<(), LinkError> {
    finite(what, &[value])?;
    let ok = if strict { value > 0.0 } else { value >= 0.0 };
    if ok {
        Ok(())
    } else {
        let must = if strict { "> 0" } else { ">= 0" };
        Err(LinkError::OutOfRange { what, value, must })
    }
}

pub(super) fn facet_nodes(
    what: &'static str,
    facet: FacetType,
    x: &[[f64; 3]],
) -> Result<(), LinkError> {
    if x.len() != facet.nodes() {
        return Err(LinkError::NodeCount {
            what,
            expected: facet.nodes(),
            got: x.len(),
        });
    }
    finite(what, x.as_flattened())
}

fn nonzero(what: &'static str, v: [f64; 3]) -> Result<(), LinkError> {
    finite(what, &v)?;
    non_negative(what, autodiff::norm(&v), true)
}

/// Checks everything [`evaluate`] relies on. The kernels call it themselves
/// and answer bad input with an invalid [`LinkState`]; call it directly to
/// learn what was wrong.
pub fn check_input(input: &LinkInput) -> Result<(), LinkError> {
    facet_nodes("slave_x", input.slave_facet, input.slave_x)?;
    finite("zeta", &input.zeta)?;
    non_negative("weight", input.weight, false)?;
    non_negative("lambda_n", input.lambda_n, false)?;
    non_negative("penalty", input.penalty, true)?;
    if let Some(f) = &input.friction {
        check_friction(input, f)?;
    }
    match input.master {
        LinkMaster::Facet { facet, x } => facet_nodes("master x", facet, x),
        LinkMaster::Plane { point, normal } => {
            finite("plane point", &point)?;
            nonzero("plane normal", normal)
        }
        LinkMaster::Sphere { centre, radius } => {
            finite("sphere centre", &centre)?;
            non_negative("sphere radius", radius, true)
        }
        LinkMaster::Cylinder {
            point,
            axis,
            radius,
        } => {
            finite("cylinder point", &point)?;
            nonzero("cylinder axis", axis)?;
            non_negative("cylinder radius", radius, true)
        }
    }
}

fn check_friction(input: &LinkInput, f: &Friction) -> Result<(), LinkError> {
    non_negative("friction coefficient", f.mu, false)?;
    non_negative("tangential penalty", f.penalty, true)?;
    let rigid = !matches!(input.master, LinkMaster::Facet { .. });
    match f.history {
        SlipHistory::Convected { xi_n, lambda } if !rigid => {
            finite("xi_n", &xi_n)?;
            finite("lambda_t", &lambda)?;
        }
        SlipHistory::Spatial { point_n, lambda } if rigid => {
            finite("point_n", &point_n)?;
            finite("lambda_t", &lambda)?;
        }
        _ => {
            return Err(LinkError::OutOfRange {
                what: "slip history",
                value: f64::NAN,
                must: "convected for facet masters, spatial for rigid ones",
            })
        }
    }
    if let Some(rate) = &f.rate {
        non_negative("time step", rate.dt, true)?;
        non_negative("dv_dx", rate.dv_dx, false)?;
        let expected_master = if rigid {
            1
        } else {
            master_nodes(&input.master)
        };
        for (what, v, n) in [
            ("slave velocities", rate.slave_v, input.slave_facet.nodes()),
            ("master velocities", rate.master_v, expected_master),
        ] {
            if v.len() != n {
                return Err(LinkError::NodeCount {
                    what,
                    expected: n,
                    got: v.len(),
                });
            }
            finite(what, v.as_flattened())?;
        }
    }
    Ok(())
}

/// Checks the lengths of the output buffers of [`residual_tangent`].
pub fn check_buffers(
    input: &LinkInput,
    r_len: usize,
    k_len: Option<usize>,
) -> Result<(), LinkError> {
    let n = dof_count(input);
    let length = |what, expected, got| {
        if expected == got {
            Ok(())
        } else {
            Err(LinkError::BufferLength {
                what,
                expected,
                got,
            })
        }
    };
    length("r", n, r_len)?;
    k_len.map_or(Ok(()), |len| length("k", n * n, len))
}

/// Nodal positions as constants in `T`, in a holder of `M` nodes.
pub(super) fn nodes_as<T: Scalar, const M: usize>(x: &[[f64; 3]]) -> [Vec3<T>; M] {
    let mut out = [autodiff::constant3([0.0; 3]); M];
    for (o, p) in out.iter_mut().zip(x) {
        *o = autodiff::constant3(*p);
    }
    out
}

/// Nodal positions as dual variables, variable index `offset + 3a + i`.
pub(super) fn seed<const N: usize, const M: usize>(
    x: &[[f64; 3]],
    offset: usize,
) -> [Vec3<Dual<N>>; M] {
    let mut out = [[Dual::constant(0.0); 3]; M];
    for (a, (o, p)) in out.iter_mut().zip(x).enumerate() {
        for (i, (oi, pi)) in o.iter_mut().zip(p).enumerate() {
            *oi = Dual::variable(*pi, offset + 3 * a + i);
        }
    }
    out
}

pub(super) fn master_x<'a>(input: &LinkInput<'a>) -> &'a [[f64; 3]] {
    match input.master {
        LinkMaster::Facet { x, .. } => x,
        _ => &[],
    }
}

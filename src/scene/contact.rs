//! Contact pairs and the Hertz check: `[[contact]]` sections checked
//! against the mesh (facet sets, rigid surfaces, formulation, distinct
//! bodies) into pair specs.
use super::conditions::{amplitude, check_facet_set, check_finite};
use super::limits;
use super::lines::Seg;
use super::parse::{Bad, Checked};
use super::sections::{ContactSection, HertzSection};
use crate::fem::{FacetType, Material};
use crate::hertz::{HertzCheck, HertzKind};
use crate::mesh::Mesh;
use crate::model::{
    Formulation, FrictionSpec, MasterSpec, PairSpec, RigidSurface, SlaveQuadrature,
};

/// Gauss points on quadrilateral slave facets (docs/formulation.md §2.4); on
/// first-order triangles, the slave nodes; on every second-order facet the
/// facet rule of `fem` (tri6 six points, quad8 / quad9 3×3), whose weights
/// on the curved reference facet integrate `N_a |X,₁ × X,₂|` exactly: the
/// nodal rule has no second-order counterpart with positive weights (the
/// tri6 corner functions integrate to zero, quad8's to −⅓). Three Gauss points per triangle put about six
/// constraints on every slave node of a tet mesh, more than linear tets can
/// meet: the Uzawa loop then stalls just above its tolerance (sphere-block:
/// 361 Newton iterations and 7 cutbacks with Gauss points, 85 with one point
/// per facet, 36 and none at the nodes).
pub(super) fn default_quadrature(facet: FacetType) -> SlaveQuadrature {
    match facet {
        FacetType::Tri3 => SlaveQuadrature::Nodal,
        _ => SlaveQuadrature::Gauss,
    }
}

/// The one facet type of a contact surface (any order; whether the pair's
/// formulation takes it is [`formulation`]'s question). A set that mixes
/// facet types is this pair's scene error, before set-up.
fn contact_facet_type(mesh: &Mesh, set: &str, name: &str) -> Result<FacetType, String> {
    let types = mesh.facet_set_types(set).map_err(|e| e.to_string())?;
    match types.as_slice() {
        [] => Ok(mesh.cell_type.face_type(0)),
        [one] => Ok(*one),
        [a, b, ..] => Err(format!(
            "contact pair '{name}': set '{set}' mixes {} and {} facets; contact needs one facet type per surface",
            a.name(),
            b.name()
        )),
    }
}

pub(super) fn contact_spec(mesh: &Mesh, c: &ContactSection, index: usize) -> Checked<PairSpec> {
    let key = |k| [Seg::Key("contact"), Seg::Index(index), Seg::Key(k)];
    let name = c.name.clone().unwrap_or_else(|| format!("pair{index}"));
    let at = format!("[[contact]] '{name}'");
    check_facet_set(mesh, &c.slave, &format!("{at} slave"))
        .map_err(|m| Bad::at(&key("slave"), m))?;
    let facet = contact_facet_type(mesh, &c.slave, &name).map_err(|m| Bad::at(&key("slave"), m))?;
    let mut master_facet = None;
    let master = match (&c.master, &c.rigid) {
        (Some(m), None) => {
            check_facet_set(mesh, m, &format!("{at} master"))
                .map_err(|e| Bad::at(&key("master"), e))?;
            master_facet =
                Some(contact_facet_type(mesh, m, &name).map_err(|e| Bad::at(&key("master"), e))?);
            if m == &c.slave {
                return Err(Bad::at(&key("master"), format!("{at}: slave and master are the same facet set '{m}'; a surface cannot contact itself here")));
            }
            check_different_bodies(mesh, &c.slave, m)
                .map_err(|e| Bad::at(&key("master"), format!("{at}: {e}")))?;
            MasterSpec::Surface { set: m.clone() }
        }
        (None, Some(r)) => {
            r.validate()
                .map_err(|e| Bad::at(&key("rigid"), format!("{at}: {e}")))?;
            MasterSpec::Rigid(*r)
        }
        (Some(_), Some(_)) => {
            return Err(Bad::at(
                &key("rigid"),
                format!(
                "{at}: give either master (a facet set) or rigid (an analytic surface), not both"
            ),
            ))
        }
        (None, None) => {
            return Err(format!("{at}: needs a master facet set or a rigid surface").into())
        }
    };
    if let MasterSpec::Rigid(r) = &master {
        rigid_point(r)
            .iter()
            .try_for_each(|&v| check_finite(v, &format!("{at}: rigid point (or centre)")))
            .map_err(|m| Bad::at(&key("rigid"), m))?;
    }
    if let Some(m) = c.motion {
        m.iter()
            .try_for_each(|&v| check_finite(v, &format!("{at}: motion")))
            .map_err(|e| Bad::at(&key("motion"), e))?;
    }
    if c.motion.is_some() && !master.is_rigid() {
        return Err(Bad::at(&key("motion"), format!("{at}: motion applies to rigid masters only; move a deformable master with [[dirichlet]] values")));
    }
    let mut spec = PairSpec::new(&name, &c.slave, master);
    spec.motion = c.motion.unwrap_or([0.0; 3]);
    if c.motion_amplitude.is_some() && c.motion.is_none() {
        return Err(Bad::at(
            &key("motion_amplitude"),
            format!("{at}: motion_amplitude is set but motion is not"),
        ));
    }
    spec.motion_amplitude = amplitude(&c.motion_amplitude, &format!("{at} motion_amplitude"))
        .map_err(|m| Bad::at(&key("motion_amplitude"), m))?;
    spec.formulation = formulation(&name, facet, master_facet, c, &at)
        .map_err(|m| Bad::at(&key("formulation"), m))?;
    spec.quadrature = match c.quadrature.as_deref() {
        None => default_quadrature(facet),
        Some("gauss") => SlaveQuadrature::Gauss,
        Some("nodal") => SlaveQuadrature::Nodal,
        Some("centroid") => SlaveQuadrature::Centroid,
        Some(other) => {
            return Err(Bad::at(
                &key("quadrature"),
                format!("{at}: quadrature '{other}' is not \"gauss\", \"centroid\" or \"nodal\""),
            ))
        }
    };
    if spec.quadrature == SlaveQuadrature::Nodal && !facet.is_linear() {
        return Err(Bad::at(
            &key("quadrature"),
            format!("{at}: quadrature \"nodal\" puts the points at the corners of first-order facets; the slave facets are {} (use \"gauss\", the default, or \"centroid\")", facet.name()),
        ));
    }
    let positive = |v: f64, k: &'static str| {
        if v > 0.0 && v.is_finite() {
            Ok(v)
        } else {
            Err(Bad::at(
                &key(k),
                format!("{at}: {k} must be positive (got {v})"),
            ))
        }
    };
    spec.penalty = c.penalty.map(|p| positive(p, "penalty")).transpose()?;
    spec.penetration_tol = positive(
        c.penetration_tol.unwrap_or(spec.penetration_tol),
        "penetration_tol",
    )?;
    spec.multiplier_tol = positive(
        c.multiplier_tol.unwrap_or(spec.multiplier_tol),
        "multiplier_tol",
    )?;
    spec.search_distance = c
        .search_distance
        .map(|d| positive(d, "search_distance"))
        .transpose()?;
    spec.max_uzawa = c.max_uzawa.unwrap_or(spec.max_uzawa);
    if spec.max_uzawa == 0 {
        return Err(Bad::at(
            &key("max_uzawa"),
            format!("{at}: max_uzawa must be at least 1"),
        ));
    }
    limits::at_most(
        &format!("{at} max_uzawa"),
        spec.max_uzawa,
        limits::MAX_UZAWA,
    )
    .map_err(|m| Bad::at(&key("max_uzawa"), m))?;
    if let Some(mu) = c.friction {
        if !(mu >= 0.0 && mu.is_finite()) {
            return Err(Bad::at(
                &key("friction"),
                format!("{at}: friction (the coefficient μ) must be zero or positive (got {mu})"),
            ));
        }
    }
    let tangential_penalty = c
        .tangential_penalty
        .map(|p| positive(p, "tangential_penalty"))
        .transpose()?;
    if tangential_penalty.is_some() && c.friction.is_none() {
        return Err(Bad::at(
            &key("tangential_penalty"),
            format!("{at}: tangential_penalty is set but friction is not; give friction = μ"),
        ));
    }
    spec.friction = c.friction.map(|mu| FrictionSpec {
        mu,
        penalty: tangential_penalty,
    });
    Ok(spec)
}

/// The point a rigid surface is placed by (its normal, axis and radius are
/// checked by [`RigidSurface::validate`]).
pub(super) fn rigid_point(r: &RigidSurface) -> [f64; 3] {
    match *r {
        RigidSurface::Plane { point, .. } | RigidSurface::Cylinder { point, .. } => point,
        RigidSurface::Sphere { centre, .. } => centre,
    }
}

/// The pair's `formulation`, checked against what the mortar formulation
/// supports (quad4 or tri3 facets, the same type on both surfaces; a master
/// facet set or a rigid surface). The links take any facet types. Without
/// the key a pair is a mortar pair, unless it sets `quadrature`, which only
/// places links' points: then it asked for links.
pub(super) fn formulation(
    name: &str,
    facet: FacetType,
    master_facet: Option<FacetType>,
    c: &ContactSection,
    at: &str,
) -> std::result::Result<Formulation, String> {
    let f = match c.formulation.as_deref() {
        None if c.quadrature.is_some() => return Ok(Formulation::Links),
        Some("links") => return Ok(Formulation::Links),
        None => Formulation::default(),
        Some("mortar") => Formulation::Mortar,
        Some(other) => {
            return Err(format!(
                "{at}: formulation '{other}' is not \"links\" or \"mortar\""
            ))
        }
    };
    // Mortar on quadratic facets needs a modified dual basis (the standard
    // one has non-positive corner weights there), which is not built.
    if let Some(t) = std::iter::once(facet)
        .chain(master_facet)
        .find(|t| !f.supports(*t))
    {
        return Err(format!(
            "contact pair '{name}': formulation \"mortar\" does not support second-order facets ({}); use formulation = \"links\" for this pair",
            t.name()
        ));
    }
    if let Some(m) = master_facet.filter(|m| *m != facet) {
        return Err(format!(
            "contact pair '{name}': the slave facets are {} and the master facets {}; formulation \"mortar\" needs one facet type on both surfaces (formulation = \"links\" takes both)",
            facet.name(),
            m.name()
        ));
    }
    if c.quadrature.is_some() {
        return Err(format!(
            "{at}: quadrature places the links' points; formulation \"mortar\" integrates the overlaps itself"
        ));
    }
    Ok(f)
}

/// Self-contact (slave and master on one body) is not supported: the search
/// would pair every slave point with its own neighbourhood at zero gap.
pub(super) fn check_different_bodies(
    mesh: &Mesh,
    slave: &str,
    master: &str,
) -> std::result::Result<(), String> {
    let bodies_of = |set: &str| -> Vec<usize> {
        let mut b: Vec<usize> = mesh.facet_sets[set]
            .iter()
            .map(|f| mesh.cell_body[f.cell] as usize)
            .collect();
        b.sort_unstable();
        b.dedup();
        b
    };
    let (s, m) = (bodies_of(slave), bodies_of(master));
    match s.iter().find(|b| m.contains(b)) {
        Some(&b) => Err(format!(
            "slave '{slave}' and master '{master}' both lie on body '{}'; self-contact is not supported (pair surfaces of two different bodies)",
            mesh.bodies[b]
        )),
        None => Ok(()),
    }
}

/// The body a facet set lies on (its first facet's cell).
pub(super) fn body_of_set(mesh: &Mesh, set: &str) -> Option<usize> {
    mesh.facet_sets
        .get(set)?
        .first()
        .map(|f| mesh.cell_body[f.cell] as usize)
}

pub(super) fn hertz_check(
    mesh: &Mesh,
    materials: &[Material],
    pairs: &[PairSpec],
    h: &HertzSection,
) -> std::result::Result<HertzCheck, String> {
    let pair = pairs
        .iter()
        .find(|p| p.name == h.pair)
        .ok_or_else(|| format!("[hertz] pair '{}' is not a [[contact]] name", h.pair))?;
    if !(h.radius.is_finite() && h.radius > 0.0) {
        return Err(format!(
            "[hertz] radius must be positive (got {})",
            h.radius
        ));
    }
    let kind = match (h.kind.as_str(), h.thickness) {
        ("line", Some(t)) if t > 0.0 && t.is_finite() => HertzKind::Line { thickness: t },
        ("line", _) => return Err("[hertz] kind = \"line\" needs a positive thickness".into()),
        ("point", None) => HertzKind::Point,
        ("point", Some(_)) => {
            return Err("[hertz] thickness applies to kind = \"line\" only".into())
        }
        (other, _) => {
            return Err(format!(
                "[hertz] kind '{other}' is not \"line\" or \"point\""
            ))
        }
    };
    let slave = body_of_set(mesh, &pair.slave).ok_or("[hertz] the pair's slave set is empty")?;
    let (e1, nu1) = (materials[slave].youngs(), materials[slave].poisson());
    let inverse_master = match &pair.master {
        MasterSpec::Surface { set } => {
            let m = body_of_set(mesh, set).ok_or("[hertz] the pair's master set is empty")?;
            (1.0 - materials[m].poisson().powi(2)) / materials[m].youngs()
        }
        _ => 0.0,
    };
    Ok(HertzCheck {
        kind,
        pair: h.pair.clone(),
        radius: h.radius,
        effective_modulus: 1.0 / ((1.0 - nu1 * nu1) / e1 + inverse_master),
    })
}

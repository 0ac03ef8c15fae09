//! Dirichlet conditions, amplitudes, dynamics and solver settings, checked
//! against the mesh and the limits.
use super::limits;
use super::lines::Seg;
use super::parse::{Bad, Checked};
use super::sections::{DirichletSection, Scene};
use crate::amplitude::Amplitude;
use crate::mesh::Mesh;
use crate::model::{DirichletSpec, DynamicsSpec, Newmark, Reuse, SolverSettings};

impl Scene {
    /// The dynamics settings, checked: a time step, valid Newmark parameters
    /// and a density for every body. Densities or initial velocities in a
    /// static scene are an error too (they would silently do nothing).
    pub(super) fn dynamics_spec(&self, mesh: &Mesh) -> Checked<Option<DynamicsSpec>> {
        use Seg::{Index, Key};
        let Some(d) = &self.dynamics else {
            if let Some((i, b)) = self
                .bodies
                .iter()
                .enumerate()
                .find(|(_, b)| b.density.is_some() || b.initial_velocity.is_some())
            {
                let key = if b.density.is_some() {
                    "density"
                } else {
                    "initial_velocity"
                };
                return Err(Bad::at(&[Key("body"), Index(i), Key(key)], format!(
                    "[[body]] '{}' has a density or initial_velocity but the scene has no [dynamics] section",
                    b.name
                )));
            }
            return Ok(None);
        };
        if !(d.time_step > 0.0 && d.time_step.is_finite()) {
            return Err(Bad::at(
                &[Key("dynamics"), Key("time_step")],
                format!(
                    "[dynamics] time_step must be positive (got {})",
                    d.time_step
                ),
            ));
        }
        match d.method.as_deref() {
            None | Some("newmark") => {}
            Some(other) => {
                return Err(Bad::at(
                    &[Key("dynamics"), Key("method")],
                    format!("[dynamics] method '{other}' is not known (use \"newmark\")"),
                ))
            }
        }
        let newmark = match (d.beta, d.gamma) {
            (None, None) => Newmark::trapezoidal(),
            (None, Some(g)) => Newmark::with_dissipation(g),
            (Some(b), g) => Newmark {
                beta: b,
                gamma: g.unwrap_or(0.5),
            },
        };
        newmark.validate().map_err(|e| format!("[dynamics] {e}"))?;
        let mut density = Vec::with_capacity(mesh.bodies.len());
        let mut velocity = Vec::with_capacity(mesh.bodies.len());
        for body in &mesh.bodies {
            let i = self
                .bodies
                .iter()
                .position(|b| &b.name == body)
                .unwrap_or(0);
            let key = |k| [Key("body"), Index(i), Key(k)];
            let b = self.bodies.get(i).filter(|b| &b.name == body);
            let rho = b.and_then(|b| b.density).ok_or_else(|| {
                Bad::at(
                    &key("density"),
                    format!("[[body]] '{body}' needs a density: the scene has [dynamics]"),
                )
            })?;
            if !(rho > 0.0 && rho.is_finite()) {
                return Err(Bad::at(
                    &key("density"),
                    format!("[[body]] '{body}': density must be positive (got {rho})"),
                ));
            }
            let v0 = b.and_then(|b| b.initial_velocity).unwrap_or([0.0; 3]);
            v0.iter()
                .try_for_each(|&v| check_finite(v, "[[body]] initial_velocity"))
                .map_err(|m| Bad::at(&key("initial_velocity"), m))?;
            density.push(rho);
            velocity.push(v0);
        }
        Ok(Some(DynamicsSpec {
            time_step: d.time_step,
            newmark,
            density,
            initial_velocity: velocity,
        }))
    }

    pub(super) fn solver_settings(&self) -> Checked<SolverSettings> {
        use Seg::Key;
        let d = SolverSettings::default();
        let s = &self.solver;
        let key = |k| [Key("solver"), Key(k)];
        let positive = |v: f64, k: &'static str| {
            if v > 0.0 && v.is_finite() {
                Ok(v)
            } else {
                Err(Bad::at(
                    &key(k),
                    format!("[solver] {k} must be positive (got {v})"),
                ))
            }
        };
        let count = |v: Option<usize>, default: usize, k: &'static str, max: usize| {
            let v = v.unwrap_or(default);
            limits::at_most(&format!("[solver] {k}"), v, max)
                .map(|()| v)
                .map_err(|m| Bad::at(&key(k), m))
        };
        let petsc_options = s.petsc_options.clone().unwrap_or_default();
        crate::petsc::options::parse_pairs(&petsc_options).map_err(|m| {
            Bad::at(
                &key("petsc_options"),
                format!("[solver] petsc_options: {m}"),
            )
        })?;
        Ok(SolverSettings {
            max_newton: count(s.max_newton, d.max_newton, "max_newton", limits::MAX_NEWTON)?.max(1),
            rtol: positive(s.rtol.unwrap_or(d.rtol), "rtol")?,
            atol: s.atol.map(|a| positive(a, "atol")).transpose()?,
            max_cutbacks: count(
                s.max_cutbacks,
                d.max_cutbacks,
                "max_cutbacks",
                limits::MAX_CUTBACKS,
            )?,
            direct_max_dofs: s.direct_max_dofs.unwrap_or(d.direct_max_dofs),
            petsc_options,
            reuse: Reuse {
                linear_stiffness: s.reuse_linear_stiffness.unwrap_or(d.reuse.linear_stiffness),
                pattern: s.reuse_pattern.unwrap_or(d.reuse.pattern),
                preconditioner: s.lag_preconditioner.unwrap_or(d.reuse.preconditioner),
                active_set: s.lag_active_set.unwrap_or(d.reuse.active_set),
            },
            extrapolate: s.extrapolate.unwrap_or(d.extrapolate),
            uzawa_forcing: match s.uzawa_forcing.unwrap_or(d.uzawa_forcing) {
                f if (0.0..1.0).contains(&f) => f,
                f => {
                    return Err(Bad::at(
                        &key("uzawa_forcing"),
                        format!("[solver] uzawa_forcing must be in [0, 1) (got {f})"),
                    ))
                }
            },
            first_contact_softening: match s
                .first_contact_softening
                .unwrap_or(d.first_contact_softening)
            {
                f if f.is_finite() && f >= 1.0 => f,
                f => {
                    return Err(Bad::at(
                        &key("first_contact_softening"),
                        format!("[solver] first_contact_softening must be at least 1 (got {f})"),
                    ))
                }
            },
            first_contact_main_tangent: s
                .first_contact_main_tangent
                .unwrap_or(d.first_contact_main_tangent),
            contact_schur: s.contact_schur.unwrap_or(d.contact_schur),
            condensed_newton: s.condensed_newton.unwrap_or(d.condensed_newton),
            uzawa_acceleration: match s.uzawa_acceleration {
                None => d.uzawa_acceleration,
                Some(n) if n <= crate::model::MAX_ACCELERATION => Some(n),
                Some(n) => {
                    return Err(Bad::at(
                        &key("uzawa_acceleration"),
                        format!(
                            "[solver] uzawa_acceleration must be 0 (off) to {} (got {n})",
                            crate::model::MAX_ACCELERATION
                        ),
                    ))
                }
            },
        })
    }
}

pub(super) fn check_finite(v: f64, what: &str) -> std::result::Result<(), String> {
    if v.is_finite() {
        Ok(())
    } else {
        Err(format!("{what} must be a finite number (got {v})"))
    }
}

pub(super) fn check_facet_set(
    mesh: &Mesh,
    set: &str,
    section: &str,
) -> std::result::Result<(), String> {
    if mesh.facet_sets.contains_key(set) {
        return Ok(());
    }
    let known: Vec<&str> = mesh.facet_sets.keys().map(String::as_str).collect();
    Err(format!(
        "{section} set '{set}' is not a facet set of the mesh (facet sets: {})",
        known.join(", ")
    ))
}

pub(super) fn dirichlet_spec(
    mesh: &Mesh,
    d: &DirichletSection,
    index: usize,
) -> Checked<DirichletSpec> {
    let key = |k| [Seg::Key("dirichlet"), Seg::Index(index), Seg::Key(k)];
    let nodes = match mesh.node_sets.get(&d.set) {
        Some(n) => n.clone(),
        None => {
            let known: Vec<&str> = mesh.node_sets.keys().map(String::as_str).collect();
            return Err(Bad::at(
                &key("set"),
                format!(
                    "[[dirichlet]] set '{}' is not a node set of the mesh (node sets: {})",
                    d.set,
                    known.join(", ")
                ),
            ));
        }
    };
    let names = d
        .components
        .clone()
        .unwrap_or_else(|| vec!["x".into(), "y".into(), "z".into()]);
    let mut components = Vec::new();
    for n in &names {
        let c = match n.as_str() {
            "x" => 0,
            "y" => 1,
            "z" => 2,
            other => {
                return Err(Bad::at(
                    &key("components"),
                    format!(
                        "[[dirichlet]] set '{}': component '{other}' is not one of x, y, z",
                        d.set
                    ),
                ))
            }
        };
        if components.contains(&c) {
            return Err(Bad::at(
                &key("components"),
                format!(
                    "[[dirichlet]] set '{}': component '{n}' listed twice",
                    d.set
                ),
            ));
        }
        components.push(c);
    }
    let values = d
        .value
        .clone()
        .unwrap_or_else(|| vec![0.0; components.len()]);
    if values.len() != components.len() {
        return Err(Bad::at(
            &key("value"),
            format!(
                "[[dirichlet]] set '{}': {} values for {} components ({})",
                d.set,
                values.len(),
                components.len(),
                names.join(", ")
            ),
        ));
    }
    let mut full = [0.0; 3];
    for (&c, &v) in components.iter().zip(&values) {
        check_finite(v, "[[dirichlet]] value").map_err(|m| Bad::at(&key("value"), m))?;
        full[c] = v;
    }
    let mut spec = DirichletSpec::uniform(&d.set, nodes, components, full);
    spec.amplitude = amplitude(&d.amplitude, &format!("[[dirichlet]] set '{}'", d.set))
        .map_err(|m| Bad::at(&key("amplitude"), m))?;
    Ok(spec)
}

/// An optional amplitude table, checked; a linear ramp when absent.
pub(super) fn amplitude(
    table: &Option<Vec<[f64; 2]>>,
    at: &str,
) -> std::result::Result<Amplitude, String> {
    match table {
        None => Ok(Amplitude::ramp()),
        Some(t) => Amplitude::from_table(t).map_err(|e| format!("{at}: {e}")),
    }
}

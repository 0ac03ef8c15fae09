//! [`Scene::build`]: the checked sections assembled into a [`Model`].
use super::conditions::{amplitude, check_facet_set, check_finite, dirichlet_spec};
use super::contact::{contact_spec, hertz_check};
use super::held;
use super::limits;
use super::lines::Seg;
use super::mesh::MeshReport;
use super::sections::{IntegrationName, MaterialName, Scene};
use crate::error::{Error, Result};
use crate::fem::{Integration, Material, QuadRule};
use crate::mesh::generate;
use crate::mesh::Mesh;
use crate::model::{FacetLoad, Model};

impl Scene {
    /// The output path the scene asks for, if any.
    pub fn output_path(&self) -> Option<&str> {
        self.output.path.as_deref()
    }

    /// Builds the mesh and checks every reference in the scene against it.
    pub fn build(&self, origin: &str) -> Result<Model> {
        Ok(self.build_with_report(origin)?.0)
    }

    /// [`Scene::build`], and what reading the mesh found (for `check`).
    pub fn build_with_report(&self, origin: &str) -> Result<(Model, MeshReport)> {
        use Seg::{Index, Key};
        let (mut mesh, report) = self.build_mesh(origin)?;
        mesh.validate()
            .map_err(|e| self.error_at(origin, &[Key("mesh")], format!("[mesh]: {e}")))?;
        if let Some(d) = &self.distort {
            mesh = generate::perturb_interior(&mesh, d.fraction, d.seed).map_err(|e| {
                self.error_at(
                    origin,
                    &[Key("distort"), Key("fraction")],
                    format!("[distort]: {e}"),
                )
            })?;
        }
        let mut materials = Vec::with_capacity(mesh.bodies.len());
        let mut integration = Vec::with_capacity(mesh.bodies.len());
        for body in &mesh.bodies {
            let Some(i) = self.bodies.iter().position(|b| &b.name == body) else {
                let given: Vec<&str> = self.bodies.iter().map(|b| b.name.as_str()).collect();
                return Err(self.error_at(
                    origin,
                    &[Key("mesh")],
                    format!(
                        "the mesh has a body '{body}' but no [[body]] gives its material (the scene's [[body]] names: {})",
                        given.join(", ")
                    ),
                ));
            };
            let section = &self.bodies[i];
            let m = match section.material {
                MaterialName::LinearElastic => Material::LinearElastic {
                    youngs: section.youngs,
                    poisson: section.poisson,
                },
                MaterialName::NeoHookean => Material::NeoHookean {
                    youngs: section.youngs,
                    poisson: section.poisson,
                },
            };
            m.validate().map_err(|e| {
                // validate() checks youngs first, so any other error is about ν.
                let (key, value) = match e {
                    crate::fem::MaterialError::InvalidYoungs { youngs } => ("youngs", youngs),
                    _ => ("poisson", section.poisson),
                };
                self.error_at(
                    origin,
                    &[Key("body"), Index(i), Key(key)],
                    format!("[[body]] '{}' {key} = {value}: {e}", section.name),
                )
            })?;
            materials.push(m);
            let rule = match section.integration {
                IntegrationName::Full => Integration::Full,
                IntegrationName::Reduced => Integration::Reduced,
            };
            if QuadRule::for_cell(mesh.cell_type, rule).is_none() {
                return Err(self.error_at(
                    origin,
                    &[Key("body"), Index(i), Key("integration")],
                    format!(
                        "[[body]] '{}' integration = \"{}\": {} cells have no reduced rule (only hex20 has: Abaqus' C3D20R)",
                        section.name,
                        rule.name(),
                        mesh.cell_type.name()
                    ),
                ));
            }
            integration.push(rule);
        }
        for (i, b) in self.bodies.iter().enumerate() {
            if !mesh.bodies.contains(&b.name) {
                return Err(self.error_at(
                    origin,
                    &[Key("body"), Index(i), Key("name")],
                    format!(
                        "[[body]] '{}' is not a body of the mesh (bodies: {})",
                        b.name,
                        mesh.bodies.join(", ")
                    ),
                ));
            }
        }
        let dirichlet = self
            .dirichlet
            .iter()
            .enumerate()
            .map(|(i, d)| {
                dirichlet_spec(&mesh, d, i)
                    .map_err(self.located(origin, &[Key("dirichlet"), Index(i)]))
            })
            .collect::<Result<Vec<_>>>()?;
        let mut facet_loads = Vec::new();
        for (i, p) in self.pressure.iter().enumerate() {
            let at = |key| [Key("pressure"), Index(i), Key(key)];
            let here = |key, m: String| self.error_at(origin, &at(key), m);
            check_facet_set(&mesh, &p.set, "[[pressure]]").map_err(|m| here("set", m))?;
            check_finite(p.value, "[[pressure]] value").map_err(|m| here("value", m))?;
            let a = amplitude(&p.amplitude, &format!("[[pressure]] '{}'", p.set))
                .map_err(|m| here("amplitude", m))?;
            facet_loads.push((p.set.clone(), FacetLoad::Pressure(p.value), a));
        }
        for (i, t) in self.traction.iter().enumerate() {
            let at = |key| [Key("traction"), Index(i), Key(key)];
            let here = |key, m: String| self.error_at(origin, &at(key), m);
            check_facet_set(&mesh, &t.set, "[[traction]]").map_err(|m| here("set", m))?;
            t.vector
                .iter()
                .try_for_each(|&v| check_finite(v, "[[traction]] vector"))
                .map_err(|m| here("vector", m))?;
            let a = amplitude(&t.amplitude, &format!("[[traction]] '{}'", t.set))
                .map_err(|m| here("amplitude", m))?;
            facet_loads.push((t.set.clone(), FacetLoad::Traction(t.vector), a));
        }
        let mut body_force = vec![[0.0; 3]; mesh.bodies.len()];
        for (j, bf) in self.body_force.iter().enumerate() {
            let i = mesh
                .bodies
                .iter()
                .position(|b| b == &bf.body)
                .ok_or_else(|| {
                    self.error_at(
                        origin,
                        &[Key("body_force"), Index(j), Key("body")],
                        format!(
                            "[[body_force]] body '{}' does not exist (bodies: {})",
                            bf.body,
                            mesh.bodies.join(", ")
                        ),
                    )
                })?;
            // A NaN here would reach every residual of the body and fail
            // the first solve far from its cause.
            bf.vector
                .iter()
                .try_for_each(|&v| check_finite(v, "vector"))
                .map_err(|m| {
                    self.error_at(
                        origin,
                        &[Key("body_force"), Index(j), Key("vector")],
                        format!("[[body_force]] body '{}': {m}", bf.body),
                    )
                })?;
            for (acc, v) in body_force[i].iter_mut().zip(bf.vector) {
                *acc += v;
            }
        }
        let contact = self
            .contact
            .iter()
            .enumerate()
            .map(|(i, c)| {
                contact_spec(&mesh, c, i).map_err(self.located(origin, &[Key("contact"), Index(i)]))
            })
            .collect::<Result<Vec<_>>>()?;
        let mut names: Vec<&str> = contact.iter().map(|c| c.name.as_str()).collect();
        names.sort_unstable();
        if let Some(w) = names.windows(2).find(|w| w[0] == w[1]) {
            let second = self
                .contact
                .iter()
                .enumerate()
                .filter(|(i, c)| c.name.clone().unwrap_or_else(|| format!("pair{i}")) == w[0]);
            let i = second.map(|(i, _)| i).nth(1).unwrap_or(0);
            return Err(self.error_at(
                origin,
                &[Key("contact"), Index(i), Key("name")],
                format!("two [[contact]] pairs are named '{}'", w[0]),
            ));
        }
        let hertz = match &self.hertz {
            Some(h) => Some(
                hertz_check(&mesh, &materials, &contact, h)
                    .map_err(|m| self.error_at(origin, &[Key("hertz")], m))?,
            ),
            None => None,
        };
        if self.steps.count == 0 {
            return Err(self.error_at(
                origin,
                &[Key("steps"), Key("count")],
                "[steps] count must be at least 1",
            ));
        }
        limits::at_most("[steps] count", self.steps.count, limits::MAX_STEPS)
            .map_err(|m| self.error_at(origin, &[Key("steps"), Key("count")], m))?;
        let solver = self
            .solver_settings()
            .map_err(self.located(origin, &[Key("solver")]))?;
        let dynamics = self
            .dynamics_spec(&mesh)
            .map_err(self.located(origin, &[Key("dynamics")]))?;
        // A static body that nothing holds has rigid-body modes: the linear
        // solver would fail (or return garbage) in the first step. Contact
        // may hold a body, and a mass matrix makes any body's operator regular.
        if dynamics.is_none() {
            if let Some(group) = held::unheld_group(&mesh, &dirichlet, &contact) {
                return Err(self.unheld_error(origin, &mesh, &group));
            }
        }
        let model = Model {
            name: self.title.clone().unwrap_or_else(|| origin.to_owned()),
            mesh,
            materials,
            integration,
            dirichlet,
            facet_loads,
            body_force,
            body_force_fn: None,
            contact,
            hertz,
            steps: self.steps.count,
            solver,
            dynamics,
        };
        Ok((model, report))
    }

    /// The error for a group of static bodies that nothing holds, at the
    /// `[[body]]` line of its first body.
    pub(super) fn unheld_error(&self, origin: &str, mesh: &Mesh, group: &held::Unheld) -> Error {
        let names: Vec<String> = group
            .bodies
            .iter()
            .map(|&b| format!("'{}'", mesh.bodies[b]))
            .collect();
        let first = &mesh.bodies[group.bodies[0]];
        let i = self
            .bodies
            .iter()
            .position(|s| &s.name == first)
            .unwrap_or(0);
        let message = match (names.len(), group.in_contact) {
            (1, false) => format!(
                "body {} has no [[dirichlet]] condition and no contact pair: nothing holds it, so its stiffness is singular (fix some of its nodes, give it a contact partner, or add [dynamics])",
                names[0]
            ),
            (1, true) => format!(
                "body {} is held by nothing: it has no [[dirichlet]] condition and no contact with a held body or a rigid surface, so its stiffness is singular (fix some of its nodes, or add [dynamics])",
                names[0]
            ),
            _ => format!(
                "bodies {} are held only through contact with each other: none has a [[dirichlet]] condition or a rigid contact surface, so together they float and their stiffness is singular (fix some nodes of one of them, or add [dynamics])",
                names.join(", ")
            ),
        };
        self.error_at(
            origin,
            &[Seg::Key("body"), Seg::Index(i), Seg::Key("name")],
            message,
        )
    }
}

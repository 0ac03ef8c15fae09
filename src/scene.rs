//! Scene files (TOML) → a validated [`Model`].
//!
//! A scene names the mesh (a generator and its parameters), a material per
//! body, Dirichlet conditions, loads, load steps, solver options and the
//! output path. Built-in scenes live in `scenes/` and are compiled in.
//! Every error names the key (and, for syntax errors, the line).
use crate::assembly::FacetLoad;
use crate::contact::{MasterSpec, PairSpec, RigidSurface, SlaveQuadrature};
use crate::error::{Error, Result};
use crate::fem::{CellType, Material};
use crate::mesh::generate::{
    self, BoxSpec, Grading, HertzCylinderSpec, HertzSphereSpec, StackedSpec,
};
use crate::mesh::Mesh;
use crate::solve::newmark::Newmark;
use crate::solve::{DirichletSpec, DynamicsSpec, Model, SolverSettings};
use crate::verify::{HertzCheck, HertzKind};
use serde::Deserialize;
use std::path::Path;

mod held;
mod limits;
mod lines;
pub use lines::{KeyLines, Origin, Seg};

/// The scenes compiled into the binary: (name, one-line description, TOML).
pub const BUILTIN: &[(&str, &str, &str)] = &[
    (
        "hertz-cylinder",
        "Hertz line contact: half-cylinder on a block, plane strain, frictionless",
        include_str!("../scenes/hertz-cylinder.toml"),
    ),
    (
        "hertz-sphere",
        "Hertz point contact: sphere cap on a block, frictionless",
        include_str!("../scenes/hertz-sphere.toml"),
    ),
    (
        "patch-test",
        "Contact patch test: stacked blocks with non-matching meshes, uniform compression",
        include_str!("../scenes/patch-test.toml"),
    ),
    (
        "block-on-plane",
        "Neo-Hookean block pressed onto a rigid plane (rigid analytic master)",
        include_str!("../scenes/block-on-plane.toml"),
    ),
    (
        "block-slide",
        "Block pressed on a rigid plane and pulled: Coulomb friction (μ = 0.3), stick then slip",
        include_str!("../scenes/block-slide.toml"),
    ),
    (
        "ironing",
        "Stiff die pressed into a soft slab and dragged along it, μ = 0.3 (Puso & Laursen 2004)",
        include_str!("../scenes/ironing.toml"),
    ),
    (
        "impact",
        "Two free blocks colliding obliquely, implicit dynamics: momentum conserved",
        include_str!("../scenes/impact.toml"),
    ),
    (
        "block-compress",
        "Neo-Hookean block compressed 20 % by a follower pressure (finite strain)",
        include_str!("../scenes/block-compress.toml"),
    ),
    (
        "uniaxial-stretch",
        "Neo-Hookean cube stretched to twice its length (closed form known)",
        include_str!("../scenes/uniaxial-stretch.toml"),
    ),
    (
        "cantilever",
        "Linear-elastic cantilever under an end traction, graded tet mesh",
        include_str!("../scenes/cantilever.toml"),
    ),
];

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Scene {
    pub title: Option<String>,
    pub mesh: MeshSection,
    #[serde(rename = "body")]
    pub bodies: Vec<BodySection>,
    #[serde(default)]
    pub dirichlet: Vec<DirichletSection>,
    #[serde(default)]
    pub pressure: Vec<PressureSection>,
    #[serde(default)]
    pub traction: Vec<TractionSection>,
    #[serde(default)]
    pub body_force: Vec<BodyForceSection>,
    #[serde(default)]
    pub contact: Vec<ContactSection>,
    pub hertz: Option<HertzSection>,
    #[serde(default)]
    pub steps: StepsSection,
    pub dynamics: Option<DynamicsSection>,
    pub distort: Option<DistortSection>,
    #[serde(default)]
    pub solver: SolverSection,
    #[serde(default)]
    pub output: OutputSection,
    /// The text and overrides the scene came from, to give errors a line.
    #[serde(skip)]
    pub lines: KeyLines,
}

#[derive(Debug, Deserialize)]
#[serde(tag = "generator", rename_all = "kebab-case")]
pub enum MeshSection {
    Box(BoxSection),
    HertzCylinder(HertzCylinderSection),
    HertzSphere(HertzSphereSection),
    StackedBlocks(StackedSection),
    Gmsh(GmshSection),
}

/// A Gmsh `.msh` 4.1 file; a relative `file` is relative to the scene
/// file's directory (for a built-in scene, the crate's `scenes/`).
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct GmshSection {
    pub file: String,
}

#[derive(Debug, Deserialize, Clone, Copy, Default)]
#[serde(rename_all = "lowercase")]
pub enum CellTypeName {
    #[default]
    Hex8,
    Tet4,
}

impl From<CellTypeName> for CellType {
    fn from(c: CellTypeName) -> Self {
        match c {
            CellTypeName::Hex8 => CellType::Hex8,
            CellTypeName::Tet4 => CellType::Tet4,
        }
    }
}

/// Element size variation along one axis.
#[derive(Debug, Deserialize, Clone, Copy, Default)]
#[serde(tag = "kind", rename_all = "lowercase", deny_unknown_fields)]
pub enum GradingSection {
    #[default]
    Uniform,
    Geometric {
        ratio: f64,
    },
    Toward {
        point: f64,
        ratio: f64,
    },
}

impl From<GradingSection> for Grading {
    fn from(g: GradingSection) -> Self {
        match g {
            GradingSection::Uniform => Grading::Uniform,
            GradingSection::Geometric { ratio } => Grading::Geometric { ratio },
            GradingSection::Toward { point, ratio } => Grading::Toward { point, ratio },
        }
    }
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct BoxSection {
    #[serde(default = "default_block")]
    pub body: String,
    #[serde(default)]
    pub origin: [f64; 3],
    pub size: [f64; 3],
    pub divisions: [usize; 3],
    #[serde(default)]
    pub grading: [GradingSection; 3],
    #[serde(default)]
    pub cell_type: CellTypeName,
}

fn default_block() -> String {
    "block".into()
}

#[derive(Debug, Deserialize, Default)]
#[serde(deny_unknown_fields)]
pub struct HertzCylinderSection {
    pub radius: Option<f64>,
    pub block_width: Option<f64>,
    pub block_height: Option<f64>,
    pub thickness: Option<f64>,
    pub gap: Option<f64>,
    pub fine_size: Option<f64>,
    pub fine_half_width: Option<f64>,
    pub growth: Option<f64>,
    pub level: Option<u32>,
    pub cell_type: Option<CellTypeName>,
}

#[derive(Debug, Deserialize, Default)]
#[serde(deny_unknown_fields)]
pub struct HertzSphereSection {
    pub radius: Option<f64>,
    pub block_width: Option<f64>,
    pub block_height: Option<f64>,
    pub gap: Option<f64>,
    pub fine_size: Option<f64>,
    pub fine_half_width: Option<f64>,
    pub growth: Option<f64>,
    pub level: Option<u32>,
    pub cell_type: Option<CellTypeName>,
}

#[derive(Debug, Deserialize, Default)]
#[serde(deny_unknown_fields)]
pub struct StackedSection {
    pub length: Option<f64>,
    pub height: Option<f64>,
    pub gap: Option<f64>,
    pub lower_divisions: Option<[usize; 3]>,
    pub upper_divisions: Option<[usize; 3]>,
    pub cell_type: Option<CellTypeName>,
}

#[derive(Debug, Deserialize, Clone, Copy)]
#[serde(rename_all = "kebab-case")]
pub enum MaterialName {
    LinearElastic,
    NeoHookean,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct BodySection {
    pub name: String,
    pub material: MaterialName,
    pub youngs: f64,
    pub poisson: f64,
    /// Mass density (needed in dynamics only).
    pub density: Option<f64>,
    /// Initial velocity of the whole body (dynamics).
    pub initial_velocity: Option<[f64; 3]>,
}

/// Random distortion of the generated mesh (stress tests): every node moves
/// by up to `fraction` of its shortest edge; nodes on flat boundaries move
/// only within them, corners and edges of the bodies stay.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct DistortSection {
    pub fraction: f64,
    #[serde(default)]
    pub seed: u64,
}

/// Implicit dynamics: Newmark time stepping; `[steps] count` steps of
/// `time_step`, loads and amplitudes follow t / t_end.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct DynamicsSection {
    pub time_step: f64,
    /// "newmark" (the only method; β, γ below).
    pub method: Option<String>,
    /// Newmark β (default 1/4, or (γ + 1/2)²/4 when only γ is given).
    pub beta: Option<f64>,
    /// Newmark γ (default 1/2: the trapezoidal rule, no numerical damping).
    pub gamma: Option<f64>,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct DirichletSection {
    pub set: String,
    /// Subset of "x", "y", "z"; all three when absent.
    pub components: Option<Vec<String>>,
    /// Displacement of each listed component at full load; zero when absent.
    pub value: Option<Vec<f64>>,
    /// Load path `[[load_factor, amplitude], ...]` (default: linear ramp).
    pub amplitude: Option<Vec<[f64; 2]>>,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct PressureSection {
    pub set: String,
    pub value: f64,
    pub amplitude: Option<Vec<[f64; 2]>>,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct TractionSection {
    pub set: String,
    pub vector: [f64; 3],
    pub amplitude: Option<Vec<[f64; 2]>>,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct BodyForceSection {
    pub body: String,
    pub vector: [f64; 3],
}

/// Compare a pair against Hertz (printed after the run).
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct HertzSection {
    /// "line" (cylinder, plane strain) or "point" (sphere).
    pub kind: String,
    pub pair: String,
    pub radius: f64,
    /// Out-of-plane thickness of a line contact model.
    pub thickness: Option<f64>,
}

/// A contact pair: `slave` and `master` facet sets, or `slave` and a `rigid` surface.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ContactSection {
    pub name: Option<String>,
    pub slave: String,
    pub master: Option<String>,
    pub rigid: Option<RigidSurface>,
    /// Translation of the rigid surface at full load.
    pub motion: Option<[f64; 3]>,
    /// Load path of the motion `[[load_factor, amplitude], ...]`.
    pub motion_amplitude: Option<Vec<[f64; 2]>>,
    pub penalty: Option<f64>,
    pub penetration_tol: Option<f64>,
    pub multiplier_tol: Option<f64>,
    pub max_uzawa: Option<usize>,
    pub search_distance: Option<f64>,
    /// "gauss" (default) or "nodal": where the slave links sit.
    pub quadrature: Option<String>,
    /// "links" (default) or "mortar".
    pub formulation: Option<String>,
    /// Coulomb friction coefficient μ (absent or 0: frictionless).
    pub friction: Option<f64>,
    /// Tangential penalty εT (default: the normal penalty).
    pub tangential_penalty: Option<f64>,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct StepsSection {
    #[serde(default = "one")]
    pub count: usize,
}

impl Default for StepsSection {
    fn default() -> Self {
        StepsSection { count: 1 }
    }
}

fn one() -> usize {
    1
}

#[derive(Debug, Deserialize, Default)]
#[serde(deny_unknown_fields)]
pub struct SolverSection {
    pub max_newton: Option<usize>,
    pub rtol: Option<f64>,
    pub atol: Option<f64>,
    pub max_cutbacks: Option<usize>,
    /// Up to this many DOFs the default linear solver is direct (MUMPS).
    pub direct_max_dofs: Option<usize>,
    pub petsc_options: Option<String>,
    /// Reuse switches (default true), to measure what each saves.
    pub reuse_linear_stiffness: Option<bool>,
    pub reuse_pattern: Option<bool>,
    pub lag_preconditioner: Option<bool>,
    pub lag_active_set: Option<bool>,
    /// Start a step from the last two converged steps extrapolated (default false).
    pub extrapolate: Option<bool>,
    /// Relative residual reduction of Newton in non-final Uzawa iterations
    /// (0: every solve to the final tolerance).
    pub uzawa_forcing: Option<f64>,
}

#[derive(Debug, Deserialize, Default)]
#[serde(deny_unknown_fields)]
pub struct OutputSection {
    pub path: Option<String>,
}

/// Where a scene came from, for messages.
#[derive(Debug, Clone)]
pub struct SceneSource {
    pub origin: String,
    pub text: String,
    /// The scene file read (none for a built-in scene).
    pub path: Option<std::path::PathBuf>,
}

impl SceneSource {
    /// A built-in scene by name, or a file by path.
    pub fn resolve(name_or_path: &str) -> Result<Self> {
        if let Some((name, _, text)) = BUILTIN.iter().find(|(n, _, _)| *n == name_or_path) {
            return Ok(SceneSource {
                origin: format!("built-in scene '{name}'"),
                text: (*text).to_owned(),
                path: None,
            });
        }
        let path = Path::new(name_or_path);
        let text = std::fs::read_to_string(path).map_err(|e| {
            let known: Vec<&str> = BUILTIN.iter().map(|(n, _, _)| *n).collect();
            Error::scene(
                name_or_path,
                format!(
                    "cannot read it ({e}); it is not a built-in scene either (built-ins: {})",
                    known.join(", ")
                ),
            )
        })?;
        Ok(SceneSource {
            origin: path.display().to_string(),
            text,
            path: Some(path.to_path_buf()),
        })
    }
}

/// Parses a scene, applying `overrides` ("a.b=value", TOML values) first.
pub fn parse(src: &SceneSource, overrides: &[String]) -> Result<Scene> {
    let mut scene = parse_values(src, overrides)?;
    scene.lines = KeyLines::new(&src.text, overrides);
    Ok(scene)
}

fn parse_values(src: &SceneSource, overrides: &[String]) -> Result<Scene> {
    if overrides.is_empty() {
        // Straight from the text, so errors carry the line and column.
        return toml::from_str(&src.text).map_err(|e| toml_error(src, &e));
    }
    let mut doc: toml::Table = toml::from_str(&src.text).map_err(|e| toml_error(src, &e))?;
    for o in overrides {
        apply_override(&mut doc, o)
            .map_err(|m| Error::scene(&src.origin, format!("--set {o}: {m}")))?;
    }
    Scene::deserialize(toml::Value::Table(doc)).map_err(|e| {
        // Overridden values carry no spans. An error the file has on its own
        // is located in the file; any other came with the overrides.
        match toml::from_str::<Scene>(&src.text) {
            Err(own) if own.message() == e.message() => toml_error(src, &own),
            _ => {
                let given: Vec<String> = overrides.iter().map(|o| format!("--set {o}")).collect();
                let mut err = toml_error(src, &e);
                if let Error::Scene { message, .. } = &mut err {
                    *message = format!("{}: {message}", given.join(" "));
                }
                err
            }
        }
    })
}

/// A syntax or schema error from toml/serde as one line, `origin:LINE:
/// message` (toml's own rendering spans several lines with a code excerpt).
fn toml_error(src: &SceneSource, e: &toml::de::Error) -> Error {
    let message = match e.message().trim() {
        "missing field `mesh`" => {
            "no [mesh] section (the mesh generator and its parameters)".to_owned()
        }
        "missing field `body`" => {
            "no [[body]] section (one per mesh body, with its material)".to_owned()
        }
        m => m.lines().map(str::trim).collect::<Vec<_>>().join("; "),
    };
    match e.span() {
        Some(span) => Error::scene(
            with_line(&src.origin, lines::line_of(&src.text, span.start)),
            message,
        ),
        None => Error::scene(&src.origin, message),
    }
}

fn apply_override(doc: &mut toml::Table, assignment: &str) -> std::result::Result<(), String> {
    let (path, value) = assignment
        .split_once('=')
        .ok_or("expected key.path=value")?;
    let parsed: toml::Value = toml::from_str::<toml::Table>(&format!("v = {value}"))
        .ok()
        .and_then(|mut t| t.remove("v"))
        .unwrap_or_else(|| toml::Value::String(value.to_owned()));
    let keys: Vec<&str> = path.trim().split('.').collect();
    let mut node = doc;
    let mut i = 0;
    while i < keys.len() {
        let k = keys[i];
        if i + 1 == keys.len() {
            node.insert(k.to_owned(), parsed);
            return Ok(());
        }
        let entry = node
            .entry(k.to_owned())
            .or_insert_with(|| toml::Value::Table(toml::Table::new()));
        i += 1;
        node = match entry {
            toml::Value::Table(t) => t,
            // An array of tables ([[contact]]): the only one, or the one the
            // next key names by index (dirichlet.2.value).
            toml::Value::Array(a) => {
                let index = match keys[i].parse::<usize>() {
                    Ok(n) if i + 1 < keys.len() => {
                        i += 1;
                        n
                    }
                    _ if a.len() == 1 => 0,
                    _ => {
                        return Err(format!(
                            "'{k}' has {} entries: name one as {k}.N.key (N from 0)",
                            a.len()
                        ))
                    }
                };
                let len = a.len();
                match a.get_mut(index) {
                    Some(toml::Value::Table(t)) => t,
                    _ => return Err(format!("'{k}' has no table entry {index} (it has {len})")),
                }
            }
            _ => return Err(format!("'{k}' is not a table")),
        };
    }
    Err("empty key".into())
}

/// A semantic scene error and the key it is about (an absolute key path;
/// empty: the section the caller names), so the message can give its line.
#[derive(Debug)]
struct Bad {
    path: Vec<Seg>,
    message: String,
}

impl Bad {
    fn at(path: &[Seg], message: impl Into<String>) -> Self {
        Bad {
            path: path.to_vec(),
            message: message.into(),
        }
    }
}

impl From<String> for Bad {
    fn from(message: String) -> Self {
        Bad {
            path: Vec::new(),
            message,
        }
    }
}

impl From<&str> for Bad {
    fn from(message: &str) -> Self {
        message.to_owned().into()
    }
}

type Checked<T> = std::result::Result<T, Bad>;

/// `origin` with a line: `path:14` for a file, `..., line 14` for a built-in.
fn with_line(origin: &str, line: usize) -> String {
    if origin.starts_with("built-in") {
        format!("{origin}, line {line}")
    } else {
        format!("{origin}:{line}")
    }
}

impl Scene {
    /// An error about the key at `path`: names its line in the scene file,
    /// or the `--set` override that supplied it.
    pub fn error_at(&self, origin: &str, path: &[Seg], message: impl Into<String>) -> Error {
        let message = message.into();
        match self.lines.locate(path) {
            Origin::Line(n) => Error::scene(with_line(origin, n), message),
            Origin::Override(o) => Error::scene(origin, format!("--set {o}: {message}")),
            Origin::Unknown => Error::scene(origin, message),
        }
    }

    /// Turns a [`Bad`] into an error at its key, or at `section` when it
    /// names none.
    fn located<'a>(&'a self, origin: &'a str, section: &'a [Seg]) -> impl Fn(Bad) -> Error + 'a {
        move |b| {
            let path = if b.path.is_empty() { section } else { &b.path };
            self.error_at(origin, path, b.message)
        }
    }

    /// The mesh file the scene reads, if any (a Gmsh `[mesh] file`).
    pub fn mesh_file(&self, origin: &str) -> Option<std::path::PathBuf> {
        match &self.mesh {
            MeshSection::Gmsh(g) => Some(gmsh_path(g, origin)),
            _ => None,
        }
    }

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
    fn unheld_error(&self, origin: &str, mesh: &Mesh, group: &held::Unheld) -> Error {
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

    /// The dynamics settings, checked: a time step, valid Newmark parameters
    /// and a density for every body. Densities or initial velocities in a
    /// static scene are an error too (they would silently do nothing).
    fn dynamics_spec(&self, mesh: &Mesh) -> Checked<Option<DynamicsSpec>> {
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

    fn solver_settings(&self) -> Checked<SolverSettings> {
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
            reuse: crate::solve::Reuse {
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
        })
    }

    fn build_mesh(&self, origin: &str) -> Result<(Mesh, MeshReport)> {
        self.generate_mesh(origin).map_err(|e| match e {
            Error::Mesh(m) => {
                let key = lines::mesh_key(&m);
                let at: Vec<Seg> = std::iter::once(Seg::Key("mesh"))
                    .chain(key.map(Seg::Key))
                    .collect();
                self.error_at(origin, &at, format!("[mesh] {m}"))
            }
            other => other,
        })
    }

    fn generate_mesh(&self, origin: &str) -> Result<(Mesh, MeshReport)> {
        let mut report = MeshReport::default();
        let mesh = match &self.mesh {
            MeshSection::Box(b) => generate::graded_box(&BoxSpec {
                body: b.body.clone(),
                origin: b.origin,
                size: b.size,
                divisions: b.divisions,
                grading: b.grading.map(Grading::from),
                cell_type: b.cell_type.into(),
            })?,
            MeshSection::HertzCylinder(h) => {
                let d = HertzCylinderSpec::default();
                generate::hertz_cylinder(&HertzCylinderSpec {
                    radius: h.radius.unwrap_or(d.radius),
                    block_width: h.block_width.unwrap_or(d.block_width),
                    block_height: h.block_height.unwrap_or(d.block_height),
                    thickness: h.thickness.unwrap_or(d.thickness),
                    gap: h.gap.unwrap_or(d.gap),
                    fine_size: h.fine_size.unwrap_or(d.fine_size),
                    fine_half_width: h.fine_half_width.unwrap_or(d.fine_half_width),
                    growth: h.growth.unwrap_or(d.growth),
                    level: h.level.unwrap_or(d.level),
                    cell_type: h.cell_type.map(CellType::from).unwrap_or(d.cell_type),
                })?
            }
            MeshSection::HertzSphere(h) => {
                let d = HertzSphereSpec::default();
                generate::hertz_sphere(&HertzSphereSpec {
                    radius: h.radius.unwrap_or(d.radius),
                    block_width: h.block_width.unwrap_or(d.block_width),
                    block_height: h.block_height.unwrap_or(d.block_height),
                    gap: h.gap.unwrap_or(d.gap),
                    fine_size: h.fine_size.unwrap_or(d.fine_size),
                    fine_half_width: h.fine_half_width.unwrap_or(d.fine_half_width),
                    growth: h.growth.unwrap_or(d.growth),
                    level: h.level.unwrap_or(d.level),
                    cell_type: h.cell_type.map(CellType::from).unwrap_or(d.cell_type),
                })?
            }
            MeshSection::StackedBlocks(s) => {
                let d = StackedSpec::default();
                generate::stacked_blocks(&StackedSpec {
                    length: s.length.unwrap_or(d.length),
                    height: s.height.unwrap_or(d.height),
                    gap: s.gap.unwrap_or(d.gap),
                    lower_divisions: s.lower_divisions.unwrap_or(d.lower_divisions),
                    upper_divisions: s.upper_divisions.unwrap_or(d.upper_divisions),
                    cell_type: s.cell_type.map(CellType::from).unwrap_or(d.cell_type),
                    ..d
                })?
            }
            MeshSection::Gmsh(g) => {
                let (mesh, gmsh) = crate::mesh::read_gmsh(&gmsh_path(g, origin)).map_err(|e| {
                    let at = [Seg::Key("mesh"), Seg::Key("file")];
                    self.error_at(origin, &at, format!("[mesh] gmsh: {e}"))
                })?;
                report.gmsh = Some(gmsh);
                mesh
            }
        };
        Ok((mesh, report))
    }
}

/// A Gmsh `file` as a path: relative to the scene's directory. `origin`
/// is the scene's path, or names a built-in scene, which is compiled in
/// from the crate's scenes/ directory.
fn gmsh_path(g: &GmshSection, origin: &str) -> std::path::PathBuf {
    let builtin = BUILTIN
        .iter()
        .any(|(n, _, _)| origin == format!("built-in scene '{n}'"));
    let base = match Path::new(origin).parent() {
        _ if builtin => Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes"),
        Some(dir) => dir.to_path_buf(),
        None => Default::default(),
    };
    base.join(&g.file)
}

/// What reading the mesh found besides the mesh (for `check` to print).
#[derive(Debug, Clone, Default)]
pub struct MeshReport {
    /// The Gmsh reader's report (reoriented cells, skipped sections), for a
    /// `generator = "gmsh"` mesh.
    pub gmsh: Option<crate::mesh::GmshReport>,
}

fn check_finite(v: f64, what: &str) -> std::result::Result<(), String> {
    if v.is_finite() {
        Ok(())
    } else {
        Err(format!("{what} must be a finite number (got {v})"))
    }
}

fn check_facet_set(mesh: &Mesh, set: &str, section: &str) -> std::result::Result<(), String> {
    if mesh.facet_sets.contains_key(set) {
        return Ok(());
    }
    let known: Vec<&str> = mesh.facet_sets.keys().map(String::as_str).collect();
    Err(format!(
        "{section} set '{set}' is not a facet set of the mesh (facet sets: {})",
        known.join(", ")
    ))
}

fn dirichlet_spec(mesh: &Mesh, d: &DirichletSection, index: usize) -> Checked<DirichletSpec> {
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
fn amplitude(
    table: &Option<Vec<[f64; 2]>>,
    at: &str,
) -> std::result::Result<crate::amplitude::Amplitude, String> {
    match table {
        None => Ok(crate::amplitude::Amplitude::ramp()),
        Some(t) => crate::amplitude::Amplitude::from_table(t).map_err(|e| format!("{at}: {e}")),
    }
}

/// Gauss points on quadrilateral slave facets (docs/formulation.md §2.4); on
/// triangles, the slave nodes. Three Gauss points per triangle put about six
/// constraints on every slave node of a tet mesh, more than linear tets can
/// meet: the Uzawa loop then stalls just above its tolerance (sphere-block:
/// 361 Newton iterations and 7 cutbacks with Gauss points, 85 with one point
/// per facet, 36 and none at the nodes).
fn default_quadrature(mesh: &Mesh) -> SlaveQuadrature {
    match mesh.cell_type.facet_type() {
        crate::fem::FacetType::Quad4 => SlaveQuadrature::Gauss,
        crate::fem::FacetType::Tri3 => SlaveQuadrature::Nodal,
    }
}

fn contact_spec(mesh: &Mesh, c: &ContactSection, index: usize) -> Checked<PairSpec> {
    let key = |k| [Seg::Key("contact"), Seg::Index(index), Seg::Key(k)];
    let name = c.name.clone().unwrap_or_else(|| format!("pair{index}"));
    let at = format!("[[contact]] '{name}'");
    check_facet_set(mesh, &c.slave, &format!("{at} slave"))
        .map_err(|m| Bad::at(&key("slave"), m))?;
    let master = match (&c.master, &c.rigid) {
        (Some(m), None) => {
            check_facet_set(mesh, m, &format!("{at} master"))
                .map_err(|e| Bad::at(&key("master"), e))?;
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
    spec.formulation =
        formulation(mesh, c, &spec, &at).map_err(|m| Bad::at(&key("formulation"), m))?;
    spec.quadrature = match c.quadrature.as_deref() {
        None => default_quadrature(mesh),
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
    spec.friction = c.friction.map(|mu| crate::contact::pair::FrictionSpec {
        mu,
        penalty: tangential_penalty,
    });
    Ok(spec)
}

/// The point a rigid surface is placed by (its normal, axis and radius are
/// checked by [`RigidSurface::validate`]).
fn rigid_point(r: &RigidSurface) -> [f64; 3] {
    match *r {
        RigidSurface::Plane { point, .. } | RigidSurface::Cylinder { point, .. } => point,
        RigidSurface::Sphere { centre, .. } => centre,
    }
}

/// The pair's `formulation`, checked against what the mortar formulation
/// supports (a master facet set of quad4 or tri3 facets).
fn formulation(
    mesh: &Mesh,
    c: &ContactSection,
    spec: &PairSpec,
    at: &str,
) -> std::result::Result<crate::contact::Formulation, String> {
    use crate::contact::Formulation;
    let f = match c.formulation.as_deref() {
        None | Some("links") => return Ok(Formulation::Links),
        Some("mortar") => Formulation::Mortar,
        Some(other) => {
            return Err(format!(
                "{at}: formulation '{other}' is not \"links\" or \"mortar\""
            ))
        }
    };
    let facet = mesh.cell_type.facet_type();
    if !f.supports(facet) {
        return Err(format!(
            "{at}: formulation \"mortar\" does not support {} facets",
            facet.name()
        ));
    }
    if spec.master.is_rigid() {
        return Err(format!(
            "{at}: formulation \"mortar\" needs a master facet set, not a rigid surface"
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
fn check_different_bodies(
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
fn body_of_set(mesh: &Mesh, set: &str) -> Option<usize> {
    mesh.facet_sets
        .get(set)?
        .first()
        .map(|f| mesh.cell_body[f.cell] as usize)
}

fn hertz_check(
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

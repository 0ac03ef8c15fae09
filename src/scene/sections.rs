//! The sections of a scene file as serde reads them, before any check
//! (`build` turns them into a model).
use super::lines::KeyLines;
use crate::fem::CellType;
use crate::mesh::generate::Grading;
use crate::model::RigidSurface;
use serde::Deserialize;

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
    Inp(InpSection),
}

/// A Gmsh `.msh` 4.1 file; a relative `file` is relative to the scene
/// file's directory (for a built-in scene, the crate's `scenes/`).
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct GmshSection {
    pub file: String,
}

/// An Abaqus/CalculiX `.inp` file (its mesh; the physics is the scene's);
/// a relative `file` is relative to the scene file's directory, as for Gmsh.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct InpSection {
    pub file: String,
}

/// A generator's `cell_type`: the hexes it builds, split or given
/// second-order nodes ([`crate::mesh::Mesh::hex_to`]).
#[derive(Debug, Deserialize, Clone, Copy, Default)]
#[serde(rename_all = "lowercase")]
pub enum CellTypeName {
    #[default]
    Hex8,
    Tet4,
    Tet10,
    Hex20,
    Hex27,
    Wedge6,
    Wedge15,
    Pyramid5,
}

impl From<CellTypeName> for CellType {
    fn from(c: CellTypeName) -> Self {
        match c {
            CellTypeName::Hex8 => CellType::Hex8,
            CellTypeName::Tet4 => CellType::Tet4,
            CellTypeName::Tet10 => CellType::Tet10,
            CellTypeName::Hex20 => CellType::Hex20,
            CellTypeName::Hex27 => CellType::Hex27,
            CellTypeName::Wedge6 => CellType::Wedge6,
            CellTypeName::Wedge15 => CellType::Wedge15,
            CellTypeName::Pyramid5 => CellType::Pyramid5,
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
    /// Stiffness integration of the body's cells.
    #[serde(default)]
    pub integration: IntegrationName,
}

/// `[[body]] integration`: the cell type's full rule, or its reduced one
/// (hex20 only: Abaqus' C3D20R).
#[derive(Debug, Deserialize, Clone, Copy, Default, PartialEq, Eq)]
#[serde(rename_all = "lowercase")]
pub enum IntegrationName {
    #[default]
    Full,
    Reduced,
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
    /// Penalty divisor of the first Uzawa iteration of a step without
    /// contact (default 1: off).
    pub first_contact_softening: Option<f64>,
    /// Main-part contact tangent in the first Uzawa iteration of a step
    /// without contact (default true).
    pub first_contact_main_tangent: Option<bool>,
    /// Bulk factored once, contact solved on its Schur complement (default true).
    pub contact_schur: Option<bool>,
    /// Newton on the condensed contact system on the Schur path (default true).
    pub condensed_newton: Option<bool>,
    /// Anderson depth of the frictionless Uzawa updates (0: off).
    pub uzawa_acceleration: Option<usize>,
}

#[derive(Debug, Deserialize, Default)]
#[serde(deny_unknown_fields)]
pub struct OutputSection {
    pub path: Option<String>,
}

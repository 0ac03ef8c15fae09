//! `contactlink check SCENE`: validate a scene and describe what a run would
//! solve (bodies, conditions, loads, contact pairs, steps), without MPI or
//! PETSc, so a scene can be checked before a long run is queued.
use crate::error::Result;
use crate::fem::Material;
use crate::mesh::Mesh;
use crate::model::{FacetLoad, Formulation, MasterSpec, Model};
use crate::scene::{self, MeshReport, SceneSource};

/// A scene's model, its output path and what reading its mesh found.
pub struct Checked {
    pub model: Model,
    pub output: Option<String>,
    pub mesh_report: MeshReport,
}

/// Loads and validates a scene (a built-in name or a path) with overrides.
pub fn load(name_or_path: &str, overrides: &[String]) -> Result<Checked> {
    let src = SceneSource::resolve(name_or_path)?;
    let parsed = scene::parse(&src, overrides)?;
    let (model, mesh_report) = parsed.build_with_report(&src.origin)?;
    Ok(Checked {
        model,
        output: parsed.output_path().map(str::to_owned),
        mesh_report,
    })
}

/// The summary `check` prints, one item per line.
pub fn summary(c: &Checked) -> String {
    let (model, m) = (&c.model, &c.model.mesh);
    let mut s = String::new();
    let mut line = |text: String| {
        s.push_str(&text);
        s.push('\n');
    };
    line(model.name.clone());
    line(format!(
        "  cells {} ({}), nodes {}, DOFs {}",
        m.num_cells(),
        m.cell_type.name(),
        m.num_nodes(),
        3 * m.num_nodes()
    ));
    for (b, name) in m.bodies.iter().enumerate() {
        let (cells, nodes) = body_size(m, b);
        let density = model
            .dynamics
            .as_ref()
            .map_or(String::new(), |d| format!(", density {}", d.density[b]));
        line(format!(
            "  body {name}: {}{density}; {cells} cells, {nodes} nodes",
            material(&model.materials[b])
        ));
    }
    if let Some(g) = &c.mesh_report.gmsh {
        line(format!("  gmsh: {} cells reoriented", g.reoriented));
    }
    for note in c.mesh_report.notes() {
        line(format!("  note: {note}"));
    }
    for d in &model.dirichlet {
        let comps: Vec<&str> = d.components.iter().map(|&c| ["x", "y", "z"][c]).collect();
        line(format!(
            "  dirichlet {}: {} nodes, components {}",
            d.set,
            d.nodes.len(),
            comps.join(" ")
        ));
    }
    for (set, load, _) in &model.facet_loads {
        let what = match load {
            FacetLoad::Pressure(p) => format!("pressure {p}"),
            FacetLoad::Traction(t) => format!("traction {t:?}"),
        };
        line(format!("  load {set}: {what} on {} facets", facets(m, set)));
    }
    for (b, f) in model.body_force.iter().enumerate() {
        if f.iter().any(|&v| v != 0.0) {
            line(format!("  body force on {}: {f:?}", m.bodies[b]));
        }
    }
    for p in &model.contact {
        let master = match &p.master {
            MasterSpec::Surface { set } => format!("master {set} ({} facets)", facets(m, set)),
            MasterSpec::Rigid(r) => format!("rigid master {r:?}"),
        };
        let friction = match p.active_friction() {
            Some(f) => format!("Coulomb friction μ = {}", f.mu),
            None => "frictionless".into(),
        };
        let formulation = match p.formulation {
            Formulation::Mortar => "mortar".to_string(),
            Formulation::Links => format!("links ({:?} points)", p.quadrature).to_lowercase(),
        };
        line(format!(
            "  contact {}: {formulation}, slave {} ({} facets), {master}, {friction}",
            p.name,
            p.slave,
            facets(m, &p.slave)
        ));
    }
    line(match &model.dynamics {
        Some(d) => format!(
            "  dynamics: Newmark β = {}, γ = {}, Δt = {}, t_end = {}",
            d.newmark.beta,
            d.newmark.gamma,
            d.time_step,
            d.time_step * model.steps as f64
        ),
        None => "  quasi-static (no mass matrix)".into(),
    });
    line(format!(
        "  steps {}, output {}",
        model.steps,
        c.output.as_deref().unwrap_or("(none; give -o FILE.h5)")
    ));
    for w in model.warnings() {
        line(format!("  warning: {w}"));
    }
    s
}

fn material(m: &Material) -> String {
    let name = match m {
        Material::LinearElastic { .. } => "linear-elastic",
        Material::NeoHookean { .. } => "neo-hookean",
    };
    format!("{name}, E = {}, ν = {}", m.youngs(), m.poisson())
}

/// Cells and distinct nodes of body `b`.
fn body_size(m: &Mesh, b: usize) -> (usize, usize) {
    let mut used = vec![false; m.num_nodes()];
    let mut cells = 0;
    for c in (0..m.num_cells()).filter(|&c| m.cell_body[c] as usize == b) {
        cells += 1;
        for &n in m.cell(c) {
            used[n] = true;
        }
    }
    (cells, used.iter().filter(|&&u| u).count())
}

fn facets(m: &Mesh, set: &str) -> usize {
    m.facet_sets.get(set).map_or(0, Vec::len)
}

//! `contactlink run SCENE --setup-only`: everything a run does before its
//! first solve (scene and mesh, partition, DOF numbering, assembly set-up,
//! the Jacobian allocated with its pattern filled in), then stop. What the
//! set-up costs in memory and time, without the solve's share.
use crate::error::Result;
use crate::pipeline::load;
use crate::runtime::Runtime;
use crate::solve::Simulation;

/// What was set up.
pub struct SetupSummary {
    pub model_name: String,
    pub cells: usize,
    pub nodes: usize,
    pub global_dofs: usize,
}

/// Collective: builds the model (its mesh on rank 0) and the set-up of a
/// run on every rank.
pub fn setup_only(rt: &Runtime, scene: &str, overrides: &[String]) -> Result<SetupSummary> {
    crate::parallel::fault::arm(rt.rank())?;
    // The mesh is built on rank 0 only, as in a run.
    let mut loaded = load::on_root(&rt.world(), scene, overrides)?;
    let mesh = loaded.take_mesh();
    let model = loaded.model;
    let sim = Simulation::setup_with_mesh(rt, &model, mesh)?;
    Ok(SetupSummary {
        model_name: model.name.clone(),
        cells: sim.local_mesh().global_cells,
        nodes: sim.local_mesh().global_nodes,
        global_dofs: 3 * sim.dofs().num_global_nodes(),
    })
}

//! The names of the result file: every group, dataset and attribute a writer
//! creates and a reader looks up is spelled here once (the file layout itself
//! is described in the module docs of [`crate::output`] and in
//! docs/architecture.md).

/// `/mesh`: the mesh, written once.
pub const MESH: &str = "/mesh";
/// `/steps`: one group per converged step.
pub const STEPS: &str = "/steps";
/// The same two groups' link names under the root.
pub const MESH_NAME: &str = "mesh";
pub const STEPS_NAME: &str = "steps";

/// Members of `/mesh` (leaf names).
pub const NODES: &str = "nodes";
pub const CELLS: &str = "cells";
pub const PARTITION: &str = "partition";
pub const CELL_BODY: &str = "cell_body";
pub const NODE_SETS: &str = "node_sets";
pub const FACET_SETS: &str = "facet_sets";

/// Full paths of the mesh datasets.
pub const MESH_NODES: &str = "/mesh/nodes";
pub const MESH_CELLS: &str = "/mesh/cells";
pub const MESH_PARTITION: &str = "/mesh/partition";
pub const MESH_CELL_BODY: &str = "/mesh/cell_body";
pub const MESH_NODE_SETS: &str = "/mesh/node_sets";
pub const MESH_FACET_SETS: &str = "/mesh/facet_sets";

/// Members of a facet set group `/mesh/facet_sets/<name>/`.
pub const FACET_NODES: &str = "nodes";
pub const FACET_CELL: &str = "cell";
pub const FACET_FACE: &str = "face";

/// Attributes of the mesh datasets and facet set groups.
pub const CELL_TYPE_ATTR: &str = "cell_type";
pub const BODIES_ATTR: &str = "bodies";

/// Attributes of a step group.
pub const TIME_ATTR: &str = "time";
pub const LOAD_FACTOR_ATTR: &str = "load_factor";
pub const NEWTON_ATTR: &str = "newton_iterations";
pub const UZAWA_ATTR: &str = "uzawa_iterations";
pub const CONVERGED_ATTR: &str = "converged";
pub const WALL_SECONDS_ATTR: &str = "wall_seconds";

/// Nodal step fields (`/steps/<NNNNNN>/<name>`, `(N,c)`).
pub const DISPLACEMENT: &str = "displacement";
pub const REACTION: &str = "reaction";
pub const VELOCITY: &str = "velocity";
pub const CONTACT_PRESSURE: &str = "contact_pressure";
/// Dynamics: `[kinetic, strain]` and the momentum vector, `(2,)` and `(3,)`.
pub const ENERGY: &str = "energy";
pub const MOMENTUM: &str = "momentum";

/// `/steps/<NNNNNN>/contact/`: one group per contact pair.
pub const CONTACT: &str = "contact";

/// Members of a pair group `contact/<pair>/`: each formulation names the
/// fields it writes (`contact::fields`).
pub use crate::contact::fields::{
    PAIR_FORCE, PAIR_GAP, PAIR_HISTORY_IDS, PAIR_LAMBDA_N, PAIR_LAMBDA_T, PAIR_NODE_AREA,
    PAIR_NODE_LAMBDA, PAIR_NODE_LAMBDA_T, PAIR_NODE_SLIP, PAIR_NODE_SLIP_ORIGIN, PAIR_NODE_STATE,
    PAIR_NODE_TRACTION, PAIR_NODE_WEIGHTED_GAP, PAIR_PENALTY, PAIR_POINTS, PAIR_PRESSURE,
    PAIR_SLIP, PAIR_SLIP_ORIGIN, PAIR_STATE, PAIR_TRACTION_T, PAIR_WEIGHT,
};

/// Root attributes: the scene text and its `--set` overrides.
pub const SCENE_ATTR: &str = "scene";
pub const SCENE_OVERRIDES_ATTR: &str = "scene_overrides";
/// `/contact_pairs`: attribute pair name → slave facet set.
pub const CONTACT_PAIRS: &str = "/contact_pairs";
/// `/hertz`: the closed-form setup `contactlink plot` draws.
pub const HERTZ: &str = "/hertz";
/// Attributes of `/hertz`: the contact kind (one of the two values below),
/// the pair, the indenter radius, the effective modulus and, for a line
/// contact, the thickness the load is spread over.
pub const HERTZ_KIND_ATTR: &str = "kind";
pub const HERTZ_PAIR_ATTR: &str = "pair";
pub const HERTZ_RADIUS_ATTR: &str = "radius";
pub const HERTZ_EFFECTIVE_MODULUS_ATTR: &str = "effective_modulus";
pub const HERTZ_THICKNESS_ATTR: &str = "thickness";
/// Values of [`HERTZ_KIND_ATTR`].
pub const HERTZ_KIND_LINE: &str = "line";
pub const HERTZ_KIND_POINT: &str = "point";
/// Attributes of `/hertz` added at the end of a run: the comparison of the
/// last step (the `Hertz:` summary lines). The load from the pair's contact
/// force, the fitted and the closed-form p0 and half-width (line) or radius
/// (point), their relative errors, and the errors of the fit that reads the
/// nodal pressures as nodal averages (absent when that fit failed).
pub const HERTZ_LOAD_ATTR: &str = "load";
pub const HERTZ_P0_ATTR: &str = "p0";
pub const HERTZ_P0_EXACT_ATTR: &str = "p0_exact";
pub const HERTZ_WIDTH_ATTR: &str = "width";
pub const HERTZ_WIDTH_EXACT_ATTR: &str = "width_exact";
pub const HERTZ_P0_ERROR_ATTR: &str = "p0_error";
pub const HERTZ_WIDTH_ERROR_ATTR: &str = "width_error";
pub const HERTZ_P0_ERROR_AVERAGED_ATTR: &str = "p0_error_nodal_average";
pub const HERTZ_WIDTH_ERROR_AVERAGED_ATTR: &str = "width_error_nodal_average";

/// `/run`: the run's totals, written once the run has ended (the `done:`
/// and `solver:` summary lines as attributes). Counts are i64, seconds f64.
pub const RUN: &str = "/run";
pub const RUN_NAME: &str = "run";
/// Ranks, global DOFs and converged steps.
pub const RUN_RANKS_ATTR: &str = "ranks";
pub const RUN_DOFS_ATTR: &str = "dofs";
pub const RUN_STEPS_ATTR: &str = "steps";
/// Summed over the converged steps (also [`NEWTON_ATTR`], [`UZAWA_ATTR`]
/// and [`WALL_SECONDS_ATTR`], the run's solve seconds): linear iterations
/// and the cutbacks taken before a step converged.
pub const LINEAR_ATTR: &str = "linear_iterations";
pub const CUTBACKS_ATTR: &str = "cutbacks";
/// Bulk tangent assemblies and sparsity pattern builds over the run.
pub const BULK_TANGENT_ASSEMBLIES_ATTR: &str = "bulk_tangent_assemblies";
pub const PATTERN_BUILDS_ATTR: &str = "pattern_builds";
/// Preconditioner builds and reuses decided by the active-set watch (both 0
/// when it is off).
pub const PRECONDITIONER_BUILDS_ATTR: &str = "preconditioner_builds";
pub const PRECONDITIONER_REUSES_ATTR: &str = "preconditioner_reuses";
/// Which contact Schur path the run took: one of the three values below.
pub const SCHUR_PATH_ATTR: &str = "schur_path";
pub const SCHUR_PATH_NONE: &str = "none";
/// One rank: K factored with a Schur complement on the contact DOFs.
pub const SCHUR_PATH_ONE_RANK: &str = "schur";
/// Several ranks: K's factor with a low-rank update.
pub const SCHUR_PATH_LOW_RANK: &str = "low-rank";
/// On a Schur path only: the contact DOFs |C| at the end of the run, the
/// sparse factorisations of K, the dense factorisations (of the Schur
/// complement on one rank, of I + D·G on several), the times C grew, the
/// solves with the sparse factor and the dense (condensed Newton) steps.
pub const SCHUR_DOFS_ATTR: &str = "schur_dofs";
pub const BULK_FACTORISATIONS_ATTR: &str = "bulk_factorisations";
pub const SCHUR_FACTORISATIONS_ATTR: &str = "schur_factorisations";
pub const SCHUR_GROWTHS_ATTR: &str = "schur_growths";
pub const SPARSE_SOLVES_ATTR: &str = "sparse_solves";
pub const DENSE_SOLVES_ATTR: &str = "dense_solves";

/// The group name of step `index`: six digits, zero-padded, so the groups
/// sort in step order under a plain name sort.
pub fn step_group_name(index: usize) -> String {
    format!("{index:06}")
}

/// `/steps/<NNNNNN>`.
pub fn step_group(step: usize) -> String {
    format!("{STEPS}/{}", step_group_name(step))
}

/// `/steps/<NNNNNN>/<rel>`; `rel` may be a relative path such as
/// [`pair_dataset`]'s.
pub fn step_dataset(step: usize, rel: &str) -> String {
    format!("{}/{rel}", step_group(step))
}

/// `contact/<pair>`, relative to a step group.
pub fn pair_group(pair: &str) -> String {
    format!("{CONTACT}/{pair}")
}

/// `contact/<pair>/<name>`, relative to a step group.
pub fn pair_dataset(pair: &str, name: &str) -> String {
    format!("{CONTACT}/{pair}/{name}")
}

/// `/mesh/node_sets/<name>`.
pub fn node_set(name: &str) -> String {
    format!("{MESH_NODE_SETS}/{name}")
}

/// `/mesh/facet_sets/<name>`.
pub fn facet_set(name: &str) -> String {
    format!("{MESH_FACET_SETS}/{name}")
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn full_paths_join_their_parts() {
        for (full, leaf) in [
            (MESH_NODES, NODES),
            (MESH_CELLS, CELLS),
            (MESH_PARTITION, PARTITION),
            (MESH_CELL_BODY, CELL_BODY),
            (MESH_NODE_SETS, NODE_SETS),
            (MESH_FACET_SETS, FACET_SETS),
        ] {
            assert_eq!(full, format!("{MESH}/{leaf}"));
        }
        assert_eq!(MESH, format!("/{MESH_NAME}"));
        assert_eq!(STEPS, format!("/{STEPS_NAME}"));
        assert_eq!(
            step_dataset(3, "contact/a/gap"),
            "/steps/000003/contact/a/gap"
        );
        assert_eq!(pair_dataset("a", PAIR_GAP), "contact/a/gap");
    }
}

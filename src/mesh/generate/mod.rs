//! Deterministic generators for the benchmark geometries.
//!
//! Every generator returns a validated [`Mesh`] whose bodies are named by
//! the spec and whose sets are named `<body>.<face>`; each facet set also
//! exists as a node set of the same name. All lengths are in mesh units.

mod blocks;
mod graded_box;
mod hertz_cylinder;
mod hertz_sphere;
mod o_grid;
mod perturb;
mod spacing;
mod stacked;

pub use graded_box::{graded_box, BoxSpec};
pub use hertz_cylinder::{hertz_cylinder, HertzCylinderSpec};
pub use hertz_sphere::{hertz_sphere, HertzSphereSpec};
pub use perturb::{perturb_interior, Perturbation};
pub use spacing::Grading;
pub use stacked::{stacked_blocks, StackedSpec};

use super::{CellType, Mesh, MeshError};

pub(crate) fn spec_error(
    generator: &'static str,
    field: impl Into<String>,
    reason: impl Into<String>,
) -> MeshError {
    MeshError::InvalidSpec {
        generator,
        field: field.into(),
        reason: reason.into(),
    }
}

/// Requires a finite value above `min` (or at least `min` when `inclusive`).
pub(crate) fn check_at_least(
    generator: &'static str,
    field: &str,
    value: f64,
    min: f64,
    inclusive: bool,
) -> Result<(), MeshError> {
    let ok = value.is_finite() && (value > min || (inclusive && value == min));
    if ok {
        Ok(())
    } else {
        let relation = if inclusive { ">=" } else { ">" };
        Err(spec_error(
            generator,
            field,
            format!("must be finite and {relation} {min} (got {value})"),
        ))
    }
}

/// Most cells a generated mesh may have (after a split into tets).
pub(crate) const MAX_CELLS: usize = blocks::MAX_CELLS;

/// Most nodes a generated mesh may have: 12 million DOFs. Every rank builds
/// the whole mesh before the partition, and building is serial: `check` of a
/// 26.3-million-node hertz-sphere (level 3) took 126 s and 6.9 GB on one
/// rank before any solver memory. Larger models need a partitioned mesh
/// reader, not a bigger generator.
pub(crate) const MAX_NODES: usize = 4_000_000;

/// Refuses a mesh of the structured blocks `dims` (cells per direction)
/// before anything is allocated: the cell count (×6 when split into tets)
/// and the point count (an upper bound on the nodes: shared block faces
/// are fused later) must stay within [`MAX_CELLS`] and [`MAX_NODES`].
/// `field` is the spec field that sets the size.
pub(crate) fn check_size(
    generator: &'static str,
    field: &str,
    dims: &[[usize; 3]],
    cell_type: CellType,
) -> Result<(), MeshError> {
    let per_hex = match cell_type.linear() {
        CellType::Tet4 | CellType::Pyramid5 => 6,
        CellType::Wedge6 => 2,
        _ => 1,
    };
    // Second-order nodes at most multiply the points by 8 (hex27: (2n+1)³;
    // tet10 adds its face and body diagonals' mid-nodes to fewer), the
    // pyramids' centres by 2.
    let node_factor = match (cell_type.order(), cell_type) {
        (2, _) => 8,
        (_, CellType::Pyramid5) => 2,
        _ => 1,
    };
    let product = |d: [usize; 3]| d.iter().fold(1usize, |a, &n| a.saturating_mul(n));
    let sum =
        |f: &dyn Fn([usize; 3]) -> usize| dims.iter().fold(0usize, |a, &d| a.saturating_add(f(d)));
    let cells = sum(&|d| product(d).saturating_mul(per_hex));
    let nodes = sum(&|d| product(d.map(|n| n.saturating_add(1)))).saturating_mul(node_factor);
    if cells <= MAX_CELLS && nodes <= MAX_NODES {
        return Ok(());
    }
    Err(spec_error(
        generator,
        field,
        format!(
            "the mesh would have {cells} {} cells and up to {nodes} nodes, above the limit of {MAX_CELLS} cells and {MAX_NODES} nodes",
            cell_type.name()
        ),
    ))
}

/// The spec field to blame for too large a Hertz mesh: the refinement level
/// when one is given, else the fine element size.
pub(crate) fn size_field(level: u32) -> &'static str {
    if level > 0 {
        "level"
    } else {
        "fine_size"
    }
}

/// Converts the generated hexes to the asked cell type ([`Mesh::hex_to`]:
/// tets, wedges, pyramids, second-order nodes), then checks the result, so
/// every generator hands out only meshes that pass [`Mesh::validate`].
pub(crate) fn finalize(mesh: Mesh, cell_type: CellType) -> Result<Mesh, MeshError> {
    let mesh = match cell_type {
        CellType::Hex8 => mesh,
        other => mesh.hex_to(other)?,
    };
    mesh.validate()?;
    Ok(mesh)
}

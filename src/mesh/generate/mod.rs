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

/// Splits into tets when asked, then checks the result, so every generator
/// hands out only meshes that pass [`Mesh::validate`].
pub(crate) fn finalize(mesh: Mesh, cell_type: CellType) -> Result<Mesh, MeshError> {
    let mesh = match cell_type {
        CellType::Hex8 => mesh,
        CellType::Tet4 => mesh.hex_to_tets()?,
    };
    mesh.validate()?;
    Ok(mesh)
}

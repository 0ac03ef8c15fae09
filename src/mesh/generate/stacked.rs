//! Two stacked blocks with non-matching meshes: the contact patch test.

use super::graded_box::{graded_box, BoxSpec};
use super::perturb::{perturb_interior, Perturbation};
use super::spacing::Grading;
use super::{check_at_least, check_size, finalize, spec_error};
use crate::mesh::{CellType, Mesh, MeshError};

const GENERATOR: &str = "stacked_blocks";

/// Parameters of [`stacked_blocks`]. Lengths in mesh units.
#[derive(Debug, Clone, PartialEq)]
pub struct StackedSpec {
    /// Side length L of both blocks in x and y.
    pub length: f64,
    /// Height h of each block.
    pub height: f64,
    /// Distance between the lower block's top and the upper block's bottom.
    pub gap: f64,
    /// Elements of `lower` along x, y, z.
    pub lower_divisions: [usize; 3],
    /// Elements of `upper` along x, y, z; choose them different from the
    /// lower ones so the interface meshes do not match.
    pub upper_divisions: [usize; 3],
    /// `Tet4` splits every hex into tets.
    pub cell_type: CellType,
    /// Optional random distortion (interior nodes, in-plane face nodes).
    pub perturbation: Option<Perturbation>,
}

impl Default for StackedSpec {
    /// Unit-square blocks of height 0.5, 4×4×2 below and 3×3×2 above.
    fn default() -> Self {
        StackedSpec {
            length: 1.0,
            height: 0.5,
            gap: 0.0,
            lower_divisions: [4, 4, 2],
            upper_divisions: [3, 3, 2],
            cell_type: CellType::Hex8,
            perturbation: None,
        }
    }
}

/// Bodies `lower` = [0, L]² × [−h, 0] and `upper` = [0, L]² × [gap, gap + h]
/// with the box sets of [`graded_box`] for each (`lower.top`,
/// `lower.bottom`, `upper.bottom`, `upper.top`, `.xmin` … `.zmax`).
pub fn stacked_blocks(spec: &StackedSpec) -> Result<Mesh, MeshError> {
    check_at_least(GENERATOR, "length", spec.length, 0.0, false)?;
    check_at_least(GENERATOR, "height", spec.height, 0.0, false)?;
    if !spec.gap.is_finite() {
        return Err(spec_error(
            GENERATOR,
            "gap",
            format!("must be finite (got {})", spec.gap),
        ));
    }
    for (field, divisions) in [
        ("lower_divisions", spec.lower_divisions),
        ("upper_divisions", spec.upper_divisions),
    ] {
        if divisions.contains(&0) {
            return Err(spec_error(
                GENERATOR,
                field,
                format!("every entry must be at least 1 (got {divisions:?})"),
            ));
        }
    }
    // Both blocks together, before either is built.
    let field = if spec.lower_divisions.iter().product::<usize>()
        >= spec.upper_divisions.iter().product::<usize>()
    {
        "lower_divisions"
    } else {
        "upper_divisions"
    };
    let dims = [spec.lower_divisions, spec.upper_divisions];
    check_size(GENERATOR, field, &dims, spec.cell_type)?;
    let block = |body: &str, z0: f64, divisions: [usize; 3]| {
        graded_box(&BoxSpec {
            body: body.to_string(),
            origin: [0.0, 0.0, z0],
            size: [spec.length, spec.length, spec.height],
            divisions,
            grading: [Grading::Uniform; 3],
            cell_type: CellType::Hex8,
        })
    };
    let lower = block("lower", -spec.height, spec.lower_divisions)?;
    let upper = block("upper", spec.gap, spec.upper_divisions)?;
    let mesh = finalize(lower.merge(upper)?, spec.cell_type)?;
    match spec.perturbation {
        Some(p) => perturb_interior(&mesh, p.fraction, p.seed),
        None => Ok(mesh),
    }
}

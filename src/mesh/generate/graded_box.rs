//! Axis-aligned box with per-axis grading.

use super::blocks::{alias_set, Block, BodyBuilder, Side};
use super::spacing::{graded_coordinates, Grading};
use super::{check_at_least, check_size, finalize, spec_error};
use crate::mesh::{CellType, Mesh, MeshError};

const GENERATOR: &str = "graded_box";

/// Parameters of [`graded_box`].
#[derive(Debug, Clone, PartialEq)]
pub struct BoxSpec {
    /// Body name, also the prefix of the set names.
    pub body: String,
    /// Corner with the smallest coordinates.
    pub origin: [f64; 3],
    /// Edge lengths along x, y, z.
    pub size: [f64; 3],
    /// Number of elements along x, y, z.
    pub divisions: [usize; 3],
    /// Element size variation along x, y, z.
    pub grading: [Grading; 3],
    /// `Tet4` splits every hex into tets (see [`Mesh::hex_to_tets`]).
    pub cell_type: CellType,
}

impl Default for BoxSpec {
    /// A uniform unit cube `block` of 4×4×4 hexes.
    fn default() -> Self {
        BoxSpec {
            body: "block".to_string(),
            origin: [0.0; 3],
            size: [1.0; 3],
            divisions: [4; 3],
            grading: [Grading::Uniform; 3],
            cell_type: CellType::Hex8,
        }
    }
}

/// Side names of a box, in `Side` order.
pub(crate) const BOX_SIDES: [(Side, &str); 6] = [
    (Side::IMin, "xmin"),
    (Side::IMax, "xmax"),
    (Side::JMin, "ymin"),
    (Side::JMax, "ymax"),
    (Side::KMin, "zmin"),
    (Side::KMax, "zmax"),
];

/// A graded box `body` with node and facet sets `<body>.xmin`, `.xmax`,
/// `.ymin`, `.ymax`, `.zmin`, `.zmax`, and the aliases `.bottom` (= zmin)
/// and `.top` (= zmax).
pub fn graded_box(spec: &BoxSpec) -> Result<Mesh, MeshError> {
    if spec.body.is_empty() {
        return Err(spec_error(GENERATOR, "body", "must not be empty"));
    }
    let mut lines: [Vec<f64>; 3] = Default::default();
    for (axis, line) in lines.iter_mut().enumerate() {
        *line = axis_line(spec, axis)?;
    }
    let dims = [0, 1, 2].map(|a| lines[a].len().saturating_sub(1));
    check_size(GENERATOR, "divisions", &[dims], spec.cell_type)?;
    let mut mesh = tensor_body(&spec.body, &lines, &BOX_SIDES)
        .map_err(|reason| spec_error(GENERATOR, "divisions", reason))?;
    alias_set(
        &mut mesh,
        &format!("{}.zmin", spec.body),
        &format!("{}.bottom", spec.body),
    );
    alias_set(
        &mut mesh,
        &format!("{}.zmax", spec.body),
        &format!("{}.top", spec.body),
    );
    finalize(mesh, spec.cell_type)
}

/// Node coordinates along one axis, with errors naming the spec field.
fn axis_line(spec: &BoxSpec, axis: usize) -> Result<Vec<f64>, MeshError> {
    if !spec.origin[axis].is_finite() {
        return Err(spec_error(
            GENERATOR,
            format!("origin[{axis}]"),
            format!("must be finite (got {})", spec.origin[axis]),
        ));
    }
    check_at_least(
        GENERATOR,
        &format!("size[{axis}]"),
        spec.size[axis],
        0.0,
        false,
    )?;
    graded_coordinates(
        spec.origin[axis],
        spec.size[axis],
        spec.divisions[axis],
        spec.grading[axis],
    )
    .map_err(|reason| {
        let field = if spec.divisions[axis] == 0 || reason.starts_with("divisions") {
            format!("divisions[{axis}]")
        } else {
            format!("grading[{axis}]")
        };
        spec_error(GENERATOR, field, reason)
    })
}

/// One tensor-product hex block as a single-body mesh, sides tagged.
pub(crate) fn tensor_body(
    body: &str,
    lines: &[Vec<f64>; 3],
    sides: &[(Side, &'static str)],
) -> Result<Mesh, String> {
    let mut block = Block::tensor(&lines[0], &lines[1], &lines[2])?;
    for &(side, name) in sides {
        block = block.tag(side, name);
    }
    let size = lines
        .iter()
        .map(|l| l.last().copied().unwrap_or(0.0) - l.first().copied().unwrap_or(0.0))
        .fold(0.0, f64::max);
    let mut builder = BodyBuilder::new(body, size);
    builder.add(&block)?;
    Ok(builder.finish())
}

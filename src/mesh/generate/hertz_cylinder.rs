//! Plane-strain Hertz line contact: a half cylinder on a block.

use super::blocks::{subset_set, Block, BodyBuilder, Side};
use super::graded_box::tensor_body;
use super::o_grid::{core_line, shell_lines, shell_point, tan_exact, ShellInput, ShellLines};
use super::spacing::{contact_block_lines, FineZone};
use super::{check_at_least, check_size, finalize, size_field, spec_error};
use crate::mesh::{CellType, Mesh, MeshError};

const GENERATOR: &str = "hertz_cylinder";

/// Parameters of [`hertz_cylinder`]. Lengths in mesh units.
#[derive(Debug, Clone, PartialEq)]
pub struct HertzCylinderSpec {
    /// Cylinder radius R.
    pub radius: f64,
    /// Block width W: the block spans x ∈ [−W/2, W/2].
    pub block_width: f64,
    /// Block height H: the block spans z ∈ [−H, 0].
    pub block_height: f64,
    /// Thickness t in y (both bodies span y ∈ [0, t], one cell thick).
    pub thickness: f64,
    /// Initial gap between the cylinder's lowest point and the block top;
    /// negative values start with an overlap.
    pub gap: f64,
    /// Element size h_c in the contact zone, on both bodies, at level 0.
    pub fine_size: f64,
    /// Half-width c_zone of the uniformly fine zone around x = 0 (also its
    /// depth into both bodies); at most π R / 4.
    pub fine_half_width: f64,
    /// Largest size ratio of neighbouring elements outside the fine zone.
    pub growth: f64,
    /// Refinement level: every element size is halved per level.
    pub level: u32,
    /// `Tet4` splits every hex into tets.
    pub cell_type: CellType,
}

impl Default for HertzCylinderSpec {
    /// R = 10 on a 40 × 20 block, 1 thick, touching; 0.1 elements over
    /// |x| ≤ 2, i.e. ≥ 10 elements per contact half-width for a/R ≥ 0.1.
    fn default() -> Self {
        HertzCylinderSpec {
            radius: 10.0,
            block_width: 40.0,
            block_height: 20.0,
            thickness: 1.0,
            gap: 0.0,
            fine_size: 0.1,
            fine_half_width: 2.0,
            growth: 1.2,
            level: 0,
            cell_type: CellType::Hex8,
        }
    }
}

/// Two bodies, `block` and `cylinder`, for plane-strain Hertz contact along
/// the line x = 0, z = 0 (axis along y).
///
/// `block`: x ∈ [−W/2, W/2], y ∈ [0, t], z ∈ [−H, 0], uniform size h_c
/// over |x| ≤ c_zone and depth c_zone, graded outside. `cylinder`: lower
/// half of the cylinder of radius R, axis (0, ·, R + gap), an O-grid (core
/// box plus three ray-mapped shell patches) with size h_c over arc length
/// c_zone and depth c_zone around its lowest point.
///
/// Sets (node and facet): `block.top`, `block.bottom`, `block.xmin`,
/// `block.xmax`, `block.front` (y = 0), `block.back` (y = t),
/// `block.contact` (top facets with |x| ≤ c_zone), `cylinder.curved`,
/// `cylinder.top` (flat face z = R + gap, for the load),
/// `cylinder.front`, `cylinder.back`, `cylinder.contact` (curved facets
/// with |x| ≤ c_zone). Node sets only: `cylinder.axis` (the nodes on the
/// axis line x = 0, z = R + gap) and `cylinder.tip` (the lowest line).
pub fn hertz_cylinder(spec: &HertzCylinderSpec) -> Result<Mesh, MeshError> {
    check_spec(spec)?;
    let lines = shell_lines(&ShellInput {
        generator: GENERATOR,
        radius: spec.radius,
        fine_size: spec.fine_size,
        fine_half_width: spec.fine_half_width,
        growth: spec.growth,
        level: spec.level,
    })?;
    let (x, z) = block_lines(spec)?;
    check_size(
        GENERATOR,
        size_field(spec.level),
        &cell_blocks(&x, &z, &lines),
        spec.cell_type,
    )?;
    let block = block_body(spec, x, z)?;
    let cylinder =
        cylinder_body(spec, &lines).map_err(|r| spec_error(GENERATOR, "fine_size", r))?;
    finalize(block.merge(cylinder)?, spec.cell_type)
}

fn check_spec(spec: &HertzCylinderSpec) -> Result<(), MeshError> {
    check_at_least(GENERATOR, "block_width", spec.block_width, 0.0, false)?;
    check_at_least(GENERATOR, "block_height", spec.block_height, 0.0, false)?;
    check_at_least(GENERATOR, "thickness", spec.thickness, 0.0, false)?;
    if !spec.gap.is_finite() {
        return Err(spec_error(
            GENERATOR,
            "gap",
            format!("must be finite (got {})", spec.gap),
        ));
    }
    Ok(())
}

/// The block's x and z node lines.
fn block_lines(spec: &HertzCylinderSpec) -> Result<(Vec<f64>, Vec<f64>), MeshError> {
    let fine = FineZone {
        size: spec.fine_size,
        half_width: spec.fine_half_width,
        growth: spec.growth,
    };
    contact_block_lines(spec.block_width / 2.0, spec.block_height, &fine, spec.level)
        .map_err(|r| spec_error(GENERATOR, "fine_size", r))
}

/// Cells per direction of every block [`hertz_cylinder`] builds: the block,
/// the cylinder's core box and its left, bottom and right shell patches.
fn cell_blocks(x: &[f64], z: &[f64], lines: &ShellLines) -> [[usize; 3]; 5] {
    let n = |v: &[f64]| v.len().saturating_sub(1);
    let (side, bottom, radial) = (n(&lines.side), n(&lines.bottom), n(&lines.radial));
    [
        [n(x), 1, n(z)],
        [bottom, 1, side],
        [side, 1, radial],
        [bottom, 1, radial],
        [side, 1, radial],
    ]
}

fn block_body(spec: &HertzCylinderSpec, x: Vec<f64>, z: Vec<f64>) -> Result<Mesh, MeshError> {
    let y = vec![0.0, spec.thickness];
    let sides = [
        (Side::IMin, "xmin"),
        (Side::IMax, "xmax"),
        (Side::JMin, "front"),
        (Side::JMax, "back"),
        (Side::KMin, "bottom"),
        (Side::KMax, "top"),
    ];
    let mut mesh = tensor_body("block", &[x, y, z], &sides)
        .map_err(|r| spec_error(GENERATOR, "fine_size", r))?;
    let zone = spec.fine_half_width * (1.0 + 1e-9);
    subset_set(&mut mesh, "block.top", "block.contact", |c| {
        c[0].abs() <= zone
    });
    Ok(mesh)
}

/// The half cylinder: core box (x ∈ [−a, a], z ∈ [C − a, C]) and the left,
/// bottom and right shell patches, all one cell thick in y.
fn cylinder_body(spec: &HertzCylinderSpec, lines: &ShellLines) -> Result<Mesh, String> {
    let centre_z = spec.radius + spec.gap;
    // Patches run counter-clockwise in the (x, z) plane (i), with y (j) and
    // σ pointing inward (k): a right-handed frame, so cells are positive.
    let left_angles = lines.side.clone();
    let right_angles: Vec<f64> = lines.side.iter().rev().copied().collect();
    let left = shell_patch(spec, lines, &left_angles, |phi| [-1.0, -tan_exact(phi)])?
        .tag(Side::IMin, "top");
    let bottom = shell_patch(spec, lines, &lines.bottom, |alpha| [tan_exact(alpha), -1.0])?;
    let right = shell_patch(spec, lines, &right_angles, |phi| [1.0, -tan_exact(phi)])?
        .tag(Side::IMax, "top");
    let mut builder = BodyBuilder::new("cylinder", spec.radius);
    for block in [&core_block(spec, lines)?, &left, &bottom, &right] {
        builder.add(block)?;
    }
    let mut mesh = builder.finish();
    add_line_sets(&mut mesh, spec, centre_z);
    Ok(mesh)
}

/// The core box; its lines are the core-side ends of the patch rays, so its
/// nodes coincide with the patches' inner nodes.
fn core_block(spec: &HertzCylinderSpec, lines: &ShellLines) -> Result<Block, String> {
    let centre_z = spec.radius + spec.gap;
    let a = lines.core;
    let x = core_line(&lines.bottom, a);
    // z of the core box side faces, ascending from C − a to C.
    let z: Vec<f64> = lines
        .side
        .iter()
        .rev()
        .map(|&phi| centre_z - a * tan_exact(phi))
        .collect();
    Ok(Block::tensor(&x, &[0.0, spec.thickness], &z)?
        .tag(Side::KMax, "top")
        .tag(Side::JMin, "front")
        .tag(Side::JMax, "back"))
}

/// One shell patch over `angles`, with `dir` giving the in-plane (x, z) ray
/// direction for an angle.
fn shell_patch(
    spec: &HertzCylinderSpec,
    lines: &ShellLines,
    angles: &[f64],
    dir: impl Fn(f64) -> [f64; 2],
) -> Result<Block, String> {
    let centre = [0.0, 0.0, spec.radius + spec.gap];
    let y = [0.0, spec.thickness];
    let dims = [
        angles.len().saturating_sub(1),
        1,
        lines.radial.len().saturating_sub(1),
    ];
    let block = Block::from_fn(dims, |i, j, k| {
        let [dx, dz] = dir(angles[i]);
        let p = shell_point(
            centre,
            lines.core,
            spec.radius,
            [dx, 0.0, dz],
            lines.radial[k],
        );
        [p[0], y[j], p[2]]
    })?;
    Ok(block
        .tag(Side::KMin, "curved")
        .tag(Side::JMin, "front")
        .tag(Side::JMax, "back"))
}

/// `cylinder.contact`, `cylinder.axis` and `cylinder.tip`.
fn add_line_sets(mesh: &mut Mesh, spec: &HertzCylinderSpec, centre_z: f64) {
    let zone = spec.fine_half_width * (1.0 + 1e-9);
    subset_set(mesh, "cylinder.curved", "cylinder.contact", |c| {
        c[0].abs() <= zone
    });
    let tol = 1e-9 * spec.radius;
    let on_line = |z: f64| -> Vec<usize> {
        mesh.nodes
            .iter()
            .enumerate()
            .filter(|(_, p)| p[0].abs() <= tol && (p[2] - z).abs() <= tol)
            .map(|(n, _)| n)
            .collect()
    };
    let axis = on_line(centre_z);
    let tip = on_line(spec.gap);
    mesh.node_sets.insert("cylinder.axis".into(), axis);
    mesh.node_sets.insert("cylinder.tip".into(), tip);
}

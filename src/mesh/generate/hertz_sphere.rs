//! 3D Hertz point contact: a hemisphere on a block.

use super::blocks::{subset_set, Block, BodyBuilder, Side};
use super::graded_box::tensor_body;
use super::o_grid::{core_line, shell_lines, shell_point, tan_exact, ShellInput, ShellLines};
use super::spacing::{contact_block_lines, FineZone};
use super::{check_at_least, check_size, finalize, size_field, spec_error};
use crate::mesh::geometry::Vec3;
use crate::mesh::{CellType, Mesh, MeshError};

const GENERATOR: &str = "hertz_sphere";

/// Parameters of [`hertz_sphere`]. Lengths in mesh units.
#[derive(Debug, Clone, PartialEq)]
pub struct HertzSphereSpec {
    /// Sphere radius R.
    pub radius: f64,
    /// Block width W: the block spans x, y ∈ [−W/2, W/2].
    pub block_width: f64,
    /// Block height H: the block spans z ∈ [−H, 0].
    pub block_height: f64,
    /// Initial gap between the sphere's lowest point and the block top;
    /// negative values start with an overlap.
    pub gap: f64,
    /// Element size h_c in the contact zone, on both bodies, at level 0.
    pub fine_size: f64,
    /// Half-width c_zone of the uniformly fine zone around the contact
    /// point (also its depth into both bodies); at most π R / 4.
    pub fine_half_width: f64,
    /// Largest size ratio of neighbouring elements outside the fine zone.
    pub growth: f64,
    /// Refinement level: every element size is halved per level (×8 cells).
    pub level: u32,
    /// `Tet4` splits every hex into tets.
    pub cell_type: CellType,
}

impl Default for HertzSphereSpec {
    /// R = 10 on a 40 × 40 × 20 block, touching; 0.25 elements over a
    /// 2 × 2 zone (about 70 k hexes; 3D meshes grow fast, refine by `level`).
    fn default() -> Self {
        HertzSphereSpec {
            radius: 10.0,
            block_width: 40.0,
            block_height: 20.0,
            gap: 0.0,
            fine_size: 0.25,
            fine_half_width: 2.0,
            growth: 1.25,
            level: 0,
            cell_type: CellType::Hex8,
        }
    }
}

/// Two bodies, `block` and `sphere`, for Hertz point contact at the origin.
///
/// `block`: x, y ∈ [−W/2, W/2], z ∈ [−H, 0], uniform size h_c over
/// |x|, |y| ≤ c_zone and depth c_zone, graded outside. `sphere`: lower
/// hemisphere of radius R centred at (0, 0, R + gap), meshed as a half cube
/// core plus five ray-mapped shell patches (bottom, ±x, ±y), no degenerate
/// cells, size h_c over arc length c_zone and depth c_zone around its lowest
/// point.
///
/// Sets (node and facet): `block.top`, `block.bottom`, `block.xmin`,
/// `block.xmax`, `block.ymin`, `block.ymax`, `block.contact` (top facets
/// with |x|, |y| ≤ c_zone), `sphere.curved`, `sphere.top` (flat face
/// z = R + gap), `sphere.contact` (curved facets with |x|, |y| ≤ c_zone).
/// Node sets only: `sphere.axis` (centre of the flat face) and `sphere.tip`
/// (lowest point).
pub fn hertz_sphere(spec: &HertzSphereSpec) -> Result<Mesh, MeshError> {
    check_at_least(GENERATOR, "block_width", spec.block_width, 0.0, false)?;
    check_at_least(GENERATOR, "block_height", spec.block_height, 0.0, false)?;
    if !spec.gap.is_finite() {
        return Err(spec_error(
            GENERATOR,
            "gap",
            format!("must be finite (got {})", spec.gap),
        ));
    }
    let lines = shell_lines(&ShellInput {
        generator: GENERATOR,
        radius: spec.radius,
        fine_size: spec.fine_size,
        fine_half_width: spec.fine_half_width,
        growth: spec.growth,
        level: spec.level,
    })?;
    let (xy, z) = block_lines(spec)?;
    check_size(
        GENERATOR,
        size_field(spec.level),
        &cell_blocks(&xy, &z, &lines),
        spec.cell_type,
    )?;
    let block = block_body(xy, z, spec)?;
    let sphere = sphere_body(spec, &lines).map_err(|r| spec_error(GENERATOR, "fine_size", r))?;
    finalize(block.merge(sphere)?, spec.cell_type)
}

/// The block's x (= y) and z node lines.
fn block_lines(spec: &HertzSphereSpec) -> Result<(Vec<f64>, Vec<f64>), MeshError> {
    let fine = FineZone {
        size: spec.fine_size,
        half_width: spec.fine_half_width,
        growth: spec.growth,
    };
    contact_block_lines(spec.block_width / 2.0, spec.block_height, &fine, spec.level)
        .map_err(|r| spec_error(GENERATOR, "fine_size", r))
}

/// Cells per direction of every block [`hertz_sphere`] builds: the block,
/// the sphere's core and its five shell patches (see [`patches`]).
fn cell_blocks(xy: &[f64], z: &[f64], lines: &ShellLines) -> Vec<[usize; 3]> {
    let n = |v: &[f64]| v.len().saturating_sub(1);
    let (side, bottom, radial) = (n(&lines.side), n(&lines.bottom), n(&lines.radial));
    let mut dims = vec![
        [n(xy), n(xy), n(z)],
        [bottom, bottom, side],
        [bottom, bottom, radial],
    ];
    dims.extend([[side, bottom, radial]; 4]);
    dims
}

fn block_body(xy: Vec<f64>, z: Vec<f64>, spec: &HertzSphereSpec) -> Result<Mesh, MeshError> {
    let sides = [
        (Side::IMin, "xmin"),
        (Side::IMax, "xmax"),
        (Side::JMin, "ymin"),
        (Side::JMax, "ymax"),
        (Side::KMin, "bottom"),
        (Side::KMax, "top"),
    ];
    let mut mesh = tensor_body("block", &[xy.clone(), xy, z], &sides)
        .map_err(|r| spec_error(GENERATOR, "fine_size", r))?;
    let zone = spec.fine_half_width * (1.0 + 1e-9);
    subset_set(&mut mesh, "block.top", "block.contact", |c| {
        c[0].abs() <= zone && c[1].abs() <= zone
    });
    Ok(mesh)
}

/// Which way one shell patch runs; see [`patch_block`].
struct Patch {
    /// Angle lines for i and j.
    i_angles: Vec<f64>,
    j_angles: Vec<f64>,
    /// Ray direction from the two angles.
    dir: fn(f64, f64) -> Vec3,
    /// Side of the patch lying on the flat face, if any.
    top: Option<Side>,
}

/// The five shell patches. Each has (i, j) ordered so that i × j points
/// toward the centre and k (σ) runs inward: a right-handed frame.
fn patches(lines: &ShellLines) -> [Patch; 5] {
    let bottom = lines.bottom.clone();
    // Side angles reversed: z ascending from the core's bottom edge.
    let up: Vec<f64> = lines.side.iter().rev().copied().collect();
    [
        Patch {
            i_angles: bottom.clone(),
            j_angles: bottom.clone(),
            dir: |a, b| [tan_exact(a), tan_exact(b), -1.0],
            top: None,
        },
        Patch {
            i_angles: up.clone(),
            j_angles: bottom.clone(),
            dir: |phi, b| [1.0, tan_exact(b), -tan_exact(phi)],
            top: Some(Side::IMax),
        },
        Patch {
            i_angles: bottom.clone(),
            j_angles: up.clone(),
            dir: |b, phi| [-1.0, tan_exact(b), -tan_exact(phi)],
            top: Some(Side::JMax),
        },
        Patch {
            i_angles: bottom.clone(),
            j_angles: up.clone(),
            dir: |a, phi| [tan_exact(a), 1.0, -tan_exact(phi)],
            top: Some(Side::JMax),
        },
        Patch {
            i_angles: up,
            j_angles: bottom,
            dir: |phi, a| [tan_exact(a), -1.0, -tan_exact(phi)],
            top: Some(Side::IMax),
        },
    ]
}

fn patch_block(
    patch: &Patch,
    lines: &ShellLines,
    centre: Vec3,
    radius: f64,
) -> Result<Block, String> {
    let dims = [
        patch.i_angles.len().saturating_sub(1),
        patch.j_angles.len().saturating_sub(1),
        lines.radial.len().saturating_sub(1),
    ];
    let block = Block::from_fn(dims, |i, j, k| {
        let dir = (patch.dir)(patch.i_angles[i], patch.j_angles[j]);
        shell_point(centre, lines.core, radius, dir, lines.radial[k])
    })?
    .tag(Side::KMin, "curved");
    Ok(match patch.top {
        Some(side) => block.tag(side, "top"),
        None => block,
    })
}

/// Half-cube core plus the five shell patches.
fn sphere_body(spec: &HertzSphereSpec, lines: &ShellLines) -> Result<Mesh, String> {
    let centre = [0.0, 0.0, spec.radius + spec.gap];
    let xy_core = core_line(&lines.bottom, lines.core);
    let z_core: Vec<f64> = lines
        .side
        .iter()
        .rev()
        .map(|&phi| centre[2] - lines.core * tan_exact(phi))
        .collect();
    let core = Block::tensor(&xy_core, &xy_core, &z_core)?.tag(Side::KMax, "top");
    let mut builder = BodyBuilder::new("sphere", spec.radius);
    builder.add(&core)?;
    for patch in patches(lines) {
        builder.add(&patch_block(&patch, lines, centre, spec.radius)?)?;
    }
    let mut mesh = builder.finish();
    add_point_sets(&mut mesh, spec, centre);
    Ok(mesh)
}

/// `sphere.contact`, `sphere.axis` and `sphere.tip`.
fn add_point_sets(mesh: &mut Mesh, spec: &HertzSphereSpec, centre: Vec3) {
    let zone = spec.fine_half_width * (1.0 + 1e-9);
    subset_set(mesh, "sphere.curved", "sphere.contact", |c| {
        c[0].abs() <= zone && c[1].abs() <= zone
    });
    let tol = 1e-9 * spec.radius;
    let at = |z: f64| -> Vec<usize> {
        mesh.nodes
            .iter()
            .enumerate()
            .filter(|(_, p)| p[0].abs() <= tol && p[1].abs() <= tol && (p[2] - z).abs() <= tol)
            .map(|(n, _)| n)
            .collect()
    };
    let axis = at(centre[2]);
    let tip = at(spec.gap);
    mesh.node_sets.insert("sphere.axis".into(), axis);
    mesh.node_sets.insert("sphere.tip".into(), tip);
}

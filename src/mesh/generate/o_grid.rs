//! Shared construction of the curved bodies: a core box surrounded by
//! mapped shell patches ("O-grid" for the half disc, "cube in a ball" for
//! the hemisphere).
//!
//! A shell node lies on the ray from the centre through a point of the core
//! box surface: with `d` the ray direction, the core point is
//! `C + core · d / ‖d‖∞` and the surface point `C + R · d / ‖d‖₂`; the node
//! is `surface + σ (core − surface)` with σ ∈ [0, 1] (0 on the curved
//! surface). Rays through the centre keep every shell cell convex and free
//! of the degenerate axis cells of a polar grid.
//!
//! Directions on the lowest patch are `(tan α, tan β, −1)` with α, β the
//! angles from the downward axis, so arc length near the contact point is
//! `R α` and the fine contact-zone spacing can be laid out in α directly.
//! Directions on the side patches use the depression angle φ ∈ [0, π/4]
//! below the flat face.

use std::f64::consts::FRAC_PI_4;

use super::spacing::{check_fine_zone, core_then_graded, subdivide, symmetric_core, MAX_LEVEL};
use super::{check_at_least, spec_error};
use crate::mesh::geometry::{add, norm, scale, sub, Vec3};
use crate::mesh::MeshError;

/// Core half-size as a fraction of the radius. Smaller makes the shell
/// cells at the core corners less skewed but the core cells more stretched;
/// 0.5 keeps the scaled Jacobian above 0.5 in both (see the quality tests).
pub(crate) const CORE_FRACTION: f64 = 0.5;

/// Parameter lines of a level-refined O-grid.
pub(crate) struct ShellLines {
    /// Core half-size (distance from centre to the core box faces).
    pub core: f64,
    /// Angles α ∈ [−π/4, π/4] of the lowest patch, fine around 0.
    pub bottom: Vec<f64>,
    /// Depression angles φ ∈ [0, π/4] of the side patches, uniform.
    pub side: Vec<f64>,
    /// Shell parameter σ ∈ [0, 1], fine at 0 (the curved surface).
    pub radial: Vec<f64>,
}

/// Inputs shared by the cylinder and sphere specs.
pub(crate) struct ShellInput {
    pub generator: &'static str,
    pub radius: f64,
    pub fine_size: f64,
    pub fine_half_width: f64,
    pub growth: f64,
    pub level: u32,
}

/// Checks the inputs and lays out the three parameter lines at level 0,
/// then subdivides them for the requested level.
pub(crate) fn shell_lines(input: &ShellInput) -> Result<ShellLines, MeshError> {
    let g = input.generator;
    check_at_least(g, "radius", input.radius, 0.0, false)?;
    check_fine_zone(input.fine_size, input.fine_half_width, input.growth)
        .map_err(|(field, reason)| spec_error(g, field, reason))?;
    if input.level > MAX_LEVEL {
        return Err(spec_error(
            g,
            "level",
            format!("must be at most {MAX_LEVEL} (got {})", input.level),
        ));
    }
    let r = input.radius;
    let quarter_arc = FRAC_PI_4 * r;
    if input.fine_half_width > quarter_arc {
        return Err(spec_error(
            g,
            "fine_half_width",
            format!(
                "must not exceed π R / 4 = {quarter_arc} (the lowest shell patch); got {}",
                input.fine_half_width
            ),
        ));
    }
    let arc = symmetric_core(
        quarter_arc,
        input.fine_half_width,
        input.fine_size,
        input.growth,
    )
    .map_err(|reason| spec_error(g, "fine_size", reason))?;
    let bottom: Vec<f64> = arc.iter().map(|s| s / r).collect();
    let side = side_angles(&arc, quarter_arc);
    let core = CORE_FRACTION * r;
    let depth = r - core;
    let radial: Vec<f64> =
        core_then_graded(depth, input.fine_half_width, input.fine_size, input.growth)
            .map_err(|reason| spec_error(g, "fine_size", reason))?
            .iter()
            .map(|d| d / depth)
            .collect();
    Ok(ShellLines {
        core,
        bottom: subdivide(&bottom, input.level),
        side: subdivide(&side, input.level),
        radial: subdivide(&radial, input.level),
    })
}

/// Uniform side-patch angles whose arc length does not exceed the coarsest
/// element of the lowest patch, so sizes never jump across the patch seam.
fn side_angles(bottom_arc: &[f64], quarter_arc: f64) -> Vec<f64> {
    let end_size = match bottom_arc {
        [.., a, b] => b - a,
        _ => quarter_arc,
    };
    let n = (quarter_arc / end_size).ceil().max(1.0) as usize;
    (0..=n).map(|i| FRAC_PI_4 * i as f64 / n as f64).collect()
}

/// `tan`, exact at ±π/4 so the patch seams meet the core box edges exactly.
pub(crate) fn tan_exact(angle: f64) -> f64 {
    if (angle.abs() - FRAC_PI_4).abs() < 1e-15 {
        angle.signum()
    } else {
        angle.tan()
    }
}

/// Shell node on the ray `dir` from `centre` (see the module docs).
pub(crate) fn shell_point(centre: Vec3, core: f64, radius: f64, dir: Vec3, sigma: f64) -> Vec3 {
    let inf_norm = dir.iter().fold(0.0_f64, |m, x| m.max(x.abs()));
    let core_point = add(centre, scale(dir, core / inf_norm));
    let surface_point = add(centre, scale(dir, radius / norm(dir)));
    add(surface_point, scale(sub(core_point, surface_point), sigma))
}

/// Core box coordinates `core · tan(angle)` matching the patch angles.
pub(crate) fn core_line(angles: &[f64], core: f64) -> Vec<f64> {
    angles.iter().map(|&a| core * tan_exact(a)).collect()
}

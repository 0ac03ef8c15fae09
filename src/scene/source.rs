//! Where a scene's text comes from: the built-in scenes compiled in from
//! `scenes/`, or a file.
use crate::error::{Error, Result};
use std::path::Path;

/// The scenes compiled into the binary: (name, one-line description, TOML).
pub const BUILTIN: &[(&str, &str, &str)] = &[
    (
        "hertz-cylinder",
        "Hertz line contact: half-cylinder on a block, plane strain, frictionless",
        include_str!("../../scenes/hertz-cylinder.toml"),
    ),
    (
        "hertz-sphere",
        "Hertz point contact: sphere cap on a block, frictionless",
        include_str!("../../scenes/hertz-sphere.toml"),
    ),
    (
        "patch-test",
        "Contact patch test: stacked blocks with non-matching meshes, uniform compression",
        include_str!("../../scenes/patch-test.toml"),
    ),
    (
        "block-on-plane",
        "Neo-Hookean block pressed onto a rigid plane (rigid analytic master)",
        include_str!("../../scenes/block-on-plane.toml"),
    ),
    (
        "block-slide",
        "Block pressed on a rigid plane and pulled: Coulomb friction (μ = 0.3), stick then slip",
        include_str!("../../scenes/block-slide.toml"),
    ),
    (
        "ironing",
        "Stiff die pressed into a soft slab and dragged along it, μ = 0.3 (Puso & Laursen 2004)",
        include_str!("../../scenes/ironing.toml"),
    ),
    (
        "impact",
        "Two free blocks colliding obliquely, implicit dynamics: momentum conserved",
        include_str!("../../scenes/impact.toml"),
    ),
    (
        "block-compress",
        "Neo-Hookean block compressed 20 % by a follower pressure (finite strain)",
        include_str!("../../scenes/block-compress.toml"),
    ),
    (
        "uniaxial-stretch",
        "Neo-Hookean cube stretched to twice its length (closed form known)",
        include_str!("../../scenes/uniaxial-stretch.toml"),
    ),
    (
        "cantilever",
        "Linear-elastic cantilever under an end traction, graded tet mesh",
        include_str!("../../scenes/cantilever.toml"),
    ),
];

/// Where a scene came from, for messages.
#[derive(Debug, Clone)]
pub struct SceneSource {
    pub origin: String,
    pub text: String,
    /// The scene file read (none for a built-in scene).
    pub path: Option<std::path::PathBuf>,
}

impl SceneSource {
    /// A built-in scene by name, or a file by path.
    pub fn resolve(name_or_path: &str) -> Result<Self> {
        if let Some((name, _, text)) = BUILTIN.iter().find(|(n, _, _)| *n == name_or_path) {
            return Ok(SceneSource {
                origin: format!("built-in scene '{name}'"),
                text: (*text).to_owned(),
                path: None,
            });
        }
        let path = Path::new(name_or_path);
        let text = std::fs::read_to_string(path).map_err(|e| {
            let known: Vec<&str> = BUILTIN.iter().map(|(n, _, _)| *n).collect();
            Error::scene(
                name_or_path,
                format!(
                    "cannot read it ({e}); it is not a built-in scene either (built-ins: {})",
                    known.join(", ")
                ),
            )
        })?;
        Ok(SceneSource {
            origin: path.display().to_string(),
            text,
            path: Some(path.to_path_buf()),
        })
    }
}

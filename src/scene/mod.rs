//! Scene files (TOML) → a validated [`Model`].
//!
//! A scene names the mesh (a generator and its parameters), a material per
//! body, Dirichlet conditions, loads, load steps, solver options and the
//! output path. Built-in scenes live in `scenes/` and are compiled in.
//! Every error names the key (and, for syntax errors, the line).
//!
//! - `source`: the built-in scenes and scene files;
//! - `sections`: the TOML sections as read;
//! - `parse`: text and `--set` overrides → [`Scene`]; errors at a key's line;
//! - `build`: [`Scene::build`] → [`Model`];
//! - `mesh`: the generated, Gmsh or `.inp` mesh;
//! - `conditions`: Dirichlet conditions, amplitudes, dynamics, solver settings;
//! - `contact`: contact pairs and the Hertz check;
//! - `held`: which static bodies nothing holds;
//! - `limits`, `lines`: count limits; key → line lookup.
mod build;
mod conditions;
mod contact;
mod held;
mod limits;
mod lines;
mod mesh;
mod parse;
mod sections;
mod source;

pub use lines::{KeyLines, Origin, Seg};
pub use mesh::MeshReport;
pub use parse::parse;
pub use sections::*;
pub use source::{SceneSource, BUILTIN};

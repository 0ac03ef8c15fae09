//! A scene loaded for a run with the mesh on rank 0 only.
//!
//! Rank 0 resolves the scene source, parses it, builds (or reads) the mesh
//! and resolves every reference of the scene against it — exactly what a
//! single-rank run does, with the same checks in the same order. What the
//! resolution found is a model without its mesh (materials, Dirichlet node
//! lists and values, facet loads, contact pairs, settings: arrays of the
//! size of a node or facet set, never of the mesh), and it goes to the other
//! ranks in one broadcast ([`crate::model::wire`]) with the output path, the
//! input files and the scene text. The set-up then cuts rank 0's mesh into
//! pieces (`distribution`) and frees it.
//!
//! Why not a mesh-free half of the scene build on every rank and only the
//! mesh-dependent half on rank 0: the mesh-free checks are cheap, and doing
//! all of them in one place gives one order of checks and one error text.
//! A scene error (a syntax error, an unknown set, a broken mesh file line,
//! an unheld body, an inverted cell) is found on rank 0 and reaches every
//! rank as that same text through [`parallel::from_root`], and no other rank
//! reads the scene or mesh files, so no rank can see them differently.
use crate::error::{Error, Result};
use crate::mesh::Mesh;
use crate::model::wire::{self, Reader, Writer};
use crate::model::Model;
use crate::output::paths::Input;
use crate::parallel;
use crate::scene::SceneSource;
use mpi::traits::*;
use std::os::unix::ffi::OsStrExt;
use std::path::PathBuf;

/// A scene ready to set up.
pub struct Loaded {
    /// The model; its mesh is empty on every rank (moved to `mesh`).
    pub model: Model,
    /// The mesh, on rank 0 only (`None` on the other ranks).
    pub mesh: Option<Mesh>,
    /// The scene's `[output] path`.
    pub output: Option<String>,
    /// The files the run reads (scene, mesh), which no output may replace.
    pub inputs: Vec<Input>,
    /// The scene text, for the result file's provenance.
    pub scene_text: String,
    /// What reading the mesh found, for rank 0 to print once (empty on the
    /// other ranks).
    pub notes: Vec<String>,
}

impl Loaded {
    /// The mesh to hand to the set-up: rank 0's, an empty one elsewhere
    /// (the distribution reads the mesh on rank 0 only).
    pub fn take_mesh(&mut self) -> Mesh {
        self.mesh
            .take()
            .unwrap_or_else(|| Mesh::empty(self.model.mesh.cell_type))
    }
}

/// The kinds of input file a run names, by their index on the wire.
const INPUTS: [&str; 2] = ["scene file", "mesh file"];

/// Loads a scene on every rank as one process would.
pub fn everywhere(name_or_path: &str, overrides: &[String]) -> Result<Loaded> {
    let src = SceneSource::resolve(name_or_path)?;
    let mut built = super::build_model(&src, overrides)?;
    let mesh = Some(built.model.take_mesh());
    Ok(Loaded {
        model: built.model,
        mesh,
        output: built.output,
        inputs: built.inputs,
        scene_text: src.text,
        notes: built.notes,
    })
}

/// Collective: loads a scene on rank 0 and hands the other ranks the model
/// without its mesh, or rank 0's error.
pub fn on_root(
    world: &impl Communicator,
    name_or_path: &str,
    overrides: &[String],
) -> Result<Loaded> {
    if world.size() == 1 {
        return everywhere(name_or_path, overrides);
    }
    if world.rank() != 0 {
        let words = parallel::from_root(world, 0, None);
        // Rank 0 passed here with its own load: the decoding is the only
        // thing left that one rank alone could fail.
        let words = words?;
        let loaded = decode(&words);
        return parallel::agree(world, loaded);
    }
    let (mine, sent) = match everywhere(name_or_path, overrides) {
        Ok(l) => match encode(&l) {
            Ok(w) => (Some(l), Ok(w)),
            Err(e) => (None, Err(e)),
        },
        Err(e) => (None, Err(e)),
    };
    parallel::from_root(world, 0, Some(sent))?;
    let mine = mine.ok_or_else(|| Error::Internal("rank 0 sent a model it does not hold".into()));
    parallel::agree(world, mine)
}

fn encode(l: &Loaded) -> Result<Vec<u64>> {
    let mut w = Writer::default();
    wire::encode(&l.model, &mut w)?;
    w.bool(l.output.is_some());
    w.str(l.output.as_deref().unwrap_or(""));
    w.usize(l.inputs.len());
    for input in &l.inputs {
        let kind = INPUTS
            .iter()
            .position(|&k| k == input.what)
            .ok_or_else(|| {
                Error::Internal(format!("an input file of unknown kind '{}'", input.what))
            })?;
        w.usize(kind);
        w.bytes(input.path.as_os_str().as_bytes());
    }
    w.str(&l.scene_text);
    Ok(w.words)
}

fn decode(words: &[u64]) -> Result<Loaded> {
    let mut r = Reader::new(words);
    let model = wire::decode(&mut r)?;
    let has_output = r.bool()?;
    let output = r.str()?;
    let n = r.usize()?;
    let mut inputs = Vec::new();
    for _ in 0..n {
        let what = *INPUTS.get(r.usize()?).ok_or_else(|| {
            Error::Internal("the broadcast scene names an input file of unknown kind".into())
        })?;
        let path = PathBuf::from(std::ffi::OsStr::from_bytes(&r.bytes()?));
        inputs.push(Input { what, path });
    }
    let scene_text = r.str()?;
    if !r.finished() {
        return Err(Error::Internal(
            "the broadcast scene has words left over".into(),
        ));
    }
    Ok(Loaded {
        model,
        mesh: None,
        output: has_output.then_some(output),
        inputs,
        scene_text,
        notes: Vec::new(),
    })
}

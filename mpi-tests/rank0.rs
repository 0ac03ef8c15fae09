//! A scene's run reads the mesh on rank 0 only (`pipeline::load::on_root`):
//! the other ranks receive the model without its mesh, the same model a
//! single process builds, and a scene error found on rank 0 is every
//! rank's, with the text a single process prints.
use contactlink::model::wire::{encode, Writer};
use contactlink::model::Model;
use contactlink::pipeline::load;
use contactlink::runtime::Runtime;
use mpi::traits::*;

fn words(model: &Model) -> Result<Vec<u64>, String> {
    let mut w = Writer::default();
    encode(model, &mut w).map_err(|e| e.to_string())?;
    Ok(w.words)
}

/// Rank 0's text on every rank.
fn rank0_text(rt: &Runtime, mine: &str) -> String {
    contactlink::parallel::broadcast_text(&rt.world(), 0, mine)
}

/// The 40³-cell box of `block-compress` (68,921 nodes, about 6 MiB of mesh
/// arrays): large enough that holding it would show in a rank's resident
/// memory, small enough to build in a moment.
const BOX: &[&str] = &["mesh.divisions=[40, 40, 40]"];

/// On rank ≥ 1 the loaded model has no mesh, `loaded.mesh` is None and the
/// resident memory grew by less than half the mesh's arrays while loading;
/// rank 0 holds the whole mesh; the model every rank holds is, word for
/// word, the one a single process builds from the scene.
pub fn only_rank_0_holds_the_mesh(rt: &Runtime) -> Result<(), String> {
    let overrides: Vec<String> = BOX.iter().map(|s| s.to_string()).collect();
    for scene in ["block-compress", "hertz-cylinder", "impact"] {
        let over: &[String] = if scene == "block-compress" {
            &overrides
        } else {
            &[]
        };
        let before = contactlink::memory::resident_mib();
        let loaded = load::on_root(&rt.world(), scene, over).map_err(|e| e.to_string())?;
        let after = contactlink::memory::resident_mib();
        let (nodes, cells, bytes) = match &loaded.mesh {
            Some(m) => (
                m.num_nodes(),
                m.num_cells(),
                24 * m.num_nodes() + 8 * m.cells.len() + 4 * m.cell_body.len(),
            ),
            None => (0, 0, 0),
        };
        let mut sizes = [nodes as u64, cells as u64, bytes as u64];
        rt.world().process_at_rank(0).broadcast_into(&mut sizes[..]);
        let [n, c, mesh_bytes] = sizes;
        if let (Some(b), Some(a), "block-compress", true) = (before, after, scene, rt.rank() > 0) {
            let grown = a - b;
            let mesh_mib = mesh_bytes as f64 / (1024.0 * 1024.0);
            if grown > 0.5 * mesh_mib {
                return Err(format!(
                    "rank {}: resident memory grew by {grown:.1} MiB while loading a scene whose mesh is {mesh_mib:.1} MiB",
                    rt.rank()
                ));
            }
        }
        let m = &loaded.model.mesh;
        if m.num_nodes() != 0 || m.num_cells() != 0 || !m.node_sets.is_empty() {
            return Err(format!(
                "{scene}: the loaded model holds a mesh of {} nodes",
                m.num_nodes()
            ));
        }
        match rt.rank() {
            0 if n == 0 || c == 0 => return Err(format!("{scene}: rank 0 holds no mesh")),
            0 => {}
            r if loaded.mesh.is_some() => {
                return Err(format!("{scene}: rank {r} holds the {n}-node mesh"))
            }
            _ => {}
        }
        // The serial build, on every rank: what one process would solve.
        let serial = load::everywhere(scene, over).map_err(|e| e.to_string())?;
        let (got, want) = (words(&loaded.model)?, words(&serial.model)?);
        if got != want {
            return Err(format!(
                "{scene}: rank {} holds a model of {} words, a single process builds {}",
                rt.rank(),
                got.len(),
                want.len()
            ));
        }
        let serial_mesh = serial.mesh.as_ref().map_or(0, |m| m.num_nodes());
        if serial_mesh as u64 != n
            || loaded.output != serial.output
            || loaded.scene_text != serial.scene_text
            || loaded.inputs.len() != serial.inputs.len()
        {
            return Err(format!(
                "{scene}: rank {} loaded other output, inputs or scene text than a single process",
                rt.rank()
            ));
        }
    }
    Ok(())
}

/// Scene errors that only the resolution against the mesh finds (an
/// unknown node or facet set, a mesh the generator refuses) fail on every rank with the text a
/// single process gives, without a rank prefix.
pub fn a_scene_error_on_rank_0_is_every_ranks(rt: &Runtime) -> Result<(), String> {
    let cases: [&[&str]; 3] = [
        &["dirichlet.0.set=no-such-set"],
        &["pressure.0.set=block.nowhere"],
        &["mesh.divisions=[2, 2, 0]"],
    ];
    for over in cases {
        let over: Vec<String> = over.iter().map(|s| s.to_string()).collect();
        let got = load::on_root(&rt.world(), "block-compress", &over);
        let serial = load::everywhere("block-compress", &over);
        let (Err(got), Err(serial)) = (got, serial) else {
            return Err(format!(
                "{over:?}: rank {} loaded the scene (or a single process did)",
                rt.rank()
            ));
        };
        let (got, serial) = (got.to_string(), serial.to_string());
        if got != serial || rank0_text(rt, &got) != got {
            return Err(format!(
                "{over:?}: rank {} says '{got}', a single process '{serial}'",
                rt.rank()
            ));
        }
    }
    Ok(())
}

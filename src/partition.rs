//! Cell partition: METIS k-way on the cell dual graph (cells sharing a facet).
use crate::error::{Error, Result};
use crate::mesh::Mesh;

/// The owning rank of every cell, for `nparts` ranks. Deterministic for a
/// given mesh and rank count (METIS with a fixed seed).
pub fn partition_cells(mesh: &Mesh, nparts: usize) -> Result<Vec<i32>> {
    let ncells = mesh.num_cells();
    if nparts <= 1 || ncells == 0 {
        return Ok(vec![0; ncells]);
    }
    if ncells < nparts {
        return Err(Error::Partition(format!(
            "{ncells} cells cannot be shared among {nparts} ranks; use fewer ranks or a finer mesh"
        )));
    }
    let shared = mesh.cell_type.facet_type().nodes();
    let (xadj, adjncy) = mesh.dual_graph(shared)?;
    let to_idx = |v: usize| {
        metis::Idx::try_from(v)
            .map_err(|_| Error::Partition("mesh too large for METIS's index type".into()))
    };
    let xadj: Vec<metis::Idx> = xadj.iter().map(|&v| to_idx(v)).collect::<Result<_>>()?;
    let adjncy: Vec<metis::Idx> = adjncy.iter().map(|&v| to_idx(v)).collect::<Result<_>>()?;
    let mut part = vec![0 as metis::Idx; ncells];
    metis::Graph::new(1, nparts as metis::Idx, &xadj, &adjncy)
        .map_err(|e| Error::Partition(format!("METIS rejected the dual graph: {e:?}")))?
        .set_option(metis::option::Seed(17))
        .set_option(metis::option::Contig(false))
        .part_kway(&mut part)
        .map_err(|e| Error::Partition(format!("METIS_PartGraphKway failed: {e:?}")))?;
    // METIS's index width is a build option of the library; ranks fit i32.
    #[allow(clippy::unnecessary_cast)]
    let part: Vec<i32> = part.into_iter().map(|p| p as i32).collect();
    for r in 0..nparts as i32 {
        if !part.contains(&r) {
            return Err(Error::Partition(format!(
                "METIS left rank {r} without cells; use fewer ranks"
            )));
        }
    }
    Ok(part)
}

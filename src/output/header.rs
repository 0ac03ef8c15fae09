//! Local validation of a [`MeshHeader`] before `/mesh` is written.

use std::path::Path;

use super::collective::to_h5_string;
use super::xdmf::{self, MeshDesc};
use super::{check_name, facet_nodes, layout, MeshHeader, OutputError, MIXED_FACETS};
use crate::fem::{CellType, MAX_FACET_NODES};

/// What the XDMF writer needs, after all local checks of the header.
pub(super) fn validate_header(path: &Path, mesh: &MeshHeader) -> Result<MeshDesc, OutputError> {
    let invalid = |object: &str, reason: String| Err(OutputError::invalid(path, object, reason));
    let Some(kind) = CellType::from_name(mesh.cell_type) else {
        return invalid(
            layout::MESH_CELLS,
            format!(
                "cell_type '{}' is not a supported cell type",
                mesh.cell_type
            ),
        );
    };
    let n_nodes = mesh.nodes.global_rows;
    let n_cells = mesh.cells.global_rows;
    if mesh.nodes.cols != 3 {
        return invalid(
            layout::MESH_NODES,
            format!("has {} columns, expected 3", mesh.nodes.cols),
        );
    }
    if mesh.cells.cols != kind.nodes() {
        return invalid(
            layout::MESH_CELLS,
            format!(
                "has {} columns, {} cells have {}",
                mesh.cells.cols,
                kind.name(),
                kind.nodes()
            ),
        );
    }
    for (object, b) in [
        (layout::MESH_PARTITION, &mesh.partition),
        (layout::MESH_CELL_BODY, &mesh.cell_body),
    ] {
        if b.cols != 1 || b.global_rows != n_cells {
            return invalid(
                object,
                format!("is ({},{}), expected ({n_cells},1)", b.global_rows, b.cols),
            );
        }
    }
    let h5_name = match path.file_name().and_then(|n| n.to_str()) {
        Some(n) => n.to_string(),
        None => return invalid("/", "the file name is empty or not UTF-8".into()),
    };
    if xdmf::sidecar_path(path) == path {
        return invalid(
            "/",
            "the result file must not end in .xmf (the sidecar's name)".into(),
        );
    }

    // Local block contents: node ids in range, body and rank indices valid.
    if let Some(bad) = mesh
        .cells
        .data
        .iter()
        .find(|&&id| usize::try_from(id).map_or(true, |i| i >= n_nodes))
    {
        return invalid(
            layout::MESH_CELLS,
            format!("node id {bad} is outside 0..{n_nodes}"),
        );
    }
    let n_bodies = mesh.bodies.len();
    if let Some(bad) = mesh
        .cell_body
        .data
        .iter()
        .find(|&&b| usize::try_from(b).map_or(true, |i| i >= n_bodies))
    {
        return invalid(
            layout::MESH_CELL_BODY,
            format!("body index {bad} is outside 0..{n_bodies} (the bodies list)"),
        );
    }
    if let Some(bad) = mesh.partition.data.iter().find(|&&r| r < 0) {
        return invalid(layout::MESH_PARTITION, format!("negative rank {bad}"));
    }
    for body in mesh.bodies {
        to_h5_string(path, layout::MESH_CELL_BODY, body)?;
    }

    for (name, ids) in mesh.node_sets {
        let object = layout::node_set(name);
        check_name(path, &object, name)?;
        if let Some(bad) = ids.iter().find(|&&i| i >= n_nodes) {
            return invalid(&object, format!("node id {bad} is outside 0..{n_nodes}"));
        }
    }
    for (name, fs) in mesh.facet_sets {
        let object = layout::facet_set(name);
        check_name(path, &object, name)?;
        let f = fs.cell.len();
        let facet_k = match facet_nodes(&fs.facet_type) {
            Some(k) => k,
            None if fs.facet_type == MIXED_FACETS && fs.k <= MAX_FACET_NODES => fs.k,
            None => {
                return invalid(
                    &object,
                    format!("facet type '{}' is not supported", fs.facet_type),
                )
            }
        };
        if fs.k != facet_k {
            return invalid(
                &object,
                format!(
                    "k = {}, but {} facets have {facet_k} nodes",
                    fs.k, fs.facet_type
                ),
            );
        }
        if fs.nodes.len() != f * fs.k || fs.face.len() != f {
            return invalid(
                &object,
                format!(
                    "{} cells, {} faces and {} node ids do not describe {f} facets of {} nodes",
                    f,
                    fs.face.len(),
                    fs.nodes.len(),
                    fs.k
                ),
            );
        }
        let padding = |id: i64| id == -1 && fs.facet_type == MIXED_FACETS;
        if let Some(bad) = fs
            .nodes
            .iter()
            .find(|&&id| !padding(id) && usize::try_from(id).map_or(true, |i| i >= n_nodes))
        {
            return invalid(&object, format!("node id {bad} is outside 0..{n_nodes}"));
        }
        if let Some(bad) = fs
            .cell
            .iter()
            .find(|&&c| usize::try_from(c).map_or(true, |i| i >= n_cells))
        {
            return invalid(&object, format!("cell id {bad} is outside 0..{n_cells}"));
        }
    }
    Ok(MeshDesc {
        h5_name,
        cell_type: kind,
        n_nodes,
        n_cells,
    })
}

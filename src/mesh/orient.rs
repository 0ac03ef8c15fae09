//! Cells as a reader finds them: fully inverted ones (some writers emit them)
//! reversed to positive orientation, tangled ones refused. The Gmsh and the
//! Abaqus readers both call this after building the connectivity.

use super::geometry::cell_jacobians;
use super::Mesh;

/// A cell whose Jacobian determinants have mixed signs or a zero: neither
/// orientation makes it valid.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct Tangled {
    /// Cell id in the mesh.
    pub(crate) cell: usize,
    pub(crate) min: f64,
    pub(crate) max: f64,
}

/// Jacobian determinants a cell is judged by ([`cell_jacobians`]: the
/// tet4's one, the hex8's corners, the quadrature points of the other
/// types).
fn jacobians(mesh: &Mesh, ids: &[usize]) -> Vec<f64> {
    let points: Vec<[f64; 3]> = ids.iter().map(|&n| mesh.nodes[n]).collect();
    cell_jacobians(mesh.cell_type, &points)
}

/// Reverses the fully inverted cells (negative Jacobian everywhere) and
/// returns how many; the first tangled cell is an error. Node ids must be in
/// range (the readers build the connectivity from their own node tables).
pub(crate) fn orient_cells(mesh: &mut Mesh) -> Result<usize, Tangled> {
    let per = mesh.cell_type.nodes();
    // A reflection of the reference cell (`CellType::mirror`).
    let perm = mesh.cell_type.mirror();
    let mut reversed = 0;
    for c in 0..mesh.num_cells() {
        let ids: Vec<usize> = mesh.cell(c).to_vec();
        let dets = jacobians(mesh, &ids);
        let min = dets.iter().copied().fold(f64::INFINITY, f64::min);
        let max = dets.iter().copied().fold(f64::NEG_INFINITY, f64::max);
        if min > 0.0 {
            continue;
        }
        if max >= 0.0 || min.is_nan() {
            return Err(Tangled { cell: c, min, max });
        }
        for (k, &from) in perm.iter().enumerate() {
            mesh.cells[c * per + k] = ids[from];
        }
        reversed += 1;
    }
    Ok(reversed)
}

//! Cells as a reader finds them: fully inverted ones (some writers emit them)
//! reversed to positive orientation, tangled ones refused. The Gmsh and the
//! Abaqus readers both call this after building the connectivity.

use super::geometry::{hex_corner_jacobians, tet_jacobian};
use super::{CellType, Mesh};

/// A cell whose Jacobian determinants have mixed signs or a zero: neither
/// orientation makes it valid.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct Tangled {
    /// Cell id in the mesh.
    pub(crate) cell: usize,
    pub(crate) min: f64,
    pub(crate) max: f64,
}

/// Renumbering that reverses a cell: tet swaps nodes 1 and 2; hex swaps the
/// bottom and top quads (a reflection ζ → −ζ of the reference cube).
fn reversal(cell_type: CellType) -> &'static [usize] {
    match cell_type {
        CellType::Tet4 => &[0, 2, 1, 3],
        CellType::Hex8 => &[4, 5, 6, 7, 0, 1, 2, 3],
    }
}

/// Jacobian determinants of a cell: the tet's one, the hex's eight corners.
fn cell_jacobians(mesh: &Mesh, ids: &[usize]) -> Vec<f64> {
    let p = |k: usize| mesh.nodes[ids[k]];
    match mesh.cell_type {
        CellType::Tet4 => vec![tet_jacobian(&std::array::from_fn(p))],
        CellType::Hex8 => hex_corner_jacobians(&std::array::from_fn(p)).to_vec(),
    }
}

/// Reverses the fully inverted cells (negative Jacobian everywhere) and
/// returns how many; the first tangled cell is an error. Node ids must be in
/// range (the readers build the connectivity from their own node tables).
pub(crate) fn orient_cells(mesh: &mut Mesh) -> Result<usize, Tangled> {
    let per = mesh.cell_type.nodes();
    let perm = reversal(mesh.cell_type);
    let mut reversed = 0;
    for c in 0..mesh.num_cells() {
        let ids: Vec<usize> = mesh.cell(c).to_vec();
        let dets = cell_jacobians(mesh, &ids);
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

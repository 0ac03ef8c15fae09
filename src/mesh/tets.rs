//! Conforming subdivision of a hex mesh into tetrahedra.
//!
//! Neighbouring hexes must cut their shared quad along the same diagonal.
//! The rule that guarantees this without looking at the neighbour is the
//! one of Dompierre et al. (1999, "How to subdivide pyramids, prisms and
//! hexahedra into tetrahedra"): every quad is cut along the diagonal through
//! its node with the lowest global id. Both cells sharing a quad see the same
//! four ids, so they agree.
//!
//! Per hex, rotate it so its lowest-id node is local node 0. Node 6 is then
//! opposite. If one of the three faces at node 6 has its diagonal through
//! node 6, rotate about the 0–6 axis until that face is the top, cut the hex
//! into two prisms along the plane (0, 2, 6, 4) and split each prism into 3
//! tets with the same lowest-id rule (6 tets). Otherwise the six face
//! diagonals are exactly the edges of tet (0, 2, 5, 7), which forces the
//! classic 5-tet split (4 corners + 1 central tet).

use super::{CellType, Mesh, MeshError};
use crate::fem::shape::HEX8_REF_NODES;

/// A rotation of the reference hex as `old = map[new]`.
type HexRotation = [usize; 8];

/// Reference coordinates of hex node `a` (VTK order), as integer signs so
/// that rotated corners compare exactly.
fn hex_corner(a: usize) -> [i8; 3] {
    HEX8_REF_NODES[a].map(|c| if c < 0.0 { -1 } else { 1 })
}

const AXIS_PERMUTATIONS: [[usize; 3]; 6] = [
    [0, 1, 2],
    [1, 2, 0],
    [2, 0, 1],
    [0, 2, 1],
    [2, 1, 0],
    [1, 0, 2],
];

/// The 24 proper rotations of the cube, generated as signed axis
/// permutations with determinant +1 (so relabelled hexes stay positively
/// oriented).
fn hex_rotations() -> Vec<HexRotation> {
    let mut rotations = Vec::with_capacity(24);
    for (p, axes) in AXIS_PERMUTATIONS.iter().enumerate() {
        // The first three permutations are even, the last three odd.
        let parity: i8 = if p < 3 { 1 } else { -1 };
        for signs in 0..8u8 {
            let s: [i8; 3] = std::array::from_fn(|k| if signs >> k & 1 == 1 { -1 } else { 1 });
            if parity * s[0] * s[1] * s[2] != 1 {
                continue;
            }
            let map = std::array::from_fn(|new| {
                let c = hex_corner(new);
                let rotated: [i8; 3] = std::array::from_fn(|k| s[k] * c[axes[k]]);
                (0..8).position(|a| hex_corner(a) == rotated).unwrap_or(0)
            });
            rotations.push(map);
        }
    }
    rotations
}

/// True when the quad's lowest-id-node diagonal joins `a` and `c` (the quad
/// being a, b, c, d in cyclic order) rather than `b` and `d`.
fn diagonal_is_ac(a: usize, b: usize, c: usize, d: usize) -> bool {
    a.min(c) < b.min(d)
}

/// Orientation-preserving symmetries of a prism (a0 a1 a2 | b0 b1 b2), as
/// `old = sym[new]`: the three rotations, and the three with the triangles
/// swapped (which also reverses the triangle order to keep orientation).
const PRISM_SYMMETRIES: [[usize; 6]; 6] = [
    [0, 1, 2, 3, 4, 5],
    [1, 2, 0, 4, 5, 3],
    [2, 0, 1, 5, 3, 4],
    [3, 5, 4, 0, 2, 1],
    [4, 3, 5, 1, 0, 2],
    [5, 4, 3, 2, 1, 0],
];

/// Splits a prism given by global ids into 3 positively oriented tets.
fn split_prism(p: [usize; 6]) -> [[usize; 4]; 3] {
    let lowest = (0..6).min_by_key(|&k| p[k]).unwrap_or(0);
    let sym = PRISM_SYMMETRIES
        .iter()
        .find(|s| s[0] == lowest)
        .unwrap_or(&PRISM_SYMMETRIES[0]);
    let q: [usize; 6] = std::array::from_fn(|k| p[sym[k]]);
    let [a0, a1, a2, b0, b1, b2] = q;
    // Both quads at a0 are cut through a0; only the opposite quad
    // (a1 a2 b2 b1) has a choice.
    if diagonal_is_ac(a1, a2, b2, b1) {
        [[a0, b0, b1, b2], [a0, a1, a2, b2], [a0, a1, b2, b1]]
    } else {
        [[a0, b0, b1, b2], [a0, a1, a2, b1], [a0, a2, b2, b1]]
    }
}

/// Splits one hex (global ids, VTK order) into 5 or 6 tets.
fn split_hex(ids: &[usize], rotations: &[HexRotation]) -> Vec<[usize; 4]> {
    let lowest = (0..8).min_by_key(|&k| ids[k]).unwrap_or(0);
    let relabel = |r: &HexRotation| -> [usize; 8] { std::array::from_fn(|k| ids[r[k]]) };
    let candidates: Vec<[usize; 8]> = rotations
        .iter()
        .filter(|r| r[0] == lowest)
        .map(relabel)
        .collect();
    // The three candidates are the rotations about the 0–6 axis; they bring
    // each face at node 6 to the top in turn. A prism cut needs the top face
    // cut along 4–6, parallel to the bottom's 0–2.
    let prism_ready = candidates
        .iter()
        .find(|g| diagonal_is_ac(g[4], g[5], g[6], g[7]));
    match prism_ready {
        Some(g) => {
            let mut tets = Vec::with_capacity(6);
            tets.extend(split_prism([g[0], g[1], g[2], g[4], g[5], g[6]]));
            tets.extend(split_prism([g[0], g[2], g[3], g[4], g[6], g[7]]));
            tets
        }
        None => {
            let g = candidates.first().copied().unwrap_or([0; 8]);
            five_tets(&g)
        }
    }
}

/// The forced split when no face at node 6 is cut through node 6.
fn five_tets(g: &[usize; 8]) -> Vec<[usize; 4]> {
    [
        [0, 1, 2, 5],
        [0, 2, 3, 7],
        [0, 4, 5, 7],
        [2, 5, 6, 7],
        [0, 5, 2, 7],
    ]
    .iter()
    .map(|t| t.map(|k| g[k]))
    .collect()
}

impl Mesh {
    /// Splits every hex into 6 tets (5 where the face diagonals force it),
    /// conformingly across neighbours; see the module docs for the rule.
    /// Bodies and node sets are kept; each facet of a facet set becomes the
    /// two outward tet faces covering it.
    pub fn hex_to_tets(&self) -> Result<Mesh, MeshError> {
        self.require(CellType::Hex8, "hex_to_tets")?;
        let rotations = hex_rotations();
        let mut out = self.children(CellType::Tet4);
        // first_child[c]..first_child[c + 1] are the tets of hex c.
        let mut first_child = Vec::with_capacity(self.num_cells() + 1);
        for (c, ids) in self.cells_iter().enumerate() {
            first_child.push(out.num_cells());
            let body = self.cell_body.get(c).copied().unwrap_or(0);
            for tet in split_hex(ids, &rotations) {
                out.cells.extend_from_slice(&tet);
                out.cell_body.push(body);
            }
        }
        first_child.push(out.num_cells());
        out.facet_sets = self.children_facet_sets(&out, &first_child)?;
        Ok(out)
    }
}

/// Six times the signed volume of a tet given by reference corner signs;
/// used by the tests to check every split is positively oriented.
#[cfg(test)]
pub(crate) fn reference_tet_det(tet: [usize; 4], corners: &[[f64; 3]; 8]) -> f64 {
    use crate::vec3::{sub, triple};
    let d = |k: usize| sub(corners[tet[k]], corners[tet[0]]);
    triple(d(1), d(2), d(3))
}

#[cfg(test)]
pub(crate) fn split_hex_for_tests(ids: &[usize]) -> Vec<[usize; 4]> {
    split_hex(ids, &hex_rotations())
}

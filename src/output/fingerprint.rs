//! Fingerprints of collective calls: every rank hashes the arguments that
//! must be equal everywhere (names, shapes, step metadata, set data), and the
//! hashes are compared across ranks before anything is written.

use super::{BlockRows, MeshHeader, StepInfo};

/// FNV-1a over a length-prefixed encoding: a cheap, deterministic summary of
/// the arguments of a collective call, compared across ranks.
pub(super) struct Fingerprint(pub(super) u64);

impl Fingerprint {
    pub(super) fn new() -> Self {
        Self(0xcbf2_9ce4_8422_2325)
    }
    pub(super) fn bytes(&mut self, b: &[u8]) {
        for &x in b {
            self.0 ^= u64::from(x);
            self.0 = self.0.wrapping_mul(0x0100_0000_01b3);
        }
    }
    pub(super) fn u64(&mut self, v: u64) {
        self.bytes(&v.to_le_bytes());
    }
    pub(super) fn usize(&mut self, v: usize) {
        self.u64(v as u64);
    }
    pub(super) fn str(&mut self, s: &str) {
        self.usize(s.len());
        self.bytes(s.as_bytes());
    }
    pub(super) fn i64s(&mut self, v: &[i64]) {
        self.usize(v.len());
        v.iter().for_each(|&x| self.bytes(&x.to_le_bytes()));
    }
    pub(super) fn f64s(&mut self, v: &[f64]) {
        self.usize(v.len());
        v.iter().for_each(|&x| self.u64(x.to_bits()));
    }
}

/// Everything of a header that must be equal on all ranks (the block data
/// is excluded: it differs by design; its global shape is included).
pub(super) fn header_fingerprint(mesh: &MeshHeader) -> u64 {
    let mut f = Fingerprint::new();
    f.str(mesh.cell_type);
    for (rows, cols) in [
        (mesh.nodes.global_rows, mesh.nodes.cols),
        (mesh.cells.global_rows, mesh.cells.cols),
        (mesh.partition.global_rows, mesh.partition.cols),
        (mesh.cell_body.global_rows, mesh.cell_body.cols),
    ] {
        f.usize(rows);
        f.usize(cols);
    }
    f.usize(mesh.bodies.len());
    mesh.bodies.iter().for_each(|b| f.str(b));
    f.usize(mesh.node_sets.len());
    for (name, ids) in mesh.node_sets {
        f.str(name);
        f.usize(ids.len());
        ids.iter().for_each(|&i| f.usize(i));
    }
    f.usize(mesh.facet_sets.len());
    for (name, fs) in mesh.facet_sets {
        f.str(name);
        f.str(&fs.facet_type);
        f.usize(fs.k);
        f.i64s(&fs.nodes);
        f.i64s(&fs.cell);
        f.usize(fs.face.len());
        fs.face.iter().for_each(|&x| f.bytes(&x.to_le_bytes()));
    }
    f.0
}

/// The step metadata and field structure that must match on all ranks.
pub(super) fn step_fingerprint(
    info: &StepInfo,
    nodal: &[(&str, BlockRows<f64>)],
    cell: &[(&str, BlockRows<f64>)],
) -> u64 {
    let mut f = Fingerprint::new();
    f.usize(info.index);
    f.u64(info.time.to_bits());
    f.u64(info.load_factor.to_bits());
    f.usize(info.newton_iterations);
    f.usize(info.uzawa_iterations);
    f.u64(u64::from(info.converged));
    for fields in [nodal, cell] {
        f.usize(fields.len());
        for (name, rows) in fields {
            f.str(name);
            f.usize(rows.global_rows);
            f.usize(rows.cols);
        }
    }
    f.0
}

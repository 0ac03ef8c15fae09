//! A piece as flat `u64` words for one MPI message: scalars, then each array
//! as its length followed by its entries, in field order.
use super::local::{
    GhostFacet, LocalFacet, LocalFacetSet, LocalMesh, OutputBlock, SharedSet, SlaveSetPiece,
};
use super::Piece;
use crate::error::{Error, Result};
use crate::fem::{CellType, MAX_FACET_NODES};
use crate::mesh::BoundingBox;

pub(super) fn encode(p: &Piece) -> Vec<u64> {
    let mut w = Vec::new();
    for s in [
        p.rank,
        p.nranks,
        p.global_nodes,
        p.global_cells,
        p.owned_node_start,
        p.n_owned,
    ] {
        w.push(s as u64);
    }
    put(&mut w, p.local_cells.iter().map(|&v| v as u64));
    put(&mut w, p.local_natural.iter().map(|&v| v as u64));
    put(&mut w, p.local_petsc.iter().map(|&v| u64::from(v)));
    put(&mut w, p.cell_nodes.iter().map(|&v| u64::from(v)));
    put(&mut w, p.block_petsc.iter().map(|&v| u64::from(v)));
    put(&mut w, p.block_partition.iter().map(|&v| v as u32 as u64));
    put_mesh(&mut w, &p.mesh);
    w
}

fn put_mesh(w: &mut Vec<u64>, m: &LocalMesh) {
    // The position in `CellType::ALL` (hex8 0, tet4 1, ...).
    let code = CellType::ALL.iter().position(|&c| c == m.cell_type);
    w.push(code.unwrap_or(0) as u64);
    w.push(m.bodies.len() as u64);
    for b in &m.bodies {
        put_str(w, b);
    }
    match &m.bounding_box {
        None => w.push(0),
        Some(b) => {
            w.push(1);
            w.extend(b.min.iter().chain(&b.max).map(|x| x.to_bits()));
        }
    }
    w.extend([m.global_nodes as u64, m.global_cells as u64]);
    put_points(w, &m.nodes);
    put(w, m.cell_body.iter().map(|&v| u64::from(v)));
    put(w, m.owned_body.iter().map(|&v| u64::from(v)));
    w.push(m.facet_sets.len() as u64);
    for (name, set) in &m.facet_sets {
        put_str(w, name);
        w.push(set.global_len as u64);
        w.push(set.facets.len() as u64);
        for f in &set.facets {
            w.extend([f.set_index as u64, f.cell as u64, u64::from(f.face)]);
            w.extend(f.nodes.iter().map(|&v| u64::from(v)));
        }
    }
    w.push(m.slaves.len() as u64);
    for s in &m.slaves {
        put(w, s.owners.iter().map(|&v| v as u32 as u64));
        w.push(s.mean_edge.to_bits());
        w.push(s.ghosts.len() as u64);
        for g in &s.ghosts {
            w.push(g.set_index as u64);
            w.extend(g.natural.iter().map(|&v| v as u64));
            w.extend(g.x_ref.iter().flatten().map(|x| x.to_bits()));
        }
    }
    w.push(m.shared.len() as u64);
    for (name, set) in &m.shared {
        put_str(w, name);
        put(w, set.cells.iter().map(|&v| v as u64));
        put(w, set.faces.iter().map(|&v| u64::from(v)));
        put(w, set.nodes.iter().map(|&v| v as u64));
    }
    w.push(m.node_sets.len() as u64);
    for (name, ids) in &m.node_sets {
        put_str(w, name);
        put(w, ids.iter().map(|&v| v as u64));
    }
    put_points(w, &m.block.nodes);
    put(w, m.block.cells.iter().map(|&v| v as u64));
    put(w, m.block.cell_body.iter().map(|&v| u64::from(v)));
}

fn put_str(w: &mut Vec<u64>, s: &str) {
    put(w, s.bytes().map(u64::from));
}

fn put_points(w: &mut Vec<u64>, points: &[[f64; 3]]) {
    w.push(points.len() as u64);
    w.extend(points.iter().flatten().map(|x| x.to_bits()));
}

fn put(w: &mut Vec<u64>, items: impl ExactSizeIterator<Item = u64>) {
    w.push(items.len() as u64);
    w.extend(items);
}

/// Reads words written by [`encode`].
pub(super) fn decode(words: &[u64]) -> Result<Piece> {
    let mut r = Reader { words, at: 0 };
    let rank = r.scalar()?;
    let nranks = r.scalar()?;
    let global_nodes = r.scalar()?;
    let global_cells = r.scalar()?;
    let owned_node_start = r.scalar()?;
    let n_owned = r.scalar()?;
    let local_cells = r.array(|v| v as usize)?;
    let local_natural = r.array(|v| v as usize)?;
    let local_petsc = r.array(|v| v as u32)?;
    let cell_nodes = r.array(|v| v as u32)?;
    let block_petsc = r.array(|v| v as u32)?;
    let block_partition = r.array(|v| v as u32 as i32)?;
    let mesh = read_mesh(&mut r)?;
    Ok(Piece {
        rank,
        nranks,
        global_nodes,
        global_cells,
        owned_node_start,
        n_owned,
        local_cells,
        local_natural,
        local_petsc,
        cell_nodes,
        block_petsc,
        block_partition,
        mesh,
    })
}

fn read_mesh(r: &mut Reader) -> Result<LocalMesh> {
    let Some(&cell_type) = CellType::ALL.get(r.scalar()?) else {
        return Err(Error::Internal("mesh piece of an unknown cell type".into()));
    };
    let n_bodies = r.scalar()?;
    let bodies = (0..n_bodies).map(|_| r.string()).collect::<Result<_>>()?;
    let bounding_box = match r.scalar()? {
        0 => None,
        _ => {
            let v = r.fixed(6)?;
            let f = |i: usize| f64::from_bits(v[i]);
            Some(BoundingBox {
                min: [f(0), f(1), f(2)],
                max: [f(3), f(4), f(5)],
            })
        }
    };
    let global_nodes = r.scalar()?;
    let global_cells = r.scalar()?;
    let nodes = r.points()?;
    let cell_body = r.array(|v| v as u32)?;
    let owned_body = r.array(|v| v as u32)?;
    let mut facet_sets = std::collections::BTreeMap::new();
    for _ in 0..r.scalar()? {
        let name = r.string()?;
        let global_len = r.scalar()?;
        let n = r.scalar()?;
        let mut facets = Vec::new();
        for _ in 0..n {
            let v = r.fixed(3 + MAX_FACET_NODES)?;
            facets.push(LocalFacet {
                set_index: v[0] as usize,
                cell: v[1] as usize,
                face: v[2] as u8,
                nodes: std::array::from_fn(|k| v[3 + k] as u32),
            });
        }
        facet_sets.insert(name, LocalFacetSet { global_len, facets });
    }
    let mut slaves = Vec::new();
    for _ in 0..r.scalar()? {
        let owners = r.array(|v| v as u32 as i32)?;
        let mean_edge = f64::from_bits(r.fixed(1)?[0]);
        let n = r.scalar()?;
        let mut ghosts = Vec::new();
        for _ in 0..n {
            const N: usize = MAX_FACET_NODES;
            let v = r.fixed(1 + 4 * N)?;
            let mut g = GhostFacet {
                set_index: v[0] as usize,
                natural: std::array::from_fn(|k| v[1 + k] as usize),
                x_ref: [[0.0; 3]; N],
            };
            for (k, x) in g.x_ref.iter_mut().flatten().enumerate() {
                *x = f64::from_bits(v[1 + N + k]);
            }
            ghosts.push(g);
        }
        slaves.push(SlaveSetPiece {
            owners,
            mean_edge,
            ghosts,
        });
    }
    let mut shared = std::collections::BTreeMap::new();
    for _ in 0..r.scalar()? {
        let name = r.string()?;
        let cells = r.array(|v| v as usize)?;
        let faces = r.array(|v| v as u8)?;
        let nodes = r.array(|v| v as usize)?;
        shared.insert(
            name,
            SharedSet {
                cells,
                faces,
                nodes,
            },
        );
    }
    let mut node_sets = std::collections::BTreeMap::new();
    for _ in 0..r.scalar()? {
        let name = r.string()?;
        node_sets.insert(name, r.array(|v| v as usize)?);
    }
    let block = OutputBlock {
        nodes: r.points()?,
        cells: r.array(|v| v as usize)?,
        cell_body: r.array(|v| v as u32)?,
    };
    Ok(LocalMesh {
        cell_type,
        bodies,
        bounding_box,
        global_nodes,
        global_cells,
        nodes,
        cell_body,
        owned_body,
        facet_sets,
        slaves,
        shared,
        node_sets,
        block,
    })
}

struct Reader<'a> {
    words: &'a [u64],
    at: usize,
}

impl Reader<'_> {
    fn scalar(&mut self) -> Result<usize> {
        let v = *self
            .words
            .get(self.at)
            .ok_or_else(|| Error::Internal("truncated mesh piece".into()))?;
        self.at += 1;
        usize::try_from(v).map_err(|_| Error::Internal("mesh piece entry out of range".into()))
    }

    /// The next `n` words.
    fn fixed(&mut self, n: usize) -> Result<&[u64]> {
        let end = self
            .at
            .checked_add(n)
            .filter(|&e| e <= self.words.len())
            .ok_or_else(|| Error::Internal("truncated mesh piece".into()))?;
        let out = &self.words[self.at..end];
        self.at = end;
        Ok(out)
    }

    fn string(&mut self) -> Result<String> {
        let bytes = self.array(|v| v as u8)?;
        String::from_utf8(bytes).map_err(|_| Error::Internal("mesh piece name not UTF-8".into()))
    }

    fn points(&mut self) -> Result<Vec<[f64; 3]>> {
        let n = self.scalar()?;
        let len = n
            .checked_mul(3)
            .ok_or_else(|| Error::Internal("truncated mesh piece".into()))?;
        let v = self.fixed(len)?;
        Ok(v.chunks_exact(3)
            .map(|c| {
                [
                    f64::from_bits(c[0]),
                    f64::from_bits(c[1]),
                    f64::from_bits(c[2]),
                ]
            })
            .collect())
    }

    fn array<T>(&mut self, f: impl Fn(u64) -> T) -> Result<Vec<T>> {
        let len = self.scalar()?;
        let end = self
            .at
            .checked_add(len)
            .filter(|&e| e <= self.words.len())
            .ok_or_else(|| Error::Internal("truncated mesh piece".into()))?;
        let out = self.words[self.at..end].iter().map(|&v| f(v)).collect();
        self.at = end;
        Ok(out)
    }
}

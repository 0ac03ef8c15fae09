//! A piece as flat `u64` words for one MPI message: scalars, then each array
//! as its length followed by its entries, in field order.
use super::Piece;
use crate::error::{Error, Result};

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
    w.push(p.facet_owners.len() as u64);
    for owners in &p.facet_owners {
        put(&mut w, owners.iter().map(|&v| v as u32 as u64));
    }
    w
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
    let n_sets = r.scalar()?;
    let facet_owners = (0..n_sets)
        .map(|_| r.array(|v| v as u32 as i32))
        .collect::<Result<_>>()?;
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
        facet_owners,
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

//! The pattern builder: couplings recorded on any rank, in rows any rank
//! owns, end up in the matrix exactly (no entry missing, none extra).
use contactlink::assembly::PatternBuilder;
use contactlink::petsc::{PetscInt, Vector};
use contactlink::runtime::Runtime;
use mpi::traits::Communicator;
use std::collections::BTreeMap;

use super::ensure;

const BS: usize = 3;

/// Nodes of rank `r`: uneven shares, so row ranges differ per rank.
fn nodes_of(r: usize) -> usize {
    2 + r
}

/// Every record of the test, the same list on every rank: (recording
/// rank, rows, cols, whether a square of whole nodes).
fn records(ranks: usize, nodes: usize) -> Vec<(usize, Vec<PetscInt>, Vec<PetscInt>, bool)> {
    let mut out = Vec::new();
    // Two-node "elements" along a chain that crosses every rank boundary,
    // each recorded by a rank that mostly does not own its rows.
    for k in 0..nodes - 1 {
        let dofs: Vec<PetscInt> = (BS * k..BS * k + 2 * BS).map(|d| d as PetscInt).collect();
        out.push((k % ranks, dofs.clone(), dofs, true));
    }
    // Single entries outside whole-node blocks, with a skipped index.
    for k in 0..nodes {
        let row = (BS * k + 1) as PetscInt;
        let col = (BS * ((k + 2) % nodes) + 2) as PetscInt;
        out.push(((k + 1) % ranks, vec![row], vec![col, -1], false));
    }
    out
}

fn value(row: PetscInt, col: PetscInt) -> f64 {
    1.0 + ((row * 7 + col * 13) % 11) as f64
}

pub fn the_pattern_holds_every_ranks_couplings(rt: &Runtime) -> Result<(), String> {
    let world = rt.world();
    let (ranks, rank) = (world.size() as usize, world.rank() as usize);
    let nodes: usize = (0..ranks).map(nodes_of).sum();
    let first_row = BS * (0..rank).map(nodes_of).sum::<usize>();
    let own_rows = BS * nodes_of(rank);
    let all = records(ranks, nodes);
    let mut pattern = PatternBuilder::new(own_rows, BS).map_err(|e| e.to_string())?;
    let mut expected: BTreeMap<(PetscInt, PetscInt), f64> = BTreeMap::new();
    for (by, rows, cols, square) in &all {
        for &r in rows.iter().filter(|&&r| r >= 0) {
            for &c in cols.iter().filter(|&&c| c >= 0) {
                expected.insert((r, c), value(r, c));
            }
        }
        if *by != rank {
            continue;
        }
        let recorded = if *square {
            pattern.add_square(rows)
        } else {
            pattern.add_block(rows, cols, &vec![0.0; rows.len() * cols.len()])
        };
        recorded.map_err(|e| e.to_string())?;
    }
    let mut a = pattern.build().map_err(|e| e.to_string())?;
    let nnz = a.global_nonzeros().map_err(|e| e.to_string())?;
    ensure(nnz == expected.len() as f64, || {
        format!("{nnz} stored entries, {} recorded", expected.len())
    })?;
    // Each entry set once, by a rank chosen apart from its row's owner:
    // inserting outside the pattern would be an error.
    for (i, (&(r, c), &v)) in expected.iter().enumerate() {
        if i % ranks == rank {
            a.add_block(&[r], &[c], &[v]).map_err(|e| e.to_string())?;
        }
    }
    a.assemble().map_err(|e| e.to_string())?;
    let mut ones = Vector::new_mpi(own_rows).map_err(|e| e.to_string())?;
    ones.set_all(1.0).map_err(|e| e.to_string())?;
    let mut sums = ones.duplicate().map_err(|e| e.to_string())?;
    a.mult(&ones, &mut sums).map_err(|e| e.to_string())?;
    let mut want = vec![0.0; own_rows];
    for (&(r, _), &v) in &expected {
        let local = r as usize;
        if (first_row..first_row + own_rows).contains(&local) {
            want[local - first_row] += v;
        }
    }
    let got = sums.with_array(|s| s.to_vec()).map_err(|e| e.to_string())?;
    ensure(got == want, || {
        format!("row sums {got:?}, expected {want:?}")
    })
}

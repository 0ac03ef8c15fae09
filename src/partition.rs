//! Cell partition: METIS k-way on the cell dual graph (cells sharing a facet).
//!
//! With contact, the cells holding a slave facet carry the contact search
//! and assembly besides their bulk work. A partition that balances cells
//! alone may put the whole contact zone on one rank (hertz-cylinder at
//! `mesh.level=1` on 2 ranks: every slave facet on one rank, no multiplier
//! halo), which then does all the contact work while the other waits. The
//! partition is therefore multi-constraint when slave sets are given: METIS
//! balances the cells (bulk assembly, matrix rows) and, as a second
//! constraint, the slave facets, both within its default imbalance.
use crate::error::{Error, Result};
use crate::mesh::Mesh;
use std::sync::Mutex;

/// Serialises the calls into METIS (see [`partition_cells`]).
static METIS: Mutex<()> = Mutex::new(());

/// The owning rank of every cell, for `nparts` ranks. Deterministic for a
/// given mesh, rank count and `balanced_sets` (METIS with a fixed seed).
///
/// `balanced_sets` names facet sets (contact slave sets) whose facets are
/// spread evenly over the ranks as well as the cells; names the mesh does
/// not have are ignored (the scene check reports them).
pub fn partition_cells(mesh: &Mesh, nparts: usize, balanced_sets: &[String]) -> Result<Vec<i32>> {
    let ncells = mesh.num_cells();
    if nparts <= 1 || ncells == 0 {
        return Ok(vec![0; ncells]);
    }
    if ncells < nparts {
        return Err(Error::Partition(format!(
            "{ncells} cells cannot be shared among {nparts} ranks; use fewer ranks or a finer mesh"
        )));
    }
    // Face adjacency: cells sharing a face (the corner key of
    // `Mesh::faces_by_key`), for every cell type.
    let (xadj, adjncy) = mesh.face_dual_graph();
    let to_idx = |v: usize| {
        metis::Idx::try_from(v)
            .map_err(|_| Error::Partition("mesh too large for METIS's index type".into()))
    };
    let xadj: Vec<metis::Idx> = xadj.iter().map(|&v| to_idx(v)).collect::<Result<_>>()?;
    let adjncy: Vec<metis::Idx> = adjncy.iter().map(|&v| to_idx(v)).collect::<Result<_>>()?;
    let facets = facets_per_cell(mesh, balanced_sets);
    // A second constraint needs slave facets on at least as many cells as
    // there are parts (METIS cannot balance a weight fewer cells carry).
    let weighted = facets.iter().filter(|&&f| f > 0).count() >= nparts;
    let vwgt: Vec<metis::Idx> = if weighted {
        facets
            .iter()
            .flat_map(|&f| [1, f])
            .map(to_idx)
            .collect::<Result<_>>()?
    } else {
        Vec::new()
    };
    let ncon = if weighted { 2 } else { 1 };
    let mut part = vec![0 as metis::Idx; ncells];
    let mut graph = metis::Graph::new(ncon, nparts as metis::Idx, &xadj, &adjncy)
        .map_err(|e| Error::Partition(format!("METIS rejected the dual graph: {e:?}")))?
        .set_option(metis::option::Seed(17))
        .set_option(metis::option::Contig(false));
    if weighted {
        graph = graph.set_vwgt(&vwgt);
    }
    // METIS keeps its random state in globals: two calls at once (threads
    // of one process, e.g. the unit tests) would draw from each other's
    // sequence and lose the fixed seed's determinism.
    let _one_at_a_time = METIS
        .lock()
        .unwrap_or_else(|poisoned| poisoned.into_inner());
    graph
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

/// How many facets of `sets` each cell holds.
fn facets_per_cell(mesh: &Mesh, sets: &[String]) -> Vec<usize> {
    let mut count = vec![0usize; mesh.num_cells()];
    for set in sets {
        for f in mesh.facet_sets.get(set).into_iter().flatten() {
            if let Some(c) = count.get_mut(f.cell) {
                *c += 1;
            }
        }
    }
    count
}

/// Work per rank of a partition: cells and facets of the balanced sets.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Balance {
    pub cells: Vec<usize>,
    pub facets: Vec<usize>,
}

impl Balance {
    pub fn of(mesh: &Mesh, part: &[i32], nparts: usize, balanced_sets: &[String]) -> Balance {
        let mut cells = vec![0usize; nparts];
        let mut facets = vec![0usize; nparts];
        let per_cell = facets_per_cell(mesh, balanced_sets);
        for (&p, &f) in part.iter().zip(&per_cell) {
            if let Some(r) = usize::try_from(p).ok().filter(|&r| r < nparts) {
                cells[r] += 1;
                facets[r] += f;
            }
        }
        Balance { cells, facets }
    }

    /// `partition: cells per rank L/S (largest/smallest), contact slave
    /// facets per rank L/S` (the line scripts/scaling.py parses).
    pub fn line(&self) -> String {
        let span = |v: &[usize]| {
            (
                v.iter().copied().max().unwrap_or(0),
                v.iter().copied().min().unwrap_or(0),
            )
        };
        let (cl, cs) = span(&self.cells);
        let (fl, fs) = span(&self.facets);
        format!(
            "partition: cells per rank {cl}/{cs} (largest/smallest), contact slave facets per rank {fl}/{fs}"
        )
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mesh::{graded_box, BoxSpec};

    fn cube(n: usize) -> Mesh {
        graded_box(&BoxSpec {
            divisions: [n, n, n],
            ..BoxSpec::default()
        })
        .unwrap()
    }

    fn top() -> Vec<String> {
        vec!["block.top".to_string()]
    }

    #[test]
    fn slave_facets_are_spread_over_the_ranks() {
        let mesh = cube(12);
        let total = mesh.facet_sets["block.top"].len();
        for nparts in [2, 3, 4] {
            let part = partition_cells(&mesh, nparts, &top()).unwrap();
            let b = Balance::of(&mesh, &part, nparts, &top());
            assert_eq!(b.facets.iter().sum::<usize>(), total);
            assert_eq!(b.cells.iter().sum::<usize>(), mesh.num_cells());
            let even_facets = total as f64 / nparts as f64;
            let even_cells = mesh.num_cells() as f64 / nparts as f64;
            for r in 0..nparts {
                assert!(
                    (b.facets[r] as f64) <= 1.1 * even_facets + 1.0,
                    "{nparts} parts: rank {r} holds {} of {total} slave facets",
                    b.facets[r]
                );
                assert!(
                    (b.cells[r] as f64) <= 1.05 * even_cells + 1.0,
                    "{nparts} parts: rank {r} holds {} cells",
                    b.cells[r]
                );
            }
        }
    }

    #[test]
    fn cells_alone_may_leave_a_face_on_few_ranks_and_weights_change_that() {
        // Unweighted, a 2-way cut of a cube is a plane; METIS's choice of
        // plane decides whether the top face is split. With the weight it
        // must be split evenly whatever the plane.
        let mesh = cube(12);
        let plain = partition_cells(&mesh, 2, &[]).unwrap();
        let weighted = partition_cells(&mesh, 2, &top()).unwrap();
        let b = Balance::of(&mesh, &weighted, 2, &top());
        assert!(b.facets.iter().all(|&f| f >= 60), "{b:?}");
        // Unweighted is what it was: unknown set names change nothing.
        assert_eq!(
            plain,
            partition_cells(&mesh, 2, &["no.such.set".into()]).unwrap()
        );
    }

    #[test]
    fn partition_is_deterministic_and_uses_every_rank() {
        let mesh = cube(8);
        let a = partition_cells(&mesh, 3, &top()).unwrap();
        let b = partition_cells(&mesh, 3, &top()).unwrap();
        assert_eq!(a, b);
        for r in 0..3 {
            assert!(a.contains(&r));
        }
        assert_eq!(partition_cells(&mesh, 1, &top()).unwrap(), vec![0; 512]);
    }

    #[test]
    fn balance_line_has_the_parsed_format() {
        let b = Balance {
            cells: vec![10, 12],
            facets: vec![3, 0],
        };
        assert_eq!(
            b.line(),
            "partition: cells per rank 12/10 (largest/smallest), contact slave facets per rank 3/0"
        );
    }
}

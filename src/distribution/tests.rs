use super::{wire, Numbering, Wanted};
use crate::mesh::{graded_box, BoxSpec};

fn small_box() -> crate::mesh::Mesh {
    graded_box(&BoxSpec::default()).unwrap()
}

#[test]
fn a_piece_survives_the_wire() {
    let mesh = small_box();
    let part: Vec<i32> = (0..mesh.num_cells()).map(|c| (c % 3) as i32).collect();
    let sets: Vec<String> = mesh.facet_sets.keys().take(2).cloned().collect();
    let numbering = Numbering::new(&mesh, &part, 3);
    let wanted = Wanted {
        extra_ghosts: &[0, 1],
        slave_sets: &sets,
    };
    for r in 0..3 {
        let piece = numbering.piece(&mesh, &part, r, &wanted);
        assert_eq!(wire::decode(&wire::encode(&piece)).unwrap(), piece);
        assert_eq!(piece.mesh.slaves.len(), 2);
        assert_eq!(piece.mesh.shared.len(), mesh.facet_sets.len());
        assert_eq!(piece.mesh.node_sets, mesh.node_sets);
    }
}

#[test]
fn pieces_tile_the_nodes_and_cells() {
    let mesh = small_box();
    let part: Vec<i32> = (0..mesh.num_cells()).map(|c| (c % 4) as i32).collect();
    let numbering = Numbering::new(&mesh, &part, 4);
    let pieces: Vec<_> = (0..4)
        .map(|r| numbering.piece(&mesh, &part, r, &Wanted::default()))
        .collect();
    let owned: usize = pieces.iter().map(|p| p.n_owned).sum();
    let cells: usize = pieces.iter().map(|p| p.local_cells.len()).sum();
    assert_eq!(owned, mesh.num_nodes());
    assert_eq!(cells, mesh.num_cells());
    let mut block: Vec<u32> = pieces.iter().flat_map(|p| p.block_petsc.clone()).collect();
    block.sort_unstable();
    assert!(block.iter().enumerate().all(|(i, &p)| p as usize == i));
    for p in &pieces {
        let npc = mesh.cell_type.nodes();
        for (i, &c) in p.local_cells.iter().enumerate() {
            for (k, &l) in p.cell_nodes[i * npc..(i + 1) * npc].iter().enumerate() {
                assert_eq!(p.local_natural[l as usize], mesh.cell(c)[k]);
            }
            assert_eq!(p.mesh.cell_body[i], mesh.cell_body[c]);
        }
        for (l, &nat) in p.local_natural.iter().enumerate() {
            assert_eq!(p.mesh.nodes[l], mesh.nodes[nat]);
        }
    }
}

/// Every facet of every set lands on exactly one rank, with the local nodes
/// of the global facet; the output blocks put the whole mesh back together.
#[test]
fn facet_sets_and_output_blocks_tile_the_mesh() {
    let mesh = small_box();
    let part: Vec<i32> = (0..mesh.num_cells()).map(|c| (c % 3) as i32).collect();
    let numbering = Numbering::new(&mesh, &part, 3);
    let pieces: Vec<_> = (0..3)
        .map(|r| numbering.piece(&mesh, &part, r, &Wanted::default()))
        .collect();
    for (name, facets) in &mesh.facet_sets {
        let mut seen = vec![0; facets.len()];
        for p in &pieces {
            let set = &p.mesh.facet_sets[name];
            assert_eq!(set.global_len, facets.len());
            for f in &set.facets {
                seen[f.set_index] += 1;
                let global = mesh.facet_nodes(&facets[f.set_index]).unwrap();
                let local: Vec<usize> = f.nodes[..global.len()]
                    .iter()
                    .map(|&l| p.local_natural[l as usize])
                    .collect();
                assert_eq!(local, global, "{name}");
            }
        }
        assert!(seen.iter().all(|&s| s == 1), "{name}: {seen:?}");
    }
    let nodes: Vec<[f64; 3]> = pieces
        .iter()
        .flat_map(|p| p.mesh.block.nodes.clone())
        .collect();
    let cells: Vec<usize> = pieces
        .iter()
        .flat_map(|p| p.mesh.block.cells.clone())
        .collect();
    assert_eq!(nodes, mesh.nodes);
    assert_eq!(cells, mesh.cells);
}

/// A METIS partition over 4 ranks gives every rank a local mesh of about a
/// quarter of the nodes plus one ghost layer: far below the whole mesh.
#[test]
fn a_local_mesh_is_a_fraction_of_the_whole() {
    let mesh = graded_box(&BoxSpec {
        divisions: [16, 16, 16],
        ..BoxSpec::default()
    })
    .unwrap();
    let n = mesh.num_nodes();
    let part = crate::partition::partition_cells(&mesh, 4, &[]).unwrap();
    let numbering = Numbering::new(&mesh, &part, 4);
    for r in 0..4 {
        let p = numbering.piece(&mesh, &part, r, &Wanted::default());
        let local = p.mesh.num_nodes();
        assert!(
            local * 2 < n,
            "rank {r} holds {local} of {n} nodes: more than half the mesh"
        );
        assert!(
            p.n_owned * 3 < n,
            "rank {r} owns {} of {n} nodes",
            p.n_owned
        );
        assert!(p.mesh.block.nodes.len() <= n / 4 + 1);
    }
}

/// Boundary nodes go to whichever of their ranks owns fewer: every node's
/// owner holds a cell with it, and the owned counts of a METIS partition
/// of a 16³ box on 4 ranks spread far less than with the lowest rank
/// always (which piles every boundary node on the lower ranks).
#[test]
fn boundary_nodes_spread_the_owned_counts() {
    let mesh = graded_box(&BoxSpec {
        divisions: [16; 3],
        ..BoxSpec::default()
    })
    .unwrap();
    let ranks = 4;
    let part = crate::partition::partition_cells(&mesh, ranks, &[]).unwrap();
    let numbering = Numbering::new(&mesh, &part, ranks);
    let pieces: Vec<_> = (0..ranks)
        .map(|r| numbering.piece(&mesh, &part, r, &Wanted::default()))
        .collect();
    let spread = |counts: &[usize]| counts.iter().max().unwrap() - counts.iter().min().unwrap();
    let owned: Vec<usize> = pieces.iter().map(|p| p.n_owned).collect();
    let mut lowest = vec![usize::MAX; mesh.num_nodes()];
    for (c, &p) in part.iter().enumerate() {
        for &v in mesh.cell(c) {
            lowest[v] = lowest[v].min(p as usize);
        }
    }
    let mut lowest_owned = vec![0; ranks];
    lowest.iter().for_each(|&r| lowest_owned[r] += 1);
    assert!(
        spread(&owned) * 4 < spread(&lowest_owned),
        "{owned:?} against {lowest_owned:?}"
    );
    assert!(spread(&owned) * 50 < mesh.num_nodes() / ranks, "{owned:?}");
    for p in &pieces {
        let local: std::collections::BTreeSet<usize> = p
            .local_cells
            .iter()
            .flat_map(|&c| mesh.cell(c).iter().copied())
            .collect();
        assert!(p.local_natural[..p.n_owned]
            .iter()
            .all(|v| local.contains(v)));
    }
}

use super::{wire, Numbering};
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
    for r in 0..3 {
        let piece = numbering.piece(&mesh, &part, r, &[0, 1], &sets);
        assert_eq!(wire::decode(&wire::encode(&piece)).unwrap(), piece);
        assert_eq!(piece.facet_owners.len(), 2);
    }
}

#[test]
fn pieces_tile_the_nodes_and_cells() {
    let mesh = small_box();
    let part: Vec<i32> = (0..mesh.num_cells()).map(|c| (c % 4) as i32).collect();
    let numbering = Numbering::new(&mesh, &part, 4);
    let pieces: Vec<_> = (0..4)
        .map(|r| numbering.piece(&mesh, &part, r, &[], &[]))
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
        }
    }
}

//! Hex to tet splitting.

use super::{assert_conforming_and_covered, assert_sets_outward, rel_err, unit_hex};
use crate::mesh::tets::{reference_tet_det, split_hex_for_tests};
use crate::mesh::{graded_box, BoxSpec, CellType, Grading, Mesh, MeshError};

const UNIT_CORNERS: [[f64; 3]; 8] = [
    [0.0, 0.0, 0.0],
    [1.0, 0.0, 0.0],
    [1.0, 1.0, 0.0],
    [0.0, 1.0, 0.0],
    [0.0, 0.0, 1.0],
    [1.0, 0.0, 1.0],
    [1.0, 1.0, 1.0],
    [0.0, 1.0, 1.0],
];

/// All permutations of 0..n (Heap's algorithm).
fn permutations(n: usize) -> Vec<Vec<usize>> {
    fn heap(k: usize, a: &mut Vec<usize>, out: &mut Vec<Vec<usize>>) {
        if k == 1 {
            out.push(a.clone());
            return;
        }
        heap(k - 1, a, out);
        for i in 0..k - 1 {
            if k.is_multiple_of(2) {
                a.swap(i, k - 1);
            } else {
                a.swap(0, k - 1);
            }
            heap(k - 1, a, out);
        }
    }
    let mut out = Vec::new();
    heap(n, &mut (0..n).collect(), &mut out);
    out
}

#[test]
fn every_id_ordering_splits_into_positive_tets_filling_the_cube() {
    let perms = permutations(8);
    assert_eq!(perms.len(), 40320);
    let (mut fives, mut sixes) = (0, 0);
    for ids in perms {
        // `ids[k]` is the global id of local corner k; global id g sits at
        // the corner whose local index has that id.
        let tets = split_hex_for_tests(&ids);
        let local = |g: usize| ids.iter().position(|&x| x == g).unwrap();
        let mut volume = 0.0;
        for tet in &tets {
            let det = reference_tet_det(tet.map(local), &UNIT_CORNERS);
            assert!(det > 0.5, "ids {ids:?}: tet {tet:?} has det {det}");
            volume += det / 6.0;
        }
        assert!((volume - 1.0).abs() < 1e-12, "ids {ids:?}: volume {volume}");
        match tets.len() {
            5 => fives += 1,
            6 => sixes += 1,
            n => panic!("{n} tets"),
        }
        assert_face_diagonals_follow_lowest_id(&ids, &tets);
    }
    // Both cases occur, so both code paths are exercised.
    assert!(fives > 0 && sixes > 0, "{fives} five-tet, {sixes} six-tet");
}

/// Each hex face is covered by two triangles whose shared edge is the
/// diagonal through the face's lowest id.
fn assert_face_diagonals_follow_lowest_id(ids: &[usize], tets: &[[usize; 4]]) {
    for face in CellType::Hex8.local_faces() {
        let quad: Vec<usize> = face.iter().map(|&l| ids[l]).collect();
        let triangles: Vec<Vec<usize>> = tets
            .iter()
            .flat_map(|t| {
                CellType::Tet4
                    .local_faces()
                    .iter()
                    .map(move |f| f.iter().map(|&l| t[l]).collect::<Vec<_>>())
            })
            .filter(|tri: &Vec<usize>| tri.iter().all(|n| quad.contains(n)))
            .collect();
        assert_eq!(triangles.len(), 2, "quad {quad:?}");
        let lowest = *quad.iter().min().unwrap();
        assert!(
            triangles.iter().all(|t| t.contains(&lowest)),
            "quad {quad:?}: {triangles:?}"
        );
    }
}

/// Renumbers nodes by a fixed pseudo-random permutation so neighbouring
/// hexes get all sorts of lowest-id corners (the natural numbering always
/// gives the 6-tet case).
fn scrambled(mesh: &Mesh) -> Mesh {
    let n = mesh.num_nodes();
    let mut new_id: Vec<usize> = (0..n).collect();
    // Fisher–Yates driven by a 64-bit LCG (Knuth's MMIX constants).
    let mut state: u64 = 0x2545_F491_4F6C_DD1D;
    for i in (1..n).rev() {
        state = state
            .wrapping_mul(6_364_136_223_846_793_005)
            .wrapping_add(1_442_695_040_888_963_407);
        let j = ((state >> 33) % (i as u64 + 1)) as usize;
        new_id.swap(i, j);
    }
    let mut out = mesh.clone();
    for (old, p) in mesh.nodes.iter().enumerate() {
        out.nodes[new_id[old]] = *p;
    }
    for c in &mut out.cells {
        *c = new_id[*c];
    }
    for set in out.node_sets.values_mut() {
        for node in set.iter_mut() {
            *node = new_id[*node];
        }
        set.sort_unstable();
    }
    out
}

const BOX_SURFACE: [&str; 6] = ["b.xmin", "b.xmax", "b.ymin", "b.ymax", "b.zmin", "b.zmax"];

#[test]
fn split_box_is_conforming_and_preserves_volume_and_areas() {
    let hexes = graded_box(&BoxSpec {
        body: "b".into(),
        origin: [1.0, -2.0, 0.5],
        size: [2.0, 1.5, 1.0],
        divisions: [4, 3, 5],
        grading: [
            Grading::Geometric { ratio: 3.0 },
            Grading::Uniform,
            Grading::Uniform,
        ],
        cell_type: CellType::Hex8,
    })
    .unwrap();
    for hexes in [hexes.clone(), scrambled(&hexes)] {
        hexes.validate().unwrap();
        let tets = hexes.hex_to_tets().unwrap();
        tets.validate().unwrap();
        assert_eq!(tets.cell_type, CellType::Tet4);
        assert!(tets.num_cells() >= 5 * hexes.num_cells());
        assert_conforming_and_covered(&tets, &BOX_SURFACE);
        assert_sets_outward(&tets);
        let volume = |m: &Mesh| m.body_volume(0).unwrap();
        assert!(rel_err(volume(&tets), 3.0) < 1e-12);
        for set in BOX_SURFACE {
            let facets = tets.facet_set(set).unwrap().len();
            assert_eq!(facets, 2 * hexes.facet_set(set).unwrap().len(), "{set}");
            let (a, b) = (
                tets.facet_set_area(set).unwrap(),
                hexes.facet_set_area(set).unwrap(),
            );
            assert!(rel_err(a, b) < 1e-12, "{set}: {a} vs {b}");
            assert_eq!(
                tets.facet_set_nodes(set).unwrap(),
                hexes.facet_set_nodes(set).unwrap()
            );
        }
        assert_eq!(tets.node_sets, hexes.node_sets);
    }
}

#[test]
fn scrambled_numbering_exercises_five_tet_splits() {
    let hexes = scrambled(&graded_box(&BoxSpec::default()).unwrap());
    let tets = hexes.hex_to_tets().unwrap();
    assert!(
        tets.num_cells() < 6 * hexes.num_cells(),
        "no 5-tet split happened"
    );
}

#[test]
fn splitting_tets_is_an_error() {
    let tets = unit_hex().hex_to_tets().unwrap();
    let err = tets.hex_to_tets().unwrap_err();
    assert!(matches!(
        err,
        MeshError::CellTypeMismatch {
            expected: "hex8",
            found: "tet4",
            ..
        }
    ));
}

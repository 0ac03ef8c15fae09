//! Mesh accessors, geometry, validation, dual graph, merge and transforms.

use super::{rel_err, unit_hex};
use crate::mesh::{graded_box, BoxSpec, CellType, FacetRef, Mesh, MeshError};

fn small_box(body: &str, divisions: [usize; 3]) -> Mesh {
    graded_box(&BoxSpec {
        body: body.into(),
        size: [3.0, 2.0, 1.0],
        divisions,
        ..BoxSpec::default()
    })
    .unwrap()
}

#[test]
fn unit_hex_geometry() {
    let mesh = unit_hex();
    assert_eq!(mesh.num_nodes(), 8);
    assert_eq!(mesh.num_cells(), 1);
    assert!(rel_err(mesh.cell_volume(0).unwrap(), 1.0) < 1e-14);
    // Corner Jacobian of the map from [−1, 1]³ onto a unit cube is 1/8.
    assert!(rel_err(mesh.min_jacobian(0).unwrap(), 0.125) < 1e-14);
    assert!(rel_err(mesh.scaled_jacobian(0).unwrap(), 1.0) < 1e-14);
    assert_eq!(mesh.cell_centroid(0).unwrap(), [0.5, 0.5, 0.5]);
    let top = FacetRef { cell: 0, face: 5 };
    assert_eq!(mesh.facet_nodes(&top).unwrap(), vec![4, 5, 6, 7]);
    assert_eq!(mesh.facet_nodes_iter(&top).unwrap().len(), 4);
    assert_eq!(mesh.facet_normal(&top).unwrap(), [0.0, 0.0, 1.0]);
    let bb = mesh.bounding_box().unwrap();
    assert_eq!((bb.min, bb.max), ([0.0; 3], [1.0; 3]));
    assert!(mesh.validate().is_ok());
}

#[test]
fn distorted_hex_volume_is_exact() {
    // Raising corner 6 by d makes the top the bilinear surface
    // z = 1 + d x y, so the volume is ∫∫ (1 + d x y) = 1 + d / 4 exactly;
    // the top is not planar, so this checks the quadrature is exact.
    let mut mesh = unit_hex();
    mesh.nodes[6][2] += 0.4;
    assert!(rel_err(mesh.cell_volume(0).unwrap(), 1.1) < 1e-14);
}

#[test]
fn regular_tet_scaled_jacobian_is_one() {
    let mut mesh = Mesh::empty(CellType::Tet4);
    mesh.nodes = vec![
        [1.0, 1.0, 1.0],
        [1.0, -1.0, -1.0],
        [-1.0, 1.0, -1.0],
        [-1.0, -1.0, 1.0],
    ];
    mesh.cells = vec![0, 1, 2, 3];
    mesh.cell_body = vec![0];
    mesh.bodies = vec!["t".into()];
    let sj = mesh.scaled_jacobian(0).unwrap();
    // This vertex order is negatively oriented; the magnitude must be 1.
    assert!(rel_err(sj.abs(), 1.0) < 1e-12, "{sj}");
    assert!(matches!(
        mesh.validate(),
        Err(MeshError::InvertedCell { cell: 0, .. })
    ));
    mesh.cells = vec![0, 2, 1, 3];
    assert!(rel_err(mesh.scaled_jacobian(0).unwrap(), 1.0) < 1e-12);
    assert!(rel_err(mesh.cell_volume(0).unwrap(), 8.0 / 3.0) < 1e-12);
    mesh.validate().unwrap();
}

#[test]
fn node_out_of_range_is_named() {
    let mut mesh = small_box("b", [2, 1, 1]);
    mesh.cells[8 + 3] = 99;
    let err = mesh.validate().unwrap_err();
    assert!(
        matches!(
            err,
            MeshError::NodeOutOfRange {
                cell: 1,
                node: 99,
                ..
            }
        ),
        "{err:?}"
    );
    let msg = err.to_string();
    assert!(msg.contains("cell 1") && msg.contains("node 99"), "{msg}");
    // Geometry queries report instead of panicking.
    assert!(mesh.cell_volume(1).is_err());
    assert!(mesh.dual_graph(1).is_err());
}

#[test]
fn inverted_cell_is_named() {
    let mut mesh = small_box("b", [2, 1, 1]);
    // Swap bottom and top layers of cell 1: a mirror image.
    let c: Vec<usize> = mesh.cell(1).to_vec();
    mesh.cells[8..16].copy_from_slice(&[c[4], c[5], c[6], c[7], c[0], c[1], c[2], c[3]]);
    let err = mesh.validate().unwrap_err();
    match &err {
        MeshError::InvertedCell { cell, det } => {
            assert_eq!(*cell, 1);
            assert!(*det < 0.0);
        }
        other => panic!("unexpected {other:?}"),
    }
    assert!(err.to_string().contains("cell 1"));
}

#[test]
fn one_folded_corner_is_caught() {
    // A hex whose volume is still positive but whose corner 6 is pushed
    // through the opposite face: only the corner test sees it.
    let mut mesh = unit_hex();
    mesh.nodes[6] = [0.3, 0.3, 0.3];
    assert!(mesh.cell_volume(0).unwrap() > 0.0);
    assert!(matches!(
        mesh.validate(),
        Err(MeshError::InvertedCell { cell: 0, .. })
    ));
}

#[test]
fn non_finite_coordinate_is_named() {
    let mut mesh = unit_hex();
    mesh.nodes[5][1] = f64::NAN;
    let err = mesh.validate().unwrap_err();
    assert!(matches!(
        err,
        MeshError::NonFiniteCoordinate { node: 5, .. }
    ));
    assert!(err.to_string().contains("node 5"));
}

#[test]
fn structural_errors_are_named() {
    let mut mesh = unit_hex();
    mesh.cells.push(3);
    assert!(matches!(
        mesh.validate(),
        Err(MeshError::ConnectivityLength { len: 9, .. })
    ));

    let mut mesh = unit_hex();
    mesh.cell_body = vec![4];
    let err = mesh.validate().unwrap_err();
    assert!(
        matches!(
            err,
            MeshError::BodyOutOfRange {
                cell: 0,
                body: 4,
                ..
            }
        ),
        "{err:?}"
    );

    let mut mesh = unit_hex();
    mesh.cell_body.clear();
    assert!(matches!(
        mesh.validate(),
        Err(MeshError::CellBodyLength { .. })
    ));

    let mut mesh = unit_hex();
    mesh.node_sets.insert("s".into(), vec![1, 12]);
    let err = mesh.validate().unwrap_err();
    assert!(
        err.to_string().contains("`s`") && err.to_string().contains("node 12"),
        "{err}"
    );

    let mut mesh = unit_hex();
    mesh.node_sets.insert("u".into(), vec![3, 1]);
    assert!(matches!(
        mesh.validate(),
        Err(MeshError::NodeSetNotSorted { .. })
    ));

    let mut mesh = unit_hex();
    mesh.facet_sets
        .insert("f".into(), vec![FacetRef { cell: 0, face: 6 }]);
    let err = mesh.validate().unwrap_err();
    assert!(matches!(&err, MeshError::FacetOutOfRange { set, cell: 0, face: 6 } if set == "f"));

    let mut mesh = unit_hex();
    mesh.facet_sets
        .insert("g".into(), vec![FacetRef { cell: 3, face: 0 }]);
    assert!(matches!(
        mesh.validate(),
        Err(MeshError::FacetOutOfRange { cell: 3, .. })
    ));
    assert!(matches!(
        mesh.facet_set_nodes("g"),
        Err(MeshError::FacetOutOfRange { .. })
    ));
    assert!(matches!(
        mesh.facet_set_nodes("nope"),
        Err(MeshError::UnknownSet { .. })
    ));
    assert!(matches!(
        mesh.try_cell(1),
        Err(MeshError::CellOutOfRange { cell: 1, .. })
    ));
    assert!(mesh.facet_nodes(&FacetRef { cell: 0, face: 9 }).is_err());
}

#[test]
fn inconsistent_facet_set_orientation_is_named() {
    let mut mesh = small_box("b", [2, 1, 1]);
    let top = mesh.facet_set("b.top").unwrap().to_vec();
    mesh.validate().unwrap();
    // Face 1 of cell 0 (x = +1 side) is the interior face shared with cell
    // 1's face 0; a set holding both sides is contradictory.
    let both_sides = vec![FacetRef { cell: 0, face: 1 }, FacetRef { cell: 1, face: 0 }];
    mesh.facet_sets.insert("bad".into(), both_sides);
    let err = mesh.validate().unwrap_err();
    assert!(
        matches!(&err, MeshError::DuplicateFacet { set, cell: 1, face: 0 } if set == "bad"),
        "{err:?}"
    );
    assert!(err.to_string().contains("`bad`"));
    // A repeated facet is caught the same way.
    mesh.facet_sets.remove("bad");
    let mut repeated = top.clone();
    repeated.push(top[0]);
    mesh.facet_sets.insert("b.top".into(), repeated);
    assert!(matches!(
        mesh.validate(),
        Err(MeshError::DuplicateFacet { .. })
    ));
    // Cell 1's interior face (x = 1.5, seen from cell 1) and its top are
    // both outward from cell 1: consistent. The same face seen from cell 0
    // points into cell 1, so with cell 1's top the shared edge is
    // traversed the same way by both.
    mesh.facet_sets.insert("b.top".into(), top);
    let consistent = vec![FacetRef { cell: 1, face: 0 }, FacetRef { cell: 1, face: 5 }];
    mesh.facet_sets.insert("corner".into(), consistent);
    mesh.validate().unwrap();
    let flipped = vec![FacetRef { cell: 0, face: 1 }, FacetRef { cell: 1, face: 5 }];
    mesh.facet_sets.insert("twisted".into(), flipped);
    let err = mesh.validate().unwrap_err();
    assert!(
        matches!(&err, MeshError::InconsistentOrientation { set, .. } if set == "twisted"),
        "{err:?}"
    );
}

#[test]
fn facet_set_nodes_and_bodies() {
    let mesh = small_box("b", [3, 2, 1]);
    let nodes = mesh.facet_set_nodes("b.top").unwrap();
    assert_eq!(nodes.len(), 4 * 3);
    assert_eq!(nodes, mesh.node_set("b.top").unwrap());
    assert!(nodes.iter().all(|&n| mesh.nodes[n][2] == 1.0));
    assert_eq!(mesh.body_id("b").unwrap(), 0);
    assert!(matches!(
        mesh.body_id("x"),
        Err(MeshError::UnknownBody { .. })
    ));
    assert_eq!(mesh.body_cells(0).count(), 6);
    assert_eq!(mesh.body_cells(1).count(), 0);
    assert_eq!(mesh.body_nodes(0).len(), mesh.num_nodes());
}

fn assert_symmetric(xadj: &[usize], adjncy: &[usize]) {
    let neighbours = |c: usize| &adjncy[xadj[c]..xadj[c + 1]];
    for c in 0..xadj.len() - 1 {
        for &d in neighbours(c) {
            assert_ne!(c, d);
            assert!(neighbours(d).contains(&c), "{c} -> {d} but not back");
        }
    }
}

#[test]
fn dual_graph_of_structured_box() {
    let (nx, ny, nz) = (3, 4, 5);
    let mesh = small_box("b", [nx, ny, nz]);
    let (xadj, adjncy) = mesh.dual_graph(4).unwrap();
    assert_eq!(xadj.len(), nx * ny * nz + 1);
    assert_symmetric(&xadj, &adjncy);
    let interior_faces = (nx - 1) * ny * nz + nx * (ny - 1) * nz + nx * ny * (nz - 1);
    assert_eq!(adjncy.len(), 2 * interior_faces);
    // Cell (i, j, k) has one neighbour per direction it can step in.
    for k in 0..nz {
        for j in 0..ny {
            for i in 0..nx {
                let c = i + nx * (j + ny * k);
                let steps = |p: usize, n: usize| usize::from(p > 0) + usize::from(p + 1 < n);
                let expected = steps(i, nx) + steps(j, ny) + steps(k, nz);
                assert_eq!(xadj[c + 1] - xadj[c], expected, "cell {c}");
            }
        }
    }
    // The node-counting path agrees with the face-key path.
    assert_eq!(mesh.face_dual_graph(), (xadj.clone(), adjncy.clone()));
    // Sharing one node: interior cells touch all 26 neighbours.
    let (x1, a1) = mesh.dual_graph(1).unwrap();
    assert_symmetric(&x1, &a1);
    let centre = 1 + nx * (1 + ny);
    assert_eq!(x1[centre + 1] - x1[centre], 26);
    // Sharing an edge (2 nodes): 18 neighbours.
    let (x2, _) = mesh.dual_graph(2).unwrap();
    assert_eq!(x2[centre + 1] - x2[centre], 18);
    assert!(matches!(
        mesh.dual_graph(0),
        Err(MeshError::InvalidArgument { .. })
    ));
    assert!(mesh.dual_graph(9).is_err());
}

#[test]
fn tet_dual_graph_matches_all_pairs_reference() {
    let mesh = small_box("b", [2, 2, 2]).hex_to_tets().unwrap();
    let (xadj, adjncy) = mesh.dual_graph(3).unwrap();
    assert_symmetric(&xadj, &adjncy);
    for min_shared in [1, 2, 3] {
        let (x, a) = mesh.dual_graph(min_shared).unwrap();
        for c in 0..mesh.num_cells() {
            let reference: Vec<usize> = (0..mesh.num_cells())
                .filter(|&d| {
                    let shared = mesh
                        .cell(c)
                        .iter()
                        .filter(|n| mesh.cell(d).contains(n))
                        .count();
                    d != c && shared >= min_shared
                })
                .collect();
            assert_eq!(
                &a[x[c]..x[c + 1]],
                reference.as_slice(),
                "cell {c}, min {min_shared}"
            );
        }
    }
}

#[test]
fn merge_renumbers_and_keeps_sets() {
    let a = small_box("a", [2, 1, 1]);
    let b = small_box("b", [1, 1, 3]);
    let (na, ca) = (a.num_nodes(), a.num_cells());
    let b_top_nodes = b.node_set("b.top").unwrap().to_vec();
    let b_top_facets = b.facet_set("b.top").unwrap().to_vec();
    let b_first_cell = b.cell(0).to_vec();
    let merged = a.merge(b).unwrap();
    merged.validate().unwrap();
    assert_eq!(merged.bodies, vec!["a".to_string(), "b".to_string()]);
    assert_eq!(merged.num_cells(), ca + 3);
    assert_eq!(
        merged.body_cells(1).collect::<Vec<_>>(),
        vec![ca, ca + 1, ca + 2]
    );
    let shifted: Vec<usize> = b_first_cell.iter().map(|n| n + na).collect();
    assert_eq!(merged.cell(ca), shifted.as_slice());
    let expected: Vec<usize> = b_top_nodes.iter().map(|n| n + na).collect();
    assert_eq!(merged.node_set("b.top").unwrap(), expected.as_slice());
    assert_eq!(
        merged.facet_set("b.top").unwrap()[0].cell,
        b_top_facets[0].cell + ca
    );
    assert_eq!(merged.facet_set_nodes("b.top").unwrap(), expected);
    assert!(merged.facet_sets.contains_key("a.top"));
}

#[test]
fn merge_rejects_clashes() {
    let a = small_box("a", [1, 1, 1]);
    let err = a.clone().merge(small_box("a", [1, 1, 1])).unwrap_err();
    assert_eq!(err, MeshError::DuplicateBody { name: "a".into() });
    let mut b = small_box("b", [1, 1, 1]);
    let stolen = b.facet_sets.remove("b.top").unwrap();
    b.facet_sets.insert("a.top".into(), stolen);
    let err = a.clone().merge(b).unwrap_err();
    assert_eq!(
        err,
        MeshError::DuplicateSet {
            name: "a.top".into()
        }
    );
    assert!(err.to_string().contains("a.top"));
    let tets = small_box("t", [1, 1, 1]).hex_to_tets().unwrap();
    assert!(matches!(
        a.merge(tets),
        Err(MeshError::CellTypeMismatch { .. })
    ));
}

#[test]
fn transforms_move_nodes() {
    let a = small_box("a", [1, 1, 1]);
    let b = small_box("b", [1, 1, 1]);
    let mut mesh = a.merge(b).unwrap();
    mesh.translate([1.0, 2.0, 3.0]);
    let bb = mesh.bounding_box().unwrap();
    assert_eq!(bb.min, [1.0, 2.0, 3.0]);
    mesh.translate_body("b", [10.0, 0.0, 0.0]).unwrap();
    let bb = mesh.bounding_box().unwrap();
    assert_eq!(bb.max, [14.0, 4.0, 4.0]);
    mesh.transform(|p| [2.0 * p[0], p[1], p[2]]);
    assert_eq!(mesh.bounding_box().unwrap().max[0], 28.0);
    mesh.validate().unwrap();
    // A mirror inverts every cell, and validate says so.
    mesh.transform_body("a", |p| [-p[0], p[1], p[2]]).unwrap();
    assert!(matches!(
        mesh.validate(),
        Err(MeshError::InvertedCell { cell: 0, .. })
    ));
    assert!(mesh.translate_body("zzz", [0.0; 3]).is_err());
}

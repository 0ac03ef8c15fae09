//! The faces S1..S6 of C3D8 and S1..S4 of C3D4 against this program's local
//! faces, surface elements matched to cell faces, and cell orientation.

use std::collections::BTreeSet;

use super::{line_of, parse, parse_err, ONE_TET};
use crate::mesh::inp::InpErrorKind;
use crate::mesh::{FacetRef, Mesh};

/// A unit cube as one C3D8, nodes 11..18 in the Abaqus order: 11-14 the
/// bottom (z = 0) counter-clockwise seen from above, 15-18 the top.
const CUBE_NODES: &str = "\
*NODE
11, 0, 0, 0
12, 1, 0, 0
13, 1, 1, 0
14, 0, 1, 0
15, 0, 0, 1
16, 1, 0, 1
17, 1, 1, 1
18, 0, 1, 1
";

/// Abaqus/CalculiX manual: C3D8 face k and its nodes (1-based local
/// numbers), with the outward normal of the unit cube above.
const HEX_FACES: [([usize; 4], [f64; 3]); 6] = [
    ([1, 2, 3, 4], [0.0, 0.0, -1.0]),
    ([5, 8, 7, 6], [0.0, 0.0, 1.0]),
    ([1, 5, 6, 2], [0.0, -1.0, 0.0]),
    ([2, 6, 7, 3], [1.0, 0.0, 0.0]),
    ([3, 7, 8, 4], [0.0, 1.0, 0.0]),
    ([4, 8, 5, 1], [-1.0, 0.0, 0.0]),
];

/// C3D4 face k (1-based local numbers) and the outward normal of the unit tet.
fn tet_faces() -> [([usize; 3], [f64; 3]); 4] {
    let s = 1.0 / 3f64.sqrt();
    [
        ([1, 2, 3], [0.0, 0.0, -1.0]),
        ([1, 4, 2], [0.0, -1.0, 0.0]),
        ([2, 4, 3], [s, s, s]),
        ([3, 4, 1], [-1.0, 0.0, 0.0]),
    ]
}

/// A deck of one element with a surface `F<k>` on each face.
fn with_surfaces(mesh: &str, faces: usize) -> String {
    let mut deck = mesh.to_string();
    for k in 1..=faces {
        deck.push_str(&format!("*SURFACE, NAME=F{k}, TYPE=ELEMENT\n1, S{k}\n"));
    }
    deck
}

/// Positions of a facet's nodes, as a set of bit patterns.
fn facet_points(mesh: &Mesh, f: &FacetRef) -> BTreeSet<[u64; 3]> {
    mesh.facet_nodes(f)
        .unwrap()
        .iter()
        .map(|&n| mesh.nodes[n].map(f64::to_bits))
        .collect()
}

/// Checks surface `F<k>` against the face's nodes (by position: the file
/// ids are gone) and its outward normal.
fn check_face(mesh: &Mesh, k: usize, points: BTreeSet<[u64; 3]>, normal: [f64; 3]) {
    let set = mesh.facet_set(&format!("F{k}")).unwrap();
    assert_eq!(set.len(), 1, "S{k}");
    assert_eq!(facet_points(mesh, &set[0]), points, "S{k}: nodes");
    let n = mesh.facet_normal(&set[0]).unwrap();
    let d: f64 = (0..3).map(|i| (n[i] - normal[i]).abs()).sum();
    assert!(d < 1e-12, "S{k}: normal {n:?}, expected {normal:?}");
}

fn cube_point(local: usize, conn: &[u64; 8]) -> [u64; 3] {
    let id = conn[local - 1];
    let base = [
        [0.0, 0.0, 0.0],
        [1.0, 0.0, 0.0],
        [1.0, 1.0, 0.0],
        [0.0, 1.0, 0.0],
        [0.0, 0.0, 1.0],
        [1.0, 0.0, 1.0],
        [1.0, 1.0, 1.0],
        [0.0, 1.0, 1.0],
    ];
    base[(id - 11) as usize].map(f64::to_bits)
}

#[test]
fn every_c3d8_face_is_the_local_face_with_its_nodes() {
    let conn = [11, 12, 13, 14, 15, 16, 17, 18];
    let deck = with_surfaces(
        &format!("{CUBE_NODES}*ELEMENT, TYPE=C3D8, ELSET=B\n1, 11, 12, 13, 14, 15, 16, 17, 18\n"),
        6,
    );
    let (mesh, report) = parse(&deck);
    assert_eq!(report.reoriented, 0);
    assert!(
        mesh.min_jacobian(0).unwrap() > 0.0,
        "Abaqus order is positive"
    );
    let mut used = BTreeSet::new();
    for (k, (nodes, normal)) in HEX_FACES.iter().enumerate() {
        let points = nodes.iter().map(|&l| cube_point(l, &conn)).collect();
        check_face(&mesh, k + 1, points, *normal);
        used.insert(mesh.facet_set(&format!("F{}", k + 1)).unwrap()[0].face);
    }
    // Six labels, six different local faces.
    assert_eq!(used.len(), 6);
    // Each face's node set also became a node set.
    assert_eq!(mesh.node_set("F1").unwrap().len(), 4);
}

#[test]
fn faces_follow_the_nodes_of_an_inverted_element() {
    // Top and bottom swapped: a fully inverted cell, renumbered by the
    // reader; S1 is still the face of the element's nodes 1-2-3-4, now the
    // top of the cube, with its normal outward.
    let conn = [15, 16, 17, 18, 11, 12, 13, 14];
    let deck = with_surfaces(
        &format!("{CUBE_NODES}*ELEMENT, TYPE=C3D8, ELSET=B\n1, 15, 16, 17, 18, 11, 12, 13, 14\n"),
        6,
    );
    let (mesh, report) = parse(&deck);
    assert_eq!(report.reoriented, 1);
    assert!(report.note().contains("1 inverted cells renumbered"));
    assert!(mesh.min_jacobian(0).unwrap() > 0.0);
    let flip = |n: &[f64; 3]| [n[0], n[1], -n[2]];
    for (k, (nodes, normal)) in HEX_FACES.iter().enumerate() {
        let points = nodes.iter().map(|&l| cube_point(l, &conn)).collect();
        check_face(&mesh, k + 1, points, flip(normal));
    }
}

#[test]
fn every_c3d4_face_is_the_local_face_with_its_nodes() {
    let (mesh, _) = parse(&with_surfaces(ONE_TET, 4));
    assert!(
        mesh.min_jacobian(0).unwrap() > 0.0,
        "Abaqus order is positive"
    );
    let corner = |local: usize| {
        let mut p = [0.0; 3];
        if local > 1 {
            p[local - 2] = 1.0;
        }
        p.map(f64::to_bits)
    };
    for (k, (nodes, normal)) in tet_faces().iter().enumerate() {
        let points = nodes.iter().map(|&l| corner(l)).collect();
        check_face(&mesh, k + 1, points, *normal);
    }
}

#[test]
fn a_face_beyond_the_element_or_of_a_surface_element_is_an_error() {
    let deck = format!("{ONE_TET}*SURFACE, NAME=TOP\n1, S5\n");
    let err = parse_err(&deck);
    assert_eq!(err.line, Some(line_of(&deck, "1, S5")));
    assert!(
        err.to_string()
            .contains("surface TOP: face `S5` of element 1 (C3D4) is not one of S1..S4"),
        "{err}"
    );
    let deck = format!(
        "{ONE_TET}*ELEMENT, TYPE=CPS3, ELSET=SKIN\n2, 1, 3, 2\n*SURFACE, NAME=TOP\nSKIN, S1\n"
    );
    let err = parse_err(&deck);
    assert!(
        matches!(&err.kind, InpErrorKind::FaceOfNonCell { element: 2, ty, .. } if ty == "CPS3"),
        "{err}"
    );
}

#[test]
fn surface_elements_become_outward_facet_sets_either_way_round() {
    // The bottom face listed in both orders: both are the cell's face, with
    // the cell's outward normal.
    let deck = format!(
        "{ONE_TET}*ELEMENT, TYPE=CPS3, ELSET=BOTTOM\n2, 1, 2, 3\n\
         *ELEMENT, type=S3, ELSET=BACK\n3, 1, 3, 4\n*ELSET, ELSET=BOTTOM\n2\n"
    );
    let (mesh, _) = parse(&deck);
    let bottom = mesh.facet_set("BOTTOM").unwrap();
    assert_eq!(bottom.len(), 1);
    assert_eq!(mesh.facet_normal(&bottom[0]).unwrap(), [0.0, 0.0, -1.0]);
    let back = mesh.facet_set("BACK").unwrap();
    assert_eq!(mesh.facet_normal(&back[0]).unwrap(), [-1.0, 0.0, 0.0]);
    assert_eq!(mesh.node_set("BACK").unwrap().len(), 3);
    // Surface elements are not cells, and no body.
    assert_eq!(mesh.num_cells(), 1);
    assert_eq!(mesh.bodies, ["TET"]);
}

#[test]
fn surface_elements_off_the_cells_are_errors_naming_type_and_line() {
    // A triangle across the tet (nodes 2, 3 and a new node 5).
    let deck = ONE_TET.replace("4, 0, 0, 1\n", "4, 0, 0, 1\n5, 1, 1, 1\n")
        + "*ELEMENT, TYPE=S3, ELSET=SHELL\n9, 2, 3, 5\n";
    let err = parse_err(&deck);
    assert_eq!(err.line, Some(line_of(&deck, "9, 2, 3, 5")));
    assert_eq!(
        err.kind.to_string(),
        "S3 element 9 of element set SHELL is no boundary face of a 3D element (matched by its nodes): shells and membranes are not supported"
    );
    // A quadrilateral on a tet mesh: no face has its four corners.
    let deck = format!("{ONE_TET}*ELEMENT, TYPE=CPS4, ELSET=Q\n9, 1, 2, 3, 4\n");
    let err = parse_err(&deck);
    assert!(
        err.to_string()
            .contains("CPS4 element 9 of element set Q is no boundary face of a 3D element"),
        "{err}"
    );
}

#[test]
fn tangled_cells_are_errors_naming_element_and_line() {
    // Two nodes swapped across a diagonal: corners of both signs.
    let deck =
        format!("{CUBE_NODES}*ELEMENT, TYPE=C3D8, ELSET=B\n33, 11, 12, 14, 13, 15, 16, 17, 18\n");
    let err = parse_err(&deck);
    assert_eq!(err.line, Some(line_of(&deck, "33, ")));
    assert!(
        matches!(err.kind, InpErrorKind::TangledCell { element: 33, .. }),
        "{err}"
    );
    let start = format!(
        "t.inp, line {}: cell from element 33 is tangled",
        line_of(&deck, "33, ")
    );
    assert!(err.to_string().starts_with(&start), "{err}");
}

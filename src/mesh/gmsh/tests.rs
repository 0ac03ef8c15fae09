//! Tests of the Gmsh reader on small in-memory files.

use super::assemble::{orient_cells, Ctx};
use super::kind::Kind;
use super::sections::ElementList;
use super::*;
use crate::mesh::{CellType, FacetRef};

/// One unit tet (nodes 10, 20, 30, 40: sparse tags) with its bottom
/// face as a physical surface and its apex as a physical point.
const TET: &str = "$MeshFormat
4.1 0 8
$EndMeshFormat
$PhysicalNames
3
0 3 \"apex\"
2 2 \"solid.bottom\"
3 1 \"solid\"
$EndPhysicalNames
$Entities
1 0 1 1
7 0 0 1 1 3
4 0 0 0 1 1 0 1 2 0
9 0 0 0 1 1 1 1 1 1 4
$EndEntities
$Nodes
2 4 10 40
0 7 0 1
40
0 0 1
2 4 1 3
10
20
30
0 0 0 0 0
1 0 0 1 0
0 1 0 0 1
$EndNodes
$Elements
3 3 1 3
0 7 15 1
1 40
2 4 2 1
2 10 30 20
3 9 4 1
3 10 20 30 40
$EndElements
";

fn parse(text: &str) -> Result<(Mesh, GmshReport), GmshError> {
    parse_gmsh(text.as_bytes(), "test.msh")
}

#[test]
fn reads_a_tet_with_groups() {
    let (mesh, report) = parse(TET).unwrap();
    assert_eq!(mesh.cell_type, CellType::Tet4);
    assert_eq!(mesh.bodies, vec!["solid".to_string()]);
    assert_eq!(mesh.cells, vec![1, 2, 3, 0]);
    assert_eq!(mesh.nodes[0], [0.0, 0.0, 1.0]);
    assert_eq!(mesh.node_set("apex").unwrap(), &[0]);
    assert_eq!(mesh.node_set("solid.bottom").unwrap(), &[1, 2, 3]);
    // The bottom is the face opposite local node 3.
    let bottom = mesh.facet_set("solid.bottom").unwrap();
    assert_eq!(bottom, &[FacetRef { cell: 0, face: 0 }]);
    assert_eq!(report.reoriented, 0);
    assert_eq!(report.unused_nodes, 0);
}

#[test]
fn inverted_tet_is_reversed_and_counted() {
    let text = TET.replace("3 10 20 30 40", "3 10 30 20 40");
    let (mesh, report) = parse(&text).unwrap();
    assert_eq!(report.reoriented, 1);
    assert_eq!(mesh.cells, vec![1, 2, 3, 0]);
}

#[test]
fn flat_tet_is_tangled() {
    let text = TET.replace("0 0 1\n2 4", "0.5 0.5 0\n2 4");
    let err = parse(&text).unwrap_err();
    assert!(matches!(
        err.kind,
        GmshErrorKind::TangledCell { element: 3, .. }
    ));
    assert_eq!(err.location, Location::Line(36));
}

#[test]
fn unknown_sections_are_skipped() {
    let text = TET.replace(
        "$Nodes",
        "$Periodic\n1\n$EndPeriodic\n$NodeData\nx y z\n$EndNodeData\n$Nodes",
    );
    let (_, report) = parse(&text).unwrap();
    assert_eq!(report.skipped_sections, vec!["Periodic", "NodeData"]);
}

#[test]
fn truncation_names_the_section_and_line() {
    let cut = TET.find("$EndNodes").unwrap();
    let err = parse(&TET[..cut]).unwrap_err();
    assert_eq!(err.location, Location::Line(28));
    let msg = err.to_string();
    assert!(msg.starts_with("test.msh, line 28: "), "{msg}");
    assert!(msg.contains("no $EndNodes"), "{msg}");
}

/// Corrupts a valid file in many ways; the reader must return, never
/// panic.
#[test]
fn never_panics_on_corrupt_input() {
    let inputs = [TET.as_bytes().to_vec(), binary_tet()];
    for bytes in inputs {
        for cut in (0..bytes.len()).step_by(7) {
            assert_no_panic(&bytes[..cut]);
            for flip in [0x01u8, 0x10, 0x80, 0xff] {
                let mut corrupt = bytes.clone();
                corrupt[cut] ^= flip;
                assert_no_panic(&corrupt);
            }
        }
    }
}

fn assert_no_panic(bytes: &[u8]) {
    let result = std::panic::catch_unwind(|| parse_gmsh(bytes, "fuzz.msh").map(|_| ()));
    assert!(
        result.is_ok(),
        "panicked on input {:?}",
        String::from_utf8_lossy(bytes)
    );
}

/// The ASCII tet written as a binary file, by re-encoding its values.
fn binary_tet() -> Vec<u8> {
    let mut b = Vec::new();
    b.extend_from_slice(b"$MeshFormat\n4.1 1 8\n");
    b.extend_from_slice(&1i32.to_le_bytes());
    b.extend_from_slice(b"\n$EndMeshFormat\n$Nodes\n");
    for v in [1u64, 4, 10, 40] {
        b.extend_from_slice(&v.to_le_bytes());
    }
    for v in [3i32, 9, 0] {
        b.extend_from_slice(&v.to_le_bytes());
    }
    b.extend_from_slice(&4u64.to_le_bytes());
    for v in [10u64, 20, 30, 40] {
        b.extend_from_slice(&v.to_le_bytes());
    }
    for x in [0.0f64, 0., 0., 1., 0., 0., 0., 1., 0., 0., 0., 1.] {
        b.extend_from_slice(&x.to_le_bytes());
    }
    b.extend_from_slice(b"\n$EndNodes\n$Elements\n");
    for v in [1u64, 1, 1, 1] {
        b.extend_from_slice(&v.to_le_bytes());
    }
    for v in [3i32, 9, 4] {
        b.extend_from_slice(&v.to_le_bytes());
    }
    for v in [1u64, 1, 10, 20, 30, 40] {
        b.extend_from_slice(&v.to_le_bytes());
    }
    b.extend_from_slice(b"\n$EndElements\n");
    b
}

#[test]
fn binary_tet_reads() {
    let (mesh, _) = parse_gmsh(&binary_tet(), "b.msh").unwrap();
    assert_eq!(mesh.bodies, vec!["volume9".to_string()]);
    assert_eq!(mesh.cells, vec![0, 1, 2, 3]);
}

#[test]
fn big_endian_marker_is_rejected() {
    let mut b = binary_tet();
    let at = b"$MeshFormat\n4.1 1 8\n".len();
    b[at..at + 4].copy_from_slice(&1i32.to_be_bytes());
    let err = parse_gmsh(&b, "b.msh").unwrap_err();
    assert_eq!(err.kind, GmshErrorKind::Endianness { value: 1 << 24 });
    assert_eq!(err.location, Location::Byte(at));
}

#[test]
fn inverted_hex_is_reversed() {
    let mut mesh = Mesh::empty(CellType::Hex8);
    mesh.nodes = vec![
        [0., 0., 0.],
        [1., 0., 0.],
        [1., 1., 0.],
        [0., 1., 0.],
        [0., 0., 1.],
        [1., 0., 1.],
        [1., 1., 1.],
        [0., 1., 1.],
    ];
    mesh.cells = vec![4, 5, 6, 7, 0, 1, 2, 3];
    mesh.cell_body = vec![0];
    let list = ElementList {
        tags: vec![5],
        entities: vec![1],
        locations: vec![Location::Line(1)],
        nodes: Vec::new(),
    };
    let ctx = Ctx { path: "x" };
    assert_eq!(orient_cells(&mut mesh, &list, &ctx).unwrap(), 1);
    assert_eq!(mesh.cells, (0..8).collect::<Vec<_>>());
}

#[test]
fn kinds_are_consistent() {
    for k in Kind::ALL {
        assert_eq!(Kind::ALL[k.index()], k);
    }
    for c in CellType::ALL {
        assert!(Kind::ALL.contains(&Kind::Cell(c)), "{}", c.name());
        assert_eq!(Kind::Cell(c).nodes(), c.nodes());
    }
    for f in crate::mesh::FacetType::ALL {
        assert!(Kind::ALL.contains(&Kind::Facet(f)), "{}", f.name());
    }
    assert_eq!(Kind::from_gmsh(18), Some(Kind::Cell(CellType::Wedge15)));
    assert_eq!(Kind::from_gmsh(13), None);
}

/// One pyramid (Gmsh type 7): base counter-clockwise seen from the apex,
/// our order; given the other way round it is reversed and counted.
const PYRAMID: &str = "$MeshFormat
4.1 0 8
$EndMeshFormat
$Nodes
1 5 1 5
3 1 0 5
1
2
3
4
5
0 0 0
1 0 0
1 1 0
0 1 0
0.5 0.5 1
$EndNodes
$Elements
1 1 1 1
3 1 7 1
1 1 2 3 4 5
$EndElements
";

#[test]
fn reads_a_pyramid_and_reverses_a_mirrored_one() {
    let (mesh, report) = parse(PYRAMID).unwrap();
    assert_eq!(mesh.cell_type, CellType::Pyramid5);
    assert_eq!(mesh.cells, vec![0, 1, 2, 3, 4]);
    assert_eq!(report.reoriented, 0);
    assert!((mesh.cell_volume(0).unwrap() - 1.0 / 3.0).abs() < 1e-15);
    let text = PYRAMID.replace("1 1 2 3 4 5\n", "1 1 4 3 2 5\n");
    let (flipped, report) = parse(&text).unwrap();
    assert_eq!(report.reoriented, 1);
    assert!((flipped.cell_volume(0).unwrap() - 1.0 / 3.0).abs() < 1e-15);
}

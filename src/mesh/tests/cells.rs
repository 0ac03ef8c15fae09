//! Reference-cell conventions.

use crate::mesh::geometry::{centroid, polygon_vector_area};
use crate::mesh::{CellType, FacetType};
use crate::vec3::{dot, sub, Vec3};

fn reference_nodes(cell: CellType) -> Vec<Vec3> {
    match cell {
        CellType::Hex8 => vec![
            [-1.0, -1.0, -1.0],
            [1.0, -1.0, -1.0],
            [1.0, 1.0, -1.0],
            [-1.0, 1.0, -1.0],
            [-1.0, -1.0, 1.0],
            [1.0, -1.0, 1.0],
            [1.0, 1.0, 1.0],
            [-1.0, 1.0, 1.0],
        ],
        CellType::Tet4 => vec![
            [0.0, 0.0, 0.0],
            [1.0, 0.0, 0.0],
            [0.0, 1.0, 0.0],
            [0.0, 0.0, 1.0],
        ],
        other => crate::fem::shape::cell_reference_nodes(other),
    }
}

#[test]
fn counts_and_names() {
    assert_eq!(CellType::Hex8.nodes(), 8);
    assert_eq!(CellType::Tet4.nodes(), 4);
    assert_eq!(CellType::Hex8.single_facet_type(), Some(FacetType::Quad4));
    assert_eq!(CellType::Tet4.single_facet_type(), Some(FacetType::Tri3));
    assert_eq!(CellType::Hex8.name(), "hex8");
    assert_eq!(CellType::Tet4.name(), "tet4");
    assert_eq!(FacetType::Quad4.name(), "quad4");
    assert_eq!(FacetType::Tri3.name(), "tri3");
    assert_eq!(FacetType::Quad4.nodes(), 4);
    assert_eq!(FacetType::Tri3.nodes(), 3);
}

#[test]
fn every_face_has_outward_normal_and_right_size() {
    for cell in [CellType::Hex8, CellType::Tet4] {
        let p = reference_nodes(cell);
        let c = centroid(&p);
        let faces = cell.local_faces();
        assert_eq!(faces.len(), if cell == CellType::Hex8 { 6 } else { 4 });
        for face in faces {
            assert_eq!(
                Some(face.len()),
                cell.single_facet_type().map(|f| f.nodes())
            );
            let pts: Vec<Vec3> = face.iter().map(|&l| p[l]).collect();
            let n = polygon_vector_area(&pts);
            assert!(
                dot(n, sub(centroid(&pts), c)) > 0.0,
                "{cell:?} face {face:?}"
            );
        }
    }
}

#[test]
fn hex_faces_follow_documented_numbering() {
    // Face k is the side whose reference coordinate (k / 2) equals ±1.
    let p = reference_nodes(CellType::Hex8);
    for (k, face) in CellType::Hex8.local_faces().iter().enumerate() {
        let axis = k / 2;
        let value = if k % 2 == 0 { -1.0 } else { 1.0 };
        assert!(face.iter().all(|&l| p[l][axis] == value), "face {k}");
    }
}

#[test]
fn tet_face_k_is_opposite_node_3_minus_k() {
    for (k, face) in CellType::Tet4.local_faces().iter().enumerate() {
        assert!(!face.contains(&(3 - k)), "face {k} contains node {}", 3 - k);
    }
}

//! Tests of the mesh module, with shared checking helpers.

mod basics;
mod cells;
mod generators;
mod hertz;
mod orders;
mod tets;

use std::collections::{BTreeSet, HashMap};

use super::topology::face_key;
use super::{FacetRef, Mesh};
use crate::vec3::{dot, sub};

/// Single unit cube hex at the origin, body `b`, with a facet set per face.
pub(crate) fn unit_hex() -> Mesh {
    let mut mesh = Mesh::empty(super::CellType::Hex8);
    mesh.nodes = vec![
        [0.0, 0.0, 0.0],
        [1.0, 0.0, 0.0],
        [1.0, 1.0, 0.0],
        [0.0, 1.0, 0.0],
        [0.0, 0.0, 1.0],
        [1.0, 0.0, 1.0],
        [1.0, 1.0, 1.0],
        [0.0, 1.0, 1.0],
    ];
    mesh.cells = (0..8).collect();
    mesh.cell_body = vec![0];
    mesh.bodies = vec!["b".into()];
    mesh
}

/// Every facet of every set points away from its cell's centroid.
pub(crate) fn assert_sets_outward(mesh: &Mesh) {
    for (name, facets) in &mesh.facet_sets {
        for f in facets {
            let normal = mesh.facet_normal(f).unwrap();
            let out = sub(
                mesh.facet_centroid(f).unwrap(),
                mesh.cell_centroid(f.cell).unwrap(),
            );
            assert!(
                dot(normal, out) > 0.0,
                "set {name}: facet {f:?} points inward"
            );
        }
    }
}

/// No face is shared by more than two cells, and the faces owned by one
/// cell are exactly the union of the listed facet sets (so the mesh is
/// conforming inside and its surface is fully covered by named sets).
pub(crate) fn assert_conforming_and_covered(mesh: &Mesh, surface_sets: &[&str]) {
    let mut count: HashMap<[usize; 4], usize> = HashMap::new();
    for ids in mesh.cells_iter() {
        for (f, local) in mesh.cell_type.local_faces().iter().enumerate() {
            let corners = &local[..mesh.cell_type.face_type(f).corners()];
            *count
                .entry(face_key(corners.iter().map(|&l| ids[l])))
                .or_default() += 1;
        }
    }
    assert!(
        count.values().all(|&c| c <= 2),
        "a face is shared by more than two cells"
    );
    let boundary: BTreeSet<FacetRef> = mesh.boundary_facets().into_iter().collect();
    let mut named = BTreeSet::new();
    for name in surface_sets {
        for f in mesh.facet_set(name).unwrap() {
            assert!(
                named.insert(*f),
                "facet {f:?} is in two surface sets ({name})"
            );
        }
    }
    assert_eq!(
        boundary, named,
        "boundary facets differ from the named surface sets"
    );
}

/// Sum of the cell volumes of the named body.
pub(crate) fn body_volume(mesh: &Mesh, body: &str) -> f64 {
    mesh.body_volume(mesh.body_id(body).unwrap()).unwrap()
}

/// Every facet of the set has this outward unit normal.
pub(crate) fn assert_set_normal(mesh: &Mesh, set: &str, expected: [f64; 3]) {
    let facets = mesh.facet_set(set).unwrap();
    assert!(!facets.is_empty(), "set {set} is empty");
    for f in facets {
        let n = mesh.facet_normal(f).unwrap();
        assert!(
            dot(n, expected) > 1.0 - 1e-12,
            "set {set}: normal {n:?} of {f:?}"
        );
    }
}

pub(crate) fn rel_err(a: f64, b: f64) -> f64 {
    (a - b).abs() / b.abs()
}

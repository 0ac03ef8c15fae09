//! Meshes of every cell type: the generators' splits and second-order
//! nodes, topology, validation of bad cells.

use super::{assert_conforming_and_covered, assert_sets_outward, body_volume, rel_err};
use crate::mesh::{
    graded_box, hertz_cylinder, stacked_blocks, BoxSpec, CellType, FacetType, Grading,
    HertzCylinderSpec, MeshError, StackedSpec,
};

fn unit_box(cell_type: CellType, n: [usize; 3]) -> crate::mesh::Mesh {
    graded_box(&BoxSpec {
        divisions: n,
        size: [1.0, 2.0, 1.5],
        grading: [
            Grading::Geometric { ratio: 2.0 },
            Grading::Uniform,
            Grading::Uniform,
        ],
        cell_type,
        ..BoxSpec::default()
    })
    .unwrap()
}

/// Counts of a structured box of n = (a, b, c) hexes: corners, edges,
/// faces, cells of the hex mesh.
fn counts([a, b, c]: [usize; 3]) -> (usize, usize, usize, usize) {
    let corners = (a + 1) * (b + 1) * (c + 1);
    let edges = a * (b + 1) * (c + 1) + (a + 1) * b * (c + 1) + (a + 1) * (b + 1) * c;
    let faces = a * b * (c + 1) + a * (b + 1) * c + (a + 1) * b * c;
    (corners, edges, faces, a * b * c)
}

#[test]
fn every_type_fills_the_box_with_the_expected_cells_and_nodes() {
    let n = [3, 2, 2];
    let (corners, edges, faces, hexes) = counts(n);
    // Wedges add the zeta faces' diagonals as edges.
    let zeta_faces = n[0] * n[1] * (n[2] + 1);
    for cell_type in CellType::ALL {
        let mesh = unit_box(cell_type, n);
        mesh.validate().unwrap();
        assert!(
            rel_err(body_volume(&mesh, "block"), 3.0) < 1e-12,
            "{}",
            cell_type.name()
        );
        let (cells, nodes) = match cell_type {
            CellType::Hex8 => (hexes, corners),
            CellType::Hex20 => (hexes, corners + edges),
            CellType::Hex27 => (hexes, corners + edges + faces + hexes),
            CellType::Wedge6 => (2 * hexes, corners),
            CellType::Wedge15 => (2 * hexes, corners + edges + zeta_faces),
            CellType::Pyramid5 => (6 * hexes, corners + hexes),
            CellType::Tet4 | CellType::Tet10 => (mesh.num_cells(), mesh.num_nodes()),
        };
        assert_eq!(mesh.num_cells(), cells, "{}", cell_type.name());
        assert_eq!(mesh.num_nodes(), nodes, "{}", cell_type.name());
        let surface: Vec<String> = ["xmin", "xmax", "ymin", "ymax", "zmin", "zmax"]
            .iter()
            .map(|s| format!("block.{s}"))
            .collect();
        let names: Vec<&str> = surface.iter().map(String::as_str).collect();
        assert_conforming_and_covered(&mesh, &names);
        assert_sets_outward(&mesh);
        // Every node of a side's node set lies on the side, and every node
        // on the side is in the set (mid-edges and face centres included).
        for (set, axis, value) in [("block.xmax", 0, 1.0), ("block.zmin", 2, 0.0)] {
            let nodes = mesh.node_set(set).unwrap();
            let on: Vec<usize> = (0..mesh.num_nodes())
                .filter(|&v| (mesh.nodes[v][axis] - value).abs() < 1e-12)
                .collect();
            assert_eq!(nodes, on.as_slice(), "{} {set}", cell_type.name());
        }
        let quality = mesh.min_scaled_jacobian().unwrap();
        assert!(
            quality > 0.0 && quality <= 1.0 + 1e-12,
            "{} {quality}",
            cell_type.name()
        );
        let bb = mesh.bounding_box().unwrap();
        assert_eq!((bb.min, bb.max), ([0.0; 3], [1.0, 2.0, 1.5]));
    }
}

#[test]
fn wedges_have_triangles_on_zeta_sides_and_pyramids_quads_outside() {
    let wedge = unit_box(CellType::Wedge6, [2, 2, 2]);
    assert_eq!(
        wedge.facet_set_types("block.zmax").unwrap(),
        [FacetType::Tri3]
    );
    assert_eq!(
        wedge.facet_set_types("block.xmin").unwrap(),
        [FacetType::Quad4]
    );
    assert_eq!(wedge.facet_set("block.zmax").unwrap().len(), 8);
    let wedge15 = unit_box(CellType::Wedge15, [2, 2, 2]);
    assert_eq!(
        wedge15.facet_set_types("block.zmin").unwrap(),
        [FacetType::Tri6]
    );
    assert_eq!(
        wedge15.facet_set_types("block.ymin").unwrap(),
        [FacetType::Quad8]
    );
    let pyramid = unit_box(CellType::Pyramid5, [2, 2, 2]);
    for side in ["xmin", "zmax"] {
        let set = format!("block.{side}");
        assert_eq!(pyramid.facet_set_types(&set).unwrap(), [FacetType::Quad4]);
        assert_eq!(pyramid.facet_set(&set).unwrap().len(), 4);
    }
    assert_eq!(
        unit_box(CellType::Hex27, [1, 1, 1])
            .facet_set_types("block.top")
            .unwrap(),
        [FacetType::Quad9]
    );
}

/// Second-order nodes sit at the means of their corners, and shared ones
/// are shared: each cell's mid-edge node is its neighbour's.
#[test]
fn higher_nodes_sit_at_their_corners_mean_and_are_shared() {
    for cell_type in [
        CellType::Tet10,
        CellType::Hex20,
        CellType::Hex27,
        CellType::Wedge15,
    ] {
        let mesh = unit_box(cell_type, [2, 2, 1]);
        let mut by_key = std::collections::HashMap::new();
        for ids in mesh.cells_iter() {
            for (k, of) in cell_type.higher_nodes().iter().enumerate() {
                let node = ids[cell_type.corners() + k];
                let mut mean = [0.0; 3];
                for &a in of.iter() {
                    for (m, x) in mean.iter_mut().zip(mesh.nodes[ids[a]]) {
                        *m += x / of.len() as f64;
                    }
                }
                assert!((0..3).all(|i| (mesh.nodes[node][i] - mean[i]).abs() < 1e-14));
                let mut key: Vec<usize> = of.iter().map(|&a| ids[a]).collect();
                key.sort_unstable();
                if key.len() < cell_type.corners() {
                    assert_eq!(*by_key.entry(key).or_insert(node), node);
                }
            }
        }
    }
}

#[test]
fn stacked_blocks_and_hertz_meshes_of_second_order() {
    for cell_type in [
        CellType::Tet10,
        CellType::Hex20,
        CellType::Wedge6,
        CellType::Pyramid5,
    ] {
        let mesh = stacked_blocks(&StackedSpec {
            cell_type,
            ..Default::default()
        })
        .unwrap();
        assert_eq!(mesh.cell_type, cell_type);
        assert!(rel_err(body_volume(&mesh, "upper"), 0.5) < 1e-12);
    }
    let spec = HertzCylinderSpec {
        fine_size: 1.0,
        cell_type: CellType::Hex20,
        ..Default::default()
    };
    let mesh = hertz_cylinder(&spec).unwrap();
    assert_eq!(mesh.cell_type, CellType::Hex20);
    // The o-grid's hexes do not share one orientation: no wedges there.
    let err = hertz_cylinder(&HertzCylinderSpec {
        cell_type: CellType::Wedge6,
        ..spec
    })
    .unwrap_err();
    assert!(err.to_string().contains("wedge"), "{err}");
}

/// A mid-edge node moved off its edge is one error naming the cell; a
/// reflected cell is inverted at its quadrature points.
#[test]
fn bad_second_order_cells_are_named() {
    let mut mesh = unit_box(CellType::Tet10, [1, 1, 1]);
    let cell = 3;
    let node = mesh.cell(cell)[5];
    // Further than a quarter of the box's longest diagonal (2.7).
    mesh.nodes[node][0] += 1.0;
    match mesh.validate().unwrap_err() {
        MeshError::MidNodeOffEdge {
            cell: c, node: n, ..
        } => {
            assert!(n == node && mesh.cell(c).contains(&node));
        }
        other => panic!("{other}"),
    }
    let mut mesh = unit_box(CellType::Hex20, [2, 1, 1]);
    let ids: Vec<usize> = mesh.cell(1).to_vec();
    for (k, &from) in CellType::Hex20.mirror().iter().enumerate() {
        mesh.cells[20 + k] = ids[from];
    }
    let err = mesh.validate().unwrap_err();
    assert!(
        matches!(err, MeshError::InvertedCell { cell: 1, .. }),
        "{err}"
    );
    assert!(err.to_string().contains("cell 1"));
}

#[test]
fn dual_graphs_of_every_type_join_face_neighbours() {
    for cell_type in CellType::ALL {
        let mesh = unit_box(cell_type, [2, 1, 1]);
        let (xadj, adjncy) = mesh.face_dual_graph();
        // Every interior face joins two cells; boundary faces none.
        let faces: usize = mesh.num_cells() * cell_type.num_faces();
        let boundary = mesh.boundary_facets().len();
        assert_eq!(adjncy.len(), faces - boundary, "{}", cell_type.name());
        assert_eq!(xadj.len(), mesh.num_cells() + 1);
        if let Some(f) = cell_type.single_facet_type() {
            assert_eq!(mesh.dual_graph(f.nodes()).unwrap(), (xadj, adjncy));
        }
    }
}

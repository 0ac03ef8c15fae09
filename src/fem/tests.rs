//! The reference cell and facet tables: outward faces, face types, higher
//! nodes and the node-order permutations agree with each other.

use super::shape::{cell_reference_nodes, facet_reference_nodes, HEX8_REF_NODES};
use super::test_util::{distorted_cell, hex8_unit, perturb, tet4_unit, Lcg};
use super::*;
use crate::vec3::{cross, dot, sub};

fn corner_normal(x: &[[f64; 3]]) -> [f64; 3] {
    match x.len() {
        3 => cross(sub(x[1], x[0]), sub(x[2], x[0])),
        _ => cross(sub(x[2], x[0]), sub(x[3], x[1])),
    }
}

fn centroid(x: &[[f64; 3]]) -> [f64; 3] {
    let mut c = [0.0; 3];
    for p in x {
        for i in 0..3 {
            c[i] += p[i] / x.len() as f64;
        }
    }
    c
}

/// On a convex cell the outward normal of every face points away from the
/// cell centroid; checked on distorted (still convex) cells so a face
/// listed in the wrong orientation cannot pass by symmetry.
fn assert_faces_outward(cell: CellType, x: &[[f64; 3]]) {
    let c = centroid(&x[..cell.corners()]);
    for (f, face) in cell.local_faces().iter().enumerate() {
        let facet = cell.face_type(f);
        assert_eq!(face.len(), facet.nodes());
        let xf: Vec<[f64; 3]> = face[..facet.corners()].iter().map(|&a| x[a]).collect();
        let n = corner_normal(&xf);
        let out = sub(centroid(&xf), c);
        assert!(dot(n, out) > 0.0, "{} face {f} points inward", cell.name());
    }
}

#[test]
fn faces_point_outward() {
    let mut rng = Lcg::new(7);
    let mut hex = hex8_unit();
    perturb(&mut hex, &mut rng, 0.1);
    assert_faces_outward(CellType::Hex8, &hex);
    let mut tet = tet4_unit();
    perturb(&mut tet, &mut rng, 0.1);
    assert_faces_outward(CellType::Tet4, &tet);
    for cell in CellType::ALL {
        assert_faces_outward(cell, &distorted_cell(cell, 8, 0.05));
    }
}

#[test]
fn faces_cover_each_corner_consistently() {
    // Every hex, tet and wedge corner lies on exactly 3 faces; the pyramid's
    // base corners too, its apex on 4. The tet face f does not contain node
    // 3 - f.
    for cell in CellType::ALL {
        let mut count = vec![0; cell.nodes()];
        for face in cell.local_faces() {
            for &a in face.iter() {
                count[a] += 1;
            }
        }
        for (a, &c) in count.iter().enumerate().take(cell.corners()) {
            let expected = if cell == CellType::Pyramid5 && a == 4 {
                4
            } else {
                3
            };
            assert_eq!(c, expected, "{} corner {a}", cell.name());
        }
        // Mid-edge nodes lie on two faces, face centres on one, the cell
        // centre on none.
        for (k, of) in cell.higher_nodes().iter().enumerate() {
            let expected = match of.len() {
                2 => 2,
                4 => 1,
                _ => 0,
            };
            assert_eq!(
                count[cell.corners() + k],
                expected,
                "{} node {k}",
                cell.name()
            );
        }
    }
    for (f, face) in CellType::Tet4.local_faces().iter().enumerate() {
        assert!(!face.contains(&(3 - f)));
    }
}

/// A face's higher nodes are the mid-edges of its consecutive corners (and
/// its centre): the face tables and the higher-node tables agree, and so do
/// the cell's face and the facet type's own numbering.
#[test]
fn face_higher_nodes_sit_on_their_corners() {
    for cell in CellType::ALL {
        for (f, face) in cell.local_faces().iter().enumerate() {
            let facet = cell.face_type(f);
            let corners = facet.corners();
            for (k, of) in facet.higher_nodes().iter().enumerate() {
                let node = face[corners + k];
                let mut want: Vec<usize> = of.iter().map(|&c| face[c]).collect();
                let mut got = cell.higher_nodes()[node - cell.corners()].to_vec();
                want.sort_unstable();
                got.sort_unstable();
                assert_eq!(got, want, "{} face {f} node {node}", cell.name());
            }
        }
    }
}

#[test]
fn reference_faces_lie_on_their_reference_planes() {
    // Every node of a face maps onto the same facet of the reference cell:
    // its reference coordinates interpolate linearly from the corners'.
    for cell in CellType::ALL {
        let xi = cell_reference_nodes(cell);
        for (f, face) in cell.local_faces().iter().enumerate() {
            let facet = cell.face_type(f);
            let c: Vec<[f64; 3]> = face[..facet.corners()].iter().map(|&a| xi[a]).collect();
            let n = corner_normal(&c);
            for &a in face.iter() {
                assert!(
                    dot(n, sub(xi[a], c[0])).abs() < 1e-14,
                    "{} face {f}",
                    cell.name()
                );
            }
        }
    }
    // The facet's reference nodes, placed by the face map of a unit face,
    // reproduce the facet's own numbering.
    for facet in FacetType::ALL {
        assert_eq!(facet_reference_nodes(facet).len(), facet.nodes());
    }
}

#[test]
fn hex_face_order_matches_reference_coordinates() {
    // (axis, sign) of face f: 0 ξ-, 1 ξ+, 2 η-, 3 η+, 4 ζ-, 5 ζ+.
    for (f, face) in CellType::Hex8.local_faces().iter().enumerate() {
        let axis = f / 2;
        let sign = if f % 2 == 0 { -1.0 } else { 1.0 };
        for &a in face.iter() {
            assert_eq!(HEX8_REF_NODES[a][axis], sign, "face {f} node {a}");
        }
    }
    // Hex27's face centre of face f is node 20 + f.
    for (f, face) in CellType::Hex27.local_faces().iter().enumerate() {
        assert_eq!(face[8], 20 + f);
    }
}

#[test]
fn face_types_and_single_facet_types() {
    assert_eq!(CellType::Hex8.single_facet_type(), Some(FacetType::Quad4));
    assert_eq!(CellType::Tet4.single_facet_type(), Some(FacetType::Tri3));
    assert_eq!(CellType::Tet10.single_facet_type(), Some(FacetType::Tri6));
    assert_eq!(CellType::Hex20.single_facet_type(), Some(FacetType::Quad8));
    assert_eq!(CellType::Hex27.single_facet_type(), Some(FacetType::Quad9));
    assert_eq!(CellType::Wedge6.single_facet_type(), None);
    assert_eq!(CellType::Pyramid5.single_facet_type(), None);
    let wedge: Vec<FacetType> = (0..5).map(|f| CellType::Wedge15.face_type(f)).collect();
    use FacetType::{Quad8, Tri6};
    assert_eq!(wedge, [Tri6, Tri6, Quad8, Quad8, Quad8]);
    assert_eq!(CellType::Pyramid5.face_type(0), FacetType::Quad4);
    assert_eq!(CellType::Pyramid5.face_type(3), FacetType::Tri3);
}

#[test]
fn names_counts_and_kin() {
    for cell in CellType::ALL {
        assert_eq!(CellType::from_name(cell.name()), Some(cell));
        assert_eq!(cell.linear().order(), 1);
        assert!(cell.corners() <= cell.nodes());
    }
    for facet in FacetType::ALL {
        assert_eq!(FacetType::from_name(facet.name()), Some(facet));
    }
    assert_eq!(CellType::from_name("hex64"), None);
    assert_eq!(CellType::Hex27.nodes(), MAX_CELL_NODES);
    assert_eq!(FacetType::Quad9.nodes(), MAX_FACET_NODES);
    assert_eq!(CellType::Tet10.order(), 2);
    assert_eq!(CellType::Wedge15.linear(), CellType::Wedge6);
    assert!(FacetType::Tri3.is_linear() && !FacetType::Quad8.is_linear());
}

/// The VTK permutations are involutions that map the cell onto a cell with
/// the VTK wedge's orientation (its (0,1,2) normal points away from
/// (3,4,5)), and the Gmsh permutations put every higher node at the mean
/// of the corners its Gmsh number names.
#[test]
fn vtk_and_gmsh_orders() {
    for cell in CellType::ALL {
        let p = cell.vtk_order();
        assert_eq!(p.len(), cell.nodes());
        for (j, &k) in p.iter().enumerate() {
            assert_eq!(p[k], j, "{} not an involution", cell.name());
        }
    }
    let x = cell_reference_nodes(CellType::Wedge6);
    let vtk: Vec<[f64; 3]> = CellType::Wedge6.vtk_order().iter().map(|&k| x[k]).collect();
    let n = corner_normal(&vtk[..3]);
    assert!(dot(n, sub(vtk[3], vtk[0])) < 0.0);
    // Gmsh's own edge lists, from its documentation.
    type Edges<'a> = (CellType, &'a [usize], &'a [[usize; 2]]);
    let gmsh_edges: [Edges; 3] = [
        (
            CellType::Tet10,
            &GMSH_TET10,
            &[[0, 1], [1, 2], [2, 0], [3, 0], [3, 2], [3, 1]],
        ),
        (
            CellType::Hex20,
            &GMSH_HEX20,
            &[
                [0, 1],
                [0, 3],
                [0, 4],
                [1, 2],
                [1, 5],
                [2, 3],
                [2, 6],
                [3, 7],
                [4, 5],
                [4, 7],
                [5, 6],
                [6, 7],
            ],
        ),
        (
            CellType::Wedge15,
            &GMSH_WEDGE15,
            &[
                [0, 1],
                [0, 2],
                [0, 3],
                [1, 2],
                [1, 4],
                [2, 5],
                [3, 4],
                [3, 5],
                [4, 5],
            ],
        ),
    ];
    for (cell, perm, edges) in gmsh_edges {
        let corners = cell.corners();
        for (k, of) in cell.higher_nodes().iter().enumerate() {
            let gmsh = perm[corners + k];
            let mut want = edges[gmsh - corners].to_vec();
            let mut got = of.to_vec();
            want.sort_unstable();
            got.sort_unstable();
            assert_eq!(got, want, "{} node {}", cell.name(), corners + k);
        }
    }
    assert_eq!(GMSH_HEX27[..20], GMSH_HEX20);
}

/// The mirror of a valid cell has every node where the mirrored cell's
/// numbering puts it: higher nodes stay the means of their corners, and
/// the corners' orientation flips.
#[test]
fn mirrors_reflect_and_keep_the_structure() {
    for cell in CellType::ALL {
        let m = cell.mirror();
        assert_eq!(m.len(), cell.nodes());
        let x = cell_reference_nodes(cell);
        let y: Vec<[f64; 3]> = m.iter().map(|&k| x[k]).collect();
        for (k, of) in cell.higher_nodes().iter().enumerate() {
            let mut mean = [0.0; 3];
            for &a in of.iter() {
                for i in 0..3 {
                    mean[i] += y[a][i] / of.len() as f64;
                }
            }
            let node = y[cell.corners() + k];
            assert!(
                (0..3).all(|i| (mean[i] - node[i]).abs() < 1e-15),
                "{} node {}",
                cell.name(),
                cell.corners() + k
            );
        }
        let geom = ElementGeometry::new(cell, &y, &QuadRule::default_for_cell(cell));
        assert!(
            matches!(geom, Err(FemError::InvertedElement { .. })),
            "{}",
            cell.name()
        );
    }
}

//! Graded box, stacked blocks and perturbation.

use super::{
    assert_conforming_and_covered, assert_set_normal, assert_sets_outward, body_volume, rel_err,
};
use crate::mesh::{
    graded_box, perturb_interior, stacked_blocks, BoxSpec, CellType, Grading, Mesh, MeshError,
    Perturbation, StackedSpec,
};

const SIDES: [(&str, [f64; 3]); 6] = [
    ("xmin", [-1.0, 0.0, 0.0]),
    ("xmax", [1.0, 0.0, 0.0]),
    ("ymin", [0.0, -1.0, 0.0]),
    ("ymax", [0.0, 1.0, 0.0]),
    ("zmin", [0.0, 0.0, -1.0]),
    ("zmax", [0.0, 0.0, 1.0]),
];

fn box_surface(body: &str) -> Vec<String> {
    SIDES.iter().map(|(s, _)| format!("{body}.{s}")).collect()
}

fn as_strs(v: &[String]) -> Vec<&str> {
    v.iter().map(String::as_str).collect()
}

/// Sorted distinct node coordinates along one axis.
fn axis_nodes(mesh: &Mesh, axis: usize) -> Vec<f64> {
    let mut v: Vec<f64> = mesh.nodes.iter().map(|p| p[axis]).collect();
    v.sort_by(f64::total_cmp);
    v.dedup();
    v
}

#[test]
fn box_volume_sets_areas_and_normals() {
    for cell_type in CellType::ALL {
        let spec = BoxSpec {
            body: "blk".into(),
            origin: [-1.0, 2.0, 3.0],
            size: [2.0, 3.0, 0.5],
            divisions: [3, 4, 2],
            grading: [
                Grading::Geometric { ratio: 4.0 },
                Grading::Toward {
                    point: 3.5,
                    ratio: 5.0,
                },
                Grading::Uniform,
            ],
            cell_type,
        };
        let mesh = graded_box(&spec).unwrap();
        mesh.validate().unwrap();
        assert_eq!(mesh.bodies, vec!["blk".to_string()]);
        assert!(rel_err(body_volume(&mesh, "blk"), 3.0) < 1e-12);
        let surface = box_surface("blk");
        assert_conforming_and_covered(&mesh, &as_strs(&surface));
        assert_sets_outward(&mesh);
        for (side, normal) in SIDES {
            assert_set_normal(&mesh, &format!("blk.{side}"), normal);
        }
        let area = |s: &str| mesh.facet_set_area(s).unwrap();
        assert!(rel_err(area("blk.zmax"), 6.0) < 1e-12);
        assert!(rel_err(area("blk.xmin"), 1.5) < 1e-12);
        assert!(rel_err(area("blk.ymax"), 1.0) < 1e-12);
        assert_eq!(
            mesh.facet_set("blk.top").unwrap(),
            mesh.facet_set("blk.zmax").unwrap()
        );
        assert_eq!(
            mesh.node_set("blk.bottom").unwrap(),
            mesh.node_set("blk.zmin").unwrap()
        );
        if cell_type.order() == 1 {
            assert_eq!(mesh.node_set("blk.top").unwrap().len(), 4 * 5);
        }
        assert!(mesh
            .node_set("blk.top")
            .unwrap()
            .iter()
            .all(|&n| mesh.nodes[n][2] == 3.5));
        let bb = mesh.bounding_box().unwrap();
        assert_eq!((bb.min, bb.max), ([-1.0, 2.0, 3.0], [1.0, 5.0, 3.5]));
    }
}

#[test]
fn geometric_grading_has_exact_end_ratio() {
    let spec = BoxSpec {
        divisions: [6, 1, 1],
        grading: [
            Grading::Geometric { ratio: 10.0 },
            Grading::Uniform,
            Grading::Uniform,
        ],
        ..BoxSpec::default()
    };
    let x = axis_nodes(&graded_box(&spec).unwrap(), 0);
    assert_eq!(x.len(), 7);
    let first = x[1] - x[0];
    let last = x[6] - x[5];
    assert!(rel_err(last / first, 10.0) < 1e-12);
    assert_eq!((x[0], x[6]), (0.0, 1.0));
}

#[test]
fn toward_grading_is_fine_at_the_point() {
    for point in [0.0, 0.3, 1.0] {
        let spec = BoxSpec {
            divisions: [1, 1, 40],
            grading: [
                Grading::Uniform,
                Grading::Uniform,
                Grading::Toward { point, ratio: 8.0 },
            ],
            ..BoxSpec::default()
        };
        let z = axis_nodes(&graded_box(&spec).unwrap(), 2);
        let sizes: Vec<(f64, f64)> = z
            .windows(2)
            .map(|w| (0.5 * (w[0] + w[1]), w[1] - w[0]))
            .collect();
        let (smallest_at, smallest) = sizes
            .iter()
            .copied()
            .min_by(|a, b| a.1.total_cmp(&b.1))
            .unwrap();
        let largest = sizes.iter().map(|s| s.1).fold(0.0, f64::max);
        assert!(
            (smallest_at - point).abs() < 2.0 * smallest,
            "point {point}: fine at {smallest_at}"
        );
        // The continuum law gives exactly 8; the discrete end cells are
        // within one cell of it.
        let ratio = largest / smallest;
        assert!((6.5..=8.5).contains(&ratio), "point {point}: ratio {ratio}");
    }
}

#[test]
fn bad_box_specs_name_the_field() {
    let cases: [(BoxSpec, &str); 5] = [
        (
            BoxSpec {
                divisions: [2, 0, 2],
                ..BoxSpec::default()
            },
            "divisions[1]",
        ),
        (
            BoxSpec {
                size: [1.0, 1.0, -1.0],
                ..BoxSpec::default()
            },
            "size[2]",
        ),
        (
            BoxSpec {
                origin: [f64::NAN, 0.0, 0.0],
                ..BoxSpec::default()
            },
            "origin[0]",
        ),
        (
            BoxSpec {
                grading: [
                    Grading::Uniform,
                    Grading::Geometric { ratio: 0.0 },
                    Grading::Uniform,
                ],
                ..BoxSpec::default()
            },
            "grading[1]",
        ),
        (
            BoxSpec {
                body: String::new(),
                ..BoxSpec::default()
            },
            "body",
        ),
    ];
    for (spec, field) in cases {
        let err = graded_box(&spec).unwrap_err();
        match &err {
            MeshError::InvalidSpec {
                generator: "graded_box",
                field: f,
                ..
            } => assert_eq!(f, field),
            other => panic!("{other:?}"),
        }
        assert!(err.to_string().contains(field), "{err}");
    }
}

#[test]
fn stacked_blocks_are_non_matching_with_all_sets() {
    for cell_type in [CellType::Hex8, CellType::Tet4] {
        let spec = StackedSpec {
            gap: 0.1,
            cell_type,
            ..StackedSpec::default()
        };
        let mesh = stacked_blocks(&spec).unwrap();
        assert_eq!(mesh.bodies, vec!["lower".to_string(), "upper".to_string()]);
        assert!(rel_err(body_volume(&mesh, "lower"), 0.5) < 1e-12);
        assert!(rel_err(body_volume(&mesh, "upper"), 0.5) < 1e-12);
        let mut surface = box_surface("lower");
        surface.extend(box_surface("upper"));
        assert_conforming_and_covered(&mesh, &as_strs(&surface));
        assert_sets_outward(&mesh);
        assert_set_normal(&mesh, "lower.top", [0.0, 0.0, 1.0]);
        assert_set_normal(&mesh, "upper.bottom", [0.0, 0.0, -1.0]);
        // 5×5 and 4×4 interface nodes: the meshes do not match.
        assert_eq!(mesh.node_set("lower.top").unwrap().len(), 25);
        assert_eq!(mesh.node_set("upper.bottom").unwrap().len(), 16);
        let upper_bottom = mesh.node_set("upper.bottom").unwrap();
        assert!(upper_bottom.iter().all(|&n| mesh.nodes[n][2] == 0.1));
        for set in ["lower.top", "lower.bottom", "upper.top", "upper.bottom"] {
            assert!(
                rel_err(mesh.facet_set_area(set).unwrap(), 1.0) < 1e-12,
                "{set}"
            );
        }
    }
}

#[test]
fn perturbation_keeps_faces_volume_and_is_deterministic() {
    for cell_type in [CellType::Hex8, CellType::Tet4] {
        let base = StackedSpec {
            lower_divisions: [5, 4, 4],
            upper_divisions: [4, 3, 3],
            cell_type,
            ..StackedSpec::default()
        };
        let regular = stacked_blocks(&base).unwrap();
        let spec = |seed| StackedSpec {
            perturbation: Some(Perturbation {
                fraction: 0.25,
                seed,
            }),
            ..base.clone()
        };
        let a = stacked_blocks(&spec(7)).unwrap();
        let b = stacked_blocks(&spec(7)).unwrap();
        let c = stacked_blocks(&spec(8)).unwrap();
        assert_eq!(a, b);
        assert_ne!(a.nodes, c.nodes);
        // Same connectivity and sets, volume exactly kept.
        assert_eq!(a.cells, regular.cells);
        assert_eq!(a.node_sets, regular.node_sets);
        for body in ["lower", "upper"] {
            assert!(rel_err(body_volume(&a, body), 0.5) < 1e-12, "{body}");
        }
        let moved = |n: usize| a.nodes[n] != regular.nodes[n];
        let interior = (0..a.num_nodes())
            .filter(|&n| {
                regular
                    .node_sets
                    .values()
                    .all(|s| s.binary_search(&n).is_err())
            })
            .collect::<Vec<_>>();
        assert!(!interior.is_empty() && interior.iter().all(|&n| moved(n)));
        // Face nodes stay on their face; face-interior nodes do move.
        for (side, normal) in SIDES {
            for body in ["lower", "upper"] {
                let set = format!("{body}.{side}");
                let axis = normal.iter().position(|&x| x != 0.0).unwrap();
                for &n in a.node_set(&set).unwrap() {
                    assert_eq!(a.nodes[n][axis], regular.nodes[n][axis], "{set} node {n}");
                }
                assert_set_normal(&a, &set, normal);
            }
        }
        assert!(a.node_set("lower.top").unwrap().iter().any(|&n| moved(n)));
        // Corners of the boxes never move.
        let bb = a.bounding_box().unwrap();
        assert_eq!(bb, regular.bounding_box().unwrap());
    }
}

#[test]
fn perturbation_rejects_bad_fraction() {
    let mesh = stacked_blocks(&StackedSpec::default()).unwrap();
    let err = perturb_interior(&mesh, 0.9, 1).unwrap_err();
    assert!(matches!(
        err,
        MeshError::InvalidArgument {
            argument: "fraction",
            ..
        }
    ));
    let err = stacked_blocks(&StackedSpec {
        lower_divisions: [0, 1, 1],
        ..StackedSpec::default()
    })
    .unwrap_err();
    assert!(err.to_string().contains("lower_divisions"));
}

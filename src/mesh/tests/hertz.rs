//! Hertz cylinder and sphere generators: geometry, sets and mesh quality.

use std::f64::consts::PI;

use super::{
    assert_conforming_and_covered, assert_set_normal, assert_sets_outward, body_volume, rel_err,
};
use crate::mesh::{
    hertz_cylinder, hertz_sphere, CellType, HertzCylinderSpec, HertzSphereSpec, Mesh, MeshError,
};
use crate::vec3::{dot, norm, sub};

const CYLINDER_SURFACE: [&str; 10] = [
    "block.top",
    "block.bottom",
    "block.xmin",
    "block.xmax",
    "block.front",
    "block.back",
    "cylinder.curved",
    "cylinder.top",
    "cylinder.front",
    "cylinder.back",
];

const SPHERE_SURFACE: [&str; 8] = [
    "block.top",
    "block.bottom",
    "block.xmin",
    "block.xmax",
    "block.ymin",
    "block.ymax",
    "sphere.curved",
    "sphere.top",
];

/// Smallest scaled Jacobian over the cells of one body.
fn body_min_scaled_jacobian(mesh: &Mesh, body: &str) -> f64 {
    let id = mesh.body_id(body).unwrap();
    mesh.body_cells(id)
        .map(|c| mesh.scaled_jacobian(c).unwrap())
        .fold(f64::INFINITY, f64::min)
}

/// Lengths of the edges of the set's facets that touch node `n`.
fn facet_edges_at(mesh: &Mesh, set: &str, n: usize) -> Vec<f64> {
    let mut lengths = Vec::new();
    for f in mesh.facet_set(set).unwrap() {
        let nodes = mesh.facet_nodes(f).unwrap();
        if let Some(k) = nodes.iter().position(|&m| m == n) {
            for neighbour in [
                nodes[(k + 1) % nodes.len()],
                nodes[(k + nodes.len() - 1) % nodes.len()],
            ] {
                lengths.push(norm(sub(mesh.nodes[neighbour], mesh.nodes[n])));
            }
        }
    }
    lengths
}

/// Edge lengths at the lowest node of a curved set and at the block's node
/// below it: the element size at the contact point.
fn contact_sizes(
    mesh: &Mesh,
    tip_set: &str,
    curved: &str,
    block_point: [f64; 3],
) -> (Vec<f64>, Vec<f64>) {
    let tip = mesh.node_set(tip_set).unwrap()[0];
    let block_node = mesh
        .node_set("block.top")
        .unwrap()
        .iter()
        .copied()
        .find(|&n| norm(sub(mesh.nodes[n], block_point)) < 1e-9)
        .expect("block has a node at the contact point");
    (
        facet_edges_at(mesh, curved, tip),
        facet_edges_at(mesh, "block.top", block_node),
    )
}

/// Area of the chord polygon inscribed in the half disc, from the chord
/// lengths of the curved facets: π R²/2 − Σ R²/2 (Δθ − sin Δθ).
fn inscribed_half_disc_area(mesh: &Mesh, radius: f64, thickness: f64) -> f64 {
    let deficit: f64 = mesh
        .facet_set("cylinder.curved")
        .unwrap()
        .iter()
        .map(|f| {
            let chord = mesh.facet_vector_area(f).map(norm).unwrap() / thickness;
            let angle = 2.0 * (chord / (2.0 * radius)).asin();
            0.5 * radius * radius * (angle - angle.sin())
        })
        .sum();
    0.5 * PI * radius * radius - deficit
}

#[test]
fn hertz_cylinder_geometry_sets_and_convergence() {
    let base = HertzCylinderSpec {
        fine_size: 0.2,
        gap: 0.05,
        ..HertzCylinderSpec::default()
    };
    let (r, t) = (base.radius, base.thickness);
    let mut errors = Vec::new();
    let mut arc_errors = Vec::new();
    println!(
        "hertz_cylinder R={r} h_c={} c_zone={}:",
        base.fine_size, base.fine_half_width
    );
    for level in 0..3 {
        let spec = HertzCylinderSpec {
            level,
            ..base.clone()
        };
        let mesh = hertz_cylinder(&spec).unwrap();
        mesh.validate().unwrap();
        assert_eq!(
            mesh.bodies,
            vec!["block".to_string(), "cylinder".to_string()]
        );
        assert_conforming_and_covered(&mesh, &CYLINDER_SURFACE);
        assert_sets_outward(&mesh);

        // Block: exact volume, flat faces, areas.
        let block_volume = spec.block_width * spec.block_height * t;
        assert!(rel_err(body_volume(&mesh, "block"), block_volume) < 1e-12);
        assert_set_normal(&mesh, "block.top", [0.0, 0.0, 1.0]);
        assert_set_normal(&mesh, "block.bottom", [0.0, 0.0, -1.0]);
        assert_set_normal(&mesh, "block.front", [0.0, -1.0, 0.0]);
        assert_set_normal(&mesh, "block.back", [0.0, 1.0, 0.0]);
        assert_set_normal(&mesh, "block.xmin", [-1.0, 0.0, 0.0]);
        assert_set_normal(&mesh, "cylinder.top", [0.0, 0.0, 1.0]);
        assert_set_normal(&mesh, "cylinder.front", [0.0, -1.0, 0.0]);
        assert!(
            rel_err(
                mesh.facet_set_area("block.top").unwrap(),
                spec.block_width * t
            ) < 1e-12
        );
        assert!(rel_err(mesh.facet_set_area("cylinder.top").unwrap(), 2.0 * r * t) < 1e-12);

        // Cylinder: every curved facet points away from the axis, and
        // straight down at the contact point.
        let centre_z = r + spec.gap;
        for f in mesh.facet_set("cylinder.curved").unwrap() {
            let n = mesh.facet_normal(f).unwrap();
            let c = mesh.facet_centroid(f).unwrap();
            let radial = [c[0], 0.0, c[2] - centre_z];
            assert!(dot(n, radial) > 0.99 * norm(radial), "{f:?}: {n:?}");
            if c[0].abs() < 0.5 {
                assert!(n[2] < -0.99, "{f:?} near contact: {n:?}");
            }
        }
        // The mesh volume is exactly the inscribed chord polygon times t
        // (no gaps or overlaps), which converges to π R² t / 2.
        let volume = body_volume(&mesh, "cylinder");
        let polygon = inscribed_half_disc_area(&mesh, r, t) * t;
        assert!(rel_err(volume, polygon) < 1e-12, "{volume} vs {polygon}");
        let front = mesh.facet_set_area("cylinder.front").unwrap();
        assert!(rel_err(front * t, volume) < 1e-12);
        let exact = 0.5 * PI * r * r * t;
        errors.push((exact - volume) / exact);
        arc_errors
            .push((PI * r * t - mesh.facet_set_area("cylinder.curved").unwrap()) / (PI * r * t));

        // Sets for loading and constraints.
        let axis = mesh.node_set("cylinder.axis").unwrap();
        assert_eq!(axis.len(), 2);
        assert!(axis
            .iter()
            .all(|&n| mesh.nodes[n][0] == 0.0 && (mesh.nodes[n][2] - centre_z).abs() < 1e-12));
        let tip = mesh.node_set("cylinder.tip").unwrap();
        assert_eq!(tip.len(), 2);
        assert!(tip
            .iter()
            .all(|&n| (mesh.nodes[n][2] - spec.gap).abs() < 1e-12));
        let contact = mesh.facet_set("block.contact").unwrap().len();
        assert!(contact > 0 && contact < mesh.facet_set("block.top").unwrap().len());
        assert!(!mesh.facet_set("cylinder.contact").unwrap().is_empty());

        // Quality and the element size at the contact point.
        let sj_cylinder = body_min_scaled_jacobian(&mesh, "cylinder");
        let sj_block = body_min_scaled_jacobian(&mesh, "block");
        let (cyl_edges, block_edges) =
            contact_sizes(&mesh, "cylinder.tip", "cylinder.curved", [0.0, 0.0, 0.0]);
        let expected = spec.fine_size / f64::from(1u32 << level);
        let in_plane: Vec<f64> = cyl_edges
            .iter()
            .copied()
            .filter(|&e| (e - t).abs() > 1e-9)
            .collect();
        let block_in_plane: Vec<f64> = block_edges
            .iter()
            .copied()
            .filter(|&e| (e - t).abs() > 1e-9)
            .collect();
        println!(
            "  level {level}: {} cells, min scaled Jacobian cylinder {sj_cylinder:.4} block {sj_block:.4}, \
             contact size cylinder {:.5} block {:.5}, volume error {:.3e}",
            mesh.num_cells(),
            in_plane[0],
            block_in_plane[0],
            errors[level as usize]
        );
        assert!(sj_cylinder > 0.6, "level {level}: {sj_cylinder}");
        assert!(sj_block > 0.999);
        for e in in_plane.iter().chain(&block_in_plane) {
            assert!(
                rel_err(*e, expected) < 0.02,
                "contact edge {e} vs {expected}"
            );
        }
    }
    // Second-order convergence of volume and curved area under `level`.
    // The chord deficit is Σ R² Δθ³ / 12 over arcs Δθ ≤ 0.2 rad at level 0,
    // so a relative error of a few 1e-3 is the expected size.
    for e in [&errors, &arc_errors] {
        assert!(e[0] > 0.0 && e[0] < 5e-3, "{e:?}");
        for pair in e.windows(2) {
            let rate = pair[0] / pair[1];
            assert!((3.8..4.2).contains(&rate), "{e:?}");
        }
    }
}

#[test]
fn hertz_cylinder_default_and_tets() {
    let spec = HertzCylinderSpec::default();
    let hexes = hertz_cylinder(&spec).unwrap();
    let tets = hertz_cylinder(&HertzCylinderSpec {
        cell_type: CellType::Tet4,
        ..spec
    })
    .unwrap();
    assert_eq!(tets.cell_type, CellType::Tet4);
    assert_conforming_and_covered(&tets, &CYLINDER_SURFACE);
    assert_sets_outward(&tets);
    // Extruded hexes have planar faces, so the tets fill them exactly.
    for body in ["block", "cylinder"] {
        assert!(rel_err(body_volume(&tets, body), body_volume(&hexes, body)) < 1e-12);
    }
    println!(
        "hertz_cylinder default: {} hexes, {} tets, min scaled Jacobian hex {:.4} tet {:.4}",
        hexes.num_cells(),
        tets.num_cells(),
        hexes.min_scaled_jacobian().unwrap(),
        tets.min_scaled_jacobian().unwrap()
    );
}

#[test]
fn hertz_sphere_geometry_sets_and_convergence() {
    let base = HertzSphereSpec {
        block_width: 30.0,
        block_height: 15.0,
        fine_size: 1.0,
        fine_half_width: 2.0,
        growth: 1.3,
        gap: 0.1,
        ..HertzSphereSpec::default()
    };
    let r = base.radius;
    let mut errors = Vec::new();
    let mut area_errors = Vec::new();
    println!(
        "hertz_sphere R={r} h_c={} c_zone={}:",
        base.fine_size, base.fine_half_width
    );
    for level in 0..3 {
        let spec = HertzSphereSpec {
            level,
            ..base.clone()
        };
        let mesh = hertz_sphere(&spec).unwrap();
        mesh.validate().unwrap();
        assert_eq!(mesh.bodies, vec!["block".to_string(), "sphere".to_string()]);
        assert_conforming_and_covered(&mesh, &SPHERE_SURFACE);
        assert_sets_outward(&mesh);
        let w = spec.block_width;
        assert!(rel_err(body_volume(&mesh, "block"), w * w * spec.block_height) < 1e-12);
        assert!(rel_err(mesh.facet_set_area("block.top").unwrap(), w * w) < 1e-12);
        assert_set_normal(&mesh, "block.top", [0.0, 0.0, 1.0]);
        assert_set_normal(&mesh, "block.ymin", [0.0, -1.0, 0.0]);
        assert_set_normal(&mesh, "sphere.top", [0.0, 0.0, 1.0]);
        let centre = [0.0, 0.0, r + spec.gap];
        for f in mesh.facet_set("sphere.curved").unwrap() {
            let n = mesh.facet_normal(f).unwrap();
            let radial = sub(mesh.facet_centroid(f).unwrap(), centre);
            assert!(dot(n, radial) > 0.95 * norm(radial), "{f:?}: {n:?}");
        }
        // Every curved node is on the sphere.
        for &node in mesh.node_set("sphere.curved").unwrap() {
            assert!(rel_err(norm(sub(mesh.nodes[node], centre)), r) < 1e-12);
        }
        let exact = 2.0 / 3.0 * PI * r * r * r;
        errors.push((exact - body_volume(&mesh, "sphere")) / exact);
        let top_area = mesh.facet_set_area("sphere.top").unwrap();
        area_errors.push((PI * r * r - top_area) / (PI * r * r));
        assert_eq!(mesh.node_set("sphere.axis").unwrap().len(), 1);
        assert_eq!(mesh.node_set("sphere.tip").unwrap().len(), 1);

        let sj_sphere = body_min_scaled_jacobian(&mesh, "sphere");
        let (sphere_edges, block_edges) =
            contact_sizes(&mesh, "sphere.tip", "sphere.curved", [0.0; 3]);
        let expected = spec.fine_size / f64::from(1u32 << level);
        println!(
            "  level {level}: {} cells, min scaled Jacobian sphere {sj_sphere:.4}, contact size sphere {:.5} block {:.5}, volume error {:.3e}",
            mesh.num_cells(),
            sphere_edges[0],
            block_edges[0],
            errors[level as usize]
        );
        assert!(sj_sphere > 0.5, "level {level}: {sj_sphere}");
        for e in sphere_edges.iter().chain(&block_edges) {
            assert!(
                rel_err(*e, expected) < 0.02,
                "contact edge {e} vs {expected}"
            );
        }
    }
    for e in [&errors, &area_errors] {
        assert!(e[0] > 0.0 && e[0] < 0.02, "{e:?}");
        for pair in e.windows(2) {
            let rate = pair[0] / pair[1];
            assert!((3.5..4.5).contains(&rate), "{e:?}");
        }
    }
}

#[test]
fn hertz_specs_are_checked() {
    let err = hertz_cylinder(&HertzCylinderSpec {
        radius: -1.0,
        ..HertzCylinderSpec::default()
    })
    .unwrap_err();
    assert!(
        matches!(&err, MeshError::InvalidSpec { generator: "hertz_cylinder", field, .. } if field == "radius")
    );
    let err = hertz_cylinder(&HertzCylinderSpec {
        fine_half_width: 100.0,
        ..HertzCylinderSpec::default()
    })
    .unwrap_err();
    assert!(err.to_string().contains("fine_half_width"), "{err}");
    let err = hertz_sphere(&HertzSphereSpec {
        fine_size: 0.0,
        ..HertzSphereSpec::default()
    })
    .unwrap_err();
    assert!(err.to_string().contains("fine_size"), "{err}");
    let err = hertz_sphere(&HertzSphereSpec {
        level: 40,
        ..HertzSphereSpec::default()
    })
    .unwrap_err();
    assert!(err.to_string().contains("level"), "{err}");
    let err = hertz_cylinder(&HertzCylinderSpec {
        gap: f64::INFINITY,
        ..HertzCylinderSpec::default()
    })
    .unwrap_err();
    assert!(err.to_string().contains("gap"), "{err}");
}

#[test]
fn hertz_sphere_default_builds() {
    let mesh = hertz_sphere(&HertzSphereSpec::default()).unwrap();
    let count = |body: &str| mesh.body_cells(mesh.body_id(body).unwrap()).count();
    println!(
        "hertz_sphere default: block {} hexes, sphere {} hexes, min scaled Jacobian sphere {:.4}",
        count("block"),
        count("sphere"),
        body_min_scaled_jacobian(&mesh, "sphere")
    );
    assert_conforming_and_covered(&mesh, &SPHERE_SURFACE);
    let exact = 2.0 / 3.0 * PI * 1000.0;
    let err = rel_err(body_volume(&mesh, "sphere"), exact);
    println!("  volume error {err:.3e}");
    assert!(err < 6e-3);
}

//! Deterministic random distortion of a mesh, for patch tests that must not
//! pass merely because the mesh is regular.

use std::collections::HashMap;

use crate::mesh::geometry::{add, dot, scale, sub, Vec3};
use crate::mesh::{Mesh, MeshError};

/// Random node perturbation applied by [`super::stacked_blocks`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Perturbation {
    /// Largest displacement per coordinate as a fraction of the shortest
    /// edge at the node, in [0, 0.3].
    pub fraction: f64,
    /// Seed of the deterministic generator.
    pub seed: u64,
}

/// Largest accepted `fraction`: each node moves less than a third of its
/// shortest edge, so neighbouring nodes cannot swap places.
const MAX_FRACTION: f64 = 0.3;

/// Two boundary facet normals closer than this are the same plane.
const COPLANAR_TOL: f64 = 1e-10;

/// SplitMix64 (Steele, Lea, Flood 2014): tiny, fast, and good enough for
/// geometric jitter; written out so results never depend on a crate version.
struct SplitMix64(u64);

impl SplitMix64 {
    fn next_u64(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^ (z >> 31)
    }

    /// Uniform in [−1, 1), from the top 53 bits.
    fn next_signed_unit(&mut self) -> f64 {
        let unit = (self.next_u64() >> 11) as f64 / (1u64 << 53) as f64;
        2.0 * unit - 1.0
    }
}

/// How a node may move.
#[derive(Debug, Clone, Copy)]
enum Freedom {
    Free,
    /// On a flat part of the boundary: move only within that plane.
    InPlane(Vec3),
    /// On an edge, a corner or a curved surface: stay put.
    Fixed,
}

/// A copy of `mesh` with every interior node moved by a random vector of
/// components up to `fraction` × (shortest edge at the node). Boundary nodes
/// inside flat faces slide within their face; nodes on edges, corners or
/// curved faces stay, so every boundary face keeps its shape and each body
/// its exact volume. Deterministic for a given `seed`.
///
/// Fails if `fraction` is outside [0, 0.3], if the mesh is invalid, or if
/// the result has an inverted cell.
pub fn perturb_interior(mesh: &Mesh, fraction: f64, seed: u64) -> Result<Mesh, MeshError> {
    if !(0.0..=MAX_FRACTION).contains(&fraction) {
        return Err(MeshError::InvalidArgument {
            operation: "perturb_interior",
            argument: "fraction",
            reason: format!("must be in [0, {MAX_FRACTION}] (got {fraction})"),
        });
    }
    mesh.validate()?;
    let sizes = shortest_edges(mesh);
    let freedom = node_freedom(mesh)?;
    let mut rng = SplitMix64(seed);
    let mut out = mesh.clone();
    for (n, p) in out.nodes.iter_mut().enumerate() {
        // Draw for every node so a node's jitter does not depend on the
        // classification of the nodes before it.
        let raw: Vec3 = std::array::from_fn(|_| rng.next_signed_unit());
        let delta = scale(raw, fraction * sizes[n]);
        *p = match freedom[n] {
            Freedom::Free => add(*p, delta),
            Freedom::InPlane(normal) => add(*p, sub(delta, scale(normal, dot(delta, normal)))),
            Freedom::Fixed => *p,
        };
    }
    out.validate()?;
    Ok(out)
}

/// Shortest distance from each node to another node of a cell it belongs
/// to (the shortest incident edge, since diagonals are longer).
fn shortest_edges(mesh: &Mesh) -> Vec<f64> {
    let mut sizes = vec![f64::INFINITY; mesh.num_nodes()];
    for ids in mesh.cells_iter() {
        for (k, &a) in ids.iter().enumerate() {
            for &b in &ids[k + 1..] {
                let d = crate::mesh::geometry::norm(sub(mesh.nodes[a], mesh.nodes[b]));
                sizes[a] = sizes[a].min(d);
                sizes[b] = sizes[b].min(d);
            }
        }
    }
    // Nodes in no cell have no size and are left where they are.
    sizes
        .iter()
        .map(|s| if s.is_finite() { *s } else { 0.0 })
        .collect()
}

/// Classifies nodes by the unit normals of the boundary facets around them.
fn node_freedom(mesh: &Mesh) -> Result<Vec<Freedom>, MeshError> {
    let mut normals: HashMap<usize, Vec<Vec3>> = HashMap::new();
    for f in mesh.boundary_facets() {
        let normal = mesh.facet_normal(&f)?;
        for n in mesh.facet_nodes_iter(&f)? {
            normals.entry(n).or_default().push(normal);
        }
    }
    let mut freedom = vec![Freedom::Free; mesh.num_nodes()];
    for (n, list) in normals {
        freedom[n] = classify_boundary_node(&list);
    }
    Ok(freedom)
}

fn classify_boundary_node(normals: &[Vec3]) -> Freedom {
    match normals.first() {
        Some(&first) if normals.iter().all(|&m| dot(m, first) >= 1.0 - COPLANAR_TOL) => {
            Freedom::InPlane(first)
        }
        _ => Freedom::Fixed,
    }
}

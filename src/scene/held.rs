//! Which bodies of a static scene are held, i.e. have no rigid-body modes.
//!
//! A body is held when a Dirichlet condition touches it, when it is the
//! slave of a pair with a rigid master, or when a contact pair joins it to
//! a body that is held (transitively). Contact between two bodies that
//! nothing holds does not hold either of them: together they still float.
use crate::mesh::Mesh;
use crate::model::{DirichletSpec, MasterSpec, PairSpec};

/// What holds nothing: the bodies (indices, ascending) of the first group
/// joined by contact in which no body is held.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Unheld {
    pub bodies: Vec<usize>,
    /// Whether the group has contact pairs (else it is one lone body).
    pub in_contact: bool,
}

/// The first group of bodies (joined by contact pairs) that nothing holds.
pub fn unheld_group(
    mesh: &Mesh,
    dirichlet: &[DirichletSpec],
    contact: &[PairSpec],
) -> Option<Unheld> {
    let n = mesh.bodies.len();
    let mut held = vec![false; n];
    let node_body = node_bodies(mesh);
    for d in dirichlet.iter().filter(|d| !d.components.is_empty()) {
        for &node in &d.nodes {
            if let Some(h) = node_body.get(node).and_then(|&b| held.get_mut(b)) {
                *h = true;
            }
        }
    }
    let mut groups = Groups::new(n);
    let mut touched = vec![false; n];
    for p in contact {
        let Some(slave) = body_of_set(mesh, &p.slave) else {
            continue;
        };
        touched[slave] = true;
        match &p.master {
            MasterSpec::Surface { set } => {
                if let Some(master) = body_of_set(mesh, set) {
                    touched[master] = true;
                    groups.join(slave, master);
                }
            }
            // A rigid surface is fixed in space (or moves as prescribed).
            _ => held[slave] = true,
        }
    }
    let mut group_held = vec![false; n];
    for b in (0..n).filter(|&b| held[b]) {
        group_held[groups.root(b)] = true;
    }
    let first = (0..n).find(|&b| !group_held[groups.root(b)])?;
    let root = groups.root(first);
    let bodies: Vec<usize> = (0..n).filter(|&b| groups.root(b) == root).collect();
    let in_contact = bodies.iter().any(|&b| touched[b]);
    Some(Unheld { bodies, in_contact })
}

/// The body of every node (the body of a cell using it).
fn node_bodies(mesh: &Mesh) -> Vec<usize> {
    let mut node_body = vec![usize::MAX; mesh.num_nodes()];
    for c in 0..mesh.num_cells() {
        for &node in mesh.cell(c) {
            node_body[node] = mesh.cell_body[c] as usize;
        }
    }
    node_body
}

/// The body a facet set lies on (its first facet's cell).
fn body_of_set(mesh: &Mesh, set: &str) -> Option<usize> {
    mesh.facet_sets
        .get(set)?
        .first()
        .map(|f| mesh.cell_body[f.cell] as usize)
}

/// Disjoint sets of bodies (union–find; a handful of bodies, no ranks).
struct Groups {
    parent: Vec<usize>,
}

impl Groups {
    fn new(n: usize) -> Self {
        Groups {
            parent: (0..n).collect(),
        }
    }

    fn root(&self, mut b: usize) -> usize {
        while self.parent[b] != b {
            b = self.parent[b];
        }
        b
    }

    fn join(&mut self, a: usize, b: usize) {
        let (ra, rb) = (self.root(a), self.root(b));
        // The smaller index stays the root, so the answer is deterministic.
        let (keep, drop) = (ra.min(rb), ra.max(rb));
        self.parent[drop] = keep;
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mesh::generate::{graded_box, stacked_blocks, BoxSpec, StackedSpec};
    use crate::model::RigidSurface;

    fn fixed(mesh: &Mesh, set: &str) -> DirichletSpec {
        DirichletSpec::uniform(set, mesh.node_sets[set].clone(), vec![0, 1, 2], [0.0; 3])
    }

    fn pair(slave: &str, master: &str) -> PairSpec {
        PairSpec::new("p", slave, MasterSpec::Surface { set: master.into() })
    }

    #[test]
    fn contact_with_a_held_body_holds_and_floating_pairs_do_not() {
        let mesh = stacked_blocks(&StackedSpec::default()).unwrap();
        let (lower, upper) = (0, 1);
        assert_eq!(mesh.bodies[lower], "lower");
        let pairs = [pair("lower.top", "upper.bottom")];
        // Held through contact with a held body.
        let d = [fixed(&mesh, "lower.bottom")];
        assert_eq!(unheld_group(&mesh, &d, &pairs), None);
        // Also when the held body is the master.
        let d = [fixed(&mesh, "upper.top")];
        assert_eq!(unheld_group(&mesh, &d, &pairs), None);
        // Two bodies held by nothing but each other: one group, reported.
        assert_eq!(
            unheld_group(&mesh, &[], &pairs),
            Some(Unheld {
                bodies: vec![lower, upper],
                in_contact: true
            })
        );
        // No contact at all: the free body alone.
        let d = [fixed(&mesh, "lower.bottom")];
        assert_eq!(
            unheld_group(&mesh, &d, &[]),
            Some(Unheld {
                bodies: vec![upper],
                in_contact: false
            })
        );
        // A Dirichlet condition with no components holds nothing.
        let mut empty = fixed(&mesh, "lower.bottom");
        empty.components.clear();
        assert!(unheld_group(&mesh, &[empty], &pairs).is_some());
    }

    #[test]
    fn a_rigid_master_holds_its_slave() {
        let mesh = graded_box(&BoxSpec::default()).unwrap();
        let plane = RigidSurface::Plane {
            point: [0.0; 3],
            normal: [0.0, 0.0, 1.0],
        };
        let pairs = [PairSpec::new("p", "block.bottom", MasterSpec::Rigid(plane))];
        assert_eq!(unheld_group(&mesh, &[], &pairs), None);
        assert!(unheld_group(&mesh, &[], &[]).is_some());
    }
}

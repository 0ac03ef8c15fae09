//! Building a mortar pair on one rank: the slave facets it evaluates (see
//! `share`), the nodal slots with their areas, element sizes and penalties,
//! and which of them this rank completes and owns.
use super::holding::Holding;
use super::master::{FacetSide, Master, RigidSide};
use super::pair::MortarPair;
use super::segment::MortarRules;
use super::share;
use super::system::NodalData;
use super::tangential::PairFriction;
use super::{facet_shape, MAX_FACET_NODES};
use crate::assembly::RankExchange;
use crate::contact::master::MasterSide;
use crate::contact::surfaces::{reference_weights, SlaveSurface};
use crate::distribution::LocalMesh;
use crate::dofs::{DofMap, GlobalDof, LocalNode, NaturalNode, DIM};
use crate::error::{Error, Result};
use crate::fem::QuadRule;
use crate::model::{FrictionSpec, MasterSpec, PairSpec};

fn facet_row(nodes: &[u32]) -> [u32; MAX_FACET_NODES] {
    let mut row = [0; MAX_FACET_NODES];
    row[..nodes.len()].copy_from_slice(nodes);
    row
}

/// Shortest edge of a facet.
fn shortest_edge(x: &[[f64; 3]]) -> f64 {
    (0..x.len())
        .map(|i| {
            crate::contact::autodiff::norm(&crate::contact::autodiff::sub(
                &x[i],
                &x[(i + 1) % x.len()],
            ))
        })
        .fold(f64::INFINITY, f64::min)
}

impl MortarPair {
    /// `(slave, master)`: the pair's slave surface and master side on this
    /// rank, and the ranks the set-up exchanges with (collective);
    /// `penalty(h)`: the pair's εN for a node of element size `h`;
    /// `friction`: the pair's Coulomb friction, if it computes any (μ > 0);
    /// `(margin, reach)`: the candidates' search margin and the distance
    /// within which nodes are reserved for the contact DOFs (see
    /// [`MortarPair::reserved_dofs`]).
    #[allow(clippy::too_many_arguments)]
    pub(super) fn build(
        mesh: &LocalMesh,
        dofs: &DofMap,
        spec: &PairSpec,
        (slave, master, ranks): (SlaveSurface, MasterSide, &dyn RankExchange),
        penalty: impl Fn(f64) -> f64,
        (search_distance, reach): (f64, f64),
        friction: Option<FrictionSpec>,
    ) -> Result<Self> {
        let facet_type = slave.facet_type;
        let nf = facet_type.nodes();
        let master_set = match &spec.master {
            MasterSpec::Surface { set } => Some(set.as_str()),
            MasterSpec::Rigid(_) => None,
        };
        let share = share::slave_share(mesh, dofs, &spec.slave, master_set, ranks)?;
        // Slave node ids in natural order.
        let mut nodes: Vec<(u64, [GlobalDof; DIM], [f64; 3])> = share
            .facets
            .iter()
            .flat_map(|f| {
                (0..nf).map(move |a| {
                    let d = [0, 1, 2].map(|c| f.dofs[DIM * a + c]);
                    (f.natural[a], d, f.x_ref[a])
                })
            })
            .collect();
        nodes.sort_by_key(|v| v.0);
        nodes.dedup_by_key(|v| v.0);
        let n_slave = nodes.len();
        let id_of = |v: u64| nodes.binary_search_by_key(&v, |e| e.0).unwrap_or(0) as u32;
        let slave_facets: Vec<_> = share
            .facets
            .iter()
            .map(|f| {
                facet_row(
                    &f.natural[..nf]
                        .iter()
                        .map(|&v| id_of(v))
                        .collect::<Vec<_>>(),
                )
            })
            .collect();
        let slave_set_index = share.facets.iter().map(|f| f.set_index).collect();
        let assembled = share.assembled;
        let local: Vec<Option<LocalNode>> = nodes
            .iter()
            .map(|v| dofs.local(NaturalNode(v.0 as usize)))
            .collect();
        let n_local = dofs.num_local_nodes();
        let mut slave_tail = Vec::new();
        let node_local: Vec<u32> = local
            .iter()
            .enumerate()
            .map(|(id, l)| match l {
                Some(l) => l.to_u32(),
                None => {
                    slave_tail.push(id as u32);
                    (n_local + slave_tail.len() - 1) as u32
                }
            })
            .collect();
        let x_ref: Vec<[f64; 3]> = nodes.iter().map(|v| v.2).collect();
        // A rank evaluates the nodes of its own facets and the slave nodes
        // it owns: the owner of a node (a rank among the cells holding
        // it) may hold none of its slave facets (a tet touching the
        // surface at that node only), yet it is the one that writes the
        // node's fields.
        let mut mine: Vec<bool> = local
            .iter()
            .map(|l| l.is_some_and(|l| dofs.is_owned(l)))
            .collect();
        for (f, _) in slave_facets.iter().zip(&assembled).filter(|(_, a)| **a) {
            for &n in &f[..nf] {
                mine[n as usize] = true;
            }
        }
        let evaluated: Vec<u32> = (0..slave_facets.len() as u32)
            .filter(|&f| {
                slave_facets[f as usize][..nf]
                    .iter()
                    .any(|&n| mine[n as usize])
            })
            .collect();
        // Nodal reference areas ∫ N_j dA₀ and element sizes.
        let rule = QuadRule::default_for_facet(facet_type);
        let (mut area, mut h_sum, mut h_count) = (
            vec![0.0; n_slave],
            vec![0.0; n_slave],
            vec![0usize; n_slave],
        );
        let mut in_evaluated = vec![false; n_slave];
        for &f in &evaluated {
            let nodes = &slave_facets[f as usize][..nf];
            let x: Vec<[f64; 3]> = nodes.iter().map(|&n| x_ref[n as usize]).collect();
            let weights = reference_weights(facet_type, &x, &rule);
            let h = shortest_edge(&x);
            for (zeta, w) in weights {
                let s = facet_shape(facet_type, zeta);
                for (a, &n) in nodes.iter().enumerate() {
                    area[n as usize] += s.n[a] * w;
                }
            }
            for &n in nodes {
                h_sum[n as usize] += h;
                h_count[n as usize] += 1;
                in_evaluated[n as usize] = true;
            }
        }
        let slots: Vec<u32> = (0..n_slave as u32)
            .filter(|&n| in_evaluated[n as usize])
            .collect();
        let h: Vec<f64> = slots
            .iter()
            .map(|&n| h_sum[n as usize] / h_count[n as usize] as f64)
            .collect();
        let complete = slots.iter().map(|&n| mine[n as usize]).collect();
        let owned = slots
            .iter()
            .map(|&n| mine[n as usize] && local[n as usize].is_some_and(|l| dofs.is_owned(l)))
            .collect();
        let nodal = NodalData::new(
            slots.clone(),
            vec![0.0; slots.len()],
            h.iter().map(|&h| penalty(h)).collect(),
            slots.iter().map(|&n| area[n as usize]).collect(),
        );
        if let Some(bad) = nodal.area.iter().position(|a| a.is_nan() || *a <= 0.0) {
            return Err(Error::scene(
                "contact",
                format!(
                    "pair '{}': slave node {} has no contact area",
                    spec.name, nodes[slots[bad] as usize].0
                ),
            ));
        }
        let master = match master {
            MasterSide::Facets(held) => Master::Facets(FacetSide {
                held,
                facets: Vec::new(),
                set_index: Vec::new(),
            }),
            MasterSide::Rigid(r) => Master::Rigid(RigidSide::new(r, &slots, &h_count)),
        };
        let natural: Vec<usize> = nodes.iter().map(|v| v.0 as usize).collect();
        let restart_rows = natural
            .iter()
            .copied()
            .chain(
                share
                    .owned_pair_nodes
                    .iter()
                    .map(|&(l, _)| dofs.natural(LocalNode::from_u32(l)).0),
            )
            .collect();
        let node_dofs = nodes.iter().map(|v| v.1).collect();
        let friction = friction.map(|f| PairFriction::new(f, &nodal.penalty, &x_ref));
        Ok(MortarPair {
            name: spec.name.clone(),
            slave,
            master,
            tangent_signature: 0,
            main_part_tangent: false,
            facet_type,
            n_slave,
            node_local,
            node_dofs,
            x_ref,
            slave_facets,
            slave_set_index,
            assembled,
            evaluated,
            nodal,
            complete,
            owned,
            h,
            candidates: Vec::new(),
            candidate_key: Vec::new(),
            search_distance,
            reach,
            reserve: Vec::new(),
            rules: MortarRules::default(),
            owned_mesh_nodes: dofs.num_owned_nodes(),
            owned_pair_nodes: share.owned_pair_nodes,
            friction,
            natural,
            holding: Holding {
                slave_tail,
                ..Holding::default()
            },
            restart_rows,
            pending_origins: None,
        })
    }
}

//! What one rank holds of a mortar pair, and the exchanges that give it.
//!
//! Slave side (decided once, at set-up). A rank assembles the slave facets
//! of its own cells. The weighted gap `g̃_j` of a node, and with it the
//! pressure every one of its facets' forces carries, sums over every facet
//! around the node, so the rank also evaluates the other ranks' facets that
//! share a node with one of its own, or that hold a slave node it owns (the
//! owner writes the node's fields even when none of its facets holds it: a
//! tet touching the surface at that node only). These come in two rounds of
//! messages addressed by node owner: each rank sends every own facet to the
//! owners of its nodes, so the owner of a node learns every facet around
//! it; each owner then sends back, to every rank that sent it a facet
//! around one of its nodes, all the facets around that node. Every rank
//! that holds node `j` then integrates the same facets in the same order
//! (by set index) from the same positions and gets the same `g̃_j` and the
//! same update of `λ_j` bit for bit; the owner counts and writes it.
//!
//! Master side (at a search, when the bodies have moved). The master facets
//! a rank holds are decided by the links' box exchange
//! ([`crate::contact::held_master`]): the box of the rank's slave nodes,
//! grown by the search distance, one more search distance of slack and the
//! largest slave facet (a facet evaluated for a neighbour reaches that far
//! beyond the nodes this rank sees). Candidates only need the search
//! distance, so the held set stays valid until some node has moved by a
//! quarter of the slack since the exchange (a facet and the slave box then
//! close in by at most half of it, and a slave facet grows by at most the
//! other half); only then is it exchanged again.
//!
//! Nodes the rank does not see itself (other ranks' slave facets' nodes,
//! held master nodes) take slots after the local nodes, in the tail the
//! solver fills by a scatter: the pair's slave tail first, then its master's.
use super::master::Master;
use super::pair::MortarPair;
use super::MAX_FACET_NODES;
use crate::assembly::RankExchange;
use crate::contact::held_master::{self, record, MasterFacet};
use crate::contact::surfaces::contact_facet_type;
use crate::distribution::LocalMesh;
use crate::dofs::{DofMap, GlobalDof, LocalNode, NaturalNode, DIM};
use crate::error::{Error, Result};
use std::collections::{BTreeMap, BTreeSet};

/// What a rank holds of the slave side, and the owned nodes of the pair.
pub(super) struct SlaveShare {
    /// The slave facets this rank evaluates, by ascending set index.
    pub facets: Vec<MasterFacet>,
    /// Per facet: one of this rank's own (its forces are assembled here).
    pub assembled: Vec<bool>,
    /// Owned nodes on either surface: local index and reference position.
    pub owned_pair_nodes: Vec<(u32, [f64; 3])>,
}

/// This rank's facets of `set` as travelling records.
fn own_records(mesh: &LocalMesh, dofs: &DofMap, set: &str) -> Result<Vec<MasterFacet>> {
    let refs = mesh
        .facet_set(set)
        .ok_or_else(|| Error::scene("contact", format!("facet set '{set}' does not exist")))?;
    let n = contact_facet_type(mesh, set)?.nodes();
    Ok(refs
        .facets
        .iter()
        .map(|f| {
            let mut facet = MasterFacet::empty(f.set_index as u32);
            for (a, &l) in f.nodes.iter().enumerate().take(n) {
                let l = LocalNode::from_u32(l);
                facet.natural[a] = dofs.natural(l).0 as u64;
                facet.x_ref[a] = mesh.nodes[l.index()];
                facet.dofs[DIM * a..DIM * (a + 1)].copy_from_slice(&dofs.node_dofs(l));
            }
            facet
        })
        .collect())
}

/// The rank owning each global DOF: the DOFs are numbered contiguously per
/// rank. Collective.
struct Owners(Vec<usize>);

impl Owners {
    fn new(dofs: &DofMap, ranks: &dyn RankExchange) -> Self {
        let starts = ranks.all_gather(&[dofs.owned_dof_start() as f64]);
        Owners(starts.iter().map(|&s| s as usize).collect())
    }

    fn of(&self, dof: GlobalDof) -> usize {
        let d = dof.0 as usize;
        self.0.partition_point(|&s| s <= d).saturating_sub(1)
    }
}

/// Records `(from rank, facet)` as one message's f64 values.
fn encode_from(from: usize, f: &MasterFacet, nodes: usize, out: &mut Vec<f64>) {
    out.push(from as f64);
    held_master::encode(f, nodes, out);
}

fn decode_from(values: &[f64], nodes: usize) -> Vec<(usize, MasterFacet)> {
    values
        .chunks_exact(1 + record(nodes))
        .map(|r| (r[0] as usize, held_master::decode(&r[1..], nodes).remove(0)))
        .collect()
}

/// The slave facets this rank evaluates and the pair's owned nodes (see the
/// module doc). Collective.
pub(super) fn slave_share(
    mesh: &LocalMesh,
    dofs: &DofMap,
    slave: &str,
    master: Option<&str>,
    ranks: &dyn RankExchange,
) -> Result<SlaveShare> {
    let nf = contact_facet_type(mesh, slave)?.nodes();
    let own = own_records(mesh, dofs, slave)?;
    let owners = Owners::new(dofs, ranks);
    let (me, size) = (ranks.rank(), ranks.size());
    let node_owner = |f: &MasterFacet, a: usize| owners.of(f.dofs[DIM * a]);
    // Round 1: every own facet to the owners of its nodes.
    let mut send = vec![Vec::new(); size];
    for f in &own {
        let to: BTreeSet<usize> = (0..nf).map(|a| node_owner(f, a)).collect();
        for r in to.into_iter().filter(|&r| r != me) {
            encode_from(me, f, nf, &mut send[r]);
        }
    }
    let first = decode_from(&ranks.all_to_all(&send), nf);
    // Every facet around each owned node, as far as this rank knows them
    // (after round 1: all of them).
    let known: Vec<&MasterFacet> = own.iter().chain(first.iter().map(|(_, f)| f)).collect();
    let mut around: BTreeMap<u64, Vec<usize>> = BTreeMap::new();
    for (k, f) in known.iter().enumerate() {
        for a in (0..nf).filter(|&a| node_owner(f, a) == me) {
            around.entry(f.natural[a]).or_default().push(k);
        }
    }
    // Round 2: back to each sender, every facet around the owned nodes of
    // the facets it sent.
    let mut back: Vec<BTreeSet<usize>> = vec![BTreeSet::new(); size];
    for (from, f) in &first {
        for a in (0..nf).filter(|&a| node_owner(f, a) == me) {
            back[*from].extend(around.get(&f.natural[a]).into_iter().flatten());
        }
    }
    let send: Vec<Vec<f64>> = back
        .iter()
        .map(|ks| {
            let mut out = Vec::new();
            for &k in ks {
                held_master::encode(known[k], nf, &mut out);
            }
            out
        })
        .collect();
    let second = held_master::decode(&ranks.all_to_all(&send), nf);
    let own_set: BTreeSet<u32> = own.iter().map(|f| f.set_index).collect();
    let mut facets: Vec<MasterFacet> = own
        .iter()
        .cloned()
        .chain(first.into_iter().map(|(_, f)| f))
        .chain(second)
        .collect();
    facets.sort_by_key(|f| f.set_index);
    facets.dedup_by_key(|f| f.set_index);
    let assembled = facets
        .iter()
        .map(|f| own_set.contains(&f.set_index))
        .collect();
    // Owned master nodes: each own master facet's nodes to their owners.
    let owned_local = |nat: u64| {
        dofs.local(NaturalNode(nat as usize))
            .filter(|&l| dofs.is_owned(l))
    };
    let mut owned: BTreeSet<u32> = BTreeSet::new();
    for f in &facets {
        owned.extend((0..nf).filter_map(|a| owned_local(f.natural[a]).map(LocalNode::to_u32)));
    }
    let masters = match master {
        Some(set) => own_records(mesh, dofs, set)?,
        None => Vec::new(),
    };
    let mut send = vec![Vec::new(); size];
    for f in &masters {
        for a in 0..nf {
            let r = node_owner(f, a);
            if r == me {
                owned.extend(owned_local(f.natural[a]).map(LocalNode::to_u32));
            } else {
                send[r].push(f.natural[a] as f64);
            }
        }
    }
    for nat in ranks.all_to_all(&send) {
        owned.extend(owned_local(nat as u64).map(LocalNode::to_u32));
    }
    let owned_pair_nodes = owned
        .into_iter()
        .map(|l| (l, mesh.nodes[l as usize]))
        .collect();
    Ok(SlaveShare {
        facets,
        assembled,
        owned_pair_nodes,
    })
}

impl MortarPair {
    /// Before a search: refreshes the master facets this rank holds when the
    /// bodies have moved by more than a quarter of the slack since the last
    /// exchange
    /// (or never exchanged), and numbers the tail from `tail_base`. `u_local`
    /// covers the local nodes only. Returns the tail nodes the pair uses.
    /// Collective.
    pub(super) fn exchange(
        &mut self,
        u_local: &[f64],
        dofs: &DofMap,
        tail_base: usize,
        ranks: &dyn RankExchange,
    ) -> usize {
        let n_local = dofs.num_local_nodes();
        let u = |l: u32| LocalNode::from_u32(l).value(u_local);
        // Motion since the last exchange: every pair node is some rank's.
        let moved = self
            .owned_pair_nodes
            .iter()
            .zip(&self.holding.u_at_exchange)
            .map(|((l, _), u0)| crate::vec3::distance2(u(*l), *u0).sqrt())
            .fold(0.0, f64::max);
        let nf = self.facet_type.nodes();
        let size = (0..self.slave_facets.len())
            .filter(|&f| self.assembled[f])
            .map(|f| {
                let x: Vec<[f64; 3]> = self.slave_facets[f][..nf]
                    .iter()
                    .map(|&n| self.position(n, u_local))
                    .collect();
                diameter(&x)
            })
            .fold(0.0, f64::max);
        let all = ranks.all_gather(&[moved, size]);
        let (moved, size) = all
            .chunks_exact(2)
            .fold((0.0f64, 0.0f64), |(m, s), r| (m.max(r[0]), s.max(r[1])));
        let slack = self.search_distance;
        let first = self.holding.tail_base.is_none();
        // Slave tail slots follow the base.
        let n_slave_tail = self.holding.slave_tail.len();
        for (k, &id) in self.holding.slave_tail.iter().enumerate() {
            self.node_local[id as usize] = (n_local + tail_base + k) as u32;
        }
        let master_base = tail_base + n_slave_tail;
        let n_slave = self.n_slave;
        if matches!(self.master, Master::Rigid(_)) {
            self.holding.tail_base = Some(tail_base);
            self.holding.tail_dofs = self.slave_tail_dofs();
            return n_slave_tail;
        }
        if first || moved > 0.25 * slack {
            // The local slave nodes' current positions.
            let points: Vec<[f64; 3]> = (0..n_slave as u32)
                .filter(|&n| (self.node_local[n as usize] as usize) < n_local)
                .map(|n| self.position(n, u_local))
                .collect();
            let margin = self.search_distance + slack + size;
            if let Master::Facets(m) = &mut self.master {
                m.held
                    .exchange(&points, margin, u_local, dofs, master_base, ranks);
            }
            self.hold_master(n_slave);
            self.holding.u_at_exchange = self.owned_pair_nodes.iter().map(|(l, _)| u(*l)).collect();
        } else if let Some(old) = self.holding.tail_base {
            // The same facets; earlier pairs' tails may have changed size.
            let (old, new) = (old + n_slave_tail, master_base);
            for l in &mut self.node_local[n_slave..] {
                if *l as usize >= n_local {
                    *l = (*l as usize - old + new) as u32;
                }
            }
        }
        self.holding.tail_base = Some(tail_base);
        let mut tail = self.slave_tail_dofs();
        let held = match &self.master {
            Master::Facets(m) => m.held.tail_nodes(),
            Master::Rigid(_) => 0,
        };
        if let Master::Facets(m) = &self.master {
            tail.extend_from_slice(&m.held.tail_dofs);
        }
        self.holding.tail_dofs = tail;
        n_slave_tail + held
    }

    fn slave_tail_dofs(&self) -> Vec<GlobalDof> {
        self.holding
            .slave_tail
            .iter()
            .flat_map(|&id| self.node_dofs[id as usize])
            .collect()
    }

    /// Takes over the held master's nodes (ids after the `n_slave` slave
    /// nodes) and facets.
    fn hold_master(&mut self, n_slave: usize) {
        let Master::Facets(side) = &mut self.master else {
            return;
        };
        let held = &side.held;
        let offset = n_slave as u32;
        self.node_local.truncate(n_slave);
        self.node_local.extend(&held.node_local);
        self.x_ref.truncate(n_slave);
        self.x_ref.extend(&held.x_ref);
        self.node_dofs.truncate(n_slave);
        self.node_dofs.extend(&held.node_dofs);
        self.natural.truncate(n_slave);
        self.natural
            .extend(held.natural_ids().iter().map(|&v| v as usize));
        let nf = self.facet_type.nodes();
        side.facets = held
            .facets
            .iter()
            .map(|f| {
                let mut row = [0; MAX_FACET_NODES];
                for (r, &n) in row.iter_mut().zip(&f[..nf]) {
                    *r = n + offset;
                }
                row
            })
            .collect();
        side.set_index = held.set_index.clone();
        if let Some(f) = &mut self.friction {
            for v in [&mut f.start, &mut f.last] {
                v.truncate(n_slave);
                v.extend(&held.x_ref);
            }
        }
        // The master numbering changed: the search finds the candidates anew.
        self.candidates.clear();
    }

    /// Global DOFs of the pair's tail (slave, then master), node-major.
    pub fn tail_dofs(&self) -> &[GlobalDof] {
        &self.holding.tail_dofs
    }

    /// A frictional pair measures the step's slip from the last converged
    /// state: `u_committed` is it (extended like every local array), taken
    /// at the search, so nodes held since are measured from where they were.
    pub fn start_slip_from(&mut self, u_committed: &[f64]) {
        if self.friction.is_some() {
            let x = self.positions(u_committed);
            if let Some(f) = &mut self.friction {
                f.start = x;
            }
        }
    }
}

fn diameter(x: &[[f64; 3]]) -> f64 {
    let mut d: f64 = 0.0;
    for a in x {
        for b in x {
            d = d.max(crate::vec3::distance2(*a, *b).sqrt());
        }
    }
    d
}

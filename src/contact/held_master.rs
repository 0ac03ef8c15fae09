//! The master facets of a links pair that one rank holds (a deformable
//! master, docs/formulation.md §11 "Parallel model").
//!
//! Each rank owns the master facets of its own cells. At every contact
//! search the ranks exchange bounding boxes: each rank's box holds its slave
//! points (current positions) inflated by the pair's search distance plus the
//! largest master facet, and every rank sends each other rank the own facets
//! whose current box meets that rank's box. A rank then holds its own facets
//! inside its box and the ones it received, and searches only those. The
//! margin covers the search distance (every facet a point can link to) plus
//! one facet (the patch of facets around the linked one, which the link may
//! slide onto during the step), so the search finds what it would find on
//! the whole master, on any number of ranks.
//!
//! Held nodes are numbered after this rank's local nodes where the rank does
//! not see them itself: the displacement array contact reads is the local
//! form followed by a tail over those nodes (which `solve` fills by a
//! scatter from the global vector), and residual entries of tail nodes go
//! back to their owners by the same scatter in reverse.
use crate::assembly::RankExchange;
use crate::contact::search;
use crate::contact::MAX_FACET_NODES;
use crate::distribution::LocalMesh;
use crate::dofs::{DofMap, GlobalDof, LocalNode, NaturalNode, DIM};
use crate::error::{Error, Result};
use crate::fem::FacetType;

/// One master facet as this rank knows it, and as it travels between ranks.
#[derive(Debug, Clone, PartialEq)]
pub struct MasterFacet {
    /// Position in the master facet set (identical on every rank).
    pub set_index: u32,
    /// Per node (the facet type's count used, the rest zero).
    pub natural: [u64; MAX_FACET_NODES],
    pub dofs: [GlobalDof; MAX_FACET_NODES * DIM],
    pub x_ref: [[f64; 3]; MAX_FACET_NODES],
}

impl MasterFacet {
    /// Facet `set_index` with every node slot zero.
    pub fn empty(set_index: u32) -> Self {
        MasterFacet {
            set_index,
            natural: [0; MAX_FACET_NODES],
            dofs: [GlobalDof(0); MAX_FACET_NODES * DIM],
            x_ref: [[0.0; 3]; MAX_FACET_NODES],
        }
    }
}

/// f64 values per facet of `nodes` nodes in a message: set index, natural
/// ids, DOFs and reference coordinates (integers below 2⁵³ are exact). A
/// message carries one facet type, so first-order facets travel without
/// second-order slots.
pub const fn record(nodes: usize) -> usize {
    1 + nodes * (1 + 2 * DIM)
}

type Aabb = ([f64; 3], [f64; 3]);

/// A box that meets nothing (a rank without slave points).
pub const EMPTY_BOX: Aabb = ([f64::INFINITY; 3], [f64::NEG_INFINITY; 3]);

#[derive(Debug, Clone)]
pub struct HeldMaster {
    pub facet_type: FacetType,
    /// Facets of this rank's cells, by set index, and each one's local nodes.
    own: Vec<MasterFacet>,
    own_local: Vec<[u32; MAX_FACET_NODES]>,
    /// Facets of the whole set (all ranks).
    pub whole: usize,
    /// The largest facet diameter over the whole set.
    pub max_facet_size: f64,
    /// Reference bounding box of the whole set (None: empty set).
    pub reference_box: Option<Aabb>,
    /// The held facets (own inside this rank's box, and received), ordered
    /// by set index so ids and ties go as on the whole set.
    pub set_index: Vec<u32>,
    /// Held facets as indices into the held node arrays (the facet type's
    /// node count used).
    pub facets: Vec<[u32; MAX_FACET_NODES]>,
    /// Held nodes, ordered by natural id.
    natural: Vec<u64>,
    /// Index of each held node in the extended local array.
    pub node_local: Vec<u32>,
    pub node_dofs: Vec<[GlobalDof; DIM]>,
    pub x_ref: Vec<[f64; 3]>,
    /// Global DOFs of the tail (held nodes this rank does not see), node-major.
    pub tail_dofs: Vec<GlobalDof>,
    /// Facets received at the last exchange.
    pub received: usize,
}

impl HeldMaster {
    /// This rank's own facets of `set`, and the set-wide sizes. Collective.
    pub fn new(
        mesh: &LocalMesh,
        dofs: &DofMap,
        set: &str,
        ranks: &dyn RankExchange,
    ) -> Result<Self> {
        let refs = mesh
            .facet_set(set)
            .ok_or_else(|| Error::scene("contact", format!("facet set '{set}' does not exist")))?;
        let facet_type = crate::contact::surfaces::contact_facet_type(mesh, set)?;
        let n = facet_type.nodes();
        let (mut own, mut own_local) = (Vec::new(), Vec::new());
        for f in &refs.facets {
            let mut facet = MasterFacet::empty(f.set_index as u32);
            let mut local = [0u32; MAX_FACET_NODES];
            for (a, &l) in f.nodes.iter().enumerate().take(n) {
                let l = LocalNode::from_u32(l);
                local[a] = l.to_u32();
                facet.natural[a] = dofs.natural(l).0 as u64;
                facet.x_ref[a] = mesh.nodes[l.index()];
                facet.dofs[DIM * a..DIM * (a + 1)].copy_from_slice(&dofs.node_dofs(l));
            }
            own.push(facet);
            own_local.push(local);
        }
        let (lo, hi) = own
            .iter()
            .flat_map(|f| f.x_ref[..n].iter())
            .fold(EMPTY_BOX, |b, x| grow(b, *x));
        let size = own
            .iter()
            .map(|f| diameter(&f.x_ref[..n]))
            .fold(0.0, f64::max);
        let mine = [
            own.len() as f64,
            size,
            lo[0],
            lo[1],
            lo[2],
            hi[0],
            hi[1],
            hi[2],
        ];
        let all = ranks.all_gather(&mine);
        let (mut whole, mut max_facet_size, mut boxed) = (0usize, 0.0f64, EMPTY_BOX);
        for r in all.chunks_exact(mine.len()) {
            whole += r[0] as usize;
            max_facet_size = max_facet_size.max(r[1]);
            boxed = grow(grow(boxed, [r[2], r[3], r[4]]), [r[5], r[6], r[7]]);
        }
        Ok(HeldMaster {
            facet_type,
            own,
            own_local,
            whole,
            max_facet_size,
            reference_box: (whole > 0).then_some(boxed),
            set_index: Vec::new(),
            facets: Vec::new(),
            natural: Vec::new(),
            node_local: Vec::new(),
            node_dofs: Vec::new(),
            x_ref: Vec::new(),
            tail_dofs: Vec::new(),
            received: 0,
        })
    }

    /// A held surface given whole (tests): nodes local 0..n, no tail.
    #[cfg(test)]
    pub fn from_parts(
        facet_type: FacetType,
        x_ref: Vec<[f64; 3]>,
        facets: Vec<[u32; MAX_FACET_NODES]>,
    ) -> Self {
        let n = x_ref.len();
        HeldMaster {
            facet_type,
            own: Vec::new(),
            own_local: Vec::new(),
            whole: facets.len(),
            max_facet_size: 0.0,
            reference_box: None,
            set_index: (0..facets.len() as u32).collect(),
            facets,
            natural: (0..n as u64).collect(),
            node_local: (0..n as u32).collect(),
            node_dofs: vec![[GlobalDof(0); DIM]; n],
            x_ref,
            tail_dofs: Vec::new(),
            received: 0,
        }
    }

    /// Facets of this rank's cells.
    pub fn own_facets(&self) -> usize {
        self.own.len()
    }

    /// The box exchange (see the module doc). `points` are this rank's slave
    /// points, `u_local` the local displacements, `tail_base` the first tail
    /// slot this pair may use after the `n_local` local nodes. Collective.
    pub fn exchange(
        &mut self,
        points: &[[f64; 3]],
        margin: f64,
        u_local: &[f64],
        dofs: &DofMap,
        tail_base: usize,
        ranks: &dyn RankExchange,
    ) {
        let n = self.facet_type.nodes();
        let mine = match search::points_bounding_box(points) {
            Some((lo, hi)) => (lo.map(|v| v - margin), hi.map(|v| v + margin)),
            None => EMPTY_BOX,
        };
        let flat = [mine.0, mine.1].concat();
        let boxes: Vec<Aabb> = ranks
            .all_gather(&flat)
            .chunks_exact(6)
            .map(|b| ([b[0], b[1], b[2]], [b[3], b[4], b[5]]))
            .collect();
        let current: Vec<Aabb> = self
            .own
            .iter()
            .zip(&self.own_local)
            .map(|(f, l)| current_box(self.facet_type, &f.x_ref[..n], &l[..n], u_local))
            .collect();
        let me = ranks.rank();
        let send: Vec<Vec<f64>> = boxes
            .iter()
            .enumerate()
            .map(|(r, b)| {
                if r == me {
                    return Vec::new();
                }
                let mut out = Vec::new();
                for i in select_in_box(&current, *b) {
                    encode(&self.own[i], n, &mut out);
                }
                out
            })
            .collect();
        let received = decode(&ranks.all_to_all(&send), n);
        self.received = received.len();
        let mut held: Vec<MasterFacet> = select_in_box(&current, mine)
            .into_iter()
            .map(|i| self.own[i].clone())
            .chain(received)
            .collect();
        held.sort_by_key(|f| f.set_index);
        held.dedup_by_key(|f| f.set_index);
        self.hold(&held, dofs, tail_base);
    }

    /// Numbers the held facets' nodes and finds the tail.
    fn hold(&mut self, held: &[MasterFacet], dofs: &DofMap, tail_base: usize) {
        let n = self.facet_type.nodes();
        let mut nodes: Vec<(u64, [GlobalDof; DIM], [f64; 3])> = held
            .iter()
            .flat_map(|f| {
                (0..n).map(move |a| {
                    let d = [0, 1, 2].map(|c| f.dofs[DIM * a + c]);
                    (f.natural[a], d, f.x_ref[a])
                })
            })
            .collect();
        nodes.sort_by_key(|v| v.0);
        nodes.dedup_by_key(|v| v.0);
        self.natural = nodes.iter().map(|v| v.0).collect();
        self.x_ref = nodes.iter().map(|v| v.2).collect();
        self.node_dofs = nodes.iter().map(|v| v.1).collect();
        self.tail_dofs.clear();
        let n_local = dofs.num_local_nodes();
        self.node_local = nodes
            .iter()
            .map(|v| match dofs.local(NaturalNode(v.0 as usize)) {
                Some(l) => l.to_u32(),
                None => {
                    let slot = n_local + tail_base + self.tail_dofs.len() / DIM;
                    self.tail_dofs.extend(v.1);
                    slot as u32
                }
            })
            .collect();
        self.set_index = held.iter().map(|f| f.set_index).collect();
        self.facets = held
            .iter()
            .map(|f| {
                let mut ids = [0u32; MAX_FACET_NODES];
                for (slot, v) in ids.iter_mut().zip(&f.natural[..n]) {
                    // Every node of a held facet is held.
                    *slot = self.natural.binary_search(v).unwrap_or(0) as u32;
                }
                ids
            })
            .collect();
    }

    /// The held facet with set index `set_index`, if held.
    pub fn held_facet(&self, set_index: u32) -> Option<u32> {
        self.set_index
            .binary_search(&set_index)
            .ok()
            .map(|i| i as u32)
    }

    /// Natural ids of the held nodes (ascending).
    pub fn natural_ids(&self) -> &[u64] {
        &self.natural
    }

    /// Tail nodes (held nodes this rank does not see).
    pub fn tail_nodes(&self) -> usize {
        self.tail_dofs.len() / DIM
    }

    /// Current positions of the held nodes from the extended local array.
    pub fn positions(&self, u_ext: &[f64]) -> Vec<[f64; 3]> {
        self.x_ref
            .iter()
            .zip(&self.node_local)
            .map(|(xr, &l)| {
                let b = DIM * l as usize;
                [xr[0] + u_ext[b], xr[1] + u_ext[b + 1], xr[2] + u_ext[b + 2]]
            })
            .collect()
    }

    pub fn facet_nodes(&self, facet: u32) -> &[u32] {
        &self.facets[facet as usize][..self.facet_type.nodes()]
    }

    pub fn facet_dofs(&self, facet: u32, out: &mut Vec<GlobalDof>) {
        for &m in self.facet_nodes(facet) {
            out.extend_from_slice(self.held_node_dofs(m));
        }
    }

    /// Slot of held node `m` in the extended local array (a local node, or
    /// past them, a tail slot).
    pub fn extended_slot(&self, m: u32) -> u32 {
        self.node_local[m as usize]
    }

    /// Global DOFs of held node `m`.
    pub fn held_node_dofs(&self, m: u32) -> &[GlobalDof; DIM] {
        &self.node_dofs[m as usize]
    }

    /// Position of held facet `facet` in the whole facet set.
    pub fn set_index_of(&self, facet: u32) -> u32 {
        self.set_index[facet as usize]
    }
}

/// Indices of the facets whose box meets `target`.
pub fn select_in_box(boxes: &[Aabb], target: Aabb) -> Vec<usize> {
    boxes
        .iter()
        .enumerate()
        .filter(|(_, b)| (0..3).all(|c| b.0[c] <= target.1[c] && target.0[c] <= b.1[c]))
        .map(|(i, _)| i)
        .collect()
}

/// The box of a facet's current shape (for a curved facet, of its Bézier
/// control points, see [`search::facet_box`]).
fn current_box(facet_type: FacetType, x_ref: &[[f64; 3]], local: &[u32], u_local: &[f64]) -> Aabb {
    let mut x = [[0.0; 3]; MAX_FACET_NODES];
    for ((o, xr), &l) in x.iter_mut().zip(x_ref).zip(local) {
        let u = LocalNode::from_u32(l).value(u_local);
        *o = [0, 1, 2].map(|c| xr[c] + u[c]);
    }
    search::facet_box(facet_type, &x[..x_ref.len()])
}

fn grow(b: Aabb, x: [f64; 3]) -> Aabb {
    (
        [0, 1, 2].map(|c| b.0[c].min(x[c])),
        [0, 1, 2].map(|c| b.1[c].max(x[c])),
    )
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

/// Appends facet `f`'s first `nodes` nodes as one record (see [`record`]).
pub fn encode(f: &MasterFacet, nodes: usize, out: &mut Vec<f64>) {
    out.push(f.set_index as f64);
    out.extend(f.natural[..nodes].iter().map(|&v| v as f64));
    out.extend(f.dofs[..nodes * DIM].iter().map(|v| v.0 as f64));
    out.extend(f.x_ref[..nodes].iter().flatten());
}

/// The facets of records of `nodes` nodes each.
pub fn decode(values: &[f64], nodes: usize) -> Vec<MasterFacet> {
    let n = nodes.min(MAX_FACET_NODES);
    values
        .chunks_exact(record(n))
        .map(|r| {
            let mut f = MasterFacet::empty(r[0] as u32);
            let (natural, rest) = r[1..].split_at(n);
            let (dofs, x_ref) = rest.split_at(n * DIM);
            for (v, x) in f.natural.iter_mut().zip(natural) {
                *v = *x as u64;
            }
            for (d, x) in f.dofs.iter_mut().zip(dofs) {
                *d = GlobalDof(*x as _);
            }
            for (p, x) in f.x_ref.iter_mut().flatten().zip(x_ref) {
                *p = *x;
            }
            f
        })
        .collect()
}

#[cfg(test)]
mod tests;

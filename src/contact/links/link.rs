//! The links of a load step: the search that makes them at the start of the
//! step, and the following of sliding during its Newton iterations.
use super::LinksPair;
use crate::assembly::RankExchange;
use crate::contact::master::MasterSide;
use crate::contact::projection::{self, Projection};
use crate::contact::search::{self, SearchIndex};
use crate::dofs::DofMap;
use std::collections::hash_map::DefaultHasher;
use std::hash::{Hash, Hasher};

/// One ContactLink3D: a slave quadrature point and its partner on the master.
#[derive(Debug, Clone)]
pub struct Link {
    /// Local slave quadrature point.
    pub qp: u32,
    /// Master facet (deformable masters).
    pub facet: u32,
    pub xi: [f64; 2],
    /// Master facets the link may move to during this step's Newton
    /// iterations (large sliding); the sparsity pattern covers them all.
    pub patch: Vec<u32>,
}

impl Link {
    /// The slave quadrature point, as an index into the slave point arrays.
    pub fn qp_index(&self) -> usize {
        self.qp as usize
    }
}

impl LinksPair {
    /// Before the step's search: the box exchange that decides which master
    /// facets this rank holds (`contact::held_master`), at the same state the
    /// search then runs at. Done at every search, because the search's links
    /// and patches are fixed for the step and must see every facet they may
    /// touch; its cost is one gather of six numbers per rank and the facets
    /// near each rank's slave points. `tail_base` is the first tail slot the
    /// pair may use; returns how many it uses. Collective (every rank calls
    /// it for every pair).
    pub(super) fn exchange(
        &mut self,
        u_local: &[f64],
        dofs: &DofMap,
        tail_base: usize,
        ranks: &dyn RankExchange,
    ) -> usize {
        let MasterSide::Facets(m) = &mut self.master else {
            return 0;
        };
        let points: Vec<[f64; 3]> = (0..self.slave.num_qps())
            .map(|q| self.slave.qp_position(q, u_local))
            .collect();
        // Last step's partners, by set index, across the renumbering.
        let previous: Vec<u32> = self.links.iter().map(|l| m.set_index_of(l.facet)).collect();
        let margin = self.search_distance + m.max_facet_size;
        m.exchange(&points, margin, u_local, dofs, tail_base, ranks);
        let mut kept = Vec::with_capacity(self.links.len());
        for (mut l, f) in std::mem::take(&mut self.links).into_iter().zip(previous) {
            if let Some(facet) = m.held_facet(f) {
                l.facet = facet;
                l.patch.clear();
                kept.push(l);
            }
        }
        self.links = kept;
        self.positions.clear();
        m.tail_nodes()
    }

    /// The search that starts every load step: outer search (closest master
    /// node through the spatial index) and inner search (projection onto the
    /// facets around it) for every slave point. Returns true when the coupling
    /// pattern differs from the previous step's.
    pub(super) fn search_links(&mut self, u_local: &[f64], factor: f64) -> bool {
        let nq = self.slave.num_qps();
        let points: Vec<[f64; 3]> = (0..nq)
            .map(|q| self.slave.qp_position(q, u_local))
            .collect();
        let previous: Vec<Option<(u32, [f64; 2])>> = {
            let mut p = vec![None; nq];
            for l in &self.links {
                p[l.qp_index()] = Some((l.facet, l.xi));
            }
            p
        };
        self.links.clear();
        match &self.master {
            MasterSide::Facets(m) => {
                self.positions = m.positions(u_local);
                let surface = search::SearchSurface {
                    facet_type: m.facet_type,
                    positions: &self.positions,
                    facets: &m.facets,
                };
                let index = SearchIndex::build(&surface);
                let far_apart = match search::points_bounding_box(&points) {
                    Some(b) => {
                        !search::boxes_overlap(b, index.bounding_box(), self.search_distance)
                    }
                    None => true,
                };
                if !far_apart {
                    for (q, x) in points.iter().enumerate() {
                        if let Some(found) = index.find(&surface, *x, self.search_distance) {
                            // Keep last step's partner while the point still lies
                            // over it (see `follow`), else take the search's.
                            let (facet, xi) = match previous[q] {
                                Some((f, xi)) if found.patch.contains(&f) => {
                                    match still_inside(&surface, f, *x, xi) {
                                        Some(p) => (f, p.xi),
                                        None => (found.facet, found.projection.xi),
                                    }
                                }
                                _ => (found.facet, found.projection.xi),
                            };
                            self.links.push(Link {
                                qp: q as u32,
                                facet,
                                xi,
                                patch: found.patch,
                            });
                        }
                    }
                }
            }
            MasterSide::Rigid(r) => {
                let geometry = r.placed(factor);
                for (q, x) in points.iter().enumerate() {
                    if geometry.distance(*x) <= self.search_distance {
                        self.links.push(Link {
                            qp: q as u32,
                            facet: 0,
                            xi: [0.0; 2],
                            patch: Vec::new(),
                        });
                    }
                }
            }
        }
        self.start_slip(&points, factor);
        let key = self.coupling_key();
        let changed = key != self.pattern_key;
        self.pattern_key = key;
        changed
    }

    fn coupling_key(&self) -> u64 {
        let mut h = DefaultHasher::new();
        // Patches by set index: the held numbering changes between steps.
        let global = |f: &u32| match &self.master {
            MasterSide::Facets(m) => m.set_index_of(*f),
            MasterSide::Rigid(_) => *f,
        };
        for l in &self.links {
            (l.qp / self.slave.nqp as u32).hash(&mut h);
            l.patch.len().hash(&mut h);
            for f in &l.patch {
                global(f).hash(&mut h);
            }
        }
        self.links.len().hash(&mut h);
        h.finish()
    }

    /// Follows sliding: re-selects each link's master facet within its patch
    /// for the current configuration, and caches the master positions.
    pub(super) fn follow(&mut self, u_local: &[f64]) {
        let MasterSide::Facets(m) = &self.master else {
            return;
        };
        self.positions = m.positions(u_local);
        let surface = search::SearchSurface {
            facet_type: m.facet_type,
            positions: &self.positions,
            facets: &m.facets,
        };
        for l in &mut self.links {
            let x = self.slave.qp_position(l.qp_index(), u_local);
            // A link stays on its facet while it still projects inside it:
            // where a point lies over a master node or edge, two facets are
            // equally near, and switching between them from one Newton
            // iteration to the next would make the residual chatter.
            if let Some(p) = still_inside(&surface, l.facet, x, l.xi) {
                l.xi = p.xi;
                continue;
            }
            if let Some((facet, p)) =
                search::select_facet(&surface, &l.patch, x, Some((l.facet, l.xi)))
            {
                l.facet = facet;
                l.xi = p.xi;
            }
        }
    }
}

/// The projection onto `facet` when it is valid and inside the facet (with a
/// small hysteresis beyond the search's own tolerance).
fn still_inside(
    surface: &search::SearchSurface,
    facet: u32,
    x: [f64; 3],
    xi: [f64; 2],
) -> Option<Projection> {
    const STICKY: f64 = 1e-3;
    let ids = surface.facet(facet)?;
    let n = surface.facet_type.nodes();
    let mut xm = [[0.0; 3]; crate::contact::MAX_FACET_NODES];
    for (slot, &id) in xm.iter_mut().zip(&ids[..n]) {
        *slot = surface.position(id)?;
    }
    let p = projection::project(surface.facet_type, &xm[..n], x, Some(xi));
    (p.converged && p.outside <= STICKY).then_some(p)
}

//! A contact pair at run time: the links of the current load step (one per
//! linked slave quadrature point), their search, their contributions to the
//! residual and tangent, and the Uzawa update of their multipliers.
use super::link::{self, LinkInput, LinkState, Master};
use super::multipliers::{updated_multiplier, Multipliers};
use super::pair::{MasterSpec, PairSpec, RigidSurface};
use super::search::{self, SearchIndex};
use super::surfaces::{MasterSurface, SlaveSurface};
use crate::dofs::{DofMap, DIM};
use crate::error::{Error, Result};
use crate::mesh::Mesh;
use crate::petsc::{BlockSink, PatternBuilder, PetscInt};
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

/// The master side at run time.
pub enum MasterSide {
    Deformable(MasterSurface),
    Rigid(RigidSurface),
}

/// What an Uzawa update found on this rank (reduced over ranks by the caller).
#[derive(Debug, Clone, Copy, Default)]
pub struct UzawaStats {
    /// Largest penetration relative to the local element size.
    pub max_penetration: f64,
    /// Largest change of a slave node's normal contact force in this update ...
    pub max_change: f64,
    /// ... and the largest nodal contact force after it.
    pub max_force: f64,
    pub max_multiplier: f64,
    pub active: usize,
}

/// Point values for output, for this rank's slave points.
pub struct PointValues {
    pub points: Vec<[f64; 3]>,
    pub pressure: Vec<f64>,
    pub gap: Vec<f64>,
    pub lambda: Vec<f64>,
    /// Owned slave nodes: reference position and nodal contact pressure.
    pub nodes: Vec<([f64; 3], f64)>,
}

pub struct ContactPair {
    pub spec: PairSpec,
    pub slave: SlaveSurface,
    pub master: MasterSide,
    pub multipliers: Multipliers,
    /// The pair's penalty as reported: the user's εN, or 10·E/h with h the
    /// mean element size; with no user value each slave facet uses its own
    /// h (`facet_penalty`), so graded meshes get a local penalty.
    pub penalty: f64,
    facet_penalty: Vec<f64>,
    pub search_distance: f64,
    links: Vec<Link>,
    pattern_key: u64,
    /// Master node positions of the last evaluation (deformable masters).
    positions: Vec<[f64; 3]>,
}

const MAX_LINK_NODES: usize = 8;
const MAX_LINK_DOFS: usize = DIM * MAX_LINK_NODES;

impl ContactPair {
    /// Resolves a pair on this rank. `softest_youngs` sets the default penalty.
    pub fn new(
        mesh: &Mesh,
        dofs: &DofMap,
        partition: &[i32],
        spec: &PairSpec,
        softest_youngs: f64,
    ) -> Result<Self> {
        let rule = spec.quadrature.rule(mesh.cell_type.facet_type());
        let slave = SlaveSurface::new(mesh, dofs, &spec.slave, &rule)?;
        let master = match &spec.master {
            MasterSpec::Surface { set } => {
                MasterSide::Deformable(MasterSurface::new(mesh, dofs, set)?)
            }
            MasterSpec::Rigid(r) => MasterSide::Rigid(*r),
        };
        let multipliers = Multipliers::new(mesh, dofs, partition, &spec.slave, &slave, &rule)?;
        let penalty = spec.penalty.unwrap_or(10.0 * softest_youngs / slave.h);
        let facet_penalty = slave
            .facets
            .iter()
            .map(|f| spec.penalty.unwrap_or(10.0 * softest_youngs / f.h))
            .collect();
        if !(penalty.is_finite() && penalty > 0.0) {
            return Err(Error::scene(
                "contact",
                format!(
                    "pair '{}': penalty must be positive (got {penalty})",
                    spec.name
                ),
            ));
        }
        let search_distance = spec
            .search_distance
            .unwrap_or_else(|| default_search_distance(mesh, &master, slave.h));
        Ok(ContactPair {
            spec: spec.clone(),
            slave,
            master,
            multipliers,
            penalty,
            facet_penalty,
            search_distance,
            links: Vec::new(),
            pattern_key: 0,
            positions: Vec::new(),
        })
    }

    pub fn links(&self) -> &[Link] {
        &self.links
    }

    /// The search that starts every load step: outer search (closest master
    /// node through the spatial index) and inner search (projection onto the
    /// facets around it) for every slave point. Returns true when the coupling
    /// pattern differs from the previous step's.
    pub fn search(&mut self, u_local: &[f64], factor: f64) -> bool {
        let nq = self.slave.num_qps();
        let points: Vec<[f64; 3]> = (0..nq)
            .map(|q| self.slave.qp_position(q, u_local))
            .collect();
        let previous: Vec<Option<(u32, [f64; 2])>> = {
            let mut p = vec![None; nq];
            for l in &self.links {
                p[l.qp as usize] = Some((l.facet, l.xi));
            }
            p
        };
        self.links.clear();
        match &self.master {
            MasterSide::Deformable(m) => {
                self.positions = m.positions(u_local);
                let surface = search::MasterSurface {
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
            MasterSide::Rigid(spec) => {
                let geometry = spec.moved(self.spec.motion, factor);
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
        let key = self.coupling_key();
        let changed = key != self.pattern_key;
        self.pattern_key = key;
        changed
    }

    fn coupling_key(&self) -> u64 {
        let mut h = DefaultHasher::new();
        for l in &self.links {
            (l.qp / self.slave.nqp as u32).hash(&mut h);
            l.patch.hash(&mut h);
        }
        self.links.len().hash(&mut h);
        h.finish()
    }

    /// Records every entry the links of this step may couple: each slave
    /// facet with itself and with every master node in its links' patches.
    pub fn add_pattern(&self, dofs: &DofMap, pattern: &mut PatternBuilder) -> Result<()> {
        let mut by_facet: std::collections::BTreeMap<usize, Vec<u32>> =
            std::collections::BTreeMap::new();
        for l in &self.links {
            let entry = by_facet.entry(l.qp as usize / self.slave.nqp).or_default();
            if let MasterSide::Deformable(m) = &self.master {
                for &f in &l.patch {
                    entry.extend_from_slice(m.facet_nodes(f));
                }
            }
        }
        let mut d: Vec<PetscInt> = Vec::new();
        for (facet, mut master_nodes) in by_facet {
            d.clear();
            d.extend_from_slice(&self.slave.facets[facet].dofs);
            if let MasterSide::Deformable(m) = &self.master {
                master_nodes.sort_unstable();
                master_nodes.dedup();
                for &n in &master_nodes {
                    let l = crate::dofs::LocalNode(m.node_local[n as usize] as usize);
                    d.extend((0..DIM).map(|c| dofs.dof(l, c).0));
                }
            }
            pattern.add_square(&d)?;
        }
        Ok(())
    }

    /// Follows sliding: re-selects each link's master facet within its patch
    /// for the current configuration, and caches the master positions.
    fn follow(&mut self, u_local: &[f64]) {
        let MasterSide::Deformable(m) = &self.master else {
            return;
        };
        self.positions = m.positions(u_local);
        let surface = search::MasterSurface {
            facet_type: m.facet_type,
            positions: &self.positions,
            facets: &m.facets,
        };
        for l in &mut self.links {
            let x = self.slave.qp_position(l.qp as usize, u_local);
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

    /// Evaluates every link at the current state, handing each one's DOFs,
    /// residual block and (when `with_tangent`) tangent block to `sink`.
    fn for_each_link(
        &mut self,
        u_local: &[f64],
        factor: f64,
        with_tangent: bool,
        mut sink: impl FnMut(&[u32], &[PetscInt], &[f64], Option<&[f64]>, &LinkState) -> Result<()>,
        dofs: &DofMap,
    ) -> Result<()> {
        self.follow(u_local);
        let ns = self.slave.facet_type.nodes();
        let mut xs = [[0.0; 3]; 4];
        let mut xm = [[0.0; 3]; 4];
        let mut r = [0.0; MAX_LINK_DOFS];
        let mut k = vec![0.0; MAX_LINK_DOFS * MAX_LINK_DOFS];
        let mut nodes: Vec<u32> = Vec::with_capacity(MAX_LINK_NODES);
        let mut link_dofs: Vec<PetscInt> = Vec::with_capacity(MAX_LINK_DOFS);
        for li in 0..self.links.len() {
            let (qp, facet, xi) = (
                self.links[li].qp as usize,
                self.links[li].facet,
                self.links[li].xi,
            );
            let sf = qp / self.slave.nqp;
            self.slave.facet_positions(sf, u_local, &mut xs[..ns]);
            nodes.clear();
            link_dofs.clear();
            nodes.extend_from_slice(&self.slave.facets[sf].nodes);
            link_dofs.extend_from_slice(&self.slave.facets[sf].dofs);
            let master = match &self.master {
                MasterSide::Deformable(m) => {
                    let fnodes = m.facet_nodes(facet);
                    for (x, &n) in xm.iter_mut().zip(fnodes) {
                        *x = self.positions[n as usize];
                    }
                    nodes.extend(fnodes.iter().map(|&n| m.node_local[n as usize]));
                    m.facet_dofs(facet, dofs, &mut link_dofs);
                    Master::Facet {
                        facet: m.facet_type,
                        x: &xm[..fnodes.len()],
                    }
                }
                MasterSide::Rigid(spec) => spec.moved(self.spec.motion, factor).as_master(),
            };
            let input = LinkInput {
                slave_facet: self.slave.facet_type,
                slave_x: &xs[..ns],
                zeta: self.slave.qp_zeta[qp],
                weight: self.slave.qp_weight[qp],
                master,
                xi_start: xi,
                lambda_n: self.multipliers.lambda[qp],
                penalty: self.facet_penalty[qp / self.slave.nqp],
                friction: None,
            };
            let n = link_dofs.len();
            let state = if with_tangent {
                link::residual_tangent(&input, &mut r[..n], Some(&mut k[..n * n]))
            } else {
                link::residual_tangent(&input, &mut r[..n], None)
            };
            self.links[li].xi = state.xi;
            if state.pressure > 0.0 {
                sink(
                    &nodes,
                    &link_dofs,
                    &r[..n],
                    with_tangent.then_some(&k[..n * n]),
                    &state,
                )?;
            }
        }
        Ok(())
    }

    /// Adds the links' residual r_c = −∫ pN δgN into the local-form array.
    pub fn add_residual(
        &mut self,
        dofs: &DofMap,
        u_local: &[f64],
        factor: f64,
        r_local: &mut [f64],
    ) -> Result<()> {
        self.for_each_link(
            u_local,
            factor,
            false,
            |nodes, _, r, _, _| {
                for (a, &l) in nodes.iter().enumerate() {
                    for c in 0..DIM {
                        r_local[DIM * l as usize + c] += r[DIM * a + c];
                    }
                }
                Ok(())
            },
            dofs,
        )
    }

    /// Adds the links' consistent tangent into `k` (not assembled).
    pub fn add_tangent(
        &mut self,
        dofs: &DofMap,
        u_local: &[f64],
        factor: f64,
        k: &mut dyn BlockSink,
    ) -> Result<()> {
        self.for_each_link(
            u_local,
            factor,
            true,
            |_, d, _, ke, _| match ke {
                Some(ke) => Ok(k.add_block(d, d, ke)?),
                None => Ok(()),
            },
            dofs,
        )
    }

    /// The Uzawa update λN ← ⟨λN − εN gN⟩ at every slave point of this rank
    /// (points without a link get λN = 0), then the halo exchange.
    pub fn uzawa_update(&mut self, u_local: &[f64], factor: f64) -> Result<UzawaStats> {
        let before = self.multipliers.nodal_forces()?;
        let states = self.evaluate_links(u_local, factor);
        let mut new_lambda = vec![0.0; self.slave.num_qps()];
        let mut stats = UzawaStats::default();
        for (l, s) in self.links.iter().zip(&states) {
            let q = l.qp as usize;
            let facet = q / self.slave.nqp;
            new_lambda[q] =
                updated_multiplier(self.multipliers.lambda[q], self.facet_penalty[facet], s.gap);
            stats.max_penetration = stats
                .max_penetration
                .max(-s.gap / self.slave.facets[facet].h);
            if new_lambda[q] > 0.0 {
                stats.active += 1;
            }
        }
        stats.max_multiplier = new_lambda.iter().copied().fold(0.0, f64::max);
        self.multipliers.lambda = new_lambda;
        self.multipliers.exchange()?;
        let after = self.multipliers.nodal_forces()?;
        for (b, a) in before.iter().zip(&after) {
            stats.max_change = stats.max_change.max((a - b).abs());
            stats.max_force = stats.max_force.max(a.abs());
        }
        Ok(stats)
    }

    fn evaluate_links(&mut self, u_local: &[f64], factor: f64) -> Vec<LinkState> {
        self.follow(u_local);
        let ns = self.slave.facet_type.nodes();
        let mut xs = [[0.0; 3]; 4];
        let mut xm = [[0.0; 3]; 4];
        let mut out = Vec::with_capacity(self.links.len());
        for l in &self.links {
            let qp = l.qp as usize;
            self.slave
                .facet_positions(qp / self.slave.nqp, u_local, &mut xs[..ns]);
            let master = match &self.master {
                MasterSide::Deformable(m) => {
                    let fnodes = m.facet_nodes(l.facet);
                    for (x, &n) in xm.iter_mut().zip(fnodes) {
                        *x = self.positions[n as usize];
                    }
                    Master::Facet {
                        facet: m.facet_type,
                        x: &xm[..fnodes.len()],
                    }
                }
                MasterSide::Rigid(spec) => spec.moved(self.spec.motion, factor).as_master(),
            };
            out.push(link::evaluate(&LinkInput {
                slave_facet: self.slave.facet_type,
                slave_x: &xs[..ns],
                zeta: self.slave.qp_zeta[qp],
                weight: self.slave.qp_weight[qp],
                master,
                xi_start: l.xi,
                lambda_n: self.multipliers.lambda[qp],
                penalty: self.facet_penalty[qp / self.slave.nqp],
                friction: None,
            }));
        }
        out
    }

    /// Reference position and nodal contact pressure of every slave node
    /// this rank owns. Reference, because small-strain closed forms (Hertz)
    /// describe the pressure over the undeformed surface: the surfaces also
    /// slide inward under load (about 1 % of the Hertz width here).
    pub fn node_values(&self) -> Result<Vec<([f64; 3], f64)>> {
        let pressures = self.multipliers.nodal_pressures()?;
        Ok(self
            .multipliers
            .owned_nodes()
            .iter()
            .zip(pressures)
            .map(|((_, x), p)| (*x, p))
            .collect())
    }

    /// Point values at the current state for output (pressure from the
    /// current multipliers: after a converged Uzawa loop λN is the pressure),
    /// and this rank's part of the total contact force on the slave surface.
    pub fn point_values(
        &mut self,
        u_local: &[f64],
        factor: f64,
    ) -> Result<(PointValues, [f64; 3])> {
        let nq = self.slave.num_qps();
        let states = self.evaluate_links(u_local, factor);
        let mut values = PointValues {
            points: (0..nq)
                .map(|q| self.slave.qp_position(q, u_local))
                .collect(),
            pressure: vec![0.0; nq],
            gap: vec![self.search_distance; nq],
            lambda: self.multipliers.lambda.clone(),
            nodes: self.node_values()?,
        };
        let mut force = [0.0; 3];
        for (l, s) in self.links.iter().zip(&states) {
            let q = l.qp as usize;
            // The updated multiplier ⟨λN − εN gN⟩ is exactly the pressure the
            // last Newton solve balanced, so forces computed from it are in
            // equilibrium with the reactions to the Newton tolerance.
            let p = self.multipliers.lambda[q];
            values.pressure[q] = p;
            values.gap[q] = s.gap;
            let w = self.slave.qp_weight[q];
            for (f, n) in force.iter_mut().zip(s.normal) {
                *f += p * n * w;
            }
        }
        Ok((values, force))
    }
}

/// The projection onto `facet` when it is valid and inside the facet (with a
/// small hysteresis beyond the search's own tolerance).
fn still_inside(
    surface: &search::MasterSurface,
    facet: u32,
    x: [f64; 3],
    xi: [f64; 2],
) -> Option<super::projection::Projection> {
    const STICKY: f64 = 1e-3;
    let ids = surface.facets.get(facet as usize)?;
    let n = surface.facet_type.nodes();
    let mut xm = [[0.0; 3]; 4];
    for (slot, &id) in xm.iter_mut().zip(&ids[..n]) {
        *slot = *surface.positions.get(id as usize)?;
    }
    let p = super::projection::project(surface.facet_type, &xm[..n], x, Some(xi));
    (p.converged && p.outside <= STICKY).then_some(p)
}

fn sub(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}

fn dot(a: [f64; 3], b: [f64; 3]) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

/// Default search distance: generous enough that bodies approaching within a
/// load step are linked (an open link costs only its evaluation).
fn default_search_distance(mesh: &Mesh, master: &MasterSide, h: f64) -> f64 {
    let diag = match master {
        MasterSide::Deformable(m) => search::points_bounding_box(&m.x_ref)
            .map_or(0.0, |(lo, hi)| dot(sub(hi, lo), sub(hi, lo)).sqrt()),
        MasterSide::Rigid(_) => mesh.bounding_box().map_or(0.0, |b| b.diagonal()),
    };
    (10.0 * h).max(0.1 * diag)
}

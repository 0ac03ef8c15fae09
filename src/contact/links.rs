//! A contact pair at run time: the links of the current load step (one per
//! linked slave quadrature point), their search, their contributions to the
//! residual and tangent, and the Uzawa update of their multipliers.
use super::dual::{dot, norm, sub};
use super::kernel::{self as link, Friction, LinkInput, LinkState, Master, SlipHistory, SlipRate};
use super::mortar::pair::{MortarPair, MortarSnapshot};
use super::multipliers::{
    updated_multiplier, FrictionRecord, Multipliers, PointFriction, PointState,
};
pub use super::outcome::{PairForce, UzawaStats};
use super::pair::{Formulation, MasterSpec, PairSpec, RigidSurface};
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

/// Point values for output, for this rank's slave points.
pub struct PointValues {
    pub points: Vec<[f64; 3]>,
    pub pressure: Vec<f64>,
    pub gap: Vec<f64>,
    pub lambda: Vec<f64>,
    /// Each point's area weight (reference configuration, the same weight
    /// the contact force Σ pN·w uses), so readers can integrate pressures
    /// and measure the contact area Σ w over points with pN > 0.
    pub weight: Vec<f64>,
    /// Friction (empty for a frictionless pair): tangential traction on the
    /// slave, slip increment of the step, state (0 open, 1 stick, 2 slip).
    pub traction: Vec<[f64; 3]>,
    pub slip: Vec<[f64; 3]>,
    pub state: Vec<i8>,
    /// Friction history a restart needs (empty for a frictionless pair).
    pub records: Vec<FrictionRecord>,
    /// Owned slave nodes: reference position and nodal contact pressure.
    pub nodes: Vec<([f64; 3], f64)>,
    /// Mortar pairs: the nodal fields, per owned mesh node.
    pub mortar: Option<crate::contact::mortar::pair::NodeFields>,
}

impl PointValues {
    fn empty() -> Self {
        PointValues {
            points: Vec::new(),
            pressure: Vec::new(),
            gap: Vec::new(),
            lambda: Vec::new(),
            weight: Vec::new(),
            traction: Vec::new(),
            slip: Vec::new(),
            state: Vec::new(),
            records: Vec::new(),
            nodes: Vec::new(),
            mortar: None,
        }
    }
}

/// One pair's state as a result file stores it, whole-pair arrays in output
/// row order: what [`ContactPair::restart_from`] takes over.
#[derive(Debug, Clone, Default)]
pub struct RestartRows {
    /// The pair's penalty at that step (None in files that lack it).
    pub penalty: Option<f64>,
    pub lambda: Vec<f64>,
    pub friction: Option<FrictionRows>,
}

#[derive(Debug, Clone, Default)]
pub struct FrictionRows {
    pub records: Vec<FrictionRecord>,
    pub state: Vec<f64>,
    pub traction: Vec<[f64; 3]>,
}

/// Friction of a pair at run time: μ and εT per slave facet.
struct PairFriction {
    mu: f64,
    penalty: Vec<f64>,
}

/// Dynamics: the time integrator's velocity, affine in the displacement,
/// `v = dv_du · u + offset` (local form, per DOF), for the slip rate.
pub struct SlipRateMap {
    pub dt: f64,
    pub dv_du: f64,
    pub offset: Vec<f64>,
    /// Velocity of a rigid master (its motion per unit time).
    pub rigid_velocity: [f64; 3],
}

/// What a cut-back step restores: the multipliers and friction state of the
/// last converged step.
pub struct PairSnapshot {
    lambda: Vec<f64>,
    friction: Option<Vec<PointFriction>>,
    /// The nodal multipliers of a mortar pair.
    mortar: Option<MortarSnapshot>,
}

/// Scratch space for one link's input (no allocation per link).
#[derive(Default)]
struct LinkBuffers {
    xs: [[f64; 3]; 4],
    xm: [[f64; 3]; 4],
    vs: [[f64; 3]; 4],
    vm: [[f64; 3]; 4],
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
    friction: Option<PairFriction>,
    /// Set by the solver in dynamics (slip from velocities); None: quasi-static.
    pub rate: Option<SlipRateMap>,
    /// `formulation = "mortar"`: the pair's constraint is the mortar one and
    /// the links above stay empty (the slave surface still gives the output
    /// its points).
    pub mortar: Option<MortarPair>,
    /// See `tangent_signature`.
    tangent_signature: u64,
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
        let friction_spec = spec.active_friction();
        let multipliers = Multipliers::new(
            mesh,
            dofs,
            partition,
            &spec.slave,
            &slave,
            &rule,
            friction_spec.is_some(),
        )?;
        let penalty = spec.penalty.unwrap_or(10.0 * softest_youngs / slave.h);
        let facet_penalty: Vec<f64> = slave
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
        let mortar = match (&spec.formulation, &spec.master) {
            (Formulation::Links, _) => None,
            (Formulation::Mortar, MasterSpec::Surface { set }) => Some(MortarPair::new(
                mesh,
                dofs,
                spec,
                set,
                |h| spec.penalty.unwrap_or(10.0 * softest_youngs / h),
                // Candidates are fixed for a step and every one widens the
                // Jacobian pattern: one element size of margin, not the
                // links' search distance.
                search_distance.min(slave.h),
                friction_spec,
            )?),
            (Formulation::Mortar, MasterSpec::Rigid(_)) => {
                return Err(Error::scene(
                    "contact",
                    format!("pair '{}': mortar needs a master facet set", spec.name),
                ))
            }
        };
        let friction = friction_spec.map(|f| PairFriction {
            mu: f.mu,
            penalty: match f.penalty {
                Some(p) => vec![p; slave.facets.len()],
                None => facet_penalty.clone(),
            },
        });
        Ok(ContactPair {
            spec: spec.clone(),
            slave,
            master,
            multipliers,
            penalty,
            facet_penalty,
            tangent_signature: 0,
            search_distance,
            links: Vec::new(),
            pattern_key: 0,
            positions: Vec::new(),
            friction,
            rate: None,
            mortar,
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
        if let Some(m) = &mut self.mortar {
            return m.search(u_local);
        }
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
                let geometry = spec.moved(self.spec.motion, self.spec.motion_amplitude.at(factor));
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
        if let Some(m) = &self.mortar {
            return m.add_pattern(dofs, pattern);
        }
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
        let mut buf = LinkBuffers::default();
        let mut r = [0.0; MAX_LINK_DOFS];
        let mut k = vec![0.0; MAX_LINK_DOFS * MAX_LINK_DOFS];
        let mut nodes: Vec<u32> = Vec::with_capacity(MAX_LINK_NODES);
        let mut link_dofs: Vec<PetscInt> = Vec::with_capacity(MAX_LINK_DOFS);
        for li in 0..self.links.len() {
            let link = &self.links[li];
            let sf = link.qp as usize / self.slave.nqp;
            nodes.clear();
            link_dofs.clear();
            nodes.extend_from_slice(&self.slave.facets[sf].nodes);
            link_dofs.extend_from_slice(&self.slave.facets[sf].dofs);
            if let MasterSide::Deformable(m) = &self.master {
                let fnodes = m.facet_nodes(link.facet);
                nodes.extend(fnodes.iter().map(|&n| m.node_local[n as usize]));
                m.facet_dofs(link.facet, dofs, &mut link_dofs);
            }
            let input = self.link_input(link, u_local, factor, &mut buf);
            let n = link_dofs.len();
            let state = if with_tangent {
                link::residual_tangent(&input, &mut r[..n], Some(&mut k[..n * n]))
            } else {
                link::residual_tangent(&input, &mut r[..n], None)
            };
            self.links[li].xi = state.xi;
            if state.closed {
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

    /// The kernel's input for one link at the current state: slave and master
    /// positions, λN, and (with friction) the slip history and velocities.
    fn link_input<'b>(
        &'b self,
        link: &Link,
        u_local: &[f64],
        factor: f64,
        buf: &'b mut LinkBuffers,
    ) -> LinkInput<'b> {
        let LinkBuffers { xs, xm, vs, vm } = buf;
        let qp = link.qp as usize;
        let sf = qp / self.slave.nqp;
        let ns = self.slave.facet_type.nodes();
        self.slave.facet_positions(sf, u_local, &mut xs[..ns]);
        let (master, master_nodes): (Master, &[u32]) = match &self.master {
            MasterSide::Deformable(m) => {
                let fnodes = m.facet_nodes(link.facet);
                for (x, &n) in xm.iter_mut().zip(fnodes) {
                    *x = self.positions[n as usize];
                }
                let x: &'b [[f64; 3]] = &xm[..fnodes.len()];
                (
                    Master::Facet {
                        facet: m.facet_type,
                        x,
                    },
                    fnodes,
                )
            }
            MasterSide::Rigid(spec) => (
                spec.moved(self.spec.motion, self.spec.motion_amplitude.at(factor))
                    .as_master(),
                &[],
            ),
        };
        let friction = match (&self.friction, &self.multipliers.tangential) {
            (Some(pf), Some(t)) => {
                let rate = self.rate.as_ref().map(|rate| {
                    let velocity = |local: u32| {
                        let d = DIM * local as usize;
                        [0, 1, 2].map(|c| rate.dv_du * u_local[d + c] + rate.offset[d + c])
                    };
                    for (v, &n) in vs.iter_mut().zip(&self.slave.facets[sf].nodes) {
                        *v = velocity(n);
                    }
                    let nm = match &self.master {
                        MasterSide::Deformable(m) => {
                            for (v, &n) in vm.iter_mut().zip(master_nodes) {
                                *v = velocity(m.node_local[n as usize]);
                            }
                            master_nodes.len()
                        }
                        MasterSide::Rigid(_) => {
                            vm[0] = rate.rigid_velocity;
                            1
                        }
                    };
                    SlipRate {
                        slave_v: &vs[..ns],
                        master_v: &vm[..nm],
                        dt: rate.dt,
                        dv_dx: rate.dv_du,
                    }
                });
                Some(Friction {
                    mu: pf.mu,
                    penalty: pf.penalty[sf],
                    history: self.slip_history(&t.points[qp], link, factor, u_local),
                    rate,
                })
            }
            _ => None,
        };
        LinkInput {
            slave_facet: self.slave.facet_type,
            slave_x: &xs[..ns],
            zeta: self.slave.qp_zeta[qp],
            weight: self.slave.qp_weight[qp],
            master,
            xi_start: link.xi,
            lambda_n: self.multipliers.lambda[qp],
            penalty: self.facet_penalty[sf],
            friction,
        }
    }

    /// The point's slip origin and λT in the terms of the link's current
    /// master: on a facet other than the one they were stored on, they are
    /// carried over (the origin as the same material point of the reference
    /// surface, λT as the same vector).
    fn slip_history(
        &self,
        p: &PointFriction,
        link: &Link,
        factor: f64,
        u_local: &[f64],
    ) -> SlipHistory {
        match &self.master {
            MasterSide::Deformable(m) => {
                let xi_n = match p.origin {
                    Some((o, f)) if f == link.facet => [o[0], o[1]],
                    Some((o, f)) => rebase_origin(m, f, [o[0], o[1]], link.facet, link.xi),
                    None => link.xi,
                };
                let lambda = if p.lambda_facet == link.facet || p.lambda == [0.0; 3] {
                    [p.lambda[0], p.lambda[1]]
                } else {
                    rebase_lambda(
                        m,
                        &self.positions,
                        p.lambda_facet,
                        [p.lambda[0], p.lambda[1]],
                        link.facet,
                        link.xi,
                    )
                };
                SlipHistory::Convected { xi_n, lambda }
            }
            MasterSide::Rigid(spec) => {
                let shift = self.rigid_shift(factor);
                let point_n = match p.origin {
                    Some((o, _)) => [o[0] + shift[0], o[1] + shift[1], o[2] + shift[2]],
                    // No history (the step's search sets one for every
                    // link): no slip yet.
                    None => spec
                        .moved(self.spec.motion, factor)
                        .closest_point(self.slave.qp_position(link.qp as usize, u_local)),
                };
                SlipHistory::Spatial {
                    point_n,
                    lambda: p.lambda,
                }
            }
        }
    }

    /// At the step's search: points that come into contact start measuring
    /// their slip where they first meet the master.
    fn start_slip(&mut self, points: &[[f64; 3]], factor: f64) {
        let shift = self.rigid_shift(factor);
        let Some(t) = &mut self.multipliers.tangential else {
            return;
        };
        for l in &self.links {
            let p = &mut t.points[l.qp as usize];
            if p.origin.is_some() {
                continue;
            }
            p.origin = Some(match &self.master {
                MasterSide::Deformable(_) => ([l.xi[0], l.xi[1], 0.0], l.facet),
                MasterSide::Rigid(spec) => {
                    let foot = spec
                        .moved(self.spec.motion, factor)
                        .closest_point(points[l.qp as usize]);
                    (
                        [foot[0] - shift[0], foot[1] - shift[1], foot[2] - shift[2]],
                        0,
                    )
                }
            });
            if p.lambda == [0.0; 3] {
                p.lambda_facet = l.facet;
            }
        }
    }

    /// Adds the links' residual r_c = −∫ pN δgN into the local-form array.
    pub fn add_residual(
        &mut self,
        dofs: &DofMap,
        u_local: &[f64],
        factor: f64,
        r_local: &mut [f64],
    ) -> Result<()> {
        if let Some(m) = &self.mortar {
            m.add_residual(u_local, self.mortar_rate().as_ref(), r_local);
            return Ok(());
        }
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
        if let Some(m) = &self.mortar {
            let rate = self.mortar_rate();
            self.tangent_signature = m.add_tangent(dofs, u_local, rate.as_ref(), k)?;
            return Ok(());
        }
        // Which links are closed, on which master facets, sticking or
        // sliding: what the tangent's structure depends on.
        let mut signature = std::collections::hash_map::DefaultHasher::new();
        self.for_each_link(
            u_local,
            factor,
            true,
            |_, d, _, ke, s| match ke {
                Some(ke) => {
                    use std::hash::Hash;
                    d.hash(&mut signature);
                    s.friction.as_ref().map(|f| f.sliding).hash(&mut signature);
                    Ok(k.add_block(d, d, ke)?)
                }
                None => Ok(()),
            },
            dofs,
        )?;
        self.tangent_signature = std::hash::Hasher::finish(&signature);
        Ok(())
    }

    /// A hash of the active set the last tangent was assembled with (this
    /// rank's links): equal hashes mean the same closed links on the same
    /// master facets in the same stick/slip states.
    pub fn tangent_signature(&self) -> u64 {
        self.tangent_signature
    }

    /// The Uzawa update λN ← ⟨λN − εN gN⟩ (and, with friction, λT ← tT) at
    /// every slave point of this rank (points without a link get λ = 0),
    /// then the halo exchange.
    pub fn uzawa_update(&mut self, u_local: &[f64], factor: f64) -> Result<UzawaStats> {
        if let Some(m) = &mut self.mortar {
            let rate = self.rate.as_ref().map(|r| super::mortar::friction::Rate {
                dt: r.dt,
                dv_du: r.dv_du,
                offset: &r.offset,
            });
            return Ok(m.uzawa_update(u_local, rate.as_ref()));
        }
        let before = self.multipliers.nodal_forces()?;
        let before_t = self.multipliers.nodal_tangential_forces()?;
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
        stats.sliding = self.update_friction(&states, factor);
        self.multipliers.exchange()?;
        let after = self.multipliers.nodal_forces()?;
        for (b, a) in before.iter().zip(&after) {
            stats.max_change = stats.max_change.max((a - b).abs());
            stats.max_force = stats.max_force.max(a.abs());
        }
        let after_t = self.multipliers.nodal_tangential_forces()?;
        for (b, a) in before_t.iter().zip(&after_t) {
            stats.max_change = stats.max_change.max(norm(&sub(a, b)));
        }
        Ok(stats)
    }

    /// λT ← tT and the stick/slip state of every point from this
    /// evaluation; returns how many points slide.
    fn update_friction(&mut self, states: &[LinkState], factor: f64) -> usize {
        let shift = self.rigid_shift(factor);
        let Some(t) = &mut self.multipliers.tangential else {
            return 0;
        };
        let mut fresh = vec![PointFriction::default(); t.points.len()];
        for (p, old) in fresh.iter_mut().zip(&t.points) {
            // A point that is open keeps where its slip started (it may
            // close again within the step), but no multiplier.
            p.origin = old.origin;
        }
        let mut sliding = 0;
        for (l, s) in self.links.iter().zip(states) {
            let p = &mut fresh[l.qp as usize];
            let Some(f) = s.friction.filter(|_| s.closed) else {
                continue;
            };
            p.state = if f.sliding {
                sliding += 1;
                PointState::Slip
            } else {
                PointState::Stick
            };
            p.traction = f.traction;
            p.slip = f.slip;
            match f.updated {
                SlipHistory::Convected { xi_n, lambda } => {
                    p.lambda = [lambda[0], lambda[1], 0.0];
                    p.lambda_facet = l.facet;
                    p.next_origin = Some(([xi_n[0], xi_n[1], 0.0], l.facet));
                }
                SlipHistory::Spatial { point_n, lambda } => {
                    p.lambda = lambda;
                    p.next_origin = Some((
                        [
                            point_n[0] - shift[0],
                            point_n[1] - shift[1],
                            point_n[2] - shift[2],
                        ],
                        0,
                    ));
                }
            }
        }
        t.points = fresh;
        sliding
    }

    /// A converged step is final: the next one measures slip from here.
    pub fn commit(&mut self) -> Result<()> {
        if let Some(m) = &mut self.mortar {
            m.commit();
            return Ok(());
        }
        if let Some(t) = &mut self.multipliers.tangential {
            t.commit();
            self.multipliers.exchange()?;
        }
        Ok(())
    }

    /// Takes over a converged step's multipliers and friction history from a
    /// result file, given as whole-pair arrays in output row order (set
    /// facet × quadrature point), then commits them as the step end did.
    pub fn restart_from(&mut self, rows: &RestartRows) -> Result<()> {
        if self.mortar.is_some() {
            return Err(Error::Restart(format!(
                "contact pair '{}': restarting a mortar pair is not supported",
                self.spec.name
            )));
        }
        let nqp = self.slave.nqp;
        let row_of = |i: usize| self.slave.facets[i / nqp].set_index * nqp + i % nqp;
        let n = self.slave.num_qps();
        let lambda = (0..n)
            .map(|i| rows.lambda.get(row_of(i)).copied())
            .collect::<Option<Vec<f64>>>()
            .filter(|l| l.iter().all(|v| v.is_finite() && *v >= 0.0))
            .ok_or_else(|| self.restart_error("lambda_n"))?;
        let friction = match (&self.multipliers.tangential, &rows.friction) {
            (None, _) => None,
            (Some(_), None) => return Err(self.restart_error("friction history")),
            (Some(_), Some(f)) => Some(
                (0..n)
                    .map(|i| {
                        let r = row_of(i);
                        PointFriction::from_record(
                            f.records.get(r)?,
                            *f.state.get(r)?,
                            *f.traction.get(r)?,
                        )
                    })
                    .collect::<Option<Vec<_>>>()
                    .ok_or_else(|| self.restart_error("friction history"))?,
            ),
        };
        if let Some(p) = rows.penalty.filter(|p| p.is_finite() && *p > 0.0) {
            // Raised during the first run: continue with the same penalty.
            self.raise_penalty(p / self.penalty);
        }
        self.restore(PairSnapshot {
            lambda,
            friction,
            mortar: None,
        })?;
        self.commit()
    }

    fn restart_error(&self, what: &str) -> Error {
        Error::Restart(format!(
            "contact pair '{}': the file's {what} does not fit this pair's {} slave points",
            self.spec.name,
            self.slave.global_facets * self.slave.nqp
        ))
    }

    /// The multipliers and friction state, to restore on a cutback.
    pub fn snapshot(&self) -> PairSnapshot {
        PairSnapshot {
            lambda: self.multipliers.lambda.clone(),
            friction: self
                .multipliers
                .tangential
                .as_ref()
                .map(|t| t.points.clone()),
            mortar: self.mortar.as_ref().map(MortarPair::snapshot),
        }
    }

    pub fn restore(&mut self, snap: PairSnapshot) -> Result<()> {
        if let (Some(m), Some(lambda)) = (&mut self.mortar, snap.mortar) {
            m.restore(lambda);
        }
        self.multipliers.lambda = snap.lambda;
        if let (Some(t), Some(points)) = (&mut self.multipliers.tangential, snap.friction) {
            t.points = points;
        }
        self.multipliers.exchange()
    }

    /// The smallest nodal force the Uzawa test resolves: the force of a
    /// penetration at the tolerance on one facet (εN · tol·h · h²). Below it
    /// a change in the multipliers cannot move the solution by more than the
    /// penetration tolerance already allows, so a near-empty contact (a
    /// grazing touch) is not iterated to relative precision.
    pub fn force_floor(&self) -> f64 {
        let h = self.slave.h;
        self.penalty * self.spec.penetration_tol * h * h * h
    }

    /// Translation of a rigid master at load factor `factor`.
    pub fn rigid_shift(&self, factor: f64) -> [f64; 3] {
        let a = self.spec.motion_amplitude.at(factor);
        self.spec.motion.map(|c| c * a)
    }

    /// Multiplies the normal penalty by `factor`, and the tangential one
    /// when it follows the normal one (no `tangential_penalty` given). The
    /// multipliers are kept: the augmented Lagrangian converges to the same
    /// solution for any penalty, only faster for a larger one.
    pub fn raise_penalty(&mut self, factor: f64) {
        self.penalty *= factor;
        self.facet_penalty.iter_mut().for_each(|p| *p *= factor);
        if let Some(m) = &mut self.mortar {
            m.raise_penalty(factor);
        }
        let follows = self
            .spec
            .active_friction()
            .is_some_and(|f| f.penalty.is_none());
        if let (true, Some(f)) = (follows, &mut self.friction) {
            f.penalty.iter_mut().for_each(|p| *p *= factor);
        }
    }

    /// This rank's points in contact (λN > 0) and, of those, sliding.
    pub fn multiplier_states(&self) -> (usize, usize) {
        if let Some(m) = &self.mortar {
            return (m.active_nodes(), m.sliding_nodes());
        }
        let active = self.multipliers.lambda.iter().filter(|l| **l > 0.0).count();
        let sliding = self.multipliers.tangential.as_ref().map_or(0, |t| {
            t.points
                .iter()
                .filter(|p| p.state == PointState::Slip)
                .count()
        });
        (active, sliding)
    }

    /// Whether the pair computes friction.
    pub fn has_friction(&self) -> bool {
        self.friction.is_some()
    }

    /// Whether the pair's tangent is symmetric: frictionless links (the
    /// Hessian of a potential). The mortar residual is not a gradient (the
    /// forces hold D, M and ν fixed), so its exact tangent is not symmetric.
    pub fn tangent_is_symmetric(&self) -> bool {
        !self.has_friction() && self.mortar.is_none()
    }

    fn evaluate_links(&mut self, u_local: &[f64], factor: f64) -> Vec<LinkState> {
        self.follow(u_local);
        let mut buf = LinkBuffers::default();
        self.links
            .iter()
            .map(|l| link::evaluate(&self.link_input(l, u_local, factor, &mut buf)))
            .collect()
    }

    /// Reference position and nodal contact pressure of every slave node
    /// this rank owns. Reference, because small-strain closed forms (Hertz)
    /// describe the pressure over the undeformed surface: the surfaces also
    /// slide inward under load (about 1 % of the Hertz width here).
    pub fn node_values(&self) -> Result<Vec<([f64; 3], f64)>> {
        if let Some(m) = &self.mortar {
            return Ok(m.node_values());
        }
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
    ) -> Result<(PointValues, PairForce)> {
        if self.mortar.is_some() {
            return Ok(self.mortar_point_values(u_local));
        }
        let nq = self.slave.num_qps();
        let states = self.evaluate_links(u_local, factor);
        let mut values = PointValues {
            points: (0..nq)
                .map(|q| self.slave.qp_position(q, u_local))
                .collect(),
            pressure: vec![0.0; nq],
            gap: vec![self.search_distance; nq],
            lambda: self.multipliers.lambda.clone(),
            weight: self.slave.qp_weight.clone(),
            traction: Vec::new(),
            slip: Vec::new(),
            state: Vec::new(),
            records: Vec::new(),
            nodes: self.node_values()?,
            mortar: None,
        };
        if let Some(t) = &self.multipliers.tangential {
            values.traction = t.points.iter().map(|p| p.traction).collect();
            values.slip = t.points.iter().map(|p| p.slip).collect();
            values.state = t.points.iter().map(|p| p.state as i8).collect();
            values.records = t.points.iter().map(PointFriction::record).collect();
        }
        let mut force = PairForce::default();
        for (l, s) in self.links.iter().zip(&states) {
            let q = l.qp as usize;
            // The updated multiplier ⟨λN − εN gN⟩ is exactly the pressure the
            // last Newton solve balanced, so forces computed from it are in
            // equilibrium with the reactions to the Newton tolerance.
            let p = self.multipliers.lambda[q];
            values.pressure[q] = p;
            values.gap[q] = s.gap;
            let w = self.slave.qp_weight[q];
            for (f, n) in force.force.iter_mut().zip(s.normal) {
                *f += p * n * w;
            }
            force.normal += p * w;
            if let Some(t) = &self.multipliers.tangential {
                // The traction of the last Uzawa update, like λN above.
                let traction = t.points[q].traction;
                for (f, tc) in force.force.iter_mut().zip(traction) {
                    *f += tc * w;
                }
                force.tangential += norm(&traction) * w;
            }
        }
        Ok((values, force))
    }

    /// Mortar pair: the slave points carry λ interpolated from the nodes
    /// with the standard shape functions (Σ N_a λ_a, the smooth nodal
    /// traction; the mortar field Σ Φ_a λ_a itself oscillates inside a facet).
    fn mortar_point_values(&self, u_local: &[f64]) -> (PointValues, PairForce) {
        let Some(m) = &self.mortar else {
            return (PointValues::empty(), PairForce::default());
        };
        let lambda = m.lambda_by_local_node();
        let nq = self.slave.num_qps();
        let mut pressure = vec![0.0; nq];
        for (q, p) in pressure.iter_mut().enumerate() {
            let facet = &self.slave.facets[q / self.slave.nqp];
            let s = crate::fem::shape::facet_shape(self.slave.facet_type, self.slave.qp_zeta[q]);
            *p = facet
                .nodes
                .iter()
                .zip(s.n)
                .map(|(n, na)| na * lambda.get(n).copied().unwrap_or(0.0))
                .sum();
        }
        let (fields, force) = m.output(u_local, self.mortar_rate().as_ref());
        let mut values = PointValues {
            points: (0..nq)
                .map(|q| self.slave.qp_position(q, u_local))
                .collect(),
            lambda: pressure.clone(),
            pressure,
            gap: vec![0.0; nq],
            weight: self.slave.qp_weight.clone(),
            nodes: m.node_values(),
            mortar: Some(fields),
            ..PointValues::empty()
        };
        if self.has_friction() {
            (values.traction, values.slip, values.state) =
                m.point_friction(&self.slave, &values.pressure);
            values.records = vec![FrictionRecord::default(); nq];
        }
        (values, force)
    }

    /// The dynamic slip rate in the mortar pair's terms (None quasi-static).
    fn mortar_rate(&self) -> Option<super::mortar::friction::Rate<'_>> {
        self.rate.as_ref().map(|r| super::mortar::friction::Rate {
            dt: r.dt,
            dv_du: r.dv_du,
            offset: &r.offset,
        })
    }

    /// Adds this pair's nodal contact pressure (owned nodes) into the field.
    pub fn add_nodal_pressure(&self, numerator: &mut [f64], denominator: &mut [f64]) -> Result<()> {
        match &self.mortar {
            Some(m) => {
                m.add_nodal_pressure(numerator, denominator);
                Ok(())
            }
            None => self.multipliers.add_nodal_pressure(numerator, denominator),
        }
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

/// Tangents `∂x/∂ξ_α` of a facet with nodes `x` at `xi`.
fn facet_tangents(m: &MasterSurface, x: &[[f64; 3]], xi: [f64; 2]) -> [[f64; 3]; 2] {
    let s = crate::fem::shape::facet_shape(m.facet_type, xi);
    let mut t = [[0.0; 3]; 2];
    for (xb, dn) in x.iter().zip(&s.dn) {
        for c in 0..3 {
            t[0][c] += dn[0] * xb[c];
            t[1][c] += dn[1] * xb[c];
        }
    }
    t
}

fn facet_points(m: &MasterSurface, facet: u32, positions: &[[f64; 3]]) -> Vec<[f64; 3]> {
    m.facet_nodes(facet)
        .iter()
        .map(|&n| positions[n as usize])
        .collect()
}

/// ξ̄ₙ stored on facet `from`, expressed on facet `to`: the same point of the
/// reference surface (history data is material, so the conversion is
/// independent of the current displacements).
fn rebase_origin(m: &MasterSurface, from: u32, xi: [f64; 2], to: u32, guess: [f64; 2]) -> [f64; 2] {
    let from_x = facet_points(m, from, &m.x_ref);
    let s = crate::fem::shape::facet_shape(m.facet_type, xi);
    let mut p = [0.0; 3];
    for (xb, nb) in from_x.iter().zip(s.n) {
        for c in 0..3 {
            p[c] += nb * xb[c];
        }
    }
    let to_x = facet_points(m, to, &m.x_ref);
    super::projection::project(m.facet_type, &to_x, p, Some(guess)).xi
}

/// λT's covariant components on facet `from` carried to facet `to` as the
/// same vector (tangents of `from` at its centre, of `to` at `xi`).
fn rebase_lambda(
    m: &MasterSurface,
    positions: &[[f64; 3]],
    from: u32,
    lambda: [f64; 2],
    to: u32,
    xi: [f64; 2],
) -> [f64; 2] {
    let [t1, t2] = facet_tangents(
        m,
        &facet_points(m, from, positions),
        super::projection::reference_centre(m.facet_type),
    );
    let (m11, m12, m22) = (dot(&t1, &t1), dot(&t1, &t2), dot(&t2, &t2));
    let det = m11 * m22 - m12 * m12;
    if det.abs() <= f64::MIN_POSITIVE {
        return [0.0; 2];
    }
    let c1 = (m22 * lambda[0] - m12 * lambda[1]) / det;
    let c2 = (m11 * lambda[1] - m12 * lambda[0]) / det;
    let v = [0, 1, 2].map(|i| c1 * t1[i] + c2 * t2[i]);
    let [s1, s2] = facet_tangents(m, &facet_points(m, to, positions), xi);
    [dot(&v, &s1), dot(&v, &s2)]
}

/// Default search distance: generous enough that bodies approaching within a
/// load step are linked (an open link costs only its evaluation).
fn default_search_distance(mesh: &Mesh, master: &MasterSide, h: f64) -> f64 {
    let diag = match master {
        MasterSide::Deformable(m) => {
            search::points_bounding_box(&m.x_ref).map_or(0.0, |(lo, hi)| norm(&sub(&hi, &lo)))
        }
        MasterSide::Rigid(_) => mesh.bounding_box().map_or(0.0, |b| b.diagonal()),
    };
    (10.0 * h).max(0.1 * diag)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::fem::FacetType;

    /// Two unit quads side by side in z = 0 (x ∈ [0, 1] and [1, 2]), the
    /// second one's nodes listed from a different corner so its ξ axes are
    /// turned against the first's.
    fn two_quads() -> MasterSurface {
        MasterSurface {
            facet_type: FacetType::Quad4,
            node_local: (0..6).collect(),
            x_ref: vec![
                [0.0, 0.0, 0.0],
                [1.0, 0.0, 0.0],
                [2.0, 0.0, 0.0],
                [0.0, 1.0, 0.0],
                [1.0, 1.0, 0.0],
                [2.0, 1.0, 0.0],
            ],
            facets: vec![[0, 1, 4, 3], [5, 4, 1, 2]],
        }
    }

    fn point_on(m: &MasterSurface, facet: u32, x: &[[f64; 3]], xi: [f64; 2]) -> [f64; 3] {
        let s = crate::fem::shape::facet_shape(m.facet_type, xi);
        let mut p = [0.0; 3];
        for (&n, nb) in m.facet_nodes(facet).iter().zip(s.n) {
            for c in 0..3 {
                p[c] += nb * x[n as usize][c];
            }
        }
        p
    }

    #[test]
    fn slip_origin_moves_to_a_neighbour_facet_as_the_same_point() {
        let m = two_quads();
        // A point of facet 0 near its edge with facet 1.
        let xi = [0.8, -0.3];
        let p = point_on(&m, 0, &m.x_ref, xi);
        let xi1 = rebase_origin(&m, 0, xi, 1, [0.0, 0.0]);
        let q = point_on(&m, 1, &m.x_ref, xi1);
        assert!(norm(&sub(&p, &q)) < 1e-12, "{p:?} vs {q:?}");
        // And back.
        let back = rebase_origin(&m, 1, xi1, 0, [0.0, 0.0]);
        assert!((back[0] - xi[0]).abs() < 1e-12 && (back[1] - xi[1]).abs() < 1e-12);
    }

    #[test]
    fn tangential_multiplier_moves_to_a_neighbour_facet_as_the_same_vector() {
        let m = two_quads();
        // Current positions: both facets stretched 1.5× in x, sheared in y.
        let x: Vec<[f64; 3]> = m
            .x_ref
            .iter()
            .map(|p| [1.5 * p[0] + 0.2 * p[1], p[1], 0.0])
            .collect();
        let vector = [0.7, -0.4, 0.0];
        let covariant = |facet: u32, xi: [f64; 2]| {
            let [t1, t2] = facet_tangents(&m, &facet_points(&m, facet, &x), xi);
            [dot(&vector, &t1), dot(&vector, &t2)]
        };
        let centre = crate::contact::projection::reference_centre(FacetType::Quad4);
        let on_0 = covariant(0, centre);
        let xi = [-0.5, 0.25];
        let moved = rebase_lambda(&m, &x, 0, on_0, 1, xi);
        let expect = covariant(1, xi);
        assert!(
            (moved[0] - expect[0]).abs() < 1e-12 && (moved[1] - expect[1]).abs() < 1e-12,
            "{moved:?} vs {expect:?}"
        );
    }
}

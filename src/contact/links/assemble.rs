//! What the links add to the Jacobian pattern, the residual and the tangent.
use super::kernel::{self, Friction, LinkInput, LinkMaster, LinkState, SlipRate};
use super::link::Link;
use super::LinksPair;
use crate::assembly::{MatrixSink, PatternSink};
use crate::contact::formulation::{self, At};
use crate::contact::master::MasterSide;
use crate::contact::MAX_FACET_NODES;
use crate::dofs::{GlobalDof, DIM};
use crate::error::Result;
use std::collections::BTreeSet;

/// Scratch space for one link's input (no allocation per link).
pub(super) struct LinkBuffers {
    xs: [[f64; 3]; MAX_FACET_NODES],
    xm: [[f64; 3]; MAX_FACET_NODES],
    vs: [[f64; 3]; MAX_FACET_NODES],
    vm: [[f64; 3]; MAX_FACET_NODES],
}

impl Default for LinkBuffers {
    fn default() -> Self {
        let zero = [[0.0; 3]; MAX_FACET_NODES];
        LinkBuffers {
            xs: zero,
            xm: zero,
            vs: zero,
            vm: zero,
        }
    }
}

const MAX_LINK_NODES: usize = 2 * MAX_FACET_NODES;

const MAX_LINK_DOFS: usize = DIM * MAX_LINK_NODES;

impl LinksPair {
    /// Records every entry the links of this step may couple. A link
    /// couples its slave facet with the one master facet it projects onto,
    /// which may be any facet of its patch, so the pattern is the union of
    /// (slave facet + one patch facet) squares: the nodes of two different
    /// patch facets are never coupled through a link. (One square over the
    /// slave facet and its whole patch stored 1.3 million zeros beyond the
    /// bulk stiffness's 7.4 million on the Hertz sphere at h = 0.35, each
    /// a multiply in every product and smoother sweep; now 0.7 million.)
    pub(super) fn pattern(&self, pattern: &mut dyn PatternSink) -> Result<()> {
        let facets: BTreeSet<usize> = self
            .links
            .iter()
            .map(|l| l.qp_index() / self.slave.nqp)
            .collect();
        for &facet in &facets {
            pattern.add_square(&self.slave.facets[facet].dofs)?;
        }
        let MasterSide::Facets(m) = &self.master else {
            return Ok(());
        };
        let pairs: BTreeSet<(usize, u32)> = self
            .links
            .iter()
            .flat_map(|l| {
                let facet = l.qp_index() / self.slave.nqp;
                l.patch.iter().map(move |&f| (facet, f))
            })
            .collect();
        let mut d: Vec<GlobalDof> = Vec::new();
        for (facet, f) in pairs {
            d.clear();
            d.extend_from_slice(&self.slave.facets[facet].dofs);
            m.facet_dofs(f, &mut d);
            pattern.add_square(&d)?;
        }
        Ok(())
    }

    /// Evaluates every link at the current state, handing each one's DOFs,
    /// residual block and (when `with_tangent`) tangent block to `sink`.
    fn for_each_link(
        &mut self,
        at: &At,
        with_tangent: bool,
        mut sink: impl FnMut(&[u32], &[GlobalDof], &[f64], Option<&[f64]>, &LinkState) -> Result<()>,
    ) -> Result<()> {
        self.follow(at.u);
        let mut buf = LinkBuffers::default();
        let mut r = [0.0; MAX_LINK_DOFS];
        let mut k = vec![0.0; MAX_LINK_DOFS * MAX_LINK_DOFS];
        let mut nodes: Vec<u32> = Vec::with_capacity(MAX_LINK_NODES);
        let mut link_dofs: Vec<GlobalDof> = Vec::with_capacity(MAX_LINK_DOFS);
        for li in 0..self.links.len() {
            let link = &self.links[li];
            let sf = link.qp_index() / self.slave.nqp;
            nodes.clear();
            link_dofs.clear();
            nodes.extend(self.slave.facets[sf].nodes.iter().map(|l| l.to_u32()));
            link_dofs.extend_from_slice(&self.slave.facets[sf].dofs);
            if let MasterSide::Facets(m) = &self.master {
                let fnodes = m.facet_nodes(link.facet);
                nodes.extend(fnodes.iter().map(|&n| m.extended_slot(n)));
                m.facet_dofs(link.facet, &mut link_dofs);
            }
            let input = self.link_input(link, at, &mut buf);
            let n = link_dofs.len();
            let state = if with_tangent {
                kernel::residual_tangent(&input, &mut r[..n], Some(&mut k[..n * n]))
            } else {
                kernel::residual_tangent(&input, &mut r[..n], None)
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
    pub(super) fn link_input<'b>(
        &'b self,
        link: &Link,
        at: &At,
        buf: &'b mut LinkBuffers,
    ) -> LinkInput<'b> {
        let (u_local, factor) = (at.u, at.factor);
        let LinkBuffers { xs, xm, vs, vm } = buf;
        let qp = link.qp_index();
        let sf = qp / self.slave.nqp;
        let ns = self.slave.facet_type.nodes();
        self.slave.facet_positions(sf, u_local, &mut xs[..ns]);
        let (master, master_nodes): (LinkMaster, &[u32]) = match &self.master {
            MasterSide::Facets(m) => {
                let fnodes = m.facet_nodes(link.facet);
                for (x, &n) in xm.iter_mut().zip(fnodes) {
                    *x = self.positions[n as usize];
                }
                let x: &'b [[f64; 3]] = &xm[..fnodes.len()];
                (
                    LinkMaster::Facet {
                        facet: m.facet_type,
                        x,
                    },
                    fnodes,
                )
            }
            MasterSide::Rigid(r) => (r.placed(factor).as_master(), &[]),
        };
        let friction = match (&self.friction, &self.multipliers.tangential) {
            (Some(pf), Some(t)) => {
                let rate = at.rate.map(|rate: &formulation::SlipRate| {
                    let velocity = |local: u32| {
                        let d = DIM * local as usize;
                        [0, 1, 2].map(|c| rate.dv_du * u_local[d + c] + rate.offset[d + c])
                    };
                    for (v, &n) in vs.iter_mut().zip(&self.slave.facets[sf].nodes) {
                        *v = velocity(n.to_u32());
                    }
                    let nm = match &self.master {
                        MasterSide::Facets(m) => {
                            for (v, &n) in vm.iter_mut().zip(master_nodes) {
                                *v = velocity(m.extended_slot(n));
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
            main_part_tangent: self.main_part_tangent,
        }
    }

    /// Adds the links' residual r_c = −∫ pN δgN into the local-form array.
    pub(super) fn residual(&mut self, at: &At, r_local: &mut [f64]) -> Result<()> {
        self.for_each_link(at, false, |nodes, _, r, _, _| {
            for (a, &l) in nodes.iter().enumerate() {
                for c in 0..DIM {
                    r_local[DIM * l as usize + c] += r[DIM * a + c];
                }
            }
            Ok(())
        })
    }

    /// Adds the links' consistent tangent into `k` (not assembled), and
    /// keeps its signature: which links are closed, on which master facets,
    /// sticking or sliding (what the tangent's structure depends on).
    pub(super) fn tangent(&mut self, at: &At, k: &mut dyn MatrixSink) -> Result<()> {
        let mut signature = std::collections::hash_map::DefaultHasher::new();
        self.for_each_link(at, true, |_, d, _, ke, s| match ke {
            Some(ke) => {
                use std::hash::Hash;
                d.hash(&mut signature);
                s.friction.as_ref().map(|f| f.sliding).hash(&mut signature);
                k.add_block(d, d, ke)
            }
            None => Ok(()),
        })?;
        self.tangent_signature = std::hash::Hasher::finish(&signature);
        Ok(())
    }
}

impl LinksPair {
    /// Every link's state at `at` after following its sliding partner.
    pub(super) fn evaluate_links(&mut self, at: &At) -> Vec<LinkState> {
        self.follow(at.u);
        let mut buf = LinkBuffers::default();
        self.links
            .iter()
            .map(|l| kernel::evaluate(&self.link_input(l, at, &mut buf)))
            .collect()
    }
}

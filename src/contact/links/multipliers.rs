//! The links' multipliers λN at the slave quadrature points (updated by
//! the rule λN ← ⟨λN − εN gN⟩ of `contact::penalty`).
//!
//! A slave quadrature point belongs to the rank that owns its facet's cell.
//! The multipliers live in an owned + ghost layout (a [`Halo`] in a
//! quadrature-point numbering that is contiguous per rank): ghosts are the
//! points of other ranks' slave facets that touch a node this rank owns, so
//! nodal quantities (the nodal contact pressure) need no further messages.
//! The ghosts are refreshed by a halo exchange after every Uzawa update.
//!
//! With friction every point also carries its tangential state (λT, where
//! this step's slip is measured from, stick/slip, traction and slip), in a
//! second halo with the same owned + ghost layout, exchanged with
//! λN: ghosts feed the nodal tangential forces the Uzawa test compares.
use crate::assembly::{Halo, HaloFactory};
use crate::contact::surfaces::{reference_weights, SlaveSurface};
use crate::contact::{facet_shape, MAX_FACET_NODES};
use crate::distribution::SlaveSetPiece;
use crate::dofs::{DofMap, LocalNode, NaturalNode};
use crate::error::Result;
use crate::fem::QuadRule;

/// A quadrature point contribution to a node this rank owns: the point's slot
/// in the local (owned + ghost) layout and its weight N_a(ζ) w.
#[derive(Debug, Clone, Copy)]
struct NodalWeight {
    owned_node: u32,
    /// Position of the node in `owned_nodes`.
    owned_slot: u32,
    slot: u32,
    /// `N_a(ζ) w`: the node's share of the point's force.
    weight: f64,
    /// The node's weight in the nodal pressure, a weighted mean of the point
    /// multipliers around it: `N_a w` on first-order facets (so the
    /// pressure is force over area), `N_a² w` on second-order ones, whose
    /// corner functions integrate to zero (tri6) or less (quad8): the
    /// diagonal, HRZ-like weights are positive and still favour the points
    /// nearest the node.
    share: f64,
}

impl NodalWeight {
    /// The owned slave node the weight goes to.
    fn owned_node(&self) -> LocalNode {
        LocalNode::from_u32(self.owned_node)
    }

    /// Position of the node in `owned_nodes`.
    fn owned_slot(&self) -> usize {
        self.owned_slot as usize
    }

    /// The slave point (halo slot) the weight comes from.
    fn slot(&self) -> usize {
        self.slot as usize
    }
}

/// Contact state of a slave point, as written to the output (`state`).
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub enum PointState {
    #[default]
    Open = 0,
    Stick = 1,
    Slip = 2,
}

/// Tangential (friction) state of one slave point.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct PointFriction {
    /// λT: covariant components `[λ_1, λ_2, 0]` on master facet
    /// `lambda_facet` (deformable master), or a vector (rigid master).
    pub lambda: [f64; 3],
    pub lambda_facet: u32,
    /// Where this step's slip is measured from: `[ξ̄ₙ_1, ξ̄ₙ_2, 0]` on the
    /// given facet, or (rigid master) the contact point in the master's own
    /// frame (its placement minus its motion). None before first contact.
    pub origin: Option<([f64; 3], u32)>,
    /// The origin the next step starts from (the master point of the last
    /// Uzawa update), taken over by `commit` once the step has converged.
    pub next_origin: Option<([f64; 3], u32)>,
    pub state: PointState,
    /// Tangential traction on the slave per reference area.
    pub traction: [f64; 3],
    pub slip: [f64; 3],
}

/// What a result file keeps of a point's friction state so that a restart
/// continues exactly: λT and where the next step's slip is measured from
/// (the uncommitted `next_origin`; `commit` runs again after reading).
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct FrictionRecord {
    pub lambda: [f64; 3],
    pub origin: [f64; 3],
    /// `lambda_facet`, 1 if there is an origin (else 0), the origin's facet;
    /// stored as f64 like every step array (exact below 2⁵³).
    pub ids: [f64; 3],
}

impl PointFriction {
    pub fn record(&self) -> FrictionRecord {
        let (origin, has, facet) = match self.next_origin {
            Some((o, f)) => (o, 1.0, f64::from(f)),
            None => ([0.0; 3], 0.0, 0.0),
        };
        FrictionRecord {
            lambda: self.lambda,
            origin,
            ids: [f64::from(self.lambda_facet), has, facet],
        }
    }

    /// The state a record, the stored `state` (0, 1, 2) and traction
    /// describe (the traction feeds the next Uzawa test's force change);
    /// `None` when the numbers cannot have come from
    /// [`PointFriction::record`].
    pub fn from_record(r: &FrictionRecord, state: f64, traction: [f64; 3]) -> Option<Self> {
        // Exact small integers only: anything else was not written by `record`.
        let id = |v: f64| u32::try_from(v as i64).ok().filter(|&i| f64::from(i) == v);
        let state = [PointState::Open, PointState::Stick, PointState::Slip]
            .into_iter()
            .find(|s| f64::from(*s as u8) == state)?;
        let next_origin = if r.ids[1] == 0.0 {
            None
        } else if r.ids[1] == 1.0 {
            Some((r.origin, id(r.ids[2])?))
        } else {
            return None;
        };
        let finite = r
            .lambda
            .iter()
            .chain(&r.origin)
            .chain(&traction)
            .all(|v| v.is_finite());
        finite.then_some(PointFriction {
            lambda: r.lambda,
            lambda_facet: id(r.ids[0])?,
            origin: None,
            next_origin,
            state,
            traction,
            slip: [0.0; 3],
        })
    }
}

/// Values per point in the friction halo: traction (3), λT (3), origin (3),
/// state (1).
const FRICTION_WIDTH: usize = 10;

/// The friction state of every owned point and its halo.
pub struct Tangential {
    pub points: Vec<PointFriction>,
    halo: Box<dyn Halo>,
}

impl Tangential {
    /// Start of a converged step's successor: slip is measured from where
    /// each closed point now is; open points forget their history.
    pub fn commit(&mut self) {
        for p in &mut self.points {
            p.origin = match p.state {
                PointState::Open => None,
                _ => p.next_origin,
            };
            if p.state == PointState::Open {
                p.lambda = [0.0; 3];
            }
        }
    }
}

pub struct Multipliers {
    /// λN of the owned points (same order as the slave surface's points).
    pub lambda: Vec<f64>,
    /// Friction state (None for a frictionless pair: nothing is stored,
    /// exchanged or evaluated).
    pub tangential: Option<Tangential>,
    /// Wall time spent in halo exchanges, for the phase report.
    pub exchange_seconds: f64,
    halo: Box<dyn Halo>,
    n_owned: usize,
    n_ghost: usize,
    /// For the nodal pressure: contributions of owned and ghost points to owned nodes.
    nodal: Vec<NodalWeight>,
    /// Owned slave nodes: local index and reference position.
    owned_nodes: Vec<(u32, [f64; 3])>,
}

impl Multipliers {
    pub fn new(
        dofs: &DofMap,
        piece: &SlaveSetPiece,
        slave: &SlaveSurface,
        rule: &QuadRule,
        friction: bool,
        halos: &dyn HaloFactory,
    ) -> Result<Self> {
        let nqp = slave.nqp;
        let global_facet = &slave.global_facet;
        let owned_node = |nat: usize| dofs.local(NaturalNode(nat)).filter(|&l| dofs.is_owned(l));
        // Ghost facets: other ranks' facets with a node this rank owns, as
        // the piece lists them.
        let ghost_facets = &piece.ghosts;
        let ghosts: Vec<usize> = ghost_facets
            .iter()
            .flat_map(|g| {
                let first = global_facet[g.set_index] * nqp;
                (0..nqp).map(move |q| first + q)
            })
            .collect();
        let n_owned = slave.num_qps();
        let halo = halos.halo(n_owned, &ghosts)?;
        let mut nodal = Vec::new();
        let mut owned_nodes: Vec<(u32, [f64; 3])> = Vec::new();
        let mut slot_of: std::collections::BTreeMap<u32, u32> = std::collections::BTreeMap::new();
        let nf = slave.facet_type.nodes();
        let linear = slave.facet_type.is_linear();
        let mut add_facet = |natural: &[usize], x_ref: &[[f64; 3]], first_slot: usize| {
            let points = reference_weights(slave.facet_type, x_ref, rule);
            for (q, (zeta, w)) in points.iter().enumerate() {
                let s = facet_shape::<MAX_FACET_NODES>(slave.facet_type, *zeta);
                for (a, &v) in natural.iter().enumerate() {
                    if let Some(l) = owned_node(v).map(LocalNode::to_u32) {
                        let owned_slot = *slot_of.entry(l).or_insert_with(|| {
                            owned_nodes.push((l, x_ref[a]));
                            (owned_nodes.len() - 1) as u32
                        });
                        let weight = s.n[a] * w;
                        nodal.push(NodalWeight {
                            owned_node: l,
                            owned_slot,
                            slot: (first_slot + q) as u32,
                            weight,
                            share: if linear { weight } else { s.n[a] * weight },
                        });
                    }
                }
            }
        };
        for (k, f) in slave.facets.iter().enumerate() {
            let natural: Vec<usize> = f.nodes.iter().map(|&l| dofs.natural(l).0).collect();
            add_facet(&natural, &f.x_ref, k * nqp);
        }
        for (k, g) in ghost_facets.iter().enumerate() {
            add_facet(&g.natural[..nf], &g.x_ref[..nf], n_owned + k * nqp);
        }
        let tangential = if friction {
            let wide: Vec<usize> = ghosts
                .iter()
                .flat_map(|&g| (0..FRICTION_WIDTH).map(move |c| g * FRICTION_WIDTH + c))
                .collect();
            Some(Tangential {
                points: vec![PointFriction::default(); n_owned],
                halo: halos.halo(n_owned * FRICTION_WIDTH, &wide)?,
            })
        } else {
            None
        };
        Ok(Multipliers {
            lambda: vec![0.0; n_owned],
            tangential,
            exchange_seconds: 0.0,
            halo,
            n_owned,
            n_ghost: ghosts.len(),
            nodal,
            owned_nodes,
        })
    }

    /// Halo exchange: ghost copies take their owners' current multipliers.
    pub fn exchange(&mut self) -> Result<()> {
        let start = std::time::Instant::now();
        let out = self.exchange_now();
        self.exchange_seconds += start.elapsed().as_secs_f64();
        out
    }

    fn exchange_now(&mut self) -> Result<()> {
        self.halo.exchange(&self.lambda)?;
        if let Some(t) = &mut self.tangential {
            let mut owned = vec![0.0; FRICTION_WIDTH * t.points.len()];
            for (chunk, p) in owned.chunks_exact_mut(FRICTION_WIDTH).zip(&t.points) {
                let origin = p.origin.map_or([f64::NAN; 3], |(o, _)| o);
                chunk[..3].copy_from_slice(&p.traction);
                chunk[3..6].copy_from_slice(&p.lambda);
                chunk[6..9].copy_from_slice(&origin);
                chunk[9] = p.state as i32 as f64;
            }
            t.halo.exchange(&owned)?;
        }
        Ok(())
    }

    /// Values one halo exchange brings to this rank: λN of every ghost point,
    /// and the friction record of each with friction.
    pub fn ghost_values(&self) -> usize {
        let width = if self.tangential.is_some() {
            1 + FRICTION_WIDTH
        } else {
            1
        };
        self.n_ghost * width
    }

    /// Tangential force carried by each owned slave node: Σ N_a(ζ) w tT over
    /// every slave point around it (any rank, through the friction halo).
    /// Zero vectors for a frictionless pair.
    pub fn nodal_tangential_forces(&self) -> Result<Vec<[f64; 3]>> {
        let mut forces = vec![[0.0; 3]; self.owned_nodes.len()];
        if let Some(t) = &self.tangential {
            let all = t.halo.local();
            for w in &self.nodal {
                let base = FRICTION_WIDTH * w.slot();
                let f = &mut forces[w.owned_slot()];
                for (fi, ti) in f.iter_mut().zip(&all[base..base + 3]) {
                    *fi += w.weight * ti;
                }
            }
        }
        Ok(forces)
    }

    /// Normal contact force carried by each owned slave node: Σ N_a(ζ) w λN
    /// over every slave point around it (on any rank, through the halo).
    /// Multipliers that change without changing these forces (possible where
    /// a facet's points over-constrain the surface) do not move the solution.
    pub fn nodal_forces(&self) -> Result<Vec<f64>> {
        let mut forces = vec![0.0; self.owned_nodes.len()];
        let all = self.halo.local();
        for w in &self.nodal {
            forces[w.owned_slot()] += w.weight * all[w.slot()];
        }
        Ok(forces)
    }

    /// Nodal contact pressure of each owned slave node: its normal force over
    /// its share of the slave area, Σ N_a w λN / Σ N_a w, on first-order
    /// facets; on second-order ones the mean Σ N_a² w λN / Σ N_a² w (see
    /// `NodalWeight::share`). Unlike the point multipliers it is unique, and
    /// it is what the Hertz checks compare.
    pub fn nodal_pressures(&self) -> Result<Vec<f64>> {
        let mut forces = vec![0.0; self.owned_nodes.len()];
        let mut area = vec![0.0; forces.len()];
        let all = self.halo.local();
        for w in &self.nodal {
            forces[w.owned_slot()] += w.share * all[w.slot()];
            area[w.owned_slot()] += w.share;
        }
        Ok(forces
            .iter()
            .zip(&area)
            .map(|(f, a)| if *a > 0.0 { f / a } else { 0.0 })
            .collect())
    }

    /// Owned slave nodes (local index, reference position), in the order of
    /// `nodal_forces`.
    pub fn owned_nodes(&self) -> &[(u32, [f64; 3])] {
        &self.owned_nodes
    }

    /// Nodal contact pressure of the owned nodes (area-weighted average of the
    /// multipliers of every slave point around the node, on any rank), added
    /// into `numerator` and `denominator` (indexed by owned local node).
    pub fn add_nodal_pressure(&self, numerator: &mut [f64], denominator: &mut [f64]) -> Result<()> {
        let all = self.halo.local();
        debug_assert_eq!(all.len(), self.n_owned + self.n_ghost);
        for w in &self.nodal {
            let l = w.owned_node().index();
            numerator[l] += w.share * all[w.slot()];
            denominator[l] += w.share;
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn friction_record_round_trips() {
        let p = PointFriction {
            lambda: [0.5, -0.25, 0.0],
            lambda_facet: 17,
            origin: Some(([0.1, 0.2, 0.0], 3)),
            next_origin: Some(([0.3, -0.4, 0.0], 18)),
            state: PointState::Slip,
            traction: [1.0, 2.0, 3.0],
            slip: [0.0; 3],
        };
        let back = PointFriction::from_record(&p.record(), 2.0, p.traction).unwrap();
        assert_eq!(back.lambda, p.lambda);
        assert_eq!(back.lambda_facet, 17);
        assert_eq!(back.next_origin, p.next_origin);
        assert_eq!(back.state, PointState::Slip);
        assert_eq!(back.traction, p.traction);
        let open = PointFriction::default();
        let back = PointFriction::from_record(&open.record(), 0.0, [0.0; 3]).unwrap();
        assert_eq!(back.next_origin, None);
        let mut bad = p.record();
        bad.ids[0] = 1.5;
        assert!(PointFriction::from_record(&bad, 2.0, p.traction).is_none());
        assert!(PointFriction::from_record(&p.record(), 7.0, p.traction).is_none());
    }
}

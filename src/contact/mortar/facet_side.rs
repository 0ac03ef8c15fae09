//! A mortar pair's deformable master at run time: the master facets this
//! rank holds, the step's candidate (slave, master) facet pairs whose
//! bounding boxes meet, and the segment-based evaluation, residual and
//! tangent over them (the integrals are `geometry`'s, `segment`'s and
//! `system`'s, the friction `friction`'s). A rigid master is the other
//! variant of the master side (`rigid_side`).
use super::friction::{self, Increment, NodeFriction, Rate};
use super::master::FacetSide;
use super::output::OutputRows;
use super::pair::MortarPair;
use super::rows::{signature, Rows};
use super::system::{self, Interface, NodeState, Segment};
use super::MAX_FACET_NODES;
use crate::assembly::MatrixSink;
use crate::contact::autodiff::Dual;
use crate::error::Result;
use crate::fem::surface::facet_normal_at_centre;

/// One evaluation of the pair (values only; the tangent takes its
/// derivatives segment by segment): segments, node states and (with
/// friction) the nodes' friction.
pub(super) struct Evaluation {
    pub segments: Vec<Segment<f64>>,
    /// Per slave facet: whether the segments cover it whole (its `D` is
    /// the exact diagonal, see `coverage`).
    pub covered: Vec<bool>,
    pub states: Vec<NodeState>,
    pub frictions: Vec<NodeFriction>,
}

impl MortarPair {
    fn facet_interface<'a>(&'a self, m: &'a FacetSide, positions: &'a [[f64; 3]]) -> Interface<'a> {
        Interface {
            slave_type: self.facet_type,
            master_type: self.facet_type,
            positions,
            reference: &self.x_ref,
            slave_facets: &self.slave_facets,
            master_facets: &m.facets,
            candidates: &self.candidates,
            assembled: &self.assembled,
        }
    }

    /// Every (evaluated slave, held master) facet pair whose bounding boxes
    /// at positions `x`, grown by `margin`, meet; by slave, then master. A
    /// master facet's box also reaches one facet size behind it (into its
    /// body), so that a slave facet pushed through the master surface
    /// further than its own thickness still pairs with the facets it
    /// crossed.
    pub(super) fn facet_pairs(
        &self,
        m: &FacetSide,
        x: &[[f64; 3]],
        margin: f64,
    ) -> Vec<(u32, u32)> {
        let nf = self.facet_type.nodes();
        let bbox = |f: &[u32; MAX_FACET_NODES]| bounding_box(&f[..nf], x);
        let masters: Vec<_> = m
            .facets
            .iter()
            .map(|f| {
                let (mut lo, mut hi) = bbox(f);
                let corners: Vec<[f64; 3]> = f[..nf].iter().map(|&n| x[n as usize]).collect();
                let depth = (0..3).map(|c| hi[c] - lo[c]).fold(0.0, f64::max);
                if let Ok(n) = facet_normal_at_centre(self.facet_type, &corners) {
                    for c in 0..3 {
                        lo[c] = lo[c].min(lo[c] - depth * n[c]);
                        hi[c] = hi[c].max(hi[c] - depth * n[c]);
                    }
                }
                (lo, hi)
            })
            .collect();
        // Masters sorted by their lower x bound: a sweep finds each slave's.
        let mut order: Vec<u32> = (0..masters.len() as u32).collect();
        order.sort_by(|a, b| masters[*a as usize].0[0].total_cmp(&masters[*b as usize].0[0]));
        let d = margin;
        let mut pairs = Vec::new();
        for &s in &self.evaluated {
            let (lo, hi) = bbox(&self.slave_facets[s as usize]);
            let end = order.partition_point(|&m| masters[m as usize].0[0] <= hi[0] + d);
            let mut found: Vec<u32> = order[..end]
                .iter()
                .copied()
                .filter(|&m| {
                    let (mlo, mhi) = masters[m as usize];
                    (0..3).all(|c| mlo[c] <= hi[c] + d && mhi[c] >= lo[c] - d)
                })
                .collect();
            found.sort_unstable();
            pairs.extend(found.into_iter().map(|m| (s, m)));
        }
        pairs
    }

    /// The nodes (ids, ascending) of every evaluated slave facet and held
    /// master facet whose bounding box at `x`, grown by `reach`, meets one
    /// of the other surface's.
    pub(super) fn nodes_within(&self, m: &FacetSide, x: &[[f64; 3]], reach: f64) -> Vec<u32> {
        let nf = self.facet_type.nodes();
        let boxes = |facets: &mut dyn Iterator<Item = &[u32; MAX_FACET_NODES]>| {
            facets
                .map(|f| bounding_box(&f[..nf], x))
                .collect::<Vec<_>>()
        };
        let slaves = boxes(
            &mut self
                .evaluated
                .iter()
                .map(|&s| &self.slave_facets[s as usize]),
        );
        let masters = boxes(&mut m.facets.iter());
        let mut nodes: Vec<u32> = Vec::new();
        let near_slaves = meeting_any(&slaves, &masters, reach);
        for (&s, near) in self.evaluated.iter().zip(near_slaves) {
            if near {
                nodes.extend(&self.slave_facets[s as usize][..nf]);
            }
        }
        for (f, near) in m.facets.iter().zip(meeting_any(&masters, &slaves, reach)) {
            if near {
                nodes.extend(&f[..nf]);
            }
        }
        nodes.sort_unstable();
        nodes.dedup();
        nodes
    }

    pub(super) fn facet_evaluate(
        &self,
        m: &FacetSide,
        x: &[[f64; 3]],
        u_local: &[f64],
        rate: Option<&Rate>,
    ) -> Evaluation {
        let interface = self.facet_interface(m, x);
        let (segments, facets_covered) = self.nodal.cache.segments(&interface, &self.rules);
        let (gap, covered) = system::weighted_gaps(&interface, &self.nodal, &segments);
        let states = system::node_states(&self.nodal, &gap, &covered);
        let frictions = self.frictions(&interface, &segments, &states, x, u_local, rate);
        Evaluation {
            segments,
            covered: facets_covered,
            states,
            frictions,
        }
    }

    /// The nodes' friction at these states (none for a frictionless pair).
    fn frictions(
        &self,
        interface: &Interface,
        segments: &[Segment<f64>],
        states: &[NodeState],
        x: &[[f64; 3]],
        u_local: &[f64],
        rate: Option<&Rate>,
    ) -> Vec<NodeFriction> {
        match &self.friction {
            Some(f) => {
                let (value, slope) = f.increments(&self.node_local, x, u_local, rate);
                let inc = Increment {
                    value: &value,
                    slope,
                };
                let slips = friction::segment_slips(interface, segments, &inc);
                friction::node_frictions(interface, &self.nodal, &f.nodal, states, segments, &slips)
            }
            None => Vec::new(),
        }
    }

    pub(super) fn facet_residual(
        &self,
        m: &FacetSide,
        (x, u_local): (&[[f64; 3]], &[f64]),
        rate: Option<&Rate>,
        r_local: &mut [f64],
    ) {
        let e = self.facet_evaluate(m, x, u_local, rate);
        let interface = self.facet_interface(m, x);
        let mut add = |n: u32, c: usize, v: f64| {
            r_local[self.local_dof(n, c)] += v;
        };
        system::residual(&interface, &self.nodal, &e.segments, &e.states, &mut add);
        if self.friction.is_some() {
            friction::residual(&interface, &self.nodal, &e.segments, &e.frictions, &mut add);
        }
    }

    /// See `MortarPair::tangent`.
    pub(super) fn facet_tangent(
        &self,
        m: &FacetSide,
        (x, u_local): (&[[f64; 3]], &[f64]),
        (rate, main_part): (Option<&Rate>, bool),
        k: &mut dyn MatrixSink,
    ) -> Result<u64> {
        if main_part && self.friction.is_none() {
            return self.add_main_part(m, x, u_local, k);
        }
        let e = self.facet_evaluate(m, x, u_local, rate);
        let interface = self.facet_interface(m, x);
        let mut rows = Rows::new(self.node_local.len());
        self.stream_tangent(&interface, &e, x, u_local, rate, &mut rows);
        rows.add_to(|id, c| self.global_dof(id, c), k)?;
        Ok(self.signature_of(&e))
    }

    /// The tangent at the node states (and friction) of the f64
    /// evaluation `e`: the derivatives are taken only on the overlaps of
    /// slave facets with a closed node (the tangent of an open node is
    /// zero, and a closed node's facets are all among them, so its terms
    /// are complete; on a curved slave most overlaps lie away from the
    /// contact), and the f64 pass found them: the dual pass makes the same
    /// clipping decisions on the values. Each `Dual` segment goes into the
    /// normal and tangential tangents as it is integrated.
    fn stream_tangent(
        &self,
        interface: &Interface,
        e: &Evaluation,
        x: &[[f64; 3]],
        u_local: &[f64],
        rate: Option<&Rate>,
        rows: &mut Rows,
    ) {
        let nf = self.facet_type.nodes();
        let closed = |f: u32| {
            self.slave_facets[f as usize][..nf]
                .iter()
                .any(|&n| self.nodal.slot_of(n).is_some_and(|j| e.states[j].closed))
        };
        let live: Vec<(u32, u32)> = e
            .segments
            .iter()
            .filter(|s| closed(s.slave))
            .map(|s| (s.slave, s.master))
            .collect();
        let live = Interface {
            candidates: &live,
            ..*interface
        };
        let increments = self
            .friction
            .as_ref()
            .map(|f| f.increments(&self.node_local, x, u_local, rate));
        type D = Dual<{ system::SEGMENT_DOFS }>;
        let mut add = |r, c, v| rows.add(r, c, v);
        match (&self.friction, &increments) {
            (Some(_), Some((value, slope))) => {
                let inc = Increment {
                    value,
                    slope: *slope,
                };
                let mut t = friction::FrictionalTangent::new(
                    interface,
                    &self.nodal,
                    &e.states,
                    &e.frictions,
                );
                system::for_each_segment::<D>(&live, &self.rules, &e.covered, |seg| {
                    t.add(
                        &seg,
                        &friction::segment_slip(interface, &seg, &inc),
                        &mut add,
                    );
                });
                t.finish(add);
            }
            _ => {
                let mut t = system::FrictionlessTangent::new(interface, &self.nodal, &e.states);
                system::for_each_segment::<D>(&live, &self.rules, &e.covered, |seg| {
                    t.add(&seg, &mut add)
                });
                t.finish(add);
            }
        }
    }

    fn add_main_part(
        &self,
        m: &FacetSide,
        x: &[[f64; 3]],
        u_local: &[f64],
        k: &mut dyn MatrixSink,
    ) -> Result<u64> {
        let e = self.facet_evaluate(m, x, u_local, None);
        let interface = self.facet_interface(m, x);
        let mut rows = Rows::new(self.node_local.len());
        let add = |r, c, v| rows.add(r, c, v);
        super::main_part::tangent(&interface, &self.nodal, &e.segments, &e.states, add);
        rows.add_to(|id, c| self.global_dof(id, c), k)?;
        Ok(self.signature_of(&e))
    }

    /// The active-set signature of an evaluation (see `MortarPair::tangent`).
    fn signature_of(&self, e: &Evaluation) -> u64 {
        signature(
            &e.segments,
            &e.states,
            &e.frictions,
            &self.slave_facets,
            self.facet_type.nodes(),
            &self.nodal,
        )
    }

    /// Node states and, per assembled facet row, `(slot, Σ_k D_jk,
    /// Σ_k D_jk ν)` (the output's weights and force directions).
    pub(super) fn facet_output_rows(
        &self,
        m: &FacetSide,
        x: &[[f64; 3]],
        u_local: &[f64],
        rate: Option<&Rate>,
    ) -> (Vec<NodeState>, OutputRows) {
        let Evaluation {
            segments, states, ..
        } = self.facet_evaluate(m, x, u_local, rate);
        let nf = self.facet_type.nodes();
        let mut rows = Vec::new();
        for seg in segments.iter().filter(|s| self.assembled[s.slave as usize]) {
            for (a, &n) in self.slave_facets[seg.slave as usize][..nf]
                .iter()
                .enumerate()
            {
                if let Some(j) = self.nodal.slot_of(n) {
                    let d: f64 = seg.terms.d[a][..nf].iter().sum();
                    rows.push((j, d, seg.terms.normal.map(|c| d * c)));
                }
            }
        }
        (states, rows)
    }
}

type BoundingBox = ([f64; 3], [f64; 3]);

fn bounding_box(nodes: &[u32], x: &[[f64; 3]]) -> BoundingBox {
    let mut lo = [f64::INFINITY; 3];
    let mut hi = [f64::NEG_INFINITY; 3];
    for &n in nodes {
        for c in 0..3 {
            lo[c] = lo[c].min(x[n as usize][c]);
            hi[c] = hi[c].max(x[n as usize][c]);
        }
    }
    (lo, hi)
}

/// For each box of `a`: whether it meets, grown by `d`, some box of `b`
/// (a sweep over `b` sorted by its lower x bound).
fn meeting_any(a: &[BoundingBox], b: &[BoundingBox], d: f64) -> Vec<bool> {
    let mut order: Vec<&BoundingBox> = b.iter().collect();
    order.sort_by(|p, q| p.0[0].total_cmp(&q.0[0]));
    a.iter()
        .map(|(lo, hi)| {
            let end = order.partition_point(|m| m.0[0] <= hi[0] + d);
            order[..end]
                .iter()
                .any(|(mlo, mhi)| (0..3).all(|c| mlo[c] <= hi[c] + d && mhi[c] >= lo[c] - d))
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn boxes_meet_within_the_distance_only() {
        let unit = |x: f64| ([x, 0.0, 0.0], [x + 1.0, 1.0, 1.0]);
        let b = [unit(5.0), unit(-3.0)];
        // Gaps to the nearest box of b: 0, 0.5, 1.5 (and overlapping).
        let a = [unit(4.0), unit(3.5), unit(2.5), unit(4.5)];
        assert_eq!(meeting_any(&a, &b, 1.0), [true, true, false, true]);
        assert_eq!(meeting_any(&a, &b, 0.0), [true, false, false, true]);
        // Apart in y alone.
        let high = [([5.0, 3.0, 0.0], [6.0, 4.0, 1.0])];
        assert_eq!(meeting_any(&high, &b, 1.5), [false]);
        assert_eq!(meeting_any(&high, &b, 2.0), [true]);
        assert_eq!(meeting_any(&a, &[], 9.0), [false; 4]);
        let bb = bounding_box(&[0, 2], &[[1.0, 2.0, 3.0], [9.0; 3], [-1.0, 4.0, 0.0]]);
        assert_eq!(bb, ([-1.0, 2.0, 0.0], [1.0, 4.0, 3.0]));
    }
}

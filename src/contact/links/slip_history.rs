//! Friction history at run time: where each point's slip is measured from
//! and its λT, expressed on the link's current master facet (carried over as
//! the same material point and the same vector when the link changes facet),
//! started at first contact and renewed by every Uzawa update.
use super::kernel::{LinkState, SlipHistory};
use super::link::Link;
use super::multipliers::{PointFriction, PointState};
use super::LinksPair;
use crate::contact::autodiff::dot;
use crate::contact::held_master::HeldMaster;
use crate::contact::master::MasterSide;
use crate::contact::projection;

impl LinksPair {
    /// The translation of a rigid master at `factor` (zero otherwise).
    fn rigid_shift(&self, factor: f64) -> [f64; 3] {
        match &self.master {
            MasterSide::Rigid(r) => r.shift(factor),
            MasterSide::Facets(_) => [0.0; 3],
        }
    }

    /// The point's slip origin and λT in the terms of the link's current
    /// master: on a facet other than the one they were stored on, they are
    /// carried over (the origin as the same material point of the reference
    /// surface, λT as the same vector).
    pub(super) fn slip_history(
        &self,
        p: &PointFriction,
        link: &Link,
        factor: f64,
        u_local: &[f64],
    ) -> SlipHistory {
        match &self.master {
            MasterSide::Facets(m) => {
                // The history names facets by set index (it outlives the
                // step's held numbering). A facet no longer held (the point
                // slid beyond the search margin within one step) starts
                // from the link's own point and keeps λT's components.
                let here = m.set_index_of(link.facet);
                let xi_n = match p.origin {
                    Some((o, f)) if f == here => [o[0], o[1]],
                    Some((o, f)) => match m.held_facet(f) {
                        Some(from) => rebase_origin(m, from, [o[0], o[1]], link.facet, link.xi),
                        None => link.xi,
                    },
                    None => link.xi,
                };
                let lambda = match m.held_facet(p.lambda_facet) {
                    Some(from) if p.lambda_facet != here && p.lambda != [0.0; 3] => rebase_lambda(
                        m,
                        &self.positions,
                        from,
                        [p.lambda[0], p.lambda[1]],
                        link.facet,
                        link.xi,
                    ),
                    _ => [p.lambda[0], p.lambda[1]],
                };
                SlipHistory::Convected { xi_n, lambda }
            }
            MasterSide::Rigid(r) => {
                let shift = self.rigid_shift(factor);
                let point_n = match p.origin {
                    Some((o, _)) => [o[0] + shift[0], o[1] + shift[1], o[2] + shift[2]],
                    // No history (the step's search sets one for every
                    // link): no slip yet.
                    None => r
                        .placed(factor)
                        .closest_point(self.slave.qp_position(link.qp_index(), u_local)),
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
    pub(super) fn start_slip(&mut self, points: &[[f64; 3]], factor: f64) {
        let shift = self.rigid_shift(factor);
        let Some(t) = &mut self.multipliers.tangential else {
            return;
        };
        for l in &self.links {
            let p = &mut t.points[l.qp_index()];
            if p.origin.is_some() {
                continue;
            }
            p.origin = Some(match &self.master {
                MasterSide::Facets(m) => ([l.xi[0], l.xi[1], 0.0], m.set_index_of(l.facet)),
                MasterSide::Rigid(r) => {
                    let foot = r.placed(factor).closest_point(points[l.qp_index()]);
                    (
                        [foot[0] - shift[0], foot[1] - shift[1], foot[2] - shift[2]],
                        0,
                    )
                }
            });
            if p.lambda == [0.0; 3] {
                p.lambda_facet = global_facet(&self.master, l.facet);
            }
        }
    }

    /// λT ← tT and the stick/slip state of every point from this
    /// evaluation; returns how many points slide.
    pub(super) fn update_friction(&mut self, states: &[LinkState], factor: f64) -> usize {
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
            let p = &mut fresh[l.qp_index()];
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
                    let facet = global_facet(&self.master, l.facet);
                    p.lambda_facet = facet;
                    p.next_origin = Some(([xi_n[0], xi_n[1], 0.0], facet));
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
}

/// The set index of held facet `facet` (0 for a rigid master).
fn global_facet(master: &MasterSide, facet: u32) -> u32 {
    match master {
        MasterSide::Facets(m) => m.set_index_of(facet),
        MasterSide::Rigid(_) => 0,
    }
}

/// Tangents `∂x/∂ξ_α` of a facet with nodes `x` at `xi`.
fn facet_tangents(m: &HeldMaster, x: &[[f64; 3]], xi: [f64; 2]) -> [[f64; 3]; 2] {
    let s = crate::contact::facet_shape::<{ crate::contact::MAX_FACET_NODES }>(m.facet_type, xi);
    let mut t = [[0.0; 3]; 2];
    for (xb, dn) in x.iter().zip(&s.dn) {
        for c in 0..3 {
            t[0][c] += dn[0] * xb[c];
            t[1][c] += dn[1] * xb[c];
        }
    }
    t
}

fn facet_points(m: &HeldMaster, facet: u32, positions: &[[f64; 3]]) -> Vec<[f64; 3]> {
    m.facet_nodes(facet)
        .iter()
        .map(|&n| positions[n as usize])
        .collect()
}

/// ξ̄ₙ stored on facet `from`, expressed on facet `to`: the same point of the
/// reference surface (history data is material, so the conversion is
/// independent of the current displacements).
fn rebase_origin(m: &HeldMaster, from: u32, xi: [f64; 2], to: u32, guess: [f64; 2]) -> [f64; 2] {
    let from_x = facet_points(m, from, &m.x_ref);
    let s = crate::contact::facet_shape::<{ crate::contact::MAX_FACET_NODES }>(m.facet_type, xi);
    let mut p = [0.0; 3];
    for (xb, nb) in from_x.iter().zip(s.n) {
        for c in 0..3 {
            p[c] += nb * xb[c];
        }
    }
    let to_x = facet_points(m, to, &m.x_ref);
    projection::project(m.facet_type, &to_x, p, Some(guess)).xi
}

/// λT's covariant components on facet `from` carried to facet `to` as the
/// same vector (tangents of `from` at its centre, of `to` at `xi`).
fn rebase_lambda(
    m: &HeldMaster,
    positions: &[[f64; 3]],
    from: u32,
    lambda: [f64; 2],
    to: u32,
    xi: [f64; 2],
) -> [f64; 2] {
    let [t1, t2] = facet_tangents(
        m,
        &facet_points(m, from, positions),
        projection::reference_centre(m.facet_type),
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

#[cfg(test)]
mod tests {
    use super::*;
    use crate::contact::autodiff::{norm, sub};
    use crate::fem::FacetType;

    /// Two unit quads side by side in z = 0 (x ∈ [0, 1] and [1, 2]), the
    /// second one's nodes listed from a different corner so its ξ axes are
    /// turned against the first's.
    fn two_quads() -> HeldMaster {
        HeldMaster::from_parts(
            FacetType::Quad4,
            vec![
                [0.0, 0.0, 0.0],
                [1.0, 0.0, 0.0],
                [2.0, 0.0, 0.0],
                [0.0, 1.0, 0.0],
                [1.0, 1.0, 0.0],
                [2.0, 1.0, 0.0],
            ],
            vec![[0, 1, 4, 3], [5, 4, 1, 2]]
                .into_iter()
                .map(|f| {
                    let mut row = [0; crate::contact::MAX_FACET_NODES];
                    row[..4].copy_from_slice(&f);
                    row
                })
                .collect(),
        )
    }

    fn point_on(m: &HeldMaster, facet: u32, x: &[[f64; 3]], xi: [f64; 2]) -> [f64; 3] {
        let s =
            crate::contact::facet_shape::<{ crate::contact::MAX_FACET_NODES }>(m.facet_type, xi);
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

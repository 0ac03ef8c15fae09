//! The mortar pair's facet search: the candidate (slave, master) facet
//! pairs whose bounding boxes meet, and the nodes reserved for the contact
//! DOFs (those within the links' search distance of the other surface).
use super::pair::MortarPair;
use crate::fem::surface::facet_normal_at_centre;
use crate::fem::MAX_FACET_NODES;

impl MortarPair {
    /// Every (evaluated slave, held master) facet pair whose bounding boxes
    /// at positions `x`, grown by `margin`, meet; by slave, then master. A
    /// master facet's box also reaches one facet size behind it (into its
    /// body), so that a slave facet pushed through the master surface
    /// further than its own thickness still pairs with the facets it
    /// crossed.
    pub(super) fn facet_pairs(&self, x: &[[f64; 3]], margin: f64) -> Vec<(u32, u32)> {
        let nf = self.facet_type.nodes();
        let bbox = |f: &[u32; MAX_FACET_NODES]| bounding_box(&f[..nf], x);
        let masters: Vec<_> = self
            .master_facets
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
    pub(super) fn nodes_within(&self, x: &[[f64; 3]], reach: f64) -> Vec<u32> {
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
        let masters = boxes(&mut self.master_facets.iter());
        let mut nodes: Vec<u32> = Vec::new();
        let near_slaves = meeting_any(&slaves, &masters, reach);
        for (&s, near) in self.evaluated.iter().zip(near_slaves) {
            if near {
                nodes.extend(&self.slave_facets[s as usize][..nf]);
            }
        }
        for (f, near) in self
            .master_facets
            .iter()
            .zip(meeting_any(&masters, &slaves, reach))
        {
            if near {
                nodes.extend(&f[..nf]);
            }
        }
        nodes.sort_unstable();
        nodes.dedup();
        nodes
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

//! Contact search throughput against the number of slave points (serial).
//!
//! A warped and a flat master surface of m × m quads over the unit square and
//! n slave points at 0.3 h and 3 h above it, in mesh order (neighbours one after another, as a slave
//! surface's points come) and in shuffled order (no locality). For each n:
//! index build time, search time (median of 3), points per second and
//! nanoseconds per point. The search must grow like n log n or better: flat
//! ns/point means linear. Output: CSV on stdout.
use contactlink::contact::search::{SearchIndex, SearchSurface};
use contactlink::contact::MAX_FACET_NODES;
use contactlink::fem::FacetType;
use std::time::Instant;

/// Amplitude of the warped master; a curved master costs more projection
/// iterations per point than a flat one.
const WARPS: [f64; 2] = [0.05, 0.0];

fn master(m: usize, warp: f64) -> (Vec<[f64; 3]>, Vec<[u32; MAX_FACET_NODES]>) {
    let h = 1.0 / m as f64;
    let mut x = Vec::with_capacity((m + 1) * (m + 1));
    for j in 0..=m {
        for i in 0..=m {
            let (px, py) = (i as f64 * h, j as f64 * h);
            x.push([px, py, warp * (6.0 * px).sin() * (4.0 * py).cos()]);
        }
    }
    let id = |i: usize, j: usize| (j * (m + 1) + i) as u32;
    let mut facets = Vec::with_capacity(m * m);
    for j in 0..m {
        for i in 0..m {
            let mut row = [0; MAX_FACET_NODES];
            row[..4].copy_from_slice(&[id(i, j), id(i + 1, j), id(i + 1, j + 1), id(i, j + 1)]);
            facets.push(row);
        }
    }
    (x, facets)
}

/// n points on a regular grid at height `gap` above the surface, row by row.
fn slave_points(n: usize, warp: f64, gap: f64) -> Vec<[f64; 3]> {
    let k = (n as f64).sqrt().ceil() as usize;
    (0..n)
        .map(|p| {
            let (i, j) = (p % k, p / k);
            let (x, y) = ((i as f64 + 0.5) / k as f64, (j as f64 + 0.5) / k as f64);
            [x, y, warp * (6.0 * x).sin() * (4.0 * y).cos() + gap]
        })
        .collect()
}

/// A fixed pseudo-random permutation (no locality between consecutive points).
fn shuffled(mut v: Vec<[f64; 3]>) -> Vec<[f64; 3]> {
    let mut s: u64 = 0x9E37_79B9_7F4A_7C15;
    for i in (1..v.len()).rev() {
        s ^= s << 13;
        s ^= s >> 7;
        s ^= s << 17;
        v.swap(i, (s % (i as u64 + 1)) as usize);
    }
    v
}

fn median(mut v: Vec<f64>) -> f64 {
    v.sort_by(|a, b| a.total_cmp(b));
    v[v.len() / 2]
}

fn main() {
    let m = 300; // 90,000 master facets
    let h = 1.0 / m as f64;
    println!(
        "master,master_facets,gap_over_h,slave_points,order,build_s,search_s,points_per_s,ns_per_point,found"
    );
    for warp in WARPS {
        let (x, facets) = master(m, warp);
        let surface = SearchSurface {
            facet_type: FacetType::Quad4,
            positions: &x,
            facets: &facets,
        };
        let t = Instant::now();
        let index = SearchIndex::build(&surface);
        let build = t.elapsed().as_secs_f64();
        let kind = if warp > 0.0 { "warped" } else { "flat" };
        // Points in or near contact (0.3 h) are what a load step searches
        // for most; 3 h is far out in the search distance (10 h).
        for gap_h in [0.3, 3.0] {
            for (n, order) in [
                (10_000usize, "mesh"),
                (100_000, "mesh"),
                (1_000_000, "mesh"),
                (100_000, "shuffled"),
            ] {
                let mut points = slave_points(n, warp, gap_h * h);
                if order == "shuffled" {
                    points = shuffled(points);
                }
                let mut found = 0;
                let secs = median(
                    (0..3)
                        .map(|_| {
                            let t = Instant::now();
                            found = points
                                .iter()
                                .filter(|p| index.find(&surface, **p, 0.1).is_some())
                                .count();
                            t.elapsed().as_secs_f64()
                        })
                        .collect(),
                );
                println!(
                    "{kind},{},{gap_h},{n},{order},{build:.4},{secs:.4},{:.3e},{:.0},{found}",
                    facets.len(),
                    n as f64 / secs,
                    1e9 * secs / n as f64
                );
            }
        }
    }
}

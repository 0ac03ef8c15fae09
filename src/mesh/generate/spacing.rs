//! One-dimensional node distributions used to build structured blocks.
//!
//! Errors are plain reasons; the generators wrap them into
//! [`MeshError::InvalidSpec`](crate::mesh::MeshError) with the field name.

/// Upper bound on divisions along one line, so that a mistyped size cannot
/// make a generator try to allocate the whole machine.
pub(crate) const MAX_DIVISIONS: usize = 1 << 20;

/// Finest `level` accepted by the generators (each level halves sizes).
pub(crate) const MAX_LEVEL: u32 = 8;

/// How element sizes vary along one axis of a [`BoxSpec`](super::BoxSpec).
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub enum Grading {
    /// Equal element sizes.
    #[default]
    Uniform,
    /// Sizes grow by a constant factor from the low end to the high end;
    /// `ratio` = last element size / first element size (< 1 refines the
    /// high end instead).
    Geometric { ratio: f64 },
    /// Fine elements near the coordinate `point` (absolute, in mesh units,
    /// on this axis; it may lie inside, at an end of, or outside the box):
    /// the element size grows linearly with the distance from `point`, and
    /// the elements at the farthest end are `ratio` times larger than those
    /// at `point`. `point` at an end biases toward that end, at the middle
    /// toward the centre.
    Toward { point: f64, ratio: f64 },
}

fn check_ratio(ratio: f64) -> Result<(), String> {
    if ratio.is_finite() && ratio > 0.0 {
        Ok(())
    } else {
        Err(format!("ratio must be positive and finite (got {ratio})"))
    }
}

/// `n + 1` node coordinates from `start` to `start + length`.
pub(crate) fn graded_coordinates(
    start: f64,
    length: f64,
    n: usize,
    grading: Grading,
) -> Result<Vec<f64>, String> {
    if n == 0 || n > MAX_DIVISIONS {
        return Err(format!(
            "divisions must be in 1..={MAX_DIVISIONS} (got {n})"
        ));
    }
    if !(length.is_finite() && length > 0.0 && start.is_finite()) {
        return Err(format!(
            "start and length must be finite with positive length (got {start}, {length})"
        ));
    }
    let unit = match grading {
        Grading::Uniform => (0..=n).map(|i| i as f64 / n as f64).collect(),
        Grading::Geometric { ratio } => {
            check_ratio(ratio)?;
            geometric_unit(n, ratio)
        }
        Grading::Toward { point, ratio } => {
            check_ratio(ratio)?;
            if !point.is_finite() {
                return Err(format!("point must be finite (got {point})"));
            }
            toward_unit(n, (point - start) / length, ratio)
        }
    };
    Ok(unit.iter().map(|u| start + length * u).collect())
}

/// Geometric sizes on [0, 1], first-to-last size ratio `ratio`.
fn geometric_unit(n: usize, ratio: f64) -> Vec<f64> {
    let q = if n > 1 {
        ratio.powf(1.0 / (n - 1) as f64)
    } else {
        1.0
    };
    let sizes: Vec<f64> = (0..n).map(|i| q.powi(i as i32)).collect();
    cumulate_normalised(&sizes)
}

/// Linear size law h(x) = h0 (1 + k |x − p|) on [0, 1]. Equal steps of the
/// stretched coordinate s = sign(x − p) ln(1 + k |x − p|) / k give exactly
/// that size law in the continuum limit, with any p inside or outside.
fn toward_unit(n: usize, p: f64, ratio: f64) -> Vec<f64> {
    let far = p.abs().max((1.0 - p).abs());
    let k = (ratio - 1.0) / far;
    if k.abs() < 1e-12 {
        return (0..=n).map(|i| i as f64 / n as f64).collect();
    }
    let stretch = |x: f64| (x - p).signum() * (k * (x - p).abs()).ln_1p() / k;
    let unstretch = |s: f64| p + s.signum() * (k * s.abs()).exp_m1() / k;
    let (s0, s1) = (stretch(0.0), stretch(1.0));
    let mut unit: Vec<f64> = (0..=n)
        .map(|i| unstretch(s0 + (s1 - s0) * i as f64 / n as f64))
        .collect();
    // Pin the ends exactly: box faces must be exactly planar.
    unit[0] = 0.0;
    unit[n] = 1.0;
    unit
}

/// Prefix sums of `sizes`, scaled so the last value is exactly 1.
fn cumulate_normalised(sizes: &[f64]) -> Vec<f64> {
    let total: f64 = sizes.iter().sum();
    let mut out = Vec::with_capacity(sizes.len() + 1);
    let mut acc = 0.0;
    out.push(0.0);
    for s in sizes {
        acc += s;
        out.push(acc / total);
    }
    if let Some(last) = out.last_mut() {
        *last = 1.0;
    }
    out
}

/// Nodes on [0, `length`]: uniform size ≈ `h` over [0, `core`], then sizes
/// growing by at most `growth` per element up to `length`. This is the
/// contact-zone distribution: fine and uniform where the pressure lives,
/// cheap far away.
pub(crate) fn core_then_graded(
    length: f64,
    core: f64,
    h: f64,
    growth: f64,
) -> Result<Vec<f64>, String> {
    // The fine zone is at least one element and at most the whole line.
    let core_len = core.max(h).min(length);
    let n_core = divisions_for(core_len, h)?;
    let h_core = core_len / n_core as f64;
    let mut sizes = vec![h_core; n_core];
    let rest = length - core_len;
    if rest > 1e-12 * length {
        sizes.extend(growing_sizes(rest, h_core, growth)?);
    }
    Ok(cumulate_normalised(&sizes)
        .into_iter()
        .map(|u| u * length)
        .collect())
}

/// Number of elements of size ≈ `h` in `length` (at least one).
fn divisions_for(length: f64, h: f64) -> Result<usize, String> {
    let n = (length / h).round().max(1.0);
    if n > MAX_DIVISIONS as f64 {
        return Err(format!(
            "{length} / {h} needs more than {MAX_DIVISIONS} elements"
        ));
    }
    Ok(n as usize)
}

/// Sizes h q, h q², …, h qⁿ filling `length` exactly with the fewest
/// elements and q ≤ `growth`; uniform if even q = 1 overfills.
fn growing_sizes(length: f64, h: f64, growth: f64) -> Result<Vec<f64>, String> {
    let n = fewest_growing_elements(length, h, growth)?;
    if n as f64 * h >= length {
        let m = divisions_for(length, h)?;
        return Ok(vec![length / m as f64; m]);
    }
    let q = solve_growth(length, h, n, growth);
    Ok((1..=n).map(|i| h * q.powi(i as i32)).collect())
}

fn geometric_sum(h: f64, q: f64, n: usize) -> f64 {
    (1..=n).map(|i| h * q.powi(i as i32)).sum()
}

fn fewest_growing_elements(length: f64, h: f64, growth: f64) -> Result<usize, String> {
    let mut covered = 0.0;
    let mut size = h;
    for n in 1..=MAX_DIVISIONS {
        size *= growth;
        covered += size;
        if covered >= length {
            return Ok(n);
        }
    }
    Err(format!(
        "grading from size {h} by {growth} needs more than {MAX_DIVISIONS} elements to span {length}"
    ))
}

/// Bisection for q in [1, growth] with Σ h qⁱ = length; the sum is
/// increasing in q and brackets `length` by construction of `n`.
fn solve_growth(length: f64, h: f64, n: usize, growth: f64) -> f64 {
    let (mut lo, mut hi) = (1.0, growth);
    for _ in 0..100 {
        let mid = 0.5 * (lo + hi);
        if geometric_sum(h, mid, n) < length {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    0.5 * (lo + hi)
}

/// [`core_then_graded`] mirrored about 0: nodes on [−half, half], fine and
/// uniform over |x| ≤ core, with a node at exactly 0.
pub(crate) fn symmetric_core(
    half: f64,
    core: f64,
    h: f64,
    growth: f64,
) -> Result<Vec<f64>, String> {
    let one_side = core_then_graded(half, core, h, growth)?;
    let mut nodes: Vec<f64> = one_side.iter().rev().map(|x| -x).collect();
    nodes.extend_from_slice(&one_side[1..]);
    Ok(nodes)
}

/// Splits every interval into 2^`level` equal parts, so each level halves
/// every element size and the coarser nodes stay in the finer mesh.
pub(crate) fn subdivide(nodes: &[f64], level: u32) -> Vec<f64> {
    let parts = 1usize << level.min(MAX_LEVEL);
    let mut out = Vec::with_capacity(nodes.len().saturating_sub(1) * parts + 1);
    for pair in nodes.windows(2) {
        for k in 0..parts {
            out.push(pair[0] + (pair[1] - pair[0]) * k as f64 / parts as f64);
        }
    }
    if let Some(&last) = nodes.last() {
        out.push(last);
    }
    out
}

/// Checks the shared parameters of the contact-zone distributions.
pub(crate) fn check_fine_zone(h: f64, core: f64, growth: f64) -> Result<(), (String, String)> {
    if !(h.is_finite() && h > 0.0) {
        return Err((
            "fine_size".into(),
            format!("must be positive and finite (got {h})"),
        ));
    }
    if !(core.is_finite() && core >= 0.0) {
        return Err((
            "fine_half_width".into(),
            format!("must be non-negative and finite (got {core})"),
        ));
    }
    if !(growth.is_finite() && growth >= 1.0) {
        return Err((
            "growth".into(),
            format!("must be finite and >= 1 (got {growth})"),
        ));
    }
    Ok(())
}

/// Fine contact-zone parameters: element size, half-width (and depth) of the
/// uniformly fine zone, growth ratio outside it.
pub(crate) struct FineZone {
    pub size: f64,
    pub half_width: f64,
    pub growth: f64,
}

/// Lines of a contact block with its top at z = 0: lateral nodes on
/// [−half_width, half_width] fine around 0, vertical nodes on [−height, 0]
/// fine below 0; both refined to `level`.
pub(crate) fn contact_block_lines(
    half_width: f64,
    height: f64,
    fine: &FineZone,
    level: u32,
) -> Result<(Vec<f64>, Vec<f64>), String> {
    let lateral = symmetric_core(half_width, fine.half_width, fine.size, fine.growth)?;
    let depth = core_then_graded(height, fine.half_width, fine.size, fine.growth)?;
    let vertical: Vec<f64> = depth.iter().rev().map(|d| -d).collect();
    Ok((subdivide(&lateral, level), subdivide(&vertical, level)))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn sizes(nodes: &[f64]) -> Vec<f64> {
        nodes.windows(2).map(|w| w[1] - w[0]).collect()
    }

    #[test]
    fn core_then_graded_is_fine_then_smoothly_growing() {
        for (length, core, h, growth) in [
            (20.0, 2.0, 0.1, 1.2),
            (5.0, 1.0, 0.25, 1.1),
            (3.0, 0.0, 0.5, 1.5),
        ] {
            let x = core_then_graded(length, core, h, growth).unwrap();
            assert_eq!(x[0], 0.0);
            assert!((x[x.len() - 1] - length).abs() < 1e-12 * length);
            let s = sizes(&x);
            assert!((s[0] - h).abs() < 1e-9, "first size {}", s[0]);
            for pair in s.windows(2) {
                let ratio = pair[1] / pair[0];
                assert!(
                    (1.0 - 1e-9..=growth * (1.0 + 1e-9)).contains(&ratio),
                    "{ratio} in {s:?}"
                );
            }
            // Uniform over the fine zone.
            let fine = x.iter().filter(|&&v| v <= core + 1e-12).count() - 1;
            assert!(s[..fine].iter().all(|&v| (v - h).abs() < 1e-9));
        }
    }

    #[test]
    fn growth_one_and_short_lines_stay_uniform() {
        let x = core_then_graded(2.0, 0.5, 0.25, 1.0).unwrap();
        assert!(sizes(&x).iter().all(|&v| (v - 0.25).abs() < 1e-12));
        let short = core_then_graded(0.1, 1.0, 0.25, 1.2).unwrap();
        assert_eq!(short, vec![0.0, 0.1]);
    }

    #[test]
    fn symmetric_core_has_node_at_zero() {
        let x = symmetric_core(10.0, 1.0, 0.2, 1.3).unwrap();
        assert_eq!(x.len() % 2, 1);
        let mid = x.len() / 2;
        assert_eq!(x[mid], 0.0);
        for k in 0..x.len() {
            assert_eq!(x[k], -x[x.len() - 1 - k]);
        }
    }

    #[test]
    fn subdivide_halves_every_size_and_keeps_nodes() {
        let x = vec![0.0, 1.0, 3.0, 7.0];
        let y = subdivide(&x, 2);
        assert_eq!(y.len(), 13);
        assert_eq!(y[4], 1.0);
        assert_eq!(y[8], 3.0);
        assert_eq!(y[12], 7.0);
        assert_eq!(sizes(&y)[..4], [0.25; 4]);
        assert_eq!(subdivide(&x, 0), x);
    }

    #[test]
    fn oversized_requests_are_errors() {
        assert!(core_then_graded(1.0, 1.0, 1e-9, 1.2).is_err());
        assert!(core_then_graded(1e9, 0.0, 1e-3, 1.0).is_err());
        assert!(graded_coordinates(0.0, 1.0, MAX_DIVISIONS + 1, Grading::Uniform).is_err());
        assert!(graded_coordinates(
            0.0,
            1.0,
            3,
            Grading::Toward {
                point: f64::NAN,
                ratio: 2.0
            }
        )
        .is_err());
    }
}

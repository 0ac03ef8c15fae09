use super::*;

/// One rank: the local sums are the global ones.
fn alone(x: [f64; REDUCED]) -> [f64; REDUCED] {
    x
}

/// Iterates λ ← G(λ) (accelerated with `depth`) until |G(λ) − λ|∞ ≤ tol;
/// the fixed point and the number of evaluations of G.
fn solve(
    g: &dyn Fn(&[f64]) -> Vec<f64>,
    start: Vec<f64>,
    depth: usize,
    tol: f64,
) -> (Vec<f64>, usize) {
    let mut acc = Anderson::new(depth);
    let counted = vec![true; start.len()];
    let mut lambda = start;
    for k in 1..=200 {
        let next = g(&lambda);
        let change = next
            .iter()
            .zip(&lambda)
            .map(|(a, b)| (a - b).abs())
            .fold(0.0, f64::max);
        if change <= tol {
            return (next, k);
        }
        lambda = acc
            .next(&lambda, &next, &counted, &mut alone)
            .unwrap_or(next);
    }
    panic!("no convergence in 200 iterations");
}

#[test]
fn the_secant_step_solves_a_scalar_linear_map_at_once() {
    // G(λ) = 0.5 λ + 1: λ* = 2, plain Uzawa contracts by 0.5 an iteration
    // (the secant coefficient is −1, at the bound `MAX_GAMMA`).
    let g = |l: &[f64]| vec![(0.5 * l[0] + 1.0_f64).max(0.0)];
    let (plain, n_plain) = solve(&g, vec![0.0], 0, 1e-10);
    let (fast, n_fast) = solve(&g, vec![0.0], 1, 1e-10);
    assert!((plain[0] - 2.0).abs() < 1e-8 && (fast[0] - 2.0).abs() < 1e-12);
    assert!(n_plain > 30, "plain: {n_plain}");
    // G(0), G(1) (plain), then the secant step lands on 2: G(2) = 2.
    assert_eq!(n_fast, 3);
}

/// A projected linear map with a known answer: G(λ) = ⟨λ − (A λ − b)⟩
/// with A symmetric positive definite (a penalty of 1 on the gap A λ − b);
/// b chosen so that λ* = (3, 2, 0, 1.5) with the third point open (its
/// gap at λ* is positive, 0.7).
fn contact_like() -> (impl Fn(&[f64]) -> Vec<f64>, Vec<f64>) {
    let a = [
        [0.30, 0.05, 0.02, 0.00],
        [0.05, 0.25, 0.04, 0.01],
        [0.02, 0.04, 0.20, 0.03],
        [0.00, 0.01, 0.03, 0.15],
    ];
    let star = [3.0, 2.0, 0.0, 1.5];
    let mut b = [0.0; 4];
    for i in 0..4 {
        b[i] = (0..4).map(|j| a[i][j] * star[j]).sum::<f64>();
    }
    // Open the third point: its gap at λ* is 0.7 > 0.
    b[2] -= 0.7;
    let g = move |l: &[f64]| {
        (0..4)
            .map(|i| {
                let gap: f64 = (0..4).map(|j| a[i][j] * l[j]).sum::<f64>() - b[i];
                (l[i] - gap).max(0.0)
            })
            .collect::<Vec<f64>>()
    };
    (g, star.to_vec())
}

#[test]
fn anderson_finds_the_projected_fixed_point_in_fewer_updates() {
    let (g, star) = contact_like();
    let (plain, n_plain) = solve(&g, vec![0.0; 4], 0, 1e-10);
    for depth in 1..=MAX_DEPTH {
        let (fast, n_fast) = solve(&g, vec![0.0; 4], depth, 1e-10);
        for (x, s) in fast.iter().zip(&star) {
            assert!((x - s).abs() < 1e-8, "depth {depth}: {fast:?}");
        }
        assert_eq!(fast[2], 0.0, "the open point stays open");
        assert!(
            n_fast < n_plain,
            "depth {depth}: {n_fast} against {n_plain} plain updates"
        );
    }
    for (x, s) in plain.iter().zip(&star) {
        assert!((x - s).abs() < 1e-8);
    }
}

#[test]
fn ranks_that_split_the_entries_take_the_same_step_as_one() {
    // Two "ranks" hold entries {0, 1} and {2, 3} (plus a copy of entry 1,
    // not counted): summing their local reductions gives one rank's step.
    let (g, _) = contact_like();
    let mut one = Anderson::new(2);
    let mut two = [Anderson::new(2), Anderson::new(2)];
    let all = vec![true; 4];
    let masks = [
        vec![true, true, false, false, false],
        vec![false, false, true, true, false],
    ];
    let mut lambda = vec![0.0; 4];
    for _ in 0..6 {
        let next = g(&lambda);
        let mine = one.next(&lambda, &next, &all, &mut alone);
        // The split: each rank's entries in its own vector (the fifth is a
        // ghost copy of entry 1, held but not summed).
        let ext = |v: &[f64]| vec![v[0], v[1], v[2], v[3], v[1]];
        let (le, ne) = (ext(&lambda), ext(&next));
        let mut partial = [[0.0; REDUCED]; 2];
        // First pass: collect each rank's local sums by running a clone.
        for (r, acc) in two.iter().enumerate() {
            let mut probe = acc.clone();
            probe.next(&le, &ne, &masks[r], &mut |x| {
                partial[r] = x;
                x
            });
        }
        let total: [f64; REDUCED] = std::array::from_fn(|i| partial[0][i] + partial[1][i]);
        let split: Vec<Option<Vec<f64>>> = two
            .iter_mut()
            .enumerate()
            .map(|(r, acc)| acc.next(&le, &ne, &masks[r], &mut |_| total))
            .collect();
        match (&mine, &split[0], &split[1]) {
            (None, None, None) => lambda = next,
            (Some(m), Some(a), Some(b)) => {
                for (x, y) in m.iter().zip(a.iter().zip(b.iter())) {
                    assert!((x - y.0).abs() < 1e-14 && (x - y.1).abs() < 1e-14);
                }
                assert!((a[4] - m[1]).abs() < 1e-14, "the ghost copy agrees");
                lambda = m.clone();
            }
            other => panic!("the ranks disagree: {other:?}"),
        }
    }
}

#[test]
fn a_residual_that_grows_drops_the_history() {
    let mut acc = Anderson::new(1);
    let counted = [true];
    assert!(acc.next(&[0.0], &[1.0], &counted, &mut alone).is_none());
    // f went from 1 to 2: the plain update stands and the history goes.
    assert!(acc.next(&[1.0], &[3.0], &counted, &mut alone).is_none());
    assert_eq!(acc.resets, 1);
    // From there a contraction is accelerated again.
    assert!(acc.next(&[3.0], &[4.0], &counted, &mut alone).is_some());
}

#[test]
fn depth_zero_is_off() {
    let mut acc = Anderson::new(0);
    assert!(!acc.is_on());
    for _ in 0..3 {
        assert!(acc.next(&[0.0], &[1.0], &[true], &mut alone).is_none());
    }
}

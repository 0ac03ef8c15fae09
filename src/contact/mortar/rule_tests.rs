//! The segment triangles' quadrature rules: exact to their degree, and
//! the fewer-point rules equal to the degree-6 rule where the integrands
//! allow.
use super::geometry::NEAR_AFFINE;
use super::segment::{reference_distortion, MortarRules};
use super::system::{segments, Interface, Segment};
use super::tests::{case_with, parallelogram_case, random_case, Case};
use crate::contact::autodiff::Dual;
use crate::fem::test_util::Lcg;
use crate::fem::FacetType::{Quad4, Tri3};

#[test]
fn segment_triangle_rules_are_exact_to_their_degree() {
    let rules = MortarRules::default();
    // ∫ x^a y^b over the reference triangle = a! b! / (a + b + 2)!.
    let factorial = |n: u32| (1..=n).map(f64::from).product::<f64>();
    for (rule, degree) in [
        (&rules.triangle, 6),
        (&rules.parallelogram_triangle, 5),
        (&rules.affine_triangle, 2),
    ] {
        for a in 0..=degree {
            for b in 0..=(degree - a) {
                let exact = factorial(a) * factorial(b) / factorial(a + b + 2);
                let got: f64 = rule
                    .iter()
                    .map(|(p, w)| w * p[0].powi(a as i32) * p[1].powi(b as i32))
                    .sum();
                assert!((got - exact).abs() < 1e-15, "x^{a} y^{b}: {got} vs {exact}");
            }
        }
    }
}

/// Asserts that `coarse` gives every segment integral and its derivative
/// as the default rules with the degree-6 rule everywhere.
fn assert_same_as_degree_six(interface: &Interface, coarse: &MortarRules) {
    let (values, derivatives) = differences_from_degree_six(interface, coarse);
    assert!(values <= 1e-13, "values {values:e}");
    assert!(derivatives <= 1e-13, "derivatives {derivatives:e}");
}

/// Tri3 on tri3 integrates with three points per triangle: the same
/// segment integrals and derivatives as the degree-6 rule, on a tilted and
/// warped pair (every integrand is a polynomial of degree 2 there).
#[test]
fn tri3_segments_with_three_points_match_the_degree_six_rule() {
    let mut case = random_case(31, Tri3, Tri3);
    let mut rng = Lcg::new(32);
    for p in &mut case.positions {
        p[2] += 0.05 * rng.next() + 0.1 * p[0] - 0.07 * p[1];
    }
    assert_eq!(MortarRules::default().affine_triangle.len(), 3);
    assert_same_as_degree_six(&case.interface(&case.positions), &MortarRules::default());
}

/// Quad4 on quad4 parallelograms integrate with seven points per triangle:
/// the same segment integrals and derivatives as the degree-6 rule, on a
/// sheared, tilted pair whose master plane is not the slave's, moved from
/// its reference by a further affine map (all facets stay parallelograms).
/// The degree-4 six-point rule fails it (a derivative 1.2e-4 off).
#[test]
fn parallelogram_segments_with_seven_points_match_the_degree_six_rule() {
    let mut case = parallelogram_case(33);
    let n_slave = case.nodal.nodes.len();
    let affine = |m: [[f64; 3]; 3], b: [f64; 3], p: [f64; 3]| {
        [0, 1, 2].map(|i| b[i] + m[i][0] * p[0] + m[i][1] * p[1] + m[i][2] * p[2])
    };
    let shear = [[1.0, 0.3, 0.0], [0.1, 0.9, 0.0], [0.2, -0.15, 1.0]];
    let tilt = [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.06, 0.04, 1.0]];
    for (i, p) in case.positions.iter_mut().enumerate() {
        *p = affine(shear, [0.1, -0.2, 0.3], *p);
        if i >= n_slave {
            *p = affine(tilt, [0.0, 0.0, -0.01], *p);
        }
    }
    let motion = [[1.02, 0.05, 0.01], [-0.03, 0.98, 0.02], [0.01, -0.02, 1.01]];
    let current: Vec<[f64; 3]> = case
        .positions
        .iter()
        .map(|p| affine(motion, [0.02, 0.01, -0.005], *p))
        .collect();
    let interface = case.interface(&current);
    let rules = MortarRules::default();
    assert_eq!(rules.parallelogram_triangle.len(), 7);
    assert_same_as_degree_six(&interface, &rules);
}

/// Segments whose quads are nearly parallelograms (distortion at most
/// [`NEAR_AFFINE`]) take the 7-point rule on a vertex fan: their integrals
/// differ from the 12-point rule's on the centroid's fan, but by less than
/// 2e-10 of the largest (1.1e-10 here, at a distortion of 8.8e-4), and
/// their derivatives by less than 1e-6 of theirs (3.0e-7). Further off a
/// parallelogram (every facet at 2.8e-3 or more) the degree-6 rule stays:
/// no difference at all.
#[test]
fn nearly_parallelogram_segments_take_seven_points_within_their_error() {
    for (jitter, near) in [(5e-4, true), (1e-2, false)] {
        let case = case_with(40, Quad4, Quad4, [jitter, jitter]);
        let (largest, smallest) = (largest_distortion(&case), smallest_distortion(&case));
        if near {
            assert!(largest <= NEAR_AFFINE, "distortion {largest:e}");
        } else {
            assert!(smallest > NEAR_AFFINE, "distortion {smallest:e}");
        }
        let interface = case.interface(&case.positions);
        let (values, derivatives) =
            differences_from_degree_six(&interface, &MortarRules::default());
        if near {
            assert!(values > 1e-13 && values < 2e-10, "values {values:e}");
            assert!(derivatives < 1e-6, "derivatives {derivatives:e}");
        } else {
            assert!(
                values == 0.0 && derivatives == 0.0,
                "{values:e} {derivatives:e}"
            );
        }
    }
}

/// The largest differences of the segment integrals of `coarse` and of
/// their derivatives from those of the degree-6 rule on the centroid's fan
/// everywhere, each relative to the largest value of its kind.
fn differences_from_degree_six(interface: &Interface, coarse: &MortarRules) -> (f64, f64) {
    let fine = MortarRules {
        affine_triangle: coarse.triangle.clone(),
        parallelogram_triangle: coarse.triangle.clone(),
        ..coarse.clone()
    };
    let flat = |segs: Vec<Segment<Dual<24>>>| -> (Vec<f64>, Vec<f64>) {
        let (mut values, mut derivatives) = (Vec::new(), Vec::new());
        for seg in segs {
            let t = seg.terms;
            let rows = t.d.iter().chain(&t.m).flatten();
            for v in t.weighted_gap.iter().chain(rows).chain([&t.area]) {
                values.push(v.re);
                derivatives.extend_from_slice(&v.eps);
            }
        }
        (values, derivatives)
    };
    let (v, d) = flat(segments(interface, coarse));
    let (v12, d12) = flat(segments(interface, &fine));
    assert_eq!(v.len(), v12.len());
    assert!(v.len() > 100, "{} values", v.len());
    let relative = |a: &[f64], b: &[f64]| {
        let scale = b.iter().fold(0.0f64, |m, x| m.max(x.abs()));
        a.iter()
            .zip(b)
            .fold(0.0f64, |m, (x, y)| m.max((x - y).abs()))
            / scale
    };
    (relative(&v, &v12), relative(&d, &d12))
}

fn largest_distortion(case: &Case) -> f64 {
    distortions(case).fold(0.0, f64::max)
}

fn smallest_distortion(case: &Case) -> f64 {
    distortions(case).fold(f64::INFINITY, f64::min)
}

fn distortions(case: &Case) -> impl Iterator<Item = f64> + '_ {
    let facets = case.slave_facets.iter().map(|f| (case.slave_type, f));
    let facets = facets.chain(case.master_facets.iter().map(|f| (case.master_type, f)));
    facets.map(|(t, f)| {
        let x: Vec<[f64; 3]> = f[..t.nodes()]
            .iter()
            .map(|&n| case.positions[n as usize])
            .collect();
        reference_distortion(t, &x)
    })
}

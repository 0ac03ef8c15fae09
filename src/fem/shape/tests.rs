//! Every cell and facet type: partition of unity, the Kronecker property at
//! the nodes, gradients against finite differences, linear (and for the
//! quadratic types, quadratic) fields reproduced.

use super::super::test_util::Lcg;
use super::*;

const H: f64 = 1e-6;

/// Random points inside the reference cell (strictly: the pyramid's
/// gradients jump at the apex, the others do not care).
fn cell_points(cell: CellType, rng: &mut Lcg) -> Vec<[f64; 3]> {
    (0..20)
        .map(|_| {
            let p = rng.vec3(1.0);
            let u = p.map(|v| 0.5 * (v + 1.0));
            match cell.linear() {
                CellType::Hex8 => p,
                CellType::Tet4 => u.map(|v| v / 3.0),
                CellType::Wedge6 => [0.5 * u[0], 0.5 * u[1], p[2]],
                _ => {
                    let z = 0.9 * u[2];
                    [p[0] * (1.0 - z), p[1] * (1.0 - z), z]
                }
            }
        })
        .collect()
}

fn facet_points(facet: FacetType, rng: &mut Lcg) -> Vec<[f64; 2]> {
    (0..20)
        .map(|_| {
            let p = [rng.next(), rng.next()];
            match facet.linear() {
                FacetType::Tri3 => p.map(|v| (v + 1.0) / 4.0),
                _ => p,
            }
        })
        .collect()
}

#[test]
fn reference_tables_agree() {
    assert_eq!(HEX27_REF_NODES[..8], HEX8_REF_NODES);
    assert_eq!(
        cell_reference_nodes(CellType::Hex27),
        HEX27_REF_NODES.to_vec()
    );
    for cell in CellType::ALL {
        assert_eq!(cell_reference_nodes(cell).len(), cell.nodes(), "{cell:?}");
        assert_eq!(cell.corners() + cell.higher_nodes().len(), cell.nodes());
    }
    for facet in FacetType::ALL {
        assert_eq!(facet_reference_nodes(facet).len(), facet.nodes());
    }
}

#[test]
fn cell_partition_of_unity_and_gradient_sum() {
    let mut rng = Lcg::new(1);
    for cell in CellType::ALL {
        for xi in cell_points(cell, &mut rng) {
            let s = cell_shape(cell, xi);
            assert_eq!(s.nodes, cell.nodes());
            let sum: f64 = s.n[..s.nodes].iter().sum();
            assert!((sum - 1.0).abs() < 1e-14, "{} sum {sum}", cell.name());
            for j in 0..3 {
                let g: f64 = s.dn[..s.nodes].iter().map(|d| d[j]).sum();
                assert!(g.abs() < 1e-13, "{} grad sum {g}", cell.name());
            }
        }
    }
}

#[test]
fn facet_partition_of_unity_and_gradient_sum() {
    let mut rng = Lcg::new(2);
    for facet in FacetType::ALL {
        for xi in facet_points(facet, &mut rng) {
            let s = facet_shape(facet, xi);
            assert_eq!(s.nodes, facet.nodes());
            let sum: f64 = s.n[..s.nodes].iter().sum();
            assert!((sum - 1.0).abs() < 1e-14, "{}", facet.name());
            for j in 0..2 {
                let g: f64 = s.dn[..s.nodes].iter().map(|d| d[j]).sum();
                assert!(g.abs() < 1e-13, "{}", facet.name());
            }
        }
    }
}

#[test]
fn kronecker_property_at_nodes() {
    for cell in CellType::ALL {
        for (b, xb) in cell_reference_nodes(cell).iter().enumerate() {
            let s = cell_shape(cell, *xb);
            for a in 0..cell.nodes() {
                let expect = if a == b { 1.0 } else { 0.0 };
                assert!(
                    (s.n[a] - expect).abs() < 1e-12,
                    "{} N_{a} at node {b}: {}",
                    cell.name(),
                    s.n[a]
                );
            }
        }
    }
    for facet in FacetType::ALL {
        for (b, xb) in facet_reference_nodes(facet).iter().enumerate() {
            let s = facet_shape(facet, *xb);
            for a in 0..facet.nodes() {
                let expect = if a == b { 1.0 } else { 0.0 };
                assert!((s.n[a] - expect).abs() < 1e-15, "{}", facet.name());
            }
        }
    }
}

#[test]
fn cell_gradients_match_finite_differences() {
    let mut rng = Lcg::new(3);
    for cell in CellType::ALL {
        for xi in cell_points(cell, &mut rng) {
            let s = cell_shape(cell, xi);
            for j in 0..3 {
                let mut xp = xi;
                let mut xm = xi;
                xp[j] += H;
                xm[j] -= H;
                let (sp, sm) = (cell_shape(cell, xp), cell_shape(cell, xm));
                for a in 0..cell.nodes() {
                    let fd = (sp.n[a] - sm.n[a]) / (2.0 * H);
                    assert!(
                        (fd - s.dn[a][j]).abs() < 1e-8,
                        "{} a={a} j={j}: {fd} vs {}",
                        cell.name(),
                        s.dn[a][j]
                    );
                }
            }
        }
    }
}

#[test]
fn facet_gradients_match_finite_differences() {
    let mut rng = Lcg::new(4);
    for facet in FacetType::ALL {
        for xi in facet_points(facet, &mut rng) {
            let s = facet_shape(facet, xi);
            for j in 0..2 {
                let mut xp = xi;
                let mut xm = xi;
                xp[j] += H;
                xm[j] -= H;
                let (sp, sm) = (facet_shape(facet, xp), facet_shape(facet, xm));
                for a in 0..facet.nodes() {
                    let fd = (sp.n[a] - sm.n[a]) / (2.0 * H);
                    assert!((fd - s.dn[a][j]).abs() < 1e-8, "{} a={a}", facet.name());
                }
            }
        }
    }
}

/// The second derivatives against central differences of the gradients
/// (error ~h², so 1e-8 with h = 1e-6 leaves the round-off ~1e-10 room).
#[test]
fn facet_second_derivatives_match_finite_differences() {
    let mut rng = Lcg::new(5);
    for facet in FacetType::ALL {
        for xi in facet_points(facet, &mut rng) {
            let dd = FacetShape::<9>::second(facet, xi).unwrap();
            for j in 0..2 {
                let (mut xp, mut xm) = (xi, xi);
                xp[j] += H;
                xm[j] -= H;
                let (sp, sm) = (facet_shape(facet, xp), facet_shape(facet, xm));
                for (a, dda) in dd.iter().enumerate().take(facet.nodes()) {
                    for i in 0..2 {
                        let fd = (sp.dn[a][i] - sm.dn[a][i]) / (2.0 * H);
                        // (i, j) in [11, 12, 22].
                        let exact = dda[i + j];
                        assert!(
                            (fd - exact).abs() < 1e-8,
                            "{} a={a} ({i},{j}): {fd} vs {exact}",
                            facet.name()
                        );
                    }
                }
            }
        }
    }
    assert!(FacetShape::<4>::second(FacetType::Quad8, [0.0; 2]).is_none());
}

/// The third derivatives `[112, 122]` against central differences of the
/// second ones (the second derivatives are at most quadratic, so the
/// differences are exact up to round-off).
#[test]
fn facet_third_derivatives_match_finite_differences() {
    let mut rng = Lcg::new(6);
    for facet in FacetType::ALL {
        for xi in facet_points(facet, &mut rng) {
            let ddd = FacetShape::<9>::third(facet, xi).unwrap();
            let second = |d: [f64; 2]| FacetShape::<9>::second(facet, d).unwrap();
            for j in 0..2 {
                let (mut xp, mut xm) = (xi, xi);
                xp[j] += H;
                xm[j] -= H;
                let (sp, sm) = (second(xp), second(xm));
                for a in 0..facet.nodes() {
                    let fd = [0, 1, 2].map(|i| (sp[a][i] - sm[a][i]) / (2.0 * H));
                    // ∂/∂ξ₁ of [11, 12, 22] is [111, 112, 122], ∂/∂ξ₂ is
                    // [112, 122, 222]; 111 and 222 vanish.
                    let exact = if j == 0 {
                        [0.0, ddd[a][0], ddd[a][1]]
                    } else {
                        [ddd[a][0], ddd[a][1], 0.0]
                    };
                    for i in 0..3 {
                        assert!(
                            (fd[i] - exact[i]).abs() < 1e-8,
                            "{} a={a} j={j} i={i}: {} vs {}",
                            facet.name(),
                            fd[i],
                            exact[i]
                        );
                    }
                }
            }
        }
    }
}

/// Σ N_a f(X_a) = f(X) for the fields the element must reproduce: linear
/// ones for every type, complete quadratics for tet10 / hex20 / hex27 / the
/// quadratic facets, and the wedge15's quadratics (its triangle is complete
/// quadratic, its ζ direction too).
#[test]
fn polynomial_fields_are_reproduced() {
    let linear = |x: [f64; 3]| 0.3 + 1.7 * x[0] - 0.4 * x[1] + 2.1 * x[2];
    let quadratic =
        |x: [f64; 3]| linear(x) + x[0] * x[0] - 0.6 * x[1] * x[2] + 0.8 * x[2] * x[2] + x[0] * x[1];
    let mut rng = Lcg::new(5);
    for cell in CellType::ALL {
        let nodes = cell_reference_nodes(cell);
        let quad = cell.order() == 2;
        for xi in cell_points(cell, &mut rng) {
            let s = cell_shape(cell, xi);
            for (f, needed) in [
                (&linear as &dyn Fn([f64; 3]) -> f64, true),
                (&quadratic, quad),
            ] {
                if !needed {
                    continue;
                }
                let v: f64 = nodes.iter().zip(&s.n).map(|(x, n)| n * f(*x)).sum();
                assert!((v - f(xi)).abs() < 1e-13, "{} at {xi:?}", cell.name());
            }
        }
    }
    for facet in FacetType::ALL {
        let nodes = facet_reference_nodes(facet);
        for xi in facet_points(facet, &mut rng) {
            let s = facet_shape(facet, xi);
            let lift = |p: [f64; 2]| [p[0], p[1], 0.0];
            let f: &dyn Fn([f64; 3]) -> f64 = if facet.is_linear() {
                &linear
            } else {
                &quadratic
            };
            let v: f64 = nodes.iter().zip(&s.n).map(|(x, n)| n * f(lift(*x))).sum();
            assert!((v - f(lift(xi))).abs() < 1e-13, "{}", facet.name());
        }
    }
}

#[test]
fn linear_facet_shape_is_the_corner_shape() {
    let xi = [0.21, 0.33];
    for facet in FacetType::ALL {
        let s = linear_facet_shape(facet, xi);
        let corner = facet_shape(facet.linear(), xi);
        assert_eq!(s.nodes, facet.corners());
        assert_eq!(s.n[..s.nodes], corner.n[..s.nodes]);
        assert_eq!(s.dn[..s.nodes], corner.dn[..s.nodes]);
    }
    assert!(FacetShape::<4>::of(FacetType::Quad8, xi).is_none());
    assert!(FacetShape::<8>::of(FacetType::Quad8, xi).is_some());
}

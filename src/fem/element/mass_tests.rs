//! Mass matrix tests: total mass, symmetry and definiteness, exact cases.

use super::super::test_util::{hex8_unit, rel_err, tet4_unit};
use super::tests::{distorted, geometry, materials, twisted_hex};
use super::*;
use nalgebra::{DMatrix, DVector};

fn mass(geom: &ElementGeometry, density: f64) -> Vec<f64> {
    let ndof = 3 * geom.nodes();
    let mut m = vec![0.0; ndof * ndof];
    mass_matrix(geom, density, &mut m).unwrap();
    m
}

/// Every case the mass tests run on: name, geometry and exact volume.
fn mass_cases() -> Vec<(&'static str, ElementGeometry, f64)> {
    let tet = distorted(CellType::Tet4, 21);
    let e = |i: usize| Vector3::from(tet[i]) - Vector3::from(tet[0]);
    let tet_volume = e(1).cross(&e(2)).dot(&e(3)) / 6.0;
    let twisted = twisted_hex();
    let twisted_volume = element_volume(&geometry(CellType::Hex8, &twisted));
    let hex3 = QuadRule::hex_3x3x3();
    let mut cases = vec![
        ("unit hex8", geometry(CellType::Hex8, &hex8_unit()), 1.0),
        (
            "twisted hex8",
            geometry(CellType::Hex8, &twisted),
            twisted_volume,
        ),
        (
            "twisted hex8 3x3x3",
            ElementGeometry::new(CellType::Hex8, &twisted, &hex3).unwrap(),
            twisted_volume,
        ),
        (
            "unit tet4",
            geometry(CellType::Tet4, &tet4_unit()),
            1.0 / 6.0,
        ),
        (
            "distorted tet4 1-pt",
            geometry(CellType::Tet4, &tet),
            tet_volume,
        ),
        (
            "distorted tet4 4-pt",
            ElementGeometry::new(CellType::Tet4, &tet, &QuadRule::tet_4()).unwrap(),
            tet_volume,
        ),
    ];
    // The other types, distorted (curved where second order), each with
    // the rule the assembly builds its mass with.
    for cell in CellType::ALL {
        if matches!(cell, CellType::Hex8 | CellType::Tet4) {
            continue;
        }
        let x = distorted(cell, 22);
        let rule =
            QuadRule::mass_for_cell(cell).unwrap_or_else(|| QuadRule::default_for_cell(cell));
        let geom = ElementGeometry::new(cell, &x, &rule).unwrap();
        let volume = element_volume(&geom);
        cases.push((cell.name(), geom, volume));
    }
    cases
}

#[test]
fn mass_total_is_density_times_volume() {
    let rho = 7.8;
    for (name, geom, volume) in mass_cases() {
        let m = mass(&geom, rho);
        let ndof = 3 * geom.nodes();
        for i in 0..3 {
            for j in 0..3 {
                let total: f64 = (0..geom.nodes())
                    .flat_map(|a| (0..geom.nodes()).map(move |b| (a, b)))
                    .map(|(a, b)| m[(3 * a + i) * ndof + 3 * b + j])
                    .sum();
                let expected = if i == j { rho * volume } else { 0.0 };
                assert!(
                    (total - expected).abs() < 1e-13 * rho * volume,
                    "{name} ({i},{j}): {total} vs {expected}"
                );
            }
        }
    }
}

#[test]
fn mass_is_symmetric_positive_definite() {
    for (name, geom, _) in mass_cases() {
        let m = mass(&geom, 2.5);
        let ndof = 3 * geom.nodes();
        let dm = DMatrix::from_row_slice(ndof, ndof, &m);
        assert_eq!(dm, dm.transpose(), "{name} not symmetric");
        let eig = dm.symmetric_eigenvalues();
        let (lo, hi) = (eig.min(), eig.max());
        println!("{name}: mass eigenvalues in [{lo:.3e}, {hi:.3e}]");
        assert!(lo > 1e-3 * hi, "{name}: smallest eigenvalue {lo:e}");
    }
}

/// Unit cube: M is the tensor product of the 1D linear mass
/// `h/6 [[2, 1], [1, 2]]`, so `M_ab = ρ/216 · Π_d (2 if a, b share
/// coordinate d else 1)`: ρ/27 on the diagonal, 4ρ/216 along an edge,
/// 2ρ/216 across a face, ρ/216 across the body.
#[test]
fn mass_of_unit_cube_hex8_is_exact() {
    let rho = 3.0;
    let x = hex8_unit();
    let m = mass(&geometry(CellType::Hex8, &x), rho);
    for a in 0..8 {
        assert!((m[(3 * a) * 24 + 3 * a] - rho / 27.0).abs() < 1e-15);
        for b in 0..8 {
            let factor: f64 = (0..3)
                .map(|d| if x[a][d] == x[b][d] { 2.0 } else { 1.0 })
                .product();
            for i in 0..3 {
                for j in 0..3 {
                    let exact = if i == j { rho * factor / 216.0 } else { 0.0 };
                    let got = m[(3 * a + i) * 24 + 3 * b + j];
                    assert!((got - exact).abs() < 1e-15, "a={a} b={b}: {got} vs {exact}");
                }
            }
        }
    }
}

/// On a parallelepiped det J is constant and 2×2×2 Gauss is exact, so
/// the mass is the unit cube's scaled by the volume.
#[test]
fn mass_of_affine_hex8_scales_with_volume() {
    let a = Matrix3::new(1.1, 0.2, -0.1, 0.05, 0.9, 0.3, -0.2, 0.1, 1.2);
    let shift = Vector3::new(0.3, -2.0, 5.0);
    let mapped: Vec<[f64; 3]> = hex8_unit()
        .iter()
        .map(|p| {
            let q = a * Vector3::from(*p) + shift;
            [q.x, q.y, q.z]
        })
        .collect();
    let m = mass(&geometry(CellType::Hex8, &mapped), 1.0);
    let unit: Vec<f64> = mass(&geometry(CellType::Hex8, &hex8_unit()), 1.0)
        .iter()
        .map(|v| v * a.determinant())
        .collect();
    assert!(rel_err(&m, &unit) < 1e-14);
}

#[test]
fn mass_of_tet4_matches_closed_form_for_any_rule() {
    let rho = 1.7;
    let tet = distorted(CellType::Tet4, 22);
    let e = |i: usize| Vector3::from(tet[i]) - Vector3::from(tet[0]);
    let volume = e(1).cross(&e(2)).dot(&e(3)) / 6.0;
    let exact: Vec<f64> = (0..144)
        .map(|k| {
            let (r, c) = (k / 12, k % 12);
            if r % 3 != c % 3 {
                0.0
            } else if r / 3 == c / 3 {
                rho * volume / 10.0
            } else {
                rho * volume / 20.0
            }
        })
        .collect();
    for rule in [QuadRule::tet_1(), QuadRule::tet_4()] {
        let geom = ElementGeometry::new(CellType::Tet4, &tet, &rule).unwrap();
        let err = rel_err(&mass(&geom, rho), &exact);
        assert!(err < 1e-14, "{} points: {err:e}", rule.len());
    }
}

#[test]
fn mass_bad_arguments_are_errors() {
    let geom = geometry(CellType::Hex8, &hex8_unit());
    let mut m = vec![1.0; 576];
    mass_matrix(&geom, 0.0, &mut m).unwrap();
    assert!(
        m.iter().all(|&v| v == 0.0),
        "zero density must give zero mass"
    );
    for bad in [-1.0, f64::NAN, f64::INFINITY] {
        assert!(matches!(
            mass_matrix(&geom, bad, &mut m),
            Err(FemError::InvalidDensity { .. })
        ));
    }
    assert!(matches!(
        mass_matrix(&geom, 1.0, &mut m[..575]),
        Err(FemError::LengthMismatch { what: "m", .. })
    ));
    let one_point = ElementGeometry::new(
        CellType::Hex8,
        &hex8_unit(),
        &QuadRule::hex_gauss(1).unwrap(),
    )
    .unwrap();
    assert!(matches!(
        mass_matrix(&one_point, 1.0, &mut m),
        Err(FemError::UnderintegratedMass {
            n_qp: 1,
            needed: 8,
            ..
        })
    ));
    let mut broken = geom.clone();
    broken.n.pop();
    assert!(mass_matrix(&broken, 1.0, &mut m).is_err());
}

/// Lateral stretch of the uniaxial Neo-Hookean test: P22 = 0 with
/// F = diag(λ1, λt, λt) gives μ(λt − 1/λt) + λ ln J / λt = 0, i.e.
/// g(λt) = μ(λt² − 1) + λ ln(λ1 λt²) = 0. g' = 2μλt + 2λ/λt > 0, so the
/// root is unique; bisection on (0, 1] (g(1) = λ ln λ1 > 0 for λ1 > 1).
fn closed_form_lateral_stretch(lambda: f64, mu: f64, l1: f64) -> f64 {
    let g = |lt: f64| mu * (lt * lt - 1.0) + lambda * (l1 * lt * lt).ln();
    let (mut lo, mut hi) = (1e-6, 1.0);
    for _ in 0..200 {
        let mid = 0.5 * (lo + hi);
        if g(mid) > 0.0 {
            hi = mid;
        } else {
            lo = mid;
        }
    }
    0.5 * (lo + hi)
}

/// Prescribed-displacement Newton on one unit hex8: symmetry planes
/// X=0, Y=0, Z=0, u_x given on X=1, Y=1 and Z=1 faces traction-free.
/// Returns the nodal displacements and internal forces.
fn solve_uniaxial(mat: &Material, stretch: f64) -> (Vec<[f64; 3]>, Vec<f64>) {
    let x = hex8_unit();
    let geom = geometry(CellType::Hex8, &x);
    let fixed = |dof: usize| {
        let (a, i) = (dof / 3, dof % 3);
        x[a][i] == 0.0 || (i == 0 && x[a][0] == 1.0)
    };
    let free: Vec<usize> = (0..24).filter(|&d| !fixed(d)).collect();
    let mut u = vec![[0.0; 3]; 8];
    let mut r = vec![0.0; 24];
    let mut k = vec![0.0; 576];
    let steps = 4;
    for step in 1..=steps {
        let ux = (stretch - 1.0) * step as f64 / steps as f64;
        for (a, xa) in x.iter().enumerate() {
            if xa[0] == 1.0 {
                u[a][0] = ux;
            }
        }
        for iter in 0..50 {
            internal_force_and_tangent(mat, &geom, &u, &mut r, &mut k).unwrap();
            let rf = DVector::from_iterator(free.len(), free.iter().map(|&d| r[d]));
            if rf.amax() < 1e-12 * mat.youngs() {
                break;
            }
            assert!(iter < 49, "Newton did not converge at step {step}");
            let kf = DMatrix::from_fn(free.len(), free.len(), |p, q| k[free[p] * 24 + free[q]]);
            let du = kf.lu().solve(&(-rf)).expect("singular free-dof stiffness");
            for (&d, dv) in free.iter().zip(du.iter()) {
                u[d / 3][d % 3] += dv;
            }
        }
    }
    internal_force(mat, &geom, &u, &mut r).unwrap();
    (u, r)
}

#[test]
fn neo_hookean_uniaxial_stretch_matches_closed_form() {
    let mat = materials()[1];
    let (lambda, mu) = mat.lame();
    let l1 = 2.0;
    let lt = closed_form_lateral_stretch(lambda, mu, l1);
    let j = l1 * lt * lt;
    let p11 = mu * (l1 - 1.0 / l1) + lambda * j.ln() / l1;
    // Check the closed form against the material law itself.
    let f = Matrix3::from_diagonal(&Vector3::new(l1, lt, lt));
    let p = mat.first_piola(&f).unwrap();
    assert!(p[(1, 1)].abs() < 1e-12 * p11 && p[(2, 2)].abs() < 1e-12 * p11);
    assert!((p[(0, 0)] - p11).abs() < 1e-12 * p11);
    assert!(lt < 1.0 && p11 > 0.0);

    let (u, r) = solve_uniaxial(&mat, l1);
    let x = hex8_unit();
    for (a, xa) in x.iter().enumerate() {
        for i in 1..3 {
            if xa[i] == 1.0 {
                let err = ((1.0 + u[a][i]) - lt).abs() / lt;
                assert!(err < 1e-8, "node {a} dir {i}: stretch err {err:e}");
            }
        }
    }
    // Nominal stress = total reaction on the unit reference face X = 1.
    let reaction: f64 = (0..8).filter(|&a| x[a][0] == 1.0).map(|a| r[3 * a]).sum();
    let err = (reaction - p11).abs() / p11;
    println!("uniaxial NH: lt = {lt:.12}, P11 = {p11:.9}, rel err {err:.2e}");
    assert!(err < 1e-8, "P11 {reaction} vs {p11}");
}

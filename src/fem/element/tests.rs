//! Element kernel tests: finite differences of the residual and tangent,
//! patch tests, body forces, mass matrix, bad input.

use super::super::surface::follower_pressure;
use super::super::test_util::{hex8_unit, perturb, rel_err, tet4_unit, Lcg};
use super::*;
use nalgebra::{DMatrix, DVector, Rotation3};

const H: f64 = 1e-6;

fn materials() -> [Material; 2] {
    [
        Material::LinearElastic {
            youngs: 1000.0,
            poisson: 0.3,
        },
        Material::NeoHookean {
            youngs: 1000.0,
            poisson: 0.3,
        },
    ]
}

fn distorted(cell: CellType, seed: u64) -> Vec<[f64; 3]> {
    let mut rng = Lcg::new(seed);
    let mut x = match cell {
        CellType::Hex8 => hex8_unit().to_vec(),
        CellType::Tet4 => tet4_unit().to_vec(),
    };
    perturb(&mut x, &mut rng, 0.15);
    x
}

fn random_u(nodes: usize, seed: u64, amp: f64) -> Vec<[f64; 3]> {
    let mut rng = Lcg::new(seed);
    (0..nodes).map(|_| rng.vec3(amp)).collect()
}

fn geometry(cell: CellType, x: &[[f64; 3]]) -> ElementGeometry {
    ElementGeometry::new(cell, x, &QuadRule::default_for_cell(cell)).unwrap()
}

fn force(mat: &Material, geom: &ElementGeometry, u: &[[f64; 3]]) -> Vec<f64> {
    let mut r = vec![0.0; 3 * u.len()];
    internal_force(mat, geom, u, &mut r).unwrap();
    r
}

fn shifted(u: &[[f64; 3]], dof: usize, h: f64) -> Vec<[f64; 3]> {
    let mut v = u.to_vec();
    v[dof / 3][dof % 3] += h;
    v
}

#[test]
fn internal_force_is_gradient_of_energy() {
    for cell in [CellType::Hex8, CellType::Tet4] {
        for mat in materials() {
            let x = distorted(cell, 5);
            let geom = geometry(cell, &x);
            let u = random_u(cell.nodes(), 6, 0.1);
            let r = force(&mat, &geom, &u);
            let fd: Vec<f64> = (0..3 * cell.nodes())
                .map(|dof| {
                    let ep = strain_energy(&mat, &geom, &shifted(&u, dof, H)).unwrap();
                    let em = strain_energy(&mat, &geom, &shifted(&u, dof, -H)).unwrap();
                    (ep - em) / (2.0 * H)
                })
                .collect();
            let err = rel_err(&r, &fd);
            println!("r vs FD energy {} {mat:?}: {err:.2e}", cell.name());
            assert!(err < 1e-6, "{} {mat:?}: {err:e}", cell.name());
        }
    }
}

#[test]
fn tangent_is_derivative_of_internal_force() {
    for cell in [CellType::Hex8, CellType::Tet4] {
        for mat in materials() {
            let x = distorted(cell, 7);
            let geom = geometry(cell, &x);
            let u = random_u(cell.nodes(), 8, 0.1);
            let ndof = 3 * cell.nodes();
            let mut r = vec![0.0; ndof];
            let mut k = vec![0.0; ndof * ndof];
            internal_force_and_tangent(&mat, &geom, &u, &mut r, &mut k).unwrap();
            assert_eq!(r, force(&mat, &geom, &u));
            let mut fd = vec![0.0; ndof * ndof];
            for col in 0..ndof {
                let rp = force(&mat, &geom, &shifted(&u, col, H));
                let rm = force(&mat, &geom, &shifted(&u, col, -H));
                for row in 0..ndof {
                    fd[row * ndof + col] = (rp[row] - rm[row]) / (2.0 * H);
                }
            }
            let err = rel_err(&k, &fd);
            println!("k vs FD r {} {mat:?}: {err:.2e}", cell.name());
            assert!(err < 1e-6, "{} {mat:?}: {err:e}", cell.name());
        }
    }
}

#[test]
fn tangent_on_higher_order_rule_matches_finite_differences() {
    let mat = materials()[1];
    let x = distorted(CellType::Hex8, 17);
    let geom = ElementGeometry::new(CellType::Hex8, &x, &QuadRule::hex_3x3x3()).unwrap();
    let u = random_u(8, 18, 0.1);
    let mut r = vec![0.0; 24];
    let mut k = vec![0.0; 576];
    internal_force_and_tangent(&mat, &geom, &u, &mut r, &mut k).unwrap();
    let col = 13;
    let rp = force(&mat, &geom, &shifted(&u, col, H));
    let rm = force(&mat, &geom, &shifted(&u, col, -H));
    let fd: Vec<f64> = (0..24).map(|row| (rp[row] - rm[row]) / (2.0 * H)).collect();
    let kc: Vec<f64> = (0..24).map(|row| k[row * 24 + col]).collect();
    assert!(rel_err(&kc, &fd) < 1e-6);
}

#[test]
fn linear_stiffness_is_tangent_at_rest_and_constant_for_linear() {
    for cell in [CellType::Hex8, CellType::Tet4] {
        let x = distorted(cell, 9);
        let geom = geometry(cell, &x);
        let ndof = 3 * cell.nodes();
        let zero = vec![[0.0; 3]; cell.nodes()];
        let u = random_u(cell.nodes(), 10, 0.1);
        let mut k0 = vec![0.0; ndof * ndof];
        let mut kt = vec![0.0; ndof * ndof];
        let mut r = vec![0.0; ndof];
        for mat in materials() {
            linear_stiffness(&mat, &geom, &mut k0).unwrap();
            internal_force_and_tangent(&mat, &geom, &zero, &mut r, &mut kt).unwrap();
            assert!(rel_err(&k0, &kt) < 1e-14);
        }
        let lin = materials()[0];
        internal_force_and_tangent(&lin, &geom, &u, &mut r, &mut kt).unwrap();
        assert!(rel_err(&k0, &kt) < 1e-14);
        // The linear internal force is exactly k·u.
        let ku: Vec<f64> = (0..ndof)
            .map(|row| {
                (0..ndof)
                    .map(|c| k0[row * ndof + c] * u[c / 3][c % 3])
                    .sum()
            })
            .collect();
        assert!(rel_err(&r, &ku) < 1e-12);
    }
}

fn max_abs(v: &[f64]) -> f64 {
    v.iter().fold(0.0f64, |m, x| m.max(x.abs()))
}

#[test]
fn rigid_translation_is_stress_free() {
    for cell in [CellType::Hex8, CellType::Tet4] {
        let geom = geometry(cell, &distorted(cell, 11));
        let u = vec![[0.4, -0.7, 1.3]; cell.nodes()];
        for mat in materials() {
            let r = force(&mat, &geom, &u);
            assert!(max_abs(&r) < 1e-10, "{} {mat:?}: {r:?}", cell.name());
        }
    }
}

#[test]
fn finite_rigid_rotation_is_stress_free_for_neo_hookean() {
    let rot = Rotation3::from_euler_angles(0.9, -0.4, 1.7);
    let [lin, nh] = materials();
    for cell in [CellType::Hex8, CellType::Tet4] {
        let x = distorted(cell, 12);
        let geom = geometry(cell, &x);
        let u: Vec<[f64; 3]> = x
            .iter()
            .map(|p| {
                let v = Vector3::from(*p);
                let d = rot * v - v + Vector3::new(0.3, 0.1, -0.2);
                [d.x, d.y, d.z]
            })
            .collect();
        let r = force(&nh, &geom, &u);
        assert!(max_abs(&r) < 1e-10, "{}: {r:?}", cell.name());
        // Small strain is not frame-indifferent: this is what NH fixes.
        assert!(max_abs(&force(&lin, &geom, &u)) > 1.0);
    }
}

/// ∫ N_a n dA over each face of a cell, accumulated per local node, via
/// the follower load at zero displacement (p = −1 turns −p∫N n da into
/// ∫N n dA).
fn boundary_vector_areas(cell: CellType, x: &[[f64; 3]]) -> Vec<[f64; 3]> {
    let mut g = vec![[0.0; 3]; cell.nodes()];
    for face in cell.local_faces() {
        let xf: Vec<[f64; 3]> = face.iter().map(|&a| x[a]).collect();
        let zero = vec![[0.0; 3]; face.len()];
        let mut f = vec![0.0; 3 * face.len()];
        follower_pressure(cell.facet_type(), &xf, &zero, -1.0, &mut f, None).unwrap();
        for (local, &a) in face.iter().enumerate() {
            for i in 0..3 {
                g[a][i] += f[3 * local + i];
            }
        }
    }
    g
}

fn twisted_hex() -> Vec<[f64; 3]> {
    let mut x = hex8_unit().to_vec();
    // Non-planar faces on every side, still well inside the valid range.
    x[6] = [1.2, 1.1, 1.3];
    x[4] = [-0.1, 0.15, 0.9];
    x[1] = [1.1, -0.1, 0.2];
    x
}

#[test]
fn linear_patch_constant_stress_and_boundary_traction() {
    let lin = materials()[0];
    let mut rng = Lcg::new(13);
    let g = Matrix3::from_fn(|_, _| 0.01 * rng.next());
    let c = Vector3::new(0.2, -0.1, 0.05);
    let exact_p = lin.first_piola(&(Matrix3::identity() + g)).unwrap();
    for (cell, x) in [
        (CellType::Hex8, twisted_hex()),
        (CellType::Tet4, distorted(CellType::Tet4, 14)),
    ] {
        let geom = geometry(cell, &x);
        let u: Vec<[f64; 3]> = x
            .iter()
            .map(|p| {
                let d = g * Vector3::from(*p) + c;
                [d.x, d.y, d.z]
            })
            .collect();
        for qp in 0..geom.n_qp() {
            let f = deformation_gradient(&geom, qp, &u).unwrap();
            let p = lin.first_piola(&f).unwrap();
            assert!((p - exact_p).abs().max() < 1e-12 * exact_p.abs().max());
        }
        // ∫ P ∇N_a dV = P ∫ N_a n dA when P is constant.
        let r = force(&lin, &geom, &u);
        let traction: Vec<f64> = boundary_vector_areas(cell, &x)
            .iter()
            .flat_map(|ga| {
                let t = exact_p * Vector3::from(*ga);
                [t.x, t.y, t.z]
            })
            .collect();
        let err = rel_err(&r, &traction);
        println!("patch r vs boundary traction {}: {err:.2e}", cell.name());
        assert!(err < 1e-12, "{}: {err:e}", cell.name());
    }
}

#[test]
fn volumes_are_exact() {
    // Oblique frustum with planar faces: V = h/3 (A1 + A2 + √(A1 A2))
    // = 7h/3 for squares of side 2 and 1, then an affine map scales it
    // by det A.
    let (h, s, t) = (1.5, 0.3, -0.2);
    let frustum = [
        [-1.0, -1.0, 0.0],
        [1.0, -1.0, 0.0],
        [1.0, 1.0, 0.0],
        [-1.0, 1.0, 0.0],
        [-0.5 + s, -0.5 + t, h],
        [0.5 + s, -0.5 + t, h],
        [0.5 + s, 0.5 + t, h],
        [-0.5 + s, 0.5 + t, h],
    ];
    let a = Matrix3::new(1.1, 0.2, -0.1, 0.05, 0.9, 0.3, -0.2, 0.1, 1.2);
    let mapped: Vec<[f64; 3]> = frustum
        .iter()
        .map(|p| {
            let q = a * Vector3::from(*p);
            [q.x, q.y, q.z]
        })
        .collect();
    let exact = a.determinant() * 7.0 * h / 3.0;
    for rule in [QuadRule::hex_2x2x2(), QuadRule::hex_3x3x3()] {
        let geom = ElementGeometry::new(CellType::Hex8, &mapped, &rule).unwrap();
        let v = element_volume(&geom);
        assert!((v - exact).abs() < 1e-13 * exact, "{v} vs {exact}");
    }
    // Twisted hex (non-planar faces): divergence theorem
    // V = ⅓ ∫ X·n dA = ⅓ Σ_a X_a · ∫ N_a n dA, independent of the
    // volume quadrature.
    let x = twisted_hex();
    let by_surface: f64 = boundary_vector_areas(CellType::Hex8, &x)
        .iter()
        .zip(&x)
        .map(|(g, p)| (g[0] * p[0] + g[1] * p[1] + g[2] * p[2]) / 3.0)
        .sum();
    let v = element_volume(&geometry(CellType::Hex8, &x));
    assert!((v - by_surface).abs() < 1e-13, "{v} vs {by_surface}");
    assert!((v - 1.0).abs() > 1e-3, "twist should change the volume");

    let tet = distorted(CellType::Tet4, 15);
    let e = |i: usize| Vector3::from(tet[i]) - Vector3::from(tet[0]);
    let exact = e(1).cross(&e(2)).dot(&e(3)) / 6.0;
    for rule in [QuadRule::tet_1(), QuadRule::tet_4()] {
        let v = element_volume(&ElementGeometry::new(CellType::Tet4, &tet, &rule).unwrap());
        assert!((v - exact).abs() < 1e-14, "{v} vs {exact}");
    }
}

#[test]
fn body_force_is_consistent() {
    let tet = distorted(CellType::Tet4, 16);
    let geom = ElementGeometry::new(CellType::Tet4, &tet, &QuadRule::tet_4()).unwrap();
    let vol = element_volume(&geom);
    let mut f = vec![0.0; 12];
    body_force(&geom, [1.0, -2.0, 3.0], &mut f).unwrap();
    // ∫ N_a dV = V/4 on a linear tet.
    for fa in f.chunks_exact(3) {
        for (fi, bi) in fa.iter().zip([1.0, -2.0, 3.0]) {
            assert!((fi - bi * vol / 4.0).abs() < 1e-14);
        }
    }
    // b = X: ∫ N_a X dV = Σ_b X_b V (1 + δ_ab) / 20 (degree 2, exact
    // with the 4-point rule).
    assert!(body_force(&geom, [f64::NAN; 3], &mut f).is_err());
    assert!(body_force_fn(&geom, &tet, |_| [0.0, f64::INFINITY, 0.0], &mut f).is_err());
    body_force_fn(&geom, &tet, |p| p, &mut f).unwrap();
    for (a, fa) in f.chunks_exact(3).enumerate() {
        for (i, fi) in fa.iter().enumerate() {
            let exact: f64 = (0..4)
                .map(|b| tet[b][i] * vol * if a == b { 2.0 } else { 1.0 } / 20.0)
                .sum();
            assert!((fi - exact).abs() < 1e-14, "a={a} i={i}: {fi} vs {exact}");
        }
    }
}

#[test]
fn interpolation_reproduces_linear_fields() {
    for cell in [CellType::Hex8, CellType::Tet4] {
        let x = distorted(cell, 19);
        let geom = geometry(cell, &x);
        let pts = qp_positions(&geom, &x).unwrap();
        assert_eq!(pts.len(), geom.n_qp());
        let field: Vec<[f64; 3]> = x
            .iter()
            .map(|p| [2.0 * p[0] - p[1], p[2] + 1.0, 3.0 * p[1]])
            .collect();
        for (qp, p) in pts.iter().enumerate() {
            let v = interpolate(&geom, qp, &field).unwrap();
            let exact = [2.0 * p[0] - p[1], p[2] + 1.0, 3.0 * p[1]];
            for i in 0..3 {
                assert!((v[i] - exact[i]).abs() < 1e-14);
            }
        }
        assert!(matches!(
            interpolate(&geom, geom.n_qp(), &field),
            Err(FemError::QpOutOfRange { .. })
        ));
    }
}

#[test]
fn inverted_elements_are_errors() {
    let mut hex = hex8_unit();
    hex.swap(0, 4);
    hex.swap(1, 5);
    hex.swap(2, 6);
    hex.swap(3, 7);
    let err = ElementGeometry::new(CellType::Hex8, &hex, &QuadRule::hex_2x2x2()).unwrap_err();
    assert!(
        matches!(err, FemError::InvertedElement { qp: 0, det_j } if det_j < 0.0),
        "{err:?}"
    );
    let mut tet = tet4_unit();
    tet.swap(1, 2);
    let err = ElementGeometry::new(CellType::Tet4, &tet, &QuadRule::tet_1()).unwrap_err();
    assert!(matches!(err, FemError::InvertedElement { qp: 0, det_j } if det_j < 0.0));
    // Collapsed tet: det J = 0 exactly.
    let flat = [[0.0; 3], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [1.0, 1.0, 0.0]];
    assert!(matches!(
        ElementGeometry::new(CellType::Tet4, &flat, &QuadRule::tet_4()),
        Err(FemError::InvertedElement { .. })
    ));
}

#[test]
fn hex_folded_at_a_corner_is_caught() {
    let mut hex = hex8_unit();
    hex[6] = [0.5, 0.5, 0.5];
    // Positive at every Gauss point, so only the corner check sees it.
    let rule = QuadRule::hex_2x2x2();
    for xi in &rule.points {
        let s = shape::hex8(*xi);
        assert!(reference_jacobian(&hex, &s.dn[..8]).determinant() > 0.0);
    }
    let err = ElementGeometry::new(CellType::Hex8, &hex, &rule).unwrap_err();
    assert!(
        matches!(err, FemError::InvertedCorner { corner: 6, det_j } if det_j < 0.0),
        "{err:?}"
    );
}

#[test]
fn inverted_current_configuration_is_an_error() {
    let nh = materials()[1];
    let geom = geometry(CellType::Tet4, &tet4_unit());
    // Push node 3 through the opposite face.
    let u = [[0.0; 3], [0.0; 3], [0.0; 3], [0.0, 0.0, -2.0]];
    let mut r = vec![0.0; 12];
    let mut k = vec![0.0; 144];
    let err = internal_force_and_tangent(&nh, &geom, &u, &mut r, &mut k).unwrap_err();
    assert!(
        matches!(err, FemError::Constitutive { qp: 0, .. }),
        "{err:?}"
    );
    assert!(internal_force(&nh, &geom, &u, &mut r).is_err());
    assert!(strain_energy(&nh, &geom, &u).is_err());
}

#[test]
fn bad_arguments_are_errors() {
    let mat = materials()[1];
    let geom = geometry(CellType::Hex8, &hex8_unit());
    let u = vec![[0.0; 3]; 8];
    let mut r = vec![0.0; 24];
    let mut short = vec![0.0; 23];
    let mut k = vec![0.0; 576];
    assert!(matches!(
        internal_force(&mat, &geom, &u, &mut short),
        Err(FemError::LengthMismatch { what: "r", .. })
    ));
    assert!(matches!(
        internal_force_and_tangent(&mat, &geom, &u, &mut r, &mut short),
        Err(FemError::LengthMismatch { what: "k", .. })
    ));
    assert!(internal_force(&mat, &geom, &u[..7], &mut r).is_err());
    let nan_u = vec![[f64::NAN, 0.0, 0.0]; 8];
    assert!(matches!(
        internal_force(&mat, &geom, &nan_u, &mut r),
        Err(FemError::NonFinite { what: "u" })
    ));
    let bad_mat = Material::NeoHookean {
        youngs: 1.0,
        poisson: 0.5,
    };
    assert!(matches!(
        internal_force_and_tangent(&bad_mat, &geom, &u, &mut r, &mut k),
        Err(FemError::Material(_))
    ));
    let mut broken = geom.clone();
    broken.grad_n.pop();
    assert!(internal_force(&mat, &broken, &u, &mut r).is_err());
    assert!(body_force(&broken, [0.0; 3], &mut r).is_err());
    assert!(
        ElementGeometry::new(CellType::Hex8, &hex8_unit()[..7], &QuadRule::hex_2x2x2()).is_err()
    );
    let empty = QuadRule {
        points: vec![],
        weights: vec![],
    };
    assert!(ElementGeometry::new(CellType::Hex8, &hex8_unit(), &empty).is_err());
}

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
    vec![
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
    ]
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

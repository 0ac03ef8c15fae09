//! Element kernel tests: finite differences of the residual and tangent,
//! patch tests, body forces, bad input (the mass matrix: mass_tests.rs).

use super::super::surface::follower_pressure;
use super::super::test_util::{
    distorted_cell, hex8_unit, perturb, rel_err, tet4_unit, unit_cell, Lcg,
};
use super::*;
use nalgebra::Rotation3;

const H: f64 = 1e-6;

pub(super) fn materials() -> [Material; 2] {
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

/// A distorted cell of any type: first-order cells with every node moved,
/// second-order ones with curved edges and faces too.
pub(super) fn distorted(cell: CellType, seed: u64) -> Vec<[f64; 3]> {
    match cell {
        CellType::Hex8 | CellType::Tet4 => {
            let mut rng = Lcg::new(seed);
            let mut x = unit_cell(cell);
            perturb(&mut x, &mut rng, 0.15);
            x
        }
        _ => distorted_cell(cell, seed, 0.1),
    }
}

/// A random affine image of the unit cell (straight edges, flat faces):
/// where the element must be exact.
pub(super) fn affine(cell: CellType, seed: u64) -> (Vec<[f64; 3]>, Matrix3<f64>) {
    let mut rng = Lcg::new(seed);
    let a = Matrix3::identity() + Matrix3::from_fn(|_, _| 0.2 * rng.next());
    let c = Vector3::from(rng.vec3(1.0));
    let x = unit_cell(cell)
        .iter()
        .map(|p| {
            let q = a * Vector3::from(*p) + c;
            [q.x, q.y, q.z]
        })
        .collect();
    (x, a)
}

/// Reference volume of each type's unit cell ([`unit_cell`]).
pub(super) fn unit_volume(cell: CellType) -> f64 {
    match cell.linear() {
        CellType::Hex8 => 1.0,
        CellType::Tet4 => 1.0 / 6.0,
        CellType::Wedge6 => 0.5,
        _ => 4.0 / 3.0,
    }
}

fn random_u(nodes: usize, seed: u64, amp: f64) -> Vec<[f64; 3]> {
    let mut rng = Lcg::new(seed);
    (0..nodes).map(|_| rng.vec3(amp)).collect()
}

pub(super) fn geometry(cell: CellType, x: &[[f64; 3]]) -> ElementGeometry {
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
    for cell in CellType::ALL {
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
    for cell in CellType::ALL {
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
    for cell in CellType::ALL {
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
    for cell in CellType::ALL {
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
    for cell in CellType::ALL {
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
    for (face_index, face) in cell.local_faces().iter().enumerate() {
        let xf: Vec<[f64; 3]> = face.iter().map(|&a| x[a]).collect();
        let zero = vec![[0.0; 3]; face.len()];
        let mut f = vec![0.0; 3 * face.len()];
        let facet = cell.face_type(face_index);
        follower_pressure(facet, &xf, &zero, -1.0, &mut f, None).unwrap();
        for (local, &a) in face.iter().enumerate() {
            for i in 0..3 {
                g[a][i] += f[3 * local + i];
            }
        }
    }
    g
}

pub(super) fn twisted_hex() -> Vec<[f64; 3]> {
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
    let mut cases = vec![
        (CellType::Hex8, twisted_hex()),
        (CellType::Tet4, distorted(CellType::Tet4, 14)),
    ];
    // Second-order cells, wedges and pyramids on affine images: there the
    // cofactor of J is constant and both integrals are exact.
    cases.extend(
        CellType::ALL
            .into_iter()
            .filter(|c| !matches!(c, CellType::Hex8 | CellType::Tet4))
            .map(|c| (c, affine(c, 14).0)),
    );
    for (cell, x) in cases {
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

/// Every type on a distorted (for the second-order types curved) cell: the
/// volume equals ⅓ ∫ X·n dA over its faces, which the facet rules integrate
/// exactly; with a volume rule exact for det J (the default, or the mass
/// rule where det J has a higher degree than the default integrates: tet10,
/// wedge15). The unit cells have their known volumes.
#[test]
fn volumes_of_distorted_cells_match_the_divergence_theorem() {
    for cell in CellType::ALL {
        let x = distorted(cell, 31);
        let rule = match cell {
            CellType::Tet10 | CellType::Wedge15 => QuadRule::mass_for_cell(cell).unwrap(),
            _ => QuadRule::default_for_cell(cell),
        };
        let v = element_volume(&ElementGeometry::new(cell, &x, &rule).unwrap());
        let by_surface: f64 = boundary_vector_areas(cell, &x)
            .iter()
            .zip(&x)
            .map(|(g, p)| (g[0] * p[0] + g[1] * p[1] + g[2] * p[2]) / 3.0)
            .sum();
        println!("{}: volume {v} vs {by_surface}", cell.name());
        assert!(
            (v - by_surface).abs() < 1e-13,
            "{}: {v} vs {by_surface}",
            cell.name()
        );
        assert!(
            (v - unit_volume(cell)).abs() > 1e-4,
            "{}: not distorted",
            cell.name()
        );
        let v0 = element_volume(&geometry(cell, &super::super::test_util::unit_cell(cell)));
        assert!((v0 - unit_volume(cell)).abs() < 1e-14, "{}", cell.name());
    }
}

/// ∫ N_a b dV sums to b V for every type, and the nodal share of an affine
/// cell is the same for every rule at least as exact as N_a's degree.
#[test]
fn body_force_totals_are_b_times_volume() {
    let b = [1.0, -2.0, 3.0];
    for cell in CellType::ALL {
        let x = distorted(cell, 32);
        let geom = geometry(cell, &x);
        let v = element_volume(&geom);
        let mut f = vec![0.0; 3 * cell.nodes()];
        body_force(&geom, b, &mut f).unwrap();
        for i in 0..3 {
            let tot: f64 = f.chunks_exact(3).map(|fa| fa[i]).sum();
            assert!((tot - b[i] * v).abs() < 1e-13, "{} {i}", cell.name());
        }
        let (xa, _) = affine(cell, 33);
        let mut f1 = vec![0.0; 3 * cell.nodes()];
        let mut f2 = vec![0.0; 3 * cell.nodes()];
        body_force(&geometry(cell, &xa), b, &mut f1).unwrap();
        let rich =
            QuadRule::mass_for_cell(cell).unwrap_or_else(|| QuadRule::default_for_cell(cell));
        body_force(&ElementGeometry::new(cell, &xa, &rich).unwrap(), b, &mut f2).unwrap();
        if cell != CellType::Tet4 {
            assert!(rel_err(&f1, &f2) < 1e-13, "{}", cell.name());
        }
    }
}

/// A mirror image of any cell is inverted at every quadrature point.
#[test]
fn mirrored_cells_of_every_type_are_inverted() {
    for cell in CellType::ALL {
        let x: Vec<[f64; 3]> = super::super::test_util::unit_cell(cell)
            .iter()
            .map(|p| [-p[0], p[1], p[2]])
            .collect();
        let err = ElementGeometry::new(cell, &x, &QuadRule::default_for_cell(cell)).unwrap_err();
        assert!(
            matches!(err, FemError::InvertedElement { qp: 0, det_j } if det_j < 0.0),
            "{}: {err:?}",
            cell.name()
        );
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
    for cell in CellType::ALL {
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

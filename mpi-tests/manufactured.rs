//! Linear elasticity with a manufactured smooth solution: the errors fall
//! at the elements' order on any rank count (hex8: L2 like h²; tet10,
//! hex20, hex27: L2 like h³, energy like h²; wedge6: h² and h).
use super::{boundary_nodes, ensure, linear, model_with, unit_box};
use contactlink::fem::{self, CellType, ElementGeometry, Integration, Material, QuadRule};
use contactlink::mesh::generate::{self, BoxSpec, Grading};
use contactlink::mesh::Mesh;
use contactlink::model::DirichletSpec;
use contactlink::pipeline;
use contactlink::runtime::Runtime;
/// The exact field of the manufactured problem (smooth, not polynomial).
fn mms_exact(x: [f64; 3]) -> [f64; 3] {
    use std::f64::consts::PI;
    let a = 1e-2;
    [
        a * (PI * x[0]).sin() * (0.5 * PI * x[1]).cos() * (1.0 + x[2]),
        a * (x[0] * x[1] + (PI * x[2]).sin()),
        a * (0.5 * PI * x[0]).cos() * (PI * x[1] * x[2]).sin(),
    ]
}

/// b = −div σ(u*) for linear elasticity, by nested central differences
/// (their error, ~1e-9 relative, is far below the discretisation error).
fn mms_body_force(material: &Material, x: [f64; 3]) -> [f64; 3] {
    let h = 1e-4;
    let stress = |p: [f64; 3]| -> [[f64; 3]; 3] {
        let mut g = [[0.0; 3]; 3];
        for j in 0..3 {
            let (mut xp, mut xm) = (p, p);
            xp[j] += 1e-5;
            xm[j] -= 1e-5;
            let (up, um) = (mms_exact(xp), mms_exact(xm));
            for i in 0..3 {
                g[i][j] = (up[i] - um[i]) / 2e-5;
            }
        }
        let (lambda, mu) = material.lame();
        let tr = g[0][0] + g[1][1] + g[2][2];
        let mut s = [[0.0; 3]; 3];
        for i in 0..3 {
            for j in 0..3 {
                s[i][j] = mu * (g[i][j] + g[j][i]) + if i == j { lambda * tr } else { 0.0 };
            }
        }
        s
    };
    let mut b = [0.0; 3];
    for j in 0..3 {
        let (mut xp, mut xm) = (x, x);
        xp[j] += h;
        xm[j] -= h;
        let (sp, sm) = (stress(xp), stress(xm));
        for i in 0..3 {
            b[i] -= (sp[i][j] - sm[i][j]) / (2.0 * h);
        }
    }
    b
}

/// Linear elasticity with a manufactured smooth solution on graded meshes of
/// 4³, 8³, 16³ cells: the L2 error must fall like h² (observed rate within
/// [1.8, 2.3] on the last refinement).
pub fn manufactured_solution_converges(rt: &Runtime) -> Result<(), String> {
    let material = linear();
    let mut errors = Vec::new();
    for n in [4, 8, 16] {
        let mesh = unit_box(
            n,
            Grading::Toward {
                point: 0.0,
                ratio: 2.0,
            },
        )?;
        let nodes = boundary_nodes(&mesh, "block");
        let values = nodes.iter().map(|&v| mms_exact(mesh.nodes[v])).collect();
        let bc = DirichletSpec {
            set: "boundary".into(),
            nodes,
            components: vec![0, 1, 2],
            values,
            amplitude: Default::default(),
        };
        let mut model = model_with(mesh, material, vec![bc], 1);
        let m = material;
        model.body_force_fn = Some(Box::new(move |x| mms_body_force(&m, x)));
        let summary = pipeline::run_model(rt, &model, None, false).map_err(|e| e.to_string())?;
        // The final displacement is on rank 0 only.
        if rt.rank() == 0 {
            let (l2, _) = relative_errors(&model.mesh, &material, &summary.report.displacement)?;
            errors.push(l2);
        }
    }
    if rt.rank() != 0 {
        return Ok(());
    }
    let rates: Vec<f64> = errors.windows(2).map(|w| (w[0] / w[1]).log2()).collect();
    if rt.rank() == 0 {
        let errs: Vec<String> = errors.iter().map(|e| format!("{e:.3e}")).collect();
        let rs: Vec<String> = rates.iter().map(|r| format!("{r:.3}")).collect();
        println!(
            "  manufactured solution: relative L2 errors [{}], rates [{}]",
            errs.join(", "),
            rs.join(", ")
        );
    }
    let last = rates[rates.len() - 1];
    ensure((1.8..=2.3).contains(&last), || {
        format!("L2 convergence rate {last:.3} is not 2 (errors {errors:?})")
    })
}

/// ∇u* by central differences (error ~1e-10, far below the
/// discretisation's): `g[i][j] = ∂u_i/∂X_j`.
fn mms_gradient(x: [f64; 3]) -> [[f64; 3]; 3] {
    let mut g = [[0.0; 3]; 3];
    for j in 0..3 {
        let (mut xp, mut xm) = (x, x);
        xp[j] += 1e-5;
        xm[j] -= 1e-5;
        let (up, um) = (mms_exact(xp), mms_exact(xm));
        for (i, gi) in g.iter_mut().enumerate() {
            gi[j] = (up[i] - um[i]) / 2e-5;
        }
    }
    g
}

/// A rule that integrates the error norms of every cell type far beyond
/// its elements' order.
fn error_rule(cell: CellType) -> Result<QuadRule, String> {
    let rule = match cell.linear() {
        CellType::Hex8 => QuadRule::hex_gauss(4),
        CellType::Tet4 => Ok(QuadRule::tet_14()),
        CellType::Wedge6 => QuadRule::wedge(&QuadRule::tri_6(), 4),
        _ => QuadRule::pyramid_collapsed(4, 4),
    };
    rule.map_err(|e| e.to_string())
}

/// Relative L2 error of the displacement and relative energy-norm error
/// `√∫ ε(e) : C : ε(e)` of the nodal field `u` (natural order) against
/// the manufactured solution.
fn relative_errors(mesh: &Mesh, material: &Material, u: &[f64]) -> Result<(f64, f64), String> {
    let rule = error_rule(mesh.cell_type)?;
    let (lambda, mu) = material.lame();
    let energy = |e: &[[f64; 3]; 3]| -> f64 {
        let sym = |i: usize, j: usize| 0.5 * (e[i][j] + e[j][i]);
        let tr = e[0][0] + e[1][1] + e[2][2];
        let mut w = lambda * tr * tr;
        for i in 0..3 {
            for j in 0..3 {
                w += 2.0 * mu * sym(i, j) * sym(i, j);
            }
        }
        w
    };
    let (mut l2, mut l2_norm, mut en, mut en_norm) = (0.0, 0.0, 0.0, 0.0);
    for c in 0..mesh.num_cells() {
        let cell = mesh.cell(c);
        let x: Vec<[f64; 3]> = cell.iter().map(|&v| mesh.nodes[v]).collect();
        let nodal: Vec<[f64; 3]> = cell
            .iter()
            .map(|&v| [u[3 * v], u[3 * v + 1], u[3 * v + 2]])
            .collect();
        let geom = ElementGeometry::new(mesh.cell_type, &x, &rule).map_err(|e| e.to_string())?;
        let points = fem::qp_positions(&geom, &x).map_err(|e| e.to_string())?;
        for (qp, p) in points.iter().enumerate() {
            let w = geom.jxw[qp];
            let uh = fem::interpolate(&geom, qp, &nodal).map_err(|e| e.to_string())?;
            let ue = mms_exact(*p);
            let f = fem::deformation_gradient(&geom, qp, &nodal).map_err(|e| e.to_string())?;
            let ge = mms_gradient(*p);
            let mut diff = [[0.0; 3]; 3];
            for i in 0..3 {
                l2 += w * (uh[i] - ue[i]).powi(2);
                l2_norm += w * ue[i].powi(2);
                for j in 0..3 {
                    let gh = f[(i, j)] - if i == j { 1.0 } else { 0.0 };
                    diff[i][j] = gh - ge[i][j];
                }
            }
            en += w * energy(&diff);
            en_norm += w * energy(&ge);
        }
    }
    Ok(((l2 / l2_norm).sqrt(), (en / en_norm).sqrt()))
}

/// The manufactured problem on the unit cube of `n`³ hexes made `cell`s,
/// solved by the program's own set-up and solver (direct): its errors.
fn solve_manufactured(
    rt: &Runtime,
    cell: CellType,
    integration: Integration,
    n: usize,
) -> Result<(f64, f64), String> {
    let material = linear();
    let mesh = generate::graded_box(&BoxSpec {
        body: "block".into(),
        divisions: [n; 3],
        cell_type: cell,
        ..Default::default()
    })
    .map_err(|e| e.to_string())?;
    let nodes = boundary_nodes(&mesh, "block");
    let values = nodes.iter().map(|&v| mms_exact(mesh.nodes[v])).collect();
    let bc = DirichletSpec {
        set: "boundary".into(),
        nodes,
        components: vec![0, 1, 2],
        values,
        amplitude: Default::default(),
    };
    let mut model = model_with(mesh, material, vec![bc], 1);
    model.integration = vec![integration];
    model.body_force_fn = Some(Box::new(move |x| mms_body_force(&material, x)));
    let summary = pipeline::run_model(rt, &model, None, false).map_err(|e| e.to_string())?;
    // The final displacement is on rank 0 only.
    if rt.rank() != 0 {
        return Ok((0.0, 0.0));
    }
    relative_errors(&model.mesh, &material, &summary.report.displacement)
}

/// The manufactured solution with tet10, hex20 (full and reduced
/// integration), hex27 (second order: displacement O(h³), energy O(h²)) and
/// wedge6 (first order: O(h²), O(h))
/// on 2³, 4³, 8³ hexes' worth of cells: both observed rates of both norms
/// within 0.15 of the order (docs/verification.md has the figures).
pub fn second_order_elements_converge_at_their_order(rt: &Runtime) -> Result<(), String> {
    let mut failures = Vec::new();
    for (cell, integration, order) in [
        (CellType::Tet10, Integration::Full, 2.0),
        (CellType::Hex20, Integration::Full, 2.0),
        (CellType::Hex20, Integration::Reduced, 2.0),
        (CellType::Hex27, Integration::Full, 2.0),
        (CellType::Wedge6, Integration::Full, 1.0),
    ] {
        let name = match integration {
            Integration::Full => cell.name().to_string(),
            Integration::Reduced => format!("{} reduced", cell.name()),
        };
        let mut errors = Vec::new();
        for n in [2, 4, 8] {
            errors.push(solve_manufactured(rt, cell, integration, n)?);
        }
        if rt.rank() != 0 {
            continue;
        }
        let rate = |a: f64, b: f64| (a / b).log2();
        let l2: Vec<f64> = errors.windows(2).map(|w| rate(w[0].0, w[1].0)).collect();
        let en: Vec<f64> = errors.windows(2).map(|w| rate(w[0].1, w[1].1)).collect();
        let fmt =
            |v: &[f64], f: &dyn Fn(&f64) -> String| v.iter().map(f).collect::<Vec<_>>().join(", ");
        println!(
            "  {name}: L2 errors [{}] rates [{}]; energy errors [{}] rates [{}]",
            fmt(
                &errors.iter().map(|e| e.0).collect::<Vec<_>>(),
                &|e| format!("{e:.3e}")
            ),
            fmt(&l2, &|r| format!("{r:.3}")),
            fmt(
                &errors.iter().map(|e| e.1).collect::<Vec<_>>(),
                &|e| format!("{e:.3e}")
            ),
            fmt(&en, &|r| format!("{r:.3}")),
        );
        let near = |r: &f64, p: f64| (r - p).abs() <= 0.15;
        if !l2.iter().all(|r| near(r, order + 1.0)) || !en.iter().all(|r| near(r, order)) {
            failures.push(format!(
                "{name}: L2 rates {l2:?} (want {}), energy rates {en:?} (want {order})",
                order + 1.0
            ));
        }
    }
    ensure(failures.is_empty(), || failures.join("; "))
}

//! The contact Schur path (`[solver] contact_schur`): the bulk stiffness
//! factored once with a MUMPS Schur complement on the contact DOFs.
//!
//! One process (MPI and PETSc start once per process), so one test: the
//! Schur solve of a small matrix against a dense solve, C forced to grow,
//! and whole runs of hertz-cylinder, frictionless (LDLᵀ), with Coulomb
//! friction over two steps and with a mortar pair (both non-symmetric:
//! the dense LU path), with and without the Schur path.
use contactlink::assembly::PatternBuilder;
use contactlink::linsolve::SchurPreconditioner;
use contactlink::petsc::{Matrix, PetscInt, Vector};
use contactlink::pipeline;
use contactlink::runtime::Runtime;

const N: usize = 24;

/// A deterministic SPD "bulk" matrix (dense, row-major) with the first
/// node's DOFs to be constrained.
fn bulk() -> Vec<f64> {
    let mut seed = 12345u64;
    let mut rnd = || {
        seed = seed
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        ((seed >> 33) as f64) / (1u64 << 31) as f64 - 0.5
    };
    let a: Vec<f64> = (0..N * N).map(|_| rnd()).collect();
    let mut k = vec![0.0; N * N];
    for i in 0..N {
        for j in 0..N {
            k[i * N + j] = (0..N).map(|m| a[i * N + m] * a[j * N + m]).sum::<f64>();
        }
        k[i * N + i] += N as f64;
    }
    k
}

/// `k` plus `scale` times a coupling on `c` (unsymmetric when `skew`).
fn with_contact(k: &[f64], c: &[usize], scale: f64, skew: bool) -> Vec<f64> {
    let mut j = k.to_vec();
    for (a, &p) in c.iter().enumerate() {
        for (b, &q) in c.iter().enumerate() {
            let sym = if a == b {
                3.0
            } else {
                1.0 / (1.0 + (a + b) as f64)
            };
            let un = if skew && a < b { 0.7 } else { 0.0 };
            j[p * N + q] += scale * (sym + un);
        }
    }
    j
}

fn dirichlet(m: &mut [f64], rows: &[usize]) {
    for &r in rows {
        for i in 0..N {
            m[r * N + i] = 0.0;
            m[i * N + r] = 0.0;
        }
        m[r * N + r] = 1.0;
    }
}

fn petsc_matrix(dense: &[f64], rows: &[PetscInt]) -> Matrix {
    let all: Vec<PetscInt> = (0..N as PetscInt).collect();
    let mut p = PatternBuilder::new(N, 3).unwrap();
    p.add_square(&all).unwrap();
    let mut m = p.build().unwrap();
    m.add_block(&all, &all, dense).unwrap();
    m.assemble().unwrap();
    // The constrained rows as the program makes them (the dense copy has
    // them already; this keeps the PETSc matrix's own handling in play).
    if !rows.is_empty() {
        m.zero_rows_columns_identity(rows).unwrap();
    }
    m
}

/// `a − b`, entry by entry.
fn minus(a: &[f64], b: &[f64]) -> Vec<f64> {
    a.iter().zip(b).map(|(x, y)| x - y).collect()
}

/// Gaussian elimination with partial pivoting.
fn dense_solve(a: &[f64], b: &[f64]) -> Vec<f64> {
    let mut a = a.to_vec();
    let mut x = b.to_vec();
    for c in 0..N {
        let p = (c..N)
            .max_by(|&i, &j| a[i * N + c].abs().total_cmp(&a[j * N + c].abs()))
            .unwrap();
        for k in 0..N {
            a.swap(c * N + k, p * N + k);
        }
        x.swap(c, p);
        for r in c + 1..N {
            let f = a[r * N + c] / a[c * N + c];
            for k in c..N {
                a[r * N + k] -= f * a[c * N + k];
            }
            x[r] -= f * x[c];
        }
    }
    for c in (0..N).rev() {
        let s: f64 = (c + 1..N).map(|k| a[c * N + k] * x[k]).sum();
        x[c] = (x[c] - s) / a[c * N + c];
    }
    x
}

fn rel_err(a: &[f64], b: &[f64]) -> f64 {
    let d: f64 = a
        .iter()
        .zip(b)
        .map(|(x, y)| (x - y).powi(2))
        .sum::<f64>()
        .sqrt();
    let n: f64 = b.iter().map(|y| y * y).sum::<f64>().sqrt();
    d / n
}

/// Solves J x = b through the preconditioner set up from the contact
/// tangent `kc` alone (as the program hands it over: without the Dirichlet
/// replacement), against the dense solve of `jd`, the whole Jacobian with it.
fn check(pc: &mut SchurPreconditioner, jd: &[f64], kc: &[f64], what: &str) {
    pc.set_up(&petsc_matrix(kc, &[])).unwrap();
    let b: Vec<f64> = (0..N).map(|i| 1.0 + (i as f64).sin()).collect();
    let mut bv = Vector::new_mpi(N).unwrap();
    bv.with_array_mut(|a| a.copy_from_slice(&b)).unwrap();
    let mut xv = bv.duplicate().unwrap();
    pc.apply(&bv, &mut xv).unwrap();
    let x: Vec<f64> = xv.with_array(|a| a.to_vec()).unwrap();
    let e = rel_err(&x, &dense_solve(jd, &b));
    assert!(
        e < 1e-12,
        "{what}: Schur solve off the dense one by {e:.3e}"
    );
}

fn small_matrices() {
    let rows: Vec<PetscInt> = vec![0, 1, 2];
    let fixed = [0usize, 1, 2];
    let mut k = bulk();
    dirichlet(&mut k, &fixed);
    for cholesky in [true, false] {
        let kind = if cholesky { "LDLᵀ" } else { "LU" };
        let skew = !cholesky;
        let mut pc = SchurPreconditioner::new(petsc_matrix(&k, &rows), rows.clone(), cholesky);
        let c1: Vec<usize> = (9..15).collect();
        pc.want(c1.iter().map(|&d| d as PetscInt).collect(), Vec::new());
        let j1 = with_contact(&k, &c1, 50.0, skew);
        check(&mut pc, &j1, &minus(&j1, &k), &format!("{kind}, C of 6"));
        // A new tangent on the same C: only the dense part is factored again.
        let j1b = with_contact(&k, &c1, 500.0, skew);
        let what = format!("{kind}, C of 6, stiffer");
        check(&mut pc, &j1b, &minus(&j1b, &k), &what);
        assert_eq!((pc.bulk_factorisations, pc.growths), (1, 0), "{kind}");
        // The contact now reaches outside C (and onto a constrained DOF):
        // C grows and K is factored again.
        let c2: Vec<usize> = (0..3).chain(9..15).chain(18..21).collect();
        // The contact tangent keeps its entries in the constrained rows and
        // columns; the Jacobian's Dirichlet replacement drops them.
        let kc2 = with_contact(&vec![0.0; N * N], &c2, 80.0, skew);
        let mut j2 = with_contact(&k, &c2, 80.0, skew);
        dirichlet(&mut j2, &fixed);
        pc.want(c2.iter().map(|&d| d as PetscInt).collect(), Vec::new());
        check(&mut pc, &j2, &kc2, &format!("{kind}, C grown to 12"));
        assert_eq!((pc.bulk_factorisations, pc.growths), (2, 1), "{kind}");
        assert_eq!(pc.schur_size(), 12, "{kind}");
        assert_eq!(pc.schur_factorisations, 3, "{kind}");
    }
}

/// The symmetric path's partial dense factorisations: C ordered by the
/// first tangent, a tangent reaching further into C (S0's leading block
/// factored again), one that makes S indefinite (LDLᵀ of the whole S) and
/// a definite one after it; each solve against the dense one.
fn partial_factorisations() {
    let rows: Vec<PetscInt> = vec![0, 1, 2];
    let mut k = bulk();
    dirichlet(&mut k, &[0, 1, 2]);
    let mut pc = SchurPreconditioner::new(petsc_matrix(&k, &rows), rows.clone(), true);
    pc.want((6..18).collect(), Vec::new());
    let steps: [(std::ops::Range<usize>, f64, &str); 5] = [
        (12..18, 50.0, "first tangent, on half of C"),
        (14..18, 70.0, "on a third of C"),
        (10..18, 60.0, "reaching further into C"),
        (12..18, -400.0, "indefinite"),
        (10..18, 40.0, "definite again"),
    ];
    for (c, scale, what) in steps {
        let c: Vec<usize> = c.collect();
        let j = with_contact(&k, &c, scale, false);
        check(&mut pc, &j, &minus(&j, &k), what);
    }
    let d = pc.dense_counts();
    // The first and the indefinite one whole (LDLᵀ); the others on a
    // trailing block: the second touched the last 4 of the 12 DOFs (split
    // at 7, room for a quarter more), the third reached 8 (split again, at
    // 2: trailing 10) and the fifth kept that split.
    assert_eq!((d.whole, d.trailing, d.leading), (2, 3, 2), "{d:?}");
    assert_eq!(d.largest_trailing, 10, "{d:?}");
    assert_eq!((pc.bulk_factorisations, pc.schur_factorisations), (1, 5));
}

/// Reserved DOFs join C when it is formed and keep a contact zone that
/// reaches them from growing it; a DOF outside both still grows C. Both
/// kinds of tangent (the non-symmetric one on its own LU path).
fn reserved_dofs() {
    let rows: Vec<PetscInt> = vec![0, 1, 2];
    let mut k = bulk();
    dirichlet(&mut k, &[0, 1, 2]);
    for symmetric in [true, false] {
        let mut pc = SchurPreconditioner::new(petsc_matrix(&k, &rows), rows.clone(), symmetric);
        pc.want((12..15).collect(), (9..18).collect());
        let c: Vec<usize> = (12..15).collect();
        let j = with_contact(&k, &c, 50.0, !symmetric);
        check(&mut pc, &j, &minus(&j, &k), "first touch, C reserved");
        assert_eq!(pc.schur_size(), 9, "symmetric {symmetric}");
        // The zone reaches the reserve: no growth.
        pc.want((9..18).collect(), Vec::new());
        let c: Vec<usize> = (9..18).collect();
        let j = with_contact(&k, &c, 60.0, !symmetric);
        check(&mut pc, &j, &minus(&j, &k), "zone over the reserve");
        assert_eq!((pc.bulk_factorisations, pc.growths), (1, 0));
        // Beyond it: C grows.
        pc.want((9..21).collect(), Vec::new());
        let c: Vec<usize> = (9..21).collect();
        let j = with_contact(&k, &c, 70.0, !symmetric);
        check(&mut pc, &j, &minus(&j, &k), "zone past the reserve");
        assert_eq!((pc.bulk_factorisations, pc.growths), (2, 1));
        assert_eq!(pc.schur_size(), 12);
    }
}

/// Displacement, reactions and contact forces of a scene with and without
/// the Schur path; and that the Schur path was taken.
fn same_run(rt: &Runtime, scene: &str, overrides: &[&str]) {
    let run = |schur: bool| {
        let mut o: Vec<String> = overrides.iter().map(|s| s.to_string()).collect();
        o.push(format!("solver.contact_schur={schur}"));
        let model = pipeline::load_model(scene, &o).unwrap().0;
        pipeline::run_model(rt, &model, None, false).unwrap().report
    };
    let (on, off) = (run(true), run(false));
    let s = on.schur.expect("the Schur path was taken");
    assert!(
        off.schur.is_none(),
        "{scene}: contact_schur = false ignored"
    );
    assert_eq!(s.bulk_factorisations, 1 + s.growths, "{scene}: {s:?}");
    // Newton on the condensed system (the default): per step one sparse
    // solve for its first Newton iteration and one forming the interior,
    // every other Newton iteration a dense solve on C.
    let steps = on.steps.len();
    let newton_on: usize = on.steps.iter().map(|s| s.newton_iterations).sum();
    assert_eq!(s.sparse_solves, 2 * steps, "{scene}: {s:?}");
    assert_eq!(s.dense_solves, newton_on - steps, "{scene}: {s:?}");
    let e = rel_err(&on.displacement, &off.displacement);
    assert!(e < 1e-9, "{scene}: displacement differs by {e:.3e}");
    let (a, b) = (on.steps.last().unwrap(), off.steps.last().unwrap());
    for ((name, ra), (_, rb)) in a.reactions.iter().zip(&b.reactions) {
        let scale = rb.iter().map(|v| v.abs()).fold(1e-30, f64::max);
        for (x, y) in ra.iter().zip(rb) {
            assert!(
                (x - y).abs() <= 1e-9 * scale,
                "{scene}: reaction on {name}: {ra:?} vs {rb:?}"
            );
        }
    }
    for (ca, cb) in a.contact.iter().zip(&b.contact) {
        let d = (ca.normal_force - cb.normal_force).abs();
        assert!(
            d <= 1e-9 * cb.normal_force.abs(),
            "{scene}: normal force {} vs {}",
            ca.normal_force,
            cb.normal_force
        );
        let d = (ca.tangential_force - cb.tangential_force).abs();
        assert!(
            d <= 1e-9 * cb.normal_force.abs(),
            "{scene}: tangential force {} vs {}",
            ca.tangential_force,
            cb.tangential_force
        );
        assert_eq!(ca.active_points, cb.active_points, "{scene}");
    }
    let newton = |r: &contactlink::solve::RunReport| -> usize {
        r.steps.iter().map(|s| s.newton_iterations).sum()
    };
    assert_eq!(
        newton(&on),
        newton(&off),
        "{scene}: Newton iterations moved"
    );
}

#[test]
fn schur_path() {
    let rt = Runtime::start(&[]).expect("MPI and PETSc start");
    small_matrices();
    partial_factorisations();
    reserved_dofs();
    same_run(&rt, "hertz-cylinder", &["mesh.fine_size=0.4"]);
    // A mortar pair on a deformable master: a non-symmetric tangent on K's
    // LDLᵀ factor (the LU path of the dense part).
    same_run(
        &rt,
        "hertz-cylinder",
        &["mesh.fine_size=0.4", "contact.formulation=\"mortar\""],
    );
    // A frictional mortar pair, whose second step's line search cuts the
    // Newton step: the same step lengths as on the full factorisation
    // (the line search's slope from the whole system, `linsolve::slope`).
    let frictional = [
        "mesh.fine_size=0.4",
        "contact.friction=0.2",
        "steps.count=2",
    ];
    let frictional_mortar = [&frictional[..], &["contact.formulation=\"mortar\""]].concat();
    same_run(&rt, "hertz-cylinder", &frictional_mortar);
    whole_newton_same_iterates(&rt);
    // Coulomb friction (LU), two load steps (a second search and pattern).
    same_run(&rt, "hertz-cylinder", &frictional);
}

/// The Schur path with Newton on the whole vector (`condensed_newton =
/// false`) takes the iterates of the condensed one: the same Newton
/// residuals to roundoff (the last ones are at its floor, about 1e-14 of
/// the first) and the same displacement.
fn whole_newton_same_iterates(rt: &Runtime) {
    let run = |condensed: bool| {
        let o = vec![
            "mesh.fine_size=0.4".to_string(),
            format!("solver.condensed_newton={condensed}"),
        ];
        let model = pipeline::load_model("hertz-cylinder", &o).unwrap().0;
        pipeline::run_model(rt, &model, None, false).unwrap().report
    };
    let (on, off) = (run(true), run(false));
    let (a, b) = (on.schur.unwrap(), off.schur.unwrap());
    assert_eq!(b.dense_solves, 0, "{b:?}");
    assert!(
        a.dense_solves > 0 && a.sparse_solves < b.sparse_solves,
        "{a:?} {b:?}"
    );
    let e = rel_err(&on.displacement, &off.displacement);
    assert!(e < 1e-9, "displacement differs by {e:.3e}");
    let (ha, hb) = (
        &on.steps[0].residual_history,
        &off.steps[0].residual_history,
    );
    assert_eq!(ha.len(), hb.len());
    for (x, y) in ha.iter().zip(hb) {
        assert!(
            (x - y).abs() <= 1e-6 * y.abs() + 1e-12 * hb[0],
            "{ha:?}\n{hb:?}"
        );
    }
}

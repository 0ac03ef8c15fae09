//! The PETSc defaults each kind of run gets (`-options_view` prints the
//! option table at the end of the run, defaults included).
mod common;
use common::*;
use std::sync::atomic::{AtomicUsize, Ordering};

/// The option table a run ended with. Each run writes its own result file:
/// the tests run in parallel, and two runs of one scene writing the scene's
/// output path at once made MPI-IO fail to open it.
fn option_table(args: &[&str]) -> String {
    static RUNS: AtomicUsize = AtomicUsize::new(0);
    let dir = scratch(&format!(
        "solver_defaults_{}",
        RUNS.fetch_add(1, Ordering::Relaxed)
    ));
    let out = dir.join("out.h5");
    let mut all = vec!["run"];
    all.extend_from_slice(args);
    all.extend(["-o", out.to_str().expect("scratch path is UTF-8")]);
    all.push("-options_view");
    let o = run(&all);
    let t = text(&o);
    assert!(o.status.success(), "{args:?} failed:\n{t}");
    t
}

#[test]
fn a_plain_linear_iterative_run_frees_the_galerkin_intermediates() {
    // Linear bodies, no contact: the Jacobian is set once, so GAMG's
    // products need not keep their intermediate data.
    let t = option_table(&[
        "scenes/cantilever.toml",
        "--set",
        "solver.direct_max_dofs=0",
    ]);
    assert!(t.contains("-pc_type gamg"), "{t}");
    assert!(t.contains("-mat_product_clear true"), "{t}");
    assert!(t.contains("-pc_gamg_agg_nsmooths 0"), "{t}");
}

#[test]
fn a_linear_iterative_contact_run_frees_the_galerkin_intermediates() {
    // Linear bodies with contact: the AMG hierarchy is built once a step
    // and kept while it works, so its products are not refreshed either.
    let cylinder = [
        "scenes/hertz-cylinder.toml",
        "--set",
        "solver.direct_max_dofs=0",
    ];
    let t = option_table(&cylinder);
    assert!(t.contains("-pc_type gamg"), "{t}");
    assert!(t.contains("-mat_product_clear true"), "{t}");
    // Unsmoothed aggregation on the contact path too.
    assert!(t.contains("-pc_gamg_agg_nsmooths 0"), "{t}");
    // Without the preconditioner reuse every Newton iteration rebuilds it.
    let mut rebuilt = cylinder.to_vec();
    rebuilt.extend(["--set", "solver.lag_preconditioner=false"]);
    let t = option_table(&rebuilt);
    assert!(!t.contains("-mat_product_clear"), "{t}");
}

#[test]
fn runs_whose_matrix_changes_keep_the_galerkin_intermediates() {
    // Contact, a hyperelastic body, the stiffness assembled every time:
    // GAMG reuses its interpolation and refreshes the products numerically.
    for args in [
        &[
            "scenes/block-on-plane.toml",
            "--set",
            "solver.direct_max_dofs=0",
        ][..],
        &[
            "scenes/uniaxial-stretch.toml",
            "--set",
            "solver.direct_max_dofs=0",
        ][..],
        &[
            "scenes/cantilever.toml",
            "--set",
            "solver.direct_max_dofs=0",
            "--set",
            "solver.reuse_linear_stiffness=false",
        ][..],
    ] {
        let t = option_table(args);
        assert!(t.contains("-pc_type gamg"), "{args:?}: {t}");
        assert!(!t.contains("-mat_product_clear"), "{args:?}: {t}");
    }
}

#[test]
fn an_iterative_contact_run_caps_the_eisenstat_walker_forcing() {
    // GMRES + GAMG with a links pair: Eisenstat–Walker, never looser than
    // 0.1 (a mortar pair solves GMRES to a fixed 1e-4 instead).
    let t = option_table(&[
        "scenes/block-on-plane.toml",
        "--set",
        "solver.direct_max_dofs=0",
        "--set",
        "contact.formulation=links",
    ]);
    assert!(t.contains("-snes_ksp_ew true"), "{t}");
    assert!(t.contains("-snes_ksp_ew_rtolmax 0.1"), "{t}");
    // The mortar, the default: GMRES to a fixed 1e-4, no Eisenstat–Walker.
    let t = option_table(&[
        "scenes/block-on-plane.toml",
        "--set",
        "solver.direct_max_dofs=0",
    ]);
    assert!(!t.contains("-snes_ksp_ew"), "{t}");
    assert!(t.contains("-ksp_rtol 1e-4"), "{t}");
    // The direct path solves each Newton step to 1e-10 around the factors.
    let t = option_table(&["scenes/block-on-plane.toml"]);
    assert!(!t.contains("-snes_ksp_ew"), "{t}");
}

/// The option table of a run on `ranks` ranks.
fn option_table_on(ranks: usize, args: &[&str]) -> String {
    let mut all = vec!["run"];
    all.extend_from_slice(args);
    all.push("-options_view");
    let o = mpirun(ranks, &all);
    let t = text(&o);
    assert!(o.status.success(), "{args:?} on {ranks} ranks failed:\n{t}");
    t
}

#[test]
fn a_plain_linear_iterative_run_on_several_ranks_forms_the_galerkin_product_with_hypre() {
    // Several ranks: hypre's P^T A P (PETSc's parallel one keeps A P and
    // P's ghost rows at the set-up peak); one rank keeps PETSc's own.
    let plain = [
        "scenes/cantilever.toml",
        "--set",
        "solver.direct_max_dofs=0",
    ];
    let t = option_table_on(2, &plain);
    assert!(t.contains("-matptap_via hypre"), "{t}");
    let t = option_table(&plain);
    assert!(!t.contains("-matptap_via"), "{t}");
    // A run whose matrix changes refreshes its products: unchanged.
    let t = option_table_on(
        2,
        &[
            "scenes/block-on-plane.toml",
            "--set",
            "solver.direct_max_dofs=0",
        ],
    );
    assert!(!t.contains("-matptap_via"), "{t}");
}

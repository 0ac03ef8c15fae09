//! Iteration counts of the main scenes, pinned to bands: a change that makes
//! Newton, the Uzawa loop or the linear solver work harder (or that stops
//! the preconditioner reuse) fails here, not only in a benchmark nobody
//! reran. The bands are the counts measured when they were set, with room
//! for round-off (a count moves by one when a residual lands on the other
//! side of a tolerance), not for a lost lever.
//!
//! Counts are summed over the steps of one serial run, read from its
//! machine output: the history CSV next to the result file (Newton, Uzawa
//! and linear iterations and cutbacks per step) and the file's `/run`
//! attributes (preconditioner builds and reuses, the contact Schur path's
//! factorisations). Small meshes only: the whole file runs in seconds.
//! Each scene is pinned with the links (`LINKS`, their counts since these
//! pins were set) and with the mortar, the default.
mod common;
use common::LINKS;

/// What one run did, summed over its steps.
#[derive(Debug, Default)]
struct Counts {
    steps: usize,
    newton: usize,
    uzawa: usize,
    ksp: usize,
    cutbacks: usize,
    /// Preconditioner builds decided by the active-set watch.
    builds: usize,
    reuses: usize,
    /// The contact Schur path: (bulk, dense Schur) factorisations.
    schur: Option<(usize, usize)>,
}

fn counts(args: &[&str]) -> Counts {
    let dir = common::scratch(&format!(
        "counts-{}",
        args.join("-").replace(['=', '.', '/'], "_")
    ));
    let out = dir.join("run.h5");
    let mut all = vec!["run"];
    all.extend_from_slice(args);
    all.extend_from_slice(&["-q", "-o", out.to_str().unwrap()]);
    let o = common::run(&all);
    let text = common::text(&o);
    assert!(o.status.success(), "{args:?} failed:\n{text}");
    let rows = common::history(&out);
    let sum = |column| common::history_sum(&rows, column);
    let run = contactlink::output::read_run_record(&out)
        .unwrap_or_else(|e| panic!("{args:?}: {e}"))
        .unwrap_or_else(|| panic!("{args:?}: no /run in {}", out.display()));
    let c = Counts {
        steps: rows.len(),
        newton: sum("newton"),
        uzawa: sum("uzawa"),
        ksp: sum("linear"),
        cutbacks: sum("cutbacks"),
        builds: run.preconditioner_builds,
        reuses: run.preconditioner_reuses,
        // One rank: the Schur complement's own path (several ranks take
        // the low-rank update, whose dense factorisations are of I + D·G).
        schur: run
            .schur
            .filter(|s| !s.low_rank)
            .map(|s| (s.bulk_factorisations, s.schur_factorisations)),
    };
    assert!(c.steps > 0, "no steps in the history of {args:?}");
    // The run's own totals agree with its per-step history.
    assert_eq!(
        (run.steps, run.newton_iterations, run.uzawa_iterations),
        (c.steps, c.newton, c.uzawa),
        "{args:?}: /run against the history"
    );
    assert_eq!(
        (run.linear_iterations, run.cutbacks),
        (c.ksp, c.cutbacks),
        "{args:?}: /run against the history"
    );
    c
}

/// `c` took `steps` steps without cutback and its Newton, Uzawa and linear
/// iterations lie within `bands`.
fn pin(scene: &str, c: &Counts, steps: usize, bands: [(usize, usize); 3]) {
    assert_eq!((c.steps, c.cutbacks), (steps, 0), "{scene}: {c:?}");
    within("Newton iterations", scene, c.newton, bands[0]);
    within("Uzawa iterations", scene, c.uzawa, bands[1]);
    within("linear iterations", scene, c.ksp, bands[2]);
}

fn within(what: &str, scene: &str, value: usize, band: (usize, usize)) {
    assert!(
        (band.0..=band.1).contains(&value),
        "{scene}: {what} = {value}, outside its pinned band {}..={}",
        band.0,
        band.1
    );
}

/// The contact Schur path (the default for these small linear scenes on
/// one rank): the same Newton and Uzawa counts as the factor-per-rebuild
/// path, one exact solve per Newton iteration, the bulk factored once and
/// the dense Schur complement once per Newton iteration.
fn schur_path(scene: &str, args: &[&str], newton: (usize, usize), uzawa: (usize, usize)) {
    let c = counts(args);
    within("Newton iterations", scene, c.newton, newton);
    within("Uzawa iterations", scene, c.uzawa, uzawa);
    assert_eq!(
        c.ksp, c.newton,
        "{scene}: not one exact solve per Newton iteration: {c:?}"
    );
    assert_eq!(c.schur, Some((1, c.newton)), "{scene}: {c:?}");
}

/// The factor-per-rebuild path these pins were set on.
const NO_SCHUR: [&str; 2] = ["--set", "solver.contact_schur=false"];

#[test]
fn hertz_cylinder_schur() {
    // Measured: 13 Newton, 7 Uzawa (the Uzawa rate rule raises the penalty
    // once; without it 14 and 11), 13 exact solves; bulk factored once.
    let args = [
        "hertz-cylinder",
        "--set",
        "mesh.fine_size=0.4",
        LINKS[0],
        LINKS[1],
    ];
    schur_path("hertz-cylinder h = 0.4, Schur", &args, (11, 15), (6, 8));
    let args = [
        "hertz-cylinder",
        "--set",
        "mesh.fine_size=0.2",
        LINKS[0],
        LINKS[1],
    ];
    schur_path("hertz-cylinder h = 0.2, Schur", &args, (6, 9), (3, 6));
    schur_path(
        "patch-test, Schur",
        &["patch-test", LINKS[0], LINKS[1]],
        (5, 8),
        (3, 6),
    );
}

#[test]
fn mortar_hertz_cylinder_schur() {
    // The default formulation. Measured: h = 0.4 7 Newton, 4 Uzawa; h = 0.2
    // 6 / 4; the patch test 5 / 5; bulk factored once each.
    let args = ["hertz-cylinder", "--set", "mesh.fine_size=0.4"];
    schur_path(
        "hertz-cylinder h = 0.4, mortar, Schur",
        &args,
        (6, 9),
        (3, 5),
    );
    let args = ["hertz-cylinder", "--set", "mesh.fine_size=0.2"];
    schur_path(
        "hertz-cylinder h = 0.2, mortar, Schur",
        &args,
        (5, 8),
        (3, 5),
    );
    schur_path("patch-test, mortar, Schur", &["patch-test"], (4, 7), (4, 6));
}

#[test]
fn hertz_cylinder_coarse() {
    // Measured: 13 Newton, 7 Uzawa, 34 GMRES iterations around 7 LDLᵀ
    // factorisations: the Uzawa rate rule raises the penalty once the
    // multiplier change stalls, and the raised tangent is refactored
    // (before the rate rule: 14 Newton, 11 Uzawa, 64 GMRES, 4
    // factorisations; before the coupled Uzawa tolerance and the
    // active-set lag: 23 Newton, 10 Uzawa, 84 GMRES).
    let scene = "hertz-cylinder h = 0.4";
    let c = counts(
        &[
            &["hertz-cylinder", "--set", "mesh.fine_size=0.4"][..],
            &NO_SCHUR,
            &LINKS,
        ]
        .concat(),
    );
    pin(scene, &c, 1, [(11, 15), (6, 8), (25, 45)]);
    within("preconditioner builds", scene, c.builds, (5, 8));
}

#[test]
fn hertz_cylinder_medium() {
    // Measured: 7 Newton, 4 Uzawa, 19 GMRES, 5 factorisations (before the
    // main-part tangent of the first Uzawa iteration: 9, 4, 20, 6; before
    // the coupled Uzawa tolerance: 11, 3, 25).
    let scene = "hertz-cylinder h = 0.2";
    let c = counts(
        &[
            &["hertz-cylinder", "--set", "mesh.fine_size=0.2"][..],
            &NO_SCHUR,
            &LINKS,
        ]
        .concat(),
    );
    pin(scene, &c, 1, [(6, 9), (3, 6), (14, 30)]);
    within("preconditioner builds", scene, c.builds, (4, 8));
}

#[test]
fn hertz_cylinder_coarse_on_the_krylov_path() {
    // GMRES + GAMG forced (direct_max_dofs = 0), serial. Measured: 16
    // Newton, 6 Uzawa, 160 GMRES iterations around one GAMG set-up kept
    // for the whole step (smoothed aggregation, the default before
    // 2026-12-07: 15, 6, 129, the same 0.25 s), since the Uzawa rate rule no longer raises
    // penalties on the Krylov path (with it: 40, 7, 203 and two set-ups,
    // the raise resetting the lag; before the Krylov path's
    // Anderson-accelerated Uzawa updates 43, 8, 215; before its non-final
    // Uzawa solves at 1e-2 and their GMRES floor 42, 8, 292). Before the
    // Eisenstat–Walker cap and the kept hierarchy the step was cut back 8
    // times and the run failed at load factor 0.996 (30 Newton iterations
    // without convergence).
    coarse_krylov_cylinder("links", [(12, 19), (5, 7), (140, 185), (1, 1)]);
}

/// hertz-cylinder h = 0.4 on GMRES + GAMG (serial) with `formulation` in
/// one step without cutback, its Newton, Uzawa and linear
/// iterations and preconditioner builds within `bands`.
fn coarse_krylov_cylinder(formulation: &str, bands: [(usize, usize); 4]) {
    let scene = format!("hertz-cylinder h = 0.4, {formulation} GMRES + GAMG");
    let set = format!("contact.formulation={formulation}");
    let c = counts(&[
        "hertz-cylinder",
        "--set",
        "mesh.fine_size=0.4",
        "--set",
        "solver.direct_max_dofs=0",
        "--set",
        &set,
    ]);
    pin(&scene, &c, 1, [bands[0], bands[1], bands[2]]);
    within("preconditioner builds", &scene, c.builds, bands[3]);
}

#[test]
fn hertz_cylinder_mortar_on_the_krylov_path() {
    // The same with a mortar pair, whose GMRES solves go to a fixed 1e-4
    // instead of Eisenstat–Walker. Measured: 10 Newton, 4 Uzawa, 151 GMRES
    // iterations, one GAMG set-up (smoothed aggregation: 9, 4, 108; with
    // Eisenstat–Walker as well: 18, 5, 111).
    coarse_krylov_cylinder("mortar", [(8, 12), (4, 5), (130, 175), (1, 1)]);
}

/// A mortar pair on a one-cell-thick `scene` of that `thickness`, pushed
/// in one step: its candidates, searched with the step's prescribed
/// motion as margin, cover the contact zone at the first search (a second
/// search from the converged state roughly doubled the iterations).
fn mortar_one_search(scene: &str, thickness: &str) {
    let mesh = format!("mesh.thickness={thickness}");
    let hertz = format!("hertz.thickness={thickness}");
    let name = format!("{scene}, {thickness} thick, mortar");
    let c = counts(&[
        scene,
        "--set",
        &mesh,
        "--set",
        &hertz,
        "--set",
        "contact.formulation=mortar",
    ]);
    within("Newton iterations", &name, c.newton, (6, 9));
    within("Uzawa iterations", &name, c.uzawa, (3, 5));
}

#[test]
fn mortar_candidates_cover_a_thin_cylinders_contact_zone_in_one_solve() {
    // The slave facets' shortest edge, the mortar search's own margin, is
    // a quarter of the step's 0.2 approach: the outer part of the zone was
    // found only by a second search (20 Newton, 10 Uzawa); now 7 / 4.
    mortar_one_search("hertz-cylinder", "0.05");
}

#[test]
fn mortar_candidates_cover_a_thin_cylinder_on_a_rigid_plane_in_one_solve() {
    // The same against a rigid plane, 0.02 thick, pushed 0.1: before, 11
    // Newton / 8 Uzawa and a second search; now 7 / 4.
    mortar_one_search("scripts/scenes/hertz-cylinder-rigid.toml", "0.02");
}

#[test]
fn block_slide_with_friction() {
    // Measured: 60 Newton, 43 Uzawa, 60 GMRES over 20 steps (friction keeps
    // every Newton solve tight; loose ones cost 74 / 63).
    let scene = "block-slide";
    let c = counts(&["block-slide", LINKS[0], LINKS[1]]);
    pin(scene, &c, 20, [(55, 66), (38, 48), (45, 80)]);
    assert!(
        c.reuses > 0,
        "{scene}: the preconditioner was never kept: {c:?}"
    );
}

#[test]
fn impact_with_the_mortar() {
    // Dynamics, Neo-Hookean blocks: backtracking line search, whose steps
    // end where the last mortar node changing state along them changes
    // (src/solve/state_change.rs). Measured:
    // 143 Newton, 121 Uzawa, 642 linear iterations over 40 steps (164
    // Newton without the shortened steps: runs of λ = 0.1 after Uzawa
    // updates opened the nodes).
    let scene = "impact, mortar";
    let c = counts(&["impact"]);
    pin(scene, &c, 40, [(136, 150), (110, 130), (560, 720)]);
}

#[test]
fn patch_test() {
    // Measured: 6 Newton, 5 Uzawa, 32 GMRES, one factorisation kept for the
    // whole step (before: 9, 4, 29).
    let scene = "patch-test";
    let c = counts(&[&["patch-test"][..], &NO_SCHUR, &LINKS].concat());
    pin(scene, &c, 1, [(5, 8), (3, 6), (20, 45)]);
    within("preconditioner builds", scene, c.builds, (1, 2));
}

#[test]
fn block_on_a_rigid_plane() {
    // A Neo-Hookean block: its tangent changes every iteration, so the
    // active-set watch stays off and SNES's own lag decides. Measured: 12
    // Newton, 10 Uzawa, 28 GMRES over 2 steps (before: 16, 8, 26).
    let scene = "block-on-plane";
    let c = counts(&["block-on-plane", LINKS[0], LINKS[1]]);
    pin(scene, &c, 2, [(10, 14), (8, 12), (20, 40)]);
    assert_eq!(c.builds, 0, "{scene}: the watch ran on a hyperelastic body");
}

#[test]
fn tight_switches_restore_the_old_counts() {
    // Both levers off: every Newton solve to the final tolerance and the
    // factors rebuilt every Newton iteration of a step's first Uzawa
    // iteration, as before they existed (hertz-cylinder h = 0.4: 23 Newton;
    // 25 with the first Uzawa iteration's main-part tangent, the default;
    // 20 with the Uzawa rate rule's penalty raise, which these switches do
    // not turn off).
    let (scene, c) = levers_off("links", (18, 22));
    assert_eq!(c.builds, 0, "{scene}: the watch ran while switched off");
}

/// hertz-cylinder h = 0.4 with `formulation`, both levers off (every Newton
/// solve tight, no active-set lag): its Newton iterations within `newton`.
fn levers_off(formulation: &str, newton: (usize, usize)) -> (String, Counts) {
    let scene = format!("hertz-cylinder h = 0.4, {formulation}, levers off");
    let set = format!("contact.formulation={formulation}");
    let c = counts(&[
        "hertz-cylinder",
        "--set",
        "mesh.fine_size=0.4",
        "--set",
        "solver.uzawa_forcing=0",
        "--set",
        "solver.lag_active_set=false",
        "--set",
        &set,
    ]);
    within("Newton iterations", &scene, c.newton, newton);
    (scene, c)
}

/// hertz-cylinder h = 0.2 with `formulation` and the full consistent
/// tangent in the first Uzawa iteration: its Newton iterations within
/// `newton`.
fn consistent_first_tangent(formulation: &str, newton: (usize, usize)) -> Counts {
    let scene = format!("hertz-cylinder h = 0.2, {formulation}, consistent first tangent");
    let set = format!("contact.formulation={formulation}");
    let c = counts(&[
        "hertz-cylinder",
        "--set",
        "mesh.fine_size=0.2",
        "--set",
        "solver.first_contact_main_tangent=false",
        "--set",
        &set,
    ]);
    within("Newton iterations", &scene, c.newton, newton);
    c
}

#[test]
fn consistent_first_contact_tangent_restores_the_old_counts() {
    // The first Uzawa iteration with the full consistent tangent, as before
    // the main-part one became the default: 9 Newton iterations where the
    // default takes 7 (hertz-cylinder h = 0.2).
    let c = consistent_first_tangent("links", (8, 11));
    assert_eq!(
        (c.steps, c.cutbacks),
        (1, 0),
        "consistent first tangent: {c:?}"
    );
}

#[test]
fn mortar_main_scenes() {
    // The default formulation on the factor-per-rebuild path and on the
    // frictional and hyperelastic scenes. Measured: hertz-cylinder h = 0.4
    // 7 Newton, 4 Uzawa, 18 GMRES, 5 factorisations; the patch test 5 / 5 /
    // 5 / 1; block-slide 59 / 44 / 59 over 20 steps; block-on-plane 12 /
    // 10 / 28 over 2 steps.
    let scene = "hertz-cylinder h = 0.4, mortar";
    let args = [
        &["hertz-cylinder", "--set", "mesh.fine_size=0.4"][..],
        &NO_SCHUR,
    ]
    .concat();
    let c = counts(&args);
    pin(scene, &c, 1, [(6, 9), (3, 5), (12, 28)]);
    within("preconditioner builds", scene, c.builds, (3, 7));
    let scene = "patch-test, mortar";
    let c = counts(&[&["patch-test"][..], &NO_SCHUR].concat());
    pin(scene, &c, 1, [(4, 7), (4, 6), (4, 10)]);
    within("preconditioner builds", scene, c.builds, (1, 2));
    let scene = "block-slide, mortar";
    let c = counts(&["block-slide"]);
    pin(scene, &c, 20, [(54, 65), (40, 49), (50, 75)]);
    let scene = "block-on-plane, mortar";
    let c = counts(&["block-on-plane"]);
    pin(scene, &c, 2, [(10, 14), (8, 12), (20, 40)]);
}

#[test]
fn mortar_levers_off_and_consistent_first_tangent() {
    // Both levers off, mortar, h = 0.4: 16 Newton where the default takes
    // 7; the full consistent tangent in the first Uzawa iteration, h = 0.2:
    // 9 where the default takes 6 (11 before the segment gap became the
    // difference of interpolated nodal heights: the nodes touching at zero
    // gap round to the other side of zero, a tie either way).
    levers_off("mortar", (14, 18));
    consistent_first_tangent("mortar", (8, 13));
}

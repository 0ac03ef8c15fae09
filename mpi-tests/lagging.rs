//! The preconditioner watch's decisions, agreed by every rank.
use contactlink::runtime::Runtime;
use contactlink::solve::lagging::{PreconditionerLag, MAX_REUSED_ITERATIONS_AMG};

/// The last rank alone sees its active set change from the second
/// Jacobian on (on one rank: that rank).
fn signature(rt: &Runtime, jacobian: u64) -> Vec<u64> {
    let changed = jacobian >= 2 && rt.rank() + 1 == rt.size();
    vec![if changed { 2 } else { 1 }]
}

/// Direct factors: a change on one rank rebuilds on all. An AMG hierarchy:
/// kept across the change, rebuilt only once a kept one's solve needed more
/// than its limit of linear iterations.
pub fn the_watch_rebuilds_factors_on_a_change_and_amg_once_worn(
    rt: &Runtime,
) -> Result<(), String> {
    let world = rt.world();
    let mut direct = PreconditionerLag::default();
    let mut amg = PreconditionerLag::iterative();
    let few = 5;
    let many = MAX_REUSED_ITERATIONS_AMG + 1;
    // (Jacobian, last solve's linear iterations, direct rebuilds, AMG rebuilds)
    let expected = [
        (1, 0, true, true),
        (1, few, false, false),
        (2, few, true, false),
        (2, few, false, false),
        (2, many, true, true),
        (2, few, false, false),
    ];
    for (i, &(jacobian, last, want_direct, want_amg)) in expected.iter().enumerate() {
        let s = signature(rt, jacobian);
        let d = direct.decide(&world, &s, last);
        let a = amg.decide(&world, &s, last);
        if d != want_direct || a != want_amg {
            return Err(format!(
                "decision {i} on rank {}: direct {d} (expected {want_direct}), AMG {a} \
                 (expected {want_amg})",
                rt.rank()
            ));
        }
    }
    if (amg.rebuilds, amg.reuses) != (2, 4) {
        return Err(format!(
            "AMG watch counted {} rebuilds and {} reuses, expected 2 and 4",
            amg.rebuilds, amg.reuses
        ));
    }
    Ok(())
}

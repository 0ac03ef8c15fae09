//! What a rank holds of a mortar pair: the master facets near its own
//! slave facets, not the whole master.
use contactlink::petsc::Vector;
use contactlink::runtime::Runtime;
use contactlink::solve::{PairFields, Simulation, StepReport, StepSink};
use mpi::collective::SystemOperation;
use mpi::traits::*;

/// Keeps nothing: the test reads the pairs after the run.
struct Discard;

impl StepSink for Discard {
    fn step(
        &mut self,
        _: &StepReport,
        _: &Vector,
        _: &Vector,
        _: &[PairFields],
        _: &[f64],
        _: Option<&Vector>,
    ) -> contactlink::error::Result<()> {
        Ok(())
    }
}

/// The patch test with the mortar formulation on a finer mesh (16 × 16 lower
/// and 12 × 12 upper facets on a unit interface): the whole interface is in
/// contact, so the contact zone spans the ranks that hold slave facets.
/// After the run, every rank holds fewer master facets than the whole
/// master and at least two ranks hold some (one rank: all of them), and the
/// contact force is the uniform stress's, E ε A.
pub fn a_mortar_pair_holds_only_the_master_near_its_slave_facets(
    rt: &Runtime,
) -> Result<(), String> {
    let overrides: Vec<String> = [
        "contact.formulation=\"mortar\"",
        "mesh.lower_divisions=[16, 16, 2]",
        "mesh.upper_divisions=[12, 12, 2]",
    ]
    .iter()
    .map(|s| s.to_string())
    .collect();
    let (model, _) =
        contactlink::pipeline::load_model("patch-test", &overrides).map_err(|e| e.to_string())?;
    let mut sim = Simulation::setup(rt, &model).map_err(|e| e.to_string())?;
    let report = sim
        .run(rt, &mut Discard, false, None)
        .map_err(|e| e.to_string())?;
    let pair = sim.contact().first().ok_or("no contact pair")?;
    let facets = pair.held_facets().ok_or("no held master")?;
    let (held, whole) = (facets.held, facets.whole);
    let world = rt.world();
    let mut holding = 0u64;
    world.all_reduce_into(&u64::from(held > 0), &mut holding, SystemOperation::sum());
    let p = rt.size();
    if p == 1 {
        crate::ensure(held == whole, || {
            format!("one rank holds {held} of {whole} master facets")
        })?;
    } else {
        crate::ensure(held < whole, || {
            format!(
                "rank {} of {p} holds {held} of {whole} master facets",
                rt.rank()
            )
        })?;
        crate::ensure(holding >= 2, || {
            format!("{holding} of {p} ranks hold master facets")
        })?;
    }
    let last = report.steps.last().ok_or("no step")?;
    let force = last.contact.first().ok_or("no contact report")?.force[2];
    if rt.rank() == 0 {
        println!(
            "  mortar patch test: rank 0 holds {held} of {whole} master facets, Fz {force:.12e}"
        );
    }
    // The compression of 1 % of the stack height: σ = E ε on the unit area.
    crate::ensure(((force.abs() - 10.0) / 10.0).abs() < 1e-6, || {
        format!("contact force {force}, expected 10 (E ε A)")
    })
}

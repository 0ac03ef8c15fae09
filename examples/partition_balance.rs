//! Work per rank of the partition `contactlink run hertz-sphere` uses, without
//! running it: cells, owned nodes (a node belongs to the lowest rank among
//! its cells, as in the distribution), nonzero 3×3 blocks of the owned
//! Jacobian rows (the bulk pattern: nodes sharing a cell), the contact slave
//! facets, and the slave and master facets near the axis, where the contact
//! zone is (the contact radius is about 1.0 at the scene's load).
//!
//! ```text
//! cargo run --release --example partition_balance -- [RANKS] [RADIUS]
//! ```
//!
//! RANKS defaults to 2, RADIUS (of the zone counted, around the axis) to 1.3.
//! It runs serially (the partition is computed where the mesh is, as rank 0
//! does) and exits with status 1 when the largest rank's owned nodes or
//! Jacobian blocks exceed the mean by more than 5 %: the bulk work and the
//! solve's `MatMult` then wait for that rank.
use contactlink::mesh::generate::{hertz_sphere, HertzSphereSpec};
use contactlink::mesh::{FacetRef, Mesh};
use std::collections::BTreeSet;
use std::process::ExitCode;

/// Distance of a facet's centroid from the z axis.
fn axis_distance(mesh: &Mesh, facet: &FacetRef) -> Result<f64, String> {
    let nodes = mesh.facet_nodes(facet).map_err(|e| e.to_string())?;
    let n = nodes.len() as f64;
    let x = nodes.iter().map(|&v| mesh.nodes[v][0]).sum::<f64>() / n;
    let y = nodes.iter().map(|&v| mesh.nodes[v][1]).sum::<f64>() / n;
    Ok(x.hypot(y))
}

/// Facets of `set` per rank, all of them and those within `radius` of the axis.
fn facets_per_rank(
    mesh: &Mesh,
    part: &[i32],
    ranks: usize,
    set: &str,
    radius: f64,
) -> Result<(Vec<usize>, Vec<usize>), String> {
    let (mut all, mut zone) = (vec![0; ranks], vec![0; ranks]);
    for f in mesh.facet_set(set).map_err(|e| e.to_string())? {
        let r = part[f.cell] as usize;
        all[r] += 1;
        if axis_distance(mesh, f)? < radius {
            zone[r] += 1;
        }
    }
    Ok((all, zone))
}

fn run(ranks: usize, radius: f64) -> Result<(), String> {
    // The scene's mesh (scenes/hertz-sphere.toml): a 20 × 20 × 10 block.
    let spec = HertzSphereSpec {
        block_width: 20.0,
        block_height: 10.0,
        ..Default::default()
    };
    let mesh = hertz_sphere(&spec).map_err(|e| e.to_string())?;
    let slave = "sphere.curved";
    let part = contactlink::partition::partition_cells(&mesh, ranks, &[slave.to_string()])
        .map_err(|e| e.to_string())?;
    let mut owner = vec![i32::MAX; mesh.num_nodes()];
    let mut neighbours = vec![BTreeSet::new(); mesh.num_nodes()];
    let mut cells = vec![0usize; ranks];
    for (c, &p) in part.iter().enumerate() {
        cells[p as usize] += 1;
        let nodes = mesh.cell(c);
        for &a in nodes {
            owner[a] = owner[a].min(p);
            neighbours[a].extend(nodes.iter().copied());
        }
    }
    let (mut nodes, mut blocks) = (vec![0usize; ranks], vec![0usize; ranks]);
    for (v, &o) in owner.iter().enumerate() {
        if let Ok(r) = usize::try_from(o) {
            nodes[r] += 1;
            blocks[r] += neighbours[v].len();
        }
    }
    let (slaves, slave_zone) = facets_per_rank(&mesh, &part, ranks, slave, radius)?;
    let (_, master_zone) = facets_per_rank(&mesh, &part, ranks, "block.top", radius)?;
    println!("hertz-sphere on {ranks} ranks, per rank:");
    println!("  cells {cells:?}");
    println!("  owned nodes {nodes:?}");
    println!("  nonzero 3x3 blocks of the owned Jacobian rows (bulk) {blocks:?}");
    println!("  slave facets ({slave}) {slaves:?}");
    println!("  slave facets within {radius} of the axis {slave_zone:?}");
    println!("  master facets (block.top) within {radius} of the axis {master_zone:?}");
    for (what, per_rank) in [("owned nodes", &nodes), ("Jacobian blocks", &blocks)] {
        let mean = per_rank.iter().sum::<usize>() as f64 / ranks as f64;
        let largest = per_rank.iter().copied().max().unwrap_or(0);
        if largest as f64 > 1.05 * mean {
            return Err(format!(
                "{what} per rank {per_rank:?}: the largest more than 5 % above the mean"
            ));
        }
    }
    Ok(())
}

fn main() -> ExitCode {
    let mut args = std::env::args().skip(1);
    let ranks = args.next().map_or(Ok(2), |a| a.parse::<usize>());
    let radius = args.next().map_or(Ok(1.3), |a| a.parse::<f64>());
    let (Ok(ranks), Ok(radius)) = (ranks, radius) else {
        eprintln!("usage: partition_balance [RANKS] [RADIUS]");
        return ExitCode::FAILURE;
    };
    match run(ranks, radius) {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("partition_balance: {e}");
            ExitCode::FAILURE
        }
    }
}

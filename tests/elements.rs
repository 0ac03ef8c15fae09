//! Meshes of the second-order cells, wedges and pyramids through the whole
//! program: a box of each type clamped at its bottom, under a follower
//! pressure on its top, a dead traction on one side and a body force, run
//! by the binary on 1, 2 and 3 ranks (direct solver). The reactions balance
//! the loads, the ranks agree to 1e-10, and the result file holds the cells
//! with their width, type and VTK's node order for the XDMF sidecar. Each
//! type passes `check`, and a Neo-Hookean run cut after its first step and
//! continued with `--restart` on 2 and 3 ranks ends where the whole run ends.
mod common;
use common::*;
use contactlink::fem::CellType;
use contactlink::output::{layout, list_steps, read_dataset, read_nodal};
use std::path::Path;

fn scene(cell: CellType) -> String {
    format!(
        r#"
[mesh]
generator = "box"
body = "block"
size = [1.0, 1.0, 2.0]
divisions = [2, 2, 2]
cell_type = "{}"

[[body]]
name = "block"
material = "linear-elastic"
youngs = 1.0e6
poisson = 0.3

[[dirichlet]]
set = "block.zmin"
components = ["x", "y", "z"]

[[pressure]]
set = "block.top"
value = 10.0

[[traction]]
set = "block.xmax"
vector = [0.0, 0.0, 5.0]

[[body_force]]
body = "block"
vector = [0.0, 0.0, -3.0]

[steps]
count = 1
"#,
        cell.name()
    )
}

/// Σ of the reaction over every node (zero away from the clamped nodes).
fn total_reaction(h5: &Path, step: usize) -> [f64; 3] {
    let (r, _, _) = read_nodal(h5, step, layout::REACTION).unwrap();
    let mut t = [0.0; 3];
    for v in r.chunks_exact(3) {
        for i in 0..3 {
            t[i] += v[i];
        }
    }
    t
}

#[test]
fn every_new_cell_type_runs_alike_on_one_two_and_three_ranks() {
    let dir = scratch("elements-types");
    for cell in [
        CellType::Tet10,
        CellType::Hex20,
        CellType::Hex27,
        CellType::Wedge6,
        CellType::Wedge15,
        CellType::Pyramid5,
    ] {
        let path = write(&dir, &format!("{}.toml", cell.name()), &scene(cell));
        let mut displacement = Vec::new();
        for n in [1, 2, 3] {
            let out = dir.join(format!("{}-{n}.h5", cell.name()));
            let args = [
                "run",
                path.to_str().unwrap(),
                "-q",
                "-o",
                out.to_str().unwrap(),
            ];
            let o = if n == 1 { run(&args) } else { mpirun(n, &args) };
            assert!(
                o.status.success(),
                "{} on {n} ranks: {}",
                cell.name(),
                text(&o)
            );
            let step = *list_steps(&out).unwrap().last().unwrap();
            let (u, _, _) = read_nodal(&out, step, layout::DISPLACEMENT).unwrap();
            displacement.push(u);
            // The clamp holds the load: 10 × 1 down on the top (small
            // strain: the follower's normal barely turns), 5 × 2 up on the
            // side, 3 × 2 down in the body.
            let r = total_reaction(&out, step);
            let expected = [0.0, 0.0, 10.0 - 10.0 + 6.0];
            for i in 0..3 {
                assert!(
                    (r[i] - expected[i]).abs() < 0.05,
                    "{} on {n} ranks: reaction {r:?}",
                    cell.name()
                );
            }
            if n == 1 {
                check_file(&out, cell);
            }
        }
        for (k, u) in displacement.iter().enumerate().skip(1) {
            let d = relative_difference(&displacement[0], u);
            assert!(
                d < 1e-10,
                "{}: {} ranks differ by {d:e}",
                cell.name(),
                k + 1
            );
        }
    }
}

/// `/mesh/cells` of the type's width and name, in VTK's node order (a
/// wedge's first triangle's normal points away from its second), and the
/// sidecar's topology.
fn check_file(h5: &Path, cell: CellType) {
    let (cells, shape) = read_dataset::<i64>(h5, layout::MESH_CELLS).unwrap();
    assert_eq!(shape[1], cell.nodes(), "{}", cell.name());
    let attr: hdf5::types::VarLenUnicode = hdf5::File::open(h5)
        .and_then(|f| f.dataset(layout::MESH_CELLS))
        .and_then(|d| d.attr(layout::CELL_TYPE_ATTR))
        .and_then(|a| a.read_scalar())
        .unwrap();
    assert_eq!(attr.as_str(), cell.name());
    let xmf = std::fs::read_to_string(h5.with_extension("xmf")).unwrap();
    let topology = match cell {
        CellType::Tet10 => "Tetrahedron_10",
        CellType::Hex20 => "Hexahedron_20",
        CellType::Hex27 => "Hexahedron_27",
        CellType::Wedge6 => "Wedge",
        CellType::Wedge15 => "Wedge_15",
        CellType::Pyramid5 => "Pyramid",
        _ => unreachable!(),
    };
    let needle = format!("TopologyType=\"{topology}\"");
    assert!(
        xmf.contains(&needle),
        "{}: {needle} not in the sidecar",
        cell.name()
    );
    assert!(xmf.contains(&format!("NodesPerElement=\"{}\"", cell.nodes())));
    if cell.linear() == CellType::Wedge6 {
        let (x, _) = read_dataset::<f64>(h5, layout::MESH_NODES).unwrap();
        let p = |k: usize| {
            let v = cells[k] as usize;
            [x[3 * v], x[3 * v + 1], x[3 * v + 2]]
        };
        let sub = |a: [f64; 3], b: [f64; 3]| [a[0] - b[0], a[1] - b[1], a[2] - b[2]];
        let (a, b, c) = (sub(p(1), p(0)), sub(p(2), p(0)), sub(p(3), p(0)));
        let n = [
            a[1] * b[2] - a[2] * b[1],
            a[2] * b[0] - a[0] * b[2],
            a[0] * b[1] - a[1] * b[0],
        ];
        assert!(
            n[0] * c[0] + n[1] * c[1] + n[2] * c[2] < 0.0,
            "not VTK's wedge"
        );
    }
}

/// A Neo-Hookean box of `cell`s under a growing follower pressure and a
/// side traction, three steps.
fn stepped_scene(cell: CellType) -> String {
    format!(
        r#"
[mesh]
generator = "box"
body = "block"
size = [1.0, 1.0, 2.0]
divisions = [2, 2, 3]
cell_type = "{}"

[[body]]
name = "block"
material = "neo-hookean"
youngs = 100.0
poisson = 0.3

[[dirichlet]]
set = "block.zmin"

[[pressure]]
set = "block.top"
value = 8.0

[[traction]]
set = "block.xmax"
vector = [0.0, 3.0, 0.0]

[steps]
count = 3
"#,
        cell.name()
    )
}

/// `check` reads every type, and a run of each cut after its first step
/// and continued with `--restart` on 2 and 3 ranks ends where the whole
/// 1-rank run ends.
#[test]
fn every_new_cell_type_is_checked_and_restarts_on_two_and_three_ranks() {
    let dir = scratch("elements-restart");
    for cell in [
        CellType::Tet10,
        CellType::Hex20,
        CellType::Hex27,
        CellType::Wedge6,
        CellType::Wedge15,
        CellType::Pyramid5,
    ] {
        let name = cell.name();
        let path = write(&dir, &format!("{name}-steps.toml"), &stepped_scene(cell));
        let scene = path.to_str().unwrap();
        let o = run(&["check", scene]);
        assert!(o.status.success(), "check {name}: {}", text(&o));
        let full = dir.join(format!("{name}-full.h5"));
        let o = run(&["run", scene, "-q", "-o", full.to_str().unwrap()]);
        assert!(o.status.success(), "{name}: {}", text(&o));
        let cut = cut_after(&full, 1, &format!("{name}-cut.h5"));
        let last = *list_steps(&full).unwrap().last().unwrap();
        assert_eq!(last, 3, "{name}");
        let (u_full, _, _) = read_nodal(&full, last, layout::DISPLACEMENT).unwrap();
        assert!(
            u_full.iter().any(|v| v.abs() > 1e-3),
            "{name}: nothing moved"
        );
        for n in [2, 3] {
            let cont = dir.join(format!("{name}-cont-{n}.h5"));
            let args = [
                "run",
                scene,
                "-q",
                "-o",
                cont.to_str().unwrap(),
                "--restart",
                cut.to_str().unwrap(),
            ];
            let o = mpirun(n, &args);
            assert!(
                o.status.success(),
                "{name} restarted on {n} ranks: {}",
                text(&o)
            );
            let (u, _, _) = read_nodal(&cont, last, layout::DISPLACEMENT).unwrap();
            let d = relative_difference(&u_full, &u);
            assert!(d < 1e-9, "{name}: restarted on {n} ranks differs by {d:e}");
        }
    }
}

//! The same scene on 1, 2 and 3 ranks writes the same answer, in the same
//! (input) order, with the documented file layout.
mod common;
use common::*;
use contactlink::output::{layout, list_steps, read_dataset, read_nodal, read_step_attrs};

fn run_on(ranks: usize, scene: &str, out: &std::path::Path) {
    let o = mpirun(ranks, &["run", scene, "-q", "-o", out.to_str().unwrap()]);
    assert!(
        o.status.success(),
        "{scene} on {ranks} ranks failed:\n{}",
        text(&o)
    );
}

fn compare_ranks(scene: &str) {
    let dir = scratch(&format!("parallel-{scene}"));
    let files: Vec<_> = [1, 2, 3]
        .iter()
        .map(|n| dir.join(format!("{scene}-{n}.h5")))
        .collect();
    for (n, f) in [1, 2, 3].iter().zip(&files) {
        run_on(*n, scene, f);
    }
    let steps = list_steps(&files[0]).unwrap();
    assert!(!steps.is_empty());
    for f in &files[1..] {
        assert_eq!(
            list_steps(f).unwrap(),
            steps,
            "{} has other steps",
            f.display()
        );
    }
    let last = *steps.last().unwrap();
    let (u1, rows, cols) = read_nodal(&files[0], last, layout::DISPLACEMENT).unwrap();
    assert_eq!(cols, 3);
    assert!(
        u1.iter().any(|v| v.abs() > 0.0),
        "the 1-rank displacement is zero"
    );
    for (n, f) in [2, 3].iter().zip(&files[1..]) {
        let (u, r, _) = read_nodal(f, last, layout::DISPLACEMENT).unwrap();
        assert_eq!(r, rows);
        let d = relative_difference(&u1, &u);
        println!("{scene}: {n} ranks vs 1: max relative displacement difference {d:.3e}");
        assert!(d < 1e-8, "{scene}: {n} ranks differ from 1 rank by {d:.3e}");
        let (reaction1, _, _) = read_nodal(&files[0], last, layout::REACTION).unwrap();
        let (reaction, _, _) = read_nodal(f, last, layout::REACTION).unwrap();
        let dr = relative_difference(&reaction1, &reaction);
        assert!(dr < 1e-6, "{scene}: {n}-rank reactions differ by {dr:.3e}");
    }
    // Mesh arrays are in input order whatever the rank count: identical.
    let (nodes1, shape) = read_dataset::<f64>(&files[0], layout::MESH_NODES).unwrap();
    let (cells1, cshape) = read_dataset::<i64>(&files[0], layout::MESH_CELLS).unwrap();
    assert_eq!(shape[1], 3);
    for f in &files[1..] {
        assert_eq!(
            read_dataset::<f64>(f, layout::MESH_NODES).unwrap().0,
            nodes1
        );
        let (cells, s) = read_dataset::<i64>(f, layout::MESH_CELLS).unwrap();
        assert_eq!((cells, s), (cells1.clone(), cshape.clone()));
    }
    // The partition column says which rank owned each cell.
    let (part3, _) = read_dataset::<i32>(&files[2], layout::MESH_PARTITION).unwrap();
    for r in 0..3 {
        assert!(
            part3.contains(&r),
            "rank {r} owns no cell in the 3-rank file"
        );
    }
    let info = read_step_attrs(&files[1], last).unwrap();
    assert!(info.converged && info.newton_iterations > 0);
    assert!((info.load_factor - 1.0).abs() < 1e-12);
    let xmf = std::fs::read_to_string(files[1].with_extension("xmf")).unwrap();
    assert!(xmf.contains(layout::DISPLACEMENT) && xmf.contains(&format!("{scene}-2.h5")));
}

#[test]
fn block_compress_same_on_1_2_3_ranks() {
    compare_ranks("block-compress");
}

#[test]
fn cantilever_tets_same_on_1_2_3_ranks() {
    compare_ranks("cantilever");
}

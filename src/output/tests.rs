//! Unit tests of the result-file module (serial: no MPI in unit tests).

use std::path::{Path, PathBuf};

use hdf5::File;

use super::collective::{attr_scalar, local_rows};
use super::fingerprint::step_fingerprint;
use super::reader::{list_steps, read_nodal, read_step_attrs};
use super::*;

#[test]
fn step_names_are_six_digits_and_sort() {
    assert_eq!(step_group_name(0), "000000");
    assert_eq!(step_group_name(42), "000042");
    assert_eq!(step_group_name(1_234_567), "1234567");
    let mut v = vec![
        step_group_name(10),
        step_group_name(2),
        step_group_name(100),
    ];
    v.sort();
    assert_eq!(v, ["000002", "000010", "000100"]);
}

#[test]
fn names_are_checked() {
    let p = Path::new("x.h5");
    assert!(check_name(p, "o", "top").is_ok());
    for bad in ["", ".", "..", "a/b", "a\0b"] {
        let err = check_name(p, "o", bad).err();
        assert!(err.is_some(), "{bad:?} accepted");
    }
}

#[test]
fn errors_name_path_and_object() {
    let e = OutputError::invalid(Path::new("/tmp/run/out.h5"), "/mesh/nodes", "bad");
    let msg = e.to_string();
    assert!(
        msg.contains("/tmp/run/out.h5") && msg.contains("/mesh/nodes"),
        "{msg}"
    );
}

#[test]
fn block_rows_helpers() {
    let d = [1.0, 2.0, 3.0, 4.0, 5.0, 6.0];
    let b = BlockRows::whole(&d, 3);
    assert_eq!((b.global_rows, b.start, b.cols), (2, 0, 3));
    let z = BlockRows::whole(&d, 0);
    assert_eq!(z.global_rows, 0);
    let e: BlockRows<f64> = BlockRows::empty(7, 7, 3);
    assert!(e.data.is_empty());
}

#[test]
fn facet_kinds() {
    assert_eq!(facet_nodes("quad4"), Some(4));
    assert_eq!(facet_nodes("tri3"), Some(3));
    assert_eq!(facet_nodes("tri6"), Some(6));
    assert_eq!(facet_nodes("quad9"), Some(9));
    assert_eq!(facet_nodes(MIXED_FACETS), None);
    assert_eq!(facet_nodes("tri10"), None);
}

#[test]
fn local_rows_checks_shape() {
    let p = Path::new("t.h5");
    let d = [0.0; 6];
    let ok = BlockRows {
        global_rows: 4,
        start: 2,
        cols: 3,
        data: &d,
    };
    assert_eq!(local_rows(p, "x", &ok).ok(), Some(2));
    let ragged = BlockRows {
        global_rows: 4,
        start: 0,
        cols: 4,
        data: &d,
    };
    assert!(local_rows(p, "x", &ragged).is_err());
    let past = BlockRows {
        global_rows: 3,
        start: 2,
        cols: 3,
        data: &d,
    };
    assert!(local_rows(p, "x", &past).is_err());
    let zero = BlockRows {
        global_rows: 3,
        start: 0,
        cols: 0,
        data: &d,
    };
    assert!(local_rows(p, "x", &zero).is_err());
    let empty: BlockRows<f64> = BlockRows::empty(3, 99, 3);
    assert_eq!(local_rows(p, "x", &empty).ok(), Some(0));
}

/// A file in the module's layout written serially with plain hdf5 calls
/// (no MPI in unit tests), read back through the helpers.
fn serial_file(name: &str) -> PathBuf {
    let path = std::env::temp_dir().join(format!("{name}_{}.h5", std::process::id()));
    let build = || -> hdf5::Result<()> {
        let f = File::create(&path)?;
        let steps = f.create_group("steps")?;
        for (i, t) in [(10_usize, 2.0_f64), (2, 1.0)] {
            let g = steps.create_group(&step_group_name(i))?;
            attr_scalar(&g, "time", &t)?;
            attr_scalar(&g, "load_factor", &(t / 2.0))?;
            attr_scalar(&g, "newton_iterations", &(i as i64))?;
            attr_scalar(&g, "uzawa_iterations", &1_i64)?;
            attr_scalar(&g, "converged", &1_u8)?;
            attr_scalar(&g, "wall_seconds", &0.25_f64)?;
            g.new_dataset_builder()
                .with_data(&ndarray::arr2(&[[1.0, 2.0, 3.0], [4.0, 5.0, 6.0]]))
                .create("displacement")?;
            g.create_group("contact")?
                .new_dataset_builder()
                .with_data(&[0.5, -0.5])
                .create("gap")?;
        }
        Ok(())
    };
    assert!(build().is_ok(), "could not build {}", path.display());
    path
}

#[test]
fn read_helpers_round_trip() {
    let path = serial_file("read_helpers");
    assert_eq!(list_steps(&path).ok(), Some(vec![2, 10]));
    let info = read_step_attrs(&path, 10).ok();
    assert_eq!(
        info,
        Some(StepInfo {
            index: 10,
            time: 2.0,
            load_factor: 1.0,
            newton_iterations: 10,
            uzawa_iterations: 1,
            converged: true,
            wall_seconds: 0.25,
        })
    );
    let d = read_nodal(&path, 2, "displacement").ok();
    assert_eq!(d, Some((vec![1.0, 2.0, 3.0, 4.0, 5.0, 6.0], 2, 3)));
    let g = read_nodal(&path, 2, "contact/gap").ok();
    assert_eq!(g, Some((vec![0.5, -0.5], 2, 1)));

    let missing = read_nodal(&path, 2, "reaction")
        .err()
        .map(|e| e.to_string());
    let msg = missing.unwrap_or_default();
    assert!(
        msg.contains(&path.display().to_string()) && msg.contains("/steps/000002/reaction"),
        "{msg}"
    );
    let _ = std::fs::remove_file(&path);
}

#[test]
fn read_errors_name_the_path() {
    let path = Path::new("/no/such/dir/out.h5");
    for msg in [
        list_steps(path).err().map(|e| e.to_string()),
        read_step_attrs(path, 1).err().map(|e| e.to_string()),
        read_nodal(path, 1, "displacement")
            .err()
            .map(|e| e.to_string()),
    ] {
        let msg = msg.unwrap_or_default();
        assert!(msg.contains("/no/such/dir/out.h5"), "{msg}");
    }
}

#[test]
fn stray_step_names_are_reported() {
    let path = std::env::temp_dir().join(format!("stray_{}.h5", std::process::id()));
    let made = File::create(&path).and_then(|f| f.create_group("steps")?.create_group("notes"));
    assert!(made.is_ok());
    let msg = list_steps(&path)
        .err()
        .map(|e| e.to_string())
        .unwrap_or_default();
    assert!(msg.contains("/steps/notes"), "{msg}");
    let _ = std::fs::remove_file(&path);
}

#[test]
fn fingerprints_see_differences() {
    let d = [0.0; 3];
    let b = BlockRows::whole(&d, 3);
    let info = StepInfo {
        index: 1,
        time: 0.5,
        load_factor: 0.5,
        newton_iterations: 3,
        uzawa_iterations: 2,
        converged: true,
        wall_seconds: 1.0,
    };
    let base = step_fingerprint(&info, &[("displacement", b)], &[]);
    let other_rank_wall = StepInfo {
        wall_seconds: 7.0,
        ..info
    };
    assert_eq!(
        base,
        step_fingerprint(&other_rank_wall, &[("displacement", b)], &[])
    );
    let later = StepInfo { time: 0.6, ..info };
    assert_ne!(base, step_fingerprint(&later, &[("displacement", b)], &[]));
    assert_ne!(base, step_fingerprint(&info, &[("reaction", b)], &[]));
    assert_ne!(base, step_fingerprint(&info, &[], &[("displacement", b)]));
}

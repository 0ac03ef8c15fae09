//! Scene errors that only rank 0 finds: a run reads the mesh and resolves
//! the scene against it on rank 0 alone (`pipeline::load`), so an unknown
//! set, a broken mesh-file line or a body nothing holds is found there and
//! handed to the other ranks. On 2 and 3 ranks the run must end within
//! 30 s (a rank left waiting for the model would never end), fail, and
//! print exactly the one error line a single process prints.
mod common;
use common::*;
use std::path::Path;
use std::process::{Command, Stdio};
use std::sync::mpsc;
use std::time::Duration;

/// The hang detector's limit.
const LIMIT: Duration = Duration::from_secs(30);

/// `contactlink ARGS` on `n` ranks (no mpirun for 1): exit success and
/// the error lines; panics when the run does not end within [`LIMIT`].
fn bounded(n: usize, args: &[&str]) -> (bool, Vec<String>) {
    let mut cmd = if n == 1 {
        Command::new(binary())
    } else {
        let mut c = Command::new("mpirun");
        c.args([
            "--allow-run-as-root",
            "--oversubscribe",
            "-n",
            &n.to_string(),
            binary(),
        ]);
        c
    };
    mpi_env(&mut cmd)
        .env_remove("CONTACTLINK_FAULT")
        .args(args)
        .stdout(Stdio::piped())
        .stderr(Stdio::piped());
    let child = cmd.spawn().expect("spawn contactlink / mpirun");
    let pid = child.id();
    let (tx, rx) = mpsc::channel();
    std::thread::spawn(move || {
        let _ = tx.send(child.wait_with_output());
    });
    let out = match rx.recv_timeout(LIMIT) {
        Ok(out) => out.expect("wait for the run"),
        Err(_) => {
            let _ = Command::new("kill")
                .args(["-KILL", &pid.to_string()])
                .status();
            panic!(
                "{n} ranks, {args:?}: still running after {LIMIT:?} (a rank waits for the model?)"
            );
        }
    };
    let lines = text(&out)
        .lines()
        .filter(|l| l.starts_with("contactlink:") && !l.starts_with("contactlink: warning"))
        .map(str::to_owned)
        .collect();
    (out.status.success(), lines)
}

/// On 1, 2 and 3 ranks, `run` and `run --setup-only` fail with one error
/// line, the same on every rank count, containing `expect`.
fn fails_alike(args: &[&str], expect: &str) {
    for setup_only in [false, true] {
        let mut args = args.to_vec();
        if setup_only {
            args.push("--setup-only");
        }
        let (ok, serial) = bounded(1, &args);
        assert!(!ok, "{args:?} succeeded on 1 rank");
        assert_eq!(serial.len(), 1, "{args:?} on 1 rank: {serial:#?}");
        assert!(serial[0].contains(expect), "{args:?}: {}", serial[0]);
        for n in [2, 3] {
            let (ok, lines) = bounded(n, &args);
            assert!(!ok, "{args:?} succeeded on {n} ranks");
            assert_eq!(lines, serial, "{args:?} on {n} ranks");
        }
    }
}

#[test]
fn an_unknown_dirichlet_set_fails_alike_on_every_rank_count() {
    fails_alike(
        &[
            "run",
            "block-compress",
            "--set",
            "dirichlet.1.set=block.nowhere",
        ],
        "[[dirichlet]] set 'block.nowhere' is not a node set of the mesh",
    );
}

#[test]
fn a_broken_mesh_file_line_fails_alike_on_every_rank_count() {
    let dir = scratch("scene-errors-gmsh");
    let fixture = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/data/gmsh/hex.msh");
    let msh = std::fs::read_to_string(fixture).expect("read the hex fixture");
    assert!(msh.contains("0 0 2.5\n"), "the fixture changed");
    write(
        &dir,
        "broken.msh",
        &msh.replacen("0 0 2.5\n", "0 0 2.q5\n", 1),
    );
    let scene = write(
        &dir,
        "scene.toml",
        "[mesh]\ngenerator = \"gmsh\"\nfile = \"broken.msh\"\n\n[[body]]\nname = \"b\"\nmaterial = \"linear-elastic\"\nyoungs = 1.0\npoisson = 0.3\n",
    );
    fails_alike(&["run", scene.to_str().unwrap()], "`2.q5`");
}

#[test]
fn an_unheld_body_fails_alike_on_every_rank_count() {
    let dir = scratch("scene-errors-unheld");
    let scene = write(
        &dir,
        "scene.toml",
        r#"
[mesh]
generator = "box"
body = "block"
size = [1.0, 1.0, 1.0]
divisions = [3, 3, 3]
cell_type = "hex8"

[[body]]
name = "block"
material = "linear-elastic"
youngs = 1000.0
poisson = 0.3

[[pressure]]
set = "block.top"
value = 1.0
"#,
    );
    fails_alike(&["run", scene.to_str().unwrap()], "nothing holds it");
}

/// The mortar formulation is first-order: a mortar pair on the quad8 faces
/// of hex20 cells is one scene error on every rank, before set-up, naming
/// the pair and the links, which take them.
#[test]
fn mortar_on_second_order_facets_fails_alike_on_every_rank_count() {
    fails_alike(
        &["run", "patch-test", "--set", "mesh.cell_type=hex20"],
        "contact pair 'interface': formulation \"mortar\" does not support second-order facets (quad8); use formulation = \"links\" for this pair",
    );
}

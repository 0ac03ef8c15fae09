//! The `.inp` reader end to end: one mesh written as a Gmsh `.msh` and as an
//! `.inp` runs to the same bits; a mesh Gmsh exported as `.inp` runs with
//! contact on 1 and 2 ranks as its `.msh` does; bad files fail in one line.
//! Gmsh is not needed: the exported fixtures are in tests/data/inp (see the
//! README there for the commands).
mod common;
use common::*;
use contactlink::mesh::{perturb_interior, stacked_blocks, CellType, FacetRef, Mesh, StackedSpec};
use contactlink::output::{layout, list_steps, read_nodal};
use std::fmt::Write as _;
use std::path::{Path, PathBuf};

/// The faces S1.. of C3D8 and C3D4 (local nodes from 0), as the Abaqus and
/// CalculiX manuals number them.
const C3D8_FACES: [&[usize]; 6] = [
    &[0, 1, 2, 3],
    &[4, 7, 6, 5],
    &[0, 4, 5, 1],
    &[1, 5, 6, 2],
    &[2, 6, 7, 3],
    &[3, 7, 4, 0],
];
const C3D4_FACES: [&[usize]; 4] = [&[0, 1, 2], &[0, 3, 1], &[1, 3, 2], &[2, 3, 0]];

/// The sets the scene below names.
const CONTACT_SETS: [&str; 2] = ["upper.bottom", "lower.top"];
const OTHER_SETS: [&str; 2] = ["lower.bottom", "upper.top"];

/// The upper block pressed into the lower one and sheared, with friction.
fn scene(mesh: &str) -> String {
    format!(
        r#"[mesh]
{mesh}

[[body]]
name = "lower"
material = "neo-hookean"
youngs = 1000.0
poisson = 0.3

[[body]]
name = "upper"
material = "neo-hookean"
youngs = 800.0
poisson = 0.25

[[dirichlet]]
set = "lower.bottom"

[[dirichlet]]
set = "upper.top"
value = [0.004, 0.001, -0.01]

[[contact]]
name = "interface"
slave = "upper.bottom"
master = "lower.top"
friction = 0.3

[steps]
count = 2
"#
    )
}

/// Two non-matching stacked blocks with their interior nodes moved.
fn two_blocks(cell_type: CellType) -> Mesh {
    let spec = StackedSpec {
        lower_divisions: [3, 3, 2],
        upper_divisions: [2, 2, 2],
        cell_type,
        ..StackedSpec::default()
    };
    let mesh = perturb_interior(&stacked_blocks(&spec).unwrap(), 0.2, 11).unwrap();
    // Cells come body by body: one element block per body in both files.
    assert!(mesh.cell_body.windows(2).all(|w| w[0] <= w[1]));
    mesh
}

/// Shortest text that reads back to the same f64.
fn num(x: f64) -> String {
    format!("{x:?}")
}

/// The mesh as Gmsh `.msh` 4.1: one volume entity per body, one surface
/// entity per facet set written, physical groups named as the sets.
fn write_msh(mesh: &Mesh, sets: &[&str]) -> String {
    let mut s = String::from("$MeshFormat\n4.1 0 8\n$EndMeshFormat\n$PhysicalNames\n");
    writeln!(s, "{}", mesh.bodies.len() + sets.len()).unwrap();
    for (b, name) in mesh.bodies.iter().enumerate() {
        writeln!(s, "3 {} \"{name}\"", b + 1).unwrap();
    }
    for (j, name) in sets.iter().enumerate() {
        writeln!(s, "2 {} \"{name}\"", 100 + j).unwrap();
    }
    s.push_str("$EndPhysicalNames\n$Entities\n");
    writeln!(s, "0 0 {} {}", sets.len(), mesh.bodies.len()).unwrap();
    for j in 0..sets.len() {
        writeln!(s, "{} 0 0 0 0 0 0 1 {} 0", j + 1, 100 + j).unwrap();
    }
    for b in 0..mesh.bodies.len() {
        writeln!(s, "{} 0 0 0 0 0 0 1 {} 0", b + 1, b + 1).unwrap();
    }
    let n = mesh.num_nodes();
    writeln!(s, "$EndEntities\n$Nodes\n1 {n} 1 {n}\n3 1 0 {n}").unwrap();
    for i in 1..=n {
        writeln!(s, "{i}").unwrap();
    }
    for p in &mesh.nodes {
        writeln!(s, "{} {} {}", num(p[0]), num(p[1]), num(p[2])).unwrap();
    }
    let facets: Vec<&[FacetRef]> = sets.iter().map(|n| mesh.facet_set(n).unwrap()).collect();
    let total = mesh.num_cells() + facets.iter().map(|f| f.len()).sum::<usize>();
    let blocks = mesh.bodies.len() + sets.len();
    writeln!(s, "$EndNodes\n$Elements\n{blocks} {total} 1 {total}").unwrap();
    let (volume, surface) = match mesh.cell_type {
        CellType::Hex8 => (5, 3),
        _ => (4, 2),
    };
    let mut tag = 0;
    for b in 0..mesh.bodies.len() {
        let cells: Vec<usize> = mesh.body_cells(b as u32).collect();
        writeln!(s, "3 {} {volume} {}", b + 1, cells.len()).unwrap();
        for c in cells {
            tag += 1;
            let ids: Vec<String> = mesh.cell(c).iter().map(|n| (n + 1).to_string()).collect();
            writeln!(s, "{tag} {}", ids.join(" ")).unwrap();
        }
    }
    for (j, list) in facets.iter().enumerate() {
        writeln!(s, "2 {} {surface} {}", j + 1, list.len()).unwrap();
        for f in list.iter() {
            tag += 1;
            let ids: Vec<String> = mesh
                .facet_nodes(f)
                .unwrap()
                .iter()
                .map(|n| (n + 1).to_string())
                .collect();
            writeln!(s, "{tag} {}", ids.join(" ")).unwrap();
        }
    }
    s.push_str("$EndElements\n");
    s
}

/// Sparse file ids, decreasing: node `i` and cell `c` of the mesh.
fn node_id(mesh: &Mesh, i: usize) -> usize {
    10 * (mesh.num_nodes() - i) + 3
}
fn element_id(mesh: &Mesh, c: usize) -> usize {
    7 * (mesh.num_cells() - c) + 2
}

/// The Abaqus face label of a facet: the face S<k> with the facet's nodes.
fn face_label(mesh: &Mesh, f: &FacetRef) -> usize {
    let cell = mesh.cell(f.cell);
    let mut facet = mesh.facet_nodes(f).unwrap();
    facet.sort_unstable();
    let faces: &[&[usize]] = match mesh.cell_type {
        CellType::Hex8 => &C3D8_FACES,
        _ => &C3D4_FACES,
    };
    let k = faces.iter().position(|face| {
        let mut nodes: Vec<usize> = face.iter().map(|&l| cell[l]).collect();
        nodes.sort_unstable();
        nodes == facet
    });
    k.expect("a facet is a face of its cell") + 1
}

/// The mesh as an `.inp` in `dir` (main.inp, its nodes in nodes.inp): the
/// contact sets as `*SURFACE` faces, the others as surface elements
/// (listed against the facets' orientation), and physics to skip.
fn write_inp(mesh: &Mesh, dir: &Path) -> PathBuf {
    let mut nodes = String::new();
    for (i, p) in mesh.nodes.iter().enumerate() {
        let id = node_id(mesh, i);
        writeln!(nodes, "{id}, {}, {}, {}", num(p[0]), num(p[1]), num(p[2])).unwrap();
    }
    std::fs::write(dir.join("nodes.inp"), nodes).unwrap();
    let (volume, surface) = match mesh.cell_type {
        CellType::Hex8 => ("C3D8", "CPS4"),
        _ => ("C3D4", "S3"),
    };
    let mut s = String::from("** the same mesh as the .msh\n*HEADING\ntwo blocks\n*NODE\n");
    s.push_str("*INCLUDE, INPUT=nodes.inp\n");
    for (b, name) in mesh.bodies.iter().enumerate() {
        writeln!(s, "*ELEMENT, TYPE={volume}, ELSET={name}").unwrap();
        for c in mesh.body_cells(b as u32) {
            let ids: Vec<String> = mesh
                .cell(c)
                .iter()
                .map(|&n| node_id(mesh, n).to_string())
                .collect();
            // Hexes over two lines, the first ending in a comma.
            let (a, rest) = ids.split_at(ids.len() / 2);
            let id = element_id(mesh, c);
            writeln!(s, "{id}, {},\n  {}", a.join(", "), rest.join(", ")).unwrap();
        }
    }
    for name in CONTACT_SETS {
        writeln!(s, "*SURFACE, NAME={name}, TYPE=ELEMENT").unwrap();
        for f in mesh.facet_set(name).unwrap() {
            let id = element_id(mesh, f.cell);
            writeln!(s, "{id}, S{}", face_label(mesh, f)).unwrap();
        }
    }
    let mut tag = 1_000_000;
    for name in OTHER_SETS {
        writeln!(s, "*ELEMENT, TYPE={surface}, ELSET={name}").unwrap();
        for f in mesh.facet_set(name).unwrap() {
            tag += 1;
            let mut ids: Vec<String> = mesh
                .facet_nodes(f)
                .unwrap()
                .iter()
                .map(|&n| node_id(mesh, n).to_string())
                .collect();
            ids.reverse();
            writeln!(s, "{tag}, {}", ids.join(", ")).unwrap();
        }
    }
    s.push_str("*MATERIAL, NAME=STEEL\n*ELASTIC\n1000., 0.3\n*STEP\n*STATIC\n");
    s.push_str("*BOUNDARY\nlower.bottom, 1, 3\n*END STEP\n");
    let path = dir.join("main.inp");
    std::fs::write(&path, s).unwrap();
    path
}

/// Runs a scene file serially, writing `out`; returns the last step's
/// displacement.
fn run_displacement(scene: &Path, out: &Path, ranks: usize) -> Vec<f64> {
    let args = [
        "run",
        scene.to_str().unwrap(),
        "-q",
        "-o",
        out.to_str().unwrap(),
    ];
    let o = if ranks == 1 {
        run(&args)
    } else {
        mpirun(ranks, &args)
    };
    assert!(o.status.success(), "{}:\n{}", scene.display(), text(&o));
    let steps = list_steps(out).unwrap();
    let last = *steps.last().expect("a step");
    let (u, _, cols) = read_nodal(out, last, layout::DISPLACEMENT).unwrap();
    assert_eq!(cols, 3);
    assert!(u.iter().any(|v| v.abs() > 1e-4), "nothing moved");
    u
}

fn same_mesh_both_ways(cell_type: CellType, name: &str) {
    let dir = scratch(name);
    let mesh = two_blocks(cell_type);
    let sets: Vec<&str> = CONTACT_SETS.iter().chain(&OTHER_SETS).copied().collect();
    std::fs::write(dir.join("blocks.msh"), write_msh(&mesh, &sets)).unwrap();
    write_inp(&mesh, &dir);
    let msh = write(
        &dir,
        "msh.toml",
        &scene("generator = \"gmsh\"\nfile = \"blocks.msh\""),
    );
    let inp = write(
        &dir,
        "inp.toml",
        &scene("generator = \"inp\"\nfile = \"main.inp\""),
    );
    // The same mesh, in the same numbering, from either file.
    let load = |p: &Path| contactlink::pipeline::load_model(p.to_str().unwrap(), &[]).unwrap();
    let (from_msh, from_inp) = (load(&msh).0, load(&inp).0);
    assert_eq!(from_inp.mesh, from_msh.mesh);
    assert_eq!(from_inp.mesh.cells, mesh.cells);
    assert_eq!(from_inp.mesh.nodes, mesh.nodes);
    // So the same run, to the bit.
    let u_msh = run_displacement(&msh, &dir.join("msh.h5"), 1);
    let u_inp = run_displacement(&inp, &dir.join("inp.h5"), 1);
    let bits = |u: &[f64]| u.iter().map(|v| v.to_bits()).collect::<Vec<_>>();
    assert_eq!(bits(&u_inp), bits(&u_msh));
}

#[test]
fn a_hex_mesh_as_msh_and_as_inp_runs_to_the_same_bits() {
    same_mesh_both_ways(CellType::Hex8, "inp-same-hex");
}

#[test]
fn a_tet_mesh_as_msh_and_as_inp_runs_to_the_same_bits() {
    same_mesh_both_ways(CellType::Tet4, "inp-same-tet");
}

fn fixture(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("tests/data/inp")
        .join(name)
}

/// The sphere-block scene on another mesh file.
fn sphere_block(dir: &Path, generator: &str, file: &Path) -> PathBuf {
    let original = Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes/sphere-block.toml");
    let text = std::fs::read_to_string(original).unwrap();
    let mesh = format!("generator = \"{generator}\"\nfile = \"{}\"", file.display());
    let text = text
        .replace("generator = \"gmsh\"\nfile = \"sphere-block.msh\"", &mesh)
        .replace("path = \"out/sphere-block.h5\"", "");
    assert!(text.contains(&mesh));
    write(dir, &format!("{generator}.toml"), &text)
}

#[test]
fn gmsh_inp_export_runs_with_contact_on_1_and_2_ranks_as_its_msh() {
    let dir = scratch("inp-gmsh-export");
    let inp = sphere_block(&dir, "inp", &fixture("sphere-block.inp"));
    let msh = sphere_block(&dir, "gmsh", &fixture("sphere-block.msh"));
    let (from_inp, _) = contactlink::pipeline::load_model(inp.to_str().unwrap(), &[]).unwrap();
    let (from_msh, _) = contactlink::pipeline::load_model(msh.to_str().unwrap(), &[]).unwrap();
    let (a, b) = (&from_inp.mesh, &from_msh.mesh);
    assert_eq!(a.cell_type, CellType::Tet4);
    assert_eq!(
        (a.cells.clone(), a.bodies.clone()),
        (b.cells.clone(), b.bodies.clone())
    );
    // Gmsh also writes each surface entity's elements as a set (Surface5).
    for (name, facets) in &b.facet_sets {
        assert!(a.facet_sets.get(name) == Some(facets), "facet set {name}");
        assert!(
            a.node_sets.get(name) == b.node_sets.get(name),
            "node set {name}"
        );
    }
    // Gmsh writes 14 significant digits to .inp, 16 to .msh.
    let moved = a
        .nodes
        .iter()
        .zip(&b.nodes)
        .flat_map(|(p, q)| (0..3).map(move |k| (p[k] - q[k]).abs()));
    assert!(moved.fold(0.0, f64::max) < 1e-12);
    let u_msh = run_displacement(&msh, &dir.join("msh.h5"), 1);
    let u1 = run_displacement(&inp, &dir.join("inp-1.h5"), 1);
    let u2 = run_displacement(&inp, &dir.join("inp-2.h5"), 2);
    let d_msh = relative_difference(&u_msh, &u1);
    let d_ranks = relative_difference(&u1, &u2);
    println!("sphere-block from Gmsh's .inp: vs its .msh {d_msh:.2e}, 2 ranks vs 1 {d_ranks:.2e}");
    assert!(
        d_msh < 1e-8,
        "the .inp run differs from the .msh run by {d_msh:.3e}"
    );
    assert!(d_ranks < 1e-8, "2 ranks differ from 1 by {d_ranks:.3e}");
}

#[test]
fn check_prints_the_note_and_run_prints_it_once() {
    let dir = scratch("inp-note");
    let mesh = two_blocks(CellType::Hex8);
    write_inp(&mesh, &dir);
    let scene = write(
        &dir,
        "scene.toml",
        &scene("generator = \"inp\"\nfile = \"main.inp\""),
    );
    let o = run(&["check", scene.to_str().unwrap()]);
    let t = text(&o);
    assert!(o.status.success(), "{t}");
    let note =
        "note: read the mesh of main.inp; not read (the scene holds the physics): *MATERIAL (line ";
    assert!(t.contains(note), "{t}");
    assert!(
        t.contains("*STEP (line ") && t.contains("*BOUNDARY (line "),
        "{t}"
    );
    let out = dir.join("out.h5");
    let o = mpirun(
        2,
        &["run", scene.to_str().unwrap(), "-o", out.to_str().unwrap()],
    );
    let t = text(&o);
    assert!(o.status.success(), "{t}");
    assert_eq!(
        t.matches("contactlink: note: read the mesh of main.inp")
            .count(),
        1,
        "{t}"
    );
    // -q prints nothing on success.
    let o = run(&[
        "run",
        scene.to_str().unwrap(),
        "-q",
        "-o",
        out.to_str().unwrap(),
    ]);
    assert!(o.status.success() && text(&o).is_empty(), "{}", text(&o));
}

/// `check` on a scene whose mesh is `deck` fails with one line that
/// contains each of `expect`, and no panic.
fn check_fails(name: &str, deck: &str, bodies: &[&str], expect: &[&str]) {
    let dir = scratch(name);
    std::fs::write(dir.join("part.inp"), deck).unwrap();
    let mut toml = String::from("[mesh]\ngenerator = \"inp\"\nfile = \"part.inp\"\n");
    for b in bodies {
        writeln!(toml, "\n[[body]]\nname = \"{b}\"\nmaterial = \"linear-elastic\"\nyoungs = 1.0\npoisson = 0.3").unwrap();
    }
    let scene = write(&dir, "scene.toml", &toml);
    let o = run(&["check", scene.to_str().unwrap()]);
    let t = text(&o);
    assert!(!o.status.success(), "{name}: accepted:\n{t}");
    assert!(!t.contains("panicked"), "{name}: panicked:\n{t}");
    assert_eq!(t.trim().lines().count(), 1, "{name}: not one line:\n{t}");
    for e in expect {
        assert!(t.contains(e), "{name}: no {e:?} in:\n{t}");
    }
}

const CUBE: &str = "*NODE\n1, 0, 0, 0\n2, 1, 0, 0\n3, 1, 1, 0\n4, 0, 1, 0\n\
                    5, 0, 0, 1\n6, 1, 0, 1\n7, 1, 1, 1\n8, 0, 1, 1\n";

#[test]
fn bad_inp_files_fail_check_in_one_line_naming_file_and_line() {
    check_fails(
        "inp-bad-c3d27",
        &format!("{CUBE}*ELEMENT, TYPE=C3D27, ELSET=B\n"),
        &["B"],
        &["part.inp, line 10: C3D27 elements are not supported"],
    );
    check_fails(
        "inp-bad-coordinate",
        &CUBE.replace("7, 1, 1, 1", "7, 1, 1, 1.0.0"),
        &["B"],
        &["part.inp, line 8: cannot read a coordinate from `1.0.0`"],
    );
    // A [[body]] the file has no element set for: at the [[body]]'s line.
    check_fails(
        "inp-bad-body",
        &format!("{CUBE}*ELEMENT, TYPE=C3D8, ELSET=B\n1, 1, 2, 3, 4, 5, 6, 7, 8\n"),
        &["B", "C"],
        &[
            "scene.toml:12: [mesh] inp: ",
            "no element set C of 3D elements",
            "element sets of 3D elements: B",
        ],
    );
    check_fails("inp-missing", "", &["B"], &["part.inp: no 3D elements"]);
}

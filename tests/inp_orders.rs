//! Second-order and wedge meshes through both readers: one box of tet10,
//! hex20, wedge6 and wedge15 cells written as a Gmsh `.msh` (Gmsh's node
//! order) and as an Abaqus `.inp` (C3D10, C3D20, C3D6, C3D15; its top as
//! `*SURFACE` faces, its side as S6/S8/S3/S4 surface elements) loads to the
//! same mesh and runs to the same bits.
mod common;
use common::*;
use contactlink::fem::{GMSH_HEX20, GMSH_TET10, GMSH_WEDGE15};
use contactlink::mesh::generate::{graded_box, BoxSpec};
use contactlink::mesh::{CellType, FacetRef, FacetType, Mesh};
use contactlink::output::{layout, list_steps, read_nodal};
use std::fmt::Write as _;
use std::path::Path;

/// The faces the `.inp` names: the top by `*SURFACE`, the side by surface
/// elements; the clamp's set by surface elements too.
const TOP: &str = "block.top";
const SIDE: &str = "block.xmax";
const BOTTOM: &str = "block.bottom";

fn scene(mesh: &str) -> String {
    format!(
        r#"[mesh]
{mesh}

[[body]]
name = "block"
material = "neo-hookean"
youngs = 1000.0
poisson = 0.3

[[dirichlet]]
set = "{BOTTOM}"

[[pressure]]
set = "{TOP}"
value = 20.0

[[traction]]
set = "{SIDE}"
vector = [0.0, 5.0, 10.0]

[steps]
count = 2
"#
    )
}

/// Gmsh's type number and node order (Gmsh node `j` is ours `order[j]`'s
/// inverse: ours `k` is Gmsh's `to_ours[k]`).
fn gmsh_cell(cell: CellType) -> (u32, Option<&'static [usize]>) {
    match cell {
        CellType::Tet10 => (11, Some(&GMSH_TET10)),
        CellType::Hex20 => (17, Some(&GMSH_HEX20)),
        CellType::Wedge6 => (6, None),
        CellType::Wedge15 => (18, Some(&GMSH_WEDGE15)),
        _ => unreachable!(),
    }
}

fn gmsh_facet(f: FacetType) -> u32 {
    match f {
        FacetType::Tri3 => 2,
        FacetType::Quad4 => 3,
        FacetType::Tri6 => 9,
        FacetType::Quad8 => 16,
        FacetType::Quad9 => 10,
    }
}

/// Node ids of a cell in Gmsh's order.
fn gmsh_nodes(cell: CellType, ours: &[usize]) -> Vec<usize> {
    match gmsh_cell(cell).1 {
        None => ours.to_vec(),
        Some(to_ours) => {
            let mut g = vec![0; ours.len()];
            for (k, &j) in to_ours.iter().enumerate() {
                g[j] = ours[k];
            }
            g
        }
    }
}

/// The mesh as Gmsh `.msh` 4.1: one volume, one surface entity per set
/// and facet type.
fn write_msh(mesh: &Mesh, sets: &[&str]) -> String {
    let mut blocks: Vec<(usize, u32, Vec<Vec<usize>>)> = Vec::new();
    for (j, name) in sets.iter().enumerate() {
        for ty in mesh.facet_set_types(name).unwrap() {
            let facets: Vec<Vec<usize>> = mesh
                .facet_set(name)
                .unwrap()
                .iter()
                .filter(|f| mesh.facet_type(f) == ty)
                .map(|f| mesh.facet_nodes(f).unwrap())
                .collect();
            blocks.push((j, gmsh_facet(ty), facets));
        }
    }
    let mut s = String::from("$MeshFormat\n4.1 0 8\n$EndMeshFormat\n$PhysicalNames\n");
    writeln!(s, "{}\n3 1 \"block\"", 1 + sets.len()).unwrap();
    for (j, name) in sets.iter().enumerate() {
        writeln!(s, "2 {} \"{name}\"", 100 + j).unwrap();
    }
    s.push_str("$EndPhysicalNames\n$Entities\n");
    writeln!(s, "0 0 {} 1", blocks.len()).unwrap();
    for (e, (j, _, _)) in blocks.iter().enumerate() {
        writeln!(s, "{} 0 0 0 0 0 0 1 {} 0", e + 1, 100 + j).unwrap();
    }
    s.push_str("1 0 0 0 0 0 0 1 1 0\n");
    let n = mesh.num_nodes();
    writeln!(s, "$EndEntities\n$Nodes\n1 {n} 1 {n}\n3 1 0 {n}").unwrap();
    for i in 1..=n {
        writeln!(s, "{i}").unwrap();
    }
    for p in &mesh.nodes {
        writeln!(s, "{:?} {:?} {:?}", p[0], p[1], p[2]).unwrap();
    }
    let total = mesh.num_cells() + blocks.iter().map(|b| b.2.len()).sum::<usize>();
    writeln!(
        s,
        "$EndNodes\n$Elements\n{} {total} 1 {total}",
        1 + blocks.len()
    )
    .unwrap();
    let line = |ids: &[usize]| ids.iter().map(|n| (n + 1).to_string()).collect::<Vec<_>>();
    let (volume, _) = gmsh_cell(mesh.cell_type);
    writeln!(s, "3 1 {volume} {}", mesh.num_cells()).unwrap();
    let mut tag = 0;
    for ids in mesh.cells_iter() {
        tag += 1;
        let g = gmsh_nodes(mesh.cell_type, ids);
        writeln!(s, "{tag} {}", line(&g).join(" ")).unwrap();
    }
    for (e, (_, ty, facets)) in blocks.iter().enumerate() {
        writeln!(s, "2 {} {ty} {}", e + 1, facets.len()).unwrap();
        for f in facets {
            tag += 1;
            writeln!(s, "{tag} {}", line(f).join(" ")).unwrap();
        }
    }
    s.push_str("$EndElements\n");
    s
}

fn abaqus_cell(cell: CellType) -> &'static str {
    match cell {
        CellType::Tet10 => "C3D10",
        CellType::Hex20 => "C3D20R",
        CellType::Wedge6 => "C3D6",
        CellType::Wedge15 => "C3D15",
        _ => unreachable!(),
    }
}

fn abaqus_facet(f: FacetType) -> &'static str {
    match f {
        FacetType::Tri3 => "S3",
        FacetType::Quad4 => "CPS4",
        FacetType::Tri6 => "STRI65",
        FacetType::Quad8 => "S8R",
        FacetType::Quad9 => "M3D9",
    }
}

/// Abaqus' faces S1.. by their corners (local, from 0): C3D10 as C3D4,
/// C3D20 as C3D8, C3D15 as C3D6 (the manuals' tables).
fn abaqus_faces(cell: CellType) -> &'static [&'static [usize]] {
    match cell.linear() {
        CellType::Tet4 => &[&[0, 1, 2], &[0, 3, 1], &[1, 3, 2], &[2, 3, 0]],
        CellType::Hex8 => &[
            &[0, 1, 2, 3],
            &[4, 7, 6, 5],
            &[0, 4, 5, 1],
            &[1, 5, 6, 2],
            &[2, 6, 7, 3],
            &[3, 7, 4, 0],
        ],
        _ => &[
            &[0, 1, 2],
            &[3, 5, 4],
            &[0, 3, 4, 1],
            &[1, 4, 5, 2],
            &[2, 5, 3, 0],
        ],
    }
}

fn face_label(mesh: &Mesh, f: &FacetRef) -> usize {
    let cell = mesh.cell(f.cell);
    let corners = mesh.facet_type(f).corners();
    let mut facet = mesh.facet_nodes(f).unwrap()[..corners].to_vec();
    facet.sort_unstable();
    let k = abaqus_faces(mesh.cell_type).iter().position(|face| {
        let mut nodes: Vec<usize> = face.iter().map(|&l| cell[l]).collect();
        nodes.sort_unstable();
        nodes == facet
    });
    k.expect("a facet is a face of its cell") + 1
}

/// The mesh as an `.inp`: ids offset, sixteen nodes a line at most (an
/// element continues on the next line after a trailing comma).
fn write_inp(mesh: &Mesh) -> String {
    let mut s = String::from("*HEADING\nthe same box as the .msh\n*NODE\n");
    for (i, p) in mesh.nodes.iter().enumerate() {
        writeln!(s, "{}, {:?}, {:?}, {:?}", i + 101, p[0], p[1], p[2]).unwrap();
    }
    let ids =
        |nodes: &[usize]| -> Vec<String> { nodes.iter().map(|&n| (n + 101).to_string()).collect() };
    writeln!(
        s,
        "*ELEMENT, TYPE={}, ELSET=block",
        abaqus_cell(mesh.cell_type)
    )
    .unwrap();
    for (c, cell) in mesh.cells_iter().enumerate() {
        let all = ids(cell);
        let (a, rest) = all.split_at(all.len().min(10));
        write!(s, "{}, {}", c + 1, a.join(", ")).unwrap();
        if rest.is_empty() {
            s.push('\n');
        } else {
            writeln!(s, ",\n{}", rest.join(", ")).unwrap();
        }
    }
    writeln!(s, "*SURFACE, NAME={TOP}, TYPE=ELEMENT").unwrap();
    for f in mesh.facet_set(TOP).unwrap() {
        writeln!(s, "{}, S{}", f.cell + 1, face_label(mesh, f)).unwrap();
    }
    let mut tag = 100_000;
    for name in [SIDE, BOTTOM] {
        for ty in mesh.facet_set_types(name).unwrap() {
            writeln!(s, "*ELEMENT, TYPE={}, ELSET={name}", abaqus_facet(ty)).unwrap();
            for f in mesh.facet_set(name).unwrap() {
                if mesh.facet_type(f) == ty {
                    tag += 1;
                    writeln!(
                        s,
                        "{tag}, {}",
                        ids(&mesh.facet_nodes(f).unwrap()).join(", ")
                    )
                    .unwrap();
                }
            }
        }
    }
    s.push_str("*MATERIAL, NAME=M\n*ELASTIC\n1000., 0.3\n*STEP\n*STATIC\n*END STEP\n");
    s
}

fn last_displacement(scene: &Path, out: &Path) -> Vec<u64> {
    let args = [
        "run",
        scene.to_str().unwrap(),
        "-q",
        "-o",
        out.to_str().unwrap(),
    ];
    let o = run(&args);
    assert!(o.status.success(), "{}:\n{}", scene.display(), text(&o));
    let last = *list_steps(out).unwrap().last().expect("a step");
    let (u, _, _) = read_nodal(out, last, layout::DISPLACEMENT).unwrap();
    assert!(u.iter().any(|v| v.abs() > 1e-4), "nothing moved");
    u.iter().map(|v| v.to_bits()).collect()
}

#[test]
fn second_order_and_wedge_meshes_as_msh_and_as_inp_run_to_the_same_bits() {
    for cell in [
        CellType::Tet10,
        CellType::Hex20,
        CellType::Wedge6,
        CellType::Wedge15,
    ] {
        let name = cell.name();
        let dir = scratch(&format!("inp-orders-{name}"));
        let mesh = graded_box(&BoxSpec {
            divisions: [2, 2, 3],
            cell_type: cell,
            ..Default::default()
        })
        .unwrap();
        std::fs::write(dir.join("box.msh"), write_msh(&mesh, &[TOP, SIDE, BOTTOM])).unwrap();
        std::fs::write(dir.join("box.inp"), write_inp(&mesh)).unwrap();
        let msh = write(
            &dir,
            "msh.toml",
            &scene("generator = \"gmsh\"\nfile = \"box.msh\""),
        );
        let inp = write(
            &dir,
            "inp.toml",
            &scene("generator = \"inp\"\nfile = \"box.inp\""),
        );
        let load = |p: &Path| contactlink::pipeline::load_model(p.to_str().unwrap(), &[]).unwrap();
        let (from_msh, from_inp) = (load(&msh).0, load(&inp).0);
        assert_eq!(from_msh.mesh.cells, mesh.cells, "{name}: .msh cells");
        assert_eq!(from_inp.mesh.cells, mesh.cells, "{name}: .inp cells");
        for set in [TOP, SIDE, BOTTOM] {
            let sorted = |m: &Mesh| {
                let mut f = m.facet_set(set).unwrap().to_vec();
                f.sort_unstable();
                f
            };
            assert_eq!(sorted(&from_inp.mesh), sorted(&mesh), "{name}: {set}");
            assert_eq!(sorted(&from_msh.mesh), sorted(&mesh), "{name}: {set}");
        }
        let u_msh = last_displacement(&msh, &dir.join("msh.h5"));
        let u_inp = last_displacement(&inp, &dir.join("inp.h5"));
        assert!(u_inp == u_msh, "{name}: the runs differ");
    }
}

//! The keyword format: continuation lines, case, comments, includes, ids.

use std::path::{Path, PathBuf};

use super::{line_of, node_at, parse, parse_err, parse_request, request, TWO_HEX};
use crate::mesh::inp::{read_inp, InpErrorKind, InpRequest};
use crate::mesh::CellType;

#[test]
fn two_hexes_are_read_in_file_order() {
    let (mesh, report) = parse(TWO_HEX);
    assert_eq!(mesh.cell_type, CellType::Hex8);
    assert_eq!(mesh.num_cells(), 2);
    assert_eq!(mesh.num_nodes(), 12);
    // Nodes numbered from 0 in file order, whatever the ids.
    assert_eq!(mesh.nodes[0], [0.0, 0.0, 0.0]);
    assert_eq!(mesh.nodes[8], [2.0, 0.0, 0.0]);
    assert_eq!(mesh.cell(0), &[0, 1, 2, 3, 4, 5, 6, 7]);
    assert_eq!(mesh.cell(1), &[1, 8, 9, 2, 5, 10, 11, 6]);
    assert_eq!(mesh.bodies, ["LEFT", "RIGHT"]);
    assert_eq!(mesh.cell_body, [0, 1]);
    assert_eq!(mesh.node_set("NALL").unwrap().len(), 12);
    assert_eq!(report.reoriented, 0);
    assert_eq!(report.unused_nodes, 0);
    assert!(report.skipped.is_empty());
    for c in 0..2 {
        assert!((mesh.cell_volume(c).unwrap() - 1.0).abs() < 1e-14);
    }
}

#[test]
fn element_lines_continue_after_a_trailing_comma() {
    let split = TWO_HEX.replace(
        "20, 101, 102, 103, 104, 105, 106, 107, 108",
        "20, 101, 102, 103,\n  104, 105,\n** a comment inside\n\n106, 107, 108",
    );
    assert_eq!(parse(&split).0, parse(TWO_HEX).0);
    // Without the comma the element is short, named at its first line.
    let cut = TWO_HEX.replace(
        "20, 101, 102, 103, 104, 105, 106, 107, 108",
        "20, 101, 102, 103\n104, 105, 106, 107, 108",
    );
    let err = parse_err(&cut);
    assert_eq!(err.line, Some(line_of(&cut, "20, 101")));
    assert!(
        err.to_string()
            .contains("element 20 (C3D8) has 3 nodes, C3D8 has 8"),
        "{err}"
    );
    // A continuation that never comes: the next keyword ends the element.
    let open = TWO_HEX.replace("7, 102, 9, 8, 103, 106, 3, 2, 107", "7, 102, 9, 8,");
    let err = parse_err(&format!("{open}*NSET, NSET=A\n1\n"));
    assert!(
        err.to_string().contains("element 7 (C3D8) has 3 nodes"),
        "{err}"
    );
}

#[test]
fn keywords_parameters_and_names_are_case_insensitive() {
    let lower = TWO_HEX
        .replace("*NODE, NSET=NALL", "*node,nset=Nall")
        .replace(
            "*ELEMENT, TYPE=C3D8, ELSET=LEFT",
            "*Element , type = c3d8r , elset=left",
        )
        .replace(
            "*ELEMENT, TYPE=C3D8, ELSET=RIGHT",
            "*ELEMENT,\nTYPE=C3D8I, ELSET=Right",
        )
        + "*nset, nset=BOTH\nnall\n*Elset, ELSET=all\nLEFT, right\n";
    let (mesh, _) = parse(&lower);
    assert_eq!(mesh.bodies, ["left", "Right"]);
    assert_eq!(mesh.node_set("BOTH").unwrap().len(), 12);
    // The scene's spelling names a set and picks the bodies.
    let r = request(&["ALL"], &["both", "NALL"]);
    let (mesh, _) = parse_request(&lower, &r).unwrap();
    assert_eq!(mesh.bodies, ["ALL"]);
    assert!(mesh.node_set("both").is_ok() && mesh.node_set("NALL").is_ok());
}

#[test]
fn comments_blank_lines_and_skipped_keywords() {
    let deck = format!(
        "** a deck\n\n*HEADING\nsome title\n{TWO_HEX}\
         *MATERIAL, NAME=STEEL\n*ELASTIC\n210000, 0.3\n\
         *SOLID SECTION, ELSET=LEFT, MATERIAL=STEEL\n\
         *STEP\n*STATIC\n*BOUNDARY\nNALL, 1, 3\n*END STEP\n\
         *STEP\n*STATIC\n*END STEP\n*NSET, NSET=X, FREQUENCY=100\n101\n"
    );
    let (mesh, report) = parse(&deck);
    assert_eq!(mesh.cells, parse(TWO_HEX).0.cells);
    assert_eq!(mesh.node_set("X").unwrap(), [0]);
    let at = |k: &str| line_of(&deck, k);
    let expected: Vec<String> = [
        ("MATERIAL", at("*MATERIAL")),
        ("ELASTIC", at("*ELASTIC")),
        ("SOLID SECTION", at("*SOLID")),
        ("STEP", at("*STEP")),
        ("STATIC", at("*STATIC")),
        ("BOUNDARY", at("*BOUNDARY")),
        ("END STEP", at("*END STEP")),
        ("NSET, FREQUENCY=", at("*NSET, NSET=X")),
    ]
    .iter()
    .map(|(k, l)| format!("*{k} (line {l})"))
    .collect();
    // Each keyword once, where first seen; *HEADING silently.
    assert_eq!(report.skipped, expected);
    let note = report.note();
    assert!(
        note.starts_with("read the mesh of t.inp; not read"),
        "{note}"
    );
    assert!(note.contains("*MATERIAL (line "), "{note}");
}

#[test]
fn coordinates_may_be_short_or_fortran() {
    let deck = TWO_HEX
        .replace("101, 0, 0, 0", "101, 0.0D0")
        .replace("102, 1, 0, 0", "102, 1.0e0,,");
    let (mesh, _) = parse(&deck);
    assert_eq!(mesh, parse(TWO_HEX).0);
}

/// A fresh directory of this test process.
fn scratch(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("contactlink-inp-{name}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

#[test]
fn includes_are_read_in_place_relative_to_the_including_file() {
    let dir = scratch("include");
    std::fs::create_dir_all(dir.join("mesh")).unwrap();
    let (nodes, elements) = TWO_HEX.split_at(TWO_HEX.find("*ELEMENT").unwrap());
    // Data lines only: the *NODE block continues in the included file.
    let node_lines = nodes.split_once('\n').unwrap().1;
    std::fs::write(dir.join("mesh/nodes.inp"), node_lines).unwrap();
    std::fs::write(
        dir.join("mesh/part.inp"),
        format!("*NODE, NSET=NALL\n*INCLUDE, INPUT=nodes.inp\n{elements}"),
    )
    .unwrap();
    std::fs::write(
        dir.join("main.inp"),
        "*include, input=mesh/part.inp\n*MATERIAL, NAME=A\n",
    )
    .unwrap();
    let (mesh, report) = read_inp(&dir.join("main.inp"), &InpRequest::default()).unwrap();
    assert_eq!(mesh, parse(TWO_HEX).0);
    assert_eq!(
        report.included,
        [dir.join("mesh/part.inp"), dir.join("mesh/nodes.inp")]
    );
    assert_eq!(report.skipped, ["*MATERIAL (line 2)"]);
    // An error in an included file names that file and its line.
    std::fs::write(dir.join("mesh/nodes.inp"), "101, 0, 0, x\n").unwrap();
    let err = read_inp(&dir.join("main.inp"), &InpRequest::default()).unwrap_err();
    assert_eq!(err.file, dir.join("mesh/nodes.inp").display().to_string());
    assert_eq!(err.line, Some(1));
    assert!(
        err.to_string()
            .contains("cannot read a coordinate from `x`"),
        "{err}"
    );
}

#[test]
fn include_cycles_and_missing_includes_are_errors() {
    let dir = scratch("cycle");
    std::fs::write(
        dir.join("a.inp"),
        "*NODE\n1, 0, 0, 0\n*INCLUDE, INPUT=b.inp\n",
    )
    .unwrap();
    std::fs::write(dir.join("b.inp"), "** b\n*INCLUDE, INPUT=a.inp\n").unwrap();
    let err = read_inp(&dir.join("a.inp"), &InpRequest::default()).unwrap_err();
    assert!(matches!(err.kind, InpErrorKind::IncludeCycle(_)), "{err}");
    assert_eq!(err.file, dir.join("b.inp").display().to_string());
    assert_eq!(err.line, Some(2));
    assert!(err.to_string().contains("a.inp → "), "{err}");
    std::fs::write(dir.join("c.inp"), "*INCLUDE, INPUT=nothere.inp\n").unwrap();
    let err = read_inp(&dir.join("c.inp"), &InpRequest::default()).unwrap_err();
    assert_eq!(err.line, Some(1));
    assert!(
        err.to_string().contains("cannot read the included file"),
        "{err}"
    );
    assert!(err.to_string().contains("nothere.inp"), "{err}");
    // A device would never end: refused before reading.
    std::fs::write(dir.join("d.inp"), "*INCLUDE, INPUT=/dev/zero\n").unwrap();
    let err = read_inp(&dir.join("d.inp"), &InpRequest::default()).unwrap_err();
    assert!(
        err.to_string().contains("/dev/zero: not a regular file"),
        "{err}"
    );
    let err = read_inp(Path::new("/dev/zero"), &InpRequest::default()).unwrap_err();
    assert_eq!(
        err.to_string(),
        "/dev/zero: cannot read the file: not a regular file"
    );
}

#[test]
fn nodes_no_cell_uses_are_dropped() {
    let deck = TWO_HEX.replace("2, 2, 1, 1\n", "2, 2, 1, 1\n999, 5, 5, 5\n");
    let (mesh, report) = parse(&deck);
    assert_eq!(report.unused_nodes, 1);
    assert_eq!(mesh, parse(TWO_HEX).0);
    assert!(mesh.nodes.iter().all(|p| *p != [5.0, 5.0, 5.0]));
    assert_eq!(node_at(&mesh, [2.0, 1.0, 1.0]), 11);
}

#[test]
fn abaqus_variants_are_named_once_in_the_note() {
    let deck = TWO_HEX
        .replace("TYPE=C3D8, ELSET=LEFT", "TYPE=C3D8R, ELSET=LEFT")
        .replace("TYPE=C3D8, ELSET=RIGHT", "TYPE=c3d8r, ELSET=RIGHT");
    let (mesh, report) = parse(&deck);
    assert_eq!(mesh, parse(TWO_HEX).0);
    assert_eq!(report.variants, ["C3D8R"]);
    let note = report.note();
    assert!(
        note.contains("C3D8R integrated by this program's full rule, not Abaqus'"),
        "{note}"
    );
    assert!(parse(TWO_HEX).1.variants.is_empty());
}

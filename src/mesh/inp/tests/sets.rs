//! Node sets, element sets, surfaces and bodies.

use super::{line_of, node_at, parse, parse_err, parse_request, request, TWO_HEX};
use crate::mesh::inp::InpErrorKind;

#[test]
fn generate_covers_the_defined_ids_of_a_range() {
    let deck = format!(
        "{TWO_HEX}*NSET, NSET=ODD, GENERATE\n101, 108, 2\n\
         *NSET, NSET=HUGE, GENERATE\n1, 1000000000000000000\n\
         *ELSET, ELSET=BOTH, GENERATE\n7, 20, 13\n"
    );
    let (mesh, _) = parse(&deck);
    let odd: Vec<[f64; 3]> = mesh
        .node_set("ODD")
        .unwrap()
        .iter()
        .map(|&n| mesh.nodes[n])
        .collect();
    assert_eq!(
        odd,
        [
            [0.0, 0.0, 0.0],
            [1.0, 1.0, 0.0],
            [0.0, 0.0, 1.0],
            [1.0, 1.0, 1.0]
        ]
    );
    // A range of 10^18 ids costs what the ids defined cost.
    assert_eq!(mesh.node_set("HUGE").unwrap().len(), 12);
    let r = request(&["BOTH"], &[]);
    let (mesh, _) = parse_request(&deck, &r).unwrap();
    assert_eq!(mesh.cell_body, [0, 0]);
    for bad in ["8, 1", "0, 4", "1, 4, 0", "1", "1, 2, 3, 4", "a, 3"] {
        let deck = format!("{TWO_HEX}*NSET, NSET=X, GENERATE\n{bad}\n");
        let err = parse_err(&deck);
        assert_eq!(
            err.line,
            Some(line_of(&deck, &format!("\n{bad}\n")) + 1),
            "{bad}"
        );
        assert!(
            matches!(err.kind, InpErrorKind::BadGenerate(_)),
            "{bad}: {err}"
        );
    }
}

#[test]
fn set_names_inside_lists_are_the_sets_defined_above() {
    let deck = format!(
        "{TWO_HEX}*NSET, NSET=A\n101, 102,\n*NSET, NSET=B\na, 9\n\
         *NSET, NSET=A\n2\n*ELSET, ELSET=E\nleft\n*ELSET, ELSET=E\n7\n"
    );
    let (mesh, _) = parse(&deck);
    // B took A as it was then; A collects both of its definitions.
    assert_eq!(mesh.node_set("B").unwrap(), [0, 1, 8]);
    assert_eq!(mesh.node_set("A").unwrap(), [0, 1, 11]);
    let (mesh, _) = parse_request(&deck, &request(&["e"], &[])).unwrap();
    assert_eq!(mesh.bodies, ["e"]);
    // A name used before its definition is unknown there.
    let deck = format!("{TWO_HEX}*NSET, NSET=B\nLATER\n*NSET, NSET=LATER\n101\n");
    let err = parse_err(&deck);
    assert_eq!(err.line, Some(line_of(&deck, "LATER\n")));
    assert_eq!(
        err.kind.to_string(),
        "node set LATER is not defined above this line"
    );
}

#[test]
fn undefined_ids_in_lists_are_errors_with_the_file_id() {
    let deck = format!("{TWO_HEX}*NSET, NSET=FIX\n101, 555\n");
    let err = parse_err(&deck);
    assert_eq!(err.line, Some(line_of(&deck, "101, 555")));
    assert_eq!(
        err.kind.to_string(),
        "node set FIX: node 555 is not defined in the file"
    );
    let deck = format!("{TWO_HEX}*SURFACE, NAME=S\n21, S1\n");
    let err = parse_err(&deck);
    assert!(
        err.to_string()
            .contains("surface S: element 21 is not defined"),
        "{err}"
    );
    let deck = format!("{TWO_HEX}*SURFACE, NAME=S\nNOSUCH, S1\n");
    let err = parse_err(&deck);
    assert_eq!(
        err.kind.to_string(),
        "element set NOSUCH is not defined above this line"
    );
}

#[test]
fn surfaces_give_facet_and_node_sets_and_node_surfaces_node_sets() {
    let deck = format!(
        "{TWO_HEX}*ELSET, ELSET=ALL\nLEFT, RIGHT\n\
         *SURFACE, NAME=BOTTOM, TYPE=ELEMENT\nALL, S1\n\
         *SURFACE, NAME=ENDS\n20, S6\n7, S4\n\
         *NSET, NSET=ENDS\n101\n\
         *NSET, NSET=CORNER\n2\n*SURFACE, NAME=TIP, TYPE=NODE\nCORNER, 1.0\n3\n"
    );
    let (mesh, _) = parse(&deck);
    assert_eq!(mesh.facet_set("BOTTOM").unwrap().len(), 2);
    assert!((mesh.facet_set_area("BOTTOM").unwrap() - 2.0).abs() < 1e-14);
    for f in mesh.facet_set("BOTTOM").unwrap() {
        assert_eq!(mesh.facet_normal(f).unwrap(), [0.0, 0.0, -1.0]);
    }
    assert_eq!(mesh.node_set("BOTTOM").unwrap().len(), 6);
    // x = 0 and x = 2, outward.
    let normals: Vec<[f64; 3]> = mesh
        .facet_set("ENDS")
        .unwrap()
        .iter()
        .map(|f| mesh.facet_normal(f).unwrap())
        .collect();
    assert!(normals.contains(&[-1.0, 0.0, 0.0]) && normals.contains(&[1.0, 0.0, 0.0]));
    // The *NSET of that name wins over the surface's nodes.
    assert_eq!(mesh.node_set("ENDS").unwrap(), [0]);
    let tip = mesh.node_set("TIP").unwrap();
    assert_eq!(
        tip,
        [
            node_at(&mesh, [2.0, 0.0, 1.0]),
            node_at(&mesh, [2.0, 1.0, 1.0])
        ]
    );
    assert!(mesh.facet_set("TIP").is_err());
}

#[test]
fn bodies_are_the_element_sets_the_request_names() {
    let deck = format!("{TWO_HEX}*ELSET, ELSET=ALL\nLEFT, RIGHT\n");
    // In the file's order, spelled as asked.
    let (mesh, _) = parse_request(&deck, &request(&["right", "Left"], &[])).unwrap();
    assert_eq!(mesh.bodies, ["Left", "right"]);
    assert_eq!(mesh.cell_body, [0, 1]);
    let err = parse_request(&deck, &request(&["LEFT", "ALL"], &[])).unwrap_err();
    assert_eq!(err.line, Some(line_of(&deck, "20, 101")));
    assert_eq!(
        err.kind.to_string(),
        "element 20 is in the element sets LEFT and ALL, which are both bodies; a cell belongs to one body"
    );
    let err = parse_request(&deck, &request(&["LEFT"], &[])).unwrap_err();
    assert_eq!(err.line, Some(line_of(&deck, "7, 102")));
    assert_eq!(
        err.kind.to_string(),
        "1 3D elements are in no element set that is a body (LEFT): elements 7"
    );
    let err = parse_request(&deck, &request(&["LEFT", "UPPER"], &[])).unwrap_err();
    assert_eq!(err.line, None);
    assert_eq!(
        err.kind,
        InpErrorKind::UnknownBodySet {
            name: "UPPER".into(),
            known: "LEFT, RIGHT, ALL".into()
        }
    );
    // Without names, elements under an *ELEMENT line without ELSET are EALL.
    let deck = TWO_HEX.replace(", ELSET=RIGHT", "");
    assert_eq!(parse(&deck).0.bodies, ["LEFT", "EALL"]);
}

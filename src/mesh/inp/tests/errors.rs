//! Bad input: one error naming the file, the line and the id; no panic.

use super::{line_of, parse_err, parse_request, request, ONE_TET, TWO_HEX};
use crate::mesh::inp::InpErrorKind;

/// The error of `deck`, asserted to be at the line of `needle`.
fn err_at(deck: &str, needle: &str) -> String {
    let err = parse_err(deck);
    assert_eq!(err.file, "t.inp");
    assert_eq!(err.line, Some(line_of(deck, needle)), "{err}");
    err.kind.to_string()
}

#[test]
fn bad_data_lines_name_their_line() {
    let cases = [
        (
            "101, 0, 0, 0",
            "101, 0, 0.q, 0",
            "cannot read a coordinate from `0.q`",
        ),
        (
            "101, 0, 0, 0",
            "101, 0, 0, nan",
            "cannot read a coordinate from `nan`",
        ),
        (
            "101, 0, 0, 0",
            "-101, 0, 0, 0",
            "node -101 is not a positive integer",
        ),
        (
            "101, 0, 0, 0",
            "101, 0, 0, 0, 1, 0, 0, 9",
            "a *NODE line: expected id, x, y, z, found 8 fields",
        ),
        ("9, 2, 0, 0", "101, 2, 0, 0", "node 101 is defined twice"),
        ("7, 102,", "20, 102,", "element 20 is defined twice"),
        (
            "7, 102,",
            "7, 999,",
            "element 7 refers to node 999, which no *NODE line defines",
        ),
        ("7, 102,", "7, 1O2,", "cannot read an id from `1O2`"),
        (
            "107\n",
            "107, 5\n",
            "element 7 (C3D8) has 9 nodes, C3D8 has 8",
        ),
    ];
    for (from, to, message) in cases {
        let deck = TWO_HEX.replacen(from, to, 1);
        assert_ne!(deck, TWO_HEX, "{from}");
        let kind = err_at(&deck, to);
        assert!(kind.contains(message), "{to}: {kind}");
    }
}

#[test]
fn bad_keyword_lines_name_their_line() {
    let cases = [
        ("*ELEMENT, ELSET=X\n", "*ELEMENT needs TYPE="),
        ("*NSET\n", "*NSET needs NSET="),
        (
            "*NODE, INPUT=n.txt\n",
            "*NODE: INPUT= (the data lines in another file) is not supported",
        ),
        ("*NODE, SYSTEM=C\n", "*NODE: SYSTEM=C is not supported"),
        (
            "*SURFACE, NAME=S, TYPE=SEGMENTS\n",
            "TYPE=SEGMENTS is not supported",
        ),
        ("*,\n", "bad keyword line `*,`"),
        ("*ELEMENT, =C3D8\n", "bad keyword line"),
        (
            "*PART, NAME=P\n",
            "*PART: parts, assemblies and instances are not supported",
        ),
        ("*NSET, NSET=A, INSTANCE=I\n", "*NSET: parts, assemblies"),
        ("*NGEN, NSET=A\n", "*NGEN generates or transforms nodes"),
    ];
    for (line, message) in cases {
        let deck = format!("{TWO_HEX}{line}");
        let kind = err_at(&deck, line);
        assert!(kind.contains(message), "{line}: {kind}");
    }
    let deck = format!("1, 2, 3\n{TWO_HEX}");
    assert_eq!(
        err_at(&deck, "1, 2, 3"),
        "a data line before any keyword: `1, 2, 3`"
    );
}

#[test]
fn unsupported_types_are_one_error_naming_type_file_and_line() {
    let deck =
        "*NODE\n1, 0, 0, 0\n*ELEMENT, TYPE=C3D27, ELSET=V\n1, 1, 2, 3, 4, 5, 6, 7, 8, 9, 10\n";
    let err = parse_err(deck);
    assert_eq!(
        err.to_string(),
        "t.inp, line 3: C3D27 elements are not supported: this program reads C3D4, C3D10, C3D6, C3D15, C3D8 (C3D8R, C3D8I) and C3D20 (C3D20R) cells"
    );
    for ty in ["C3D13", "c3d5", "C3D20H", "C3D10T"] {
        let deck = format!("*ELEMENT, TYPE={ty}\n");
        let kind = err_at(&deck, "*ELEMENT");
        let expected = format!("{} elements are not supported", ty.to_uppercase());
        assert!(kind.starts_with(&expected), "{kind}");
    }
    // An unread volume type is reported, not the facets before it.
    let deck = "*NODE\n1, 0, 0, 0\n*ELEMENT, TYPE=CPS6, ELSET=S\n1, 1, 1, 1, 1, 1, 1\n*ELEMENT, TYPE=C3D27, ELSET=V\n";
    assert!(err_at(deck, "*ELEMENT, TYPE=C3D27").starts_with("C3D27 elements"));
    // A second-order facet on a first-order cell's face.
    let deck = format!("{ONE_TET}*ELEMENT, TYPE=CPS6, ELSET=S\n2, 1, 2, 3, 1, 2, 3\n");
    assert_eq!(
        err_at(&deck, "2, 1, 2, 3, 1, 2, 3"),
        "CPS6 element 2 of element set S is a tri6, but the face of the tet4 cell it lies on is a tri3"
    );
    // Beams and trusses name the set they are in.
    let deck = format!("{ONE_TET}*ELEMENT, TYPE=B31, ELSET=FRAME\n2, 1, 2\n");
    assert_eq!(
        err_at(&deck, "*ELEMENT, TYPE=B31"),
        "B31 elements (beams) in element set FRAME are not supported: the mesh is volumes of C3D4, C3D10, C3D6, C3D15, C3D8 or C3D20 cells, triangles or quadrilaterals on their faces, and sets"
    );
    let deck = format!("{ONE_TET}*ELEMENT, TYPE=T3D2\n2, 1, 2\n");
    assert!(err_at(&deck, "*ELEMENT, TYPE=T3D2").contains("(trusses) in element set (none)"));
    let deck = format!("{ONE_TET}*ELEMENT, TYPE=XYZ9\n");
    assert!(err_at(&deck, "XYZ9").starts_with("element type XYZ9 is not known"));
}

#[test]
fn mixed_hex_and_tet_cells_are_one_error() {
    let deck = format!("{TWO_HEX}*ELEMENT, TYPE=C3D4, ELSET=T\n50, 101, 102, 103, 105\n");
    assert_eq!(
        err_at(&deck, "50, 101"),
        format!(
            "element 50 is a tet4 cell but element 20 (line {}) is a hex8: a mesh holds one cell type today (mesh all volumes with one type of one order)",
            line_of(&deck, "20, 101")
        )
    );
}

#[test]
fn files_without_cells_and_unknown_bodies_are_errors() {
    let err = parse_err("*NODE\n1, 0, 0, 0\n*MATERIAL, NAME=A\n");
    assert_eq!(
        err.to_string(),
        "t.inp: no 3D elements (C3D4, C3D10, C3D6, C3D15, C3D8, C3D20): the file holds no volume mesh"
    );
    let err = parse_err("");
    assert_eq!(err.kind, InpErrorKind::NoVolumeCells);
    let err = parse_request(TWO_HEX, &request(&["BLOCK"], &[])).unwrap_err();
    assert_eq!(
        err.to_string(),
        "t.inp: no element set BLOCK of 3D elements for the body BLOCK (element sets of 3D elements: LEFT, RIGHT)"
    );
}

#[test]
fn garbage_does_not_panic() {
    let inputs = [
        "\u{0}\u{1}\u{2}binary",
        "*",
        "*NODE\n,,,,\n",
        "*NODE\n1, 1e400, 0, 0\n",
        "*ELEMENT, TYPE=C3D8\n1,\n",
        "*ELEMENT, TYPE=C3D8\n18446744073709551616, 1\n",
        "*NSET, NSET=A, GENERATE\n1, 18446744073709551615, 18446744073709551615\n",
        "*SURFACE, NAME=A\n1\n",
        "*SURFACE, NAME=A\n,S1\n",
        "*ELEMENT, TYPE=C3D4\n1, 1, 1, 1, 1\n*NODE\n1, 0, 0, 0\n",
    ];
    for text in inputs {
        let result = std::panic::catch_unwind(|| parse_request(text, &request(&[], &[])));
        assert!(matches!(result, Ok(Err(_))), "{text:?}: {result:?}");
    }
}

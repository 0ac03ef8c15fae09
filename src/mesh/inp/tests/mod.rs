//! Unit tests of the `.inp` reader: the keyword format, sets, faces, bodies
//! and the errors, each on a small deck written here.

mod errors;
mod faces;
mod format;
mod sets;

use std::path::Path;

use super::{parse_inp, InpError, InpReport, InpRequest};
use crate::mesh::Mesh;

/// Two unit cubes side by side along x (ids sparse and out of order), as
/// C3D8: element 20 at x ∈ [0, 1], element 7 at x ∈ [1, 2].
pub(super) const TWO_HEX: &str = "\
*NODE, NSET=NALL
101, 0, 0, 0
102, 1, 0, 0
103, 1, 1, 0
104, 0, 1, 0
105, 0, 0, 1
106, 1, 0, 1
107, 1, 1, 1
108, 0, 1, 1
9, 2, 0, 0
8, 2, 1, 0
3, 2, 0, 1
2, 2, 1, 1
*ELEMENT, TYPE=C3D8, ELSET=LEFT
20, 101, 102, 103, 104, 105, 106, 107, 108
*ELEMENT, TYPE=C3D8, ELSET=RIGHT
7, 102, 9, 8, 103, 106, 3, 2, 107
";

/// One unit tet, nodes 1..4 at the origin and on the axes.
pub(super) const ONE_TET: &str = "\
*NODE
1, 0, 0, 0
2, 1, 0, 0
3, 0, 1, 0
4, 0, 0, 1
*ELEMENT, TYPE=C3D4, ELSET=TET
1, 1, 2, 3, 4
";

pub(super) fn parse_request(
    text: &str,
    request: &InpRequest,
) -> Result<(Mesh, InpReport), InpError> {
    parse_inp(text, Path::new("t.inp"), request)
}

/// Parsed with the bodies taken from the `*ELEMENT` lines.
pub(super) fn parse(text: &str) -> (Mesh, InpReport) {
    parse_request(text, &InpRequest::default()).unwrap_or_else(|e| panic!("{e}"))
}

pub(super) fn parse_err(text: &str) -> InpError {
    match parse_request(text, &InpRequest::default()) {
        Ok(_) => panic!("accepted:\n{text}"),
        Err(e) => e,
    }
}

pub(super) fn request(bodies: &[&str], names: &[&str]) -> InpRequest {
    InpRequest {
        bodies: bodies.iter().map(|s| s.to_string()).collect(),
        names: names.iter().map(|s| s.to_string()).collect(),
    }
}

/// 1-based line of the first occurrence of `needle`.
pub(super) fn line_of(text: &str, needle: &str) -> usize {
    let at = text
        .find(needle)
        .unwrap_or_else(|| panic!("{needle:?} not in the text"));
    text[..at].matches('\n').count() + 1
}

/// The mesh node at a position (the reader renumbers).
pub(super) fn node_at(mesh: &Mesh, x: [f64; 3]) -> usize {
    mesh.nodes
        .iter()
        .position(|p| *p == x)
        .unwrap_or_else(|| panic!("no node at {x:?}"))
}

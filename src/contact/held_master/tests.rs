use super::*;

fn unit_box(lo: [f64; 3]) -> Aabb {
    (lo, [lo[0] + 1.0, lo[1] + 1.0, lo[2] + 1.0])
}

#[test]
fn selection_keeps_the_boxes_that_meet_the_target() {
    let facets = [
        unit_box([0.0, 0.0, 0.0]),
        unit_box([2.0, 0.0, 0.0]),
        unit_box([4.0, 0.0, 0.0]),
    ];
    // Touching counts, so a facet on the box's face is sent.
    assert_eq!(
        select_in_box(&facets, unit_box([1.0, 0.5, 0.5])),
        vec![0, 1]
    );
    assert_eq!(
        select_in_box(&facets, ([3.5, -1.0, -1.0], [10.0, 0.0, 0.0])),
        vec![2]
    );
    assert!(select_in_box(&facets, unit_box([0.0, 5.0, 0.0])).is_empty());
}

#[test]
fn an_empty_box_selects_nothing() {
    let facets = [unit_box([0.0, 0.0, 0.0]), unit_box([-1e300, 0.0, 0.0])];
    assert!(select_in_box(&facets, EMPTY_BOX).is_empty());
}

#[test]
fn records_travel_unchanged() {
    let f = MasterFacet {
        set_index: 12345,
        natural: [7, 8, 9_000_000_000, 10],
        dofs: [GlobalDof(3); 4 * DIM],
        x_ref: [[0.1, -0.2, 0.3]; 4],
    };
    let mut out = Vec::new();
    encode(&f, &mut out);
    encode(&f, &mut out);
    assert_eq!(out.len(), 2 * RECORD);
    assert_eq!(decode(&out), vec![f.clone(), f]);
}

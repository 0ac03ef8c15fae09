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
    for nodes in [3, 4, 6, 8, 9] {
        let mut f = MasterFacet::empty(12345);
        for a in 0..nodes {
            f.natural[a] = 7 + 9_000_000_000 * (a as u64 % 2);
            f.x_ref[a] = [0.1 * a as f64, -0.2, 0.3];
            for c in 0..DIM {
                f.dofs[DIM * a + c] = GlobalDof((3 + a * DIM + c) as _);
            }
        }
        let mut out = Vec::new();
        encode(&f, nodes, &mut out);
        encode(&f, nodes, &mut out);
        assert_eq!(out.len(), 2 * record(nodes));
        assert_eq!(decode(&out, nodes), vec![f.clone(), f]);
    }
}

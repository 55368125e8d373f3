//! Polyomino geometry and the rep-tile rules stored in luts/.

use proptest::prelude::*;
use tessera::polyomino::{Orientation, Rule, Shape};

fn stored_rules(name: &str) -> (Shape, Vec<Rule>) {
    let path = format!("{}/luts/{name}.rules.json", env!("CARGO_MANIFEST_DIR"));
    let text = std::fs::read_to_string(&path).unwrap();
    let value: serde_json::Value = serde_json::from_str(&text).unwrap();
    let shape: Shape = serde_json::from_value(value["shape"].clone()).unwrap();
    let rules: Vec<Rule> = serde_json::from_value(value["rules"].clone()).unwrap();
    (shape, rules)
}

#[test]
fn the_stored_g_hexomino_rule_tiles_its_nine_fold_parent_cell_by_cell() {
    let (shape, rules) = stored_rules("ghexomino");
    assert_eq!(shape, Shape::g_hexomino());
    assert_eq!(rules.len(), 1);
    let rule = &rules[0];
    assert_eq!((rule.scale, rule.children.len()), (9, 81));
    // every cell of the 9x parent is covered exactly once
    let mut covered = std::collections::HashMap::new();
    for child in &rule.children {
        for cell in child.cells(&shape) {
            *covered.entry(cell).or_insert(0) += 1;
        }
    }
    let parent = shape.scaled(9);
    assert_eq!(covered.len(), parent.cells().len());
    for cell in parent.cells() {
        assert_eq!(covered.get(cell), Some(&1), "cell {cell:?}");
    }
    assert!(rule.tiles_parent(&shape));
}

#[test]
fn the_stored_p_pentomino_rules_are_the_two_the_search_finds() {
    let (shape, rules) = stored_rules("ppentomino");
    assert_eq!(shape, Shape::p_pentomino());
    assert_eq!(rules, Rule::p_pentomino_rules());
    assert_eq!(rules, tessera::lut::sphere_lut().rules);
}

#[test]
fn outlines_are_closed_unit_step_loops() {
    for shape in [
        Shape::p_pentomino(),
        Shape::g_hexomino(),
        Shape::new(vec![(0, 0)]),
    ] {
        let outline = shape.outline();
        for k in 0..outline.len() {
            let (a, b) = (outline[k], outline[(k + 1) % outline.len()]);
            assert_eq!((a.0 - b.0).abs() + (a.1 - b.1).abs(), 1);
        }
    }
}

proptest! {
    #[test]
    fn orientations_form_the_dihedral_group(a in 0usize..8, b in 0usize..8, x in -50i64..50, y in -50i64..50) {
        let (a, b) = (Orientation::from_index(a), Orientation::from_index(b));
        prop_assert_eq!(a.then(b).apply((x, y)), b.apply(a.apply((x, y))));
        prop_assert_eq!(a.inverse().apply(a.apply((x, y))), (x, y));
        // lattice cells map to lattice cells, and placements keep cell counts
        let p = tessera::polyomino::Placement::new((x, y), a);
        let cells: std::collections::HashSet<_> = p.cells(&Shape::g_hexomino()).collect();
        prop_assert_eq!(cells.len(), 6);
    }
}

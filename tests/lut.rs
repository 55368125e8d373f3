//! Table files: round trip, and clear errors for bad ones.

use tessera::lut::{sphere_lut, SphereLut, SPHERE_LUT_VERSION};

#[test]
fn the_shipped_table_round_trips() {
    let lut = sphere_lut();
    assert_eq!(SphereLut::from_bytes(&lut.to_bytes()).unwrap(), *lut);
}

#[test]
fn bad_tables_are_refused_with_a_reason() {
    let bytes = sphere_lut().to_bytes();
    let err = |b: &[u8]| SphereLut::from_bytes(b).unwrap_err().to_string();
    assert!(err(&[]).contains("version 0"));
    let mut wrong_version = bytes.clone();
    wrong_version[0] = (SPHERE_LUT_VERSION + 1) as u8;
    assert!(err(&wrong_version).contains(&format!("version {}", SPHERE_LUT_VERSION + 1)));
    assert!(err(&bytes[..bytes.len() / 2]).contains("does not decode"));
    // a table whose automaton points nowhere
    let mut broken = (*sphere_lut()).clone();
    broken.transitions[0][0] = u32::MAX;
    assert!(err(&broken.to_bytes()).contains("missing class"));
    let mut far = (*sphere_lut()).clone();
    far.tables[0][0] = [i8::MAX, 0];
    assert!(err(&far.to_bytes()).contains("outside"));
    let mut short = (*sphere_lut()).clone();
    short.fills[2].pop();
    assert!(err(&short.to_bytes()).contains("sibling-fill table 2 has the wrong size"));
    let mut far_fill = (*sphere_lut()).clone();
    far_fill.fills[1][0] = [0, i8::MIN];
    assert!(err(&far_fill.to_bytes()).contains("sibling-fill table 1 has an offset outside"));
}

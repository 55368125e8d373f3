//! Table files: round trip, and clear errors for bad ones.

use tessera::lut::{frame_sizes, sphere_lut, SphereLut, SPHERE_LUT_VERSION};

#[test]
fn the_shipped_table_round_trips() {
    let lut = sphere_lut();
    let bytes = lut.to_bytes();
    assert_eq!(SphereLut::from_bytes(&bytes).unwrap(), *lut);
    // byte for byte: the file is what `tessera lut build` writes for it
    assert!(bytes == include_bytes!("../luts/sphere.lut"));
}

#[test]
fn the_embedded_table_is_valid() {
    // `sphere_lut()` decodes its offset tables as requests reach them,
    // without the checks `from_bytes` makes
    let bytes = include_bytes!("../luts/sphere.lut");
    assert_eq!(SphereLut::from_bytes(bytes).unwrap(), *sphere_lut());
}

/// The embedded table's sample reach, kept in the code so that no request
/// decodes the whole table to measure it, is what its offsets measure.
#[test]
fn the_embedded_sample_reach_holds() {
    use std::sync::Arc;
    use tessera::tiling::sphere::SphereTiling;
    let bytes = include_bytes!("../luts/sphere.lut");
    let measured = SphereTiling::new(Arc::new(SphereLut::from_bytes(bytes).unwrap()));
    let embedded = SphereTiling::default();
    for level in 0..=12 {
        assert_eq!(
            measured.sample_reach(level),
            embedded.sample_reach(level),
            "level {level}: update EMBEDDED_REACH in src/tiling/sphere.rs"
        );
    }
}

#[test]
fn bad_files_are_refused_with_a_reason() {
    let bytes = sphere_lut().to_bytes();
    let err = |b: &[u8]| SphereLut::from_bytes(b).unwrap_err().to_string();
    assert!(err(&[]).contains("version 0"));
    let mut wrong_version = (*sphere_lut()).clone();
    wrong_version.version += 1;
    let expected = format!("version {}", SPHERE_LUT_VERSION + 1);
    assert!(err(&wrong_version.to_bytes()).contains(&expected));
    // an uncompressed table of an earlier format names its version
    assert!(err(&[5, 0, 0]).contains("version 5"));
    assert!(err(&bytes[..bytes.len() / 2]).contains("does not decompress"));
    let moves_end = bytes.len() - frame_sizes(&bytes).last().expect("frames");
    assert!(err(&bytes[..moves_end]).contains("ends before its zonal warps"));
    // a file that decodes is checked as a table in memory is (below)
    let mut broken = (*sphere_lut()).clone();
    broken.transitions[0][0] = u32::MAX;
    assert!(err(&broken.to_bytes()).contains("missing class"));
}

#[test]
fn bad_tables_are_refused_with_a_reason() {
    // what `SphereLut::from_bytes` checks once a file decodes, without
    // encoding each case (6 s each at zstd level 22)
    let err = |lut: &SphereLut| lut.validate().unwrap_err().to_string();
    assert!(sphere_lut().validate().is_ok());
    // a table whose automaton points nowhere
    let mut broken = (*sphere_lut()).clone();
    broken.transitions[0][0] = u32::MAX;
    assert!(err(&broken).contains("missing class"));
    let mut far = (*sphere_lut()).clone();
    far.tables[0][0][0] = [i8::MAX, 0];
    assert!(err(&far).contains("outside"));
    // the first level with sibling fills (those before have drop moves)
    let fills = (sphere_lut().fills.iter())
        .position(|fills| !fills.is_empty())
        .expect("the table has sibling fills");
    let mut short = (*sphere_lut()).clone();
    short.fills[fills].pop();
    let expected = format!("sibling-fill table {fills} has the wrong size");
    assert!(err(&short).contains(&expected));
    let mut far_fill = (*sphere_lut()).clone();
    far_fill.fills[fills][0] = [0, i8::MIN];
    let expected = format!("sibling-fill table {fills} has an offset outside");
    assert!(err(&far_fill).contains(&expected));
    // drop moves: a row too few, and a key past its bin
    let mut fewer = (*sphere_lut()).clone();
    let rows: Vec<Vec<(u16, [i8; 2], u8)>> = vec![Vec::new(); fewer.rows(1) - 1];
    fewer.drop_moves[1][3] = tessera::lut::DropMoves::from_rows(rows);
    assert!(err(&fewer).contains("drop-move table 1 bin 3 has the wrong size"));
    let mut past = (*sphere_lut()).clone();
    let mut rows: Vec<Vec<(u16, [i8; 2], u8)>> = vec![Vec::new(); past.rows(1)];
    rows[0].push((u16::MAX, [0, 0], 0));
    past.drop_moves[1][3] = tessera::lut::DropMoves::from_rows(rows);
    assert!(err(&past).contains("a key past its bin"));
    // ring-shared rows past the tree-indexed levels, and a table sized for
    // the wrong sharing
    let mut ring = (*sphere_lut()).clone();
    ring.ring_from = ring.exact_levels + 1;
    assert!(err(&ring).contains("ring_from"));
    let mut unshared = (*sphere_lut()).clone();
    unshared.ring_from = unshared.exact_levels;
    let level = sphere_lut().ring_from;
    assert!(err(&unshared).contains(&format!("offset table {level} has the wrong size")));
    // zonal warps: one that would swap latitudes, and a bin missing
    let mut wild = (*sphere_lut()).clone();
    wild.zonal_warps[2][5] = tessera::lut::ZonalWarp::new([0.0, 0.3, 0.0, 0.0, 0.0, 0.0]);
    assert!(err(&wild).contains("zonal warp of level 2 bin 5"));
    let mut missing = (*sphere_lut()).clone();
    missing.zonal_warps[3].pop();
    assert!(err(&missing).contains("zonal-warp table 3 has the wrong number of bins"));
}

#[test]
fn ring_shared_rows_serve_the_four_faces_of_each_ring() {
    // the quarter turn about the axis maps face f to f + 1 within its ring
    // (0-3 north, 4-7 equatorial, 8-11 south): the same place on each
    // shares one row, and the three rings' rows are disjoint
    let lut = sphere_lut();
    for level in lut.ring_from as usize..lut.exact_levels as usize {
        let per_face = 20usize << (2 * level);
        let rows = lut.tables[level][0].len();
        assert_eq!(rows, 3 * per_face);
        for place in [0, 1, per_face / 2, per_face - 1] {
            let row = |face: usize| lut.row(level, face * per_face + place);
            // `place` is root `place >> 2 level` of the face, and the path
            // `place & (4^level - 1)` below it; rows are path-major
            let (root, path) = (place >> (2 * level), place & ((1 << (2 * level)) - 1));
            for ring in 0..3 {
                let first = row(4 * ring);
                assert_eq!(first, path * 60 + ring * 20 + root);
                assert!((1..4).all(|k| row(4 * ring + k) == first));
            }
        }
    }
}

#[test]
fn every_row_of_a_per_tile_level_serves_some_tile() {
    let lut = sphere_lut();
    for level in 0..lut.exact_levels as usize {
        let mut used = vec![false; lut.rows(level)];
        for index in 0..240usize << (2 * level) {
            used[lut.row(level, index)] = true;
        }
        assert!(used.iter().all(|&u| u), "level {level} leaves a row unused");
    }
}

/// The four shipped tables stay within issue 18's 4 MB budget.
#[test]
fn the_shipped_tables_fit_in_4_mb() {
    let sizes = [
        include_bytes!("../luts/sphere.lut").len(),
        include_bytes!("../luts/penrose.lut").len(),
        include_bytes!("../luts/ghexomino.lut").len(),
        include_bytes!("../luts/ppentomino.lut").len(),
    ];
    let total: usize = sizes.iter().sum();
    assert!(total < 4_000_000, "{sizes:?}: {total} bytes");
}

/// The last per-tile level's offsets, fills and drop moves lie on the
/// build's coarser grid (`BuildOptions::deep_tile_step`, 4), the level
/// above on one half as coarse, which is what keeps the sphere table
/// within the budget.
#[test]
fn the_last_per_tile_levels_lie_on_coarser_grids() {
    let lut = sphere_lut();
    let on = |step: i8| move |pairs: &[[i8; 2]]| pairs.iter().flatten().all(|v| v % step == 0);
    let last = lut.exact_levels as usize - 1;
    for (level, step) in [(last, 4), (last - 1, 2)] {
        for (bin, table) in lut.tables[level].iter().enumerate() {
            assert!(on(step)(table), "level {level} bin {bin}");
        }
        // the level's fills (if it has them) and drop moves
        let fills = lut.fills.get(level).map_or(&[][..], |f| &f[..]);
        assert!(on(step)(fills), "fills of level {level}");
        for (bin, moves) in lut.drop_moves.get(level).into_iter().flatten().enumerate() {
            let offsets: Vec<[i8; 2]> = moves.iter().map(|(_, _, offset)| offset).collect();
            assert!(on(step)(&offsets), "drop moves of level {level} bin {bin}");
        }
        // and the level above is finer
        assert!(!on(step)(&lut.tables[level - 1][0]), "level {}", level - 1);
    }
}

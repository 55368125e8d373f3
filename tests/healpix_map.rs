//! HEALPix maps as densities (`tessera::density::healpix`), their indexing
//! (`tessera::healpix::{ring_cell, nested_index}`) and FITS files
//! (`tessera::io::fits`): pixels agree with `cdshealpix`, tile bounds never
//! fall below the value anywhere in the tile (plain, rotated, bare caps),
//! counts per pixel follow the map in RING and NESTED order, and the
//! command line reads the files the tests write.

mod common;

use cdshealpix::nested;
use common::fits::{card, healpix_cards, partial_sky, table_bytes, text, write_map, Column};
use glam::DVec3;
use proptest::prelude::*;
use std::f64::consts::TAU;
use tessera::baselines::SplitMix64;
use tessera::density::healpix::{HealpixMap, INVERSE_LIPSCHITZ, INVERSE_LIPSCHITZ_EQUATORIAL};
use tessera::density::sphere::{angle_between, Rotated};
use tessera::density::Density;
use tessera::healpix::{cell_of, nested_index, ring_cell, FacePoint, Scheme, UNSEEN};
use tessera::io::fits::read_healpix;
use tessera::request::{SphereDensity, SphereRequest};
use tessera::tiling::sphere::{SphereRegion, SphereTiling};
use tessera::tiling::TileSystem;

fn lon_lat(v: DVec3) -> (f64, f64) {
    let v = v.normalize();
    (v.y.atan2(v.x).rem_euclid(TAU), v.z.clamp(-1.0, 1.0).asin())
}

/// A uniformly random unit vector.
fn random_direction(rng: &mut SplitMix64) -> DVec3 {
    let z = 2.0 * rng.next_f64() - 1.0;
    let phi = TAU * rng.next_f64();
    let s = ((1.0 - z) * (1.0 + z)).sqrt();
    DVec3::new(s * phi.cos(), s * phi.sin(), z)
}

/// The pixel index of a direction in a map of `scheme` order at
/// `nside = 2^depth`, by cdshealpix (independent of tessera's lookup).
fn cds_pixel(v: DVec3, depth: u8, scheme: Scheme) -> usize {
    let (lon, lat) = lon_lat(v);
    match scheme {
        Scheme::Nested => nested::hash(depth, lon, lat) as usize,
        Scheme::Ring => cdshealpix::ring::hash(1 << depth, lon, lat) as usize,
    }
}

#[test]
fn ring_and_nested_indices_agree_with_cdshealpix() {
    for depth in 0..=6u8 {
        let layer = nested::get(depth);
        for h in 0..12u64 << (2 * depth) {
            let ring = layer.to_ring(h);
            assert_eq!(
                nested_index(ring_cell(ring, depth as u32), depth as u32),
                h,
                "depth {depth}, ring {ring}"
            );
        }
    }
    let mut rng = SplitMix64::new(4);
    for depth in [10u8, 13, 20, 29] {
        let layer = nested::get(depth);
        for _ in 0..20_000 {
            let h = (rng.next_f64() * (12u64 << (2 * depth)) as f64) as u64;
            let ring = layer.to_ring(h);
            assert_eq!(nested_index(ring_cell(ring, depth as u32), depth as u32), h);
        }
    }
}

#[test]
fn pixel_lookup_agrees_with_cdshealpix() {
    let mut rng = SplitMix64::new(5);
    for depth in [0u8, 3, 8, 13, 20] {
        for _ in 0..50_000 {
            let v = random_direction(&mut rng);
            let ours = nested_index(cell_of(FacePoint::from_vec(v), depth as u32), depth as u32);
            assert_eq!(ours as usize, cds_pixel(v, depth, Scheme::Nested), "{v}");
        }
    }
}

#[test]
fn face_steps_are_within_the_inverse_lipschitz_constant() {
    // pairs of nearby points on one face, everywhere (poles and three-face
    // corners included): face distance / geodesic distance
    let mut rng = SplitMix64::new(6);
    let (mut worst, mut equatorial): (f64, f64) = (0.0, 0.0);
    for k in 0..400_000 {
        let face = (k % 12) as u8;
        // a third of the points within 1e-3 of one of the four corners
        let near = |t: f64| if k % 3 == 0 { t * 1e-3 } else { t };
        let (x, y) = (near(rng.next_f64()), near(rng.next_f64()));
        let (x, y) = match k % 4 {
            0 => (x, y),
            1 => (1.0 - x, y),
            2 => (x, 1.0 - y),
            _ => (1.0 - x, 1.0 - y),
        };
        let a = rng.next_f64() * TAU;
        let step = 1e-4 * (0.5 + rng.next_f64());
        let (x2, y2) = (x + step * a.cos(), y + step * a.sin());
        if !(0.0..=1.0).contains(&x2) || !(0.0..=1.0).contains(&y2) {
            continue;
        }
        let p = FacePoint::new(face, x, y).to_vec();
        let q = FacePoint::new(face, x2, y2).to_vec();
        let ratio = step / angle_between(p, q);
        worst = worst.max(ratio);
        if (4..8).contains(&face) {
            equatorial = equatorial.max(ratio);
        }
    }
    println!("equatorial faces: {equatorial:.4} (bound {INVERSE_LIPSCHITZ_EQUATORIAL})");
    assert!(
        equatorial <= INVERSE_LIPSCHITZ_EQUATORIAL && equatorial > 1.18,
        "{equatorial}"
    );
    println!("largest face step per radian: {worst:.4} (bound {INVERSE_LIPSCHITZ:.4})");
    assert!(worst <= INVERSE_LIPSCHITZ, "{worst} > {INVERSE_LIPSCHITZ}");
    // the supremum, 1.5242, is at the poles along the face edges
    assert!(worst > 1.52, "the constant is far too loose: {worst}");
}

/// A map at `depth` with a few hot pixels among dim and zero ones.
fn spiky_map(depth: u32, seed: u64, scheme: Scheme) -> HealpixMap {
    let mut rng = SplitMix64::new(seed);
    let values = (0..12usize << (2 * depth))
        .map(|_| match rng.next_f64() {
            u if u < 0.02 => 1000.0 * rng.next_f64(),
            u if u < 0.3 => 0.0,
            _ => rng.next_f64(),
        })
        .collect::<Vec<_>>();
    let mut values = values;
    values[0] = 1.0; // never all zero
    HealpixMap::new("spiky", values, scheme, false).unwrap()
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(48))]

    #[test]
    fn bounds_cover_every_value_in_the_tile(
        depth in 0u32..7,
        seed in any::<u64>(),
        nested in any::<bool>(),
    ) {
        let scheme = if nested { Scheme::Nested } else { Scheme::Ring };
        let map = spiky_map(depth, seed, scheme);
        let rotated = Rotated::new(&map, seed ^ 0x5eed);
        let tiling = SphereTiling::default();
        let shape = tiling.shape().clone();
        let mut rng = SplitMix64::new(seed);
        for _ in 0..60 {
            let level = (rng.next_f64() * 7.0) as u32;
            let code = (rng.next_f64() * tiling.capacity(level)) as u128;
            let tile = tiling.tile_with_code(level, code).unwrap();
            let region = tiling.region(&tile);
            let (bound, turned) = (map.bound(&region), rotated.bound(&region));
            for _ in 0..12 {
                let (cx, cy) = shape.cells()[(rng.next_f64() * 5.0) as usize];
                let local = [cx as f64 + rng.next_f64(), cy as f64 + rng.next_f64()];
                let p = tiling.face_point(&tile, local).to_vec();
                prop_assert!(bound >= map.value(p), "level {level}, code {code}, {p}");
                prop_assert!(turned >= rotated.value(p), "rotated: level {level}, code {code}");
            }
        }
        // bare caps of every size, points anywhere inside them
        for _ in 0..400 {
            let centre = random_direction(&mut rng);
            let radius = 10f64.powf(-6.0 + 6.2 * rng.next_f64());
            let c = FacePoint::from_vec(centre);
            let cap = SphereRegion { centroid: c, radius, face: c.face, cells: [[c.x, c.y]; 5], spill: 0.0, warp: 0.0, stretch: tessera::tiling::sphere::FACE_LIPSCHITZ };
            let bound = map.bound(&cap);
            for _ in 0..24 {
                // a point at angle <= radius from the centre (often near the rim)
                let towards = random_direction(&mut rng).cross(centre).normalize();
                let angle = radius * rng.next_f64().sqrt().max(0.999 * f64::from(rng.next_f64() < 0.5));
                let p = centre * angle.cos() + towards * angle.sin();
                prop_assert!(angle_between(p, centre) <= radius * (1.0 + 1e-9));
                prop_assert!(bound >= map.value(p), "cap {centre} radius {radius}, {p}");
            }
        }
    }
}

/// `n` samples of `map` (in the world frame, with a seed).
fn sample(map: &HealpixMap, n: usize, seed: Option<u64>) -> Vec<DVec3> {
    let request = SphereRequest {
        count: n,
        seed,
        ..Default::default()
    };
    request
        .points(&SphereDensity::Healpix(map.clone()))
        .unwrap()
}

#[test]
fn counts_per_pixel_follow_a_coarse_map() {
    // nside 8, 768 pixels of values from 0.5 to 2, about 200 samples each
    let mut rng = SplitMix64::new(7);
    let values: Vec<f64> = (0..768).map(|_| 0.5 + 1.5 * rng.next_f64()).collect();
    let total: f64 = values.iter().sum();
    let n = 153_600;
    for scheme in [Scheme::Ring, Scheme::Nested] {
        let map = HealpixMap::new("nside 8", values.clone(), scheme, false).unwrap();
        for seed in [None, Some(11)] {
            let mut counts = vec![0usize; 768];
            for p in sample(&map, n, seed) {
                counts[cds_pixel(p, 3, scheme)] += 1;
            }
            let mut worst: f64 = 0.0;
            for (k, &count) in counts.iter().enumerate() {
                let expected = n as f64 * values[k] / total;
                let z = (count as f64 - expected) / expected.sqrt();
                assert!(
                    z.abs() <= 4.0,
                    "{scheme:?}, seed {seed:?}: pixel {k} has {count}, expected {expected:.1}"
                );
                worst = worst.max(z.abs());
            }
            println!("{scheme:?}, seed {seed:?}: largest |count - expected| / sqrt(expected) over 768 pixels: {worst:.3}");
        }
    }
}

#[test]
fn a_hot_pixel_gets_its_share() {
    // one pixel 1000 times its 767 neighbours: 1000 / 1767 of the samples
    let mut values = vec![1.0; 768];
    values[300] = 1000.0;
    let share = 1000.0 / 1767.0;
    let n = 20_000;
    for scheme in [Scheme::Ring, Scheme::Nested] {
        let map = HealpixMap::new("hot", values.clone(), scheme, false).unwrap();
        for seed in [None, Some(3)] {
            let hits = sample(&map, n, seed)
                .into_iter()
                .filter(|&p| cds_pixel(p, 3, scheme) == 300)
                .count();
            let got = hits as f64 / n as f64;
            println!("{scheme:?}, seed {seed:?}: hot pixel share {got:.4} (expected {share:.4}, {:+.2} %)", 100.0 * (got / share - 1.0));
            assert!(
                (got / share - 1.0).abs() < 0.1,
                "{scheme:?}: {got} against {share}"
            );
        }
    }
}

#[test]
fn pdf_is_value_over_four_pi_mean() {
    let map = spiky_map(4, 9, Scheme::Ring);
    let mut rng = SplitMix64::new(10);
    let mean = map.mean();
    for _ in 0..1000 {
        let v = random_direction(&mut rng);
        let expected = map.value(v) / (4.0 * std::f64::consts::PI * mean);
        assert_eq!(map.pdf(v * 3.0), expected);
    }
    // the request's pdf is the map's, seeded or not
    let density = SphereDensity::Healpix(map.clone());
    let pdf = density.pdf();
    for p in sample(&map, 500, Some(2)) {
        assert_eq!(pdf(p), map.pdf(p));
        assert!(pdf(p) > 0.0, "a sample where the map is 0");
    }
}

#[test]
fn bad_inputs_are_clear_errors() {
    let message = |values: Vec<f64>, strict: bool| {
        HealpixMap::new("input", values, Scheme::Ring, strict)
            .err()
            .map(|e| e.to_string())
            .unwrap_or_default()
    };
    assert!(message(vec![1.0; 100], false).contains("100 values"));
    assert!(message(vec![1.0; 12 * 9], false).contains("12 nside^2")); // nside 3
    assert!(message(vec![], false).contains("0 values"));
    assert!(message(vec![0.0; 48], false).contains("nothing to sample"));
    assert!(message(vec![UNSEEN; 48], false).contains("nothing to sample"));
    let mut v = vec![1.0; 48];
    v[7] = f64::INFINITY;
    assert!(message(v.clone(), true).contains("pixel 7 (RING order) is inf"));
    v[7] = -3.0;
    assert!(message(v.clone(), true).starts_with("input: pixel 7"));
    let map = HealpixMap::new("input", v, Scheme::Ring, false).unwrap();
    assert_eq!((map.bad_pixels(), map.unseen_pixels()), (1, 0));
}

fn temp_dir(name: &str) -> std::path::PathBuf {
    let dir = std::env::temp_dir().join(format!("tessera-healpix-{name}-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

#[test]
fn fits_files_read_back_as_written() {
    let dir = temp_dir("read");
    let mut rng = SplitMix64::new(12);
    // nside 16 in rows of 1024 float32, RING, galactic
    let values: Vec<f64> = (0..3072).map(|_| (rng.next_f64() as f32) as f64).collect();
    let path = dir.join("ring16.fits");
    write_map(&path, &values, "RING", Some("G"));
    let read = read_healpix(&path, 0).unwrap();
    assert_eq!(read.values, values);
    assert_eq!((read.scheme, read.nside), (Scheme::Ring, 16));
    assert_eq!((read.coordsys.as_deref(), read.listed), (Some("G"), None));
    assert_eq!(read.column, "TEMPERATURE");
    // nside 8, one double a row, NESTED, three columns: field picks one
    let i: Vec<f64> = (0..768).map(|k| k as f64).collect();
    let q: Vec<f64> = (0..768).map(|k| 0.5 * k as f64).collect();
    let columns = [
        Column {
            name: "I",
            kind: 'D',
            repeat: 1,
            values: &i,
        },
        Column {
            name: "Q",
            kind: 'D',
            repeat: 1,
            values: &q,
        },
        Column {
            name: "N_OBS",
            kind: 'J',
            repeat: 1,
            values: &i,
        },
    ];
    let path = dir.join("nest8.fits");
    std::fs::write(
        &path,
        table_bytes(&columns, &healpix_cards("NESTED", 8, None)),
    )
    .unwrap();
    let read = read_healpix(&path, 1).unwrap();
    assert_eq!(
        (read.values, read.scheme, read.column.as_str()),
        (q, Scheme::Nested, "Q")
    );
    assert_eq!(read_healpix(&path, 2).unwrap().values, i);
    let err = read_healpix(&path, 3).unwrap_err().to_string();
    assert!(
        err.contains("field 3: the table has 3 map column(s) (I, Q, N_OBS)"),
        "{err}"
    );
    // a partial sky: PIXEL then SIGNAL, the rest UNSEEN
    let columns = partial_sky(&[3.0, 40.0, 767.0], &[1.0, 2.0, 3.0]);
    let mut cards = healpix_cards("RING", 8, Some("C"));
    cards.retain(|c| !c.starts_with("INDXSCHM") && !c.starts_with("OBJECT"));
    cards.push(card("INDXSCHM", &text("EXPLICIT")));
    cards.push(card("OBJECT", &text("PARTIAL")));
    let path = dir.join("partial.fits");
    std::fs::write(&path, table_bytes(&columns, &cards)).unwrap();
    let read = read_healpix(&path, 0).unwrap();
    assert_eq!(read.listed, Some(3));
    assert_eq!((read.values[40], read.values[41]), (2.0, UNSEEN));
    let map = HealpixMap::open(&path, 0, true).unwrap();
    assert_eq!((map.unseen_pixels(), map.coordsys()), (765, Some("C")));
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn broken_fits_files_are_clear_errors() {
    let dir = temp_dir("broken");
    let values = vec![1.0; 768];
    let column = || Column {
        name: "T",
        kind: 'E',
        repeat: 1,
        values: &values,
    };
    let cases: Vec<(&str, Vec<String>, &str)> = vec![
        (
            "no-ordering",
            healpix_cards("RING", 8, None)
                .into_iter()
                .filter(|c| !c.starts_with("ORDERING"))
                .collect(),
            "no ORDERING keyword",
        ),
        (
            "no-nside",
            healpix_cards("RING", 8, None)
                .into_iter()
                .filter(|c| !c.starts_with("NSIDE"))
                .collect(),
            "no NSIDE keyword",
        ),
        (
            "nside-6",
            [healpix_cards("RING", 8, None), vec![card("NSIDE", "6")]].concat(),
            "NSIDE = 6: not a power of two",
        ),
        (
            "nside-16",
            [healpix_cards("RING", 8, None), vec![card("NSIDE", "16")]].concat(),
            "holds 768 values, but NSIDE 16 needs 12 NSIDE^2 = 3072",
        ),
        (
            "zigzag",
            [
                healpix_cards("RING", 8, None),
                vec![card("ORDERING", &text("ZIGZAG"))],
            ]
            .concat(),
            "ordering 'ZIGZAG'",
        ),
        (
            "not-healpix",
            [
                healpix_cards("RING", 8, None),
                vec![card("PIXTYPE", &text("TAN"))],
            ]
            .concat(),
            "not a HEALPix map",
        ),
    ];
    for (name, cards, expected) in cases {
        let path = dir.join(format!("{name}.fits"));
        // later cards repeat a keyword: the last one wins
        std::fs::write(&path, table_bytes(&[column()], &cards)).unwrap();
        let err = read_healpix(&path, 0).unwrap_err().to_string();
        assert!(
            err.contains(expected) && err.contains(&format!("{name}.fits")),
            "{name}: {err}"
        );
    }
    // truncated data, garbage, an empty file, a partial sky listing a pixel too far
    let good = table_bytes(&[column()], &healpix_cards("RING", 8, None));
    let path = dir.join("truncated.fits");
    std::fs::write(&path, &good[..good.len() - 2880]).unwrap();
    assert!(read_healpix(&path, 0)
        .unwrap_err()
        .to_string()
        .contains("truncated"));
    for bytes in [
        &b""[..],
        &b"SIMPLE  =                    T"[..],
        &[0xffu8; 6000][..],
    ] {
        std::fs::write(&path, bytes).unwrap();
        assert!(read_healpix(&path, 0).is_err());
    }
    let columns = partial_sky(&[3.0, 768.0], &[1.0, 2.0]);
    let cards = [
        healpix_cards("RING", 8, None),
        vec![card("INDXSCHM", &text("EXPLICIT"))],
    ]
    .concat();
    std::fs::write(&path, table_bytes(&columns, &cards)).unwrap();
    let err = read_healpix(&path, 0).unwrap_err().to_string();
    assert!(
        err.contains("pixel 768 (row 2) is not a pixel of an NSIDE 8 map"),
        "{err}"
    );
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn the_command_line_samples_a_fits_map() {
    let dir = temp_dir("cli");
    let mut values = vec![1.0; 768];
    values[300] = 1000.0;
    values[5] = UNSEEN;
    values[6] = -1.0;
    let path = dir.join("hot.fits");
    write_map(&path, &values, "NESTED", Some("G"));
    let file = path.to_str().unwrap();
    let out = common::tessera(&[
        "sphere",
        "-n",
        "2000",
        "--healpix-map",
        file,
        "--format",
        "csv",
        "--seed",
        "4",
    ]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(
        stderr.contains("1 UNSEEN pixel(s) (no data) treated as 0"),
        "{stderr}"
    );
    assert!(
        stderr
            .contains("1 negative, NaN or infinite pixel(s) treated as 0 (--strict refuses them)"),
        "{stderr}"
    );
    // the same points as the library's request
    let (map, _) = tessera::request::open_healpix(&path, 0, false).unwrap();
    let expected = SphereRequest {
        count: 2000,
        seed: Some(4),
        ..Default::default()
    }
    .points(&SphereDensity::Healpix(map.clone()))
    .unwrap();
    let rows = common::csv_rows(&out.stdout);
    assert_eq!(rows.len(), 2000);
    for (row, p) in rows.iter().zip(&expected) {
        assert_eq!(DVec3::new(row[0], row[1], row[2]), *p);
        assert_eq!(row[5], map.pdf(*p));
    }
    // --strict refuses the negative pixel, --field a missing column
    let out = common::tessera(&["sphere", "-n", "10", "--healpix-map", file, "--strict"]);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(
        !out.status.success() && stderr.contains("pixel 6 (NESTED order) is -1"),
        "{stderr}"
    );
    let out = common::tessera(&["sphere", "-n", "10", "--healpix-map", file, "--field", "1"]);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(
        !out.status.success()
            && stderr.contains("field 1: the table has 1 map column(s) (TEMPERATURE)"),
        "{stderr}"
    );
    let out = common::tessera(&["sphere", "-n", "10", "--strict"]);
    assert!(!out.status.success());
    std::fs::remove_dir_all(&dir).unwrap();
}

//! Hard cases: tiny and huge counts and densities, deep levels, poles.

use glam::DVec3;
use std::collections::HashSet;
use tessera::density::sphere::{Cap, SphereFn};
use tessera::density::Uniform;
use tessera::healpix::FacePoint;
use tessera::tiling::sphere::{SphereTiling, MAX_LEVEL};
use tessera::tiling::TileSystem;
use tessera::{engine, Sampler};

fn assert_clean(points: &[DVec3]) {
    let mut seen = HashSet::new();
    for p in points {
        assert!(p.is_finite() && (p.length() - 1.0).abs() < 1e-12, "{p}");
        assert!(
            seen.insert(p.to_array().map(f64::to_bits)),
            "duplicate point {p}"
        );
    }
}

#[test]
fn tiny_counts() {
    let cap = Cap::new(0.0, 90.0, 1.0, 1e6).unwrap();
    for n in [0usize, 1, 2] {
        let uniform = Sampler::sphere().count(n).generate().unwrap();
        let capped = Sampler::sphere().density(cap).count(n).generate().unwrap();
        assert_eq!((uniform.len(), capped.len()), (n, n));
        assert_clean(&capped.iter().map(|s| s.position).collect::<Vec<_>>());
    }
}

#[test]
fn densities_at_the_ends_of_the_f64_range() {
    for scale in [1e-300, 1e-310, 1e300, f64::MIN_POSITIVE] {
        let d = SphereFn::new(move |v: DVec3| scale * (1.5 + v.z), scale).unwrap();
        let s = Sampler::sphere().density(d).count(2000).generate().unwrap();
        assert_eq!(s.len(), 2000, "scale {scale}");
        let north = s.iter().filter(|s| s.position.z > 0.0).count() as f64 / 2000.0;
        // mass north of the equator: (1.5 + 1/2) / 3 = 2/3
        assert!((north - 2.0 / 3.0).abs() < 0.03, "scale {scale}: {north}");
    }
    for contrast in [1e-300, 1e300] {
        let cap = Cap::new(10.0, -20.0, 30.0, contrast).unwrap();
        let s = Sampler::sphere()
            .density(cap)
            .count(1000)
            .generate()
            .unwrap();
        assert_eq!(s.len(), 1000);
        let inside = s.iter().filter(|s| cap.contains(s.position)).count() as f64 / 1000.0;
        // about 100 of the 1000 samples sit in tiles on the rim, which are
        // kept by their average: allow a rim term of 4 %
        assert!(
            (inside - cap.mass_fraction()).abs() < 0.04,
            "{contrast}: {inside}"
        );
    }
}

#[test]
fn zero_density_over_most_of_the_sphere() {
    // a 2-degree cap around the south pole, 1e12 times brighter than the
    // rest: the rest holds about 0.1 % of the mass
    let cap = Cap::new(0.0, -90.0, 2.0, 1e12).unwrap();
    let s = Sampler::sphere()
        .density(cap)
        .count(500)
        .generate()
        .unwrap();
    assert_clean(&s.iter().map(|s| s.position).collect::<Vec<_>>());
    // a tile straddling the rim is kept by its average, and its point may sit
    // just outside: every point is within about one sample spacing (0.16
    // degrees here) of the lit cap
    let near = Cap::new(0.0, -90.0, 2.3, 1.0).unwrap();
    assert!(s.iter().all(|s| near.contains(s.position)));
}

#[test]
fn a_bright_cap_at_the_pole_gets_thousands_of_distinct_points() {
    let cap = Cap::new(0.0, 90.0, 1e-3, 1e10).unwrap();
    let s = Sampler::sphere()
        .density(cap)
        .count(20_000)
        .generate()
        .unwrap();
    let inside: Vec<DVec3> = s
        .iter()
        .map(|s| s.position)
        .filter(|&p| cap.contains(p))
        .collect();
    let expected = cap.mass_fraction() * 20_000.0;
    assert!(expected > 1000.0 && (inside.len() as f64 - expected).abs() < 0.05 * expected);
    assert_clean(&inside);
}

#[test]
fn deepest_level_points_stay_in_their_tiles() {
    let tiling = SphereTiling::default();
    let level = MAX_LEVEL;
    let nside = SphereTiling::nside(level) as f64;
    let capacity = tiling.capacity(level) as u64;
    let mut points = Vec::new();
    // codes spread over the whole range: every face, poles and seams included
    for k in 0..2000u64 {
        let code = k.wrapping_mul(0x9E37_79B9_7F4A_7C15) % capacity;
        let tile = tiling.tile_with_code(level, code).unwrap();
        assert_eq!(tile.code, code);
        let p = tiling.sample(&tile, 1.0);
        let fp = FacePoint::from_vec(p);
        let cell = ((fp.x * nside).floor() as i32, (fp.y * nside).floor() as i32);
        let cells: Vec<(i32, i32)> = tile.placement.cells(tiling.shape()).collect();
        assert_eq!(fp.face, tile.face, "code {code}");
        assert!(
            cells.contains(&cell),
            "code {code}: {cell:?} not in {cells:?}"
        );
        points.push(p);
    }
    assert_clean(&points);
    assert!(tiling.tile_with_code(level + 1, 0).is_none());
    assert!(tiling.tile_with_code(level, capacity).is_none());
}

#[test]
fn streams_are_identical_to_generated_sets() {
    let tiling = SphereTiling::default();
    let n = 5000;
    let a: Vec<_> = engine::stream(&tiling, n).unwrap().collect();
    let b = engine::generate(&tiling, &Uniform, n, true).unwrap();
    assert_eq!(a, b);
}

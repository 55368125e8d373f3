//! Baselines: Sobol nets, inverse-CDF warps, Bridson, i.i.d. and jittered sets.

use glam::DVec2;
use proptest::prelude::*;
use tessera::baselines::cdf::RasterCdf;
use tessera::baselines::envmap::InverseCdf;
use tessera::baselines::sobol::{owen_sobol_2d, sphere};
use tessera::baselines::{bridson, jittered_healpix, uniform_random_2d};
use tessera::density::envmap::{EnvMap, Up};
use tessera::density::plane::Raster;

/// Every elementary interval of area 2^-m holds exactly one of 2^m points.
fn is_net(points: &[DVec2], m: u32) -> bool {
    (0..=m).all(|a| {
        let (nx, ny) = (1usize << a, 1usize << (m - a));
        let mut hits = vec![0u32; nx * ny];
        for p in points {
            hits[(p.y * ny as f64) as usize * nx + (p.x * nx as f64) as usize] += 1;
        }
        hits.iter().all(|&h| h == 1)
    })
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(16))]
    #[test]
    fn owen_sobol_prefixes_are_nets(seed in any::<u64>(), m in 0u32..11) {
        let p = owen_sobol_2d(1 << m, seed);
        prop_assert!(is_net(&p, m));
    }
}

#[test]
fn iid_points_are_not_nets_and_seeds_differ() {
    assert!(!is_net(&uniform_random_2d(256, 1), 8));
    assert_ne!(owen_sobol_2d(8, 1), owen_sobol_2d(8, 2));
}

#[test]
fn sobol_on_the_sphere_is_stratified_in_z() {
    let p = sphere(1024, 5);
    // 2^10 points: each of 32 equal-area z bands holds exactly 32
    let mut bands = [0; 32];
    for v in &p {
        bands[(((1.0 - v.z) / 2.0 * 32.0) as usize).min(31)] += 1;
    }
    assert!(bands.iter().all(|&b| b == 32), "{bands:?}");
}

#[test]
fn raster_warp_follows_the_pixel_weights() {
    // weights 1, 3 (top row) and 0, 4 (bottom row) out of 8
    let raster = Raster::new(2, 2, vec![1.0, 3.0, 0.0, 4.0], false).unwrap();
    let cdf = RasterCdf::new(&raster).unwrap();
    let p: Vec<DVec2> = owen_sobol_2d(1 << 12, 3)
        .into_iter()
        .map(|u| cdf.warp(u))
        .collect();
    let count = |x0: f64, y0: f64| {
        p.iter()
            .filter(|q| (q.x >= x0 && q.x < x0 + 0.5) && (q.y >= y0 && q.y < y0 + 0.5))
            .count() as f64
            / p.len() as f64
    };
    approx::assert_abs_diff_eq!(count(0.0, 0.0), 1.0 / 8.0, epsilon = 1e-3);
    approx::assert_abs_diff_eq!(count(0.5, 0.0), 3.0 / 8.0, epsilon = 1e-3);
    assert_eq!(count(0.0, 0.5), 0.0);
    approx::assert_abs_diff_eq!(count(0.5, 0.5), 4.0 / 8.0, epsilon = 1e-3);
    assert!(RasterCdf::new(&raster).is_ok());
}

#[test]
fn envmap_warp_lands_on_lit_pixels_in_proportion() {
    let values = vec![0.0, 1.0, 2.0, 0.0, 0.0, 0.0, 0.0, 1.0];
    let raster = tessera::io::image::Raster {
        width: 4,
        height: 2,
        values,
        bad_pixels: 0,
    };
    let map = EnvMap::new(raster, Up::Z).unwrap();
    let cdf = InverseCdf::new(&map);
    let dirs: Vec<_> = owen_sobol_2d(4096, 1)
        .iter()
        .map(|u| cdf.warp([u.x, u.y]))
        .collect();
    assert!(dirs.iter().all(|d| map.pdf(*d) > 0.0));
    // the two upper lit pixels hold 3/4 of the mass (equal solid angles)
    let upper = dirs.iter().filter(|d| d.z > 0.0).count() as f64 / 4096.0;
    approx::assert_abs_diff_eq!(upper, 0.75, epsilon = 1e-3);
}

#[test]
fn bridson_keeps_its_radius_and_jittered_healpix_its_cells() {
    let p = bridson(2000, 4);
    let r = (0.7f64 / 2000.0).sqrt();
    let tree: Vec<_> = p.iter().collect();
    for (i, a) in tree.iter().enumerate().step_by(37) {
        assert!(tree
            .iter()
            .enumerate()
            .all(|(j, b)| i == j || (**a - **b).length() >= r * (1.0 - 1e-9)));
    }
    let h = jittered_healpix(4, 1);
    assert_eq!(h.len(), 192);
    // one point per cell: HEALPix nested index at nside 4 is a permutation
    let mut cells: Vec<u64> = h.iter().map(|v| cell_nside4(*v)).collect();
    cells.sort_unstable();
    cells.dedup();
    assert_eq!(cells.len(), 192);
}

fn cell_nside4(v: glam::DVec3) -> u64 {
    let (lon, lat) = (v.y.atan2(v.x), v.z.asin());
    cdshealpix::nested::hash(2, lon.rem_euclid(std::f64::consts::TAU), lat)
}

/// Weighted sample elimination keeps the spacing its paper reports
/// (separation about 2.4, covering about 4) and is reproducible.
#[test]
fn weighted_sample_elimination_spreads_points() {
    use tessera::baselines::elimination::weighted_sample_elimination;
    use tessera::metrics::sphere::{covering_radius, separation};
    let points = weighted_sample_elimination(3000, 7);
    assert_eq!(points.len(), 3000);
    assert!(points.iter().all(|p| (p.length() - 1.0).abs() < 1e-12));
    let (s, c) = (separation(&points), covering_radius(&points));
    assert!(s > 2.3 && c < 4.8, "separation {s}, covering {c}");
    assert_eq!(points, weighted_sample_elimination(3000, 7));
    assert!(weighted_sample_elimination(0, 7).is_empty());
}

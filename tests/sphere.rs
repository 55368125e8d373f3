//! The sphere tile system and sampler: geometry, codes, counts, determinism.

mod common;
use approx::assert_relative_eq;
use glam::DVec3;
use proptest::prelude::*;
use std::collections::HashSet;
use std::f64::consts::PI;
use tessera::density::sphere::{angle_between, Cap, SphereFn};
use tessera::density::Uniform;
use tessera::engine::Order;
use tessera::healpix::FacePoint;
use tessera::polyomino::{Rule, Shape};
use tessera::tiling::sphere::{SphereTiling, FACE_LIPSCHITZ};
use tessera::tiling::TileSystem;
use tessera::{engine, Sampler};

/// The positions of a uniform request of `n` samples.
fn uniform_points(n: usize) -> Vec<DVec3> {
    let samples = Sampler::sphere().count(n).generate().unwrap();
    samples.iter().map(|s| s.position).collect()
}

#[test]
fn the_p_pentomino_has_exactly_two_dissections_and_both_tile_the_parent() {
    let rules = Rule::p_pentomino_rules();
    assert_eq!(rules.len(), 2);
    for rule in &rules {
        assert!(rule.tiles_parent(&Shape::p_pentomino()));
    }
    // the shipped table uses exactly these rules
    assert_eq!(SphereTiling::default().lut().rules, rules);
}

#[test]
fn every_level_partitions_the_healpix_cells_into_pentominoes() {
    let tiling = SphereTiling::default();
    for level in 0..=3u32 {
        let tiles = tiling.tiles(level);
        assert_eq!(tiles.len(), 240 << (2 * level));
        let nside = SphereTiling::nside(level);
        let mut cells = HashSet::new();
        for t in &tiles {
            for (i, j) in t.placement.cells(tiling.shape()) {
                assert!(
                    (0..nside).contains(&i) && (0..nside).contains(&j),
                    "cell off its face"
                );
                assert!(cells.insert((t.face, i, j)), "two tiles share a cell");
            }
        }
        assert_eq!(cells.len(), 12 * (nside * nside) as usize);
        // equal-area cells: the tiles' areas add up to the sphere's
        let cell_area = 4.0 * PI / (12.0 * (nside as f64).powi(2));
        let total: f64 = tiles.iter().map(|_| 5.0 * cell_area).sum();
        assert_relative_eq!(total, 4.0 * PI, max_relative = 1e-12);
    }
}

#[test]
fn codes_of_a_level_are_a_permutation() {
    let tiling = SphereTiling::default();
    for level in 0..=3u32 {
        let mut codes: Vec<u128> = tiling.tiles(level).iter().map(|t| t.code).collect();
        codes.sort_unstable();
        assert!(
            codes.iter().enumerate().all(|(i, &c)| c == i as u128),
            "level {level}"
        );
    }
}

#[test]
fn bounding_caps_contain_their_tiles() {
    let tiling = SphereTiling::default();
    let shape = Shape::p_pentomino();
    let mut worst: f64 = 0.0;
    for level in [0u32, 1, 3] {
        for (n, t) in tiling.tiles(level).iter().enumerate() {
            if level == 3 && n % 7 != 0 {
                continue;
            }
            let region = tiling.region(t);
            for &(cx, cy) in shape.cells() {
                for a in 0..=4 {
                    for b in 0..=4 {
                        let local = [cx as f64 + a as f64 / 4.0, cy as f64 + b as f64 / 4.0];
                        let fp = tiling.face_point(t, local);
                        let p = fp.to_vec();
                        let d = angle_between(p, region.center());
                        let c = region.centroid;
                        let on_face = (fp.x - c.x).hypot(fp.y - c.y);
                        worst = worst.max(d / (FACE_LIPSCHITZ * on_face));
                        assert!(d <= region.radius, "tile point outside its cap");
                    }
                }
            }
        }
    }
    // the Lipschitz constant is not wildly loose either
    assert!(worst > 0.9 && worst <= 1.0, "worst ratio {worst}");
}

/// Every sample a tile's bound covers lands inside its region: its own,
/// at every bin and between bins (where drop moves and sibling fills carry
/// points past the tile), and its children's. A sample outside would land
/// where a density may exceed the bound it was thinned against, which
/// biases the set (DESIGN, "The terminal rule").
#[test]
fn regions_hold_every_sample_they_bound() {
    use tessera::density::healpix::{INVERSE_LIPSCHITZ, INVERSE_LIPSCHITZ_EQUATORIAL};
    let tiling = SphereTiling::default();
    let lut = tiling.lut();
    // every bin's fraction, and 24 counts between each two (the drop moves
    // a request reads depend on how many codes it keeps)
    let mut fractions = vec![0.01, 0.1, 0.2];
    let mut lower = 0.25;
    for &upper in &lut.bin_fractions {
        fractions.extend((1..=24).map(|k| lower + (upper - lower) * k as f64 / 24.0));
        lower = upper;
    }
    let mut farthest_past = 0.0f64;
    for level in 0..=8u32 {
        let capacity = 240u128 << (2 * level);
        // about 600 tiles a level, spread over its codes
        let stride = (capacity / 600).max(1) | 1;
        for code in (0..capacity).step_by(stride as usize) {
            let tile = tiling.tile_with_code(level, code).unwrap();
            let region = tiling.region(&tile);
            let side = region.cell_side();
            let children = (0..4).map(|i| tiling.child(&tile, i));
            for t in std::iter::once(tile).chain(children) {
                for &f in &fractions {
                    let s = tiling.sample(&t, f);
                    let at = format!("level {level} code {code} fraction {f}");
                    let d = angle_between(s, region.center());
                    assert!(
                        d <= region.radius * (1.0 + 1e-12),
                        "{at}: {d} past the cap {}",
                        region.radius
                    );
                    let nearest = (region.probes().iter())
                        .map(|&p| angle_between(p, s))
                        .fold(f64::INFINITY, f64::min);
                    assert!(
                        nearest <= region.cell_reach() * (1.0 + 1e-12),
                        "{at}: {nearest} from the probes"
                    );
                    let fp = FacePoint::from_vec(s);
                    if fp.face == region.face {
                        let past = (region.cells.iter())
                            .map(|c| {
                                ((fp.x - c[0]).abs().max((fp.y - c[1]).abs()) - side / 2.0).max(0.0)
                            })
                            .fold(f64::INFINITY, f64::min);
                        // face units per radian, as `HealpixMap` widens its box
                        let inverse = match (4..8).contains(&region.face) {
                            true => INVERSE_LIPSCHITZ_EQUATORIAL,
                            false => INVERSE_LIPSCHITZ,
                        };
                        let spill = region.spill + inverse * region.warp;
                        assert!(
                            past <= spill + 1e-12,
                            "{at}: {past} past the cells, spill {spill}"
                        );
                        farthest_past = farthest_past.max(past / side);
                    }
                }
            }
        }
    }
    // the moves carry some samples well past the tile's cells
    assert!(farthest_past > 1.0, "farthest {farthest_past} cells past");
}

#[test]
fn full_levels_put_one_point_in_each_pentomino() {
    let tiling = SphereTiling::default();
    for level in 0..=3u32 {
        let n = 240usize << (2 * level);
        let samples = engine::generate(&tiling, &Uniform, n, true).unwrap();
        assert_eq!(samples.len(), n);
        let nside = SphereTiling::nside(level);
        let mut per_face = [0usize; 12];
        let mut cells = HashSet::new();
        for s in &samples {
            let fp = FacePoint::from_vec(s.position);
            per_face[fp.face as usize] += 1;
            let cell = (
                fp.face,
                ((fp.x * nside as f64) as i64).min(nside - 1),
                ((fp.y * nside as f64) as i64).min(nside - 1),
            );
            assert!(
                cells.insert(cell),
                "two points in one HEALPix cell at level {level}"
            );
        }
        assert!(per_face.iter().all(|&c| c == n / 12), "{per_face:?}");
        // each point inside its own tile
        for t in tiling.tiles(level) {
            let offset = tiling.offset(&t, 1.0);
            assert!(tiling.shape().contains(offset));
        }
    }
}

#[test]
fn output_is_deterministic_and_independent_of_threads() {
    let cap = Cap::new(30.0, 10.0, 25.0, 40.0).unwrap();
    let run = |threads: usize| {
        common::on_threads(threads, || {
            Sampler::sphere()
                .density(cap)
                .count(5000)
                .generate()
                .unwrap()
        })
    };
    let one = run(1);
    assert_eq!(one, run(2));
    assert_eq!(one, run(1));
}

#[test]
fn every_prefix_is_a_progressive_subset() {
    let samples = Sampler::sphere().count(3072).generate().unwrap();
    let nearest = |pts: &[DVec3]| {
        let mut best = f64::INFINITY;
        for (i, a) in pts.iter().enumerate() {
            for b in &pts[i + 1..] {
                best = best.min(angle_between(*a, *b));
            }
        }
        best * (pts.len() as f64).sqrt()
    };
    let points: Vec<DVec3> = samples.iter().map(|s| s.position).collect();
    let full = nearest(&points);
    // stated bound: every prefix keeps at least 0.4x the full set's
    // normalised separation (jittered HEALPix reaches < 0.5 absolute)
    for prefix in [50, 100, 200, 500, 1000, 1500, 2000, 2500] {
        let sep = nearest(&points[..prefix]);
        assert!(sep > 0.4 * full, "prefix {prefix}: {sep} vs {full}");
    }
}

#[test]
fn farthest_first_prefixes_meet_issue_18s_floors() {
    // issue 18: the first N/4 and N/16 of N = 3072, 20,000 and 200,000 keep
    // separation >= 2.0 and covering <= 3.6 as sets of their own length
    use tessera::metrics::sphere::{covering_radius, separation};
    for n in [3072, 20_000, 200_000] {
        let request = Sampler::sphere().count(n);
        let spread = request
            .clone()
            .order(Order::FarthestFirst)
            .generate()
            .unwrap();
        let points: Vec<DVec3> = spread.iter().map(|s| s.position).collect();
        for length in [n / 4, n / 16] {
            let prefix = &points[..length];
            let (sep, cov) = (separation(prefix), covering_radius(prefix));
            assert!(
                sep >= 2.0 && cov <= 3.6,
                "N = {n}, first {length}: {sep:.3} / {cov:.3}"
            );
        }
        // the same samples as the progressive order
        let key = |p: DVec3| p.to_array().map(f64::to_bits);
        let mut ours: Vec<_> = points.iter().map(|&p| key(p)).collect();
        let mut progressive: Vec<_> = uniform_points(n).into_iter().map(key).collect();
        ours.sort_unstable();
        progressive.sort_unstable();
        assert!(
            ours == progressive,
            "N = {n}: not the progressive order's samples"
        );
    }
}

#[test]
fn farthest_first_prefixes_of_an_adaptive_set_follow_the_density() {
    // in local spacings: every prefix holds about the cap's share of the set
    let cap = Cap::new(30.0, 20.0, 25.0, 16.0).unwrap();
    let spread = (Sampler::sphere().density(cap).count(20_000))
        .order(Order::FarthestFirst)
        .generate()
        .unwrap();
    let share = |prefix: &[tessera::Sample<DVec3>]| {
        prefix.iter().filter(|s| cap.contains(s.position)).count() as f64 / prefix.len() as f64
    };
    let whole = share(&spread);
    assert!(
        (whole - cap.mass_fraction()).abs() < 0.02 * whole,
        "{whole}"
    );
    // (prefixes of a fixed set: where the set is more regular its samples
    // come out later, 4-8 % off at 10,000 and 15,000)
    for length in [1000, 5000, 10_000, 15_000] {
        let part = share(&spread[..length]);
        eprintln!("first {length}: {part:.4} inside the cap (the set: {whole:.4})");
        assert!(
            (part - whole).abs() < 0.1 * whole,
            "first {length}: {part} vs {whole}"
        );
    }
}

#[test]
fn cap_with_contrast_100_gets_its_share_within_two_percent() {
    for (lon, lat) in [(0.0, 90.0), (45.0, 0.0), (-120.0, -41.8)] {
        let cap = Cap::new(lon, lat, 15.0, 100.0).unwrap();
        let n = 20000;
        let samples = Sampler::sphere().density(cap).count(n).generate().unwrap();
        assert_eq!(samples.len(), n);
        let inside = samples.iter().filter(|s| cap.contains(s.position)).count() as f64 / n as f64;
        let expected = cap.mass_fraction();
        assert!(
            (inside - expected).abs() <= 0.02 * expected,
            "cap at ({lon},{lat}): {inside} vs {expected}"
        );
    }
}

#[test]
fn small_bright_caps_are_never_skipped() {
    // a cap far smaller than a root tile, 1e6 times brighter
    let cap = Cap::new(10.0, 20.0, 0.05, 1e6).unwrap();
    let samples = Sampler::sphere()
        .density(cap)
        .count(2000)
        .generate()
        .unwrap();
    let inside = samples.iter().filter(|s| cap.contains(s.position)).count() as f64;
    let expected = cap.mass_fraction() * 2000.0;
    assert!(expected > 100.0);
    assert!(
        (inside - expected).abs() < 0.05 * expected + 3.0,
        "{inside} vs {expected}"
    );
}

#[test]
fn common_counts_use_a_bin_optimised_for_exactly_their_density() {
    // powers of two, HEALPix pixel counts 12 * 4^k and 3 * 2^k: the uniform
    // request keeps codes 0..N of the first level holding N, and the table
    // has a bin for exactly that fraction, so the set has no holes
    let tiling = SphereTiling::default();
    let lut = tiling.lut();
    let families = (4..=24)
        .map(|k| 1u64 << k)
        .chain((2..=12).map(|k| 12 << (2 * k)))
        .chain((5..=24).map(|k| 3 << k));
    for n in families {
        let level = (0..).find(|&l| tiling.capacity(l) >= n as f64).unwrap();
        let fraction = n as f64 / tiling.capacity(level);
        if fraction <= 0.25 {
            continue; // the level below is full: no holes either
        }
        let bin = lut.bin(fraction, tiling.capacity(level));
        assert_relative_eq!(lut.bin_fractions[bin], fraction, max_relative = 1e-12);
    }
}

#[test]
fn every_bins_own_count_gets_the_set_it_was_relaxed_on() {
    // the optimiser relaxed bin b on the codes below `f_b * capacity`; most
    // bins' fractions are not multiples of 1 / capacity, so that count lies
    // a sliver above f_b and must still use bin b (it used b + 1, leaving
    // one hole and a covering of 3.5-3.8 at half the bins)
    use tessera::metrics::sphere::covering_radius;
    let tiling = SphereTiling::default();
    let capacity = tiling.capacity(2);
    for &edge in &tiling.lut().bin_fractions[1..] {
        let n = (edge * capacity).ceil() as usize;
        let points = uniform_points(n);
        let covering = covering_radius(&points);
        assert!(
            covering <= 3.0,
            "N = {n} (bin {edge:.4}): covering {covering:.2}"
        );
    }
}

#[test]
fn drop_moves_close_the_holes_between_bins_without_crowding() {
    // between two bins a request keeps a prefix of the upper bin's set;
    // the kept points beside each code it drops take the places the
    // builder relaxed them to, dropping the bin's codes from the top.
    // Without any (the same counts): covering mean 3.95 and worst 5.17,
    // mesh ratio worst 3.81; with the siblings of each dropped code alone
    // moving (sibling fills, solved in the order requests read them): mean
    // 3.39, worst 4.62, mesh ratio 3.32, separation at least 2.51. Drop
    // moves: 2.95, 3.23, 2.41, 2.47
    use tessera::metrics::sphere::{covering_radius, separation};
    let (mut coverings, mut worst_mesh) = (Vec::new(), 0.0f64);
    for n in (965..3840).step_by(97) {
        let points = uniform_points(n);
        let (covering, spacing) = (covering_radius(&points), separation(&points));
        assert!(spacing >= 2.45, "N = {n}: separation {spacing:.3}");
        coverings.push(covering);
        worst_mesh = worst_mesh.max(2.0 * covering / spacing);
    }
    let mean = coverings.iter().sum::<f64>() / coverings.len() as f64;
    let worst = coverings.iter().cloned().fold(0.0, f64::max);
    println!("covering mean {mean:.3}, worst {worst:.3}; mesh ratio worst {worst_mesh:.3}");
    assert!(
        mean <= 3.1 && worst <= 3.4,
        "covering mean {mean:.3}, worst {worst:.3}"
    );
    assert!(worst_mesh <= 2.8, "mesh ratio worst {worst_mesh:.3}");
}

#[test]
fn levels_with_drop_moves_meet_issue_18s_floors_at_the_sweeps_counts() {
    // docs/SPHERE_SWEEP.md's counts between bins up to level 6's
    // capacity: with sibling fills, covering <= 3.4 held at 17 of the 43
    // up to level 4 and mesh ratio <= 2.8 at 38 (worst 4.64 and 3.32, N =
    // 1661, a pole's hole), at 1 of level 5's 10 (worst 4.64 and 3.49, N =
    // 112,421), and at none of level 6's 9 (worst 4.15 and 3.12, N =
    // 458,160); with drop moves (level 6's where the fills leave a hole)
    // at all
    use tessera::metrics::sphere::{covering_radius, separation};
    let counts = [
        100, 117, 137, 160, 187, 218, 255, 298, 349, 408, 476, 557, 651, 761, 890, 1040, 1215,
        1421, 1661, 1941, 2270, 2653, 3101, 3625, 4238, 4954, 5790, 6769, 7912, 9249, 10_812,
        12_638, 14_774, 15_400, 17_270, 20_188, 23_598, 27_585, 32_246, 37_694, 44_062, 51_507,
        60_209, 61_500, 70_381, 82_272, 96_172, 112_421, 131_415, 153_617, 179_571, 209_910,
        245_375, 246_000, 286_832, 335_292, 391_941, 458_160, 535_567, 626_052, 731_824, 855_467,
    ];
    for n in counts {
        let points = uniform_points(n);
        let (covering, spacing) = (covering_radius(&points), separation(&points));
        let mesh = 2.0 * covering / spacing;
        assert!(
            spacing >= 2.4 && covering <= 3.4 && mesh <= 2.8,
            "N = {n}: separation {spacing:.3}, covering {covering:.3}, mesh ratio {mesh:.3}"
        );
    }
}

#[test]
fn a_pole_keeps_no_hole_where_its_ring_orbit_is_dropped() {
    // the four tiles next to a pole, one ring orbit with consecutive codes,
    // drop together: their siblings' fills, relaxed with the other three
    // in place, moved little, and the pole's hole set the covering: 4.08
    // (N = 476), 4.49 (6769), 3.88 (14,774); relaxed with the whole orbit
    // missing 3.49, 3.67, 3.53. Drop moves close it with the neighbours of
    // every dropped twin
    use tessera::metrics::sphere::{covering_radius, separation};
    for n in [476, 491, 725, 1661, 6769, 14_774] {
        let points = uniform_points(n);
        let (covering, spacing) = (covering_radius(&points), separation(&points));
        assert!(covering <= 3.4, "N = {n}: covering {covering:.3}");
        assert!(spacing >= 2.45, "N = {n}: separation {spacing:.3}");
    }
}

#[test]
fn per_tile_levels_keep_issue_18s_separation_floor_at_and_between_bins() {
    // the separation steps after Lloyd pushed apart the close pairs Lloyd
    // left (a level-4 bin read 1.85, and N = 17,270 between bins 1.73);
    // level 5, per tile since format 5, read 1.62-2.28 with classes, and
    // level 6, per tile since format 6, 1.98-2.25; rows past a face edge
    // never moved in the separation steps (level-6 bins 2.42, N = 491,520
    // 2.35 and 600,000 2.38) until the builder's seam fix
    use tessera::metrics::sphere::separation;
    let tiling = SphereTiling::default();
    let mut counts: Vec<usize> = (3..7)
        .flat_map(|level| {
            let capacity = tiling.capacity(level);
            let edges = tiling.lut().bin_fractions.clone();
            edges
                .into_iter()
                .map(move |f| (f * capacity).ceil() as usize)
        })
        .collect();
    // between bins, from docs/SPHERE_SWEEP.md
    counts.extend([17_270, 20_188, 27_585, 37_694, 44_062, 51_507, 60_209]);
    counts.extend([61_500, 70_381, 82_272, 112_421, 131_415, 179_571, 245_375]);
    counts.extend([
        246_000, 286_832, 335_292, 391_941, 458_160, 535_567, 626_052,
    ]);
    counts.extend([491_520, 500_000, 600_000, 731_824, 855_467]);
    for n in counts {
        let spacing = separation(&uniform_points(n));
        assert!(spacing >= 2.4, "N = {n}: separation {spacing:.3}");
    }
}

#[test]
fn classes_met_only_below_the_enumerated_levels_keep_their_points_apart() {
    // such a class borrowed the offset of a class fitted around other
    // neighbours: at N = 2·10^6 (level 7) two of its points came within
    // 0.74 / sqrt(N) of each other across a face edge, and 0.98 at 3·10^6.
    // With the class table's separation steps on level 6 (per tile since
    // format 6) rather than level 7, the first it serves, 10^6 read 1.65
    // and 2·10^6 1.16 (the polar cap)
    use tessera::metrics::sphere::separation;
    for n in [1_000_000, 2_000_000, 3_000_000] {
        let spacing = separation(&uniform_points(n));
        assert!(spacing >= 1.9, "N = {n}: separation {spacing:.3}");
    }
}

#[test]
fn classes_first_met_on_level_8_are_separated_there() {
    // 469 enumerated classes (relaxed on levels 4-5 only) first appear on
    // level 8, yet only the 349 closure classes had separation steps there:
    // one of them met a level-7 class at 1.19 / sqrt(N), N = 5·10^6, and
    // 4.5·10^6 read 1.13. With steps for all 818: 1.61 and 1.52
    use tessera::metrics::sphere::separation;
    for n in [4_500_000, 5_000_000] {
        let spacing = separation(&uniform_points(n));
        assert!(spacing >= 1.45, "N = {n}: separation {spacing:.3}");
    }
}

/// `sqrt(4 pi N pdf)` times each sample's angle to its nearest neighbour:
/// the nearest-neighbour distance in local spacings.
fn local_spacings<D>(sampler: &Sampler<SphereTiling, D>, n: usize) -> Vec<f64>
where
    D: tessera::density::Density<tessera::tiling::sphere::SphereRegion>,
{
    use tessera::metrics::sphere::nearest_angles;
    let samples = sampler.generate().unwrap();
    let points: Vec<DVec3> = samples.iter().map(|s| s.position).collect();
    let pdfs = sampler.pdfs(&samples);
    nearest_angles(&points)
        .iter()
        .zip(pdfs)
        .map(|(angle, pdf)| angle * (4.0 * PI * n as f64 * pdf).sqrt())
        .collect()
}

/// A density whose bound falls below it where samples land is refused,
/// not sampled with a bias: a von Mises-Fisher lobe of `kappa` 200 given
/// a Lipschitz constant of 1 (its steepest slope is about 8.6), in a
/// progressive request, an unsorted one and one computed in batches
/// (over 2^22). With its true constant the same requests succeed.
#[test]
fn a_density_above_its_bound_is_an_error() {
    let kappa = 200.0;
    let lobe = move |v: DVec3| (kappa * (v.z - 1.0)).exp();
    let steepest = (kappa / std::f64::consts::E).sqrt();
    for (lipschitz, fails) in [(1.0, true), (steepest * 1.01, false)] {
        for (n, order) in [
            (20_000, Order::Progressive),
            (20_000, Order::Unsorted),
            ((1 << 22) + 1, Order::Progressive),
        ] {
            let density = SphereFn::new(lobe, lipschitz).unwrap();
            let result = Sampler::sphere()
                .density(density)
                .count(n)
                .order(order)
                .generate();
            match (fails, result) {
                (true, Err(e)) => {
                    let why = e.to_string();
                    assert!(
                        why.contains("times its bound") && why.contains("Lipschitz"),
                        "{why}"
                    );
                }
                (false, Ok(samples)) => assert_eq!(samples.len(), n),
                (fails, result) => panic!(
                    "Lipschitz {lipschitz}, N = {n}, {order:?}: expected failure {fails}, got {:?}",
                    result.map(|s| s.len())
                ),
            }
        }
    }
}

#[test]
fn smooth_densities_past_the_per_tile_levels_keep_their_points_apart() {
    // under a smooth density neighbouring tiles take neighbouring bins of
    // the class table (levels 7 and deeper); relaxed one bin at a time,
    // their points met at 0.93 and 0.98 / sqrt(N pdf) under 2^(4 z) at
    // N = 300,000 and 10^6 (8 points under 1.0 each), and 0.86 under
    // 2^(8 z) at 10^6 (200), where a uniform request past level 6 keeps
    // 1.8 or more; with its bins coupled, 1.06, 1.21 and 1.14
    use std::f64::consts::LN_2;
    for (k, n) in [(4.0, 300_000), (4.0, 1_000_000), (8.0, 1_000_000)] {
        // |grad 2^(k z)| = k ln 2 2^(k z) sin(theta) <= k ln 2 2^k
        let lipschitz = k * LN_2 * 2f64.powf(k);
        let density = SphereFn::new(move |v: DVec3| (k * LN_2 * v.z).exp(), lipschitz).unwrap();
        let sampler = Sampler::sphere().density(density).count(n);
        let spacings = local_spacings(&sampler, n);
        let closest = spacings.iter().copied().fold(f64::INFINITY, f64::min);
        assert!(closest >= 1.0, "2^({k} z), N = {n}: closest {closest:.3}");
    }
}

#[test]
fn ring_shared_levels_leave_no_hole_at_the_common_counts() {
    // levels 4-6 share rows between a ring's four faces; a common
    // fraction's set (powers of two, 3 * 2^k, HEALPix's 12 * 4^k) must be
    // the same on each face, or the shared offsets leave holes (N = 49,152
    // read covering 3.56 while root ranks split the ring orbits); since
    // the bins are coupled (so that adaptive sets do not crowd where the
    // bin changes) these counts read 2.91-3.23, 2.83-3.06 before
    use tessera::metrics::sphere::covering_radius;
    for n in [
        16_384, 24_576, 32_768, 49_152, 65_536, 98_304, 131_072, 196_608, 262_144, 393_216,
        524_288, 786_432,
    ] {
        let covering = covering_radius(&uniform_points(n));
        assert!(covering <= 3.3, "N = {n}: covering {covering:.3}");
    }
}

#[test]
fn uniform_sets_meet_the_quality_floors_against_fibonacci() {
    // the floors of the flagship issue, measured on the shipped table
    for n in [3072, 12288] {
        let points = uniform_points(n);
        let ours = tessera::metrics::sphere_report(&points);
        let fibonacci =
            tessera::metrics::sphere_report(&tessera::baselines::spherical_fibonacci(n));
        use tessera::metrics::SphereMeasure::*;
        assert!(ours[Separation] >= 2.6, "N = {n}: {ours:?}");
        assert!(ours[Energy] <= -1.08, "N = {n}: {ours:?}");
        let ratio = ours[CapDiscrepancy] / fibonacci[CapDiscrepancy];
        assert!(
            ratio <= 1.3,
            "N = {n}: cap discrepancy {ratio:.3}x Fibonacci's"
        );
    }
}

#[test]
fn cap_discrepancy_meets_issue_18s_floor_where_farthest_point_root_ranks_failed() {
    // the sweep's counts under 10^4 that read 1.31-1.88 times Fibonacci's
    // with the roots in farthest-point order (their kept tiles' zonal
    // moments; DESIGN.md, root ranks)
    use tessera::metrics::sphere::cap_discrepancy_l2;
    for n in [160, 187, 218, 349, 890, 1421, 1661, 2270, 3101] {
        let ours = cap_discrepancy_l2(&uniform_points(n));
        let ratio = ours / cap_discrepancy_l2(&tessera::baselines::spherical_fibonacci(n));
        assert!(
            ratio <= 1.3,
            "N = {n}: cap discrepancy {ratio:.3}x Fibonacci's"
        );
    }
}

/// Between bins a set's density drifts between latitudes by a few points
/// (the same sibling ranks in every root), and each bin's zonal warp
/// evens it out: at the sweep's counts on levels 4 and 5 that read 1.35
/// and 1.33 times Fibonacci's cap discrepancy without the warps, the
/// floor holds, and the warps take off more than 0.03 of the ratio.
#[test]
fn zonal_warps_bring_the_cap_discrepancy_between_bins_under_issue_18s_floor() {
    use std::sync::Arc;
    use tessera::lut::{sphere_lut, SphereLut};
    use tessera::metrics::sphere::cap_discrepancy_l2;
    let unwarped = SphereTiling::new(Arc::new(SphereLut {
        zonal_warps: Vec::new(),
        ..(*sphere_lut()).clone()
    }));
    for n in [20_188, 82_272] {
        let fibonacci = cap_discrepancy_l2(&tessera::baselines::spherical_fibonacci(n));
        let ratio = cap_discrepancy_l2(&uniform_points(n)) / fibonacci;
        let plain: Vec<DVec3> = (engine::generate(&unwarped, &Uniform, n, true).unwrap())
            .iter()
            .map(|s| s.position)
            .collect();
        let before = cap_discrepancy_l2(&plain) / fibonacci;
        assert!(
            ratio <= 1.3 && ratio < before - 0.03,
            "N = {n}: cap discrepancy {ratio:.3}x Fibonacci's, {before:.3}x without the warps"
        );
    }
}

/// Levels 4 and 5's drop moves reach 2.0 spacings about a hole (1.5 on
/// the others): at their sweep counts between bins the normalised energy
/// meets issue 18's floor, where a reach of 1.5 read -1.0826 at N =
/// 20,188, -1.0845 at 51,507 and -1.0837 at 82,272.
#[test]
fn wider_drop_moves_meet_issue_18s_energy_floor_between_bins() {
    use tessera::metrics::sphere::riesz1_normalized;
    for n in [20_188, 23_598, 37_694, 51_507, 82_272] {
        let energy = riesz1_normalized(&uniform_points(n));
        assert!(energy <= -1.085, "N = {n}: energy {energy:.4}");
    }
}

#[test]
fn counts_are_exact_for_awkward_n() {
    for n in [0usize, 1, 2, 3, 239, 241, 1001, 4097] {
        assert_eq!(Sampler::sphere().count(n).generate().unwrap().len(), n);
    }
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 64, ..ProptestConfig::default() })]
    /// A von Mises-Fisher lobe's bounds hold over every point of a tile
    /// (`|grad f| <= kappa` and `|grad f| / f <= kappa`), the relative one
    /// never looser than the additive one.
    #[test]
    fn relative_lipschitz_bounds_hold_over_their_tiles(
        kappa in 0.0f64..200.0,
        axis in (-1.0f64..1.0, 0.0f64..std::f64::consts::TAU),
        level in 0u32..6,
        pick in 0usize..usize::MAX,
    ) {
        use tessera::density::Density;
        let (z, phi) = axis;
        let r = (1.0 - z * z).sqrt();
        let mu = DVec3::new(r * phi.cos(), r * phi.sin(), z);
        let lobe = move |v: DVec3| (kappa * (v.dot(mu) - 1.0)).exp();
        // |grad f| = kappa sin(angle) f <= kappa
        let plain = SphereFn::new(lobe, kappa).unwrap();
        let relative = SphereFn::new(lobe, kappa)
            .unwrap()
            .with_relative_lipschitz(kappa)
            .unwrap();
        let tiling = SphereTiling::default();
        let tile = tiling
            .tile_with_code(level, (pick % (240 << (2 * level))) as u128)
            .unwrap();
        let region = tiling.region(&tile);
        let (bound, additive) = (relative.bound(&region), plain.bound(&region));
        prop_assert!(bound <= additive);
        for &(cx, cy) in tiling.shape().cells() {
            for (a, b) in [(0.0, 0.0), (1.0, 0.0), (0.0, 1.0), (1.0, 1.0), (0.5, 0.5)] {
                let p = tiling.face_point(&tile, [cx as f64 + a, cy as f64 + b]).to_vec();
                prop_assert!(lobe(p) <= bound * (1.0 + 1e-12), "f {} > bound {}", lobe(p), bound);
                prop_assert!(lobe(p) <= additive * (1.0 + 1e-12));
            }
        }
    }
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 256, ..ProptestConfig::default() })]
    /// Deep tiles' caps, which follow the face's local stretch, hold their
    /// samples and their children's with no tolerance, at levels 9-36
    /// (down to 3e-12 rad across), past `regions_hold_every_sample_they_bound`'s
    /// levels.
    #[test]
    fn deep_caps_hold_their_samples_to_the_last_bit(
        level in 9u32..=36,
        pick in 0u128..u128::MAX,
        fraction in 0.01f64..1.0,
    ) {
        let tiling = SphereTiling::default();
        let tile = tiling.tile_with_code(level, pick % (240u128 << (2 * level))).unwrap();
        let region = tiling.region(&tile);
        for t in std::iter::once(tile).chain((0..4).map(|i| tiling.child(&tile, i))) {
            let s = tiling.sample(&t, fraction);
            let d = angle_between(s, region.center());
            prop_assert!(d <= region.radius, "level {level}: {d} past the cap {}", region.radius);
        }
    }
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 64, ..ProptestConfig::default() })]
    /// `Density::bounds`, which the engine calls where it needs a tile's
    /// bound and its placing bound together, gives exactly the two bounds
    /// apart, for every density that computes them in one pass.
    #[test]
    fn joint_bounds_are_the_bounds_apart(
        level in 0u32..9,
        pick in 0usize..usize::MAX,
        seed in 0u64..1000,
    ) {
        use tessera::density::envmap::{EnvMap, Up};
        use tessera::density::region::Regions;
        use tessera::density::sphere::Rotated;
        use tessera::density::Density;
        use tessera::io::image::Raster;
        use tessera::tiling::sphere::SphereRegion;
        fn check(d: &dyn Density<SphereRegion>, region: &SphereRegion, inner: &SphereRegion) {
            assert_eq!(d.bounds(region, inner), (d.bound(region), d.bound(inner)));
        }
        let tiling = SphereTiling::default();
        let tile = tiling
            .tile_with_code(level, (pick % (240 << (2 * level))) as u128)
            .unwrap();
        let region = tiling.region(&tile);
        let inner = tiling.placing_region(&tile, &region).unwrap();
        // a map with a bright spot and texture, plain and turned
        let (width, height) = (96, 48);
        let values = (0..width * height)
            .map(|k| {
                let (i, j) = (k % width, k / width);
                1.0 + ((i * 7 + j * 13) % 5) as f64 + if (i, j) == (30, 9) { 1e4 } else { 0.0 }
            })
            .collect();
        let raster = Raster { width, height, values, bad_pixels: 0 };
        let map = EnvMap::new(raster, Up::Z).unwrap();
        check(&map, &region, &inner);
        check(&map.with_seed(seed), &region, &inner);
        check(&EnvMap::new(Raster { width: 1, height: 1, values: vec![2.0], bad_pixels: 0 }, Up::Y).unwrap(), &region, &inner);
        let lobe = |v: DVec3| (40.0 * (v.z - 1.0)).exp();
        let plain = SphereFn::new(lobe, 40.0).unwrap();
        check(&plain, &region, &inner);
        let relative = SphereFn::new(lobe, 40.0).unwrap().with_relative_lipschitz(40.0).unwrap();
        check(&relative, &region, &inner);
        check(&Rotated::new(SphereFn::new(lobe, 40.0).unwrap(), seed), &region, &inner);
        let regions = Regions::parse(&["cap:20,40,25,16", "polygon:-10 35,40 30,55 55,20 72,-15 62;4"]).unwrap();
        check(&regions, &region, &inner);
        check(&Rotated::new(regions, seed), &region, &inner);
        let cap = Cap::new(20.0, 40.0, 25.0, 16.0).unwrap();
        check(&cap, &region, &inner);
        check(&Rotated::new(cap, seed), &region, &inner);
    }
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 24, ..ProptestConfig::default() })]
    #[test]
    fn random_caps_follow_their_density(
        lon in -180.0f64..180.0,
        lat in -90.0f64..90.0,
        radius in 5.0f64..60.0,
        contrast in 0.0f64..50.0,
        n in 500usize..3000,
    ) {
        let cap = Cap::new(lon, lat, radius, contrast).unwrap();
        let samples = Sampler::sphere().density(cap).count(n).generate().unwrap();
        prop_assert_eq!(samples.len(), n);
        for s in &samples {
            prop_assert!(s.position.is_finite());
            prop_assert!((s.position.length() - 1.0).abs() < 1e-12);
        }
        let inside = samples.iter().filter(|s| cap.contains(s.position)).count() as f64;
        let expected = cap.mass_fraction() * n as f64;
        // blue-noise sets beat Poisson counting noise; the cap's rim is
        // resolved to about one tile, so allow a rim term too
        let rim_tiles = 2.0 * PI * radius.to_radians().sin() / (4.0 * PI / n as f64).sqrt();
        prop_assert!((inside - expected).abs() <= 4.0 * expected.sqrt() + 0.5 * rim_tiles + 2.0,
            "inside {} expected {}", inside, expected);
    }
}

#[test]
fn uniform_fast_path_streaming_and_recursion_agree() {
    let tiling = SphereTiling::default();
    for n in [1usize, 240, 1000, 3072] {
        let fast = engine::generate(&tiling, &Uniform, n, true).unwrap();
        let streamed: Vec<_> = engine::stream(&tiling, n).unwrap().collect();
        assert_eq!(fast, streamed);
        // the general recursion, ranked by sorting, finds the same set in the same order
        let mut recursed = engine::collect(&tiling, &Uniform, n as f64).unwrap();
        recursed.sort_by(|a, b| a.rank.total_cmp(&b.rank));
        assert_eq!(fast, recursed, "n = {n}");
    }
}

#[test]
fn streams_reach_the_deepest_level_without_buffering() {
    let tiling = SphereTiling::default();
    // 10^18 samples would need level 26; the first few come at once
    let first: Vec<_> = engine::stream(&tiling, 1_000_000_000_000_000_000)
        .unwrap()
        .take(1000)
        .collect();
    let points: Vec<DVec3> = first.iter().map(|s| s.position).collect();
    assert!(points
        .iter()
        .all(|p| p.is_finite() && (p.length() - 1.0).abs() < 1e-12));
    let distinct: HashSet<[u64; 3]> = points
        .iter()
        .map(|p| p.to_array().map(f64::to_bits))
        .collect();
    assert_eq!(distinct.len(), points.len());
}

/// `--relax`: Lloyd iterations approach a CVT's spacing from a set past
/// level 6 (where the class table's points crowd: separation 1.98, mesh
/// ratio 3.74), and keep a cap's share of the points (the weight is the
/// density squared).
#[test]
fn lloyd_relaxation_evens_spacing_and_keeps_the_density() {
    use tessera::metrics::sphere::{covering_radius, mesh_ratio, separation};
    use tessera::relax::relax;
    let positions = |samples: Vec<tessera::Sample<DVec3>>| -> Vec<DVec3> {
        samples.into_iter().map(|s| s.position).collect()
    };
    let mut points = positions(Sampler::sphere().count(1_000_000).generate().unwrap());
    assert!(
        mesh_ratio(&points) > 2.8,
        "the unrelaxed set misses issue 18's mesh-ratio floor here"
    );
    relax(&mut points, &Uniform, 10).unwrap();
    let (s, c, m) = (
        separation(&points),
        covering_radius(&points),
        mesh_ratio(&points),
    );
    // 2.70 / 2.84 / 2.11 when written
    assert!(s > 2.6 && c < 2.95 && m < 2.2, "after 10: {s} {c} {m}");

    let cap = Cap::new(10.0, 20.0, 30.0, 16.0).unwrap();
    let tiling = SphereTiling::default();
    let mut points = positions(engine::generate(&tiling, &cap, 20_000, true).unwrap());
    let inside = |points: &[DVec3]| {
        points.iter().filter(|&&p| cap.contains(p)).count() as f64 / points.len() as f64
    };
    let before = inside(&points);
    relax(&mut points, &cap, 10).unwrap();
    assert!(
        (inside(&points) - before).abs() < 0.005,
        "{before} -> {}",
        inside(&points)
    );
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(32))]
    /// Samples of any code range (what a stream computes block by block)
    /// are that range of the prefix's samples.
    #[test]
    fn code_ranges_are_slices_of_the_prefix(
        level in 0u32..6,
        (start, len) in (0usize..250_000, 0usize..60_000),
    ) {
        let tiling = SphereTiling::default();
        let capacity = tiling.capacity(level) as usize;
        let end = (start + len).min(capacity);
        let start = start.min(end);
        let mut prefix = Vec::new();
        prop_assert!(tiling.code_order_samples(level, 0..end, 0.6, 1e4, &mut prefix));
        let mut range = Vec::new();
        prop_assert!(tiling.code_order_samples(level, start..end, 0.6, 1e4, &mut range));
        prop_assert_eq!(&range[..], &prefix[start..]);
    }
}

/// A stream crossing several of its blocks gives the in-memory path's
/// samples.
#[test]
fn streams_across_blocks_equal_the_fast_path() {
    let tiling = SphereTiling::default();
    let n = 700_000;
    let fast = engine::generate(&tiling, &Uniform, n, true).unwrap();
    let streamed: Vec<_> = engine::stream(&tiling, n).unwrap().collect();
    assert!(streamed == fast);
}

/// Unsorted sphere samples written as they are computed equal the
/// in-memory unsorted path's: a cap across several batches, a combination
/// of caps, and uniform (streamed codes).
#[test]
fn unsorted_batches_equal_the_in_memory_unsorted_path() {
    let tiling = SphereTiling::default();
    let cap = Cap::new(10.0, 20.0, 30.0, 10.0).unwrap();
    let regions = tessera::density::region::Regions::parse(&[
        "cap:-120,-80,3,1000",
        "polygon:-10 30,40 30,40 70,-10 70;16",
    ])
    .unwrap();
    for (count, exact) in [(1, true), (5000, true), (1_200_000, true), (300_000, false)] {
        for density in [
            &cap as &dyn tessera::density::Density<_>,
            &regions,
            &Uniform,
        ] {
            let mut buffers = engine::Buffers::default();
            let in_memory = engine::generate_into(
                &tiling,
                density,
                count,
                exact,
                engine::Order::Unsorted,
                &mut buffers,
            )
            .unwrap();
            let streamed: Vec<_> = engine::unsorted(&tiling, density, count, exact)
                .unwrap()
                .collect();
            assert!(streamed == in_memory, "{count} {exact}");
        }
    }
}

/// Levels deeper than the listed one (level 5, 245,760 tiles: see
/// `tiling::code_order`) descend from it along each run's digits: every
/// sample is its tile's, found from its root by the code's digits, across
/// a run boundary.
#[test]
fn deep_code_order_samples_are_their_tiles_samples() {
    let tiling = SphereTiling::default();
    let run = 240 * 4usize.pow(5);
    for level in [6u32, 8, 12] {
        let codes = 3 * run - 300..3 * run + 300;
        let (fraction, d) = (0.6, 0.6 * tiling.capacity(level));
        let mut samples = Vec::new();
        assert!(tiling.code_order_samples(level, codes.clone(), fraction, d, &mut samples));
        assert_eq!(samples.len(), codes.len());
        for (code, s) in codes.zip(&samples) {
            let tile = tiling.tile_with_code(level, code as u128).unwrap();
            assert_eq!(
                s.position,
                tiling.sample(&tile, fraction),
                "level {level}, code {code}"
            );
            assert_eq!(s.rank, code as f64 / d);
        }
    }
}

//! The Penrose system: production-rule geometry, codes, the deepest level,
//! and (with the shipped table) quality, density following, exactness,
//! domain and determinism.

mod common;
use common::tessera;

use approx::assert_relative_eq;
use common::plane::{
    check_counts, in_domain, parse_xy, photograph, positions, ramp_expected, raster_mass,
};
use glam::DVec2;
use std::collections::HashSet;
use tessera::density::plane::{Ramp, Raster};
use tessera::density::Uniform;
use tessera::engine;
use tessera::lut::{penrose_lut, PenroseLut};
use tessera::metrics::plane::{low_frequency_power, min_distance, spectral_peaks};
use tessera::tiling::penrose::{Kind, PenroseTile, PenroseTiling, PHI};
use tessera::tiling::TileSystem;

fn tiling() -> PenroseTiling {
    PenroseTiling::default()
}

/// Golden triangles: legs one edge, base `edge / phi`; gnomons: legs one
/// edge, base `phi * edge`; `c` and `f` wind counter-clockwise.
fn check_shape(t: &PenroseTile, edge: f64) {
    let [a, b, c] = t.v;
    assert_relative_eq!(a.distance(b), edge, max_relative = 1e-6);
    assert_relative_eq!(a.distance(c), edge, max_relative = 1e-6);
    let base = if t.kind.is_golden() {
        edge / PHI
    } else {
        edge * PHI
    };
    assert_relative_eq!(b.distance(c), base, max_relative = 1e-6);
    let ccw = (b - a).perp_dot(c - a) > 0.0;
    assert_eq!(ccw, matches!(t.kind, Kind::C | Kind::F), "{:?}", t.kind);
}

/// Child triangles cover the parent exactly: their areas sum to its area,
/// each corner is a parent corner or a new vertex on a parent side, and
/// the point child is one of those new vertices.
fn check_rule(tiling: &PenroseTiling, parent: &PenroseTile) {
    let (kids, n) = tiling.all_children(parent);
    let expected: &[Kind] = match parent.kind {
        Kind::C => &[Kind::F, Kind::C, Kind::A],
        Kind::D => &[Kind::E, Kind::D],
        Kind::E => &[Kind::F, Kind::C, Kind::E, Kind::A],
        Kind::F => &[Kind::E, Kind::D, Kind::F, Kind::A],
        Kind::A => &[Kind::B],
        Kind::B => &[Kind::A],
    };
    let kinds: Vec<Kind> = kids[..n].iter().map(|k| k.kind).collect();
    assert_eq!(kinds, expected);
    if parent.kind.is_point() {
        assert_eq!(kids[0].v[0], parent.v[0]);
        assert_eq!(kids[0].code, parent.code);
        return;
    }
    let edge = parent.v[0].distance(parent.v[1]) / PHI;
    let [a, b, c] = parent.v;
    let scale = edge;
    let mut area = 0.0;
    let mut new_vertices = Vec::new();
    for k in kids[..n].iter().filter(|k| !k.kind.is_point()) {
        check_shape(k, edge);
        area += k.area();
        for v in k.v {
            if [a, b, c].iter().any(|p| p.distance(v) < 1e-6 * scale) {
                continue;
            }
            // a new vertex: on a parent side, 1/phi of the way along
            let on_side = [(a, b), (b, a), (b, c), (c, b), (a, c), (c, a)]
                .iter()
                .any(|&(p, q)| (p + (q - p) / PHI).distance(v) < 1e-6 * scale);
            assert!(
                on_side,
                "{:?} child corner {v} is not on a side",
                parent.kind
            );
            new_vertices.push(v);
        }
    }
    assert_relative_eq!(area, parent.area(), max_relative = 1e-9);
    for k in kids[..n].iter().filter(|k| k.kind.is_point()) {
        assert!(new_vertices
            .iter()
            .any(|v| v.distance(k.v[0]) < 1e-6 * scale));
        assert_relative_eq!(k.v[1].length(), edge, max_relative = 1e-9);
    }
}

#[test]
fn children_cover_their_parent_exactly_at_every_depth() {
    let t = tiling();
    for tile in t.tiles(6) {
        check_shape_if_triangle(&tile, t.edge(6));
        check_rule(&t, &tile);
    }
    // down to the deepest level along the first child that reaches the
    // square, every step checked
    let mut tile = t.roots()[0];
    while t.level(&tile) < t.max_level() {
        check_rule(&t, &tile);
        let (kids, n) = t.all_children(&tile);
        tile = *kids[..n]
            .iter()
            .filter(|k| !k.kind.is_point())
            .max_by(|x, y| x.area().total_cmp(&y.area()))
            .unwrap();
        check_shape(&tile, t.edge(t.level(&tile)));
    }
}

fn check_shape_if_triangle(tile: &PenroseTile, edge: f64) {
    if !tile.kind.is_point() {
        check_shape(tile, edge);
    }
}

#[test]
fn every_vertex_in_the_square_is_one_point_tile() {
    let t = tiling();
    let level = 12;
    let tiles = t.tiles(level);
    let key = |p: DVec2| ((p.x * 1e8).round() as i64, (p.y * 1e8).round() as i64);
    let inside = |p: DVec2| (0.0..1.0).contains(&p.x) && (0.0..1.0).contains(&p.y);
    let mut points = HashSet::new();
    for p in tiles.iter().filter(|p| p.kind.is_point() && inside(p.v[0])) {
        assert!(points.insert(key(p.v[0])), "vertex {} owned twice", p.v[0]);
    }
    let vertices: HashSet<_> = tiles
        .iter()
        .filter(|p| !p.kind.is_point())
        .flat_map(|p| p.v)
        .filter(|&v| inside(v))
        .map(key)
        .collect();
    assert_eq!(points, vertices);
    assert!(points.len() > 5000, "{} points", points.len());
}

#[test]
fn codes_are_distinct_zeckendorf_numbers_of_uniform_density() {
    let t = tiling();
    let level = 12;
    let points: Vec<PenroseTile> = t
        .tiles(level)
        .into_iter()
        .filter(|p| p.kind.is_point() && in_domain(&p.v[0]))
        .collect();
    let cap = t.capacity(level);
    let codes: HashSet<_> = points.iter().map(|p| p.code).collect();
    assert_eq!(codes.len(), points.len());
    assert!(points.iter().all(|p| (p.code as f64) < cap));
    // the structural index is the value of the top six digits
    for p in &points {
        assert!(p.class() < 21);
    }
    // about c / codes_per_sample points below any threshold c, in the
    // square and in each of its quarters
    for fraction in [0.2, 0.45, 0.618, 0.8, 1.0] {
        let c = fraction * cap;
        let n = points.iter().filter(|p| (p.code as f64) < c).count() as f64;
        assert_relative_eq!(n, c / t.codes_per_sample(), max_relative = 0.02);
        let quarter = points
            .iter()
            .filter(|p| (p.code as f64) < c && p.v[0].x < 0.5 && p.v[0].y >= 0.5)
            .count() as f64;
        assert_relative_eq!(quarter, c / t.codes_per_sample() / 4.0, max_relative = 0.04);
    }
}

#[test]
fn the_deepest_level_keeps_codes_and_points_apart() {
    let t = tiling();
    let level = t.max_level();
    // F(2 level + 2) fits a code and one level more would not
    let fib = |n: u32| {
        let (mut a, mut b) = (0u128, 1u128);
        for _ in 0..n {
            (a, b) = (b, a + b);
        }
        a
    };
    let code_max = tessera::tiling::Code::MAX;
    assert!(fib(2 * level + 2) - 1 <= code_max);
    assert!(
        fib(2 * level + 4) - 1 > code_max || level == tessera::tiling::penrose::GEOMETRY_LEVELS
    );
    assert_eq!(t.capacity(level), fib(2 * level + 2) as f64);
    // the points of a deep tile's children stay distinct and in order
    let mut tile = t.roots()[0];
    while t.level(&tile) + 1 < level {
        let (kids, n) = t.all_children(&tile);
        tile = kids[..n]
            .iter()
            .copied()
            .find(|k| k.kind == Kind::E || k.kind == Kind::C)
            .unwrap_or(kids[0]);
    }
    let (kids, n) = t.all_children(&tile);
    let codes: HashSet<_> = kids[..n]
        .iter()
        .filter(|k| !k.kind.is_point())
        .map(|k| k.code)
        .collect();
    assert_eq!(
        codes.len(),
        kids[..n].iter().filter(|k| !k.kind.is_point()).count()
    );
    for k in &kids[..n] {
        assert!(k.code < fib(2 * level + 2));
        assert_eq!(t.level(k), level);
    }
}

#[test]
fn shipped_table_is_small_round_trips_and_corrupt_tables_are_refused() {
    let lut = penrose_lut();
    assert!(lut.bins >= 21);
    let bytes = lut.to_bytes();
    assert!(bytes.len() < 10_000, "{} bytes", bytes.len());
    assert_eq!(PenroseLut::from_bytes(&bytes).unwrap(), *lut);
    let path = format!("{}/luts/penrose.lut", env!("CARGO_MANIFEST_DIR"));
    assert_eq!(std::fs::read(path).unwrap(), bytes);
    assert!(PenroseLut::from_bytes(&bytes[..bytes.len() / 2]).is_err());
    let mut other = bytes.clone();
    other[0] = 7;
    let e = PenroseLut::from_bytes(&other).unwrap_err().to_string();
    assert!(e.contains("version"), "{e}");
    let mut wrong = (*lut).clone();
    wrong.classes = 20;
    let e = PenroseLut::from_bytes(&wrong.to_bytes())
        .unwrap_err()
        .to_string();
    assert!(e.contains("structural"), "{e}");
    let mut wrong = (*lut).clone();
    wrong.offsets[5] = [i16::MAX, 0];
    let e = PenroseLut::from_bytes(&wrong.to_bytes())
        .unwrap_err()
        .to_string();
    assert!(e.contains("offset 5"), "{e}");
    let mut wrong = (*lut).clone();
    wrong.offsets.pop();
    assert!(PenroseLut::from_bytes(&wrong.to_bytes()).is_err());
}

#[test]
fn uniform_4096_is_blue_noise() {
    let points = positions(&tiling(), &Uniform, 4096);
    let d = min_distance(&points);
    let low = low_frequency_power(&points);
    let peaks = spectral_peaks(&points, 256);
    println!(
        "penrose: min distance {d:.3}, low-frequency power {low:.3}, radial peak {:.2} at |k| = {}, largest single peak {:.1} at |k| = {:.1}",
        peaks.radial, peaks.radial_at, peaks.single, peaks.single_at
    );
    assert!(d >= 0.45, "normalised min distance {d}");
    assert!(low <= 0.10, "low-frequency power {low}");
}

#[test]
fn ramp_and_photograph_counts_follow_the_density() {
    let t = tiling();
    let n = 40_000;
    let points = positions(&t, &Ramp, n);
    assert_eq!(points.len(), n);
    assert!(points.iter().all(in_domain));
    check_counts(&points, |col, _| ramp_expected(n, col), "penrose ramp");
    let (w, h) = (96, 80);
    let pixels = photograph(w, h, 7);
    let mass = raster_mass(&pixels, w, h);
    let raster = Raster::new(w, h, pixels, false).unwrap();
    let n = 30_000;
    let points = positions(&t, &raster, n);
    assert_eq!(points.len(), n);
    assert!(points.iter().all(in_domain));
    check_counts(&points, |c, r| n as f64 * mass[r][c], "penrose photograph");
}

#[test]
fn exact_counts_and_domain_for_small_and_odd_requests() {
    let t = tiling();
    for n in [0usize, 1, 2, 3, 17, 216, 999, 5121, 17_497] {
        for points in [positions(&t, &Uniform, n), positions(&t, &Ramp, n)] {
            assert_eq!(points.len(), n);
            assert!(points.iter().all(in_domain));
        }
    }
    // without the exactness pass the count is close to the request
    let natural = engine::generate(&t, &Uniform, 10_000, false).unwrap().len();
    assert!((9_700..10_300).contains(&natural), "{natural}");
}

#[test]
fn output_is_progressive_and_deterministic() {
    let t = tiling();
    let points = positions(&t, &Uniform, 4096);
    let full = min_distance(&points);
    for prefix in [1000, 2048, 3000] {
        let d = min_distance(&points[..prefix]);
        println!("penrose prefix {prefix}: {d:.3} (full {full:.3})");
        assert!(d > 0.4 * full, "prefix {prefix} spread {d}");
    }
    assert_eq!(points, positions(&t, &Uniform, 4096));
    let run = |threads: usize| {
        common::on_threads(threads, || {
            let u = engine::generate(&t, &Uniform, 30_000, true).unwrap();
            let r = engine::generate(&t, &Ramp, 5_000, true).unwrap();
            (u, r)
        })
    };
    assert_eq!(run(1), run(2));
}

#[test]
fn the_sampler_builder_drives_the_penrose_tiling() {
    let sampler = tessera::Sampler::new(tiling()).density(Ramp).count(300);
    let samples = sampler.generate().unwrap();
    assert_eq!(samples.len(), 300);
    let pdfs = sampler.pdfs(&samples);
    assert!(samples
        .iter()
        .zip(&pdfs)
        .all(|(s, &p)| (p - 2.0 * s.position.x).abs() < 1e-12));
}

#[test]
fn cli_samples_and_draws_the_penrose_tiling() {
    let dir = std::env::temp_dir().join(format!("tessera-penrose-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let out = dir.join("ramp.txt");
    let run = tessera(&[
        "plane",
        "--system",
        "penrose",
        "--density",
        "ramp",
        "-n",
        "777",
        "-o",
        out.to_str().unwrap(),
    ]);
    assert!(
        run.status.success(),
        "{}",
        String::from_utf8_lossy(&run.stderr)
    );
    let text = std::fs::read_to_string(&out).unwrap();
    let points = parse_xy(&text);
    assert_eq!(points.len(), 777);
    assert!(points.iter().all(in_domain));
    let svg = dir.join("tiles.svg");
    let run = tessera(&[
        "tiles",
        "--system",
        "penrose",
        "--level",
        "5",
        "--svg",
        svg.to_str().unwrap(),
    ]);
    assert!(
        run.status.success(),
        "{}",
        String::from_utf8_lossy(&run.stderr)
    );
    let drawing = std::fs::read_to_string(&svg).unwrap();
    assert!(
        drawing.contains("<polygon") && drawing.contains("<text") && drawing.contains("<circle")
    );
    let refused = tessera(&[
        "tiles", "--system", "penrose", "--level", "15", "--svg", "x.svg",
    ]);
    assert!(!refused.status.success());
    assert!(String::from_utf8_lossy(&refused.stderr).contains("level 15"));
    let refused = tessera(&[
        "lut",
        "build",
        "--system",
        "penrose",
        "--bins",
        "1",
        "--out-dir",
        dir.to_str().unwrap(),
    ]);
    assert!(!refused.status.success());
    assert!(String::from_utf8_lossy(&refused.stderr).contains("2 bins"));
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn a_single_bright_pixel_and_a_dark_half_are_respected() {
    let t = tiling();
    let (w, h) = (256, 256);
    let mut pixels = vec![1e-6; w * h];
    pixels[200 * w + 37] = 1e6; // about 94 % of the mass
    let raster = Raster::new(w, h, pixels, false).unwrap();
    let points = positions(&t, &raster, 2000);
    let inside = points
        .iter()
        .filter(|p| (p.x * w as f64) as usize == 37 && (p.y * h as f64) as usize == 200)
        .count();
    assert!(inside > 1700, "{inside} of 2000 in the bright pixel");
    // left half black, right half white: inverted, the samples go left
    let raster = Raster::new(2, 1, vec![0.0, 1.0], true).unwrap();
    let points = positions(&t, &raster, 500);
    assert_eq!(points.len(), 500);
    let right = points.iter().filter(|p| p.x >= 0.5).count();
    assert!(right <= 5, "{right} points on the white side");
}

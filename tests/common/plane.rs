//! Checks shared by the planar tests (tests/plane.rs, tests/penrose.rs):
//! the domain, counts per grid cell against a density, and a
//! photograph-like raster with its exact mass per cell.
#![allow(dead_code)]

use glam::DVec2;
use tessera::baselines::SplitMix64;
use tessera::density::Density;
use tessera::engine;
use tessera::tiling::plane::PlaneRegion;
use tessera::tiling::TileSystem;

/// Exactly `n` sample positions of `density` on a planar system.
pub fn positions<S, D>(system: &S, density: &D, n: usize) -> Vec<DVec2>
where
    S: TileSystem<Point = DVec2, Region = PlaneRegion>,
    D: Density<PlaneRegion> + ?Sized,
{
    engine::generate(system, density, n, true)
        .unwrap()
        .iter()
        .map(|s| s.position)
        .collect()
}

/// The points of `x y` lines (what `tessera plane` writes).
pub fn parse_xy(text: &str) -> Vec<DVec2> {
    text.lines()
        .map(|l| {
            let v: Vec<f64> = l.split_whitespace().map(|x| x.parse().unwrap()).collect();
            DVec2::new(v[0], v[1])
        })
        .collect()
}

/// Whether a point lies in `[0, 1)^2`.
pub fn in_domain(p: &DVec2) -> bool {
    (0.0..1.0).contains(&p.x) && (0.0..1.0).contains(&p.y)
}

/// Counts per cell of a 16x16 grid against `expected(cell)`: every cell
/// within 4 Poisson sigma (and 1 point of rounding).
pub fn check_counts(points: &[DVec2], expected: impl Fn(usize, usize) -> f64, what: &str) {
    let mut counts = [[0usize; 16]; 16];
    for p in points {
        counts[(p.y * 16.0) as usize][(p.x * 16.0) as usize] += 1;
    }
    for (row, line) in counts.iter().enumerate() {
        for (col, &n) in line.iter().enumerate() {
            let e = expected(col, row);
            let sigma = e.sqrt().max(1.0);
            assert!(
                (n as f64 - e).abs() <= 4.0 * sigma + 1.0,
                "{what}: cell ({col}, {row}) has {n} points, expected {e:.1}"
            );
        }
    }
}

/// Expected count of `n` ramp samples (density proportional to x) in a
/// cell of the 16x16 grid: the mass over column c is (2c + 1) / 256.
pub fn ramp_expected(n: usize, col: usize) -> f64 {
    n as f64 * (2 * col + 1) as f64 / 256.0 / 16.0
}

/// A photograph-like raster: smooth gradients, a bright disc, a dark
/// square, texture and a few hot pixels, with a black band.
pub fn photograph(width: usize, height: usize, seed: u64) -> Vec<f64> {
    let mut rng = SplitMix64::new(seed);
    let mut v = Vec::with_capacity(width * height);
    for row in 0..height {
        for col in 0..width {
            let (x, y) = (col as f64 / width as f64, row as f64 / height as f64);
            let mut g = 0.3 + 0.4 * x * (1.0 - y) + 0.1 * (12.0 * x).sin() * (9.0 * y).cos();
            if (x - 0.65).powi(2) + (y - 0.35).powi(2) < 0.04 {
                g += 0.5;
            }
            if (0.1..0.3).contains(&x) && (0.6..0.85).contains(&y) {
                g *= 0.1;
            }
            g += 0.05 * rng.next_f64();
            if rng.next_u64() % 4000 == 0 {
                g = 1.0;
            }
            if row < height / 16 {
                g = 0.0;
            }
            v.push(g.clamp(0.0, 1.0));
        }
    }
    v
}

/// The share of a raster's mass in each cell of the 16x16 grid (pixels
/// split between cells contribute by area), `[row][col]`.
pub fn raster_mass(pixels: &[f64], w: usize, h: usize) -> Vec<[f64; 16]> {
    let total: f64 = pixels.iter().sum();
    let mut mass = vec![[0.0; 16]; 16];
    for (row, line) in mass.iter_mut().enumerate() {
        for (col, m) in line.iter_mut().enumerate() {
            for r in 0..h {
                for c in 0..w {
                    let ox = overlap(c as f64 / w as f64, (c + 1) as f64 / w as f64, col);
                    let oy = overlap(r as f64 / h as f64, (r + 1) as f64 / h as f64, row);
                    *m += pixels[r * w + c] * ox * oy;
                }
            }
            *m /= total;
        }
    }
    mass
}

fn overlap(a: f64, b: f64, cell: usize) -> f64 {
    let (lo, hi) = (cell as f64 / 16.0, (cell + 1) as f64 / 16.0);
    (b.min(hi) - a.max(lo)).max(0.0) / (b - a)
}

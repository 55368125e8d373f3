//! Metrics for point sets in the unit square `[0, 1)²`.
//!
//! Distances are plain Euclidean inside the square (no toroidal wrapping).
//! Nearest-neighbour distances are normalised by the spacing of the
//! hexagonal lattice with the same density, `d_hex = √(2 / (√3 N))`.
//!
//! | function | cost | empty input | one point |
//! | --- | --- | --- | --- |
//! | [`min_distance`], [`mean_nn_distance`] | O(N log N) | NaN | +∞ |
//! | [`l2_star_discrepancy`], [`centered_l2_discrepancy`] | O(N²/2), parallel | NaN | closed form |
//! | [`periodogram`] | O(N size²), parallel | NaN grid | all 1 |
//! | [`radial_average`], [`anisotropy`] | O(size²) | | |
//! | [`low_frequency_power`] | O(N²) (size ≈ √N), parallel | NaN | NaN |
//!
//! ```
//! use tessera::baselines::{jittered_grid_2d, uniform_random_2d};
//! use tessera::metrics::plane::{l2_star_discrepancy, low_frequency_power};
//! let (jit, rnd) = (jittered_grid_2d(32, 1), uniform_random_2d(1024, 1));
//! assert!(l2_star_discrepancy(&jit) < l2_star_discrepancy(&rnd));
//! assert!(low_frequency_power(&jit) < low_frequency_power(&rnd));
//! ```

use super::report::{quiet, Measure, Options, Progress, Report, Tally};
use super::Dd;
use crate::density::rectangle::Rectangle;
use glam::DVec2;
use kiddo::{ImmutableKdTree, SquaredEuclidean};
use rayon::prelude::*;
use serde::Serialize;
use std::f64::consts::TAU;
use std::num::NonZero;

/// Spacing of the hexagonal lattice with N points per unit area,
/// `√(2 / (√3 N))`, the normalisation of [`min_distance`] and
/// [`mean_nn_distance`].
///
/// ```
/// use tessera::metrics::plane::hex_spacing;
/// // A unit-area rhombus cell of side d has area (√3/2) d².
/// let d = hex_spacing(100);
/// assert!((100.0 * 3f64.sqrt() / 2.0 * d * d - 1.0).abs() < 1e-12);
/// ```
pub fn hex_spacing(n: usize) -> f64 {
    (2.0 / (3f64.sqrt() * n as f64)).sqrt()
}

/// Index of the first point that is not finite or lies outside the closed
/// unit square, where every measure here is defined (a set sampled on a
/// `--domain` rectangle is not measured by them).
///
/// ```
/// use glam::DVec2;
/// use tessera::metrics::plane::first_outside_unit_square;
/// assert_eq!(first_outside_unit_square(&[DVec2::ZERO, DVec2::ONE]), None);
/// assert_eq!(first_outside_unit_square(&[DVec2::ZERO, DVec2::new(1.5, 0.5)]), Some(1));
/// assert_eq!(first_outside_unit_square(&[DVec2::NAN]), Some(0));
/// ```
pub fn first_outside_unit_square(points: &[DVec2]) -> Option<usize> {
    points.iter().position(|&p| !Rectangle::UNIT.holds(p))
}

/// The indices of `points` along a Morton (Z-order) curve over their
/// bounding box (32 bits per axis): points near in the plane are mostly
/// near in this order, so visiting them in it keeps a k-d tree's nodes in
/// cache. A progressive file's order jumps across the square at every
/// point and misses the cache on nearly every query. NaN coordinates key
/// as the box's low side.
fn morton_order(points: &[DVec2]) -> Vec<usize> {
    let (lo, hi) = points
        .iter()
        .filter(|p| p.is_finite())
        .fold((DVec2::INFINITY, DVec2::NEG_INFINITY), |(lo, hi), &p| {
            (lo.min(p), hi.max(p))
        });
    // a flat box (or none) keys every point 0 along that axis
    let extent = hi - lo;
    let scale = DVec2::select(
        extent.cmpgt(DVec2::ZERO),
        u32::MAX as f64 / extent,
        DVec2::ZERO,
    );
    // spreads the 32 bits of a coordinate to the even bits of a u64
    fn spread(v: f64) -> u64 {
        let mut x = v as u64 & 0xffff_ffff; // saturating cast: NaN is 0
        x = (x | x << 16) & 0x0000_ffff_0000_ffff;
        x = (x | x << 8) & 0x00ff_00ff_00ff_00ff;
        x = (x | x << 4) & 0x0f0f_0f0f_0f0f_0f0f;
        x = (x | x << 2) & 0x3333_3333_3333_3333;
        (x | x << 1) & 0x5555_5555_5555_5555
    }
    let mut keyed: Vec<(u64, usize)> = points
        .par_iter()
        .enumerate()
        .map(|(i, p)| {
            let q = (*p - lo) * scale;
            (spread(q.x) | spread(q.y) << 1, i)
        })
        .collect();
    keyed.par_sort_unstable();
    keyed.into_iter().map(|(_, i)| i).collect()
}

/// Euclidean distance from each point to its nearest other point (N ≥ 2),
/// in [`morton_order`] (the points are visited, and the k-d tree built,
/// in that order, for cache locality).
fn nn_distances(points: &[DVec2], progress: Progress) -> Vec<f64> {
    let coords: Vec<[f64; 2]> = morton_order(points)
        .into_par_iter()
        .map(|i| points[i].to_array())
        .collect();
    let tree: ImmutableKdTree<f64, 2> = ImmutableKdTree::new_from_slice(&coords);
    let tally = Tally::new("neighbours", points.len() as u64, progress);
    (0..coords.len())
        .into_par_iter()
        .map(|i| {
            let found = tree.nearest_n::<SquaredEuclidean>(&coords[i], NonZero::new(2).unwrap());
            let j = found
                .iter()
                .map(|nn| nn.item as usize)
                .find(|&j| j != i)
                .expect("a tree of at least two points returns another point");
            tally.add(1);
            DVec2::from_array(coords[i]).distance(DVec2::from_array(coords[j]))
        })
        .collect()
}

/// Minimum pairwise distance divided by [`hex_spacing`]`(N)` (1 for a
/// hexagonal lattice of the same density, about 0.75–0.85 for good blue
/// noise). Nearest neighbours by k-d tree, cost O(N log N). Returns NaN for
/// an empty set and +∞ for a single point; coincident points give 0.
///
/// ```
/// use glam::DVec2;
/// use tessera::metrics::plane::{hex_spacing, min_distance};
/// let pts = [DVec2::new(0.25, 0.5), DVec2::new(0.75, 0.5)];
/// assert!((min_distance(&pts) - 0.5 / hex_spacing(2)).abs() < 1e-15);
/// ```
pub fn min_distance(points: &[DVec2]) -> f64 {
    match points.len() {
        0 => f64::NAN,
        1 => f64::INFINITY,
        n => {
            nn_distances(points, &quiet)
                .into_iter()
                .fold(f64::INFINITY, f64::min)
                / hex_spacing(n)
        }
    }
}

/// Mean nearest-neighbour distance divided by [`hex_spacing`]`(N)` (1 for a
/// hexagonal lattice, about 0.465 for uniform random points away from the
/// border). Cost O(N log N). Returns NaN for an empty set and +∞ for a single
/// point.
///
/// ```
/// use tessera::baselines::uniform_random_2d;
/// use tessera::metrics::plane::mean_nn_distance;
/// let m = mean_nn_distance(&uniform_random_2d(4000, 1));
/// assert!(m > 0.43 && m < 0.50);
/// ```
pub fn mean_nn_distance(points: &[DVec2]) -> f64 {
    match points.len() {
        0 => f64::NAN,
        1 => f64::INFINITY,
        n => {
            let mut acc = Dd::ZERO;
            nn_distances(points, &quiet)
                .into_iter()
                .for_each(|d| acc.add(d));
            acc.value() / n as f64 / hex_spacing(n)
        }
    }
}

/// Number of unordered pairs of `n` points.
fn pairs(n: usize) -> u64 {
    (n as u64) * (n as u64).saturating_sub(1) / 2
}

/// `Σ_i single(x_i)` and `Σ_{i,j} pair(x_i, x_j)` (ordered pairs, symmetric
/// `pair`), in double-double, parallel over rows; each row's pairs are
/// added to `tally`.
fn single_and_pair_sums(
    points: &[DVec2],
    single: impl Fn(DVec2) -> f64 + Sync,
    pair: impl Fn(DVec2, DVec2) -> f64 + Sync,
    tally: &Tally,
) -> (Dd, Dd) {
    (0..points.len())
        .into_par_iter()
        .map(|i| {
            let p = points[i];
            let mut s = Dd::ZERO;
            s.add(single(p));
            let mut off = Dd::ZERO;
            for &q in &points[i + 1..] {
                off.add(pair(p, q));
            }
            let mut d = off.plus(off);
            d.add(pair(p, p));
            tally.add((points.len() - 1 - i) as u64);
            (s, d)
        })
        .reduce(
            || (Dd::ZERO, Dd::ZERO),
            |a, b| (a.0.plus(b.0), a.1.plus(b.1)),
        )
}

/// `√max(c + a · single_sum / N + pair_sum / N², 0)`, evaluated in
/// double-double.
fn combine(constant: Dd, a: f64, single_sum: Dd, pair_sum: Dd, n: usize) -> f64 {
    let nf = n as f64;
    // a is a power of two (exact scaling).
    let s = single_sum.div(nf);
    let s = Dd {
        hi: s.hi * a,
        lo: s.lo * a,
    };
    let d2 = constant.plus(s).plus(pair_sum.div(nf).div(nf)).value();
    d2.max(0.0).sqrt()
}

/// L2-star discrepancy by Warnock's closed form (d = 2):
/// `T² = 1/9 − (1/(2N)) Σ_i (1−x_i²)(1−y_i²)
///        + (1/N²) Σ_{i,j} (1−max(x_i,x_j))(1−max(y_i,y_j))`,
/// returns `T`, the L2 norm over anchored boxes `[0, u) × [0, v)` of the
/// local discrepancy (no lower-dimensional projections).
///
/// Cost O(N²/2), parallel; sums and the final difference in double-double,
/// so the absolute error of T² is about 1e-17 (relative error of T about
/// `1e-17 / T²`). Returns NaN for an empty set.
///
/// ```
/// use glam::DVec2;
/// use tessera::metrics::plane::l2_star_discrepancy;
/// // One point at the centre: T² = 1/9 − (3/4)²/2 + 1/4 = 23/288.
/// let t = l2_star_discrepancy(&[DVec2::splat(0.5)]);
/// assert!((t * t - 23.0 / 288.0).abs() < 1e-15);
/// ```
pub fn l2_star_discrepancy(points: &[DVec2]) -> f64 {
    l2_star(points, &Tally::new("pairs", pairs(points.len()), &quiet))
}

fn l2_star(points: &[DVec2], tally: &Tally) -> f64 {
    let n = points.len();
    if n == 0 {
        return f64::NAN;
    }
    let (s, p) = single_and_pair_sums(
        points,
        |p| (1.0 - p.x * p.x) * (1.0 - p.y * p.y),
        |p, q| (1.0 - p.x.max(q.x)) * (1.0 - p.y.max(q.y)),
        tally,
    );
    combine(Dd::ratio(1.0, 9.0), -0.5, s, p, n)
}

/// Centred L2 discrepancy by Hickernell's closed form (d = 2):
/// `CD² = (13/12)² − (2/N) Σ_i Π_k (1 + |z_ik|/2 − z_ik²/2)
///        + (1/N²) Σ_{i,j} Π_k (1 + |z_ik|/2 + |z_jk|/2 − |x_ik − x_jk|/2)`
/// with `z = x − 1/2`; returns `CD`. It includes the one-dimensional
/// projections (boxes between a point and its nearest cube vertex) and is
/// invariant under the reflections `x ↦ 1 − x` of each coordinate.
///
/// Cost O(N²/2), parallel, double-double accumulation (absolute error of CD²
/// about 1e-16). Returns NaN for an empty set.
///
/// ```
/// use glam::DVec2;
/// use tessera::metrics::plane::centered_l2_discrepancy;
/// // One point at the centre: CD² = (13/12)² − 2 + 1 = 25/144.
/// let cd = centered_l2_discrepancy(&[DVec2::splat(0.5)]);
/// assert!((cd - 5.0 / 12.0).abs() < 1e-15);
/// ```
pub fn centered_l2_discrepancy(points: &[DVec2]) -> f64 {
    centered_l2(points, &Tally::new("pairs", pairs(points.len()), &quiet))
}

fn centered_l2(points: &[DVec2], tally: &Tally) -> f64 {
    let n = points.len();
    if n == 0 {
        return f64::NAN;
    }
    let f1 = |t: f64| {
        let z = (t - 0.5).abs();
        1.0 + 0.5 * z - 0.5 * z * z
    };
    let f2 =
        |s: f64, t: f64| 1.0 + 0.5 * (s - 0.5).abs() + 0.5 * (t - 0.5).abs() - 0.5 * (s - t).abs();
    let (s, p) = single_and_pair_sums(
        points,
        |p| f1(p.x) * f1(p.y),
        |p, q| f2(p.x, q.x) * f2(p.y, q.y),
        tally,
    );
    combine(Dd::ratio(169.0, 144.0), -2.0, s, p, n)
}

/// Points per chunk of the periodogram (bounds the memory of the per-point
/// exponential tables to `2 · CHUNK · size` complex numbers).
const CHUNK: usize = 256;

/// Lowest integer frequency of a grid of `size` frequencies: `−⌊size/2⌋`.
fn k_min(size: usize) -> i64 {
    -((size / 2) as i64)
}

/// Periodogram `P(k) = |Σ_j exp(−2πi k · x_j)|² / N` on the `size × size`
/// grid of integer frequencies `k = (kx, ky)` with
/// `kx, ky ∈ [−⌊size/2⌋, size − ⌊size/2⌋)` (for even `size`,
/// `[−size/2, size/2)`), DC included (`P(0) = N`).
///
/// Layout: row-major, `index = (ky + ⌊size/2⌋) · size + (kx + ⌊size/2⌋)`, so
/// the DC term is at `(size/2) · (size + 1)` for even `size`. For independent
/// uniform points `E[P(k)] = 1` for k ≠ 0. The transform is evaluated
/// directly (points need not be on a grid): per point one `sin_cos` per axis
/// frequency, then a complex outer-product accumulation, cost O(N · size²)
/// multiply-adds (+ O(N · size) `sin_cos`), parallel over rows `ky`, memory
/// O(size² + 256 · size). Returns NaN everywhere for an empty set.
///
/// ```
/// use glam::DVec2;
/// use tessera::metrics::plane::periodogram;
/// let p = periodogram(&[DVec2::new(0.3, 0.7)], 8);
/// assert_eq!(p.len(), 64);
/// assert!(p.iter().all(|v| (v - 1.0).abs() < 1e-12));
/// ```
pub fn periodogram(points: &[DVec2], size: usize) -> Vec<f64> {
    periodogram_with(
        points,
        size,
        &Tally::new("periodogram", points.len() as u64, &quiet),
    )
}

/// [`periodogram`], adding each chunk of points to `tally`.
fn periodogram_with(points: &[DVec2], size: usize, tally: &Tally) -> Vec<f64> {
    let n = points.len();
    if n == 0 {
        return vec![f64::NAN; size * size];
    }
    if size == 0 {
        return Vec::new();
    }
    let k0 = k_min(size);
    // acc[ky * 2 size + 2 kx] = Re, [+1] = Im.
    let mut acc = vec![0.0f64; 2 * size * size];
    let mut table = vec![0.0f64; 4 * CHUNK * size];
    for chunk in points.chunks(CHUNK) {
        let m = chunk.len();
        // table layout per point j: [cos x (size), sin x (size), cos y, sin y]
        // of the angle −2π k t.
        table[..4 * m * size]
            .par_chunks_mut(4 * size)
            .zip(chunk.par_iter())
            .for_each(|(row, p)| {
                for idx in 0..size {
                    let k = (k0 + idx as i64) as f64;
                    let (sx, cx) = (-TAU * k * p.x).sin_cos();
                    let (sy, cy) = (-TAU * k * p.y).sin_cos();
                    row[idx] = cx;
                    row[size + idx] = sx;
                    row[2 * size + idx] = cy;
                    row[3 * size + idx] = sy;
                }
            });
        let table = &table[..4 * m * size];
        acc.par_chunks_mut(2 * size)
            .enumerate()
            .for_each(|(ky, row)| {
                let (re, im) = row.split_at_mut(size);
                for t in table.chunks_exact(4 * size) {
                    let (ex_re, rest) = t.split_at(size);
                    let (ex_im, rest) = rest.split_at(size);
                    let ey_re = rest[ky];
                    let ey_im = rest[size + ky];
                    for kx in 0..size {
                        re[kx] += ey_re * ex_re[kx] - ey_im * ex_im[kx];
                        im[kx] += ey_re * ex_im[kx] + ey_im * ex_re[kx];
                    }
                }
            });
        tally.add(m as u64);
    }
    let nf = n as f64;
    let mut out = vec![0.0f64; size * size];
    out.par_chunks_mut(size)
        .zip(acc.par_chunks(2 * size))
        .for_each(|(o, row)| {
            let (re, im) = row.split_at(size);
            for kx in 0..size {
                o[kx] = (re[kx] * re[kx] + im[kx] * im[kx]) / nf;
            }
        });
    out
}

/// Ring index `round(|k|)` of every cell of a `size × size` periodogram, or
/// `None` outside the complete rings `0..⌊size/2⌋`.
fn ring_of(size: usize, idx: usize) -> Option<usize> {
    let k0 = k_min(size);
    let kx = (idx % size) as i64 + k0;
    let ky = (idx / size) as i64 + k0;
    let r = (((kx * kx + ky * ky) as f64).sqrt() + 0.5).floor() as usize;
    (r < size / 2).then_some(r)
}

/// Values of a periodogram grouped by ring.
fn rings(periodogram: &[f64], size: usize) -> Vec<Vec<f64>> {
    assert_eq!(
        periodogram.len(),
        size * size,
        "periodogram length must be size²"
    );
    let mut rings = vec![Vec::new(); size / 2];
    for (idx, &v) in periodogram.iter().enumerate() {
        if let Some(r) = ring_of(size, idx) {
            rings[r].push(v);
        }
    }
    rings
}

/// Radially averaged power of a [`periodogram`] of side `size`: entry `r` is
/// the mean over the frequencies with `r − 1/2 ≤ |k| < r + 1/2` (ring of
/// integer radius r), for the complete rings `r = 0..⌊size/2⌋` (entry 0 is
/// the DC value N). Cost O(size²).
///
/// # Panics
/// If `periodogram.len() != size * size`.
///
/// ```
/// use tessera::metrics::plane::radial_average;
/// let flat = vec![2.0; 16 * 16];
/// let r = radial_average(&flat, 16);
/// assert_eq!(r.len(), 8);
/// assert!(r.iter().all(|&v| v == 2.0));
/// ```
pub fn radial_average(periodogram: &[f64], size: usize) -> Vec<f64> {
    rings(periodogram, size)
        .iter()
        .map(|ring| ring.iter().sum::<f64>() / ring.len() as f64)
        .collect()
}

/// The largest spectral peaks of a point set up to `|k| = size / 2`, DC
/// excluded: of the radially averaged power and of single frequencies.
///
/// ```
/// use tessera::baselines::uniform_random_2d;
/// use tessera::metrics::plane::spectral_peaks;
/// let p = spectral_peaks(&uniform_random_2d(512, 1), 32);
/// assert!(p.radial > 0.5 && p.radial < 3.0 && p.single >= p.radial);
/// ```
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct SpectralPeaks {
    /// Ring radius of the largest radially averaged power.
    pub radial_at: usize,
    /// That power (white noise: about 1).
    pub radial: f64,
    /// `|k|` of the largest single-frequency power.
    pub single_at: f64,
    /// That power.
    pub single: f64,
}

/// Computes [`SpectralPeaks`] from a [`periodogram`] of side `size`.
///
/// ```
/// use glam::DVec2;
/// use tessera::metrics::plane::spectral_peaks;
/// // a 16 x 16 lattice: all power on the lattice frequencies (multiples of 16)
/// let grid: Vec<DVec2> = (0..256)
///     .map(|i| DVec2::new((i % 16) as f64 + 0.5, (i / 16) as f64 + 0.5) / 16.0)
///     .collect();
/// let p = spectral_peaks(&grid, 40);
/// assert!((p.single_at - 16.0).abs() < 1e-9 && p.single > 200.0);
/// ```
pub fn spectral_peaks(points: &[DVec2], size: usize) -> SpectralPeaks {
    let power = periodogram(points, size);
    let radial = radial_average(&power, size);
    let (radial_at, radial) = radial
        .iter()
        .enumerate()
        .skip(1)
        .fold((0, 0.0f64), |b, (r, &v)| if v > b.1 { (r, v) } else { b });
    let k0 = k_min(size);
    let (mut single_at, mut single) = (0.0, 0.0f64);
    for (idx, &v) in power.iter().enumerate() {
        let kx = (idx % size) as i64 + k0;
        let ky = (idx / size) as i64 + k0;
        let k = ((kx * kx + ky * ky) as f64).sqrt();
        if k > 0.0 && k <= (size / 2) as f64 && v > single {
            (single_at, single) = (k, v);
        }
    }
    SpectralPeaks {
        radial_at,
        radial,
        single_at,
        single,
    }
}

/// Ulichney's anisotropy of a [`periodogram`] of side `size`, in decibels:
/// for each ring r of [`radial_average`], `10 log10(s²(r) / P_r(r)²)` with
/// `s²` the unbiased variance (divisor `count − 1`) of the ring's values and
/// `P_r` their mean. Isotropic noise gives about 0 dB (white noise: the
/// periodogram is exponentially distributed with variance = mean²; since
/// `P(−k) = P(k)` only half of each ring is independent); strongly
/// anisotropic spectra give large positive values. Entries are NaN for
/// rings of fewer than two values (ring 0) or zero mean, and −∞ for constant
/// rings. Cost O(size²).
///
/// # Panics
/// If `periodogram.len() != size * size`.
///
/// ```
/// use tessera::baselines::uniform_random_2d;
/// use tessera::metrics::plane::{anisotropy, periodogram};
/// let a = anisotropy(&periodogram(&uniform_random_2d(512, 3), 64), 64);
/// assert!(a[0].is_nan());
/// let mean = a[8..].iter().sum::<f64>() / a[8..].len() as f64;
/// assert!(mean.abs() < 1.5);
/// ```
pub fn anisotropy(periodogram: &[f64], size: usize) -> Vec<f64> {
    rings(periodogram, size)
        .iter()
        .map(|ring| {
            let c = ring.len() as f64;
            let mean = ring.iter().sum::<f64>() / c;
            if ring.len() < 2 || mean == 0.0 {
                return f64::NAN;
            }
            let var = ring.iter().map(|v| (v - mean) * (v - mean)).sum::<f64>() / (c - 1.0);
            10.0 * (var / (mean * mean)).log10()
        })
        .collect()
}

/// Mean periodogram power over all integer frequencies `k ≠ 0` with
/// `|k| < √N / 2` (about πN/4 frequencies): 1 in expectation for white noise,
/// much smaller for blue noise, 0 for a perfect square lattice of √N × √N
/// points. Evaluated with [`periodogram`] on the smallest grid containing the
/// disc (side about √N + 2), cost O(N²) (≈ N · (√N + 2)² complex
/// multiply-adds), parallel. Returns NaN when there is no such frequency
/// (N ≤ 4, including the empty set).
///
/// ```
/// use tessera::baselines::uniform_random_2d;
/// use tessera::metrics::plane::low_frequency_power;
/// let w = low_frequency_power(&uniform_random_2d(1024, 7));
/// assert!(w > 0.85 && w < 1.15);
/// ```
pub fn low_frequency_power(points: &[DVec2]) -> f64 {
    low_frequency(points, &quiet)
}

fn low_frequency(points: &[DVec2], progress: Progress) -> f64 {
    let n = points.len();
    let r2 = n as f64 / 4.0; // |k|² < (√N / 2)²
    let kmax = r2.sqrt().ceil() as usize;
    let size = 2 * kmax + 2;
    if n <= 4 {
        return f64::NAN;
    }
    let tally = Tally::new("low frequencies", n as u64, progress);
    let p = periodogram_with(points, size, &tally);
    let k0 = k_min(size);
    let mut sum = Dd::ZERO;
    let mut count = 0usize;
    for (idx, &v) in p.iter().enumerate() {
        let kx = (idx % size) as i64 + k0;
        let ky = (idx / size) as i64 + k0;
        let k2 = (kx * kx + ky * ky) as f64;
        if k2 > 0.0 && k2 < r2 {
            sum.add(v);
            count += 1;
        }
    }
    if count == 0 {
        f64::NAN
    } else {
        sum.value() / count as f64
    }
}

/// The measures of [`measure`], by their keys in reports.
///
/// ```
/// use tessera::metrics::{Measure, PlaneMeasure};
/// assert!(PlaneMeasure::L2Star.quadratic() && !PlaneMeasure::MinDistance.quadratic());
/// ```
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum PlaneMeasure {
    /// [`min_distance`].
    MinDistance,
    /// [`mean_nn_distance`].
    MeanNnDistance,
    /// [`l2_star_discrepancy`].
    L2Star,
    /// [`centered_l2_discrepancy`].
    CenteredL2,
    /// [`low_frequency_power`].
    LowFrequencyPower,
}

impl Measure for PlaneMeasure {
    const ALL: &'static [Self] = &[
        PlaneMeasure::MinDistance,
        PlaneMeasure::MeanNnDistance,
        PlaneMeasure::L2Star,
        PlaneMeasure::CenteredL2,
        PlaneMeasure::LowFrequencyPower,
    ];

    fn key(self) -> &'static str {
        match self {
            PlaneMeasure::MinDistance => "min_distance_over_hex_spacing",
            PlaneMeasure::MeanNnDistance => "mean_nn_distance_over_hex_spacing",
            PlaneMeasure::L2Star => "l2_star_discrepancy",
            PlaneMeasure::CenteredL2 => "centered_l2_discrepancy",
            PlaneMeasure::LowFrequencyPower => "low_frequency_power",
        }
    }

    fn meaning(self) -> &'static str {
        match self {
            PlaneMeasure::MinDistance => {
                "The smallest distance between two points over the spacing \
                 sqrt(2 / (sqrt(3) N)) of the hexagonal lattice with N points per unit \
                 area (Euclidean, no wrap-around). Higher is better: 1 for that \
                 lattice, near 0 for independent uniform points. Cost O(N log N)."
            }
            PlaneMeasure::MeanNnDistance => {
                "The mean distance from a point to its nearest other point, over the \
                 same hexagonal spacing: 1 for that lattice, about 0.465 for \
                 independent uniform points (1 / (2 sqrt(N)) away from the border). \
                 Cost O(N log N)."
            }
            PlaneMeasure::L2Star => {
                "Warnock's L2-star discrepancy T of [0,1)^2, not normalised: the L2 \
                 norm of the local discrepancy over anchored boxes [0,u) x [0,v) \
                 (closed form). Lower is better. Cost O(N^2)."
            }
            PlaneMeasure::CenteredL2 => {
                "Hickernell's centred L2 discrepancy CD, not normalised: boxes between \
                 a point and its nearest corner of the square, 1-D projections \
                 included (closed form). Lower is better. Cost O(N^2)."
            }
            PlaneMeasure::LowFrequencyPower => {
                "The mean periodogram power |sum_j exp(-2 pi i k.x_j)|^2 / N over the \
                 integer frequencies 0 < |k| < sqrt(N) / 2: 1 in expectation for \
                 independent uniform points (white noise), lower for blue noise, 0 \
                 for a sqrt(N) x sqrt(N) square lattice. Cost O(N^2)."
            }
        }
    }

    fn quadratic(self) -> bool {
        !matches!(
            self,
            PlaneMeasure::MinDistance | PlaneMeasure::MeanNnDistance
        )
    }
}

/// The measures `options` ask for (all by default, the O(N²) ones only up
/// to [`Options::pairs_up_to`] points), the two distance measures from one
/// k-d tree pass. Values equal those of the functions named in
/// [`PlaneMeasure`] (up to rounding for the mean distance).
///
/// ```
/// use tessera::baselines::uniform_random_2d;
/// use tessera::metrics::{plane, Options, PlaneMeasure};
/// let points = uniform_random_2d(256, 5);
/// let options = Options { only: Some(vec![PlaneMeasure::L2Star]), ..Options::default() };
/// let r = plane::measure(&points, &options);
/// assert_eq!(r.entries().len(), 1);
/// assert_eq!(r[PlaneMeasure::L2Star], plane::l2_star_discrepancy(&points));
/// ```
pub fn measure(points: &[DVec2], options: &Options<PlaneMeasure>) -> Report<PlaneMeasure> {
    use PlaneMeasure::*;
    let n = points.len();
    let distances = (n >= 2
        && (options.computes(MinDistance, n) || options.computes(MeanNnDistance, n)))
    .then(|| nn_distances(points, options.progress));
    let distance = |mean: bool| match (&distances, n) {
        (_, 0) => f64::NAN,
        (_, 1) => f64::INFINITY,
        (None, _) => unreachable!("distances are computed when asked for"),
        (Some(d), n) if mean => {
            let mut acc = Dd::ZERO;
            d.iter().for_each(|&v| acc.add(v));
            acc.value() / n as f64 / hex_spacing(n)
        }
        (Some(d), n) => d.iter().copied().fold(f64::INFINITY, f64::min) / hex_spacing(n),
    };
    let discrepancies = |centred| {
        let tally = Tally::new(
            if centred { "centred pairs" } else { "pairs" },
            pairs(n),
            options.progress,
        );
        if centred {
            centered_l2(points, &tally)
        } else {
            l2_star(points, &tally)
        }
    };
    Report::new(n, options, |m| match m {
        MinDistance => distance(false),
        MeanNnDistance => distance(true),
        L2Star => discrepancies(false),
        CenteredL2 => discrepancies(true),
        LowFrequencyPower => low_frequency(points, options.progress),
    })
}

/// Every measure of [`PlaneMeasure`], whatever N.
///
/// ```
/// use tessera::baselines::uniform_random_2d;
/// use tessera::metrics::{plane_report, PlaneMeasure};
/// let r = plane_report(&uniform_random_2d(256, 5));
/// assert!(r[PlaneMeasure::L2Star] > 0.0 && r[PlaneMeasure::L2Star] < 0.1);
/// ```
pub fn plane_report(points: &[DVec2]) -> Report<PlaneMeasure> {
    let options = Options {
        pairs_up_to: usize::MAX,
        ..Options::default()
    };
    measure(points, &options)
}

/// Above this many points, [`PlaneSpectrum`] measures a corner window
/// holding about this many (its grid then reaches twice the blue-noise
/// peak at a bounded cost, O(N · size²) with size ≈ 4.4 √N).
///
/// ```
/// assert_eq!(tessera::metrics::plane::SPECTRUM_POINTS, 20_000);
/// ```
pub const SPECTRUM_POINTS: usize = 20_000;

/// The periodogram of a point set on a grid sized to it, with its radial
/// average and anisotropy (what `tessera metrics plane --spectrum` prints).
///
/// ```
/// use tessera::baselines::uniform_random_2d;
/// use tessera::metrics::plane::PlaneSpectrum;
/// let s = PlaneSpectrum::new(&uniform_random_2d(256, 1));
/// assert_eq!(s.periodogram.len(), s.size * s.size);
/// assert_eq!(s.radial_power.len(), s.size / 2);
/// ```
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct PlaneSpectrum {
    /// Side of the frequency grid: frequencies `|kx|, |ky| ≤ size / 2`.
    pub size: usize,
    /// Side of the square `[0, window)²` measured, rescaled to the unit
    /// square: 1 up to [`SPECTRUM_POINTS`] points, then the corner holding
    /// about that many (frequencies are then in the window's units).
    pub window: f64,
    /// Number of points measured (those in the window).
    pub points: usize,
    /// [`periodogram`] on the grid.
    pub periodogram: Vec<f64>,
    /// [`radial_average`] of it: the mean power of each ring of integer
    /// radius (white noise 1).
    pub radial_power: Vec<f64>,
    /// [`anisotropy`] of each ring, in dB (isotropic noise about 0).
    pub anisotropy_db: Vec<f64>,
}

impl PlaneSpectrum {
    /// The spectrum on a grid of side `2 ⌈2.2 √N⌉` (at least 32), so that
    /// its rings reach twice the blue-noise peak (near `|k| = 1.07 √N`, the
    /// first ring of the hexagonal lattice of N points); above
    /// [`SPECTRUM_POINTS`] points, of the corner window holding about that
    /// many. Cost O(N · size²).
    ///
    /// ```
    /// use tessera::baselines::jittered_grid_2d;
    /// use tessera::metrics::plane::PlaneSpectrum;
    /// let s = PlaneSpectrum::new(&jittered_grid_2d(16, 1));
    /// assert_eq!((s.size, s.window, s.points), (72, 1.0, 256));
    /// ```
    pub fn new(points: &[DVec2]) -> Self {
        Self::with_progress(points, &quiet)
    }

    /// [`PlaneSpectrum::new`], telling `progress` how many points are
    /// transformed (stage `"spectrum"`).
    ///
    /// ```
    /// use tessera::baselines::jittered_grid_2d;
    /// use tessera::metrics::plane::PlaneSpectrum;
    /// let told = std::sync::atomic::AtomicBool::new(false);
    /// let s = PlaneSpectrum::with_progress(&jittered_grid_2d(16, 1), &|stage, _, _| {
    ///     told.store(stage == "spectrum", std::sync::atomic::Ordering::Relaxed);
    /// });
    /// assert!(told.into_inner() && s.size == 72);
    /// ```
    pub fn with_progress(points: &[DVec2], progress: Progress) -> Self {
        let n = points.len();
        let window = if n > SPECTRUM_POINTS {
            (SPECTRUM_POINTS as f64 / n as f64).sqrt()
        } else {
            1.0
        };
        let kept: Vec<DVec2> = points
            .iter()
            .filter(|p| window == 1.0 || (p.x < window && p.y < window))
            .map(|p| *p / window)
            .collect();
        let size = (2 * (2.2 * (kept.len() as f64).sqrt()).ceil() as usize).max(32);
        let tally = Tally::new("spectrum", kept.len() as u64, progress);
        let periodogram = periodogram_with(&kept, size, &tally);
        PlaneSpectrum {
            size,
            window,
            points: kept.len(),
            radial_power: radial_average(&periodogram, size),
            anisotropy_db: anisotropy(&periodogram, size),
            periodogram,
        }
    }
}

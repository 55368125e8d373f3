//! Metrics for point sets on the unit sphere S².
//!
//! All functions take `&[DVec3]` of **unit** vectors (they are not
//! re-normalised; inputs off the sphere by more than rounding bias the
//! results). Normalisations use N = `points.len()`; distances are geodesic
//! angles in radians unless stated otherwise.
//!
//! | function | cost | empty input | one point |
//! | --- | --- | --- | --- |
//! | [`separation`] | O(N log N) | NaN | +∞ |
//! | [`cap_discrepancy_l2`] | O(N²/2), parallel | NaN | 1/√3 |
//! | [`riesz1_normalized`] | O(N²/2), parallel | NaN | −1 |
//! | [`covering_radius`] | O(N log N) typical, parallel | NaN | π |
//! | [`mesh_ratio`] | O(N log N) | NaN | NaN |
//! | [`angular_power`] | O(N l_max² / 2), parallel | zeros | all 1 |
//!
//! ```
//! use tessera::baselines::{spherical_fibonacci, uniform_random_sphere};
//! use tessera::metrics::sphere::{cap_discrepancy_l2, separation};
//! let (fib, rnd) = (spherical_fibonacci(1000), uniform_random_sphere(1000, 1));
//! assert!(separation(&fib) > 10.0 * separation(&rnd));
//! assert!(cap_discrepancy_l2(&fib) < 0.2 * cap_discrepancy_l2(&rnd));
//! ```

use super::report::{quiet, Measure, Options, Progress, Report, Tally};
use super::Dd;
use crate::voronoi::{build_tree, cell_of, spatial_order, Tree3};
use glam::DVec3;
use kiddo::SquaredEuclidean;
use rayon::prelude::*;
use serde::Serialize;
use std::f64::consts::PI;
use std::num::NonZero;

/// Geodesic angle between two unit vectors, `atan2(|a × b|, a · b)`: accurate
/// for all angles, including nearly coincident and nearly antipodal points.
///
/// ```
/// use glam::DVec3;
/// use tessera::metrics::sphere::geodesic_distance;
/// let d = geodesic_distance(DVec3::X, DVec3::Y);
/// assert!((d - std::f64::consts::FRAC_PI_2).abs() < 1e-15);
/// ```
#[inline]
pub fn geodesic_distance(a: DVec3, b: DVec3) -> f64 {
    crate::voronoi::geodesic(a, b)
}

/// The index of the first point that is not a finite unit vector (to
/// 1e-6): the points `tessera metrics sphere` refuses to measure.
///
/// ```
/// use glam::DVec3;
/// use tessera::metrics::sphere::first_non_unit;
/// assert_eq!(first_non_unit(&[DVec3::X, DVec3::Y]), None);
/// assert_eq!(first_non_unit(&[DVec3::X, DVec3::splat(1.0), DVec3::NAN]), Some(1));
/// ```
pub fn first_non_unit(points: &[DVec3]) -> Option<usize> {
    points
        .iter()
        .position(|p| !p.is_finite() || (p.length() - 1.0).abs() > 1e-6)
}

/// Index of the nearest other point of `points[i]` (requires N ≥ 2).
fn nearest_other(tree: &Tree3, points: &[DVec3], i: usize) -> usize {
    let q = points[i].to_array();
    let found = tree.nearest_n::<SquaredEuclidean>(&q, NonZero::new(2).unwrap());
    found
        .iter()
        .map(|nn| nn.item as usize)
        .find(|&j| j != i)
        .expect("a tree of at least two points returns another point")
}

/// The geodesic angle from each point to its nearest other point (+∞ for
/// a single point), by a k-d tree: O(N log N), parallel.
///
/// ```
/// use glam::DVec3;
/// use tessera::metrics::sphere::nearest_angles;
/// let angles = nearest_angles(&[DVec3::X, DVec3::Y, DVec3::NEG_X]);
/// assert!((angles[0] - std::f64::consts::FRAC_PI_2).abs() < 1e-12);
/// assert_eq!(nearest_angles(&[DVec3::Z]), vec![f64::INFINITY]);
/// ```
pub fn nearest_angles(points: &[DVec3]) -> Vec<f64> {
    if points.len() < 2 {
        return vec![f64::INFINITY; points.len()];
    }
    let tree = build_tree(points);
    (0..points.len())
        .into_par_iter()
        .map(|i| geodesic_distance(points[i], points[nearest_other(&tree, points, i)]))
        .collect()
}

/// Normalised separation `√N · min_{i≠j} d(x_i, x_j)` (geodesic).
///
/// Each point's nearest neighbour is found with a k-d tree on the 3-D
/// coordinates (chordal and geodesic distance have the same order), and the
/// angle of the closest pair is evaluated with [`geodesic_distance`].
/// Cost O(N log N), parallel. Returns NaN for an empty set and +∞ for a single
/// point (the minimum over no pair); coincident points give 0. For reference,
/// the hexagonal-lattice bound is about 3.81 and the Fibonacci lattice gives
/// about 3.09.
///
/// ```
/// use tessera::baselines::spherical_fibonacci;
/// use tessera::metrics::sphere::separation;
/// let s = separation(&spherical_fibonacci(1000));
/// assert!(s > 3.0 && s < 3.2);
/// assert_eq!(separation(&[glam::DVec3::Z]), f64::INFINITY);
/// ```
pub fn separation(points: &[DVec3]) -> f64 {
    neighbourhoods(points, (true, false), None, &quiet).0 * (points.len() as f64).sqrt()
}

/// Sums over unordered pairs of the `K` values `f(x_i, x_j)`, in
/// double-double, parallel over rows; each row's pairs are added to
/// `tally`. A non-finite `f` makes its sum non-finite.
fn pair_sums<const K: usize>(
    points: &[DVec3],
    f: impl Fn(DVec3, DVec3) -> [f64; K] + Sync,
    tally: &Tally,
) -> [Dd; K] {
    (0..points.len())
        .into_par_iter()
        .map(|i| {
            let p = points[i];
            // four independent accumulators, so that their dependency
            // chains overlap
            let mut lanes = [[Dd::ZERO; K]; 4];
            let mut chunks = points[i + 1..].chunks_exact(4);
            for c in &mut chunks {
                for (lane, &q) in lanes.iter_mut().zip(c) {
                    lane.iter_mut().zip(f(p, q)).for_each(|(a, v)| a.add(v));
                }
            }
            for &q in chunks.remainder() {
                lanes[0].iter_mut().zip(f(p, q)).for_each(|(a, v)| a.add(v));
            }
            tally.add((points.len() - 1 - i) as u64);
            std::array::from_fn(|k| {
                (lanes[0][k].plus(lanes[1][k])).plus(lanes[2][k].plus(lanes[3][k]))
            })
        })
        .reduce(
            || [Dd::ZERO; K],
            |a, b| std::array::from_fn(|k| a[k].plus(b[k])),
        )
}

/// Number of unordered pairs of `n` points.
fn pairs(n: usize) -> u64 {
    (n as u64) * (n as u64).saturating_sub(1) / 2
}

/// D from the sum of chordal distances over unordered pairs.
fn cap_discrepancy_from(n: usize, half_sum: Dd) -> f64 {
    if n == 0 || !half_sum.value().is_finite() {
        return f64::NAN;
    }
    // Σ_{i,j} = 2 · half_sum, so D² = 1/3 − half_sum / (2 N²).
    let nf = n as f64;
    let term = half_sum.div(2.0 * nf).div(nf);
    let d2 = Dd::ratio(1.0, 3.0).plus(term.neg()).value();
    d2.max(0.0).sqrt()
}

/// (E − N²) / N^1.5 from the energy over unordered pairs.
fn riesz1_from(n: usize, half_energy: Dd) -> f64 {
    if n == 0 {
        return f64::NAN;
    }
    if !half_energy.value().is_finite() {
        return f64::INFINITY;
    }
    let nf = n as f64;
    let e = half_energy.plus(half_energy);
    let mut n2 = Dd::ZERO;
    n2.add(nf * nf);
    n2.add(nf.mul_add(nf, -(nf * nf)));
    e.plus(n2.neg()).value() / nf.powf(1.5)
}

/// Spherical-cap L2 discrepancy D via Stolarsky's invariance principle:
/// `D² = 1/3 − (1/(4N²)) Σ_{i,j} |x_i − x_j|` (chordal distances, all ordered
/// pairs), returns `D = √D²`.
///
/// Cost O(N²/2) square roots, parallel over rows (about 1.4 s for
/// N = 5·10⁴ on two cores).
///
/// Precision: D² is a difference of two numbers close to 1/3, so it is
/// ill-conditioned in the *inputs*: moving the points by one rounding unit
/// (e.g. rotating them) changes D² by a few 1e-17 absolute. The pair sum is
/// accumulated in double-double and the difference with 1/3 is taken in
/// double-double, so the computation adds far less than that (the chord
/// roundings are random and average out). Measured on the Fibonacci lattice
/// (D² absolute error ≈ 3e-17): relative error of D ≈ 1e-11 at N = 3072
/// and 9e-11 at N = 12288 (a plain f64 sum gives 2e-9 and 6e-7); in general
/// about `1.5e-17 / D²`. Returns NaN for an empty set (or non-finite input);
/// one point gives `1/√3`. A negative D² (possible only for inputs off the
/// sphere) is clamped to 0.
///
/// ```
/// use glam::DVec3;
/// use tessera::metrics::sphere::cap_discrepancy_l2;
/// // Two antipodal points: D² = 1/3 − 4/16 = 1/12.
/// let d = cap_discrepancy_l2(&[DVec3::Z, -DVec3::Z]);
/// assert!((d - (1.0f64 / 12.0).sqrt()).abs() < 1e-15);
/// ```
pub fn cap_discrepancy_l2(points: &[DVec3]) -> f64 {
    let tally = Tally::new("pairs", pairs(points.len()), &quiet);
    let [half_sum] = pair_sums(points, |p, q| [(p - q).length()], &tally);
    cap_discrepancy_from(points.len(), half_sum)
}

/// Normalised Riesz s = 1 energy `(E − N²) / N^1.5`, with
/// `E = Σ_{i≠j} 1/|x_i − x_j|` over ordered pairs (chordal distances).
///
/// The continuous energy of the uniform measure is N², so the value is the
/// second-order coefficient: about −1.106 for (conjectured) optimal
/// configurations, −1.100 for the Fibonacci lattice and about 0 (with
/// fluctuations of order 1) for independent uniform points. Cost O(N²/2),
/// parallel, double-double accumulation. Returns NaN for an empty set, −1 for
/// one point (E = 0), and +∞ if two points coincide.
///
/// ```
/// use glam::DVec3;
/// use tessera::metrics::sphere::riesz1_normalized;
/// // Two antipodal points: E = 2 · 1/2 = 1, (1 − 4) / 2^1.5.
/// let r = riesz1_normalized(&[DVec3::Z, -DVec3::Z]);
/// assert!((r - (-3.0 / 8f64.sqrt())).abs() < 1e-15);
/// ```
pub fn riesz1_normalized(points: &[DVec3]) -> f64 {
    let tally = Tally::new("pairs", pairs(points.len()), &quiet);
    let [half_energy] = pair_sums(points, |p, q| [1.0 / (p - q).length()], &tally);
    riesz1_from(points.len(), half_energy)
}

/// Normalised covering radius `√N · max_{y ∈ S²} min_i d(y, x_i)` (geodesic).
///
/// **Exact** (up to rounding, about 1e-15 rad): the maximum is attained at a
/// vertex of the spherical Voronoi diagram, and each Voronoi cell is computed
/// by clipping a gnomonic chart centred on its site with the bisector
/// great circles of its k nearest neighbours (k-d tree), k being doubled until
/// the radius-of-security test certifies the cell: every neighbour not used is
/// farther than twice the cell's circumradius (chordal). Cells too wide for
/// the chart (a hole of more than about 76°) are recomputed on the six
/// charts of the cube map with all points, where edge interiors and the
/// antipode are also candidates, so any input (N ≥ 1, clusters, coincident
/// points, all points on a great circle) is handled. Cost O(N log N) for
/// well-spread sets (O(N) per wide cell otherwise), parallel; the cells are
/// visited along a Morton curve, so that consecutive queries share the
/// tree's nodes in cache.
///
/// Returns NaN for an empty set and π for one point. For reference, the
/// hexagonal lattice of the same density gives `√(8π / (3√3)) ≈ 2.199` and
/// the spherical Fibonacci lattice about 2.728 (its largest holes are at the
/// poles).
///
/// ```
/// use glam::DVec3;
/// use tessera::metrics::sphere::covering_radius;
/// let octahedron = [DVec3::X, -DVec3::X, DVec3::Y, -DVec3::Y, DVec3::Z, -DVec3::Z];
/// let c = covering_radius(&octahedron) / 6f64.sqrt();
/// assert!((c - (1.0 / 3f64.sqrt()).acos()).abs() < 1e-14);
/// ```
pub fn covering_radius(points: &[DVec3]) -> f64 {
    neighbourhoods(points, (false, true), None, &quiet).1 * (points.len() as f64).sqrt()
}

/// Mesh ratio `2 · covering / min distance` (both unnormalised geodesic
/// distances; equal to `2 · covering_radius / separation`). Always ≥ 1;
/// `2/√3 ≈ 1.155` for the hexagonal lattice, about 1.764 for the spherical
/// Fibonacci lattice. Cost O(N log N). Returns NaN for N < 2 and +∞ if two points
/// coincide.
///
/// ```
/// use tessera::baselines::spherical_fibonacci;
/// use tessera::metrics::sphere::mesh_ratio;
/// let m = mesh_ratio(&spherical_fibonacci(500));
/// assert!(m > 1.0 && m < 2.0);
/// ```
pub fn mesh_ratio(points: &[DVec3]) -> f64 {
    if points.len() < 2 {
        return f64::NAN;
    }
    let (min_angle, cover_angle) = neighbourhoods(points, (true, true), None, &quiet);
    2.0 * cover_angle / min_angle
}

/// Angular power spectrum `P(l) = (1/N) Σ_{i,j} P_l(x_i · x_j)` for
/// `l = 0..=l_max` (all ordered pairs, diagonal included, so `P(0) = N` and
/// `P(l) ≥ 0`; for independent uniform points `E[P(l)] = 1`, l ≥ 1).
///
/// Computed without pairs, by the addition theorem
/// `P_l(x · y) = Σ_{m=0..l} Q_lm(z_x) Q_lm(z_y) cos(m (φ_x − φ_y))`
/// (`Q_lm` the Schmidt semi-normalised associated Legendre functions), so
/// `P(l) = (1/N) Σ_m (C_lm² + S_lm²)` with `C_lm = Σ_i Q_lm(z_i) cos(m φ_i)`
/// and `S_lm` the same with sines: the same numbers as the sum over pairs,
/// to rounding. Cost O(N l_max² / 2), about 10⁹ point-degree-order steps
/// per second of CPU time (1.5 s for N = 20000 and l_max = 425), parallel
/// over blocks of points, memory O(l_max²) per thread. The recurrences run
/// in f64 with the normalised functions (see `harmonic_sums`); for 104
/// points, some at and near the poles, `P(l)` agrees with the sum over
/// pairs to 1.3e-11 up to l = 1024. [`spectrum_degree`] is the `l_max`
/// `tessera metrics sphere --spectrum` uses. Returns `l_max + 1` zeros for
/// an empty set.
///
/// ```
/// use glam::DVec3;
/// use tessera::metrics::sphere::angular_power;
/// let octahedron = [DVec3::X, -DVec3::X, DVec3::Y, -DVec3::Y, DVec3::Z, -DVec3::Z];
/// let p = angular_power(&octahedron, 4);
/// assert_eq!(p[0], 6.0);
/// assert!(p[1].abs() < 1e-12 && p[2].abs() < 1e-12 && p[3].abs() < 1e-12);
/// assert!((p[4] - 3.5).abs() < 1e-12);
/// ```
pub fn angular_power(points: &[DVec3], l_max: usize) -> Vec<f64> {
    angular_power_with(points, l_max, &quiet)
}

/// [`angular_power`], telling `progress` how many of the points are done
/// (stage `"spectrum"`).
///
/// ```
/// use std::sync::atomic::{AtomicU64, Ordering};
/// use tessera::baselines::spherical_fibonacci;
/// use tessera::metrics::sphere::angular_power_with;
/// let done = AtomicU64::new(0);
/// let p = angular_power_with(&spherical_fibonacci(100), 8, &|_, d, _| {
///     done.fetch_max(d, Ordering::Relaxed);
/// });
/// assert_eq!((p.len(), done.into_inner()), (9, 100));
/// ```
pub fn angular_power_with(points: &[DVec3], l_max: usize, progress: Progress) -> Vec<f64> {
    let n = points.len();
    let len = l_max + 1;
    if n == 0 {
        return vec![0.0; len];
    }
    let sums = harmonic_sums(points, l_max, &Tally::new("spectrum", n as u64, progress));
    let nf = n as f64;
    (0..len)
        .map(|l| {
            let power: f64 = (0..=l)
                .map(|m| {
                    let [c, s] = sums[Triangle::at(len, l, m)];
                    c * c + s * s
                })
                .sum();
            power / nf
        })
        .collect()
}

/// The `l_max` of `tessera metrics sphere --spectrum` for N points: `3 √N`
/// (the blue-noise peak of a tessera set is near `l = 2 √N`: the largest
/// `P(l)` of `tessera sphere -n N` is at l = 284 for N = 20000 and 616 for
/// N = 10⁵; the first ring of a hexagonal lattice of the same density is
/// at `1.9 √N`), at least 64,
/// at most [`SPECTRUM_L_CAP`], and lower where [`angular_power`]'s cost,
/// `N (l_max + 1)(l_max + 2) / 2` recurrence steps, would pass
/// [`SPECTRUM_STEPS`]: from about N = 82000 on `l_max` is below `3 √N`,
/// and from about N = 120000 on below the peak.
///
/// ```
/// use tessera::metrics::sphere::spectrum_degree;
/// assert_eq!(spectrum_degree(100), 64);
/// assert_eq!(spectrum_degree(20_000), 425);
/// assert!(spectrum_degree(1_000_000) < 300);
/// ```
pub fn spectrum_degree(n: usize) -> usize {
    let wanted = ((3.0 * (n as f64).sqrt()).ceil() as usize).clamp(64, SPECTRUM_L_CAP);
    // the largest l with N (l + 1)(l + 2) / 2 within the budget
    let affordable = ((2.0 * SPECTRUM_STEPS as f64 / n.max(1) as f64).sqrt() - 1.5).floor();
    wanted.min(affordable.max(1.0) as usize)
}

/// The highest degree [`spectrum_degree`] asks for: the f64 recurrences
/// of [`angular_power`] are checked against the sum over pairs to it.
///
/// ```
/// assert_eq!(tessera::metrics::sphere::SPECTRUM_L_CAP, 1024);
/// ```
pub const SPECTRUM_L_CAP: usize = 1024;

/// The cost budget of [`spectrum_degree`], in point-degree-order
/// recurrence steps (about 25 s of CPU time).
///
/// ```
/// assert_eq!(tessera::metrics::sphere::SPECTRUM_STEPS, 30_000_000_000);
/// ```
pub const SPECTRUM_STEPS: u64 = 30_000_000_000;

/// Index of `(l, m)`, `0 ≤ m ≤ l < len`, in the triangle stored column by
/// column: column `m` holds degrees `m..len`.
struct Triangle;

impl Triangle {
    fn column(len: usize, m: usize) -> usize {
        m * len - m * m.saturating_sub(1) / 2
    }

    fn at(len: usize, l: usize, m: usize) -> usize {
        Self::column(len, m) + (l - m)
    }

    fn size(len: usize) -> usize {
        len * (len + 1) / 2
    }
}

/// Points recurred together: their recurrences are independent, so the
/// steps of a block overlap (and vectorise), and a column of sums stays in
/// cache while the block adds to it.
const BLOCK: usize = 64;

/// Scale of the sectoral values' exponent (see `harmonic_sums`): 2^256.
const BIG: f64 = 1.157_920_892_373_162e77;

/// `[C_lm, S_lm]` for `0 ≤ m ≤ l ≤ l_max`, indexed by [`Triangle::at`].
///
/// Per point `Q_lm(z)` is recurred up in `l` for each `m` from the
/// sectoral `Q_mm = sqrt((2m−1)/(2m)) sin θ Q_{m−1,m−1}` by
/// `Q_lm = ((2l−1) z Q_{l−1,m} − sqrt((l−1)²−m²) Q_{l−2,m}) / sqrt(l²−m²)`.
/// Normalised functions are at most 1 in magnitude, so nothing overflows
/// (the unnormalised `P_ll` is `(2l−1)!! sin^l θ`, and `(2l−1)!!` passes
/// f64 at l = 151). They can underflow: `Q_mm ~ sin^m θ` is below 1e-308
/// within 30° of a pole at m = 1024, while `Q_lm` for larger `l` grows
/// back to matter. So the
/// sectoral value is kept as a mantissa times `BIG^−e`, and a point whose
/// `e > 0` is recurred silently (scaled, rescaled by `BIG` whenever it
/// passes 1) until `e` reaches 0; it is added from that degree on, and
/// never if it stays below `BIG^−1 ≈ 1e-77` up to `l_max`.
fn harmonic_sums(points: &[DVec3], l_max: usize, tally: &Tally) -> Vec<[f64; 2]> {
    let len = l_max + 1;
    let size = Triangle::size(len);
    // (a, b) of Q_lm = a z Q_{l−1,m} − b Q_{l−2,m}; at l = m + 1, b = 0
    let coef: Vec<[f64; 2]> = (0..len)
        .flat_map(|m| {
            (m..len).map(move |l| {
                let (lf, mf) = (l as f64, m as f64);
                if l == m {
                    return [0.0, 0.0];
                }
                let d = ((lf - mf) * (lf + mf)).sqrt();
                let b = ((lf - 1.0 - mf) * (lf - 1.0 + mf)).max(0.0).sqrt();
                [(2.0 * lf - 1.0) / d, b / d]
            })
        })
        .collect();
    let blocks = n_blocks(points.len());
    let threads = rayon::current_num_threads();
    points
        .par_chunks(BLOCK)
        .with_min_len(blocks.div_ceil(2 * threads).max(1))
        .fold(
            || vec![[0.0f64; 2]; size],
            |mut sums, block| {
                Block::new(block).add_to(&mut sums, &coef, len);
                tally.add(block.len() as u64);
                sums
            },
        )
        .reduce(
            || vec![[0.0f64; 2]; size],
            |mut a, b| {
                a.iter_mut().zip(&b).for_each(|(x, y)| {
                    x[0] += y[0];
                    x[1] += y[1];
                });
                a
            },
        )
}

/// Number of [`BLOCK`]s covering `n` points.
fn n_blocks(n: usize) -> usize {
    n.div_ceil(BLOCK)
}

/// The per-point state of [`harmonic_sums`] for one block (padding lanes
/// have all-zero weights and add nothing).
struct Block {
    z: [f64; BLOCK],
    /// `sin θ`, and `cos φ`, `sin φ`.
    s: [f64; BLOCK],
    cos_phi: [f64; BLOCK],
    sin_phi: [f64; BLOCK],
    /// `cos mφ`, `sin mφ` for the current `m`.
    cos_m: [f64; BLOCK],
    sin_m: [f64; BLOCK],
    /// The sectoral `Q_mm = sectoral · BIG^−exponent`.
    sectoral: [f64; BLOCK],
    exponent: [i32; BLOCK],
}

impl Block {
    fn new(points: &[DVec3]) -> Self {
        let mut b = Block {
            z: [0.0; BLOCK],
            s: [0.0; BLOCK],
            cos_phi: [0.0; BLOCK],
            sin_phi: [0.0; BLOCK],
            cos_m: [0.0; BLOCK],
            sin_m: [0.0; BLOCK],
            sectoral: [0.0; BLOCK],
            exponent: [0; BLOCK],
        };
        for (k, p) in points.iter().enumerate() {
            // sin θ from x and y: accurate near the poles
            let s = p.x.hypot(p.y);
            b.z[k] = p.z;
            b.s[k] = s;
            (b.cos_phi[k], b.sin_phi[k]) = if s > 0.0 {
                (p.x / s, p.y / s)
            } else {
                (1.0, 0.0)
            };
            b.cos_m[k] = 1.0;
            b.sectoral[k] = 1.0;
        }
        b
    }

    /// Adds the block's `[C_lm, S_lm]` to `sums`.
    fn add_to(mut self, sums: &mut [[f64; 2]], coef: &[[f64; 2]], len: usize) {
        let mut q0 = [0.0f64; BLOCK];
        let mut q1 = [0.0f64; BLOCK];
        // points that become large enough at a degree above m: (l, lane,
        // Q_{l−1,m}, Q_lm)
        let mut pending: Vec<(usize, usize, f64, f64)> = Vec::new();
        for m in 0..len {
            if m > 0 {
                let f = if m == 1 {
                    1.0
                } else {
                    ((2 * m - 1) as f64 / (2 * m) as f64).sqrt()
                };
                for k in 0..BLOCK {
                    let (c, s) = (self.cos_m[k], self.sin_m[k]);
                    self.cos_m[k] = c * self.cos_phi[k] - s * self.sin_phi[k];
                    self.sin_m[k] = s * self.cos_phi[k] + c * self.sin_phi[k];
                    let mut v = self.sectoral[k] * f * self.s[k];
                    while v != 0.0 && v < 1.0 / BIG {
                        v *= BIG;
                        self.exponent[k] += 1;
                    }
                    self.sectoral[k] = v;
                }
            }
            let col = Triangle::column(len, m);
            let coef = &coef[col..col + len - m];
            pending.clear();
            for k in 0..BLOCK {
                q0[k] = 0.0;
                q1[k] = 0.0;
                if self.sectoral[k] == 0.0 {
                    continue;
                }
                if self.exponent[k] == 0 {
                    q1[k] = self.sectoral[k];
                    continue;
                }
                // silent: scaled by BIG^e until e = 0
                let (mut a0, mut a1, mut e) = (0.0, self.sectoral[k], self.exponent[k]);
                for (l, &[a, b]) in coef.iter().enumerate().skip(1) {
                    let next = a * self.z[k] * a1 - b * a0;
                    (a0, a1) = (a1, next);
                    if a1.abs() > 1.0 {
                        a0 /= BIG;
                        a1 /= BIG;
                        e -= 1;
                        if e == 0 {
                            pending.push((m + l, k, a0, a1));
                            break;
                        }
                    }
                }
            }
            if q1.iter().all(|&v| v == 0.0) && pending.is_empty() {
                continue;
            }
            pending.sort_unstable_by_key(|p| p.0);
            let mut next = 0;
            for (i, &[a, b]) in coef.iter().enumerate() {
                let l = m + i;
                if i > 0 {
                    for k in 0..BLOCK {
                        let q = a * self.z[k] * q1[k] - b * q0[k];
                        q0[k] = q1[k];
                        q1[k] = q;
                    }
                }
                while next < pending.len() && pending[next].0 == l {
                    let (_, k, a0, a1) = pending[next];
                    (q0[k], q1[k]) = (a0, a1);
                    next += 1;
                }
                // four partial sums, so that the additions overlap
                let (mut c, mut s) = ([0.0f64; 4], [0.0f64; 4]);
                for k in (0..BLOCK).step_by(4) {
                    for j in 0..4 {
                        c[j] += q1[k + j] * self.cos_m[k + j];
                        s[j] += q1[k + j] * self.sin_m[k + j];
                    }
                }
                let sum = &mut sums[col + i];
                sum[0] += (c[0] + c[1]) + (c[2] + c[3]);
                sum[1] += (s[0] + s[1]) + (s[2] + s[3]);
            }
        }
    }
}

/// The measures of [`measure`], by their keys in reports.
///
/// ```
/// use tessera::metrics::{Measure, SphereMeasure};
/// let keys: Vec<_> = SphereMeasure::ALL.iter().map(|m| m.key()).collect();
/// assert_eq!(keys[0], "separation_sqrt_n");
/// ```
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum SphereMeasure {
    /// [`separation`].
    Separation,
    /// [`cap_discrepancy_l2`].
    CapDiscrepancy,
    /// [`riesz1_normalized`].
    Energy,
    /// [`covering_radius`].
    Covering,
    /// [`mesh_ratio`].
    MeshRatio,
}

impl Measure for SphereMeasure {
    const ALL: &'static [Self] = &[
        SphereMeasure::Separation,
        SphereMeasure::CapDiscrepancy,
        SphereMeasure::Energy,
        SphereMeasure::Covering,
        SphereMeasure::MeshRatio,
    ];

    fn key(self) -> &'static str {
        match self {
            SphereMeasure::Separation => "separation_sqrt_n",
            SphereMeasure::CapDiscrepancy => "cap_discrepancy_l2",
            SphereMeasure::Energy => "riesz1_excess_over_n1_5",
            SphereMeasure::Covering => "covering_radius_sqrt_n",
            SphereMeasure::MeshRatio => "mesh_ratio",
        }
    }

    fn meaning(self) -> &'static str {
        match self {
            SphereMeasure::Separation => {
                "sqrt(N) x the smallest geodesic angle between two points (radians). \
                 Higher is better: spherical Fibonacci 3.092 at N = 3072, independent \
                 uniform points near 0. Cost O(N log N)."
            }
            SphereMeasure::CapDiscrepancy => {
                "Spherical-cap L2 discrepancy D, not normalised: \
                 D^2 = 1/3 - sum over all ordered pairs of |x_i - x_j| / (4 N^2) \
                 (Stolarsky, chordal distances). Lower is better: spherical Fibonacci \
                 1.092e-3 at N = 3072, uniform random 1.348e-2. Cost O(N^2)."
            }
            SphereMeasure::Energy => {
                "(E - N^2) / N^1.5 with E = sum over ordered pairs i != j of \
                 1 / |x_i - x_j| (Riesz s = 1 energy, chordal): N^2 is the energy of \
                 the uniform measure, so this is the next term. Lower is better: \
                 spherical Fibonacci -1.100 at N = 3072, independent uniform points \
                 near 0. Cost O(N^2)."
            }
            SphereMeasure::Covering => {
                "sqrt(N) x the covering radius: the largest geodesic angle (radians) \
                 from a point of the sphere to its nearest sample, exact (spherical \
                 Voronoi cells). Lower is better: hexagonal lattice \
                 sqrt(8 pi / (3 sqrt 3)) = 2.199, spherical Fibonacci 2.728 at \
                 N = 3072. Cost O(N log N)."
            }
            SphereMeasure::MeshRatio => {
                "2 x covering radius / smallest distance (both geodesic angles), \
                 dimensionless, at least 1: hexagonal lattice 2 / sqrt 3 = 1.155, \
                 spherical Fibonacci 1.764 at N = 3072; infinite when two points \
                 coincide. Lower is better. Cost O(N log N)."
            }
        }
    }

    fn quadratic(self) -> bool {
        matches!(self, SphereMeasure::CapDiscrepancy | SphereMeasure::Energy)
    }
}

/// A point's spacing scale: angles near it are multiplied by it.
type Scale<'a> = &'a (dyn Fn(DVec3) -> f64 + Sync);

/// Smallest geodesic angle between two points and covering radius
/// (radians) in one pass over one k-d tree, visiting the points in
/// [`spatial_order`] for cache locality; each is computed only if asked
/// for (NaN otherwise). With a `scale`, each nearest-neighbour angle is
/// multiplied by the larger scale of its two ends, and each cell's radius
/// by the scale at its farthest point. Empty set: NaN, NaN; one point:
/// +∞, π.
fn neighbourhoods(
    points: &[DVec3],
    (min, cover): (bool, bool),
    scale: Option<Scale>,
    progress: Progress,
) -> (f64, f64) {
    let n = points.len();
    match n {
        0 => return (f64::NAN, f64::NAN),
        1 => return (f64::INFINITY, PI),
        _ => {}
    }
    let sorted: Vec<DVec3> = spatial_order(points)
        .into_par_iter()
        .map(|i| points[i])
        .collect();
    let tree = build_tree(&sorted);
    let tally = Tally::new("neighbours", n as u64, progress);
    let at = |x: DVec3| scale.map_or(1.0, |s| s(x));
    let (min_angle, cover_angle) = (0..n)
        .into_par_iter()
        .map_init(Vec::new, |normals, i| {
            // the covering cell's neighbours include the nearest one
            let (c, nearest) = if cover {
                let cell = cell_of(
                    &sorted,
                    (n > 64).then_some(&tree),
                    i,
                    normals,
                    f64::INFINITY,
                );
                (cell.radius * at(cell.farthest), cell.nearest)
            } else {
                (f64::NAN, Some(nearest_other(&tree, &sorted, i)))
            };
            let d = match (min, nearest) {
                (true, Some(j)) => {
                    geodesic_distance(sorted[i], sorted[j]) * at(sorted[i]).max(at(sorted[j]))
                }
                _ => f64::NAN,
            };
            tally.add(1);
            (d, c)
        })
        .reduce(|| (f64::INFINITY, 0.0), |a, b| (a.0.min(b.0), a.1.max(b.1)));
    (
        if min { min_angle } else { f64::NAN },
        if cover { cover_angle } else { f64::NAN },
    )
}

/// Separation, covering radius and mesh ratio in units of the spacing a
/// density asks for where they are measured (what `tessera sphere
/// --report` prints); see [`local_spacing`].
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct LocalSpacing {
    /// The smallest nearest-neighbour angle times `√(4π N pdf)`, the pdf
    /// the larger of the pair's two ends.
    pub separation: f64,
    /// The largest Voronoi cell radius times `√(4π N pdf)` at the cell's
    /// farthest point (0 where the pdf is 0: no sample is owed there).
    pub covering_radius: f64,
    /// `2 · covering_radius / separation`.
    pub mesh_ratio: f64,
}

/// The measures of [`LocalSpacing`] for points drawn with `pdf` (per
/// steradian): every angle is multiplied by `√(4π N pdf)`, which is `√N`
/// for a uniform pdf, so that a set following a density exactly reads as
/// a uniform set of the same quality would: for a uniform pdf the fields
/// equal [`separation`], [`covering_radius`] and [`mesh_ratio`]. A
/// piecewise-constant density (regions, maps) measures each level in its
/// own spacing, as `examples/geodesy.rs` does per level. Cost
/// O(N log N) plus 3N evaluations of `pdf`.
///
/// ```
/// use std::f64::consts::PI;
/// use tessera::baselines::spherical_fibonacci;
/// use tessera::metrics::sphere::{local_spacing, separation};
/// let points = spherical_fibonacci(1000);
/// let local = local_spacing(&points, |_| 1.0 / (4.0 * PI));
/// assert!((local.separation - separation(&points)).abs() < 1e-12);
/// ```
pub fn local_spacing(points: &[DVec3], pdf: impl Fn(DVec3) -> f64 + Sync) -> LocalSpacing {
    let n = points.len() as f64;
    let scale = |x: DVec3| (4.0 * PI * n * pdf(x).max(0.0)).sqrt();
    let (separation, covering_radius) = neighbourhoods(points, (true, true), Some(&scale), &quiet);
    LocalSpacing {
        separation,
        covering_radius,
        mesh_ratio: if points.len() < 2 {
            f64::NAN
        } else {
            2.0 * covering_radius / separation
        },
    }
}

/// The measures `options` ask for (all by default, the O(N²) ones only up
/// to [`Options::pairs_up_to`] points), sharing work between them: one
/// k-d tree pass for separation, covering radius and mesh ratio, one pair
/// pass for cap discrepancy and energy. Values equal those of the
/// functions named in [`SphereMeasure`] (up to rounding for the mesh
/// ratio).
///
/// ```
/// use tessera::baselines::spherical_fibonacci;
/// use tessera::metrics::{sphere, Options, SphereMeasure};
/// let points = spherical_fibonacci(300);
/// let options = Options { pairs_up_to: 100, ..Options::default() };
/// let r = sphere::measure(&points, &options);
/// assert_eq!(r.get(SphereMeasure::Energy), None);
/// assert_eq!(r[SphereMeasure::Covering], sphere::covering_radius(&points));
/// ```
pub fn measure(points: &[DVec3], options: &Options<SphereMeasure>) -> Report<SphereMeasure> {
    use SphereMeasure::*;
    let n = points.len();
    let computes = |m| options.computes(m, n);
    let (min_angle, cover_angle) = neighbourhoods(
        points,
        (
            computes(Separation) || computes(MeshRatio),
            computes(Covering) || computes(MeshRatio),
        ),
        None,
        options.progress,
    );
    // one pass for both sums, each only if asked for
    let tally = || Tally::new("pairs", pairs(n), options.progress);
    let [half_sum, half_energy] = match (computes(CapDiscrepancy), computes(Energy)) {
        (false, false) => [Dd::ZERO; 2],
        (true, false) => [
            pair_sums(points, |p, q| [(p - q).length()], &tally())[0],
            Dd::ZERO,
        ],
        (false, true) => [
            Dd::ZERO,
            pair_sums(points, |p, q| [1.0 / (p - q).length()], &tally())[0],
        ],
        (true, true) => pair_sums(
            points,
            |p, q| {
                let d = (p - q).length();
                [d, 1.0 / d]
            },
            &tally(),
        ),
    };
    let root_n = (n as f64).sqrt();
    Report::new(n, options, |m| match m {
        Separation => min_angle * root_n,
        CapDiscrepancy => cap_discrepancy_from(n, half_sum),
        Energy => riesz1_from(n, half_energy),
        Covering => cover_angle * root_n,
        MeshRatio if n < 2 => f64::NAN,
        MeshRatio => 2.0 * cover_angle / min_angle,
    })
}

/// Every measure of [`SphereMeasure`], whatever N (the O(N²) ones cost
/// about 0.1 s for N = 10⁴ on two cores).
///
/// ```
/// use tessera::baselines::spherical_fibonacci;
/// use tessera::metrics::{sphere_report, SphereMeasure::*};
/// let r = sphere_report(&spherical_fibonacci(300));
/// assert!((r[MeshRatio] - 2.0 * r[Covering] / r[Separation]).abs() < 1e-12);
/// ```
pub fn sphere_report(points: &[DVec3]) -> Report<SphereMeasure> {
    let options = Options {
        pairs_up_to: usize::MAX,
        ..Options::default()
    };
    measure(points, &options)
}

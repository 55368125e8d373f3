//! Baseline point sets to compare samplers against: the spherical Fibonacci
//! lattice, independent uniform points on the sphere and in the square, the
//! jittered grid and jittered HEALPix, weighted sample elimination
//! ([`elimination`]), exact farthest-point ordering ([`farthest_point`]),
//! Owen-scrambled Sobol ([`sobol`])
//! warped by inverse CDFs ([`cdf`], [`envmap`]), with a small self-contained RNG ([`SplitMix64`]) so
//! that results are reproducible from a seed without extra dependencies.
//!
//! ```
//! use tessera::baselines::{jittered_grid_2d, spherical_fibonacci, uniform_random_sphere};
//! assert_eq!(spherical_fibonacci(12).len(), 12);
//! assert_eq!(uniform_random_sphere(5, 7), uniform_random_sphere(5, 7));
//! assert_eq!(jittered_grid_2d(3, 0).len(), 9);
//! ```

pub mod cdf;
pub mod elimination;
pub mod envmap;
pub mod farthest_point;
pub mod median_cut;
pub mod sobol;

pub use crate::random::{random_rotation, SplitMix64};
use glam::{DVec2, DVec3};
use std::f64::consts::TAU;

/// `2^128 / φ` rounded down: `i` times it, modulo `2^128`, is
/// `frac(i / φ)` in 128-bit fixed point.
const INV_PHI_FIXED: u128 = 0x9e37_79b9_7f4a_7c15_f39c_c060_5ced_c834;

/// `frac(i / φ)` within 2^-53 for every `i < 2^64` (the constant's
/// truncation, times `i`, stays below 2^-64; the result keeps 53 bits):
/// the reduction is one 128-bit product. The double-double form it
/// replaced called `fma` from libm and made the lattice 22 % slower than
/// plain code.
#[inline]
fn frac_inv_phi(i: u64) -> f64 {
    const ULP: f64 = 1.0 / (1u64 << 53) as f64;
    let fixed = (i as u128).wrapping_mul(INV_PHI_FIXED);
    ((fixed >> 75) as u64) as f64 * ULP
}

/// Streams the spherical Fibonacci lattice of `n` points to `f`, in order
/// `i = 0..n`, without allocating: `z_i = 1 − (2i+1)/n`,
/// `φ_i = 2π frac(i/φ)` (golden ratio φ), and
/// `sin θ_i = √((2i+1)(2n−2i−1)) / n` (the `(1−z)(1+z)` form, accurate near
/// the poles). The azimuth is reduced modulo 2π in fixed point, so it is
/// accurate for any `n` (no loss for large i).
///
/// ```
/// use tessera::baselines::spherical_fibonacci_into;
/// let mut sum = glam::DVec3::ZERO;
/// spherical_fibonacci_into(1000, |p| sum += p);
/// assert!(sum.length() < 1.0);
/// ```
pub fn spherical_fibonacci_into(n: usize, mut f: impl FnMut(DVec3)) {
    let nf = n as f64;
    for i in 0..n {
        let a = (2 * i + 1) as f64; // n (1 − z)
        let b = (2 * (n - i) - 1) as f64; // n (1 + z)
        let z = if a <= b { 1.0 - a / nf } else { b / nf - 1.0 };
        let sin_theta = (a * b).sqrt() / nf;
        let (s, c) = (TAU * frac_inv_phi(i as u64)).sin_cos();
        f(DVec3::new(sin_theta * c, sin_theta * s, z));
    }
}

/// The spherical Fibonacci lattice of `n` points (see
/// [`spherical_fibonacci_into`] for the formulas). Cost O(n).
///
/// ```
/// use tessera::baselines::spherical_fibonacci;
/// let pts = spherical_fibonacci(100);
/// assert_eq!(pts.len(), 100);
/// assert!(pts.iter().all(|p| (p.length() - 1.0).abs() < 1e-15));
/// assert!((pts[0].z - 0.99).abs() < 1e-15);
/// ```
pub fn spherical_fibonacci(n: usize) -> Vec<DVec3> {
    let mut out = Vec::with_capacity(n);
    spherical_fibonacci_into(n, |p| out.push(p));
    out
}

/// `n` independent uniform points on the unit sphere (Archimedes: z uniform
/// in (−1, 1], azimuth uniform), reproducible from `seed` with
/// [`SplitMix64`]. `sin θ = 2√(u(1−u))` avoids cancellation near the poles.
///
/// ```
/// use tessera::baselines::uniform_random_sphere;
/// let pts = uniform_random_sphere(1000, 1);
/// assert!(pts.iter().all(|p| (p.length() - 1.0).abs() < 1e-15));
/// assert_eq!(pts, uniform_random_sphere(1000, 1));
/// ```
pub fn uniform_random_sphere(n: usize, seed: u64) -> Vec<DVec3> {
    let mut rng = SplitMix64::new(seed);
    (0..n)
        .map(|_| {
            let u = rng.next_f64();
            equal_area(DVec2::new(u, rng.next_f64()))
        })
        .collect()
}

/// Archimedes' equal-area map of `[0, 1)²` onto the unit sphere:
/// `z = 1 − 2u.x`, azimuth `2π u.y`; `sin θ = 2√(u(1−u))` avoids
/// cancellation near the poles. Uniform in, uniform out.
///
/// ```
/// use tessera::baselines::equal_area;
/// let v = equal_area(glam::DVec2::new(0.5, 0.25));
/// assert!((v - glam::DVec3::Y).length() < 1e-15);
/// ```
pub fn equal_area(u: DVec2) -> DVec3 {
    let z = 1.0 - 2.0 * u.x;
    let sin_theta = 2.0 * (u.x * (1.0 - u.x)).sqrt();
    let (s, c) = (TAU * u.y).sin_cos();
    DVec3::new(sin_theta * c, sin_theta * s, z)
}

/// Largest f64 below 1.
const BELOW_ONE: f64 = 1.0 - f64::EPSILON / 2.0;

/// Jittered (stratified) grid of `n_side²` points in `[0, 1)²`: one uniform
/// point in each cell `[i/n, (i+1)/n) × [j/n, (j+1)/n)`, row-major (`j`
/// slow, `i` fast), reproducible from `seed`. Coordinates are clamped below 1.
///
/// ```
/// use tessera::baselines::jittered_grid_2d;
/// let pts = jittered_grid_2d(4, 2);
/// assert_eq!(pts.len(), 16);
/// assert!(pts[5].x >= 0.25 && pts[5].x < 0.5 && pts[5].y >= 0.25 && pts[5].y < 0.5);
/// ```
pub fn jittered_grid_2d(n_side: usize, seed: u64) -> Vec<DVec2> {
    let mut rng = SplitMix64::new(seed);
    let s = n_side as f64;
    let mut out = Vec::with_capacity(n_side * n_side);
    for j in 0..n_side {
        for i in 0..n_side {
            let x = ((i as f64 + rng.next_f64()) / s).min(BELOW_ONE);
            let y = ((j as f64 + rng.next_f64()) / s).min(BELOW_ONE);
            out.push(DVec2::new(x, y));
        }
    }
    out
}

/// `n` independent uniform points in `[0, 1)²`, reproducible from `seed`.
///
/// ```
/// use tessera::baselines::uniform_random_2d;
/// let pts = uniform_random_2d(100, 3);
/// assert!(pts.iter().all(|p| p.x >= 0.0 && p.x < 1.0 && p.y >= 0.0 && p.y < 1.0));
/// ```
pub fn uniform_random_2d(n: usize, seed: u64) -> Vec<DVec2> {
    let mut rng = SplitMix64::new(seed);
    (0..n)
        .map(|_| {
            let x = rng.next_f64();
            DVec2::new(x, rng.next_f64())
        })
        .collect()
}

/// Jittered HEALPix: one uniformly random point in each of the
/// `12 nside^2` equal-area cells (stratified sampling of the sphere).
///
/// # Example
/// ```
/// let p = tessera::baselines::jittered_healpix(16, 7);
/// assert_eq!(p.len(), 3072);
/// assert!(p.iter().all(|v| (v.length() - 1.0).abs() < 1e-12));
/// ```
pub fn jittered_healpix(nside: usize, seed: u64) -> Vec<DVec3> {
    let mut rng = SplitMix64::new(seed);
    let mut out = Vec::with_capacity(12 * nside * nside);
    for face in 0..12u8 {
        for j in 0..nside {
            for i in 0..nside {
                let x = (i as f64 + rng.next_f64()) / nside as f64;
                let y = (j as f64 + rng.next_f64()) / nside as f64;
                out.push(crate::healpix::FacePoint::new(face, x, y).to_vec());
            }
        }
    }
    out
}

/// [`jittered_healpix`] at the `nside` whose `12 nside²` cells come
/// nearest to `n` (at least 12 points).
///
/// # Example
/// ```
/// assert_eq!(tessera::baselines::jittered_healpix_about(1000, 1).len(), 12 * 9 * 9);
/// ```
pub fn jittered_healpix_about(n: usize, seed: u64) -> Vec<DVec3> {
    let nside = ((n as f64 / 12.0).sqrt().round() as usize).max(1);
    jittered_healpix(nside, seed)
}

/// Bridson's Poisson-disk sampling of the unit square (the `fast_poisson`
/// crate) with the radius `√(0.7 / n)` that gives about `n` points (the
/// count varies with the seed; a maximal set at this radius holds about
/// 0.7 / r² points).
///
/// ```
/// let p = tessera::baselines::bridson(1000, 1);
/// assert!((800..1200).contains(&p.len()));
/// assert!(p.iter().all(|q| q.x >= 0.0 && q.x < 1.0 && q.y >= 0.0 && q.y < 1.0));
/// ```
pub fn bridson(n: usize, seed: u64) -> Vec<DVec2> {
    let radius = (0.7 / n.max(1) as f64).sqrt();
    fast_poisson::Poisson2D::new()
        .with_dimensions([1.0, 1.0], radius)
        .with_seed(seed)
        .iter()
        .map(|[x, y]| DVec2::new(x, y).min(DVec2::splat(BELOW_ONE)))
        .collect()
}

#[cfg(test)]
mod tests {
    use super::frac_inv_phi;

    #[test]
    fn golden_fraction_is_exact_for_huge_indices() {
        // frac(i / φ) to 80 digits (Python's decimal module), rounded to f64
        let reference = [
            (1, 0.6180339887498949),
            (1_000_000_000, 0.7498948482045869),
            ((1 << 40) + 7, 0.6171938195109653),
            ((1 << 60) + 3, 0.22607762797604747),
        ];
        for (i, want) in reference {
            approx::assert_abs_diff_eq!(frac_inv_phi(i), want, epsilon = 2e-16);
        }
        assert_eq!(frac_inv_phi(0), 0.0);
    }
}

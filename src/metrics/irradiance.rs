//! Irradiance `E(n) = integral of L(w) max(0, n . w) dw` from an environment
//! map: the reference value by quadrature over the map's own pixels, the
//! Monte Carlo estimate `(1/N) sum L(w_i) max(0, n . w_i) / pdf(w_i)` from
//! samples, and the relative RMSE over several normals.
//!
//! ```
//! use tessera::density::envmap::{EnvMap, Up};
//! use tessera::io::image::Raster;
//! use tessera::metrics::irradiance::{estimate, exact};
//! let map = EnvMap::new(Raster { width: 8, height: 4, values: vec![1.0; 32], bad_pixels: 0 }, Up::Z).unwrap();
//! // a constant unit sky gives pi on every normal
//! let e = exact(&map, &[glam::DVec3::Z]);
//! assert!((e[0] - std::f64::consts::PI).abs() < 1e-3);
//! let s: Vec<_> = map.generate(4096).unwrap().iter().map(|s| s.position).collect();
//! assert!((estimate(&map, &s, glam::DVec3::Z) / e[0] - 1.0).abs() < 0.01);
//! ```

use crate::density::envmap::EnvMap;
use glam::DVec3;
use rayon::prelude::*;

/// Reference irradiance for each normal: a midpoint rule on 4x4 sub-pixels
/// (uniform in solid angle) of every lit pixel, 32x32 for pixels holding
/// more than 1e-4 of the map's integral (a sun).
///
/// # Example
/// ```
/// # use tessera::{density::envmap::{EnvMap, Up}, io::image::Raster, metrics::irradiance::exact};
/// let map = EnvMap::new(Raster { width: 8, height: 4, values: vec![2.0; 32], bad_pixels: 0 }, Up::Z).unwrap();
/// assert!((exact(&map, &[glam::DVec3::X])[0] - 2.0 * std::f64::consts::PI).abs() < 1e-3);
/// ```
pub fn exact(map: &EnvMap, normals: &[DVec3]) -> Vec<f64> {
    exact_lobe(map, normals, |c| c.max(0.0))
}

/// Reference integral `integral of L(w) lobe(a . w) dw` for each axis `a`,
/// by [`exact`]'s quadrature: a Phong lobe is `max(0, c)^m`.
///
/// # Example
/// ```
/// # use tessera::{density::envmap::{EnvMap, Up}, io::image::Raster, metrics::irradiance::exact_lobe};
/// let map = EnvMap::new(Raster { width: 8, height: 4, values: vec![1.0; 32], bad_pixels: 0 }, Up::Z).unwrap();
/// // a constant unit sky: the Phong lobe of exponent 10 integrates to 2 pi / 11
/// let g = exact_lobe(&map, &[glam::DVec3::Z], |c| c.max(0.0).powi(10));
/// assert!((g[0] - std::f64::consts::TAU / 11.0).abs() < 1e-2);
/// ```
pub fn exact_lobe(map: &EnvMap, axes: &[DVec3], lobe: impl Fn(f64) -> f64 + Sync) -> Vec<f64> {
    quadrature(map, axes.len(), |d, weight, sums| {
        for (sum, n) in sums.iter_mut().zip(axes) {
            *sum += weight * lobe(n.dot(d));
        }
    })
}

/// Runs [`exact`]'s quadrature for several integrands at once: `add(d,
/// weight, sums)` adds each integrand's value at node `d`, times
/// `weight` (radiance times solid angle), into its entry of `sums`
/// (`len` of them). One pass over the map serves every integrand.
///
/// # Example
/// ```
/// # use tessera::{density::envmap::{EnvMap, Up}, io::image::Raster, metrics::irradiance::quadrature};
/// let map = EnvMap::new(Raster { width: 8, height: 4, values: vec![1.0; 32], bad_pixels: 0 }, Up::Z).unwrap();
/// // the map's integral and its irradiance facing up, in one pass
/// let sums = quadrature(&map, 2, |d, w, s| {
///     s[0] += w;
///     s[1] += w * d.z.max(0.0);
/// });
/// assert!((sums[0] - 4.0 * std::f64::consts::PI).abs() < 1e-9);
/// assert!((sums[1] - std::f64::consts::PI).abs() < 1e-3);
/// ```
pub fn quadrature(
    map: &EnvMap,
    len: usize,
    add: impl Fn(DVec3, f64, &mut [f64]) + Sync,
) -> Vec<f64> {
    let (w, h) = (map.width(), map.height());
    // row by row: each row's sub-pixel nodes against every integrand
    (0..h)
        .into_par_iter()
        .map(|j| {
            let mut sums = vec![0.0; len];
            for i in 0..w {
                let v = map.values()[j * w + i];
                if v <= 0.0 {
                    continue;
                }
                let mass = v * map.pixel_solid_angle(j);
                let k = if mass > 1e-4 * map.integral() { 32 } else { 4 };
                let weight = mass / (k * k) as f64;
                for s in 0..k * k {
                    let (u, t) = (
                        ((s % k) as f64 + 0.5) / k as f64,
                        ((s / k) as f64 + 0.5) / k as f64,
                    );
                    add(map.direction_in_pixel(i, j, u, t), weight, &mut sums);
                }
            }
            sums
        })
        .reduce(
            || vec![0.0; len],
            |mut a, b| {
                a.iter_mut().zip(b).for_each(|(x, y)| *x += y);
                a
            },
        )
}

/// The Monte Carlo estimate of `E(normal)` from samples of the map's pdf
/// ([`EnvMap::pdf`]); samples where the pdf is 0 contribute nothing.
///
/// # Example
/// ```
/// # use tessera::{density::envmap::{EnvMap, Up}, io::image::Raster, metrics::irradiance::estimate};
/// let map = EnvMap::new(Raster { width: 2, height: 1, values: vec![1.0, 1.0], bad_pixels: 0 }, Up::Z).unwrap();
/// // all the mass of one direction along the normal: 4 pi radiance-weighted
/// assert!((estimate(&map, &[glam::DVec3::Z], glam::DVec3::Z) - 4.0 * std::f64::consts::PI).abs() < 1e-9);
/// ```
pub fn estimate(map: &EnvMap, samples: &[DVec3], normal: DVec3) -> f64 {
    let sum: f64 = samples
        .iter()
        .map(|&d| {
            let pdf = map.pdf(d);
            if pdf > 0.0 {
                map.radiance(d) * normal.dot(d).max(0.0) / pdf
            } else {
                0.0
            }
        })
        .sum();
    sum / samples.len().max(1) as f64
}

/// Relative RMSE of estimates against references:
/// `sqrt(mean(((e - r) / r)^2))`, over the pairs with `r > 0`.
///
/// # Example
/// ```
/// use tessera::metrics::irradiance::relative_rmse;
/// assert!((relative_rmse(&[1.1, 0.9], &[1.0, 1.0]) - 0.1).abs() < 1e-12);
/// ```
pub fn relative_rmse(estimates: &[f64], references: &[f64]) -> f64 {
    let (sum, count) = estimates
        .iter()
        .zip(references)
        .filter(|(_, &r)| r > 0.0)
        .fold((0.0, 0usize), |(s, c), (e, r)| {
            (s + ((e - r) / r).powi(2), c + 1)
        });
    (sum / count.max(1) as f64).sqrt()
}

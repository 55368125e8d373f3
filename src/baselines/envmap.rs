//! The i.i.d. samplers renderers use for lat-long environment maps, as
//! baselines: inverse-CDF sampling (marginal over rows, conditional over
//! columns, two binary searches on f64 CDFs) and Walker/Vose alias tables
//! over all pixels. Both pick a pixel with probability proportional to its
//! value times its solid angle, then a direction uniform in solid angle
//! inside it, so their pdf is [`EnvMap::pdf`].
//!
//! ```
//! use tessera::baselines::envmap::{AliasTable, InverseCdf};
//! use tessera::density::envmap::{EnvMap, Up};
//! use tessera::io::image::Raster;
//! let map = EnvMap::new(Raster { width: 4, height: 2, values: vec![0.0, 1.0, 0.0, 0.0, 0.0, 0.0, 2.0, 0.0], bad_pixels: 0 }, Up::Z).unwrap();
//! for d in InverseCdf::new(&map).samples(100, 1).into_iter().chain(AliasTable::new(&map).samples(100, 1)) {
//!     assert!(map.pdf(d) > 0.0);
//! }
//! ```

use crate::baselines::cdf::GridCdf;
use crate::baselines::SplitMix64;
use crate::density::envmap::EnvMap;
use glam::DVec3;

/// `n` directions from four SplitMix64 numbers each.
fn draw(n: usize, seed: u64, sample: impl Fn([f64; 4]) -> DVec3) -> Vec<DVec3> {
    let mut rng = SplitMix64::new(seed);
    (0..n)
        .map(|_| {
            sample([
                rng.next_f64(),
                rng.next_f64(),
                rng.next_f64(),
                rng.next_f64(),
            ])
        })
        .collect()
}

/// Inverse-CDF sampling of a lat-long map.
///
/// # Example
/// ```
/// # use tessera::{baselines::envmap::InverseCdf, density::envmap::{EnvMap, Up}, io::image::Raster};
/// let map = EnvMap::new(Raster { width: 2, height: 2, values: vec![1.0; 4], bad_pixels: 0 }, Up::Z).unwrap();
/// let d = InverseCdf::new(&map).sample([0.1, 0.2, 0.3, 0.4]);
/// assert!((d.length() - 1.0).abs() < 1e-12 && d.z > 0.0);
/// ```
pub struct InverseCdf<'a> {
    map: &'a EnvMap,
    /// Over pixel weights value x solid angle.
    cdf: GridCdf,
}

impl<'a> InverseCdf<'a> {
    /// Builds the CDFs (one pass over the pixels).
    ///
    /// # Example
    /// ```
    /// # use tessera::{baselines::envmap::InverseCdf, density::envmap::{EnvMap, Up}, io::image::Raster};
    /// let map = EnvMap::new(Raster { width: 2, height: 1, values: vec![1.0, 0.0], bad_pixels: 0 }, Up::Z).unwrap();
    /// assert!(InverseCdf::new(&map).samples(10, 3).iter().all(|d| d.y >= 0.0));
    /// ```
    pub fn new(map: &'a EnvMap) -> Self {
        let w = map.width();
        let weights: Vec<f64> = (map.values().iter().enumerate())
            .map(|(k, v)| v * map.pixel_solid_angle(k / w))
            .collect();
        let cdf =
            GridCdf::new(w, map.height(), &weights).expect("an EnvMap has a positive integral");
        InverseCdf { map, cdf }
    }

    /// The direction for four uniform numbers in `[0, 1)`: row, column,
    /// and the position inside the pixel.
    ///
    /// # Example
    /// ```
    /// # use tessera::{baselines::envmap::InverseCdf, density::envmap::{EnvMap, Up}, io::image::Raster};
    /// let map = EnvMap::new(Raster { width: 2, height: 2, values: vec![1.0; 4], bad_pixels: 0 }, Up::Z).unwrap();
    /// assert!(InverseCdf::new(&map).sample([0.9, 0.2, 0.3, 0.4]).z < 0.0);
    /// ```
    pub fn sample(&self, u: [f64; 4]) -> DVec3 {
        let (i, j, _) = self.cdf.locate([u[0], u[1]]);
        self.map.direction_in_pixel(i, j, u[2], u[3])
    }

    /// The direction for two numbers in `[0, 1)`: row and column by the
    /// CDFs, the position inside the pixel from where each fell in its
    /// CDF entry, so a stratified `(u_row, u_column)` (Sobol) stays
    /// stratified.
    ///
    /// # Example
    /// ```
    /// # use tessera::{baselines::envmap::InverseCdf, density::envmap::{EnvMap, Up}, io::image::Raster};
    /// let map = EnvMap::new(Raster { width: 2, height: 2, values: vec![1.0; 4], bad_pixels: 0 }, Up::Z).unwrap();
    /// assert!(InverseCdf::new(&map).warp([0.1, 0.7]).z > 0.0);
    /// ```
    pub fn warp(&self, u: [f64; 2]) -> DVec3 {
        let (i, j, [a, b]) = self.cdf.locate(u);
        self.map.direction_in_pixel(i, j, a, b)
    }

    /// `n` independent samples from a seed.
    ///
    /// # Example
    /// ```
    /// # use tessera::{baselines::envmap::InverseCdf, density::envmap::{EnvMap, Up}, io::image::Raster};
    /// let map = EnvMap::new(Raster { width: 2, height: 2, values: vec![1.0; 4], bad_pixels: 0 }, Up::Z).unwrap();
    /// assert_eq!(InverseCdf::new(&map).samples(5, 1).len(), 5);
    /// ```
    pub fn samples(&self, n: usize, seed: u64) -> Vec<DVec3> {
        draw(n, seed, |u| self.sample(u))
    }
}

/// Alias-table sampling of a lat-long map (Vose's construction).
///
/// # Example
/// ```
/// # use tessera::{baselines::envmap::AliasTable, density::envmap::{EnvMap, Up}, io::image::Raster};
/// let map = EnvMap::new(Raster { width: 2, height: 1, values: vec![0.0, 1.0], bad_pixels: 0 }, Up::Z).unwrap();
/// assert!(AliasTable::new(&map).sample([0.1, 0.2, 0.3, 0.4]).y < 0.0);
/// ```
pub struct AliasTable<'a> {
    map: &'a EnvMap,
    /// Probability of keeping pixel `k` rather than its alias.
    keep: Vec<f64>,
    alias: Vec<u32>,
}

impl<'a> AliasTable<'a> {
    /// Builds the table in O(pixels).
    ///
    /// # Example
    /// ```
    /// # use tessera::{baselines::envmap::AliasTable, density::envmap::{EnvMap, Up}, io::image::Raster};
    /// let map = EnvMap::new(Raster { width: 2, height: 1, values: vec![3.0, 1.0], bad_pixels: 0 }, Up::Z).unwrap();
    /// let s = AliasTable::new(&map).samples(4000, 2);
    /// let left = s.iter().filter(|d| d.y > 0.0).count();
    /// assert!((2800..3200).contains(&left));
    /// ```
    pub fn new(map: &'a EnvMap) -> Self {
        let (w, h) = (map.width(), map.height());
        let weights: Vec<f64> = (0..w * h)
            .map(|k| map.values()[k] * map.pixel_solid_angle(k / w))
            .collect();
        let n = weights.len();
        let total: f64 = weights.iter().sum();
        let mut scaled: Vec<f64> = weights.iter().map(|x| x / total * n as f64).collect();
        let mut keep = vec![1.0; n];
        let mut alias: Vec<u32> = (0..n as u32).collect();
        let (mut small, mut large): (Vec<usize>, Vec<usize>) =
            (0..n).partition(|&k| scaled[k] < 1.0);
        while let (Some(&s), Some(&l)) = (small.last(), large.last()) {
            small.pop();
            keep[s] = scaled[s];
            alias[s] = l as u32;
            scaled[l] -= 1.0 - scaled[s];
            if scaled[l] < 1.0 {
                large.pop();
                small.push(l);
            }
        }
        // what remains is 1 up to rounding; a zero-weight leftover must
        // never be kept
        for k in small.into_iter().chain(large) {
            keep[k] = if weights[k] > 0.0 { 1.0 } else { 0.0 };
            if weights[k] == 0.0 {
                alias[k] = weights.iter().position(|&x| x > 0.0).expect("positive") as u32;
            }
        }
        AliasTable { map, keep, alias }
    }

    /// The direction for four uniform numbers in `[0, 1)`: pixel, keep or
    /// alias, and the position inside the pixel.
    ///
    /// # Example
    /// ```
    /// # use tessera::{baselines::envmap::AliasTable, density::envmap::{EnvMap, Up}, io::image::Raster};
    /// let map = EnvMap::new(Raster { width: 1, height: 2, values: vec![1.0, 0.0], bad_pixels: 0 }, Up::Z).unwrap();
    /// assert!(AliasTable::new(&map).sample([0.7, 0.9, 0.5, 0.5]).z > 0.0);
    /// ```
    pub fn sample(&self, u: [f64; 4]) -> DVec3 {
        let n = self.keep.len();
        let k = ((u[0] * n as f64) as usize).min(n - 1);
        let k = if u[1] < self.keep[k] {
            k
        } else {
            self.alias[k] as usize
        };
        let w = self.map.width();
        self.map.direction_in_pixel(k % w, k / w, u[2], u[3])
    }

    /// `n` independent samples from a seed.
    ///
    /// # Example
    /// ```
    /// # use tessera::{baselines::envmap::AliasTable, density::envmap::{EnvMap, Up}, io::image::Raster};
    /// let map = EnvMap::new(Raster { width: 2, height: 2, values: vec![1.0; 4], bad_pixels: 0 }, Up::Z).unwrap();
    /// assert_eq!(AliasTable::new(&map).samples(5, 1).len(), 5);
    /// ```
    pub fn samples(&self, n: usize, seed: u64) -> Vec<DVec3> {
        draw(n, seed, |u| self.sample(u))
    }
}

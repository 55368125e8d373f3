//! The samplers renderers use for lat-long environment maps, as
//! baselines: i.i.d. inverse-CDF sampling ([`InverseCdf`]: marginal over
//! rows, conditional over columns, two binary searches on f64 CDFs),
//! Walker/Vose alias tables over all pixels ([`AliasTable`]), and 1-D
//! stratified inverse-CDF sampling through the row-major CDF over all
//! pixels ([`Stratified`]). Each picks a pixel with probability
//! proportional to its value times its solid angle, then a direction
//! uniform in solid angle inside it, so their pdf is [`EnvMap::pdf`].
//!
//! ```
//! use tessera::baselines::envmap::{AliasTable, InverseCdf, Stratified};
//! use tessera::density::envmap::{EnvMap, Up};
//! use tessera::io::image::Raster;
//! let map = EnvMap::new(Raster { width: 4, height: 2, values: vec![0.0, 1.0, 0.0, 0.0, 0.0, 0.0, 2.0, 0.0], bad_pixels: 0 }, Up::Z).unwrap();
//! let iid = InverseCdf::new(&map).samples(100, 1).into_iter();
//! let alias = AliasTable::new(&map).samples(100, 1).into_iter();
//! for d in iid.chain(alias).chain(Stratified::new(&map).samples(100, 1)) {
//!     assert!(map.pdf(d) > 0.0);
//! }
//! ```

use crate::baselines::cdf::{normalised_cdf, remainder, search_from, GridCdf};
use crate::baselines::SplitMix64;
use crate::density::envmap::{EnvMap, Up};
use glam::DVec3;
use std::f64::consts::{PI, TAU};

/// `n` directions from four SplitMix64 numbers each.
#[inline]
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

/// Pixel weights `value x pixel solid angle`, row-major.
fn pixel_weights(map: &EnvMap) -> Vec<f64> {
    let w = map.width();
    (map.values().iter().enumerate())
        .map(|(k, v)| v * map.pixel_solid_angle(k / w))
        .collect()
}

/// [`EnvMap::direction_in_pixel`] with its per-row trigonometry read from
/// a table: the same floating-point operations in the same order, so the
/// same bits, at one `sin_cos` and one `sqrt` a direction instead of
/// three more sines and cosines.
#[derive(Clone, Debug)]
struct PixelDirections {
    up: Up,
    width: f64,
    /// Per row `j` with edges `a = j pi / h`, `b = (j + 1) pi / h`:
    /// `cos a`, `sin((a + b) / 2)` and `sin((b - a) / 2)`.
    rows: Vec<[f64; 3]>,
}

impl PixelDirections {
    fn new(map: &EnvMap) -> Self {
        let h = map.height() as f64;
        let rows = (0..map.height())
            .map(|j| {
                let (a, b) = (j as f64 * PI / h, (j + 1) as f64 * PI / h);
                [a.cos(), ((a + b) / 2.0).sin(), ((b - a) / 2.0).sin()]
            })
            .collect();
        PixelDirections {
            up: map.up(),
            width: map.width() as f64,
            rows,
        }
    }

    /// The world direction at `(u, v)` in `[0, 1)²` of pixel (column `i`,
    /// row `j`): `u` along the azimuth, `v` uniform in `cos θ`.
    #[inline]
    fn get(&self, i: usize, j: usize, u: f64, v: f64) -> DVec3 {
        let [cos_a, sin_mid, sin_half] = self.rows[j];
        let phi = TAU * (i as f64 + u) / self.width;
        // as EnvMap::direction_in_pixel writes it
        let z = cos_a - v * 2.0 * sin_mid * sin_half;
        let z = z.clamp(-1.0, 1.0);
        let s = ((1.0 - z) * (1.0 + z)).sqrt();
        let (sin_phi, cos_phi) = phi.sin_cos();
        self.up.from_map(DVec3::new(s * cos_phi, s * sin_phi, z))
    }
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
    directions: PixelDirections,
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
        let cdf = GridCdf::new(map.width(), map.height(), &pixel_weights(map))
            .expect("an EnvMap has a positive integral");
        InverseCdf {
            map,
            cdf,
            directions: PixelDirections::new(map),
        }
    }

    /// The map sampled.
    ///
    /// # Example
    /// ```
    /// # use tessera::{baselines::envmap::InverseCdf, density::envmap::{EnvMap, Up}, io::image::Raster};
    /// let map = EnvMap::new(Raster { width: 2, height: 1, values: vec![1.0, 0.0], bad_pixels: 0 }, Up::Z).unwrap();
    /// assert_eq!(InverseCdf::new(&map).map().width(), 2);
    /// ```
    pub fn map(&self) -> &'a EnvMap {
        self.map
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
    #[inline]
    pub fn sample(&self, u: [f64; 4]) -> DVec3 {
        let (i, j, _) = self.cdf.locate([u[0], u[1]]);
        self.directions.get(i, j, u[2], u[3])
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
    #[inline]
    pub fn warp(&self, u: [f64; 2]) -> DVec3 {
        let (i, j, [a, b]) = self.cdf.locate(u);
        self.directions.get(i, j, a, b)
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
    directions: PixelDirections,
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
        let weights = pixel_weights(map);
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
        AliasTable {
            map,
            directions: PixelDirections::new(map),
            keep,
            alias,
        }
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
    #[inline]
    pub fn sample(&self, u: [f64; 4]) -> DVec3 {
        let n = self.keep.len();
        let k = ((u[0] * n as f64) as usize).min(n - 1);
        let k = if u[1] < self.keep[k] {
            k
        } else {
            self.alias[k] as usize
        };
        let w = self.map.width();
        self.directions.get(k % w, k / w, u[2], u[3])
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

/// Largest f64 below 1.
const BELOW_ONE: f64 = 1.0 - f64::EPSILON / 2.0;

/// 1-D stratified inverse-CDF sampling of a lat-long map through the
/// row-major CDF over all its pixels (weights value x pixel solid angle):
/// sample `i` of `n` takes `u_i = (i + ξ_i) / n`, one uniform `ξ_i` per
/// stratum, and the pixel whose CDF interval holds `u_i`. Inside the pixel
/// the azimuth comes from where `u_i` fell inside the pixel's CDF entry
/// (so several samples in one bright pixel stay stratified along it, and
/// `u -> φ` is monotonic along each row) and `cos θ` from a second
/// uniform number: two SplitMix64 numbers a sample, `ξ_i` then the
/// `cos θ` one. Each `u_i` is uniform in its stratum and the strata tile
/// `[0, 1)`, so the estimate `(1/n) Σ f / pdf` is unbiased with the pdf
/// [`EnvMap::pdf`].
///
/// The `u_i` increase with `i`, so the pixels are found by one forward
/// walk over the CDF (a galloping search from the previous pixel), not a
/// binary search over the whole CDF each; the result is the same pixel.
///
/// # Example
/// ```
/// use tessera::baselines::envmap::Stratified;
/// use tessera::density::envmap::{EnvMap, Up};
/// use tessera::io::image::Raster;
/// // one pixel of the 2x2 map holds 3/4 of the mass
/// let raster = Raster { width: 2, height: 2, values: vec![3.0, 0.5, 0.5, 0.0], bad_pixels: 0 };
/// let map = EnvMap::new(raster, Up::Z).unwrap();
/// let stratified = Stratified::new(&map);
/// let s = stratified.samples(400, 7);
/// assert_eq!(s.len(), 400);
/// // 1-D stratification: the heavy pixel receives 300 samples, give or take one
/// let heavy = s.iter().filter(|d| d.z > 0.0 && d.y > 0.0).count();
/// assert!((299..=301).contains(&heavy));
/// assert!(s.iter().all(|&d| map.pdf(d) > 0.0));
/// assert_eq!(s, stratified.samples(400, 7));
/// ```
#[derive(Clone)]
pub struct Stratified<'a> {
    map: &'a EnvMap,
    /// Row-major over all pixels: `width * height + 1` entries, 0 to 1.
    cdf: Vec<f64>,
    directions: PixelDirections,
}

impl<'a> Stratified<'a> {
    /// Builds the CDF (one pass over the pixels): running sums of
    /// `value x pixel solid angle` in row-major order, divided by their
    /// total, the last entry exactly 1.
    ///
    /// # Example
    /// ```
    /// # use tessera::{baselines::envmap::Stratified, density::envmap::{EnvMap, Up}, io::image::Raster};
    /// let map = EnvMap::new(Raster { width: 2, height: 1, values: vec![1.0, 0.0], bad_pixels: 0 }, Up::Z).unwrap();
    /// assert!(Stratified::new(&map).samples(10, 3).iter().all(|d| d.y >= 0.0));
    /// ```
    pub fn new(map: &'a EnvMap) -> Self {
        let cdf = normalised_cdf(pixel_weights(map).into_iter())
            .expect("an EnvMap has a positive integral");
        Stratified {
            map,
            cdf,
            directions: PixelDirections::new(map),
        }
    }

    /// The map sampled.
    ///
    /// # Example
    /// ```
    /// # use tessera::{baselines::envmap::Stratified, density::envmap::{EnvMap, Up}, io::image::Raster};
    /// let map = EnvMap::new(Raster { width: 2, height: 1, values: vec![1.0, 0.0], bad_pixels: 0 }, Up::Z).unwrap();
    /// assert_eq!(Stratified::new(&map).map().width(), 2);
    /// ```
    pub fn map(&self) -> &'a EnvMap {
        self.map
    }

    /// The row-major CDF over all pixels: `width * height + 1` entries,
    /// entry `k` the mass of pixels `0..k` (pixel `k` is column `k % width`
    /// of row `k / width`), the last exactly 1.
    ///
    /// # Example
    /// ```
    /// # use tessera::{baselines::envmap::Stratified, density::envmap::{EnvMap, Up}, io::image::Raster};
    /// let map = EnvMap::new(Raster { width: 2, height: 1, values: vec![1.0, 3.0], bad_pixels: 0 }, Up::Z).unwrap();
    /// assert_eq!(Stratified::new(&map).cdf(), &[0.0, 0.25, 1.0]);
    /// ```
    pub fn cdf(&self) -> &[f64] {
        &self.cdf
    }

    /// Exactly `n` stratified samples from a seed, in stratum order (world
    /// directions). Cost O(n log(pixels / n) + n) after the CDF.
    ///
    /// # Example
    /// ```
    /// # use tessera::{baselines::envmap::Stratified, density::envmap::{EnvMap, Up}, io::image::Raster};
    /// let map = EnvMap::new(Raster { width: 4, height: 2, values: vec![1.0; 8], bad_pixels: 0 }, Up::Z).unwrap();
    /// let s = Stratified::new(&map).samples(8, 1);
    /// // a uniform map: the first half of the strata lies in the upper row
    /// assert!(s[..4].iter().all(|d| d.z > 0.0) && s[4..].iter().all(|d| d.z < 0.0));
    /// ```
    pub fn samples(&self, n: usize, seed: u64) -> Vec<DVec3> {
        let mut rng = SplitMix64::new(seed);
        let (w, count) = (self.map.width(), n as f64);
        let mut k = 0;
        (0..n)
            .map(|i| {
                let u = ((i as f64 + rng.next_f64()) / count).min(BELOW_ONE);
                k = search_from(&self.cdf, k, u);
                let t = remainder(&self.cdf, k, u);
                self.directions.get(k % w, k / w, t, rng.next_f64())
            })
            .collect()
    }
}

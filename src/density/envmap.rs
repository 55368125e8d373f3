//! Lat-long environment maps as sphere densities.
//!
//! Convention (Z up): column `i` of a `W x H` map covers
//! `phi in [2 pi i / W, 2 pi (i+1) / W)` with `phi = atan2(y, x) mod 2 pi`;
//! row `j` (the file's first row is `j = 0`) covers
//! `theta in [j pi / H, (j+1) pi / H]`, `theta` measured from +Z. With
//! [`Up::Y`] the map's pole is +Y: a direction `(x, y, z)` is looked up as
//! the Z-up direction `(z, x, y)` (a cyclic relabelling, so handedness is
//! kept).
//!
//! The density is the map at its own resolution, constant per pixel per
//! unit solid angle. Tile bounds take the maximum over every pixel the
//! tile's bounding cap touches (a cap containing a pole touches every
//! column) from a max pyramid whose coarser levels are built on first use;
//! tile averages are the pixel's value when the cap lies in one pixel, else
//! a midpoint quadrature over equal-area sub-cells about a pixel row across
//! or smaller.
//!
//! ```
//! use tessera::density::{envmap::{EnvMap, Up}, Density};
//! use tessera::io::image::Raster;
//! use tessera::tiling::sphere::SphereRegion;
//! let raster = Raster { width: 4, height: 2, values: vec![1.0; 8], bad_pixels: 0 };
//! let map = EnvMap::new(raster, Up::Z).unwrap();
//! assert!((map.integral() - 4.0 * std::f64::consts::PI).abs() < 1e-12);
//! assert_eq!(Density::<SphereRegion>::value(&map, glam::DVec3::Z), 1.0);
//! ```

use super::Density;
use crate::healpix::FacePoint;
use crate::io::image::{read_raster, Raster, ReadOptions};
use crate::random::random_rotation;
use crate::tiling::sphere::SphereRegion;
use crate::Error;
use glam::{DMat3, DVec3};
use std::f64::consts::{PI, TAU};
use std::path::Path;
use std::sync::{Arc, OnceLock};

/// Which world axis the map's first row looks towards.
///
/// # Example
/// ```
/// use tessera::density::envmap::Up;
/// assert_eq!(Up::Y.to_map(glam::DVec3::Y), glam::DVec3::Z);
/// assert_eq!(Up::Y.from_map(glam::DVec3::Z), glam::DVec3::Y);
/// ```
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Up {
    /// +Z is the map's pole (theta = 0).
    #[default]
    Z,
    /// +Y is the map's pole; `(x, y, z)` is looked up as `(z, x, y)`.
    Y,
}

impl Up {
    /// The Z-up map direction of a world direction.
    ///
    /// # Example
    /// ```
    /// use tessera::density::envmap::Up;
    /// assert_eq!(Up::Z.to_map(glam::DVec3::X), glam::DVec3::X);
    /// ```
    pub fn to_map(self, v: DVec3) -> DVec3 {
        match self {
            Up::Z => v,
            Up::Y => DVec3::new(v.z, v.x, v.y),
        }
    }

    /// The world direction of a Z-up map direction (inverse of [`Up::to_map`]).
    ///
    /// # Example
    /// ```
    /// use tessera::density::envmap::Up;
    /// let v = glam::DVec3::new(0.1, 0.2, 0.3);
    /// assert_eq!(Up::Y.from_map(Up::Y.to_map(v)), v);
    /// ```
    pub fn from_map(self, m: DVec3) -> DVec3 {
        match self {
            Up::Z => m,
            Up::Y => DVec3::new(m.y, m.z, m.x),
        }
    }
}

/// Pixels, per-row solid angles and the lazily built max pyramid.
struct Pixels {
    width: usize,
    height: usize,
    values: Vec<f64>,
    /// Solid angle of one pixel of each row.
    row_solid_angle: Vec<f64>,
    integral: f64,
    /// Level `l >= 1` holds the maximum over `2^l x 2^l` pixel blocks.
    max_levels: Vec<OnceLock<Vec<f64>>>,
    edges: Edges,
    /// `height / pi` and `width / (2 pi)`.
    rows_per_rad: f64,
    cols_per_rad: f64,
}

impl Pixels {
    fn dims(&self, level: usize) -> (usize, usize) {
        (
            self.width.div_ceil(1 << level),
            self.height.div_ceil(1 << level),
        )
    }

    /// The max pyramid level, built (with the levels below it) on first use.
    fn max_level(&self, level: usize) -> &[f64] {
        if level == 0 {
            return &self.values;
        }
        self.max_levels[level - 1].get_or_init(|| {
            let finer = self.max_level(level - 1);
            let (fw, fh) = self.dims(level - 1);
            let (w, h) = self.dims(level);
            let mut out = vec![0.0f64; w * h];
            for j in 0..fh {
                for i in 0..fw {
                    let o = &mut out[(j / 2) * w + i / 2];
                    *o = o.max(finer[j * fw + i]);
                }
            }
            out
        })
    }

    /// Maximum over rows `j0..=j1` and columns `i0..=i1` (no wrap), read from
    /// the finest level where the range spans at most three blocks a side.
    fn max_over(&self, j0: usize, j1: usize, i0: usize, i1: usize) -> f64 {
        let mut level = 0;
        while level < self.max_levels.len()
            && ((j1 >> level) - (j0 >> level) > 2 || (i1 >> level) - (i0 >> level) > 2)
        {
            level += 1;
        }
        let data = self.max_level(level);
        let (w, _) = self.dims(level);
        let mut m = 0.0f64;
        for j in (j0 >> level)..=(j1 >> level) {
            for i in (i0 >> level)..=(i1 >> level) {
                m = m.max(data[j * w + i]);
            }
        }
        m
    }

    /// Row and column of a Z-up map direction, without trigonometry: a
    /// bucket table gives the first candidate and comparisons with the
    /// exact edges (cosines of row edges, pseudo-angles of column edges)
    /// settle it.
    fn pixel_of(&self, m: DVec3) -> (usize, usize) {
        let z = m.z / m.length();
        let (j, i) = (self.edges.row(z), self.edges.column(m.x, m.y));
        (j.min(self.height - 1), i.min(self.width - 1))
    }
}

/// Pixel edges as trigonometry-free keys, with bucket tables into them.
struct Edges {
    /// `cos(j pi / H)` for `j = 0..=H` (decreasing).
    row_cos: Vec<f64>,
    /// For each of `4H` equal buckets of `z` in `[-1, 1]`: the row of its top.
    row_start: Vec<u32>,
    /// [`pseudo_angle`] of `phi = 2 pi i / W` for `i = 0..=W` (increasing, 0 to 4).
    col_key: Vec<f64>,
    /// For each of `4W` equal buckets of the pseudo-angle: its first column.
    col_start: Vec<u32>,
}

/// A trigonometry-free angle in `[0, 4)` increasing with `phi = atan2(y, x)`
/// (one unit per quadrant); 0 for the zero vector.
fn pseudo_angle(x: f64, y: f64) -> f64 {
    let a = if y >= 0.0 {
        if x > 0.0 {
            y / (x + y)
        } else {
            1.0 + (-x) / (y - x)
        }
    } else if x <= 0.0 {
        2.0 + (-y) / (-x - y)
    } else {
        3.0 + x / (x - y)
    };
    if a.is_nan() || a >= 4.0 {
        0.0
    } else {
        a
    }
}

impl Edges {
    fn new(width: usize, height: usize) -> Self {
        let row_cos: Vec<f64> = (0..=height)
            .map(|j| (j as f64 * PI / height as f64).cos())
            .collect();
        // number of edges k in 1..H with row_cos[k] >= z: the row of z
        let row_exact = |z: f64| row_cos[1..height].partition_point(|&c| c >= z);
        let buckets = 4 * height;
        let row_start = (0..buckets)
            .map(|b| row_exact((-1.0 + 2.0 * (b + 1) as f64 / buckets as f64).min(1.0)) as u32)
            .collect();
        let mut col_key: Vec<f64> = (0..=width)
            .map(|i| {
                let phi = TAU * i as f64 / width as f64;
                pseudo_angle(phi.cos(), phi.sin())
            })
            .collect();
        col_key[0] = 0.0;
        col_key[width] = 4.0;
        let buckets = 4 * width;
        let col_start = (0..buckets)
            .map(|b| {
                let key = 4.0 * b as f64 / buckets as f64;
                (col_key[1..width].partition_point(|&k| k <= key)) as u32
            })
            .collect();
        Edges {
            row_cos,
            row_start,
            col_key,
            col_start,
        }
    }

    fn row(&self, z: f64) -> usize {
        let buckets = self.row_start.len();
        let b = (((z + 1.0) * 0.5 * buckets as f64) as usize).min(buckets - 1);
        // one row back in case rounding put z a hair above its bucket
        let mut j = (self.row_start[b] as usize).saturating_sub(1);
        let last = self.row_cos.len() - 2;
        while j < last && self.row_cos[j + 1] >= z {
            j += 1;
        }
        j
    }

    fn column(&self, x: f64, y: f64) -> usize {
        let key = pseudo_angle(x, y);
        let buckets = self.col_start.len();
        let b = ((key * 0.25 * buckets as f64) as usize).min(buckets - 1);
        let mut i = (self.col_start[b] as usize).saturating_sub(1);
        let last = self.col_key.len() - 2;
        while i < last && self.col_key[i + 1] <= key {
            i += 1;
        }
        i
    }
}

/// `x.floor() as i64` without a libm call (NaN gives 0, as the cast does).
#[inline]
fn floor_i64(x: f64) -> i64 {
    let t = x as i64;
    if (t as f64) > x {
        t - 1
    } else {
        t
    }
}

/// Largest error (rad) of [`fast_atan2`], checked by a unit test.
const FAST_ATAN2_ERROR: f64 = 2e-5;

/// `atan2(y, x)` by a degree-11 odd polynomial for the arctangent on
/// `[0, 1]` and octant reduction; within [`FAST_ATAN2_ERROR`] of the truth.
fn fast_atan2(y: f64, x: f64) -> f64 {
    let (ax, ay) = (x.abs(), y.abs());
    let (lo, hi) = if ax < ay { (ax, ay) } else { (ay, ax) };
    if hi == 0.0 {
        return 0.0;
    }
    let a = lo / hi;
    let s = a * a;
    let mut r = a
        * (0.999_977_26
            + s * (-0.332_623_47
                + s * (0.193_543_46
                    + s * (-0.116_432_87 + s * (0.052_653_32 - s * 0.011_721_20)))));
    if ay > ax {
        r = std::f64::consts::FRAC_PI_2 - r;
    }
    if x < 0.0 {
        r = PI - r;
    }
    if y < 0.0 {
        -r
    } else {
        r
    }
}

/// A lat-long HDR environment map as a density on the sphere (see the
/// [module docs](self) for the convention). Cloning is cheap (the pixels
/// and pyramid are shared).
///
/// # Example
/// ```
/// use tessera::density::envmap::{EnvMap, Up};
/// use tessera::io::image::Raster;
/// // one lit pixel: every sample lands in it
/// let mut values = vec![0.0; 8 * 4];
/// values[1 * 8 + 3] = 5.0;
/// let map = EnvMap::new(Raster { width: 8, height: 4, values, bad_pixels: 0 }, Up::Z).unwrap();
/// let samples = map.generate(200).unwrap();
/// assert_eq!(samples.len(), 200);
/// assert!(samples.iter().all(|s| map.pdf(s.position) > 0.0));
/// ```
#[derive(Clone)]
pub struct EnvMap {
    pixels: Arc<Pixels>,
    up: Up,
    /// Sampling frame to world: the engine samples `value(p) = map(rotation p)`
    /// and samples are reported at `rotation p`.
    rotation: DMat3,
    /// Z up and no rotation: face points are looked up from their `(z, phi)`
    /// directly, without building the direction.
    plain: bool,
    /// The seed of `rotation`, when drawn from one.
    seed: Option<u64>,
}

impl EnvMap {
    /// A map from a raster (values must be finite and >= 0, some positive).
    ///
    /// # Example
    /// ```
    /// use tessera::density::envmap::{EnvMap, Up};
    /// use tessera::io::image::Raster;
    /// let zero = Raster { width: 2, height: 1, values: vec![0.0, 0.0], bad_pixels: 0 };
    /// assert!(EnvMap::new(zero, Up::Z).is_err());
    /// ```
    pub fn new(raster: Raster, up: Up) -> Result<Self, Error> {
        let Raster {
            width,
            height,
            values,
            ..
        } = raster;
        // re-validate: the raster's fields are public
        let raster = Raster::from_values("environment map", width, height, values, true)?;
        let (w, h) = (raster.width, raster.height);
        let row_solid_angle: Vec<f64> = (0..h)
            .map(|j| {
                let (a, b) = (j as f64 * PI / h as f64, (j + 1) as f64 * PI / h as f64);
                // cos a - cos b without cancellation
                TAU / w as f64 * 2.0 * ((a + b) / 2.0).sin() * ((b - a) / 2.0).sin()
            })
            .collect();
        let integral = raster
            .values
            .chunks(w)
            .zip(&row_solid_angle)
            .map(|(row, omega)| row.iter().sum::<f64>() * omega)
            .sum::<f64>();
        if !(integral.is_finite() && integral > 0.0) {
            return Err(Error::Density(
                "environment map".into(),
                format!("its integral is {integral}; it must be positive and finite"),
            ));
        }
        let levels = usize::BITS - (w.max(h) - 1).leading_zeros();
        Ok(EnvMap {
            pixels: Arc::new(Pixels {
                width: w,
                height: h,
                values: raster.values,
                row_solid_angle,
                integral,
                max_levels: (0..levels).map(|_| OnceLock::new()).collect(),
                edges: Edges::new(w, h),
                rows_per_rad: h as f64 / PI,
                cols_per_rad: w as f64 / TAU,
            }),
            up,
            rotation: DMat3::IDENTITY,
            plain: up == Up::Z,
            seed: None,
        })
    }

    /// Reads a map file (EXR, `.hdr`, PNG; see [`read_raster`]).
    ///
    /// # Example
    /// ```
    /// use tessera::density::envmap::{EnvMap, Up};
    /// let e = EnvMap::open("missing.exr".as_ref(), &Default::default(), Up::Z).err().unwrap();
    /// assert!(e.to_string().contains("missing.exr"));
    /// ```
    pub fn open(path: &Path, options: &ReadOptions, up: Up) -> Result<Self, Error> {
        let raster = read_raster(path, options)?;
        EnvMap::new(raster, up).map_err(|e| Error::File {
            path: path.into(),
            reason: e.to_string(),
        })
    }

    /// The same map sampled in a uniformly random rotated frame (Shoemake's
    /// uniform quaternion from `seed`): estimates from different seeds are
    /// independent and unbiased, and can be averaged. Without it sampling
    /// is deterministic. [`EnvMap::generate`] returns world directions; a
    /// generic `Sampler` or `engine` call returns sampling-frame directions,
    /// which [`EnvMap::to_world`] maps to the world.
    ///
    /// # Example
    /// ```
    /// use tessera::density::envmap::{EnvMap, Up};
    /// use tessera::io::image::Raster;
    /// let map = EnvMap::new(Raster { width: 2, height: 1, values: vec![1.0, 2.0], bad_pixels: 0 }, Up::Z).unwrap();
    /// let a = map.with_seed(1).generate(10).unwrap();
    /// let b = map.with_seed(2).generate(10).unwrap();
    /// assert_ne!(a[0].position, b[0].position);
    /// ```
    pub fn with_seed(&self, seed: u64) -> Self {
        EnvMap {
            rotation: random_rotation(seed),
            plain: false,
            seed: Some(seed),
            ..self.clone()
        }
    }

    /// Width in pixels.
    ///
    /// # Example
    /// ```
    /// # use tessera::{density::envmap::{EnvMap, Up}, io::image::Raster};
    /// let map = EnvMap::new(Raster { width: 2, height: 1, values: vec![1.0, 2.0], bad_pixels: 0 }, Up::Z).unwrap();
    /// assert_eq!((map.width(), map.height()), (2, 1));
    /// ```
    pub fn width(&self) -> usize {
        self.pixels.width
    }

    /// Height in pixels.
    ///
    /// # Example
    /// ```
    /// # use tessera::{density::envmap::{EnvMap, Up}, io::image::Raster};
    /// let map = EnvMap::new(Raster { width: 2, height: 1, values: vec![1.0, 2.0], bad_pixels: 0 }, Up::Z).unwrap();
    /// assert_eq!(map.height(), 1);
    /// ```
    pub fn height(&self) -> usize {
        self.pixels.height
    }

    /// The pixel values, row-major, row 0 first.
    ///
    /// # Example
    /// ```
    /// # use tessera::{density::envmap::{EnvMap, Up}, io::image::Raster};
    /// let map = EnvMap::new(Raster { width: 2, height: 1, values: vec![1.0, 2.0], bad_pixels: 0 }, Up::Z).unwrap();
    /// assert_eq!(map.values(), &[1.0, 2.0]);
    /// ```
    pub fn values(&self) -> &[f64] {
        &self.pixels.values
    }

    /// Solid angle (sr) of one pixel of row `j`.
    ///
    /// # Example
    /// ```
    /// # use tessera::{density::envmap::{EnvMap, Up}, io::image::Raster};
    /// let map = EnvMap::new(Raster { width: 2, height: 1, values: vec![1.0, 2.0], bad_pixels: 0 }, Up::Z).unwrap();
    /// assert!((map.pixel_solid_angle(0) - 2.0 * std::f64::consts::PI).abs() < 1e-12);
    /// ```
    pub fn pixel_solid_angle(&self, j: usize) -> f64 {
        self.pixels.row_solid_angle[j]
    }

    /// The map's up axis.
    ///
    /// # Example
    /// ```
    /// # use tessera::{density::envmap::{EnvMap, Up}, io::image::Raster};
    /// let map = EnvMap::new(Raster { width: 2, height: 1, values: vec![1.0, 2.0], bad_pixels: 0 }, Up::Y).unwrap();
    /// assert_eq!(map.up(), Up::Y);
    /// ```
    pub fn up(&self) -> Up {
        self.up
    }

    /// The integral of the map over the sphere (value x steradians): the
    /// normaliser of the pdf, so `(1/N) sum f(w_i) / pdf(w_i)` estimates
    /// `integral of f`.
    ///
    /// # Example
    /// ```
    /// # use tessera::{density::envmap::{EnvMap, Up}, io::image::Raster};
    /// let map = EnvMap::new(Raster { width: 2, height: 1, values: vec![1.0, 3.0], bad_pixels: 0 }, Up::Z).unwrap();
    /// assert!((map.integral() - 8.0 * std::f64::consts::PI).abs() < 1e-12);
    /// ```
    pub fn integral(&self) -> f64 {
        self.pixels.integral
    }

    /// The map's value in a world direction (need not be normalised).
    ///
    /// # Example
    /// ```
    /// # use tessera::{density::envmap::{EnvMap, Up}, io::image::Raster};
    /// let map = EnvMap::new(Raster { width: 1, height: 2, values: vec![1.0, 3.0], bad_pixels: 0 }, Up::Z).unwrap();
    /// assert_eq!(map.radiance(-glam::DVec3::Z), 3.0);
    /// ```
    pub fn radiance(&self, world: DVec3) -> f64 {
        let (j, i) = self.pixels.pixel_of(self.up.to_map(world));
        self.pixels.values[j * self.pixels.width + i]
    }

    /// The pdf per steradian of a world direction: `radiance / integral`.
    ///
    /// # Example
    /// ```
    /// # use tessera::{density::envmap::{EnvMap, Up}, io::image::Raster};
    /// let map = EnvMap::new(Raster { width: 1, height: 1, values: vec![2.0], bad_pixels: 0 }, Up::Z).unwrap();
    /// assert!((map.pdf(glam::DVec3::X) * 4.0 * std::f64::consts::PI - 1.0).abs() < 1e-12);
    /// ```
    pub fn pdf(&self, world: DVec3) -> f64 {
        self.radiance(world) / self.pixels.integral
    }

    /// The pdfs of samples (computed only when asked).
    ///
    /// # Example
    /// ```
    /// # use tessera::{density::envmap::{EnvMap, Up}, io::image::Raster};
    /// let map = EnvMap::new(Raster { width: 2, height: 1, values: vec![1.0, 3.0], bad_pixels: 0 }, Up::Z).unwrap();
    /// let s = map.generate(8).unwrap();
    /// assert!(map.pdfs(&s).iter().all(|&p| p > 0.0));
    /// ```
    pub fn pdfs(&self, samples: &[crate::sample::Sample<DVec3>]) -> Vec<f64> {
        samples.iter().map(|s| self.pdf(s.position)).collect()
    }

    /// The world direction of a direction in the sampling frame.
    ///
    /// # Example
    /// ```
    /// # use tessera::{density::envmap::{EnvMap, Up}, io::image::Raster};
    /// let map = EnvMap::new(Raster { width: 2, height: 1, values: vec![1.0, 3.0], bad_pixels: 0 }, Up::Z).unwrap();
    /// assert_eq!(map.to_world(glam::DVec3::X), glam::DVec3::X);
    /// ```
    pub fn to_world(&self, p: DVec3) -> DVec3 {
        self.rotation * p
    }

    /// The world direction at `(u, v)` in `[0, 1)^2` of pixel (column `i`,
    /// row `j`), uniform in solid angle over the pixel.
    ///
    /// # Example
    /// ```
    /// # use tessera::{density::envmap::{EnvMap, Up}, io::image::Raster};
    /// let map = EnvMap::new(Raster { width: 4, height: 2, values: vec![1.0; 8], bad_pixels: 0 }, Up::Z).unwrap();
    /// let d = map.direction_in_pixel(1, 0, 0.5, 0.5);
    /// assert!(d.z > 0.0 && d.x < 0.0 && d.y > 0.0);
    /// ```
    pub fn direction_in_pixel(&self, i: usize, j: usize, u: f64, v: f64) -> DVec3 {
        let (w, h) = (self.pixels.width as f64, self.pixels.height as f64);
        let phi = TAU * (i as f64 + u) / w;
        let (a, b) = (j as f64 * PI / h, (j + 1) as f64 * PI / h);
        // cos(theta) uniform in [cos b, cos a], written as cos a - v (cos a - cos b)
        // with the difference taken without cancellation
        let z = a.cos() - v * 2.0 * ((a + b) / 2.0).sin() * ((b - a) / 2.0).sin();
        let z = z.clamp(-1.0, 1.0);
        let s = ((1.0 - z) * (1.0 + z)).sqrt();
        self.up
            .from_map(DVec3::new(s * phi.cos(), s * phi.sin(), z))
    }

    /// Rows `j0..=j1` and columns `c0..=c1` (wrapping when `c0 > c1`) of
    /// every pixel a tile's bounding cap touches; a cap holding a pole
    /// touches every column.
    fn touched(&self, region: &SphereRegion) -> (usize, usize, usize, usize) {
        self.touched_about(self.centre_of(region), region.radius)
    }

    /// A region's centre in the map's frame: `(sin theta, phi, theta)`,
    /// `theta` and `phi` within [`FAST_ATAN2_ERROR`].
    #[inline(always)]
    fn centre_of(&self, region: &SphereRegion) -> (f64, f64, f64) {
        let (z, rxy, phi) = if self.plain {
            // straight from face coordinates: no trigonometry
            region.centroid.z_sin_phi()
        } else {
            let m = self.up.to_map(self.rotation * region.center());
            let phi = fast_atan2(m.y, m.x);
            let phi = if phi < 0.0 { phi + TAU } else { phi };
            (m.z, (m.x * m.x + m.y * m.y).sqrt(), phi)
        };
        (rxy, phi, fast_atan2(rxy, z))
    }

    /// [`EnvMap::touched`] of the cap of `radius` about `centre` (see
    /// [`EnvMap::centre_of`]).
    fn touched_about(
        &self,
        (rxy, phi, theta): (f64, f64, f64),
        radius: f64,
    ) -> (usize, usize, usize, usize) {
        let px = &*self.pixels;
        // wider than the cap by the angles' error, so pixel edges never
        // round inwards
        let r = radius * (1.0 + 1e-9) + 2.0 * FAST_ATAN2_ERROR;
        let (rows_per_rad, cols_per_rad) = (px.rows_per_rad, px.cols_per_rad);
        let j1 = (((theta + r) * rows_per_rad) as usize).min(px.height - 1);
        let j0 = (((theta - r).max(0.0) * rows_per_rad) as usize).min(j1);
        // sin(theta) of the unit vector without trigonometry, a hair low;
        // r >= sin r, so `s` bounds sin r / sin theta from above
        let sin_theta = rxy * (1.0 - 1e-12);
        let s = r / sin_theta;
        if theta - r <= 0.0 || theta + r >= PI || s >= 1.0 || s.is_nan() {
            return (j0, j1, 0, px.width - 1);
        }
        // asin(s) <= s + s^3 / 5 for s <= 0.1 (its series is s + s^3/6 + ...)
        let half = if s <= 0.1 {
            s + s * s * s / 5.0
        } else {
            s.asin()
        } + FAST_ATAN2_ERROR;
        let c0 = floor_i64((phi - half) * cols_per_rad);
        let c1 = floor_i64((phi + half) * cols_per_rad);
        let width = px.width as i64;
        if c1 - c0 + 1 >= width {
            return (j0, j1, 0, px.width - 1);
        }
        // phi in [0, 2 pi) and half below pi: at most one turn out
        let wrap = |c: i64| {
            if c < 0 {
                (c + width) as usize
            } else if c >= width {
                (c - width) as usize
            } else {
                c as usize
            }
        };
        (j0, j1, wrap(c0), wrap(c1))
    }

    /// The value in the sampling frame.
    fn at(&self, p: DVec3) -> f64 {
        if self.plain {
            // Z up, identity frame: the world direction is `p` itself
            return self.radiance(p);
        }
        self.radiance(self.rotation * p)
    }

    /// The value at a face point in the sampling frame; without a rotation
    /// or axis swap, from its `(z, phi)` without trigonometry.
    #[inline(always)]
    fn at_face_point(&self, p: FacePoint) -> f64 {
        if !self.plain {
            return self.at(p.to_vec());
        }
        let px = &*self.pixels;
        let (z, phi) = p.z_phi();
        let j = px.edges.row(z).min(px.height - 1);
        let i = ((phi * px.cols_per_rad) as usize).min(px.width - 1);
        px.values[j * px.width + i]
    }
}

impl EnvMap {
    /// The maximum over the pixels a region touches, and the pixel's value
    /// when it touches only one (then the region's exact average).
    fn bound_in(&self, region: &SphereRegion) -> (f64, Option<f64>) {
        self.max_touched(self.touched(region))
    }

    /// The maximum over the pixels of a [`EnvMap::touched`] range, and the
    /// pixel's value when it is one pixel.
    fn max_touched(&self, touched: (usize, usize, usize, usize)) -> (f64, Option<f64>) {
        let px = &*self.pixels;
        match touched {
            (j0, j1, c0, c1) if j0 == j1 && c0 == c1 => {
                let v = px.values[j0 * px.width + c0];
                (v, Some(v))
            }
            (j0, j1, c0, c1) if c0 <= c1 => (px.max_over(j0, j1, c0, c1), None),
            (j0, j1, c0, c1) => (
                px.max_over(j0, j1, c0, px.width - 1)
                    .max(px.max_over(j0, j1, 0, c1)),
                None,
            ),
        }
    }

    /// The midpoint rule over equal-area sub-cells about a pixel row across.
    fn quadrature(&self, region: &SphereRegion) -> f64 {
        let side = region.cell_side();
        // pixel rows per cell side (a face side is about 1.02 rad)
        let rows = side * 1.02 / (PI / self.pixels.height as f64);
        // sub-cells at most about a pixel row across
        // `rows.ceil()` without a libm call (NaN gives 0 either way)
        let whole = rows as usize;
        let n = (whole + usize::from((whole as f64) < rows)).clamp(1, 8);
        let mut sum = 0.0;
        if n == 1 {
            for [cx, cy] in region.cells {
                sum += self.at_face_point(FacePoint::new(region.face, cx, cy));
            }
            return sum / 5.0;
        }
        let mut offsets = [0.0f64; 8];
        for (a, o) in offsets.iter_mut().enumerate().take(n) {
            *o = side * ((a as f64 + 0.5) / n as f64 - 0.5);
        }
        let offsets = &offsets[..n];
        for [cx, cy] in region.cells {
            for &da in offsets {
                for &db in offsets {
                    sum += self.at_face_point(FacePoint::new(region.face, cx + da, cy + db));
                }
            }
        }
        sum / (5 * n * n) as f64
    }
}

impl Density<SphereRegion> for EnvMap {
    fn bound(&self, region: &SphereRegion) -> f64 {
        self.bound_in(region).0
    }

    fn bounds(&self, region: &SphereRegion, inner: &SphereRegion) -> (f64, f64) {
        if region.centroid != inner.centroid {
            return (self.bound(region), self.bound(inner));
        }
        // one centre, two radii
        let centre = self.centre_of(region);
        let of = |radius| self.max_touched(self.touched_about(centre, radius)).0;
        (of(region.radius), of(inner.radius))
    }

    fn average(&self, region: &SphereRegion) -> f64 {
        // a cap at least a pixel row across always touches two rows (or,
        // clamped at a pole, every column): only smaller caps may lie in
        // one pixel
        if 2.0 * region.radius < PI / self.pixels.height as f64 || self.pixels.width == 1 {
            let (j0, j1, c0, c1) = self.touched(region);
            if j0 == j1 && c0 == c1 {
                // the tile lies in one pixel: its value is the exact average
                return self.pixels.values[j0 * self.pixels.width + c0];
            }
        }
        self.quadrature(region)
    }

    fn value(&self, point: DVec3) -> f64 {
        self.at(point)
    }

    fn mean(&self) -> f64 {
        self.pixels.integral / (4.0 * PI)
    }

    fn seed(&self) -> Option<u64> {
        self.seed
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::healpix::vec_to_angles;
    use crate::random::SplitMix64;

    #[test]
    fn fast_atan2_is_within_its_error() {
        let mut rng = SplitMix64::new(1);
        let mut worst: f64 = 0.0;
        for k in 0..200_000 {
            let (y, x) = (rng.next_f64() * 2.0 - 1.0, rng.next_f64() * 2.0 - 1.0);
            // also the axes and diagonals, and tiny arguments
            let (y, x) = match k % 5 {
                0 => (y, 0.0),
                1 => (0.0, x),
                2 => (x, x),
                3 => (y * 1e-300, x),
                _ => (y, x),
            };
            worst = worst.max((fast_atan2(y, x) - y.atan2(x)).abs());
        }
        assert!(worst <= FAST_ATAN2_ERROR, "{worst}");
        assert!(
            worst > FAST_ATAN2_ERROR / 100.0,
            "the bound is far too loose: {worst}"
        );
    }

    #[test]
    fn pixel_lookup_agrees_with_exact_angles() {
        let raster = Raster {
            width: 1000,
            height: 500,
            values: vec![1.0; 500_000],
            bad_pixels: 0,
        };
        let map = EnvMap::new(raster, Up::Z).unwrap();
        let px = &*map.pixels;
        let mut rng = SplitMix64::new(2);
        for _ in 0..200_000 {
            // points on and near pixel edges
            let t = ((rng.next_f64() * 500.0).round() + (rng.next_f64() - 0.5) * 1e-3) / 500.0 * PI;
            let p =
                ((rng.next_f64() * 1000.0).round() + (rng.next_f64() - 0.5) * 1e-3) / 1000.0 * TAU;
            let m = crate::healpix::angles_to_vec(t.clamp(0.0, PI), p.rem_euclid(TAU));
            if m.x == 0.0 && m.y == 0.0 {
                continue; // a pole: every column meets there
            }
            let (theta, phi) = vec_to_angles(m);
            let exact = (
                ((theta / PI * 500.0) as usize).min(499),
                ((phi / TAU * 1000.0) as usize).min(999),
            );
            assert_eq!(px.pixel_of(m), exact, "{m}");
        }
    }
}

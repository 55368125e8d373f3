//! Densities on the unit square: uniform, a linear ramp, and an in-memory
//! raster (a grey image), each with conservative bounds over tiles.
//!
//! A point `(x, y)` of `[0, 1)^2` falls in pixel column `floor(x W)` and row
//! `floor(y H)`, row 0 being the raster's first row (y points down).

use super::{Density, Region, Uniform};
use crate::tiling::plane::PlaneRegion;
use crate::Error;
use glam::DVec2;

impl Region for PlaneRegion {
    type Point = DVec2;
}

/// Density proportional to `x` (zero on the left edge, largest on the right).
///
/// # Example
/// ```
/// use tessera::{density::plane::Ramp, engine, tiling::plane::PlaneTiling};
/// let s = engine::generate(&PlaneTiling::ppentomino(), &Ramp, 2000, true).unwrap();
/// let right = s.iter().filter(|p| p.position.x >= 0.5).count();
/// assert!(right > 1400); // 3/4 of the mass lies right of the middle
/// ```
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Ramp;

impl Density<PlaneRegion> for Ramp {
    fn bound(&self, region: &PlaneRegion) -> f64 {
        region.hi.x
    }
    fn average(&self, region: &PlaneRegion) -> f64 {
        // exact (to an ulp): x is linear over the equal cells, so its mean
        // is the x of their centres' mean (reading one field, not the
        // cells, took about 5 % off ramp requests)
        region.centroid.x
    }
    fn value(&self, point: DVec2) -> f64 {
        point.x
    }
    fn mean(&self) -> f64 {
        0.5
    }
}

/// A grey raster (`width x height`, row-major, row 0 on top) as a density:
/// importance is the stored value, or `max - value` when inverted (dark
/// areas get the samples, as in stippling).
///
/// Bounds over a tile come from a max pyramid over the pixels its bounding
/// box touches (so a single bright pixel is never skipped); averages from a
/// summed-area table over each of the tile's cells.
///
/// # Example
/// ```
/// use tessera::density::plane::Raster;
/// // a 2x1 image: black left half, white right half
/// let r = Raster::new(2, 1, vec![0.0, 1.0], false).unwrap();
/// assert_eq!(r.pixel(glam::DVec2::new(0.75, 0.5)), 1.0);
/// assert!(Raster::new(2, 1, vec![0.0, f64::NAN], false).is_err());
/// ```
#[derive(Clone, Debug)]
pub struct Raster {
    width: usize,
    height: usize,
    values: Vec<f64>,
    /// `(width + 1) x (height + 1)` summed-area table.
    sums: Vec<f64>,
    /// Level `p` holds the max of each `2^p x 2^p` block.
    pyramid: Vec<(usize, usize, Vec<f64>)>,
    mean: f64,
}

impl Raster {
    /// A raster density from pixel values (non-negative, finite), row-major
    /// with row 0 on top. `invert` uses `max - value` instead. Values are
    /// then normalised to a maximum of 1 (only ratios matter).
    ///
    /// # Example
    /// ```
    /// use tessera::density::plane::Raster;
    /// let r = Raster::new(1, 3, vec![0.0, 0.5, 1.0], true).unwrap();
    /// assert_eq!(r.pixel(glam::DVec2::new(0.5, 0.1)), 1.0); // top row, inverted
    /// assert_eq!(r.pixel(glam::DVec2::new(0.5, 0.5)), 0.5);
    /// assert!(Raster::new(0, 2, vec![], false).is_err());
    /// ```
    pub fn new(width: usize, height: usize, values: Vec<f64>, invert: bool) -> Result<Self, Error> {
        let fail = |why: String| Error::Density("image".into(), why);
        if width == 0 || height == 0 {
            return Err(fail(format!(
                "the raster is {width}x{height}; it must have pixels"
            )));
        }
        if width.checked_mul(height) != Some(values.len()) {
            return Err(fail(format!(
                "{} values for a {width}x{height} raster",
                values.len()
            )));
        }
        if let Some(at) = values.iter().position(|v| !(v.is_finite() && *v >= 0.0)) {
            return Err(fail(format!(
                "pixel (column {}, row {}) is {}; values must be finite and non-negative",
                at % width,
                at / width,
                values[at]
            )));
        }
        let max = values.iter().copied().fold(0.0, f64::max);
        let values: Vec<f64> = if invert {
            values.iter().map(|v| max - v).collect()
        } else {
            values
        };
        // normalise by the largest value so sums stay far from overflow
        let top = values.iter().copied().fold(0.0, f64::max);
        if top <= 0.0 {
            return Err(fail(
                "every pixel is zero (after inversion): there is nothing to sample".into(),
            ));
        }
        let values: Vec<f64> = values.iter().map(|v| v / top).collect();
        let mut sums = vec![0.0; (width + 1) * (height + 1)];
        for row in 0..height {
            let mut line = 0.0;
            for col in 0..width {
                line += values[row * width + col];
                sums[(row + 1) * (width + 1) + col + 1] = sums[row * (width + 1) + col + 1] + line;
            }
        }
        let mean = sums[(width + 1) * (height + 1) - 1] / (width * height) as f64;
        let mut pyramid = vec![(width, height, values.clone())];
        while let Some((w, h, level)) = pyramid.last().filter(|(w, h, _)| *w > 1 || *h > 1) {
            let (nw, nh) = (w.div_ceil(2), h.div_ceil(2));
            let mut next = vec![0.0f64; nw * nh];
            for row in 0..*h {
                for col in 0..*w {
                    let v = &mut next[(row / 2) * nw + col / 2];
                    *v = v.max(level[row * w + col]);
                }
            }
            pyramid.push((nw, nh, next));
        }
        Ok(Raster {
            width,
            height,
            values,
            sums,
            pyramid,
            mean,
        })
    }

    /// Width and height in pixels.
    ///
    /// # Example
    /// ```
    /// use tessera::density::plane::Raster;
    /// assert_eq!(Raster::new(3, 2, vec![1.0; 6], false).unwrap().dimensions(), (3, 2));
    /// ```
    pub fn dimensions(&self) -> (usize, usize) {
        (self.width, self.height)
    }

    /// The normalised pixel values (maximum 1), row-major.
    ///
    /// # Example
    /// ```
    /// use tessera::density::plane::Raster;
    /// assert_eq!(Raster::new(2, 1, vec![1.0, 4.0], false).unwrap().values(), &[0.25, 1.0]);
    /// ```
    pub fn values(&self) -> &[f64] {
        &self.values
    }

    /// The (normalised) importance of the pixel holding `point`.
    ///
    /// # Example
    /// ```
    /// use tessera::density::plane::Raster;
    /// let r = Raster::new(2, 2, vec![1.0, 2.0, 3.0, 4.0], false).unwrap();
    /// assert_eq!(r.pixel(glam::DVec2::new(0.9, 0.9)), 1.0); // bottom right, the maximum
    /// ```
    pub fn pixel(&self, point: DVec2) -> f64 {
        let (col, row) = (self.column(point.x), self.row(point.y));
        self.values[row * self.width + col]
    }

    fn column(&self, x: f64) -> usize {
        ((x * self.width as f64).max(0.0) as usize).min(self.width - 1)
    }

    fn row(&self, y: f64) -> usize {
        ((y * self.height as f64).max(0.0) as usize).min(self.height - 1)
    }

    /// Pixel index range `[first, last]` covered by `[a, b)` on an axis of `n` pixels.
    fn span(a: f64, b: f64, n: usize) -> (usize, usize) {
        let first = ((a * n as f64).floor().max(0.0) as usize).min(n - 1);
        let last = (((b * n as f64).ceil() as usize).saturating_sub(1)).clamp(first, n - 1);
        (first, last)
    }

    /// Mean of the pixels `[c0, c1] x [r0, r1]`.
    fn box_mean(&self, (c0, c1): (usize, usize), (r0, r1): (usize, usize)) -> f64 {
        let w = self.width + 1;
        let s = |r: usize, c: usize| self.sums[r * w + c];
        let total = s(r1 + 1, c1 + 1) - s(r0, c1 + 1) - s(r1 + 1, c0) + s(r0, c0);
        // the differences of large sums carry rounding of about 1e-16 times
        // the image's total (values are normalised to a maximum of 1)
        (total / ((c1 + 1 - c0) * (r1 + 1 - r0)) as f64).max(0.0)
    }
}

impl Density<PlaneRegion> for Raster {
    fn bound(&self, region: &PlaneRegion) -> f64 {
        let (c0, c1) = Self::span(region.lo.x, region.hi.x, self.width);
        let (r0, r1) = Self::span(region.lo.y, region.hi.y, self.height);
        // the level whose blocks are at least as large as the box: at most
        // 2x2 blocks cover it
        let extent = (c1 - c0).max(r1 - r0) + 1;
        let p = (usize::BITS - (extent - 1).leading_zeros()) as usize;
        let p = p.min(self.pyramid.len() - 1);
        let (w, _, level) = &self.pyramid[p];
        let mut best = 0.0f64;
        for row in (r0 >> p)..=(r1 >> p) {
            for col in (c0 >> p)..=(c1 >> p) {
                best = best.max(level[row * w + col]);
            }
        }
        best
    }
    fn average(&self, region: &PlaneRegion) -> f64 {
        // cells lie inside the bounding box; shrinking them by a hair keeps
        // rounding from reaching a pixel the bound did not see
        let h = 0.5 * region.cell * (1.0 - 1e-9);
        let c = region.centres();
        c.iter()
            .map(|p| {
                let cols = Self::span(p.x - h, p.x + h, self.width);
                let rows = Self::span(p.y - h, p.y + h, self.height);
                self.box_mean(cols, rows)
            })
            .sum::<f64>()
            / c.len() as f64
    }
    fn value(&self, point: DVec2) -> f64 {
        self.pixel(point)
    }
    fn mean(&self) -> f64 {
        self.mean
    }
}

/// Parses a planar density specification: `uniform`, `ramp` or
/// `image:PATH` (an OpenEXR, Radiance .hdr or PNG file read by
/// [`crate::io::image::read_raster`]: its luminance or grey level as
/// stored, no sRGB decoding, bad pixels as 0). `invert` samples `max - value` (stippling) and is refused for
/// the analytic densities.
///
/// # Example
/// ```
/// use tessera::density::plane::parse;
/// assert!(parse("ramp", false).is_ok());
/// assert!(parse("ramp:2", false).is_err_and(|e| e.to_string().contains("ramp:2")));
/// assert!(parse("image:/no/such.png", false).is_err_and(|e| e.to_string().contains("/no/such.png")));
/// assert!(parse("uniform", true).is_err());
/// ```
pub fn parse(spec: &str, invert: bool) -> Result<Box<dyn Density<PlaneRegion> + Send>, Error> {
    let fail = |why: &str| Err(Error::Density(spec.to_string(), why.into()));
    if let Some(path) = spec.strip_prefix("image:") {
        let path = std::path::Path::new(path);
        // importance is the value as stored (a PNG's grey level, not linear light)
        let options = crate::io::image::ReadOptions {
            decode_srgb: false,
            ..Default::default()
        };
        let raster = crate::io::image::read_raster(path, &options)?;
        let image =
            Raster::new(raster.width, raster.height, raster.values, invert).map_err(|e| {
                Error::File {
                    path: path.into(),
                    reason: e.to_string(),
                }
            })?;
        return Ok(Box::new(image));
    }
    if invert {
        return fail("invert applies to image densities only");
    }
    match spec {
        "uniform" => Ok(Box::new(Uniform)),
        "ramp" => Ok(Box::new(Ramp)),
        _ => fail("unknown planar density; expected 'uniform', 'ramp' or 'image:PATH'"),
    }
}

/// A planar density sampled under a uniformly random toroidal shift: the
/// engine samples `value(p) = inner((p + shift) mod 1)`, and
/// [`Shifted::to_world`] maps its samples back. Averaged over seeds,
/// estimates from the samples are unbiased (see [`crate::engine`]).
///
/// # Example
/// ```
/// use tessera::density::plane::{Ramp, Shifted};
/// use tessera::{engine, tiling::plane::PlaneTiling};
/// let ramp = Shifted::new(Ramp, 5);
/// let s = engine::generate(&PlaneTiling::ppentomino(), &ramp, 2000, true).unwrap();
/// let right = s.iter().filter(|s| ramp.to_world(s.position).x >= 0.5).count();
/// assert!(right > 1400);
/// ```
pub struct Shifted<D> {
    inner: D,
    shift: DVec2,
    seed: u64,
}

impl<D> Shifted<D> {
    /// `inner` shifted by two numbers of [`crate::random::SplitMix64`]`(seed)`.
    ///
    /// # Example
    /// ```
    /// use tessera::density::{plane::Shifted, Uniform};
    /// let p = Shifted::new(Uniform, 1).to_world(glam::DVec2::new(0.5, 0.5));
    /// assert!(p.x >= 0.0 && p.x < 1.0 && p.y >= 0.0 && p.y < 1.0);
    /// ```
    pub fn new(inner: D, seed: u64) -> Self {
        let mut rng = crate::random::SplitMix64::new(seed);
        let shift = DVec2::new(rng.next_f64(), rng.next_f64());
        Shifted { inner, shift, seed }
    }

    /// The point of the unit square a sample of the shifted frame stands for.
    ///
    /// # Example
    /// ```
    /// use tessera::density::{plane::Shifted, Uniform};
    /// let s = Shifted::new(Uniform, 2);
    /// assert_ne!(s.to_world(glam::DVec2::ZERO), glam::DVec2::ZERO);
    /// ```
    pub fn to_world(&self, p: DVec2) -> DVec2 {
        wrap_unit(p + self.shift)
    }
}

/// `p` reduced into `[0, 1)^2`.
fn wrap_unit(p: DVec2) -> DVec2 {
    let f = |v: f64| {
        let w = v - v.floor();
        if w >= 1.0 {
            0.0
        } else {
            w
        }
    };
    DVec2::new(f(p.x), f(p.y))
}

impl<D: Density<PlaneRegion>> Density<PlaneRegion> for Shifted<D> {
    fn bound(&self, region: &PlaneRegion) -> f64 {
        // the part of the box inside the square, shifted: it crosses the
        // square's far edges at most once per axis, so at most four pieces
        let lo = region.lo.clamp(DVec2::ZERO, DVec2::ONE) + self.shift;
        let hi = region.hi.clamp(DVec2::ZERO, DVec2::ONE) + self.shift;
        let spans = |a: f64, b: f64| -> [Option<(f64, f64)>; 2] {
            [
                (a < 1.0).then(|| (a, b.min(1.0))),
                (b > 1.0).then(|| (a.max(1.0) - 1.0, b - 1.0)),
            ]
        };
        let mut bound: f64 = 0.0;
        for (x0, x1) in spans(lo.x, hi.x).into_iter().flatten() {
            for (y0, y1) in spans(lo.y, hi.y).into_iter().flatten() {
                let piece = PlaneRegion {
                    lo: DVec2::new(x0, y0),
                    hi: DVec2::new(x1, y1),
                    ..*region
                };
                bound = bound.max(self.inner.bound(&piece));
            }
        }
        bound
    }
    fn average(&self, region: &PlaneRegion) -> f64 {
        let cells = region.centres();
        cells.iter().map(|&p| self.value(p)).sum::<f64>() / cells.len().max(1) as f64
    }
    fn value(&self, point: DVec2) -> f64 {
        self.inner.value(wrap_unit(point + self.shift))
    }
    fn mean(&self) -> f64 {
        self.inner.mean()
    }
    fn constant(&self) -> Option<f64> {
        self.inner.constant()
    }
    fn seed(&self) -> Option<u64> {
        Some(self.seed)
    }
}

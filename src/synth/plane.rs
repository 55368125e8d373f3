//! The synthetic planar rasters.

use super::noise::{fbm, uniform};
use crate::random::SplitMix64;

/// A kind of synthetic grey raster for the planar systems, each a feature
/// that stresses sampling on the unit square: hard edges, gradients,
/// lognormal texture, zero pixels.
///
/// Values are row-major with row 0 on top (y down), the convention of
/// [`crate::density::plane::Raster::new`]; all finite and `>= 0`.
///
/// # Example
/// ```
/// use tessera::density::plane::Raster;
/// use tessera::synth::Raster2d;
/// for kind in Raster2d::all() {
///     let values = kind.generate(64, 48, 3);
///     assert!(Raster::new(64, 48, values, false).is_ok(), "{}", kind.name());
/// }
/// ```
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Raster2d {
    /// 6-12 hard-edged discs of values 0.2-1 over a background of 0.05:
    /// curved edges at many contrasts (stipple targets, spot lights).
    Discs,
    /// 5-10 hard-edged rectangles, half of them rotated, values 0.2-1 over
    /// 0.05: straight edges at every angle (text, windows, UI).
    Rectangles,
    /// One straight edge at a random angle near the centre, 1 on one side
    /// and 0.02 on the other: a 50:1 contrast step.
    Step,
    /// A linear ramp along a random direction plus a Gaussian bump: smooth
    /// gradients with no edges (vignetting, soft lights).
    Gradient,
    /// `exp(f)`, `f` a unit-variance fBm down to 2-pixel cells: lognormal
    /// texture at every scale (photographs of foliage, gravel, clouds).
    Lognormal,
    /// A linear ramp with a random 20 % of its pixels exactly 0: the zeros
    /// clamped compression noise leaves.
    ZeroNoise,
    /// Everything at once: discs and rectangles over a lognormal (sigma
    /// 0.5) background darkened beyond a step, with 5 % zero pixels.
    Mixed,
}

const ALL: [Raster2d; 7] = [
    Raster2d::Discs,
    Raster2d::Rectangles,
    Raster2d::Step,
    Raster2d::Gradient,
    Raster2d::Lognormal,
    Raster2d::ZeroNoise,
    Raster2d::Mixed,
];

/// A random shape of the `Discs` or `Rectangles` kinds, in pixel units.
enum Shape {
    /// Centre and radius.
    Disc(f64, f64, f64),
    /// Centre, half sizes, and the direction of the first axis.
    Rect(f64, f64, f64, f64, f64, f64),
}

impl Shape {
    fn contains(&self, x: f64, y: f64) -> bool {
        match *self {
            Shape::Disc(cx, cy, r) => (x - cx).powi(2) + (y - cy).powi(2) < r * r,
            Shape::Rect(cx, cy, hu, hv, c, s) => {
                let (dx, dy) = (x - cx, y - cy);
                (dx * c + dy * s).abs() < hu && (-dx * s + dy * c).abs() < hv
            }
        }
    }
}

impl Raster2d {
    /// Every kind: the set a planar bias test should loop over.
    ///
    /// # Example
    /// ```
    /// assert_eq!(tessera::synth::Raster2d::all().len(), 7);
    /// ```
    pub fn all() -> &'static [Raster2d] {
        &ALL
    }

    /// A short stable name for file names and reports.
    ///
    /// # Example
    /// ```
    /// assert_eq!(tessera::synth::Raster2d::ZeroNoise.name(), "zero-noise");
    /// ```
    pub fn name(&self) -> &'static str {
        match self {
            Raster2d::Discs => "discs",
            Raster2d::Rectangles => "rectangles",
            Raster2d::Step => "step",
            Raster2d::Gradient => "gradient",
            Raster2d::Lognormal => "lognormal",
            Raster2d::ZeroNoise => "zero-noise",
            Raster2d::Mixed => "mixed",
        }
    }

    /// The raster's `width * height` values, row-major, row 0 on top;
    /// deterministic for `seed`.
    ///
    /// # Example
    /// ```
    /// use tessera::synth::Raster2d;
    /// let v = Raster2d::ZeroNoise.generate(100, 100, 1);
    /// let zeros = v.iter().filter(|&&x| x == 0.0).count();
    /// assert!((1500..2500).contains(&zeros));
    /// assert_eq!(v, Raster2d::ZeroNoise.generate(100, 100, 1));
    /// ```
    pub fn generate(&self, width: usize, height: usize, seed: u64) -> Vec<f64> {
        if width == 0 || height == 0 {
            return Vec::new();
        }
        let rng = &mut SplitMix64::new(seed);
        let (w, h) = (width as f64, height as f64);
        let mut values = match self {
            Raster2d::Discs => paint_shapes(width, height, &discs(w, h, rng), 0.05),
            Raster2d::Rectangles => paint_shapes(width, height, &rectangles(w, h, rng), 0.05),
            Raster2d::Step => {
                let step = step(w, h, rng);
                pixels(width, height, |x, y| if step(x, y) { 1.0 } else { 0.02 })
            }
            Raster2d::Gradient => {
                let ramp = ramp(w, h, rng);
                let (bx, by) = (uniform(rng, 0.2, 0.8) * w, uniform(rng, 0.2, 0.8) * h);
                let s = uniform(rng, 0.1, 0.25) * w.min(h);
                pixels(width, height, |x, y| {
                    let r2 = ((x - bx).powi(2) + (y - by).powi(2)) / (s * s);
                    0.5 * ramp(x, y) + 0.5 * (-0.5 * r2).exp()
                })
            }
            Raster2d::Lognormal => texture(width, height, rng)
                .into_iter()
                .map(f64::exp)
                .collect(),
            Raster2d::ZeroNoise => {
                let ramp = ramp(w, h, rng);
                let mut v = pixels(width, height, ramp);
                zero_fraction(&mut v, 0.2, rng);
                v
            }
            Raster2d::Mixed => {
                let f = texture(width, height, rng);
                let step = step(w, h, rng);
                let mut shapes = discs(w, h, rng);
                shapes.extend(rectangles(w, h, rng));
                let mut v: Vec<f64> = f
                    .iter()
                    .enumerate()
                    .map(|(k, f)| {
                        let (x, y) = ((k % width) as f64 + 0.5, (k / width) as f64 + 0.5);
                        0.1 * (0.5 * f).exp() * if step(x, y) { 1.0 } else { 0.3 }
                    })
                    .collect();
                paint_over(&mut v, width, &shapes);
                zero_fraction(&mut v, 0.05, rng);
                v
            }
        };
        values.iter_mut().for_each(|v| *v = v.max(0.0));
        values
    }
}

/// `f(x, y)` at every pixel centre (pixel units), row-major.
fn pixels(width: usize, height: usize, f: impl Fn(f64, f64) -> f64) -> Vec<f64> {
    (0..width * height)
        .map(|k| f((k % width) as f64 + 0.5, (k / width) as f64 + 0.5))
        .collect()
}

/// Unit-variance fBm with roughly square cells, 4 across the shorter side
/// at the coarsest octave.
fn texture(width: usize, height: usize, rng: &mut SplitMix64) -> Vec<f64> {
    let rows0 = (4 * height / width.min(height)).max(1);
    let cols0 = (4 * width / width.min(height)).max(1);
    fbm(width, height, (rows0, cols0), 0.6, rng)
}

/// A ramp from 0.05 to 1 across the raster along a random direction.
fn ramp(w: f64, h: f64, rng: &mut SplitMix64) -> impl Fn(f64, f64) -> f64 {
    let a = uniform(rng, 0.0, std::f64::consts::TAU);
    let (c, s) = (a.cos() / w, a.sin() / h);
    // the projection's range over the corners, to map it onto [0.05, 1]
    let corners = [0.0, c * w, s * h, c * w + s * h];
    let lo = corners.iter().copied().fold(f64::INFINITY, f64::min);
    let hi = corners.iter().copied().fold(f64::NEG_INFINITY, f64::max);
    move |x, y| 0.05 + 0.95 * ((c * x + s * y - lo) / (hi - lo)).clamp(0.0, 1.0)
}

/// The bright side of a straight edge at a random angle through a point
/// in the middle 40 % of the raster both ways.
fn step(w: f64, h: f64, rng: &mut SplitMix64) -> impl Fn(f64, f64) -> bool {
    let (px, py) = (uniform(rng, 0.3, 0.7) * w, uniform(rng, 0.3, 0.7) * h);
    let a = uniform(rng, 0.0, std::f64::consts::TAU);
    let (c, s) = a.sin_cos();
    move |x, y| (x - px) * c + (y - py) * s >= 0.0
}

fn discs(w: f64, h: f64, rng: &mut SplitMix64) -> Vec<(Shape, f64)> {
    let n = 6 + (rng.next_f64() * 7.0) as usize;
    (0..n)
        .map(|_| {
            let (x, y) = (rng.next_f64() * w, rng.next_f64() * h);
            let r = uniform(rng, 0.03, 0.15) * w.min(h);
            (Shape::Disc(x, y, r), uniform(rng, 0.2, 1.0))
        })
        .collect()
}

fn rectangles(w: f64, h: f64, rng: &mut SplitMix64) -> Vec<(Shape, f64)> {
    let n = 5 + (rng.next_f64() * 6.0) as usize;
    (0..n)
        .map(|k| {
            let (x, y) = (rng.next_f64() * w, rng.next_f64() * h);
            let (hu, hv) = (
                uniform(rng, 0.03, 0.2) * w.min(h),
                uniform(rng, 0.03, 0.2) * w.min(h),
            );
            let a = if k % 2 == 1 {
                uniform(rng, 0.0, std::f64::consts::PI)
            } else {
                0.0
            };
            (
                Shape::Rect(x, y, hu, hv, a.cos(), a.sin()),
                uniform(rng, 0.2, 1.0),
            )
        })
        .collect()
}

/// Shapes painted in order (later ones on top) over a constant.
fn paint_shapes(width: usize, height: usize, shapes: &[(Shape, f64)], background: f64) -> Vec<f64> {
    let mut v = vec![background; width * height];
    paint_over(&mut v, width, shapes);
    v
}

fn paint_over(v: &mut [f64], width: usize, shapes: &[(Shape, f64)]) {
    for (k, p) in v.iter_mut().enumerate() {
        let (x, y) = ((k % width) as f64 + 0.5, (k / width) as f64 + 0.5);
        for (shape, value) in shapes {
            if shape.contains(x, y) {
                *p = *value;
            }
        }
    }
}

/// Sets a random `fraction` of the values to exactly 0.
fn zero_fraction(v: &mut [f64], fraction: f64, rng: &mut SplitMix64) {
    for p in v {
        if rng.next_f64() < fraction {
            *p = 0.0;
        }
    }
}

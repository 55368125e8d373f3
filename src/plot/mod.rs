//! Pictures a user looks at before reading numbers: planar stipples (y
//! down, as in images), sphere
//! views (equirectangular and orthographic, samples over their map),
//! periodogram images and line plots (linear or log-log, several series
//! with markers and a legend, ticks, a title and axis names in an 8x8
//! bitmap font). Pure functions returning image buffers; saving is the caller's.
//!
//! ```
//! use tessera::plot::{line_plot, stipple, Axes, Labels, Marker, Series};
//! let square = tessera::density::rectangle::Rectangle::UNIT;
//! let img = stipple(&[glam::DVec2::new(0.5, 0.5)], square, 64).unwrap();
//! assert_eq!(img.dimensions(), (64, 64));
//! let s = Series { points: vec![(1.0, 1.0), (10.0, 0.1)], color: [200, 0, 0], name: String::new(), marker: Marker::Square };
//! let plot = line_plot(&[s], Axes { log_x: true, log_y: true }, &Labels::default(), 320, 240);
//! assert_eq!(plot.dimensions(), (320, 240));
//! ```

pub mod svg;

use crate::density::envmap::Up;
use crate::density::rectangle::Rectangle;
use crate::lights::RgbMap;
use crate::Error;
use glam::{DVec2, DVec3};
use image::{GrayImage, Luma, Rgb, RgbImage};
use std::f64::consts::{PI, TAU};

/// Distinct colours for plot series, with [`PALETTE_NAMES`] for legends.
///
/// # Example
/// ```
/// assert_eq!(tessera::plot::PALETTE.len(), tessera::plot::PALETTE_NAMES.len());
/// ```
pub const PALETTE: [[u8; 3]; 16] = [
    [228, 26, 28],
    [55, 126, 184],
    [77, 175, 74],
    [152, 78, 163],
    [255, 127, 0],
    [166, 86, 40],
    [247, 129, 191],
    [120, 120, 120],
    [0, 0, 0],
    [23, 190, 207],
    [188, 189, 34],
    [0, 0, 140],
    [128, 0, 0],
    [0, 128, 128],
    [230, 190, 0],
    [170, 110, 255],
];

/// Names of the [`PALETTE`] colours.
///
/// # Example
/// ```
/// assert_eq!(tessera::plot::PALETTE_NAMES[0], "red");
/// ```
pub const PALETTE_NAMES: [&str; 16] = [
    "red", "blue", "green", "purple", "orange", "brown", "pink", "grey", "black", "cyan", "olive",
    "navy", "maroon", "teal", "gold", "lavender",
];

const WHITE: Luma<u8> = Luma([255]);
const BLACK: Luma<u8> = Luma([0]);

/// A white canvas; dots one pixel wide, or 3x3 when the set is sparse
/// enough (at least 64 pixels per point) for them not to merge.
fn canvas(width: u32, height: u32, n: usize) -> (GrayImage, i64) {
    let radius = i64::from((width as usize * height as usize) >= 64 * n.max(1));
    (GrayImage::from_pixel(width, height, WHITE), radius)
}

fn dot(img: &mut GrayImage, col: i64, row: i64, radius: i64, value: Luma<u8>) {
    for r in row - radius..=row + radius {
        for c in col - radius..=col + radius {
            if (0..img.width() as i64).contains(&c) && (0..img.height() as i64).contains(&r) {
                img.put_pixel(c as u32, r as u32, value);
            }
        }
    }
}

/// Pixel index of coordinate `t` in `[0, 1]` on an axis of `len` pixels.
fn pixel(t: f64, len: u32) -> i64 {
    ((t * len as f64).floor() as i64).clamp(0, len as i64 - 1)
}

/// Black dots for planar points on a white image `width` pixels wide and
/// as tall as `domain`'s aspect makes it, y down as in images, so that the
/// stipple of an image density comes out upright: `(x, y)` lands in column
/// `⌊(x − x0) / (x1 − x0) · width⌋` and row `⌊(y − y0) / (y1 − y0) · height⌋`
/// (the far edges in the last column and row). A point that is not finite
/// or lies outside `domain` is an error naming it, not a dot piled on the
/// border, as is an image with a side over [`MAX_STIPPLE_SIDE`] pixels.
///
/// # Example
/// ```
/// use tessera::density::rectangle::Rectangle;
/// let img = tessera::plot::stipple(&[glam::DVec2::new(0.1, 0.1)], Rectangle::UNIT, 100).unwrap();
/// assert_eq!(img.get_pixel(10, 10)[0], 0);
/// assert_eq!(img.get_pixel(50, 50)[0], 255);
/// let wide = Rectangle::new(0.0, 0.0, 2.0, 1.0).unwrap();
/// assert_eq!(tessera::plot::stipple(&[], wide, 100).unwrap().dimensions(), (100, 50));
/// let e = tessera::plot::stipple(&[glam::DVec2::new(1.5, 0.5)], Rectangle::UNIT, 100);
/// assert!(e.unwrap_err().to_string().contains("point 1 (1.5, 0.5)"));
/// ```
pub fn stipple(points: &[DVec2], domain: Rectangle, width: u32) -> Result<GrayImage, Error> {
    let size = domain.hi - domain.lo;
    let height = (f64::from(width) * size.y / size.x).round().max(1.0);
    if width == 0 || width > MAX_STIPPLE_SIDE || height > f64::from(MAX_STIPPLE_SIDE) {
        return Err(Error::Request(format!(
            "a stipple of the domain {} x {} at {width} pixels wide would be {height} pixels high; \
             an image takes 1 to {MAX_STIPPLE_SIDE} pixels a side",
            size.x, size.y
        )));
    }
    let height = height as u32;
    let (mut img, radius) = canvas(width, height, points.len());
    for (i, p) in points.iter().enumerate() {
        if !domain.holds(*p) {
            let (lo, hi) = (domain.lo, domain.hi);
            let why = if p.is_finite() {
                format!(
                    "lies outside the plotted domain {},{},{},{}",
                    lo.x, lo.y, hi.x, hi.y
                )
            } else {
                "is not finite".into()
            };
            return Err(Error::Request(format!(
                "point {} ({}, {}) {why}",
                i + 1,
                p.x,
                p.y
            )));
        }
        let t = (*p - domain.lo) / size;
        dot(
            &mut img,
            pixel(t.x, width),
            pixel(t.y, height),
            radius,
            BLACK,
        );
    }
    Ok(img)
}

/// The tallest (or widest) stipple [`stipple`] draws, in pixels.
///
/// # Example
/// ```
/// assert!(tessera::plot::MAX_STIPPLE_SIDE >= 4096);
/// ```
pub const MAX_STIPPLE_SIDE: u32 = 32_768;

/// Pixel `(column, row)` of direction `m` (map frame, +Z up) in a
/// `width x height` lat-long image with the map convention of
/// [`EnvMap`](crate::density::envmap): `phi = atan2(y, x) mod 2π` from 0 at
/// the left edge, `theta` from +Z at the top row.
fn lat_long_pixel(m: DVec3, width: u32, height: u32) -> (i64, i64) {
    // + 0 turns −0 into +0: the poles at phi = 0
    let phi = (m.y + 0.0).atan2(m.x + 0.0).rem_euclid(TAU);
    let theta = m.z.clamp(-1.0, 1.0).acos();
    (pixel(phi / TAU, width), pixel(theta / PI, height))
}

/// Equirectangular view of points on the unit sphere, `width x width/2`,
/// in the lat-long map convention (column 0 at `phi = atan2(y, x) = 0`,
/// phi growing to the right; the north pole `+z` at the top row), so that
/// it lines up with the map a set was drawn from (see [`over_map`]).
///
/// # Example
/// ```
/// use glam::DVec3;
/// let img = tessera::plot::equirectangular(&[DVec3::X, DVec3::Z, -DVec3::X], 200);
/// assert_eq!(img.dimensions(), (200, 100));
/// assert_eq!(img.get_pixel(0, 50)[0], 0); // +x: phi 0, the left edge, on the equator
/// assert_eq!(img.get_pixel(100, 50)[0], 0); // −x: phi = π, the middle
/// assert_eq!(img.get_pixel(0, 0)[0], 0); // the north pole
/// ```
pub fn equirectangular(points: &[DVec3], width: u32) -> GrayImage {
    let height = (width / 2).max(1);
    let (mut img, radius) = canvas(width, height, points.len());
    for p in points.iter().filter(|p| p.is_finite()) {
        let (col, row) = lat_long_pixel(*p, width, height);
        dot(&mut img, col, row, radius, BLACK);
    }
    img
}

/// A lat-long map for display, `width x width/2`: each output pixel the
/// mean of the map pixels it covers, scaled so that the mean luminance
/// reads 0.18 (the map's level, whatever its units), compressed by
/// Reinhard's `v / (1 + v)` per channel and encoded as sRGB.
///
/// # Example
/// ```
/// use tessera::lights::RgbMap;
/// let map = RgbMap { width: 4, height: 2, rgb: vec![[2.0, 2.0, 2.0]; 8], bad_samples: 0 };
/// let img = tessera::plot::tone_map(&map, 8);
/// assert_eq!(img.dimensions(), (8, 4));
/// // 0.18 / (1 + 0.18) in sRGB
/// assert!(img.pixels().all(|p| p.0 == [109, 109, 109]));
/// ```
pub fn tone_map(map: &RgbMap, width: u32) -> RgbImage {
    let height = (width / 2).max(1);
    let luminance = map.luminance();
    let mean = luminance.iter().sum::<f64>() / luminance.len().max(1) as f64;
    let scale = if mean > 0.0 { 0.18 / mean } else { 1.0 };
    let srgb = |v: f64| {
        let v = (v / (1.0 + v)).clamp(0.0, 1.0);
        let e = if v <= 0.003_130_8 {
            12.92 * v
        } else {
            1.055 * v.powf(1.0 / 2.4) - 0.055
        };
        (e * 255.0).round() as u8
    };
    // the map pixels [lo, hi) an output pixel k of n covers
    let span = |k: u32, n: u32, len: usize| {
        let lo = k as usize * len / n as usize;
        (
            lo,
            (((k + 1) as usize * len).div_ceil(n as usize))
                .max(lo + 1)
                .min(len),
        )
    };
    RgbImage::from_fn(width, height, |x, y| {
        let (c0, c1) = span(x, width, map.width);
        let (r0, r1) = span(y, height, map.height);
        let mut sum = [0.0f64; 3];
        for row in r0..r1 {
            for p in &map.rgb[row * map.width + c0..row * map.width + c1] {
                (0..3).for_each(|c| sum[c] += f64::from(p[c]).max(0.0));
            }
        }
        let count = ((r1 - r0) * (c1 - c0)).max(1) as f64;
        Rgb(sum.map(|v| srgb(v / count * scale)))
    })
}

/// Samples drawn over the map they were drawn from: the [`tone_map`] of
/// `map` (`width x width/2`) with each point a red dot (3x3, outlined in
/// black, when there are at least 64 pixels a point) at its map pixel;
/// `up` is the map's up axis, as when sampling it.
///
/// # Example
/// ```
/// use glam::DVec3;
/// use tessera::{density::envmap::Up, lights::RgbMap};
/// let map = RgbMap { width: 8, height: 4, rgb: vec![[1.0; 3]; 32], bad_samples: 0 };
/// let img = tessera::plot::over_map(&[DVec3::X], &map, Up::Z, 64);
/// assert_eq!(img.get_pixel(1, 16).0, [255, 0, 0]); // phi 0 on the equator
/// ```
pub fn over_map(points: &[DVec3], map: &RgbMap, up: Up, width: u32) -> RgbImage {
    let mut img = tone_map(map, width);
    let (w, h) = img.dimensions();
    let big = (w as usize * h as usize) >= 64 * points.len().max(1);
    let pixels: Vec<(i64, i64)> = points
        .iter()
        .filter(|p| p.is_finite())
        .map(|p| lat_long_pixel(up.to_map(*p), w, h))
        .collect();
    if big {
        for &(col, row) in &pixels {
            for (dx, dy) in (-2..=2).flat_map(|dx| (-2..=2).map(move |dy| (dx, dy))) {
                put(&mut img, col + dx, row + dy, [0, 0, 0]);
            }
        }
    }
    let r = i64::from(big);
    for &(col, row) in &pixels {
        for (dx, dy) in (-r..=r).flat_map(|dx| (-r..=r).map(move |dy| (dx, dy))) {
            put(&mut img, col + dx, row + dy, [255, 0, 0]);
        }
    }
    img
}

/// Orthographic view (`size x size`) of the hemisphere facing a viewer far
/// away in direction `toward`: the disc's outline in grey, the points with
/// `p · toward > 0` in black. Screen up is the projection of `+z` (of `+x`
/// when looking along the z axis), screen right completes the frame.
///
/// # Example
/// ```
/// use glam::DVec3;
/// let near_z = DVec3::new(0.1, 0.0, 1.0).normalize();
/// let img = tessera::plot::orthographic(&[DVec3::X, -DVec3::X, near_z], 101, DVec3::X);
/// assert_eq!(img.get_pixel(50, 50)[0], 0); // +x faces the viewer: the centre
/// assert_eq!(img.get_pixel(50, 0)[0], 0); // near +z: top of the disc
/// ```
pub fn orthographic(points: &[DVec3], size: u32, toward: DVec3) -> GrayImage {
    let (mut img, radius) = canvas(size, size, points.len() / 2);
    let f = toward.normalize();
    let up = if f.z.abs() > 0.999 {
        DVec3::X
    } else {
        DVec3::Z
    };
    let e2 = (up - up.dot(f) * f).normalize();
    let e1 = e2.cross(f);
    let to_pixel = |a: f64, b: f64| (pixel((1.0 + a) / 2.0, size), pixel((1.0 - b) / 2.0, size));
    let steps = 8 * size as usize;
    for k in 0..steps {
        let (s, c) = (TAU * k as f64 / steps as f64).sin_cos();
        let (col, row) = to_pixel(c, s);
        dot(&mut img, col, row, 0, Luma([160]));
    }
    for p in points.iter().filter(|p| p.is_finite() && p.dot(f) > 0.0) {
        let (col, row) = to_pixel(p.dot(e1), p.dot(e2));
        dot(&mut img, col, row, radius, BLACK);
    }
    img
}

/// A `size x size` grid of non-negative values (row-major, row 0 at the
/// bottom, as a periodogram's `ky` grows upward) as grey levels on a log
/// scale between the 1st and 99th percentiles of the positive values
/// (white: high). Non-positive and non-finite values are black.
///
/// # Example
/// ```
/// let img = tessera::plot::log_image(&[1.0, 10.0, 100.0, 0.0], 2);
/// assert_eq!(img.get_pixel(0, 0)[0], 255); // value 100: top-left
/// assert_eq!(img.get_pixel(0, 1)[0], 0); // value 1, bottom-left
/// ```
pub fn log_image(values: &[f64], size: usize) -> GrayImage {
    let mut logs: Vec<f64> = values
        .iter()
        .filter(|v| v.is_finite() && **v > 0.0)
        .map(|v| v.ln())
        .collect();
    logs.sort_by(f64::total_cmp);
    let pick = |q: f64| logs.get(((logs.len() as f64 - 1.0) * q).round() as usize);
    let (lo, hi) = (pick(0.01).copied(), pick(0.99).copied());
    let side = size as u32;
    let mut img = GrayImage::from_pixel(side, side, BLACK);
    let (Some(lo), Some(hi)) = (lo, hi) else {
        return img;
    };
    let span = (hi - lo).max(1e-300);
    for (k, v) in values.iter().enumerate().take(size * size) {
        if v.is_finite() && *v > 0.0 {
            let t = ((v.ln() - lo) / span).clamp(0.0, 1.0);
            let (col, row) = ((k % size) as u32, (size - 1 - k / size) as u32);
            img.put_pixel(col, row, Luma([(t * 255.0).round() as u8]));
        }
    }
    img
}

/// One curve of a [`line_plot`]: `(x, y)` points joined in order, named
/// in the legend (unless the name is empty).
///
/// # Example
/// ```
/// use tessera::plot::{Marker, Series};
/// let s = Series { points: vec![(0.0, 1.0)], color: [0, 0, 0], name: "a".into(), marker: Marker::Square };
/// assert_eq!(s.points.len(), 1);
/// ```
#[derive(Clone, Debug, PartialEq)]
pub struct Series {
    /// The points, in drawing order.
    pub points: Vec<(f64, f64)>,
    /// RGB colour.
    pub color: [u8; 3],
    /// Legend entry; empty for none.
    pub name: String,
    /// The mark at each point.
    pub marker: Marker,
}

/// The mark a [`Series`] draws at each point (5 pixels across), so that
/// series of one colour stay apart.
///
/// # Example
/// ```
/// assert_ne!(tessera::plot::Marker::Square, tessera::plot::Marker::Cross);
/// ```
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Marker {
    /// A filled square.
    Square,
    /// A square outline.
    Hollow,
    /// A diagonal cross.
    Cross,
    /// An upright cross.
    Plus,
    /// A diamond outline.
    Diamond,
    /// No mark: the line alone.
    None,
}

impl Marker {
    /// The pixels of the mark around its centre.
    fn offsets(self) -> Vec<(i64, i64)> {
        let square = (-2..=2).flat_map(|dx| (-2..=2).map(move |dy| (dx, dy)));
        match self {
            Marker::Square => square.collect(),
            Marker::Hollow => square
                .filter(|(x, y)| x.abs() == 2 || y.abs() == 2)
                .collect(),
            Marker::Cross => (-2..=2).flat_map(|d| [(d, d), (d, -d)]).collect(),
            Marker::Plus => (-2..=2).flat_map(|d| [(d, 0), (0, d)]).collect(),
            Marker::Diamond => (-3i64..=3)
                .flat_map(|d| {
                    let e = 3 - d.abs();
                    [(d, e), (d, -e)]
                })
                .collect(),
            Marker::None => Vec::new(),
        }
    }
}

/// The words around a [`line_plot`]: a title above, the axes' names.
///
/// # Example
/// ```
/// let l = tessera::plot::Labels { title: "t".into(), ..Default::default() };
/// assert!(l.x.is_empty());
/// ```
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct Labels {
    /// Above the frame.
    pub title: String,
    /// Under the x axis.
    pub x: String,
    /// Beside the y axis, written upwards.
    pub y: String,
}

/// Axis scales of a [`line_plot`].
///
/// # Example
/// ```
/// let loglog = tessera::plot::Axes { log_x: true, log_y: true };
/// assert!(loglog.log_x);
/// ```
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Axes {
    /// Logarithmic x axis (non-positive x are dropped).
    pub log_x: bool,
    /// Logarithmic y axis (non-positive y are dropped).
    pub log_y: bool,
}

/// One axis: data range (after the log when logarithmic) and pixel span.
struct Scale {
    log: bool,
    lo: f64,
    hi: f64,
}

impl Scale {
    fn new(log: bool, values: impl Iterator<Item = f64>) -> Self {
        let (mut lo, mut hi) = (f64::INFINITY, f64::NEG_INFINITY);
        for v in values.filter_map(|v| Self::map(log, v)) {
            lo = lo.min(v);
            hi = hi.max(v);
        }
        if lo > hi {
            (lo, hi) = (0.0, 1.0);
        }
        let pad = if hi > lo { 0.04 * (hi - lo) } else { 0.5 };
        Scale {
            log,
            lo: lo - pad,
            hi: hi + pad,
        }
    }

    fn map(log: bool, v: f64) -> Option<f64> {
        let m = if log { v.log10() } else { v };
        (v.is_finite() && (!log || v > 0.0)).then_some(m)
    }

    /// Position in `[0, 1]` along the axis.
    fn unit(&self, v: f64) -> Option<f64> {
        Self::map(self.log, v).map(|m| (m - self.lo) / (self.hi - self.lo))
    }

    /// Tick positions (data values): decades on a log axis (every other
    /// one when there are more than 8), else 1, 2 or 5 times a power of
    /// ten giving 4 to 10 ticks.
    fn ticks(&self) -> Vec<f64> {
        if self.log {
            let (a, b) = (self.lo.ceil() as i32, self.hi.floor() as i32);
            let step = if b - a > 8 { 2 } else { 1 };
            return (a..=b).step_by(step).map(|e| 10f64.powi(e)).collect();
        }
        let span = self.hi - self.lo;
        let base = 10f64.powf((span / 10.0).log10().ceil());
        let step = [0.2, 0.5, 1.0]
            .iter()
            .map(|m| m * base)
            .find(|s| span / s <= 10.0)
            .unwrap_or(base);
        let first = (self.lo / step).ceil() as i64;
        let last = (self.hi / step).floor() as i64;
        (first..=last).map(|k| k as f64 * step).collect()
    }
}

/// Width in pixels of `text` as [`label`] draws it.
fn text_width(text: &str) -> i64 {
    8 * text.chars().count() as i64
}

/// Draws `text` (ASCII, 8x8 pixels a character) in black with its top-left
/// corner at `(x, y)`, upright or, when `upwards`, turned a quarter left
/// (reading bottom to top, `(x, y)` then the bottom-left corner).
fn label(img: &mut RgbImage, text: &str, x: i64, y: i64, upwards: bool) {
    for (k, c) in text.chars().enumerate() {
        let rows = font8x8::legacy::BASIC_LEGACY
            .get(c as usize)
            .copied()
            .unwrap_or([0; 8]);
        for (r, bits) in rows.iter().enumerate() {
            for b in 0..8 {
                if bits >> b & 1 == 1 {
                    let (along, across) = (8 * k as i64 + b, r as i64);
                    let (px, py) = if upwards {
                        (x + across, y - along)
                    } else {
                        (x + along, y + across)
                    };
                    put(img, px, py, [0, 0, 0]);
                }
            }
        }
    }
}

fn put(img: &mut RgbImage, x: i64, y: i64, color: [u8; 3]) {
    if (0..img.width() as i64).contains(&x) && (0..img.height() as i64).contains(&y) {
        img.put_pixel(x as u32, y as u32, Rgb(color));
    }
}

/// Straight segment by sampling it every half pixel.
fn segment(img: &mut RgbImage, a: (f64, f64), b: (f64, f64), color: [u8; 3]) {
    let steps = (2.0 * (b.0 - a.0).abs().max((b.1 - a.1).abs()))
        .ceil()
        .max(1.0) as usize;
    for k in 0..=steps {
        let t = k as f64 / steps as f64;
        let (x, y) = (a.0 + t * (b.0 - a.0), a.1 + t * (b.1 - a.1));
        put(img, x.round() as i64, y.round() as i64, color);
    }
}

/// Tick label: `1e-3` style for decades, else the shortest plain number.
fn tick_text(v: f64, log: bool) -> String {
    if log {
        format!("1e{}", v.log10().round() as i32)
    } else {
        let s = format!("{:.3}", v);
        s.trim_end_matches('0').trim_end_matches('.').to_string()
    }
}

/// Several series on shared axes (`width x height`, white background):
/// the title above a frame, ticks with numeric labels, the axes' names,
/// each series as joined points with its marker, and a legend of the named
/// series in a column at the right. Points that a log axis cannot show are
/// dropped.
///
/// # Example
/// ```
/// use tessera::plot::{line_plot, Axes, Labels, Marker, Series};
/// let s = Series { points: vec![(1.0, 1.0), (100.0, 0.01)], color: [255, 0, 0], name: "fit".into(), marker: Marker::Square };
/// let labels = Labels { title: "error".into(), x: "N".into(), y: "RMSE".into() };
/// let img = line_plot(&[s], Axes { log_x: true, log_y: true }, &labels, 400, 300);
/// assert!(img.pixels().any(|p| p.0 == [255, 0, 0]));
/// ```
pub fn line_plot(
    series: &[Series],
    axes: Axes,
    labels: &Labels,
    width: u32,
    height: u32,
) -> RgbImage {
    let all = || series.iter().flat_map(|s| s.points.iter());
    let sx = Scale::new(axes.log_x, all().map(|p| p.0));
    let sy = Scale::new(axes.log_y, all().map(|p| p.1));
    let mut img = RgbImage::from_pixel(width, height, Rgb([255, 255, 255]));
    let named: Vec<&Series> = series.iter().filter(|s| !s.name.is_empty()).collect();
    let legend = named
        .iter()
        .map(|s| text_width(&s.name))
        .max()
        .map(|w| w + 40);
    let y_ticks = sy.ticks();
    let tick_width = y_ticks
        .iter()
        .map(|&t| text_width(&tick_text(t, sy.log)))
        .max()
        .unwrap_or(0);
    let left = (tick_width + 24) as f64;
    let right = width as f64 - 12.0 - legend.unwrap_or(0) as f64;
    let top = if labels.title.is_empty() { 12.0 } else { 28.0 };
    let bottom = height as f64 - if labels.x.is_empty() { 24.0 } else { 40.0 };
    let to_px = |x: f64, y: f64| -> Option<(f64, f64)> {
        let (u, v) = (sx.unit(x)?, sy.unit(y)?);
        Some((left + u * (right - left), bottom - v * (bottom - top)))
    };
    let frame = [(left, top), (right, top), (right, bottom), (left, bottom)];
    for k in 0..4 {
        segment(&mut img, frame[k], frame[(k + 1) % 4], [0, 0, 0]);
    }
    for t in sx.ticks() {
        if let Some(u) = sx.unit(t) {
            let x = left + u * (right - left);
            segment(&mut img, (x, bottom), (x, bottom - 6.0), [0, 0, 0]);
            let text = tick_text(t, sx.log);
            let at = x as i64 - text_width(&text) / 2;
            label(&mut img, &text, at, bottom as i64 + 5, false);
        }
    }
    for t in y_ticks {
        if let Some(v) = sy.unit(t) {
            let y = bottom - v * (bottom - top);
            segment(&mut img, (left, y), (left + 6.0, y), [0, 0, 0]);
            let text = tick_text(t, sy.log);
            let at = left as i64 - 4 - text_width(&text);
            label(&mut img, &text, at, y as i64 - 4, false);
        }
    }
    let middle = |lo: f64, hi: f64, text: &str| ((lo + hi) / 2.0) as i64 - text_width(text) / 2;
    label(
        &mut img,
        &labels.title,
        middle(left, right, &labels.title),
        8,
        false,
    );
    label(
        &mut img,
        &labels.x,
        middle(left, right, &labels.x),
        bottom as i64 + 20,
        false,
    );
    let y_at = ((top + bottom) / 2.0) as i64 + text_width(&labels.y) / 2;
    label(&mut img, &labels.y, 4, y_at, true);
    let mark = |img: &mut RgbImage, (x, y): (f64, f64), s: &Series| {
        for (dx, dy) in s.marker.offsets() {
            put(img, x.round() as i64 + dx, y.round() as i64 + dy, s.color);
        }
    };
    for s in series {
        let pts: Vec<(f64, f64)> = s.points.iter().filter_map(|p| to_px(p.0, p.1)).collect();
        for w in pts.windows(2) {
            segment(&mut img, w[0], w[1], s.color);
        }
        pts.iter().for_each(|&p| mark(&mut img, p, s));
    }
    for (k, s) in named.iter().enumerate() {
        let (x, y) = (right + 12.0, top + 6.0 + 14.0 * k as f64);
        segment(&mut img, (x, y), (x + 20.0, y), s.color);
        mark(&mut img, (x + 10.0, y), s);
        label(&mut img, &s.name, x as i64 + 26, y as i64 - 4, false);
    }
    img
}

/// Grey "white noise: 1" reference line from `x0` to `x1` for spectra.
fn white_noise(x0: f64, x1: f64) -> Series {
    Series {
        points: vec![(x0, 1.0), (x1, 1.0)],
        color: PALETTE[7],
        name: "white noise".into(),
        marker: Marker::None,
    }
}

/// Figure for a planar point set's spectrum: the [`log_image`] of its
/// periodogram (left, `size x size` pixels scaled to 256, DC at the centre)
/// beside the radial power against the frequency radius `|k|` (right,
/// linear axes, 1 = white noise drawn in grey), both labelled.
///
/// # Example
/// ```
/// use tessera::{baselines::uniform_random_2d, metrics::plane::PlaneSpectrum};
/// let img = tessera::plot::plane_spectrum_figure(&PlaneSpectrum::new(&uniform_random_2d(64, 1)));
/// assert_eq!(img.dimensions(), (768, 280));
/// ```
pub fn plane_spectrum_figure(spectrum: &crate::metrics::plane::PlaneSpectrum) -> RgbImage {
    let side = 256u32;
    let grey = log_image(&spectrum.periodogram, spectrum.size);
    let grey = image::imageops::resize(&grey, side, side, image::imageops::FilterType::Nearest);
    let radial: Vec<(f64, f64)> = (1..spectrum.radial_power.len())
        .map(|r| (r as f64, spectrum.radial_power[r]))
        .collect();
    let series = [
        white_noise(1.0, radial.len() as f64),
        Series {
            points: radial,
            color: PALETTE[1],
            name: "radial power".into(),
            marker: Marker::None,
        },
    ];
    let labels = Labels {
        title: "radially averaged periodogram".into(),
        x: "frequency |k|".into(),
        y: "power (white noise 1)".into(),
    };
    let plot = line_plot(&series, Axes::default(), &labels, 2 * side, side + 24);
    let mut img = RgbImage::from_pixel(3 * side, side + 24, Rgb([255, 255, 255]));
    for (x, y, p) in grey.enumerate_pixels() {
        img.put_pixel(x, y + 24, Rgb([p[0]; 3]));
    }
    // 32 characters fit the 256 pixels
    let caption = format!(
        "periodogram{}, |k| <= {}",
        if spectrum.window < 1.0 {
            " (corner)"
        } else {
            ""
        },
        spectrum.size / 2
    );
    label(&mut img, &caption, 4, 8, false);
    image::imageops::overlay(&mut img, &plot, i64::from(side), 0);
    img
}

/// Plot of an angular power spectrum `P(l)` for `l ≥ 1` (linear axes,
/// labelled; 1 = white noise drawn in grey).
///
/// # Example
/// ```
/// let img = tessera::plot::angular_power_figure(&[4.0, 0.5, 0.8, 1.1]);
/// assert_eq!(img.dimensions(), (640, 360));
/// ```
pub fn angular_power_figure(power: &[f64]) -> RgbImage {
    let curve: Vec<(f64, f64)> = (1..power.len()).map(|l| (l as f64, power[l])).collect();
    let series = [
        white_noise(1.0, power.len().max(2) as f64 - 1.0),
        Series {
            points: curve,
            color: PALETTE[1],
            name: "P(l)".into(),
            marker: Marker::Square,
        },
    ];
    let labels = Labels {
        title: "angular power spectrum".into(),
        x: "degree l".into(),
        y: "P(l) (white noise 1)".into(),
    };
    line_plot(&series, Axes::default(), &labels, 640, 360)
}

//! An environment map as `N` directional lights with exact powers.
//!
//! [`lights`] draws `N` directions with tessera from a flattened density
//! `min(L^exponent, cap)` of the map: the exponent (below 1, see
//! [`default_exponent`]) and a per-pixel cap (no pixel expects more than
//! one draw by default) keep a sun holding a third of the energy in a few
//! pixels from taking a third of the lights. It cuts the sphere into the
//! directions' spherical Voronoi cells and gives each light its cell's
//! power, the integral of each channel over the cell (map units x
//! steradians), placed at the cell's luminance-weighted mean direction.
//! Lloyd steps (4 to 20 by default, see [`default_lloyd_steps`]) first
//! even the cells' shapes: each re-cuts the sphere around the cells' mean
//! directions and re-centres, weighted by the square of the drawn density
//! so that the steps keep the drawn spread (a Lloyd iteration weighted by
//! the map itself would drift to `L^(1/2)`), on blocks of up to 8 x 8
//! pixels. The cells partition the sphere, so the powers sum to the map's
//! integral in every channel, to rounding.
//!
//! Cells are integrated over the per-pixel model (the map constant per
//! pixel per steradian). A pixel that a distance bound proves to lie in
//! one cell goes to it whole, with its exact first moment. A pixel crossed
//! by a cell boundary is split into 2 x 2 equal-area pieces, recursively,
//! while a piece is undecided and holds more than `tolerance` of an
//! average light's power or solid angle; an undecided piece left whole is
//! shared among its candidate lights along their bisectors linearised
//! across the piece (in `(phi, theta)`, exact up to the bisectors'
//! curvature inside it). A piece holding a generator is split until
//! decided, so every light drawn where the map is positive gets positive
//! power, and Lloyd steps keep every generator on a lit pixel. On the
//! 1024 x 512 test maps at the default tolerance, light powers are within
//! about 7e-5 (relative) of the exact Voronoi cells' and directions within
//! 6e-5 rad (docs/LIGHTS.md). A k-d tree (kiddo) finds each block of
//! pixels' few candidate lights; a pass is `O(pixels log N)` plus the
//! boundary pieces, runs in parallel with rayon, and its result does not
//! depend on the thread count. Passes before the last (the Lloyd steps)
//! split boundary pixels at tolerance 1, since they only place the lights.
//!
//! ```
//! use tessera::lights::{lights, LightOptions, RgbMap};
//! use tessera::synth::Sky;
//! let rgb = RgbMap::from(Sky::Overcast.generate(128, 64, 1));
//! let map = rgb.env_map(Default::default()).unwrap();
//! let options = LightOptions { rgb: Some(&rgb), ..Default::default() };
//! let lights = lights(&map, 64, &options).unwrap();
//! assert_eq!(lights.len(), 64);
//! let total: f64 = lights.iter().map(|l| l.luminance).sum();
//! assert!((total / map.integral() - 1.0).abs() < 1e-9);
//! let red: f64 = lights.iter().map(|l| l.rgb[0]).sum();
//! assert!((red / rgb.integral()[0] - 1.0).abs() < 1e-9);
//! ```

mod cells;
mod read;

use crate::density::envmap::{EnvMap, Up};
use crate::density::Density;
use crate::io::image::{Raster, ReadOptions};
use crate::lut::SphereLut;
use crate::tiling::sphere::{SphereRegion, SphereTiling};
use crate::Error;
use glam::DVec3;
use std::f64::consts::PI;
use std::io::Write;
use std::path::Path;
use std::sync::Arc;

/// One directional light: a unit direction (world frame) and the power of
/// its cell.
///
/// # Example
/// ```
/// use tessera::lights::Light;
/// let l = Light { direction: glam::DVec3::Z, rgb: [1.0, 2.0, 3.0], luminance: 1.8596, solid_angle: 0.1 };
/// assert_eq!(l.irradiance(glam::DVec3::Z), 1.8596);
/// assert_eq!(l.irradiance(-glam::DVec3::Z), 0.0);
/// ```
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Light {
    /// Unit direction towards the light, in the world frame.
    pub direction: DVec3,
    /// The integral of each channel's radiance over the light's cell (map
    /// units x sr).
    pub rgb: [f64; 3],
    /// The integral of the map's importance (Rec.709 luminance unless
    /// another channel was chosen) over the cell.
    pub luminance: f64,
    /// The cell's solid angle (sr).
    pub solid_angle: f64,
}

impl Light {
    /// The luminance irradiance this light gives a surface of unit normal
    /// `normal`: `luminance x max(0, normal . direction)`.
    ///
    /// # Example
    /// ```
    /// use tessera::lights::Light;
    /// let l = Light { direction: glam::DVec3::X, rgb: [1.0; 3], luminance: 2.0, solid_angle: 1.0 };
    /// let n = glam::DVec3::new(1.0, 1.0, 0.0).normalize();
    /// assert!((l.irradiance(n) - 2f64.sqrt()).abs() < 1e-12);
    /// ```
    pub fn irradiance(&self, normal: DVec3) -> f64 {
        self.luminance * normal.dot(self.direction).max(0.0)
    }
}

/// The colour of a lat-long map: `(R, G, B)` per pixel, row-major, row 0
/// on top, finite and `>= 0`, in the layout of
/// [`EnvMap`].
///
/// # Example
/// ```
/// use tessera::lights::RgbMap;
/// let rgb = RgbMap { width: 2, height: 1, rgb: vec![[1.0, 1.0, 1.0], [0.0, 1.0, 0.0]], bad_samples: 0 };
/// assert!((rgb.luminance()[1] - 0.7152).abs() < 1e-12);
/// ```
#[derive(Clone, Debug, PartialEq)]
pub struct RgbMap {
    /// Columns.
    pub width: usize,
    /// Rows.
    pub height: usize,
    /// Row-major (R, G, B) per pixel, `width * height` of them.
    pub rgb: Vec<[f32; 3]>,
    /// Colour samples that were negative, NaN or infinite and were set to 0.
    pub bad_samples: usize,
}

impl From<crate::synth::SynthMap> for RgbMap {
    /// A generated map's colour (generated maps are finite and `>= 0`).
    ///
    /// # Example
    /// ```
    /// use tessera::lights::RgbMap;
    /// let rgb = RgbMap::from(tessera::synth::Sky::Smooth.generate(8, 4, 1));
    /// assert_eq!((rgb.width, rgb.height, rgb.rgb.len()), (8, 4, 32));
    /// ```
    fn from(map: crate::synth::SynthMap) -> Self {
        RgbMap {
            width: map.width,
            height: map.height,
            rgb: map.rgb,
            bad_samples: 0,
        }
    }
}

impl RgbMap {
    /// Rec.709 luminance `0.2126 R + 0.7152 G + 0.0722 B` per pixel, in f64
    /// from the f32 channels, as [`read_raster`](crate::io::image::read_raster) computes it.
    ///
    /// # Example
    /// ```
    /// use tessera::lights::RgbMap;
    /// let rgb = RgbMap { width: 1, height: 1, rgb: vec![[1.0, 0.0, 0.0]], bad_samples: 0 };
    /// assert_eq!(rgb.luminance(), vec![0.2126]);
    /// ```
    pub fn luminance(&self) -> Vec<f64> {
        self.rgb
            .iter()
            .map(|p| 0.2126 * p[0] as f64 + 0.7152 * p[1] as f64 + 0.0722 * p[2] as f64)
            .collect()
    }

    /// The luminance as a map to sample (refused, as
    /// [`EnvMap::new`] refuses, when it has no positive pixel).
    ///
    /// # Example
    /// ```
    /// use tessera::lights::RgbMap;
    /// let rgb = RgbMap { width: 2, height: 1, rgb: vec![[1.0; 3], [0.0; 3]], bad_samples: 0 };
    /// let map = rgb.env_map(Default::default()).unwrap();
    /// assert!((map.integral() - 2.0 * std::f64::consts::PI).abs() < 1e-12);
    /// ```
    pub fn env_map(&self, up: Up) -> Result<EnvMap, Error> {
        let raster = Raster {
            width: self.width,
            height: self.height,
            values: self.luminance(),
            bad_pixels: 0,
        };
        EnvMap::new(raster, up)
    }

    /// The integral of each channel over the sphere (value x sr), pixel by
    /// pixel with the solid angles [`EnvMap`] uses.
    ///
    /// # Example
    /// ```
    /// use tessera::lights::RgbMap;
    /// let rgb = RgbMap { width: 2, height: 1, rgb: vec![[1.0, 0.0, 2.0]; 2], bad_samples: 0 };
    /// let [r, g, b] = rgb.integral();
    /// assert!((r - 4.0 * std::f64::consts::PI).abs() < 1e-12 && g == 0.0 && (b - 2.0 * r).abs() < 1e-12);
    /// ```
    pub fn integral(&self) -> [f64; 3] {
        let row_area = row_solid_angles(self.width, self.height);
        let mut total = [0.0; 3];
        for (row, omega) in self.rgb.chunks(self.width.max(1)).zip(&row_area) {
            for c in 0..3 {
                total[c] += row.iter().map(|p| p[c] as f64).sum::<f64>() * omega;
            }
        }
        total
    }
}

/// Solid angle of one pixel of each row of a `width x height` lat-long map,
/// computed as [`EnvMap`] computes it.
fn row_solid_angles(width: usize, height: usize) -> Vec<f64> {
    (0..height)
        .map(|j| {
            let (a, b) = (
                j as f64 * PI / height as f64,
                (j + 1) as f64 * PI / height as f64,
            );
            std::f64::consts::TAU / width as f64
                * 2.0
                * ((a + b) / 2.0).sin()
                * ((b - a) / 2.0).sin()
        })
        .collect()
}

/// Reads a map file's colour planes and its importance raster in one
/// decode (EXR, Radiance `.hdr`, PNG, recognised by their first bytes).
/// The raster is exactly what [`read_raster`](crate::io::image::read_raster)
/// returns for the same options (luminance, or the chosen channel; bad
/// pixels zeroed and counted, or refused with `strict`). The colour planes
/// are R, G, B, or a grey file's Y (or chosen channel) three times; a
/// negative or non-finite colour sample is set to 0 and counted, or
/// refused with `strict`. Errors name the file.
///
/// # Example
/// ```
/// use tessera::io::image::{read_raster, ReadOptions};
/// use tessera::lights::read_rgb;
/// let dir = std::env::temp_dir().join(format!("tessera-doc-read-rgb-{}", std::process::id()));
/// std::fs::create_dir_all(&dir).unwrap();
/// let path = dir.join("two.exr");
/// exr::prelude::write_rgb_file(&path, 2, 1, |x, _| (x as f32, 1.0f32, 0.5f32)).unwrap();
/// let (rgb, raster) = read_rgb(&path, &ReadOptions::default()).unwrap();
/// assert_eq!(rgb.rgb[1], [1.0, 1.0, 0.5]);
/// assert_eq!(raster, read_raster(&path, &ReadOptions::default()).unwrap());
/// let e = read_rgb(&dir.join("missing.exr"), &ReadOptions::default()).unwrap_err();
/// assert!(e.to_string().contains("missing.exr"));
/// std::fs::remove_dir_all(&dir).unwrap();
/// ```
pub fn read_rgb(path: &Path, options: &ReadOptions) -> Result<(RgbMap, Raster), Error> {
    read::read_rgb(path, options)
}

/// How [`lights`] draws and places the lights.
///
/// # Example
/// ```
/// let o = tessera::lights::LightOptions::default();
/// assert!(o.rgb.is_none() && o.seed.is_none());
/// assert!(o.rgb.is_none() && o.exponent.is_none() && o.lloyd_steps.is_none());
/// assert!(o.table.is_none());
/// ```
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LightOptions<'a> {
    /// The map's colour (the same size as the map); without it every
    /// channel's power is the importance's.
    pub rgb: Option<&'a RgbMap>,
    /// Directions are drawn from the density `value^exponent` (0 draws
    /// them uniformly, 1 in proportion to the map), in `[0, 4]`; `None`
    /// takes [`default_exponent`] of the light count.
    pub exponent: Option<f64>,
    /// The most draws a pixel may expect: the density is capped pixel by
    /// pixel so that none expects more (a sun of a few pixels then takes a
    /// few lights, not a share of `n` in proportion to its energy);
    /// infinite for no cap. Positive.
    pub pixel_cap: f64,
    /// Lloyd steps before the last cut: each re-cuts the sphere around the
    /// cells' mean directions (weighted by the square of the drawn density)
    /// and re-centres, for one more pass over a grid of blocks of up to
    /// 8 x 8 pixels, at least 32 blocks per light (see [`LloydWeight`];
    /// about 50 ms on one thread for a 1024 x 512 map at `n = 4096`,
    /// docs/LIGHTS.md); at most 100. `None` takes
    /// [`default_lloyd_steps`] of the light count.
    pub lloyd_steps: Option<usize>,
    /// Split boundary pixels until a piece holds at most this fraction of
    /// an average light's power (`integral / n`) and solid angle
    /// (`4 pi / n`), in the last pass (earlier passes use `max(tolerance,
    /// 1)`). Finite and positive.
    pub tolerance: f64,
    /// Draw the directions in a uniformly random rotated frame from this
    /// seed (see [`EnvMap::with_seed`]); without it the lights are
    /// deterministic.
    pub seed: Option<u64>,
    /// Draw the directions with this sphere table instead of the built-in
    /// one (a table read at run time, [`crate::lut::Table::open`]).
    pub table: Option<&'a SphereLut>,
    /// What the Lloyd steps weight the cells' centres by.
    pub lloyd_weight: LloydWeight,
}

/// What [`lights`]' Lloyd steps weight the cells' centres by (the lights
/// themselves always end at their cells' luminance-weighted mean
/// directions, with their cells' exact powers).
///
/// # Example
/// ```
/// use tessera::lights::{LightOptions, LloydWeight};
/// assert_eq!(LightOptions::default().lloyd_weight, LloydWeight::DrawnSquared);
/// ```
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum LloydWeight {
    /// The square of the drawn density `min(L^e, cap)`, summed over blocks
    /// of up to 8 x 8 pixels (at least 32 blocks per light): a Lloyd
    /// iteration converges to points spread as the square root of its
    /// weight, so these steps keep the drawn spread and only even the
    /// cells' shapes (the default).
    #[default]
    DrawnSquared,
    /// The map itself, on its own pixels: the steps pull the spread
    /// towards `L^(1/2)` whatever the exponent (the weighting before
    /// [`LloydWeight::DrawnSquared`], kept for comparison).
    Map,
}

/// The density exponent for `n` lights when none is given, piecewise
/// linear in `log2 n` between [`EXPONENT_KNOTS`]. Few lights must cover
/// the sphere (a narrow lobe anywhere needs a light near it: a flat
/// density); many lights want cells of equal power, where the leading
/// second-order error of every smooth integrand cancels (the exponent
/// towards 1). The knots were chosen by measurement on the maps of seeds
/// 1-3 and checked on seeds 4-7; see docs/LIGHTS.md.
///
/// # Example
/// ```
/// use tessera::lights::default_exponent;
/// assert_eq!(default_exponent(16), 0.2);
/// assert_eq!(default_exponent(256), 0.875);
/// assert!((default_exponent(2048) - 0.9125).abs() < 1e-12);
/// assert_eq!(default_exponent(1 << 20), 0.95);
/// ```
pub fn default_exponent(n: usize) -> f64 {
    piecewise(&EXPONENT_KNOTS, n)
}

/// `(log2 n, exponent)` knots of [`default_exponent`], constant outside.
///
/// # Example
/// ```
/// assert_eq!(tessera::lights::EXPONENT_KNOTS[0], (6.0, 0.2));
/// ```
pub const EXPONENT_KNOTS: [(f64, f64); 6] = [
    (6.0, 0.2),
    (7.0, 0.625),
    (8.0, 0.875),
    (9.0, 0.8),
    (10.0, 0.875),
    (12.0, 0.95),
];

/// The Lloyd steps for `n` lights when none are given, piecewise linear
/// in `log2 n` between [`LLOYD_KNOTS`] and rounded: a few hundred lights
/// gain from 20 steps, while at 4096 lights and more a step gains little
/// and costs about 50 ms on one thread on a 1024 x 512 map: 4 steps keep
/// that request under 0.5 s, reading the file included (docs/LIGHTS.md).
///
/// # Example
/// ```
/// use tessera::lights::default_lloyd_steps;
/// assert_eq!(default_lloyd_steps(64), 10);
/// assert_eq!(default_lloyd_steps(512), 20);
/// assert_eq!(default_lloyd_steps(2048), 12);
/// assert_eq!(default_lloyd_steps(1 << 20), 4);
/// ```
pub fn default_lloyd_steps(n: usize) -> usize {
    piecewise(&LLOYD_KNOTS, n).round() as usize
}

/// `(log2 n, steps)` knots of [`default_lloyd_steps`], constant outside.
///
/// # Example
/// ```
/// assert_eq!(tessera::lights::LLOYD_KNOTS.last(), Some(&(12.0, 4.0)));
/// ```
pub const LLOYD_KNOTS: [(f64, f64); 4] = [(7.0, 10.0), (8.0, 20.0), (10.0, 20.0), (12.0, 4.0)];

/// Linear interpolation in `log2 n` between sorted knots, constant
/// outside them.
fn piecewise(knots: &[(f64, f64)], n: usize) -> f64 {
    let l = (n.max(1) as f64).log2();
    let (first, last) = (knots[0], knots[knots.len() - 1]);
    if l <= first.0 {
        return first.1;
    }
    if l >= last.0 {
        return last.1;
    }
    let k = knots.partition_point(|&(x, _)| x <= l);
    let ((x0, y0), (x1, y1)) = (knots[k - 1], knots[k]);
    y0 + (y1 - y0) * (l - x0) / (x1 - x0)
}

/// Default cap of the draws a pixel expects.
///
/// # Example
/// ```
/// assert_eq!(tessera::lights::LightOptions::default().pixel_cap, tessera::lights::DEFAULT_PIXEL_CAP);
/// ```
pub const DEFAULT_PIXEL_CAP: f64 = 1.0;
/// Default tolerance of the boundary split.
///
/// # Example
/// ```
/// assert_eq!(tessera::lights::LightOptions::default().tolerance, tessera::lights::DEFAULT_TOLERANCE);
/// ```
pub const DEFAULT_TOLERANCE: f64 = 0.01;

impl Default for LightOptions<'_> {
    fn default() -> Self {
        LightOptions {
            rgb: None,
            exponent: None,
            pixel_cap: DEFAULT_PIXEL_CAP,
            lloyd_steps: None,
            tolerance: DEFAULT_TOLERANCE,
            seed: None,
            table: None,
            lloyd_weight: LloydWeight::DrawnSquared,
        }
    }
}

/// How the last cut of [`lights_with_stats`] was made, and its cost.
///
/// # Example
/// ```
/// use tessera::{density::envmap::{EnvMap, Up}, io::image::Raster, lights::*};
/// let map = EnvMap::new(Raster { width: 64, height: 32, values: vec![1.0; 2048], bad_pixels: 0 }, Up::Z).unwrap();
/// let (_, stats) = lights_with_stats(&map, 16, &LightOptions::default()).unwrap();
/// assert_eq!(stats.passes, 1 + default_lloyd_steps(16));
/// // a constant map: mass and solid angle are the same fraction
/// assert!((stats.unresolved_mass - stats.unresolved_area).abs() < 1e-9);
/// assert!(stats.split_pixels > 0 && stats.pieces > 2048);
/// ```
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct LightStats {
    /// Mass of the boundary pieces shared along linearised bisectors (not
    /// proved inside one cell), as a fraction of the map's integral: the
    /// only mass whose cell is approximate.
    pub unresolved_mass: f64,
    /// Their solid angle as a fraction of `4 pi`.
    pub unresolved_area: f64,
    /// Pixels the last cut had to split.
    pub split_pixels: usize,
    /// Pieces (whole pixels included) the last cut assigned.
    pub pieces: usize,
    /// Passes over the pixels (1 + Lloyd steps).
    pub passes: usize,
}

/// `n` lights of `map` (see the [module docs](self)): exactly `n` for any
/// `n >= 1`, in the progressive order of the drawn directions. Errors on
/// `n = 0`, options out of range or colour planes of another size.
///
/// # Example
/// ```
/// use tessera::{density::envmap::{EnvMap, Up}, io::image::Raster, lights::*};
/// // one lit pixel and 10 lights: every light shares it, all positive
/// let mut values = vec![0.0; 32 * 16];
/// values[5 * 32 + 7] = 3.0;
/// let map = EnvMap::new(Raster { width: 32, height: 16, values, bad_pixels: 0 }, Up::Z).unwrap();
/// let l = lights(&map, 10, &LightOptions::default()).unwrap();
/// assert_eq!(l.len(), 10);
/// assert!(l.iter().all(|l| l.luminance > 0.0));
/// let sum: f64 = l.iter().map(|l| l.luminance).sum();
/// assert!((sum / map.integral() - 1.0).abs() < 1e-12);
/// let area: f64 = l.iter().map(|l| l.solid_angle).sum();
/// assert!((area / (4.0 * std::f64::consts::PI) - 1.0).abs() < 1e-12);
/// ```
pub fn lights(map: &EnvMap, n: usize, options: &LightOptions) -> Result<Vec<Light>, Error> {
    lights_with_stats(map, n, options).map(|(lights, _)| lights)
}

/// [`lights`] with how its last cut was made.
///
/// # Example
/// ```
/// use tessera::{lights::*, synth::Sky};
/// let rgb = RgbMap::from(Sky::ClearSky.generate(256, 128, 1));
/// let map = rgb.env_map(Default::default()).unwrap();
/// let options = LightOptions { rgb: Some(&rgb), lloyd_steps: Some(1), ..Default::default() };
/// let (l, stats) = lights_with_stats(&map, 256, &options).unwrap();
/// assert_eq!((l.len(), stats.passes), (256, 2));
/// // boundary pixels hold a part of the map; the rest went whole to a cell
/// assert!(stats.unresolved_mass > 0.0 && stats.unresolved_mass < 0.5);
/// ```
pub fn lights_with_stats(
    map: &EnvMap,
    n: usize,
    options: &LightOptions,
) -> Result<(Vec<Light>, LightStats), Error> {
    if n == 0 {
        return Err(Error::Request("lights: ask for at least one light".into()));
    }
    let exponent = options.exponent.unwrap_or_else(|| default_exponent(n));
    if !(0.0..=4.0).contains(&exponent) {
        return Err(Error::Request(format!(
            "lights: the exponent {exponent} is outside [0, 4]"
        )));
    }
    if options.pixel_cap.is_nan() || options.pixel_cap <= 0.0 {
        return Err(Error::Request(format!(
            "lights: the pixel cap {} must be positive",
            options.pixel_cap
        )));
    }
    let lloyd_steps = options
        .lloyd_steps
        .unwrap_or_else(|| default_lloyd_steps(n));
    if lloyd_steps > 100 {
        return Err(Error::Request(format!(
            "lights: {lloyd_steps} Lloyd steps is more than 100"
        )));
    }
    if !(options.tolerance.is_finite() && options.tolerance > 0.0) {
        return Err(Error::Request(format!(
            "lights: the tolerance {} must be finite and positive",
            options.tolerance
        )));
    }
    let (w, h) = (map.width(), map.height());
    if let Some(rgb) = options.rgb {
        if (rgb.width, rgb.height) != (w, h) || rgb.rgb.len() != w * h {
            return Err(Error::Request(format!(
                "lights: the colour planes are {}x{} ({} pixels) but the map is {w}x{h}",
                rgb.width,
                rgb.height,
                rgb.rgb.len()
            )));
        }
    }
    let up = map.up();
    // the directions: tessera on the flattened map
    let density = if exponent == 1.0 && options.pixel_cap.is_infinite() {
        map.clone()
    } else {
        let mut values: Vec<f64> = map.values().iter().map(|&v| flatten(v, exponent)).collect();
        if options.pixel_cap.is_finite() {
            cap_pixels(
                &mut values,
                w,
                |j| map.pixel_solid_angle(j),
                n,
                options.pixel_cap,
            );
        }
        EnvMap::new(
            Raster {
                width: w,
                height: h,
                values,
                bad_pixels: 0,
            },
            up,
        )?
    };
    let seed = options.seed.or_else(|| Density::<SphereRegion>::seed(map));
    let density = match seed {
        Some(seed) => density.with_seed(seed),
        None => density,
    };
    let tiling = options.table.map_or_else(SphereTiling::default, |lut| {
        SphereTiling::new(Arc::new(lut.clone()))
    });
    let drawn = density.generate_with(&tiling, n)?;
    let mut generators: Vec<DVec3> = drawn
        .iter()
        .map(|s| up.to_map(s.position).normalize())
        .collect();
    let row_area = (0..h).map(|j| map.pixel_solid_angle(j)).collect();
    let grid = cells::Grid::new(
        w,
        h,
        map.values(),
        options.rgb.map(|m| &m.rgb[..]),
        row_area,
    );
    // Lloyd steps place the generators on a coarser grid holding the
    // square of the drawn density (see `Placement`); the last pass cuts
    // the map itself
    let place = match options.lloyd_weight {
        LloydWeight::DrawnSquared => Some(Placement::new(density.values(), w, h, n)),
        LloydWeight::Map => None,
    };
    let place_grid = place
        .as_ref()
        .map(|p| cells::Grid::new(p.width, p.height, &p.values, None, p.row_area.clone()));
    let tol_mass = options.tolerance * map.integral() / n as f64;
    let tol_area = options.tolerance * 4.0 * PI / n as f64;
    let lit = |m: DVec3| map.radiance(up.from_map(m)) > 0.0;
    let mut passes = 0;
    loop {
        let gens = cells::Generators::new(generators.clone());
        // passes before the last only place generators: a coarser split
        let coarse = if passes < lloyd_steps {
            1f64.max(options.tolerance) / options.tolerance
        } else {
            1.0
        };
        let cut = match (&place, &place_grid) {
            (Some(p), Some(g)) if passes < lloyd_steps => {
                let tol_place = options.tolerance * p.integral / n as f64;
                cells::cells(g, &gens, tol_place * coarse, tol_area * coarse)
            }
            _ => cells::cells(&grid, &gens, tol_mass * coarse, tol_area * coarse),
        };
        passes += 1;
        let centres: Vec<DVec3> = cut
            .acc
            .iter()
            .zip(&generators)
            .map(|(a, &g)| mean_direction(a).unwrap_or(g))
            .collect();
        if passes > lloyd_steps {
            let lights = cut
                .acc
                .iter()
                .zip(&centres)
                .map(|(a, &c)| Light {
                    direction: up.from_map(c),
                    rgb: [a[2], a[3], a[4]],
                    luminance: a[0],
                    solid_angle: a[1],
                })
                .collect();
            let stats = LightStats {
                unresolved_mass: cut.unresolved_mass / map.integral(),
                unresolved_area: cut.unresolved_area / (4.0 * PI),
                split_pixels: cut.split_pixels,
                pieces: cut.pieces,
                passes,
            };
            return Ok((lights, stats));
        }
        // re-centre; a mean direction in an unlit pixel is pulled back
        // towards the (lit) generator until it is lit, so that every
        // generator stays where the map is positive
        for (g, &c) in generators.iter_mut().zip(&centres) {
            if let Some(p) = (0..=16)
                .map(|k| (c + (*g - c) * (k as f64 / 16.0)).normalize())
                .find(|&p| p.is_finite() && lit(p))
            {
                *g = p;
            }
        }
    }
}

/// What the Lloyd steps centre the cells by: the square of the drawn
/// density, summed over blocks of `f x f` pixels.
///
/// A density-weighted Lloyd iteration converges to points spread as the
/// square root of its density (the optimal quantiser's point density in
/// two dimensions), so Lloyd steps weighted by the map itself would pull
/// the drawn spread `min(L^e, cap)` towards `L^(1/2)` step by step: unequal
/// cell powers, which the smooth integrands' second-order errors no longer
/// cancel over. Weighted by the square of the drawn density, the iteration
/// keeps the drawn spread and only evens the cells' shapes. The blocks
/// (`f` the largest power of two up to [`PLACEMENT_MAX_BLOCK`] dividing the
/// map that leaves [`PLACEMENT_BLOCKS_PER_LIGHT`] blocks per light) make a
/// step somewhat cheaper (a pass's cost is mostly its `4 n` groups of
/// pixels, not its pixels); the last cut is on the map's own pixels.
struct Placement {
    width: usize,
    height: usize,
    values: Vec<f64>,
    row_area: Vec<f64>,
    integral: f64,
}

/// The fewest placement blocks per light (see `Placement`).
const PLACEMENT_BLOCKS_PER_LIGHT: usize = 32;
/// The largest placement block side in pixels (see `Placement`).
const PLACEMENT_MAX_BLOCK: usize = 8;

impl Placement {
    fn new(density: &[f64], w: usize, h: usize, n: usize) -> Self {
        let mut f = 1;
        while f < PLACEMENT_MAX_BLOCK
            && w % (2 * f) == 0
            && h % (2 * f) == 0
            && (w / (2 * f)) * (h / (2 * f)) >= PLACEMENT_BLOCKS_PER_LIGHT * n
        {
            f *= 2;
        }
        let fine = row_solid_angles(w, h);
        let (cw, ch) = (w / f, h / f);
        let row_area = row_solid_angles(cw, ch);
        let mut values = vec![0.0; cw * ch];
        for j in 0..h {
            for i in 0..w {
                let d = density[j * w + i];
                values[(j / f) * cw + i / f] += d * d * fine[j];
            }
        }
        let mut integral = 0.0;
        for (j, row) in values.chunks_mut(cw).enumerate() {
            integral += row.iter().sum::<f64>();
            row.iter_mut().for_each(|v| *v /= row_area[j]);
        }
        Placement {
            width: cw,
            height: ch,
            values,
            row_area,
            integral,
        }
    }
}

/// Caps a density so that no pixel expects more than `cap` of `n` draws:
/// each pixel's mass (value x solid angle) is limited to the `t` solving
/// `t = cap / n x sum of min(mass, t)` (bisection), or, when there are too
/// few lit pixels for that, to the smallest lit mass (every lit pixel then
/// expects the same count).
fn cap_pixels(
    values: &mut [f64],
    width: usize,
    solid_angle: impl Fn(usize) -> f64,
    n: usize,
    cap: f64,
) {
    let mass: Vec<f64> = values
        .iter()
        .enumerate()
        .map(|(p, &v)| v * solid_angle(p / width))
        .collect();
    let k = cap / n as f64;
    let top = mass.iter().cloned().fold(0.0, f64::max);
    if k * mass.iter().sum::<f64>() >= top {
        return; // no pixel expects more than `cap`
    }
    let mut active: Vec<f64> = mass.iter().cloned().filter(|&m| m > 0.0).collect();
    let t = if cap * active.len() as f64 <= n as f64 {
        active.iter().cloned().fold(f64::INFINITY, f64::min)
    } else {
        // bisection on `k sum min(m, t) > t`, keeping only the masses
        // between the bounds: those below `lo` count whole, those above
        // `hi` count `t`
        let (mut lo, mut hi, mut below, mut above) = (0.0, top, 0.0, 0usize);
        for _ in 0..64 {
            let mid = 0.5 * (lo + hi);
            let sum = below + active.iter().map(|&m| m.min(mid)).sum::<f64>() + above as f64 * mid;
            if k * sum > mid {
                lo = mid;
                active.retain(|&m| {
                    let keep = m >= mid;
                    if !keep {
                        below += m;
                    }
                    keep
                });
            } else {
                hi = mid;
                active.retain(|&m| {
                    let keep = m <= mid;
                    if !keep {
                        above += 1;
                    }
                    keep
                });
            }
        }
        hi
    };
    for (p, v) in values.iter_mut().enumerate() {
        if mass[p] > t {
            *v = t / solid_angle(p / width);
        }
    }
}

/// `v^exponent`, with `0^0 = 0` (unlit pixels stay unlit).
fn flatten(v: f64, exponent: f64) -> f64 {
    if v > 0.0 {
        v.powf(exponent)
    } else {
        0.0
    }
}

/// The normalised first moment of a cell, when it has mass and the moment
/// is not lost in cancellation.
fn mean_direction(a: &cells::Acc) -> Option<DVec3> {
    let m = DVec3::new(a[5], a[6], a[7]);
    let len = m.length();
    (a[0] > 0.0 && len > 1e-9 * a[0]).then(|| m / len)
}

/// Writes lights as CSV: the header `x,y,z,r,g,b,luminance,solid_angle`
/// and one light per line (shortest round-trip decimal form).
///
/// # Example
/// ```
/// use tessera::lights::{write_csv, Light};
/// let l = Light { direction: glam::DVec3::Z, rgb: [1.0, 2.0, 3.0], luminance: 1.5, solid_angle: 0.25 };
/// let mut out = Vec::new();
/// write_csv(&mut out, &[l]).unwrap();
/// assert_eq!(String::from_utf8(out).unwrap(), "x,y,z,r,g,b,luminance,solid_angle\n0,0,1,1,2,3,1.5,0.25\n");
/// ```
pub fn write_csv(out: &mut dyn Write, lights: &[Light]) -> std::io::Result<()> {
    writeln!(out, "x,y,z,r,g,b,luminance,solid_angle")?;
    for l in lights {
        let d = l.direction;
        writeln!(
            out,
            "{},{},{},{},{},{},{},{}",
            d.x, d.y, d.z, l.rgb[0], l.rgb[1], l.rgb[2], l.luminance, l.solid_angle
        )?;
    }
    Ok(())
}

/// Writes lights as a JSON array of objects with the keys `x`, `y`, `z`,
/// `r`, `g`, `b`, `luminance` and `solid_angle`.
///
/// # Example
/// ```
/// use tessera::lights::{write_json, Light};
/// let l = Light { direction: glam::DVec3::X, rgb: [1.0, 2.0, 3.0], luminance: 1.5, solid_angle: 0.25 };
/// let mut out = Vec::new();
/// write_json(&mut out, &[l]).unwrap();
/// let v: serde_json::Value = serde_json::from_slice(&out).unwrap();
/// assert_eq!(v[0]["x"], 1.0);
/// assert_eq!(v[0]["solid_angle"], 0.25);
/// ```
pub fn write_json(out: &mut dyn Write, lights: &[Light]) -> std::io::Result<()> {
    writeln!(out, "[")?;
    for (k, l) in lights.iter().enumerate() {
        let d = l.direction;
        let object = serde_json::json!({
            "x": d.x, "y": d.y, "z": d.z,
            "r": l.rgb[0], "g": l.rgb[1], "b": l.rgb[2],
            "luminance": l.luminance, "solid_angle": l.solid_angle,
        });
        let sep = if k + 1 < lights.len() { "," } else { "" };
        writeln!(out, "  {object}{sep}")?;
    }
    writeln!(out, "]")
}

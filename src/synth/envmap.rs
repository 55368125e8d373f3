//! The synthetic lat-long environment maps.

use super::noise::{blocky, fbm, gaussian, sprinkle_zeros, uniform, zero_lines};
use super::{luminance_of, SynthMap};
use crate::random::SplitMix64;
use glam::DVec3;
use std::collections::BTreeMap;
use std::f64::consts::{FRAC_PI_2, PI, TAU};

/// A kind of synthetic environment map, each imitating a feature of real
/// HDR maps that stresses importance sampling.
///
/// Every kind but the issue-17 reproductions and [`Sky::Smooth`] also has a
/// textured ground and the two defects clamped lossy compression leaves:
/// isolated zero pixels inside lit areas (a fraction stated per kind) and
/// one-pixel zero lines beside the brightest features. The reproductions
/// are exactly as issue 17 describes them, so its numbers can be re-run.
///
/// # Example
/// ```
/// use tessera::synth::Sky;
/// for sky in Sky::all() {
///     let map = sky.generate(64, 32, 1);
///     assert!(map.luminance().iter().all(|v| v.is_finite() && *v >= 0.0), "{}", sky.name());
/// }
/// ```
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Sky {
    /// Clear day: CIE clear-sky gradation (brighter toward the horizon) and
    /// circumsolar brightening, a limb-darkened sun disk of radius 0.3-0.45
    /// degrees at 5e4 times the sky's median (mean 4e4) at 30-40 degrees
    /// elevation, a power-law aureole over 10 degrees, antialiased;
    /// textured ground, 2 % zero pixels, zero lines beside the sun.
    ClearSky,
    /// Overcast day: CIE overcast gradation (zenith 3 times the horizon)
    /// with mild cloud texture; textured ground, 1 % zero pixels, zero
    /// lines beside the brightest pixel.
    Overcast,
    /// City at night: a dark sky with skyglow toward the horizon over dark
    /// textured ground, 300-600 lights of 1-4 pixels at 1e2-1e3 times the
    /// background level 0.01 (the map's median is about 0.004), mostly just
    /// below the horizon, 6-10 street lamps near 1e4 times it; 12 % zero pixels (dark areas compress worst), zero
    /// lines beside the street lamps.
    CityNight,
    /// A dim room seen from inside: 2-4 rectangular ceiling lamps, 1-2
    /// windows with a sky gradient and a frame, walls lit by them with
    /// texture, a plank floor; 5 % zero pixels, zero lines beside the
    /// lamps.
    Interior,
    /// Lognormal multi-scale texture over sky and ground: `exp(sigma f)`,
    /// `f` a unit-variance fBm, the texture of clouds, foliage and gravel
    /// at every scale down to pixels; 3 % zero pixels, zero lines beside
    /// the two brightest spots.
    Textured {
        /// Standard deviation of the log radiance (a non-finite one is
        /// taken as 0; the exponent is clamped to +-80 so values stay
        /// finite in f32).
        sigma: f64,
    },
    /// Issue 17's first reproduction: a smooth sky gradient over a darker
    /// ground `0.1 exp(f)`, `f` the sum of blocky Gaussian octaves of 16x32
    /// to 256x512 cells scaled to unit variance.
    GroundLognormal,
    /// Issue 17's second reproduction: the same, ground `0.2 exp(0.5 f)`.
    GroundLognormalMild,
    /// Issue 17's third reproduction: [`Sky::Smooth`] with a random 20 % of
    /// its pixels exactly 0, as clamped compression noise leaves them.
    Zeros20,
    /// The reference without texture or zeros: the smooth sky gradient
    /// over a constant ground of 0.1, where issue 17 saw no bias (the same
    /// for every seed).
    Smooth,
}

const ALL: [Sky; 11] = [
    Sky::ClearSky,
    Sky::Overcast,
    Sky::CityNight,
    Sky::Interior,
    Sky::Textured { sigma: 0.5 },
    Sky::Textured { sigma: 1.0 },
    Sky::Textured { sigma: 2.0 },
    Sky::GroundLognormal,
    Sky::GroundLognormalMild,
    Sky::Zeros20,
    Sky::Smooth,
];

impl Sky {
    /// Every kind shipped, textures at sigma 0.5, 1 and 2: the set a bias
    /// test should loop over.
    ///
    /// # Example
    /// ```
    /// use tessera::synth::Sky;
    /// assert!(Sky::all().contains(&Sky::Textured { sigma: 2.0 }));
    /// assert_eq!(Sky::all().len(), 11);
    /// ```
    pub fn all() -> &'static [Sky] {
        &ALL
    }

    /// A short stable name for file names and reports (`clear-sky`,
    /// `textured-0.5`, ...); a texture at an unshipped sigma is `textured`.
    ///
    /// # Example
    /// ```
    /// use tessera::synth::Sky;
    /// assert_eq!(Sky::ClearSky.name(), "clear-sky");
    /// assert_eq!(Sky::Textured { sigma: 1.0 }.name(), "textured-1");
    /// ```
    pub fn name(&self) -> &'static str {
        match *self {
            Sky::ClearSky => "clear-sky",
            Sky::Overcast => "overcast",
            Sky::CityNight => "city-night",
            Sky::Interior => "interior",
            Sky::Textured { sigma: 0.5 } => "textured-0.5",
            Sky::Textured { sigma: 1.0 } => "textured-1",
            Sky::Textured { sigma: 2.0 } => "textured-2",
            Sky::Textured { .. } => "textured",
            Sky::GroundLognormal => "ground-lognormal",
            Sky::GroundLognormalMild => "ground-lognormal-mild",
            Sky::Zeros20 => "zeros-20",
            Sky::Smooth => "smooth",
        }
    }

    /// The shipped kind of this name (see [`Sky::name`]).
    ///
    /// # Example
    /// ```
    /// use tessera::synth::Sky;
    /// assert_eq!(Sky::from_name("textured-2"), Some(Sky::Textured { sigma: 2.0 }));
    /// assert_eq!(Sky::from_name("sunset"), None);
    /// ```
    pub fn from_name(name: &str) -> Option<Sky> {
        ALL.iter().copied().find(|s| s.name() == name)
    }

    /// The map at `width x height` for `seed`: the same seed gives the same
    /// map, another seed moves the sun, lights, lamps and texture. A map
    /// with no pixels has an empty `rgb`.
    ///
    /// # Example
    /// ```
    /// use tessera::synth::Sky;
    /// let a = Sky::CityNight.generate(256, 128, 5);
    /// assert_eq!(a, Sky::CityNight.generate(256, 128, 5));
    /// assert_ne!(a, Sky::CityNight.generate(256, 128, 6));
    /// ```
    pub fn generate(&self, width: usize, height: usize, seed: u64) -> SynthMap {
        let mut map = SynthMap {
            width,
            height,
            rgb: Vec::new(),
        };
        if width == 0 || height == 0 {
            return map;
        }
        let rng = &mut SplitMix64::new(seed);
        match *self {
            Sky::ClearSky => clear_sky(&mut map, rng),
            Sky::Overcast => overcast(&mut map, rng),
            Sky::CityNight => city_night(&mut map, rng),
            Sky::Interior => interior(&mut map, rng),
            Sky::Textured { sigma } => textured(&mut map, sigma, rng),
            Sky::GroundLognormal => issue_ground(&mut map, 0.1, 1.0, rng),
            Sky::GroundLognormalMild => issue_ground(&mut map, 0.2, 0.5, rng),
            Sky::Zeros20 => {
                smooth(&mut map);
                sprinkle_zeros(&mut map, 0.2, f64::INFINITY, rng);
            }
            Sky::Smooth => smooth(&mut map),
        }
        map
    }
}

/// Direction of polar angle `theta` (from +Z) and azimuth `phi`.
fn direction(theta: f64, phi: f64) -> DVec3 {
    let (st, ct) = theta.sin_cos();
    let (sp, cp) = phi.sin_cos();
    DVec3::new(st * cp, st * sp, ct)
}

/// Polar angle of the centre of row `j`.
fn row_theta(j: usize, height: usize) -> f64 {
    (j as f64 + 0.5) / height as f64 * PI
}

/// Azimuth of the centre of column `i`.
fn column_phi(i: usize, width: usize) -> f64 {
    (i as f64 + 0.5) / width as f64 * TAU
}

/// The pixel holding direction `d` (unit).
fn pixel_of(d: DVec3, width: usize, height: usize) -> (usize, usize) {
    let phi = d.y.atan2(d.x).rem_euclid(TAU);
    let theta = d.z.clamp(-1.0, 1.0).acos();
    let i = ((phi / TAU * width as f64) as usize).min(width - 1);
    let j = ((theta / PI * height as f64) as usize).min(height - 1);
    (i, j)
}

/// Solid angle of a pixel of row `j`.
fn pixel_solid_angle(j: usize, width: usize, height: usize) -> f64 {
    let t0 = j as f64 / height as f64 * PI;
    let t1 = (j + 1) as f64 / height as f64 * PI;
    TAU / width as f64 * (t0.cos() - t1.cos())
}

/// A colour of luminance 1 with the hue of `rgb`.
fn tint(rgb: [f64; 3]) -> [f64; 3] {
    let l = 0.2126 * rgb[0] + 0.7152 * rgb[1] + 0.0722 * rgb[2];
    [rgb[0] / l, rgb[1] / l, rgb[2] / l]
}

/// `luminance` in colour `tint` (itself of luminance 1).
fn paint(luminance: f64, tint: [f64; 3]) -> [f32; 3] {
    [
        (luminance * tint[0]) as f32,
        (luminance * tint[1]) as f32,
        (luminance * tint[2]) as f32,
    ]
}

/// Median of the luminance of the pixels `keep` accepts (0 if none).
fn median_where(map: &SynthMap, keep: impl Fn(usize) -> bool) -> f64 {
    let mut v: Vec<f64> = (0..map.rgb.len())
        .filter(|&k| keep(k))
        .map(|k| luminance_of(map.rgb[k]))
        .collect();
    if v.is_empty() {
        return 0.0;
    }
    let mid = v.len() / 2;
    *v.select_nth_unstable_by(mid, f64::total_cmp).1
}

fn clear_sky(map: &mut SynthMap, rng: &mut SplitMix64) {
    let (w, h) = (map.width, map.height);
    let sun_phi = uniform(rng, 0.0, TAU);
    let sun_theta = FRAC_PI_2 - uniform(rng, 30.0, 40.0).to_radians();
    let sun_radius = uniform(rng, 0.3, 0.45).to_radians();
    let sun = direction(sun_theta, sun_phi);
    let ground_texture = fbm(w, h, (4, 8), 0.7, rng);
    // CIE standard clear sky (Perez form, a = -1, b = -0.32, c = 10,
    // d = -3, e = 0.45), zenith about 0.25
    let sky = |d: DVec3| -> f64 {
        let cos_g = d.dot(sun).clamp(-1.0, 1.0);
        let gradation = 1.0 - (-0.32 / d.z.max(1e-4)).exp();
        let indicatrix = 1.0
            + 10.0 * ((-3.0 * cos_g.acos()).exp() - (-3.0 * FRAC_PI_2).exp())
            + 0.45 * cos_g * cos_g;
        0.1 * gradation * indicatrix
    };
    let zenith_blue = tint([0.45, 0.65, 1.3]);
    let horizon_white = tint([0.85, 0.9, 1.0]);
    let sky_tint = |d: DVec3| -> [f64; 3] {
        let t = (-d.z.max(0.0) / 0.25).exp();
        std::array::from_fn(|k| zenith_blue[k] * (1.0 - t) + horizon_white[k] * t)
    };
    // the sky alone first: its median sets the sun and aureole levels
    map.rgb = Vec::with_capacity(w * h);
    for j in 0..h {
        let theta = row_theta(j, h);
        for i in 0..w {
            let d = direction(theta, column_phi(i, w));
            map.rgb.push(if d.z > 0.0 {
                paint(sky(d), sky_tint(d))
            } else {
                [0.0; 3]
            });
        }
    }
    let median = median_where(map, |k| row_theta(k / w, h) < FRAC_PI_2);
    let aureole = |cos_g: f64| -> f64 {
        let g = cos_g.clamp(-1.0, 1.0).acos();
        let edge = 10f64.to_radians();
        if g >= edge {
            return 0.0;
        }
        let taper = 1.0 - (g / edge) * (g / edge);
        150.0 * median * (1f64.to_radians() / g.max(sun_radius)).powi(2) * taper * taper
    };
    // aureole: supersampled (4 x 4, equal-area) within 3 degrees + 2 pixels
    // of the sun, where it changes across a pixel
    let near = (3f64.to_radians() + 2.0 * PI / h as f64).cos();
    let sun_tint = tint([1.0, 0.96, 0.88]);
    for j in 0..h {
        let (z0, z1) = (
            (j as f64 / h as f64 * PI).cos(),
            ((j + 1) as f64 / h as f64 * PI).cos(),
        );
        for i in 0..w {
            let d = direction(row_theta(j, h), column_phi(i, w));
            if d.z <= 0.0 {
                continue;
            }
            let extra = if d.dot(sun) > near {
                let mut sum = 0.0;
                for a in 0..4 {
                    for b in 0..4 {
                        let z = z0 + (z1 - z0) * (a as f64 + 0.5) / 4.0;
                        let phi = (i as f64 + (b as f64 + 0.5) / 4.0) / w as f64 * TAU;
                        let s = (1.0 - z * z).max(0.0).sqrt();
                        let e = DVec3::new(s * phi.cos(), s * phi.sin(), z);
                        sum += aureole(e.dot(sun)) + sky(e) - sky(d);
                    }
                }
                sum / 16.0
            } else {
                aureole(d.dot(sun))
            };
            let p = &mut map.rgb[j * w + i];
            let add = paint(extra.max(0.0), sun_tint);
            for k in 0..3 {
                p[k] += add[k];
            }
        }
    }
    // the disk: 2^16 points of a Vogel spiral over it, each carrying its
    // share of the disk's radiant flux into the pixel it falls in, so edge
    // pixels get their exact coverage (limb darkening u = 0.6)
    let limb = 0.6;
    let centre = 4e4 * median / (1.0 - limb / 3.0);
    let n = 1usize << 16;
    let disk_solid_angle = TAU * (1.0 - sun_radius.cos());
    let e1 = sun.cross(DVec3::Z).normalize();
    let e2 = sun.cross(e1);
    let golden = PI * (3.0 - 5f64.sqrt());
    let mut deposit: BTreeMap<(usize, usize), f64> = BTreeMap::new();
    for k in 0..n {
        let u = (k as f64 + 0.5) / n as f64;
        let r = sun_radius * u.sqrt();
        let (sa, ca) = (k as f64 * golden).sin_cos();
        let d = (sun * r.cos() + (e1 * ca + e2 * sa) * r.sin()).normalize();
        let mu = (1.0 - u).sqrt();
        let radiance = centre * (1.0 - limb * (1.0 - mu));
        *deposit.entry(pixel_of(d, w, h)).or_default() += radiance * disk_solid_angle / n as f64;
    }
    for ((i, j), flux) in deposit {
        let add = paint(flux / pixel_solid_angle(j, w, h), sun_tint);
        let p = &mut map.rgb[j * w + i];
        for k in 0..3 {
            p[k] += add[k];
        }
    }
    // ground: dry grass and soil, lognormal texture of mean 1
    let ground_tint = tint([0.9, 0.8, 0.6]);
    for (k, p) in map.rgb.iter_mut().enumerate() {
        if row_theta(k / w, h) > FRAC_PI_2 {
            *p = paint(
                0.5 * median * (0.6 * ground_texture[k] - 0.18).exp(),
                ground_tint,
            );
        }
    }
    zero_lines(map, 0.05, 1);
    sprinkle_zeros(map, 0.02, 100.0 * median, rng);
}

fn overcast(map: &mut SynthMap, rng: &mut SplitMix64) {
    let (w, h) = (map.width, map.height);
    let clouds = fbm(w, h, (4, 8), 0.5, rng);
    let ground = fbm(w, h, (4, 8), 0.7, rng);
    let sky_tint = tint([0.95, 1.0, 1.06]);
    let ground_tint = tint([0.85, 0.85, 0.75]);
    map.rgb = (0..w * h)
        .map(|k| {
            let cos_t = row_theta(k / w, h).cos();
            if cos_t > 0.0 {
                // CIE overcast: L = Lz (1 + 2 cos theta) / 3
                let l = (1.0 + 2.0 * cos_t) / 3.0 * (0.12 * clouds[k] - 0.0072).exp();
                paint(l, sky_tint)
            } else {
                // albedo 0.2 under the overcast illuminance 7 pi Lz / 9
                let l = 0.2 * 7.0 / 9.0 * (0.5 * ground[k] - 0.125).exp();
                paint(l, ground_tint)
            }
        })
        .collect();
    zero_lines(map, 0.98, 1);
    sprinkle_zeros(map, 0.01, f64::INFINITY, rng);
}

fn city_night(map: &mut SynthMap, rng: &mut SplitMix64) {
    let (w, h) = (map.width, map.height);
    let background = 0.01;
    let haze = fbm(w, h, (4, 8), 0.5, rng);
    let ground = fbm(w, h, (8, 16), 0.7, rng);
    let glow_tint = tint([1.0, 0.75, 0.55]);
    let ground_tint = tint([0.9, 0.85, 0.8]);
    map.rgb = (0..w * h)
        .map(|k| {
            let theta = row_theta(k / w, h);
            if theta < FRAC_PI_2 {
                let elevation = FRAC_PI_2 - theta;
                let glow = 0.35 + 1.3 * (-elevation / 10f64.to_radians()).exp();
                paint(background * glow * (0.1 * haze[k]).exp(), glow_tint)
            } else {
                paint(
                    background * 0.7 * (0.8 * ground[k] - 0.32).exp(),
                    ground_tint,
                )
            }
        })
        .collect();
    let colours = [
        tint([1.0, 0.55, 0.2]),  // sodium
        tint([1.0, 0.95, 0.9]),  // white LED
        tint([0.8, 0.9, 1.1]),   // cool white
        tint([1.0, 0.25, 0.12]), // red
    ];
    // pixel offsets of lights of 1, 2, 3 and 4 pixels
    let shapes: [&[(i64, i64)]; 6] = [
        &[(0, 0)],
        &[(0, 0), (1, 0)],
        &[(0, 0), (0, 1)],
        &[(0, 0), (1, 0), (0, 1)],
        &[(0, 0), (1, 0), (2, 0)],
        &[(0, 0), (1, 0), (0, 1), (1, 1)],
    ];
    fn light(
        map: &mut SynthMap,
        rng: &mut SplitMix64,
        elevation: f64,
        shape: &[(i64, i64)],
        level: f64,
        colour: [f64; 3],
    ) {
        let (w, h) = (map.width, map.height);
        let d = direction(FRAC_PI_2 - elevation, uniform(rng, 0.0, TAU));
        let (i, j) = pixel_of(d, w, h);
        for &(di, dj) in shape {
            let i = (i as i64 + di).rem_euclid(w as i64) as usize;
            let j = (j as i64 + dj).clamp(0, h as i64 - 1) as usize;
            let add = paint(level * uniform(rng, 0.8, 1.0), colour);
            let p = &mut map.rgb[j * w + i];
            for k in 0..3 {
                p[k] += add[k];
            }
        }
    }
    let count = 300 + (rng.next_f64() * 301.0) as usize;
    for _ in 0..count {
        // most just below the horizon (streets, buildings), some lit
        // windows just above it
        let elevation = if rng.next_f64() < 0.8 {
            -(gaussian(rng).abs() * 8.0).min(70.0).to_radians()
        } else {
            uniform(rng, 0.0, 5.0).to_radians()
        };
        let shape = shapes[(rng.next_f64() * shapes.len() as f64) as usize];
        let level = background * 10f64.powf(uniform(rng, 2.1, 3.0));
        let c = (rng.next_f64() * colours.len() as f64) as usize;
        light(map, rng, elevation, shape, level, colours[c]);
    }
    let lamps = 6 + (rng.next_f64() * 5.0) as usize;
    for _ in 0..lamps {
        let elevation = uniform(rng, -12.0, 8.0).to_radians();
        let level = background * 10f64.powf(uniform(rng, 3.7, 4.3));
        let c = (rng.next_f64() * 2.0) as usize;
        light(map, rng, elevation, shapes[5], level, colours[c]);
    }
    zero_lines(map, 0.05, lamps);
    sprinkle_zeros(map, 0.12, 20.0 * background, rng);
}

/// An axis-aligned rectangle of a room face: `(u0, u1, v0, v1)` in the
/// face's two in-plane world coordinates.
type Rect = (f64, f64, f64, f64);

fn inside(r: &Rect, u: f64, v: f64) -> bool {
    u >= r.0 && u < r.1 && v >= r.2 && v < r.3
}

fn interior(map: &mut SynthMap, rng: &mut SplitMix64) {
    let (w, h) = (map.width, map.height);
    // the room, camera at the origin about 1.3 m above the floor
    let lo = DVec3::new(
        -uniform(rng, 2.0, 3.0),
        -uniform(rng, 1.8, 2.5),
        -uniform(rng, 1.2, 1.5),
    );
    let hi = DVec3::new(
        uniform(rng, 2.0, 3.0),
        uniform(rng, 1.8, 2.5),
        uniform(rng, 1.2, 1.5),
    );
    let lamp_radiance = 1000.0;
    let lamps: Vec<Rect> = (0..2 + (rng.next_f64() * 3.0) as usize)
        .map(|_| {
            let (cx, cy) = (
                uniform(rng, lo.x + 0.6, hi.x - 0.6),
                uniform(rng, lo.y + 0.6, hi.y - 0.6),
            );
            let (hx, hy) = (uniform(rng, 0.1, 0.2), uniform(rng, 0.15, 0.5));
            (cx - hx, cx + hx, cy - hy, cy + hy)
        })
        .collect();
    // windows on distinct walls: wall 0..4 is x = hi.x, x = lo.x, y = hi.y,
    // y = lo.y; the rectangle is in (the other horizontal axis, z)
    let window_radiance = 0.08 * lamp_radiance;
    let first_wall = (rng.next_f64() * 4.0) as usize;
    let windows: Vec<(usize, Rect)> = (0..1 + (rng.next_f64() < 0.5) as usize)
        .map(|k| {
            let wall = (first_wall + k) % 4;
            let half = if wall < 2 {
                hi.y.min(-lo.y)
            } else {
                hi.x.min(-lo.x)
            };
            let centre = uniform(rng, -0.4, 0.4) * half;
            let half_width = uniform(rng, 0.5, 0.9);
            let bottom = lo.z + 0.9;
            let top = (bottom + uniform(rng, 1.2, 1.6)).min(hi.z - 0.25);
            (
                wall,
                (centre - half_width, centre + half_width, bottom, top),
            )
        })
        .collect();
    let wall_normal = |wall: usize| match wall {
        0 => -DVec3::X,
        1 => DVec3::X,
        2 => -DVec3::Y,
        _ => DVec3::Y,
    };
    // point sources standing in for the emitters, for the shading:
    // (position, emitter normal, intensity = radiance x area)
    let mut sources: Vec<(DVec3, DVec3, f64)> = lamps
        .iter()
        .map(|r| {
            let p = DVec3::new((r.0 + r.1) / 2.0, (r.2 + r.3) / 2.0, hi.z);
            (p, -DVec3::Z, lamp_radiance * (r.1 - r.0) * (r.3 - r.2))
        })
        .collect();
    for (wall, r) in &windows {
        let (u, v) = ((r.0 + r.1) / 2.0, (r.2 + r.3) / 2.0);
        let p = match wall {
            0 => DVec3::new(hi.x, u, v),
            1 => DVec3::new(lo.x, u, v),
            2 => DVec3::new(u, hi.y, v),
            _ => DVec3::new(u, lo.y, v),
        };
        sources.push((
            p,
            wall_normal(*wall),
            0.8 * window_radiance * (r.1 - r.0) * (r.3 - r.2),
        ));
    }
    let floor_area = (hi.x - lo.x) * (hi.y - lo.y);
    let ambient = 0.3 * sources.iter().map(|s| s.2).sum::<f64>() / (2.0 * floor_area);
    let plank_seed = rng.next_u64();
    let texture = fbm(w, h, (8, 16), 0.6, rng);
    let wall_tint = tint([1.0, 0.95, 0.85]);
    let ceiling_tint = tint([1.0, 1.0, 0.97]);
    let floor_tint = tint([0.9, 0.65, 0.4]);
    let lamp_tint = tint([1.0, 0.93, 0.8]);
    let window_tint = tint([0.75, 0.88, 1.2]);
    let frame_tint = tint([0.9, 0.9, 0.9]);
    // radiance seen along d: (emitted rgb, reflected rgb before texture)
    let shade = |d: DVec3| -> ([f64; 3], [f64; 3]) {
        let t = |a: f64, l: f64, u: f64| {
            if a > 0.0 {
                u / a
            } else if a < 0.0 {
                l / a
            } else {
                f64::INFINITY
            }
        };
        let (tx, ty, tz) = (t(d.x, lo.x, hi.x), t(d.y, lo.y, hi.y), t(d.z, lo.z, hi.z));
        let tmin = tx.min(ty).min(tz);
        let p = d * tmin;
        let (normal, albedo, colour) = if tz == tmin {
            if d.z > 0.0 {
                if lamps.iter().any(|r| inside(r, p.x, p.y)) {
                    return (lamp_tint.map(|c| c * lamp_radiance), [0.0; 3]);
                }
                (-DVec3::Z, 0.75, ceiling_tint)
            } else {
                // planks 0.14 m wide along x, 1.2 m long, staggered
                let row = ((p.y - lo.y) / 0.14).floor() as i64;
                let stagger = (row.rem_euclid(3)) as f64 * 0.4;
                let column = ((p.x - lo.x + stagger) / 1.2).floor() as i64;
                let key = (row as u64).wrapping_mul(0x9E37_79B9_7F4A_7C15)
                    ^ (column as u64).wrapping_mul(0xC2B2_AE3D_27D4_EB4F);
                let shade = 0.7 + 0.6 * SplitMix64::new(plank_seed ^ key).next_f64();
                (DVec3::Z, 0.25 * shade, floor_tint)
            }
        } else {
            let (wall, u, v) = if tx == tmin {
                (if d.x > 0.0 { 0 } else { 1 }, p.y, p.z)
            } else {
                (if d.y > 0.0 { 2 } else { 3 }, p.x, p.z)
            };
            for (ww, r) in &windows {
                if *ww == wall && inside(r, u, v) {
                    // frame: a mullion and a transom 6 cm wide
                    let mid = (r.0 + r.1) / 2.0;
                    let transom = r.2 + 0.65 * (r.3 - r.2);
                    if (u - mid).abs() > 0.03 && (v - transom).abs() > 0.03 {
                        let up = (v - r.2) / (r.3 - r.2);
                        return (
                            window_tint.map(|c| c * window_radiance * (0.55 + 0.45 * up)),
                            [0.0; 3],
                        );
                    }
                    return ([0.0; 3], frame_tint.map(|c| c * 0.02 * window_radiance));
                }
            }
            (wall_normal(wall), 0.55, wall_tint)
        };
        let mut irradiance = ambient;
        for &(s, n, intensity) in &sources {
            let to = s - p;
            let r2 = to.length_squared().max(1e-4);
            let r = r2.sqrt();
            let cos_surface = normal.dot(to) / r;
            let cos_emitter = -n.dot(to) / r;
            if cos_surface > 0.0 && cos_emitter > 0.0 {
                irradiance += intensity * cos_surface * cos_emitter / r2;
            }
        }
        ([0.0; 3], colour.map(|c| c * albedo / PI * irradiance))
    };
    map.rgb = Vec::with_capacity(w * h);
    for j in 0..h {
        for i in 0..w {
            // 2 x 2 supersampling: antialiased lamp and window edges
            let (mut emitted, mut reflected) = ([0.0; 3], [0.0; 3]);
            for a in 0..2 {
                for b in 0..2 {
                    let theta = (j as f64 + 0.25 + 0.5 * a as f64) / h as f64 * PI;
                    let phi = (i as f64 + 0.25 + 0.5 * b as f64) / w as f64 * TAU;
                    let (e, r) = shade(direction(theta, phi));
                    for k in 0..3 {
                        emitted[k] += e[k] / 4.0;
                        reflected[k] += r[k] / 4.0;
                    }
                }
            }
            let grain = (0.2 * texture[j * w + i] - 0.02).exp();
            map.rgb.push(std::array::from_fn(|k| {
                (emitted[k] + reflected[k] * grain) as f32
            }));
        }
    }
    zero_lines(map, 0.05, lamps.len());
    sprinkle_zeros(map, 0.05, 0.5 * lamp_radiance, rng);
}

fn textured(map: &mut SynthMap, sigma: f64, rng: &mut SplitMix64) {
    let (w, h) = (map.width, map.height);
    let sigma = if sigma.is_finite() { sigma } else { 0.0 };
    let f = fbm(w, h, (2, 4), 0.6, rng);
    let sky_tint = tint([0.7, 0.85, 1.1]);
    let ground_tint = tint([0.85, 0.8, 0.7]);
    map.rgb = (0..w * h)
        .map(|k| {
            let cos_t = row_theta(k / w, h).cos();
            let t = (sigma * f[k]).clamp(-80.0, 80.0).exp();
            if cos_t > 0.0 {
                paint((0.8 + 0.2 * cos_t) * t, sky_tint)
            } else {
                paint(0.3 * t, ground_tint)
            }
        })
        .collect();
    zero_lines(map, 0.05, 2);
    sprinkle_zeros(map, 0.03, f64::INFINITY, rng);
}

/// The smooth sky gradient of the issue-17 reproductions, grey: 1 at the
/// zenith, 0.4 at the horizon.
fn smooth_sky(cos_theta: f64) -> f64 {
    0.4 + 0.6 * cos_theta
}

fn issue_ground(map: &mut SynthMap, scale: f64, sigma: f64, rng: &mut SplitMix64) {
    let (w, h) = (map.width, map.height);
    let f = blocky(w, h, 16, 32, 5, rng);
    map.rgb = (0..w * h)
        .map(|k| {
            let cos_t = row_theta(k / w, h).cos();
            let l = if cos_t > 0.0 {
                smooth_sky(cos_t)
            } else {
                scale * (sigma * f[k]).exp()
            };
            [l as f32; 3]
        })
        .collect();
}

fn smooth(map: &mut SynthMap) {
    let (w, h) = (map.width, map.height);
    map.rgb = (0..w * h)
        .map(|k| {
            let cos_t = row_theta(k / w, h).cos();
            let l = if cos_t > 0.0 { smooth_sky(cos_t) } else { 0.1 };
            [l as f32; 3]
        })
        .collect();
}

//! Debevec's median cut (2005): an environment map cut into rectangles of
//! pixels of about equal energy, one light per rectangle at its energy
//! centroid with the rectangle's exact power.
//!
//! A region's sides are measured in angle: its height is `rows x pi / H`,
//! its width `columns x 2 pi / W x sin(theta)` at the region's middle
//! latitude. It splits across its longer side (the other one when the
//! longer is a single pixel; ties split the rows) at the pixel boundary
//! that comes nearest to halving its energy (the middle for a region
//! without energy). Energy is the map's value times the pixel's solid
//! angle; a light's power is the sum over its rectangle, and its direction
//! the normalised importance-weighted mean direction (each pixel's exact
//! first moment), so the powers sum to the map's integral.
//!
//! - [`MedianCut::Classic`] splits every region each round: `2^k` regions
//!   after `k` rounds. For `n` not a power of two, the last round splits
//!   only the `n - 2^k` most energetic regions, so exactly `n` come out.
//! - [`MedianCut::Greedy`] always splits the most energetic region, until
//!   there are `n`.
//!
//! Single pixels cannot split: a map of fewer than `n` pixels gives one
//! light per pixel.
//!
//! ```
//! use tessera::baselines::median_cut::{median_cut, MedianCut};
//! use tessera::{density::envmap::{EnvMap, Up}, io::image::Raster};
//! let map = EnvMap::new(Raster { width: 8, height: 4, values: vec![1.0; 32], bad_pixels: 0 }, Up::Z).unwrap();
//! let lights = median_cut(&map, None, 2, MedianCut::Classic).unwrap();
//! // two hemispheres, phi in [0, pi) and [pi, 2 pi): +Y and -Y
//! assert!((lights[0].direction - glam::DVec3::Y).length() < 1e-12);
//! assert!((lights[1].luminance - 2.0 * std::f64::consts::PI).abs() < 1e-12);
//! ```

use crate::density::envmap::EnvMap;
use crate::lights::{Light, RgbMap};
use crate::Error;
use glam::DVec3;
use std::cmp::Ordering;
use std::collections::BinaryHeap;
use std::f64::consts::{PI, TAU};

/// Which median cut (see the [module docs](self)).
///
/// # Example
/// ```
/// use tessera::baselines::median_cut::MedianCut;
/// assert_eq!(MedianCut::all(), [MedianCut::Classic, MedianCut::Greedy]);
/// assert_eq!(MedianCut::Greedy.name(), "greedy");
/// ```
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum MedianCut {
    /// Every region splits each round.
    Classic,
    /// The most energetic region splits first.
    Greedy,
}

impl MedianCut {
    /// Both variants.
    ///
    /// # Example
    /// ```
    /// assert_eq!(tessera::baselines::median_cut::MedianCut::all().len(), 2);
    /// ```
    pub fn all() -> [MedianCut; 2] {
        [MedianCut::Classic, MedianCut::Greedy]
    }

    /// `classic` or `greedy`.
    ///
    /// # Example
    /// ```
    /// assert_eq!(tessera::baselines::median_cut::MedianCut::Classic.name(), "classic");
    /// ```
    pub fn name(self) -> &'static str {
        match self {
            MedianCut::Classic => "classic",
            MedianCut::Greedy => "greedy",
        }
    }
}

/// A rectangle of pixels: columns `i0..i1`, rows `j0..j1`.
#[derive(Clone, Copy, Debug, PartialEq)]
struct Region {
    i0: usize,
    i1: usize,
    j0: usize,
    j1: usize,
    energy: f64,
}

struct Cutter<'a> {
    width: usize,
    height: usize,
    /// Value x solid angle per pixel.
    energy: Vec<f64>,
    map: &'a EnvMap,
}

impl Cutter<'_> {
    fn energy_of(&self, i0: usize, i1: usize, j0: usize, j1: usize) -> f64 {
        (j0..j1)
            .map(|j| {
                self.energy[j * self.width + i0..j * self.width + i1]
                    .iter()
                    .sum::<f64>()
            })
            .sum()
    }

    fn region(&self, i0: usize, i1: usize, j0: usize, j1: usize) -> Region {
        Region {
            i0,
            i1,
            j0,
            j1,
            energy: self.energy_of(i0, i1, j0, j1),
        }
    }

    fn splittable(r: &Region) -> bool {
        r.i1 - r.i0 > 1 || r.j1 - r.j0 > 1
    }

    /// The two halves of a splittable region.
    fn split(&self, r: &Region) -> (Region, Region) {
        let (cols, rows) = (r.i1 - r.i0, r.j1 - r.j0);
        let theta = (r.j0 + r.j1) as f64 / 2.0 * PI / self.height as f64;
        let width = cols as f64 * TAU / self.width as f64 * theta.sin();
        let height = rows as f64 * PI / self.height as f64;
        let across_columns = (width > height && cols > 1) || rows == 1;
        // energy per column or per row of the region
        let marginal: Vec<f64> = if across_columns {
            let mut m = vec![0.0; cols];
            for j in r.j0..r.j1 {
                let row = &self.energy[j * self.width + r.i0..j * self.width + r.i1];
                for (a, e) in m.iter_mut().zip(row) {
                    *a += e;
                }
            }
            m
        } else {
            (r.j0..r.j1)
                .map(|j| {
                    self.energy[j * self.width + r.i0..j * self.width + r.i1]
                        .iter()
                        .sum()
                })
                .collect()
        };
        let total: f64 = marginal.iter().sum();
        let cut = if total > 0.0 {
            let mut best = (f64::INFINITY, 1);
            let mut below = 0.0;
            for (c, m) in marginal.iter().enumerate().take(marginal.len() - 1) {
                below += m;
                let miss = (below - total / 2.0).abs();
                if miss < best.0 {
                    best = (miss, c + 1);
                }
            }
            best.1
        } else {
            marginal.len() / 2
        };
        if across_columns {
            let m = r.i0 + cut;
            (
                self.region(r.i0, m, r.j0, r.j1),
                self.region(m, r.i1, r.j0, r.j1),
            )
        } else {
            let m = r.j0 + cut;
            (
                self.region(r.i0, r.i1, r.j0, m),
                self.region(r.i0, r.i1, m, r.j1),
            )
        }
    }
}

/// Region with a total order by energy (then position), for the heap.
struct ByEnergy(Region, usize);

impl PartialEq for ByEnergy {
    fn eq(&self, other: &Self) -> bool {
        self.cmp(other) == Ordering::Equal
    }
}
impl Eq for ByEnergy {}
impl PartialOrd for ByEnergy {
    fn partial_cmp(&self, other: &Self) -> Option<Ordering> {
        Some(self.cmp(other))
    }
}
impl Ord for ByEnergy {
    fn cmp(&self, other: &Self) -> Ordering {
        self.0
            .energy
            .total_cmp(&other.0.energy)
            .then(other.1.cmp(&self.1))
    }
}

fn classic(cutter: &Cutter, n: usize, whole: Region) -> Vec<Region> {
    let mut regions = vec![whole];
    while regions.len() < n {
        let (mut can, cannot): (Vec<Region>, Vec<Region>) =
            regions.iter().partition(|r| Cutter::splittable(r));
        if can.is_empty() {
            break;
        }
        let room = n - regions.len();
        if can.len() > room {
            // the last round: the most energetic first (stable on ties)
            can.sort_by(|a, b| b.energy.total_cmp(&a.energy));
        }
        let mut next = cannot;
        for (k, r) in can.iter().enumerate() {
            if k < room {
                let (a, b) = cutter.split(r);
                next.push(a);
                next.push(b);
            } else {
                next.push(*r);
            }
        }
        // a fixed order: top to bottom, left to right
        next.sort_by_key(|r| (r.j0, r.i0));
        regions = next;
    }
    regions
}

fn greedy(cutter: &Cutter, n: usize, whole: Region) -> Vec<Region> {
    let mut heap = BinaryHeap::new();
    let mut done = Vec::new();
    let mut serial = 0;
    heap.push(ByEnergy(whole, serial));
    while heap.len() + done.len() < n {
        let Some(ByEnergy(r, _)) = heap.pop() else {
            break;
        };
        if !Cutter::splittable(&r) {
            done.push(r);
            continue;
        }
        let (a, b) = cutter.split(&r);
        for half in [a, b] {
            serial += 1;
            heap.push(ByEnergy(half, serial));
        }
    }
    done.extend(heap.into_iter().map(|ByEnergy(r, _)| r));
    done.sort_by_key(|r| (r.j0, r.i0));
    done
}

/// Median cut of `map` into `n` lights (fewer only when the map has fewer
/// than `n` pixels), with each light's channel powers from `rgb` (every
/// channel the importance's without it). Cost `O(pixels log n)`. Errors
/// on `n = 0` or colour planes of another size.
///
/// # Example
/// ```
/// use tessera::baselines::median_cut::{median_cut, MedianCut};
/// use tessera::{lights::RgbMap, synth::Sky};
/// let rgb = RgbMap::from(Sky::ClearSky.generate(128, 64, 1));
/// let map = rgb.env_map(Default::default()).unwrap();
/// for variant in MedianCut::all() {
///     let lights = median_cut(&map, Some(&rgb), 100, variant).unwrap();
///     assert_eq!(lights.len(), 100);
///     let sum: f64 = lights.iter().map(|l| l.luminance).sum();
///     assert!((sum / map.integral() - 1.0).abs() < 1e-12);
/// }
/// ```
pub fn median_cut(
    map: &EnvMap,
    rgb: Option<&RgbMap>,
    n: usize,
    variant: MedianCut,
) -> Result<Vec<Light>, Error> {
    if n == 0 {
        return Err(Error::Request(
            "median cut: ask for at least one light".into(),
        ));
    }
    let (w, h) = (map.width(), map.height());
    if let Some(rgb) = rgb {
        if (rgb.width, rgb.height) != (w, h) || rgb.rgb.len() != w * h {
            return Err(Error::Request(format!(
                "median cut: the colour planes are {}x{} ({} pixels) but the map is {w}x{h}",
                rgb.width,
                rgb.height,
                rgb.rgb.len()
            )));
        }
    }
    let values = map.values();
    let energy = (0..w * h)
        .map(|p| values[p] * map.pixel_solid_angle(p / w))
        .collect();
    let cutter = Cutter {
        width: w,
        height: h,
        energy,
        map,
    };
    let whole = cutter.region(0, w, 0, h);
    let regions = match variant {
        MedianCut::Classic => classic(&cutter, n, whole),
        MedianCut::Greedy => greedy(&cutter, n, whole),
    };
    Ok(regions.iter().map(|r| cutter.light(r, rgb)).collect())
}

impl Cutter<'_> {
    /// The light of a region: exact sums over its pixels.
    fn light(&self, r: &Region, rgb: Option<&RgbMap>) -> Light {
        let (w, h) = (self.width, self.height);
        let dphi = TAU / w as f64;
        let z_edge = |j: usize| match j {
            0 => 1.0,
            j if j == h => -1.0,
            j => (j as f64 * PI / h as f64).cos(),
        };
        // the antiderivative of sqrt(1 - z^2)
        let half_disc = |z: f64| (z * ((1.0 - z) * (1.0 + z)).max(0.0).sqrt() + z.asin()) / 2.0;
        let columns: Vec<(f64, f64)> = (r.i0..r.i1)
            .map(|i| {
                let (s0, c0) = (i as f64 * dphi).sin_cos();
                let (s1, c1) = ((i + 1) as f64 * dphi).sin_cos();
                (s1 - s0, c0 - c1)
            })
            .collect();
        let (mut mass, mut area, mut colour, mut moment) = (0.0, 0.0, [0.0; 3], DVec3::ZERO);
        let values = self.map.values();
        for j in r.j0..r.j1 {
            let omega = self.map.pixel_solid_angle(j);
            let (top, bottom) = (z_edge(j), z_edge(j + 1));
            let ms = half_disc(top) - half_disc(bottom);
            let mz = dphi * (top - bottom) * (top + bottom) / 2.0;
            let (mut row_mass, mut row_colour, mut mx, mut my, mut row_value) =
                (0.0, [0.0; 3], 0.0, 0.0, 0.0);
            for (i, &(mc, msn)) in (r.i0..r.i1).zip(&columns) {
                let p = j * w + i;
                let v = values[p];
                row_value += v;
                row_mass += v * omega;
                let c = match rgb {
                    Some(rgb) => rgb.rgb[p].map(|c| c as f64),
                    None => [v; 3],
                };
                for k in 0..3 {
                    row_colour[k] += c[k];
                }
                mx += v * mc;
                my += v * msn;
            }
            mass += row_mass;
            area += omega * (r.i1 - r.i0) as f64;
            for k in 0..3 {
                colour[k] += row_colour[k] * omega;
            }
            moment += DVec3::new(mx * ms, my * ms, row_value * mz);
        }
        let len = moment.length();
        let direction = if mass > 0.0 && len > 1e-9 * mass {
            moment / len
        } else {
            // no energy: the region's middle
            let phi = (r.i0 + r.i1) as f64 / 2.0 * dphi;
            let theta = (r.j0 + r.j1) as f64 / 2.0 * PI / h as f64;
            DVec3::new(
                theta.sin() * phi.cos(),
                theta.sin() * phi.sin(),
                theta.cos(),
            )
        };
        Light {
            direction: self.map.up().from_map(direction),
            rgb: colour,
            luminance: mass,
            solid_angle: area,
        }
    }
}

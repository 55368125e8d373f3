//! HEALPix maps as sphere densities.
//!
//! A map of `12 nside^2` values (`nside` a power of two, RING or NESTED
//! order) is a density constant over each pixel per unit solid angle, the
//! directions in the map's own frame (`theta` from +Z, `phi` from +X
//! towards +Y, as healpy's `ang2pix`). Pixels are equal-area, so the mean
//! is the mean of the values and `pdf = value / (4 pi mean)`.
//!
//! Bad values are handled as for environment maps
//! ([`crate::density::envmap`]): NaN, infinite and negative pixels count
//! as 0 and are counted (`strict` refuses them instead), and a map with
//! nothing positive is refused. [`UNSEEN`] pixels (healpy's no-data
//! marker, within its tolerance) count as 0 and are counted separately,
//! strict or not: they are the format's mask, not damage.
//!
//! Tiles (Nside `10 * 2^k`) and pixels (Nside `2^m`) share the face
//! coordinates of [`crate::healpix`] but not their grid, so a tile's bound
//! is the maximum over every pixel its face-coordinate box meets, read
//! from a max pyramid over the NESTED quadtree (a parent holds the maximum
//! of its four children) at the finest depth where the box spans at most
//! three pixels a side. A bare cap (a rotated tile, [`Rotated`]) is turned
//! into a face box by [`INVERSE_LIPSCHITZ`] (or, on the equatorial faces,
//! [`INVERSE_LIPSCHITZ_EQUATORIAL`]); a box that leaves its face
//! takes the pixel holding the cap's centre and its neighbours, across
//! seams, at a depth whose pixels are wider than the cap.
//!
//! ```
//! use tessera::density::{healpix::HealpixMap, Density};
//! use tessera::healpix::Scheme;
//! use tessera::tiling::sphere::SphereRegion;
//! // nside 1: one value per base face, RING = NESTED
//! let mut values = vec![1.0; 12];
//! values[0] = 3.0;
//! let map = HealpixMap::new("mem", values, Scheme::Ring, false).unwrap();
//! assert_eq!(Density::<SphereRegion>::value(&map, glam::DVec3::new(1.0, 1.0, 1.5)), 3.0);
//! assert!((Density::<SphereRegion>::mean(&map) - 14.0 / 12.0).abs() < 1e-15);
//! ```
//!
//! [`Rotated`]: crate::density::sphere::Rotated

use super::Density;
use crate::healpix::{
    cell_of, nested_index, ring_cell, step, Cell, Dir, FacePoint, Scheme, UNSEEN,
};
use crate::tiling::sphere::{SphereRegion, FACE_LIPSCHITZ};
use crate::Error;
use glam::DVec3;
use std::f64::consts::PI;
use std::path::Path;
use std::sync::Arc;

/// Face-coordinate length per radian on the sphere, anywhere on any face:
/// the mapping's area element is the constant `pi / 3`, so it stretches no
/// direction by less than `(pi / 3) / FACE_LIPSCHITZ` (the true supremum
/// is 1.5242, at the poles along the face edges, where the mapping's
/// largest stretch is 1.5961 < `FACE_LIPSCHITZ`). Every point within
/// `r` radians of a face point lies within `INVERSE_LIPSCHITZ * r` of it
/// in face coordinates while the box of that half-width stays on the face.
///
/// # Example
/// ```
/// use tessera::density::healpix::INVERSE_LIPSCHITZ;
/// assert!(INVERSE_LIPSCHITZ > 1.5 && INVERSE_LIPSCHITZ < 1.6);
/// ```
pub const INVERSE_LIPSCHITZ: f64 = FACE_LIPSCHITZ * 3.0 / PI;

/// [`INVERSE_LIPSCHITZ`] on the four equatorial faces (4 to 7), which lie
/// in the zone `|z| <= 2/3` where `z = 2 (x + y - 1) / 3` and `phi` is
/// linear in `x - y`: the least stretch, `(pi / 4) sqrt 2 sin(theta)` with
/// `sin(theta) >= sqrt 5 / 3`, is 0.8279, so 1.2079 face units per radian.
///
/// # Example
/// ```
/// use tessera::density::healpix::{INVERSE_LIPSCHITZ, INVERSE_LIPSCHITZ_EQUATORIAL};
/// assert!(INVERSE_LIPSCHITZ_EQUATORIAL < INVERSE_LIPSCHITZ);
/// ```
pub const INVERSE_LIPSCHITZ_EQUATORIAL: f64 = 1.208;

/// Face units per radian on `face` (see [`INVERSE_LIPSCHITZ`]).
fn inverse_lipschitz(face: u8) -> f64 {
    if (4..8).contains(&face) {
        INVERSE_LIPSCHITZ_EQUATORIAL
    } else {
        INVERSE_LIPSCHITZ
    }
}

/// Added to every face box (face units): a sample near a box edge, turned
/// into a direction and back, moves by a few ulps.
const MARGIN: f64 = 1e-12;

/// The half-width (face units) of a box on `face` holding every point
/// within `radius` radians of its centre, while the box stays on the face.
fn reach(face: u8, radius: f64) -> f64 {
    inverse_lipschitz(face) * radius * (1.0 + 1e-9) + MARGIN
}

/// Whether a value is healpy's `UNSEEN` (its tolerance: `1e-5` relative).
fn is_unseen(v: f64) -> bool {
    (v - UNSEEN).abs() <= 1e-5 * UNSEEN.abs()
}

/// The depth `m` of a map of `len = 12 * 4^m` values.
fn depth_of(len: usize) -> Option<u32> {
    let quarter = len / 12;
    (len % 12 == 0 && quarter.is_power_of_two() && quarter.trailing_zeros() % 2 == 0)
        .then(|| quarter.trailing_zeros() / 2)
}

/// The values in NESTED order and their max pyramid.
struct Pixels {
    depth: u32,
    /// `levels[l]` holds, per pixel of depth `depth - l`, the maximum of
    /// its `4^l` descendants; `levels[0]` is the map.
    levels: Vec<Vec<f64>>,
    mean: f64,
    unseen: usize,
    bad: usize,
}

impl Pixels {
    /// The maximum over the pixels a face box meets, `None` unless the
    /// box lies inside its face.
    fn box_max(&self, face: u8, x: [f64; 2], y: [f64; 2]) -> Option<f64> {
        // (false for NaN)
        if !(x[0] > 0.0 && y[0] > 0.0 && x[1] < 1.0 && y[1] < 1.0) {
            return None;
        }
        let nside = (1u64 << self.depth) as f64;
        let (i0, i1) = ((x[0] * nside) as i64, (x[1] * nside) as i64);
        let (j0, j1) = ((y[0] * nside) as i64, (y[1] * nside) as i64);
        let mut l = 0;
        while l < self.depth && ((i1 >> l) - (i0 >> l) > 2 || (j1 >> l) - (j0 >> l) > 2) {
            l += 1;
        }
        let level = &self.levels[l as usize];
        let mut m = 0.0f64;
        for i in (i0 >> l)..=(i1 >> l) {
            for j in (j0 >> l)..=(j1 >> l) {
                m = m.max(level[nested_index(Cell { face, i, j }, self.depth - l) as usize]);
            }
        }
        Some(m)
    }

    /// The maximum over every pixel within `radius` radians of `centre`.
    fn cap_max(&self, centre: FacePoint, radius: f64) -> f64 {
        let top = self.levels.last().expect("depth 0 exists");
        let global = || top.iter().fold(0.0f64, |a, &b| a.max(b));
        // the box on the centre's face, then (across faces) the neighbours
        let on_face = reach(centre.face, radius);
        let w = INVERSE_LIPSCHITZ * radius * (1.0 + 1e-9) + MARGIN;
        if !(centre.x.is_finite() && centre.y.is_finite() && w < 1.0) {
            return global();
        }
        let (x, y) = (centre.x, centre.y);
        let (xs, ys) = ([x - on_face, x + on_face], [y - on_face, y + on_face]);
        if let Some(m) = self.box_max(centre.face, xs, ys) {
            return m;
        }
        // the finest depth (at most the map's) whose pixels are wider than
        // `w`: a cap that narrow cannot pass the neighbours of its centre's pixel
        let mut d = 0;
        while d < self.depth && w * ((2u64 << d) as f64) < 1.0 {
            d += 1;
        }
        let level = &self.levels[(self.depth - d) as usize];
        let at = |c: Cell| level[nested_index(c, d) as usize];
        let cell = cell_of(centre, d);
        let nside = 1i64 << d;
        let mut m = at(cell);
        for dir in Dir::ALL {
            let (next, turns) = step(cell, nside, dir);
            m = m.max(at(next));
            // on a quarter turn further: the diagonal neighbour (or, by a
            // three-face corner, a pixel beyond, which costs only slack)
            let side = dir.rotate_ccw(1).reframe(turns);
            m = m.max(at(step(next, nside, side).0));
        }
        m
    }

    fn at(&self, p: FacePoint) -> f64 {
        if p.x.is_nan() || p.y.is_nan() {
            return 0.0;
        }
        self.levels[0][nested_index(cell_of(p, self.depth), self.depth) as usize]
    }
}

/// A HEALPix map as a density on the sphere (see the [module docs](self)).
/// Cloning is cheap (the pixels and pyramid are shared). A seeded request
/// samples it through [`crate::density::sphere::Rotated`], which bounds it
/// over each tile's bounding cap.
///
/// # Example
/// ```
/// use tessera::density::healpix::HealpixMap;
/// use tessera::healpix::Scheme;
/// use tessera::{engine, tiling::sphere::SphereTiling};
/// // nside 2: one hot pixel of 48, NESTED
/// let mut values = vec![1.0; 48];
/// values[17] = 100.0;
/// let map = HealpixMap::new("mem", values, Scheme::Nested, false).unwrap();
/// let samples = engine::generate(&SphereTiling::default(), &map, 1000, true).unwrap();
/// let hot = samples.iter().filter(|s| map.pdf(s.position) > 1.0).count();
/// // 100 / 147 of the mass
/// assert!((650..710).contains(&hot), "{hot}");
/// ```
#[derive(Clone)]
pub struct HealpixMap {
    pixels: Arc<Pixels>,
    coordsys: Option<String>,
}

impl HealpixMap {
    /// A map of `12 nside^2` values in `scheme` order (`nside` a power of
    /// two). `name` is what errors call the data. Bad and [`UNSEEN`]
    /// values count as 0 (see the [module docs](self)); `strict` refuses
    /// NaN, infinite and negative values.
    ///
    /// # Example
    /// ```
    /// use tessera::density::healpix::HealpixMap;
    /// use tessera::healpix::{Scheme, UNSEEN};
    /// let mut values = vec![1.0; 48];
    /// values[3] = f64::NAN;
    /// values[4] = UNSEEN;
    /// let map = HealpixMap::new("mem", values.clone(), Scheme::Ring, false).unwrap();
    /// assert_eq!((map.nside(), map.bad_pixels(), map.unseen_pixels()), (2, 1, 1));
    /// let err = HealpixMap::new("mem", values, Scheme::Ring, true).err().unwrap();
    /// assert!(err.to_string().contains("pixel 3"), "{err}");
    /// assert!(HealpixMap::new("mem", vec![1.0; 47], Scheme::Ring, false).is_err());
    /// ```
    pub fn new(
        name: impl AsRef<Path>,
        values: Vec<f64>,
        scheme: Scheme,
        strict: bool,
    ) -> Result<Self, Error> {
        let fail = |reason: String| Error::File {
            path: name.as_ref().into(),
            reason,
        };
        let len = values.len();
        let depth = depth_of(len).ok_or_else(|| {
            fail(format!(
                "{len} values: a HEALPix map has 12 nside^2 of them, nside a power of two \
                 (12 for nside 1, 768 for 8, 3072 for 16, ...)"
            ))
        })?;
        let (mut values, mut unseen, mut bad) = (values, 0, 0);
        for (k, v) in values.iter_mut().enumerate() {
            if is_unseen(*v) {
                unseen += 1;
                *v = 0.0;
            } else if !(v.is_finite() && *v >= 0.0) {
                if strict {
                    return Err(fail(format!(
                        "pixel {k} ({} order) is {v}: NaN, infinite or negative \
                         (UNSEEN pixels would count as 0)",
                        if scheme == Scheme::Ring {
                            "RING"
                        } else {
                            "NESTED"
                        }
                    )));
                }
                bad += 1;
                *v = 0.0;
            }
        }
        if !values.iter().any(|&v| v > 0.0) {
            return Err(fail(
                "every pixel is zero, UNSEEN, negative or invalid: there is nothing to sample"
                    .into(),
            ));
        }
        let nested = match scheme {
            Scheme::Nested => values,
            Scheme::Ring => {
                let mut nested = vec![0.0; len];
                for (ring, &v) in values.iter().enumerate() {
                    nested[nested_index(ring_cell(ring as u64, depth), depth) as usize] = v;
                }
                nested
            }
        };
        let mean = nested.iter().sum::<f64>() / len as f64;
        let mut levels = vec![nested];
        for _ in 0..depth {
            let finer = levels.last().expect("the map");
            let coarser = finer
                .chunks_exact(4)
                .map(|c| c[0].max(c[1]).max(c[2]).max(c[3]))
                .collect();
            levels.push(coarser);
        }
        Ok(HealpixMap {
            pixels: Arc::new(Pixels {
                depth,
                levels,
                mean,
                unseen,
                bad,
            }),
            coordsys: None,
        })
    }

    /// Reads column `field` of a HEALPix FITS file
    /// ([`crate::io::fits::read_healpix`]) as [`HealpixMap::new`] takes
    /// values; errors name the file.
    ///
    /// # Example
    /// ```
    /// use tessera::density::healpix::HealpixMap;
    /// let e = HealpixMap::open("missing.fits".as_ref(), 0, false).err().unwrap();
    /// assert!(e.to_string().contains("missing.fits"));
    /// ```
    pub fn open(path: &Path, field: usize, strict: bool) -> Result<Self, Error> {
        let file = crate::io::fits::read_healpix(path, field)?;
        let mut map = HealpixMap::new(path, file.values, file.scheme, strict)?;
        map.coordsys = file.coordsys;
        Ok(map)
    }

    /// `nside` (a power of two).
    ///
    /// # Example
    /// ```
    /// # use tessera::{density::healpix::HealpixMap, healpix::Scheme};
    /// let map = HealpixMap::new("mem", vec![1.0; 768], Scheme::Ring, false).unwrap();
    /// assert_eq!(map.nside(), 8);
    /// ```
    pub fn nside(&self) -> u64 {
        1 << self.pixels.depth
    }

    /// NaN, infinite and negative pixels set to 0.
    ///
    /// # Example
    /// ```
    /// # use tessera::{density::healpix::HealpixMap, healpix::Scheme};
    /// let mut v = vec![1.0; 12];
    /// v[0] = -2.0;
    /// assert_eq!(HealpixMap::new("mem", v, Scheme::Ring, false).unwrap().bad_pixels(), 1);
    /// ```
    pub fn bad_pixels(&self) -> usize {
        self.pixels.bad
    }

    /// [`UNSEEN`] pixels (and pixels a partial-sky file does not list),
    /// set to 0.
    ///
    /// # Example
    /// ```
    /// # use tessera::{density::healpix::HealpixMap, healpix::{Scheme, UNSEEN}};
    /// let mut v = vec![1.0; 12];
    /// v[5] = UNSEEN as f32 as f64; // as a float32 map stores it
    /// assert_eq!(HealpixMap::new("mem", v, Scheme::Ring, true).unwrap().unseen_pixels(), 1);
    /// ```
    pub fn unseen_pixels(&self) -> usize {
        self.pixels.unseen
    }

    /// The file's `COORDSYS` (`C`, `G` or `E`), the frame of the
    /// directions, when the map was read from a file that gives it.
    ///
    /// # Example
    /// ```
    /// # use tessera::{density::healpix::HealpixMap, healpix::Scheme};
    /// assert_eq!(HealpixMap::new("mem", vec![1.0; 12], Scheme::Ring, false).unwrap().coordsys(), None);
    /// ```
    pub fn coordsys(&self) -> Option<&str> {
        self.coordsys.as_deref()
    }

    /// The pdf per steradian of a direction (need not be normalised):
    /// `value / (4 pi mean)`.
    ///
    /// # Example
    /// ```
    /// # use tessera::{density::healpix::HealpixMap, healpix::Scheme};
    /// let map = HealpixMap::new("mem", vec![2.0; 12], Scheme::Ring, false).unwrap();
    /// assert!((map.pdf(glam::DVec3::X) * 4.0 * std::f64::consts::PI - 1.0).abs() < 1e-15);
    /// ```
    pub fn pdf(&self, direction: DVec3) -> f64 {
        self.pixels.at(FacePoint::from_vec(direction)) / (4.0 * PI * self.pixels.mean)
    }
}

impl Density<SphereRegion> for HealpixMap {
    fn bound(&self, region: &SphereRegion) -> f64 {
        let px = &*self.pixels;
        let side = region.cell_side();
        if side.is_finite() {
            // a tile: the box of its cells and of the samples its bound
            // covers, widened by their warp (`box_max` refuses a box that
            // leaves the face)
            let h = side / 2.0 + region.spill + reach(region.face, region.warp);
            let (mut x, mut y) = (
                [f64::INFINITY, -f64::INFINITY],
                [f64::INFINITY, -f64::INFINITY],
            );
            for [cx, cy] in region.cells {
                x = [x[0].min(cx - h), x[1].max(cx + h)];
                y = [y[0].min(cy - h), y[1].max(cy + h)];
            }
            if let Some(m) = px.box_max(region.face, x, y) {
                return m;
            }
        }
        px.cap_max(region.centroid, region.radius)
    }

    fn average(&self, region: &SphereRegion) -> f64 {
        let px = &*self.pixels;
        let cells = region.cells.iter();
        let at = |&[x, y]: &[f64; 2]| px.at(FacePoint::new(region.face, x, y));
        cells.map(at).sum::<f64>() / 5.0
    }

    fn value(&self, point: DVec3) -> f64 {
        self.pixels.at(FacePoint::from_vec(point))
    }

    fn mean(&self) -> f64 {
        self.pixels.mean
    }
}

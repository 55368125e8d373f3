//! The sampling commands' requests as library calls.
//!
//! `tessera sphere`, `tessera plane` and `tessera lights` take a density
//! (region strings, a map, an image), a count and a few options (exact or
//! expected count, order, seed, window, relaxation, domain). The types here
//! carry those requests and run them, and the command line and the Python
//! package (`python/`) both call them: the same request gives the same
//! points, bit for bit, from either.
//!
//! ```
//! use tessera::request::{SphereDensity, SphereRequest};
//! let density = SphereDensity::parse(&["cap:0,90,20,10"]).unwrap();
//! let request = SphereRequest { count: 1000, seed: Some(3), ..Default::default() };
//! let points = request.points(&density).unwrap();
//! assert_eq!(points.len(), 1000);
//! let pdf = density.pdf();
//! assert!(points.iter().all(|&p| pdf(p) > 0.0));
//! ```

use crate::blocks::{Blocks, IterBlocks};
use crate::density::envmap::{EnvMap, Up};
use crate::density::healpix::HealpixMap;
use crate::density::plane::Shifted;
use crate::density::rectangle::Rectangle;
use crate::density::sphere::{Cap, Rotated};
use crate::density::{Density, Uniform};
use crate::engine::{self, Order, Sample};
use crate::io::image::{read_raster, Raster, ReadOptions};
use crate::lights::RgbMap;
use crate::lut::{Table, TableSystem};
use crate::tiling::penrose::PenroseTiling;
use crate::tiling::plane::{PlaneRegion, PlaneTiling};
use crate::tiling::sphere::{SphereRegion, SphereTiling};
use crate::tiling::TileSystem;
use crate::Error;
use glam::{DVec2, DVec3};
use std::path::Path;

/// What a sphere request samples: the command line's region strings
/// (`--density`), a lat-long environment map (`--map`) or a HEALPix map
/// (`--healpix-map`).
///
/// # Example
/// ```
/// use tessera::request::SphereDensity;
/// let d = SphereDensity::parse(&["uniform"]).unwrap();
/// let pdf = d.pdf();
/// assert!((pdf(glam::DVec3::X) * 4.0 * std::f64::consts::PI - 1.0).abs() < 1e-15);
/// assert!(SphereDensity::parse(&["cap:0,0"]).is_err());
/// ```
pub enum SphereDensity {
    /// `uniform`, a cap or a combination of caps and polygons (see
    /// [`crate::density::region::parse_all`]).
    Regions(Box<dyn Density<SphereRegion> + Send>),
    /// A lat-long map, luminance per unit solid angle.
    Map(EnvMap),
    /// A HEALPix map (`--healpix-map`), constant per pixel per unit solid
    /// angle.
    Healpix(HealpixMap),
}

impl SphereDensity {
    /// Parses `--density` values as `tessera sphere` does
    /// ([`crate::density::region::parse_all`]).
    ///
    /// # Example
    /// ```
    /// use tessera::request::SphereDensity;
    /// assert!(SphereDensity::parse(&["cap:0,0,5,3", "polygon:0 0,10 0,10 10;4"]).is_ok());
    /// ```
    pub fn parse<S: AsRef<str>>(specs: &[S]) -> Result<Self, Error> {
        crate::density::region::parse_all(specs).map(SphereDensity::Regions)
    }

    /// The pdf per steradian the samples follow, as a function of a world
    /// direction (what `tessera sphere --format csv` writes). With
    /// [`SphereRequest::relax`] it is the target density's, and with
    /// [`SphereRequest::within`] that of the whole request. Directions need
    /// not be normalised.
    ///
    /// # Example
    /// ```
    /// use tessera::request::SphereDensity;
    /// let d = SphereDensity::parse(&["cap:0,90,10,100"]).unwrap();
    /// let pdf = d.pdf();
    /// assert!((pdf(glam::DVec3::Z) / pdf(-glam::DVec3::Z) - 100.0).abs() < 1e-9);
    /// ```
    pub fn pdf(&self) -> impl Fn(DVec3) -> f64 + Sync + '_ {
        let tiling = SphereTiling::default();
        move |p| match self {
            SphereDensity::Regions(density) => engine::pdf(&tiling, &**density, p),
            SphereDensity::Map(map) => map.pdf(p),
            SphereDensity::Healpix(map) => map.pdf(p),
        }
    }
}

/// The options of `tessera sphere` besides the density: `-n`,
/// `--expected`, `--unsorted`, `--seed`, `--within` and `--relax`.
///
/// # Example
/// ```
/// use tessera::{engine::Order, request::{SphereDensity, SphereRequest}};
/// let uniform = SphereDensity::parse(&["uniform"]).unwrap();
/// let request = SphereRequest { count: 500, order: Order::Unsorted, ..Default::default() };
/// assert_eq!(request.points(&uniform).unwrap().len(), 500);
/// ```
#[derive(Clone, Debug, Default, PartialEq)]
pub struct SphereRequest {
    /// Number of samples (exact unless `expected`).
    pub count: usize,
    /// Skip the exactness pass: the natural count near `count`.
    pub expected: bool,
    /// Progressive (by rank), farthest first (every prefix evenly spread)
    /// or the cheapest order: see [`Order`].
    pub order: Order,
    /// Sample in a uniformly random frame drawn from this seed (estimates
    /// averaged over seeds are unbiased); without it the set is
    /// deterministic.
    pub seed: Option<u64>,
    /// Keep only the samples of the request inside this cap, visiting only
    /// the tiles reaching it (see [`engine::collect_within`]): the count is
    /// the expected one, and `expected` and `order` are not used. Not with
    /// a map, a seed or relaxation.
    pub within: Option<Cap>,
    /// Density-weighted Lloyd iterations run on the set
    /// ([`crate::relax::relax`]).
    pub relax: usize,
    /// Sample with this table instead of the built-in one (a sphere
    /// [`Table`], see [`Table::open`]).
    pub table: Option<Table>,
}

impl SphereRequest {
    /// The tiling driven by the request's table, or the built-in one.
    ///
    /// # Example
    /// ```
    /// use tessera::{lut::{penrose_lut, Table}, request::SphereRequest};
    /// let request = SphereRequest { table: Some(Table::Penrose(penrose_lut())), ..Default::default() };
    /// let refused = request.tiling().err().expect("a Penrose table is refused");
    /// assert!(refused.to_string().contains("not a sphere table"));
    /// ```
    pub fn tiling(&self) -> Result<SphereTiling, Error> {
        match &self.table {
            None => Ok(SphereTiling::default()),
            Some(Table::Sphere(lut)) => Ok(SphereTiling::new(lut.clone())),
            Some(_) => Err(Error::Request("the table is not a sphere table".into())),
        }
    }

    /// The request's world directions, in its order.
    ///
    /// # Example
    /// ```
    /// use tessera::{density::sphere::Cap, request::{SphereDensity, SphereRequest}};
    /// let uniform = SphereDensity::parse(&["uniform"]).unwrap();
    /// let window = Cap::window("0,0,10").unwrap();
    /// let request = SphereRequest { count: 100_000, within: Some(window), ..Default::default() };
    /// let near = request.points(&uniform).unwrap();
    /// assert!(near.iter().all(|&p| window.contains(p)));
    /// // a 10-degree cap holds 0.76 % of the sphere
    /// assert!((700..820).contains(&near.len()), "{}", near.len());
    /// ```
    pub fn points(&self, density: &SphereDensity) -> Result<Vec<DVec3>, Error> {
        let tiling = self.tiling()?;
        if let Some(window) = &self.within {
            let refuse = |what: &str| {
                Err(Error::Request(format!(
                    "a window (within) cannot be combined with {what}"
                )))
            };
            let SphereDensity::Regions(density) = density else {
                return refuse("a map");
            };
            if self.seed.is_some() {
                return refuse("a seed");
            }
            if self.relax > 0 {
                return refuse("relaxation");
            }
            if self.order == Order::FarthestFirst {
                return refuse("the farthest-first order");
            }
            // a window visits only the tiles reaching it
            let near = engine::collect_within(&tiling, &**density, self.count as f64, &|r| {
                window.reaches(r)
            })?;
            return Ok(near
                .into_iter()
                .map(|s| s.position)
                .filter(|&p| window.contains(p))
                .collect());
        }
        struct InMemory<'r> {
            request: &'r SphereRequest,
            tiling: SphereTiling,
        }
        impl InFrame<SphereRegion> for InMemory<'_> {
            type Out = Result<Vec<DVec3>, Error>;
            fn run<D, W>(self, density: &D, to_world: W) -> Self::Out
            where
                D: Density<SphereRegion> + ?Sized,
                W: Fn(DVec3) -> DVec3,
            {
                let request = self.request;
                let samples = engine::generate_ordered(
                    &self.tiling,
                    density,
                    request.count,
                    !request.expected,
                    request.order,
                )?;
                request.finish(samples, density, to_world)
            }
        }
        self.in_frame(
            density,
            InMemory {
                request: self,
                tiling,
            },
        )
    }

    /// `job` run on the density in the frame it is sampled in (rotated by
    /// the request's seed), with the map from that frame to the world.
    fn in_frame<J: InFrame<SphereRegion>>(&self, density: &SphereDensity, job: J) -> J::Out {
        match (density, self.seed) {
            (SphereDensity::Map(map), seed) => {
                let map = match seed {
                    Some(seed) => map.with_seed(seed),
                    None => map.clone(),
                };
                job.run(&map, |p| map.to_world(p))
            }
            (SphereDensity::Healpix(map), Some(seed)) => {
                let rotated = Rotated::new(map, seed);
                job.run(&rotated, |p| rotated.to_world(p))
            }
            (SphereDensity::Healpix(map), None) => job.run(map, |p| p),
            (SphereDensity::Regions(density), Some(seed)) => {
                let rotated = Rotated::new(&**density, seed);
                job.run(&rotated, |p| rotated.to_world(p))
            }
            (SphereDensity::Regions(density), None) => job.run(&**density, |p| p),
        }
    }

    /// [`SphereRequest::points`] handed to `sink` a block at a time
    /// ([`Blocks`]): a uniform request (without window or relaxation) streams
    /// block by block in bounded memory ([`engine::stream`]), an
    /// unsorted one (without window or relaxation) a batch at a time
    /// ([`engine::unsorted`]); others are generated in memory first. This
    /// is how `tessera sphere` writes.
    ///
    /// # Example
    /// ```
    /// use tessera::request::{SphereDensity, SphereRequest};
    /// let uniform = SphereDensity::parse(&["uniform"]).unwrap();
    /// let request = SphereRequest { count: 1000, ..Default::default() };
    /// let mut streamed = Vec::new();
    /// request.with_points(&uniform, |points| {
    ///     points.try_for_each_block(&mut |block| {
    ///         streamed.extend_from_slice(block);
    ///         Ok(())
    ///     })
    /// }).unwrap().unwrap();
    /// assert_eq!(streamed, request.points(&uniform).unwrap());
    /// ```
    pub fn with_points<R>(
        &self,
        density: &SphereDensity,
        sink: impl FnOnce(&mut dyn Blocks<DVec3>) -> R,
    ) -> Result<R, Error> {
        if let SphereDensity::Regions(d) = density {
            let tiling = self.tiling()?;
            let uniform = d.constant().is_some()
                && self.within.is_none()
                && self.relax == 0
                && self.order != Order::FarthestFirst;
            let stream = engine::stream(&tiling, self.count).filter(|_| uniform);
            if let Some(stream) = stream {
                // the frame of `Rotated::new(density, seed)`
                let frame = self.seed.map(|seed| Rotated::new(Uniform, seed));
                let mut points = stream.positions(|p| match &frame {
                    Some(frame) => frame.to_world(p),
                    None => p,
                });
                return Ok(sink(&mut points));
            }
        }
        if self.order == Order::Unsorted && self.within.is_none() && self.relax == 0 {
            struct Batches<'r, F> {
                request: &'r SphereRequest,
                tiling: SphereTiling,
                sink: F,
            }
            impl<F, R> InFrame<SphereRegion> for Batches<'_, F>
            where
                F: FnOnce(&mut dyn Blocks<DVec3>) -> R,
            {
                type Out = Result<R, Error>;
                fn run<D, W>(self, density: &D, to_world: W) -> Self::Out
                where
                    D: Density<SphereRegion> + ?Sized,
                    W: Fn(DVec3) -> DVec3,
                {
                    let (count, exact) = (self.request.count, !self.request.expected);
                    let samples = engine::unsorted(&self.tiling, density, count, exact)?;
                    Ok((self.sink)(&mut IterBlocks::new(
                        samples.map(|s| to_world(s.position)),
                    )))
                }
            }
            let tiling = self.tiling()?;
            return self.in_frame(
                density,
                Batches {
                    request: self,
                    tiling,
                    sink,
                },
            );
        }
        let points = self.points(density)?;
        Ok(sink(&mut IterBlocks::new(points)))
    }

    /// The positions of `samples` (in `density`'s sampling frame), relaxed,
    /// then mapped to the world.
    fn finish<D>(
        &self,
        samples: Vec<Sample<DVec3>>,
        density: &D,
        to_world: impl Fn(DVec3) -> DVec3,
    ) -> Result<Vec<DVec3>, Error>
    where
        D: Density<SphereRegion> + ?Sized,
    {
        // (`into_iter` and `collect` reuse the samples' memory, in one
        // pass without relaxation)
        if self.relax == 0 {
            return Ok(samples.into_iter().map(|s| to_world(s.position)).collect());
        }
        let mut points: Vec<DVec3> = samples.into_iter().map(|s| s.position).collect();
        crate::relax::relax(&mut points, density, self.relax)?;
        Ok(points.into_iter().map(to_world).collect())
    }
}

/// A job run on a request's density in its sampling frame (see
/// `SphereRequest::in_frame` and `PlaneRequest::in_frame`): generic over
/// the density, so that each kind is sampled without dynamic dispatch.
trait InFrame<R: crate::density::Region> {
    type Out;
    fn run<D, W>(self, density: &D, to_world: W) -> Self::Out
    where
        D: Density<R> + ?Sized,
        W: Fn(R::Point) -> R::Point;
}

/// Something worth telling about a map that was read all the same.
///
/// # Example
/// ```
/// use tessera::request::MapWarning;
/// let w = MapWarning::NotTwoToOne { name: "sky.exr".into(), width: 3, height: 1 };
/// assert_eq!(w.message("--strict"), "sky.exr: 3x1 is not a 2:1 lat-long map; using it as one");
/// ```
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum MapWarning {
    /// Pixels (and, for lights, colour samples) that were negative, NaN or
    /// infinite and were set to 0.
    BadPixels {
        /// The file, or what data in memory is called.
        name: std::path::PathBuf,
        /// Importance pixels set to 0.
        pixels: usize,
        /// Colour samples set to 0, when the colour was read too.
        colour_samples: Option<usize>,
    },
    /// HEALPix pixels marked [`crate::healpix::UNSEEN`] (no data), or
    /// left out of a partial-sky file, set to 0.
    Unseen {
        /// The file, or what data in memory is called.
        name: std::path::PathBuf,
        /// Pixels set to 0.
        pixels: usize,
    },
    /// HEALPix pixels that were negative, NaN or infinite and were set to 0.
    BadValues {
        /// The file, or what data in memory is called.
        name: std::path::PathBuf,
        /// Pixels set to 0.
        pixels: usize,
    },
    /// A map that is not 2:1, used as a lat-long map all the same.
    NotTwoToOne {
        /// The file, or what data in memory is called.
        name: std::path::PathBuf,
        /// Columns.
        width: usize,
        /// Rows.
        height: usize,
    },
}

impl MapWarning {
    /// The warning as `tessera` prints it, naming the strict option as the
    /// caller spells it (`--strict` on the command line).
    ///
    /// # Example
    /// ```
    /// use tessera::request::MapWarning;
    /// let w = MapWarning::BadPixels { name: "a.exr".into(), pixels: 2, colour_samples: Some(5) };
    /// assert!(w.message("strict=True").ends_with("treated as 0 (strict=True refuses them)"));
    /// ```
    pub fn message(&self, strict: &str) -> String {
        match self {
            MapWarning::BadPixels {
                name,
                pixels,
                colour_samples: None,
            } => format!(
                "{}: {pixels} negative, NaN or infinite pixel(s) treated as 0 ({strict} refuses NaN, infinities and negatives beyond codec noise)",
                name.display()
            ),
            MapWarning::BadPixels {
                name,
                pixels,
                colour_samples: Some(colour),
            } => format!(
                "{}: {pixels} pixel(s) and {colour} colour sample(s) negative, NaN or infinite, treated as 0 ({strict} refuses them)",
                name.display()
            ),
            MapWarning::Unseen { name, pixels } => format!(
                "{}: {pixels} UNSEEN pixel(s) (no data) treated as 0",
                name.display()
            ),
            MapWarning::BadValues { name, pixels } => format!(
                "{}: {pixels} negative, NaN or infinite pixel(s) treated as 0 ({strict} refuses them)",
                name.display()
            ),
            MapWarning::NotTwoToOne {
                name,
                width,
                height,
            } => format!(
                "{}: {width}x{height} is not a 2:1 lat-long map; using it as one",
                name.display()
            ),
        }
    }
}

/// A lat-long map read from `path` as `tessera sphere --map` reads it, with
/// the warnings it prints (bad pixels set to 0, then
/// [`map_from_raster`]'s). Errors name the file.
///
/// # Example
/// ```
/// use tessera::{density::envmap::Up, request::{open_map, MapWarning}};
/// let dir = std::env::temp_dir().join(format!("tessera-doc-open-map-{}", std::process::id()));
/// std::fs::create_dir_all(&dir).unwrap();
/// let path = dir.join("wide.exr");
/// exr::prelude::write_rgb_file(&path, 3, 1, |x, _| (x as f32, 1.0f32, 0.0f32)).unwrap();
/// let (map, warnings) = open_map(&path, &Default::default(), Up::Z).unwrap();
/// assert_eq!((map.width(), map.height()), (3, 1));
/// assert!(matches!(warnings[..], [MapWarning::NotTwoToOne { width: 3, height: 1, .. }]));
/// assert!(open_map(&dir.join("missing.exr"), &Default::default(), Up::Z).is_err());
/// std::fs::remove_dir_all(&dir).unwrap();
/// ```
pub fn open_map(
    path: &Path,
    options: &ReadOptions,
    up: Up,
) -> Result<(EnvMap, Vec<MapWarning>), Error> {
    let raster = read_raster(path, options)?;
    let mut warnings = Vec::new();
    if raster.bad_pixels > 0 {
        warnings.push(MapWarning::BadPixels {
            name: path.into(),
            pixels: raster.bad_pixels,
            colour_samples: None,
        });
    }
    let (map, more) = map_from_raster(path, raster, up)?;
    warnings.extend(more);
    Ok((map, warnings))
}

/// The environment map of a raster read from (or, for data in memory,
/// named) `name`, and the warning `tessera sphere --map` and `tessera
/// lights` print when it is not 2:1 (it is used as a lat-long map all the
/// same). Errors name `name`.
///
/// # Example
/// ```
/// use tessera::{density::envmap::Up, io::image::Raster, request::map_from_raster};
/// let raster = Raster::from_values("mem", 4, 2, vec![1.0; 8], false).unwrap();
/// let (map, warning) = map_from_raster("mem".as_ref(), raster, Up::Y).unwrap();
/// assert!(warning.is_none() && map.up() == Up::Y);
/// ```
pub fn map_from_raster(
    name: &Path,
    raster: Raster,
    up: Up,
) -> Result<(EnvMap, Option<MapWarning>), Error> {
    let warning = (raster.width != 2 * raster.height).then(|| MapWarning::NotTwoToOne {
        name: name.into(),
        width: raster.width,
        height: raster.height,
    });
    let map = EnvMap::new(raster, up).map_err(|e| Error::File {
        path: name.into(),
        reason: e.to_string(),
    })?;
    Ok((map, warning))
}

/// A map file's importance and colour as `tessera lights` reads them
/// ([`crate::lights::read_rgb`]), its environment map and the warnings it
/// prints (bad samples set to 0, a map that is not 2:1).
///
/// # Example
/// ```
/// use tessera::{density::envmap::Up, request::open_light_map};
/// let dir = std::env::temp_dir().join(format!("tessera-doc-open-light-map-{}", std::process::id()));
/// std::fs::create_dir_all(&dir).unwrap();
/// let path = dir.join("sky.exr");
/// exr::prelude::write_rgb_file(&path, 4, 2, |x, _| (x as f32, 1.0f32, 0.5f32)).unwrap();
/// let (map, rgb, warnings) = open_light_map(&path, &Default::default(), Up::Z).unwrap();
/// assert_eq!((map.width(), rgb.rgb.len(), warnings.len()), (4, 8, 0));
/// std::fs::remove_dir_all(&dir).unwrap();
/// ```
pub fn open_light_map(
    path: &Path,
    options: &ReadOptions,
    up: Up,
) -> Result<(EnvMap, RgbMap, Vec<MapWarning>), Error> {
    let (rgb, raster) = crate::lights::read_rgb(path, options)?;
    let mut warnings = Vec::new();
    if raster.bad_pixels > 0 || rgb.bad_samples > 0 {
        warnings.push(MapWarning::BadPixels {
            name: path.into(),
            pixels: raster.bad_pixels,
            colour_samples: Some(rgb.bad_samples),
        });
    }
    let (map, more) = map_from_raster(path, raster, up)?;
    warnings.extend(more);
    Ok((map, rgb, warnings))
}

/// A HEALPix map's warnings: its [`crate::healpix::UNSEEN`] pixels and
/// its bad values (negative, NaN, infinite), each set to 0.
///
/// # Example
/// ```
/// use tessera::{density::healpix::HealpixMap, healpix::{Scheme, UNSEEN}};
/// use tessera::request::{healpix_warnings, MapWarning};
/// let mut values = vec![1.0; 12];
/// values[2] = UNSEEN;
/// let map = HealpixMap::new("mem", values, Scheme::Ring, false).unwrap();
/// let warnings = healpix_warnings("mem".as_ref(), &map);
/// assert!(matches!(warnings[..], [MapWarning::Unseen { pixels: 1, .. }]));
/// ```
pub fn healpix_warnings(name: &Path, map: &HealpixMap) -> Vec<MapWarning> {
    let mut warnings = Vec::new();
    if map.unseen_pixels() > 0 {
        warnings.push(MapWarning::Unseen {
            name: name.into(),
            pixels: map.unseen_pixels(),
        });
    }
    if map.bad_pixels() > 0 {
        warnings.push(MapWarning::BadValues {
            name: name.into(),
            pixels: map.bad_pixels(),
        });
    }
    warnings
}

/// A HEALPix FITS map read as `tessera sphere --healpix-map FILE --field
/// N` reads it ([`HealpixMap::open`]), with the warnings it prints.
///
/// # Example
/// ```
/// use tessera::request::open_healpix;
/// let err = open_healpix("missing.fits".as_ref(), 0, false).err().unwrap();
/// assert!(err.to_string().contains("missing.fits"));
/// ```
pub fn open_healpix(
    path: &Path,
    field: usize,
    strict: bool,
) -> Result<(HealpixMap, Vec<MapWarning>), Error> {
    let map = HealpixMap::open(path, field, strict)?;
    let warnings = healpix_warnings(path, &map);
    Ok((map, warnings))
}

/// The planar tile systems of `tessera plane --system`.
///
/// # Example
/// ```
/// use tessera::request::PlaneKind;
/// assert_eq!("ppentomino".parse::<PlaneKind>().unwrap(), PlaneKind::Ppentomino);
/// assert!("hexagon".parse::<PlaneKind>().is_err());
/// ```
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum PlaneKind {
    /// Penrose: six tile types, scale 1/phi per level.
    Penrose,
    /// G-hexomino, 81-rep.
    Ghexomino,
    /// P-pentomino, 4-rep.
    Ppentomino,
}

impl PlaneKind {
    /// The tables this system samples with.
    ///
    /// # Example
    /// ```
    /// use tessera::{lut::TableSystem, request::PlaneKind};
    /// assert_eq!(PlaneKind::Penrose.table_system(), TableSystem::Penrose);
    /// ```
    pub fn table_system(self) -> TableSystem {
        match self {
            PlaneKind::Penrose => TableSystem::Penrose,
            PlaneKind::Ghexomino => TableSystem::Plane(crate::lut::PlaneSystem::Ghexomino),
            PlaneKind::Ppentomino => TableSystem::Plane(crate::lut::PlaneSystem::Ppentomino),
        }
    }
}

impl std::str::FromStr for PlaneKind {
    type Err = Error;
    fn from_str(s: &str) -> Result<Self, Error> {
        match s {
            "penrose" => Ok(PlaneKind::Penrose),
            "ghexomino" => Ok(PlaneKind::Ghexomino),
            "ppentomino" => Ok(PlaneKind::Ppentomino),
            other => Err(Error::Request(format!(
                "unknown planar system '{other}'; expected penrose, ghexomino or ppentomino"
            ))),
        }
    }
}

/// The options of `tessera plane` besides the density: `--system`, `-n`,
/// `--expected`, `--unsorted`, `--seed` and `--domain`.
///
/// # Example
/// ```
/// use tessera::density::{plane::Ramp, rectangle::Rectangle};
/// use tessera::request::{PlaneKind, PlaneRequest};
/// let mut request = PlaneRequest::new(PlaneKind::Penrose, 400);
/// request.domain = Some(Rectangle::parse("0,0,2,1").unwrap());
/// let points = request.points(&Ramp).unwrap();
/// assert_eq!(points.len(), 400);
/// assert!(points.iter().all(|p| p.x < 2.0 && p.y < 1.0));
/// ```
#[derive(Clone, Debug, PartialEq)]
pub struct PlaneRequest {
    /// The tile system.
    pub system: PlaneKind,
    /// Number of samples (exact unless `expected`).
    pub count: usize,
    /// Skip the exactness pass: the natural count near `count`.
    pub expected: bool,
    /// Progressive (by rank), farthest first (every prefix evenly spread)
    /// or the cheapest order: see [`Order`].
    pub order: Order,
    /// Sample under a uniformly random toroidal shift drawn from this seed.
    pub seed: Option<u64>,
    /// Sample this rectangle instead of the unit square: the density's
    /// unit square stretched over it.
    pub domain: Option<Rectangle>,
    /// Sample with this table of `system` instead of the built-in one (see
    /// [`Table::open`] and [`PlaneKind::table_system`]).
    pub table: Option<Table>,
}

impl PlaneRequest {
    /// `count` samples of `system` on the unit square, exact, progressive,
    /// without seed.
    ///
    /// # Example
    /// ```
    /// use tessera::{density::Uniform, request::{PlaneKind, PlaneRequest}};
    /// let points = PlaneRequest::new(PlaneKind::Ghexomino, 81).points(&Uniform).unwrap();
    /// assert_eq!(points.len(), 81);
    /// ```
    pub fn new(system: PlaneKind, count: usize) -> Self {
        PlaneRequest {
            system,
            count,
            expected: false,
            order: Order::Progressive,
            seed: None,
            domain: None,
            table: None,
        }
    }

    /// The request's points (in the domain), in its order. `density` is
    /// given on the unit square, as [`crate::density::plane::parse`]
    /// returns it.
    ///
    /// # Example
    /// ```
    /// use tessera::{density::plane::Ramp, request::{PlaneKind, PlaneRequest}};
    /// let mut request = PlaneRequest::new(PlaneKind::Ppentomino, 2000);
    /// request.seed = Some(4);
    /// let points = request.points(&Ramp).unwrap();
    /// assert!(points.iter().filter(|p| p.x >= 0.5).count() > 1400);
    /// ```
    pub fn points(&self, density: &dyn Density<PlaneRegion>) -> Result<Vec<DVec2>, Error> {
        match self.tiling()? {
            Tiling::Penrose(tiling) => self.points_with(&tiling, density),
            Tiling::Polyomino(tiling) => self.points_with(&*tiling, density),
        }
    }

    /// The tiling of `system`, driven by the request's table or the
    /// built-in one.
    fn tiling(&self) -> Result<Tiling, Error> {
        let built_in = || match self.system {
            PlaneKind::Penrose => Tiling::Penrose(PenroseTiling::default()),
            PlaneKind::Ghexomino => Tiling::Polyomino(Box::new(PlaneTiling::ghexomino())),
            PlaneKind::Ppentomino => Tiling::Polyomino(Box::new(PlaneTiling::ppentomino())),
        };
        match (&self.table, self.system) {
            (None, _) => Ok(built_in()),
            (Some(Table::Penrose(lut)), PlaneKind::Penrose) => {
                Ok(Tiling::Penrose(PenroseTiling::new(lut.clone())))
            }
            (Some(Table::Plane(lut)), PlaneKind::Ghexomino | PlaneKind::Ppentomino) => {
                Ok(Tiling::Polyomino(Box::new(PlaneTiling::new(lut.clone()))))
            }
            (Some(_), system) => Err(Error::Request(format!(
                "the table is not a {} table",
                system.table_system().name()
            ))),
        }
    }

    /// [`PlaneRequest::points`] handed to `sink` a block at a time
    /// ([`Blocks`]): a uniform request on the unit square without seed streams block by
    /// block in bounded memory ([`engine::stream`]), an unsorted
    /// one a batch at a time ([`engine::unsorted`]). This is how `tessera
    /// plane` writes.
    ///
    /// # Example
    /// ```
    /// use tessera::{density::Uniform, request::{PlaneKind, PlaneRequest}};
    /// let request = PlaneRequest::new(PlaneKind::Ppentomino, 300);
    /// let n = request.with_points(&Uniform, |points| points.len()).unwrap();
    /// assert_eq!(n, 300);
    /// ```
    pub fn with_points<R>(
        &self,
        density: &dyn Density<PlaneRegion>,
        sink: impl FnOnce(&mut dyn Blocks<DVec2>) -> R,
    ) -> Result<R, Error> {
        let streams = density.constant().is_some()
            && self.domain.is_none()
            && self.seed.is_none()
            && self.order != Order::FarthestFirst;
        if streams {
            let tiling = self.tiling()?;
            let stream = tiling.stream(self.count);
            if let Some(mut points) = stream {
                return Ok(sink(&mut *points));
            }
        }
        if self.order == Order::Unsorted {
            struct Batches<'t, S, F> {
                tiling: &'t S,
                count: usize,
                exact: bool,
                sink: F,
            }
            impl<S, F, R> InFrame<PlaneRegion> for Batches<'_, S, F>
            where
                S: TileSystem<Point = DVec2, Region = PlaneRegion>,
                F: FnOnce(&mut dyn Blocks<DVec2>) -> R,
            {
                type Out = Result<R, Error>;
                fn run<D, W>(self, density: &D, to_world: W) -> Self::Out
                where
                    D: Density<PlaneRegion> + ?Sized,
                    W: Fn(DVec2) -> DVec2,
                {
                    let samples = engine::unsorted(self.tiling, density, self.count, self.exact)?;
                    Ok((self.sink)(&mut IterBlocks::new(
                        samples.map(|s| to_world(s.position)),
                    )))
                }
            }
            let (count, exact) = (self.count, !self.expected);
            return match self.tiling()? {
                Tiling::Penrose(tiling) => self.in_frame(
                    density,
                    Batches {
                        tiling: &tiling,
                        count,
                        exact,
                        sink,
                    },
                ),
                Tiling::Polyomino(tiling) => self.in_frame(
                    density,
                    Batches {
                        tiling: &*tiling,
                        count,
                        exact,
                        sink,
                    },
                ),
            };
        }
        let points = self.points(density)?;
        Ok(sink(&mut IterBlocks::new(points)))
    }

    /// The pdf per unit area of the domain at a point of it, for samples
    /// of `density` (given on the unit square, which the domain stretches):
    /// what `tessera plane --format csv` writes.
    ///
    /// # Example
    /// ```
    /// use tessera::density::{rectangle::Rectangle, Uniform};
    /// use tessera::request::{PlaneKind, PlaneRequest};
    /// let mut request = PlaneRequest::new(PlaneKind::Ghexomino, 10);
    /// request.domain = Some(Rectangle::parse("0,0,4,2").unwrap());
    /// assert_eq!(request.pdf(&Uniform)(glam::DVec2::new(1.0, 1.0)), 1.0 / 8.0);
    /// ```
    pub fn pdf<'a>(&self, density: &'a dyn Density<PlaneRegion>) -> impl Fn(DVec2) -> f64 + 'a {
        // the density's unit square is stretched over the rectangle
        let (lo, size) = self
            .domain
            .map_or((DVec2::ZERO, DVec2::ONE), |r| (r.lo, r.hi - r.lo));
        let scale = density.mean() * size.x * size.y;
        move |q: DVec2| density.value((q - lo) / size) / scale
    }

    fn points_with<S>(
        &self,
        tiling: &S,
        density: &dyn Density<PlaneRegion>,
    ) -> Result<Vec<DVec2>, Error>
    where
        S: TileSystem<Point = DVec2, Region = PlaneRegion>,
    {
        struct InMemory<'r, S> {
            request: &'r PlaneRequest,
            tiling: &'r S,
        }
        impl<S> InFrame<PlaneRegion> for InMemory<'_, S>
        where
            S: TileSystem<Point = DVec2, Region = PlaneRegion>,
        {
            type Out = Result<Vec<DVec2>, Error>;
            fn run<D, W>(self, density: &D, to_world: W) -> Self::Out
            where
                D: Density<PlaneRegion> + ?Sized,
                W: Fn(DVec2) -> DVec2,
            {
                let r = self.request;
                let samples =
                    engine::generate_ordered(self.tiling, density, r.count, !r.expected, r.order)?;
                // (`into_iter` and `collect` reuse the samples' memory)
                Ok(samples.into_iter().map(|s| to_world(s.position)).collect())
            }
        }
        self.in_frame(
            density,
            InMemory {
                request: self,
                tiling,
            },
        )
    }

    /// `job` run on the density of the unit square (the domain's, shifted
    /// by the request's seed), with the map from the square to the domain.
    fn in_frame<J: InFrame<PlaneRegion>>(
        &self,
        density: &dyn Density<PlaneRegion>,
        job: J,
    ) -> J::Out {
        let restricted = self.domain.map(|rect| rect.restrict(density));
        let square: &dyn Density<PlaneRegion> = match &restricted {
            Some(r) => r,
            None => density,
        };
        let domain = self.domain;
        let to_domain = move |p: DVec2| domain.map_or(p, |rect| rect.to_world(p));
        match self.seed {
            Some(seed) => {
                let shifted = Shifted::new(square, seed);
                job.run(&shifted, |p| to_domain(shifted.to_world(p)))
            }
            None => job.run(square, to_domain),
        }
    }
}

/// The tiling of a planar request, whichever system.
enum Tiling {
    Penrose(PenroseTiling),
    // boxed: its level tables make it 17 times the Penrose tiling's size
    Polyomino(Box<PlaneTiling>),
}

impl Tiling {
    /// The tiling's uniform stream of `count` points, if it has one.
    fn stream(&self, count: usize) -> Option<Box<dyn Blocks<DVec2> + '_>> {
        fn points<'a, S: TileSystem<Point = DVec2>>(
            tiling: &'a S,
            count: usize,
        ) -> Option<Box<dyn Blocks<DVec2> + 'a>> {
            let stream = engine::stream(tiling, count)?;
            Some(Box::new(stream.positions(|p| p)))
        }
        match self {
            Tiling::Penrose(tiling) => points(tiling, count),
            Tiling::Polyomino(tiling) => points(&**tiling, count),
        }
    }
}

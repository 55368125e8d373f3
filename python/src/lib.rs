//! The native half of the `tessera` Python package: numpy arrays in and
//! out of the library's requests (`tessera::request`), which the command
//! line runs too, so that a request gives the same bits from either.
//!
//! Every call copies its Python inputs into owned memory, releases the GIL,
//! runs (on a pool of `threads` workers when asked) and turns the library's
//! errors into `ValueError` or `OSError` (`FileNotFoundError` for a
//! missing file), and a panic into `RuntimeError`. The keyword options,
//! defaults and docstrings live in `python/tessera/__init__.py`.

use glam::{DVec2, DVec3};
use numpy::{PyArray1, PyArray2, PyArrayMethods, PyReadonlyArray1, PyReadonlyArray2};
use numpy::{PyReadonlyArrayDyn, PyUntypedArrayMethods};
use pyo3::exceptions::{PyOSError, PyRuntimeError, PyValueError};
use pyo3::prelude::*;
use rayon::prelude::*;
use std::path::PathBuf;
use std::sync::{Arc, Mutex, OnceLock};
use tessera::density::envmap::{EnvMap, Up};
use tessera::density::healpix::HealpixMap;
use tessera::density::sphere::Cap;
use tessera::engine::Order;
use tessera::healpix::Scheme;
use tessera::io::image::{Raster, ReadOptions};
use tessera::lights::RgbMap;
use tessera::lut::{Table, TableSystem};
use tessera::request::{MapWarning, PlaneKind, PlaneRequest, SphereDensity, SphereRequest};
use tessera::tiling::sphere::SphereTiling;
use tessera::Error;

/// Why a call failed.
enum Failure {
    Tessera(Error),
    Panic(String),
    Pool(String),
}

impl From<Error> for Failure {
    fn from(e: Error) -> Self {
        Failure::Tessera(e)
    }
}

impl From<Failure> for PyErr {
    fn from(failure: Failure) -> PyErr {
        match failure {
            Failure::Tessera(e) => match &e {
                // OSError(errno, message) becomes FileNotFoundError,
                // PermissionError, IsADirectoryError... as the errno says
                Error::Io { source, .. } => match source.raw_os_error() {
                    Some(errno) => PyOSError::new_err((errno, e.to_string())),
                    None => PyOSError::new_err(e.to_string()),
                },
                _ => PyValueError::new_err(e.to_string()),
            },
            Failure::Panic(why) => {
                PyRuntimeError::new_err(format!("tessera: internal error (a panic): {why}"))
            }
            Failure::Pool(why) => PyRuntimeError::new_err(why),
        }
    }
}

/// A pool of `threads` workers, built once per count.
fn pool(threads: usize) -> Result<Arc<rayon::ThreadPool>, Failure> {
    static POOLS: Mutex<Vec<(usize, Arc<rayon::ThreadPool>)>> = Mutex::new(Vec::new());
    let threads = threads.max(1);
    let mut pools = POOLS.lock().unwrap_or_else(|e| e.into_inner());
    if let Some((_, pool)) = pools.iter().find(|(t, _)| *t == threads) {
        return Ok(pool.clone());
    }
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()
        .map_err(|e| Failure::Pool(format!("tessera: cannot start {threads} threads: {e}")))?;
    let pool = Arc::new(pool);
    pools.push((threads, pool.clone()));
    Ok(pool)
}

/// Runs `job` without the GIL, on `threads` workers (the global pool when
/// `None`), with panics caught.
fn run<T: Send>(
    py: Python<'_>,
    threads: Option<usize>,
    job: impl FnOnce() -> Result<T, Error> + Send,
) -> PyResult<T> {
    let result = py.detach(move || {
        let guarded = move || match std::panic::catch_unwind(std::panic::AssertUnwindSafe(job)) {
            Ok(result) => result.map_err(Failure::from),
            Err(panic) => {
                let why = panic
                    .downcast_ref::<&str>()
                    .map(|s| s.to_string())
                    .or_else(|| panic.downcast_ref::<String>().cloned())
                    .unwrap_or_else(|| "unknown".into());
                Err(Failure::Panic(why))
            }
        };
        match threads {
            None => guarded(),
            Some(t) => pool(t)?.install(guarded),
        }
    });
    result.map_err(PyErr::from)
}

/// The order `unsorted` and `farthest_first` ask for (not both).
fn order(unsorted: bool, farthest_first: bool) -> Result<Order, Error> {
    match (unsorted, farthest_first) {
        (true, true) => Err(Error::Request(
            "unsorted and farthest_first are two orders; ask for one".into(),
        )),
        (true, false) => Ok(Order::Unsorted),
        (false, true) => Ok(Order::FarthestFirst),
        (false, false) => Ok(Order::Progressive),
    }
}

fn up_axis(up: &str) -> PyResult<Up> {
    match up {
        "z" | "Z" => Ok(Up::Z),
        "y" | "Y" => Ok(Up::Y),
        other => Err(PyValueError::new_err(format!(
            "up '{other}': expected 'z' or 'y'"
        ))),
    }
}

/// A map given as an array: an importance raster (H x W) or colour
/// (H x W x 3), copied out of Python.
enum MapArray {
    Grey {
        width: usize,
        height: usize,
        values: Vec<f64>,
    },
    Rgb(RgbMap),
}

/// The name errors and warnings give a map passed as an array.
const MAP_ARRAY: &str = "map array";

impl MapArray {
    fn copy(array: &PyReadonlyArrayDyn<'_, f64>) -> PyResult<MapArray> {
        let shape = array.shape().to_vec();
        let view = array.as_array();
        // (the Python side passes C-contiguous arrays: read in place)
        let flat = match view.as_slice() {
            Some(flat) => std::borrow::Cow::Borrowed(flat),
            None => std::borrow::Cow::Owned(view.iter().copied().collect()),
        };
        match shape[..] {
            [height, width] => Ok(MapArray::Grey {
                width,
                height,
                values: flat.into_owned(),
            }),
            [height, width, 3] => {
                // colour is held in f32, as a file's channels are
                let rgb = flat
                    .chunks_exact(3)
                    .map(|c| [c[0] as f32, c[1] as f32, c[2] as f32])
                    .collect();
                Ok(MapArray::Rgb(RgbMap {
                    width,
                    height,
                    rgb,
                    bad_samples: 0,
                }))
            }
            _ => Err(PyValueError::new_err(format!(
                "a map array is H x W or H x W x 3; this one has shape {shape:?}"
            ))),
        }
    }

    /// The importance raster, as `read_raster` makes it of a file holding
    /// these values (Rec.709 luminance of the colour).
    fn raster(&self, strict: bool) -> Result<Raster, Error> {
        match self {
            MapArray::Grey {
                width,
                height,
                values,
            } => Raster::from_values(MAP_ARRAY, *width, *height, values.clone(), strict),
            MapArray::Rgb(rgb) => {
                Raster::from_values(MAP_ARRAY, rgb.width, rgb.height, rgb.luminance(), strict)
            }
        }
    }

    /// The colour of the lights, bad samples (negative, NaN, infinite) set
    /// to 0 and counted, or refused with `strict`, as `read_rgb` does.
    fn colour(&self, strict: bool) -> Result<RgbMap, Error> {
        let mut rgb = match self {
            MapArray::Grey {
                width,
                height,
                values,
            } => RgbMap {
                width: *width,
                height: *height,
                rgb: values.iter().map(|&v| [v as f32; 3]).collect(),
                bad_samples: 0,
            },
            MapArray::Rgb(rgb) => rgb.clone(),
        };
        let width = rgb.width.max(1);
        let mut first_bad = None;
        for (k, pixel) in rgb.rgb.iter_mut().enumerate() {
            for (c, v) in pixel.iter_mut().enumerate() {
                if !(v.is_finite() && *v >= 0.0) {
                    first_bad.get_or_insert((k % width, k / width, c, *v));
                    rgb.bad_samples += 1;
                    *v = 0.0;
                }
            }
        }
        if let (true, Some((i, j, c, v))) = (strict, first_bad) {
            return Err(Error::File {
                path: MAP_ARRAY.into(),
                reason: format!(
                    "{} colour sample(s) are negative, NaN or infinite (first: column {i}, row {j}, channel {}, value {v})",
                    rgb.bad_samples,
                    ["R", "G", "B"][c]
                ),
            });
        }
        Ok(rgb)
    }
}

/// Where a lat-long map comes from.
enum MapSource {
    Path(PathBuf),
    Array(MapArray),
}

fn map_source(
    path: Option<PathBuf>,
    array: Option<PyReadonlyArrayDyn<'_, f64>>,
) -> PyResult<MapSource> {
    match (path, array) {
        (Some(path), None) => Ok(MapSource::Path(path)),
        (None, Some(array)) => Ok(MapSource::Array(MapArray::copy(&array)?)),
        _ => Err(PyValueError::new_err(
            "a map is a path or an array, one of them",
        )),
    }
}

/// The name errors and warnings give a HEALPix map passed as an array.
const HEALPIX_ARRAY: &str = "healpix array";

/// How warnings name the strict option.
const STRICT: &str = "strict=True";

fn messages(warnings: impl IntoIterator<Item = MapWarning>) -> Warnings {
    warnings.into_iter().map(|w| w.message(STRICT)).collect()
}

/// A lat-long map read from its source, with the warnings it deserves.
fn read_map(
    source: &MapSource,
    up: Up,
    channel: Option<String>,
    strict: bool,
) -> Result<(EnvMap, Warnings), Error> {
    match source {
        MapSource::Path(path) => {
            let options = ReadOptions {
                channel,
                strict,
                ..Default::default()
            };
            let (map, warnings) = tessera::request::open_map(path, &options, up)?;
            Ok((map, messages(warnings)))
        }
        MapSource::Array(array) => {
            if channel.is_some() {
                return Err(Error::Request(
                    "channel picks a channel of a map file; of an array, pass the plane you want (e.g. map[..., 0])".into(),
                ));
            }
            let raster = array.raster(strict)?;
            let mut warnings = Vec::new();
            if raster.bad_pixels > 0 {
                warnings.push(MapWarning::BadPixels {
                    name: MAP_ARRAY.into(),
                    pixels: raster.bad_pixels,
                    colour_samples: None,
                });
            }
            let (map, more) = tessera::request::map_from_raster(MAP_ARRAY.as_ref(), raster, up)?;
            warnings.extend(more);
            Ok((map, messages(warnings)))
        }
    }
}

/// The density of a sphere request: a prepared map, or the regions.
fn sphere_density(
    density: &[String],
    map: Option<&Map>,
    healpix: Option<&Healpix>,
) -> Result<SphereDensity, Error> {
    match (map, healpix) {
        (Some(map), _) => Ok(SphereDensity::Map(map.map.clone())),
        (None, Some(healpix)) => Ok(SphereDensity::Healpix(healpix.map.clone())),
        (None, None) => SphereDensity::parse(density),
    }
}

/// `Vec<DVec3>` as an (n, 3) array, in its memory (no copy).
fn points3(py: Python<'_>, points: Vec<DVec3>) -> PyResult<Bound<'_, PyArray2<f64>>> {
    let n = points.len();
    let flat: Vec<f64> = bytemuck::allocation::cast_vec(points);
    PyArray1::from_vec(py, flat).reshape([n, 3])
}

/// `Vec<DVec2>` as an (n, 2) array, in its memory (no copy).
fn points2(py: Python<'_>, points: Vec<DVec2>) -> PyResult<Bound<'_, PyArray2<f64>>> {
    let n = points.len();
    let flat: Vec<f64> = bytemuck::allocation::cast_vec(points);
    PyArray1::from_vec(py, flat).reshape([n, 2])
}

/// The rows of an (n, k) array, copied.
fn rows<const K: usize>(array: &PyReadonlyArray2<'_, f64>) -> PyResult<Vec<[f64; K]>> {
    let shape = array.shape();
    if shape[1] != K {
        return Err(PyValueError::new_err(format!(
            "expected an (n, {K}) array; this one has shape {shape:?}"
        )));
    }
    let view = array.as_array();
    Ok(view
        .rows()
        .into_iter()
        .map(|r| std::array::from_fn(|k| r[k]))
        .collect())
}

type Warnings = Vec<String>;
/// Points and their pdfs when asked for.
type Points<'py> = (Bound<'py, PyArray2<f64>>, Option<Bound<'py, PyArray1<f64>>>);
/// Points, their pdfs when asked for, and warnings.
type PointsOut<'py> = (
    Bound<'py, PyArray2<f64>>,
    Option<Bound<'py, PyArray1<f64>>>,
    Warnings,
);
/// Two columns, as (lon, lat).
type Columns<'py> = (Bound<'py, PyArray1<f64>>, Bound<'py, PyArray1<f64>>);

/// See `tessera.sphere`.
#[pyfunction]
#[pyo3(signature = (n, density, map, healpix, within, seed, threads, expected, unsorted, farthest_first, pdf, relax, table))]
#[allow(clippy::too_many_arguments)]
fn sphere<'py>(
    py: Python<'py>,
    n: usize,
    density: Vec<String>,
    map: Option<PyRef<'py, Map>>,
    healpix: Option<PyRef<'py, Healpix>>,
    within: Option<String>,
    seed: Option<u64>,
    threads: Option<usize>,
    expected: bool,
    unsorted: bool,
    farthest_first: bool,
    pdf: bool,
    relax: usize,
    table: Option<PathBuf>,
) -> PyResult<Points<'py>> {
    let density =
        sphere_density(&density, map.as_deref(), healpix.as_deref()).map_err(Failure::from)?;
    let (points, pdfs) = run(py, threads, move || {
        let request = SphereRequest {
            count: n,
            expected,
            order: order(unsorted, farthest_first)?,
            seed,
            within: within.as_deref().map(Cap::window).transpose()?,
            relax,
            table: table
                .map(|path| Table::open(&path, TableSystem::Sphere))
                .transpose()?,
        };
        let points = request.points(&density)?;
        let pdfs = pdf.then(|| {
            let pdf = density.pdf();
            points.par_iter().map(|&p| pdf(p)).collect::<Vec<f64>>()
        });
        Ok((points, pdfs))
    })?;
    let pdfs = pdfs.map(|p| PyArray1::from_vec(py, p));
    Ok((points3(py, points)?, pdfs))
}

/// See `tessera.pdf`.
#[pyfunction]
#[pyo3(signature = (directions, density, map, healpix, threads))]
fn pdf<'py>(
    py: Python<'py>,
    directions: PyReadonlyArray2<'py, f64>,
    density: Vec<String>,
    map: Option<PyRef<'py, Map>>,
    healpix: Option<PyRef<'py, Healpix>>,
    threads: Option<usize>,
) -> PyResult<Bound<'py, PyArray1<f64>>> {
    let density =
        sphere_density(&density, map.as_deref(), healpix.as_deref()).map_err(Failure::from)?;
    let directions: Vec<DVec3> = rows::<3>(&directions)?
        .into_iter()
        .map(DVec3::from_array)
        .collect();
    if let Some(k) = directions
        .iter()
        .position(|d| !d.is_finite() || d.length_squared() == 0.0)
    {
        return Err(PyValueError::new_err(format!(
            "direction {k} ({}) is not a finite non-zero vector",
            directions[k]
        )));
    }
    let pdfs = run(py, threads, move || {
        let pdf = density.pdf();
        Ok(directions.par_iter().map(|&d| pdf(d)).collect())
    })?;
    Ok(PyArray1::from_vec(py, pdfs))
}

/// See `tessera.plane`.
#[pyfunction]
#[pyo3(signature = (n, system, density, image_path, image_array, invert, domain, seed, threads, expected, unsorted, farthest_first, pdf, table))]
#[allow(clippy::too_many_arguments)]
fn plane<'py>(
    py: Python<'py>,
    n: usize,
    system: &str,
    density: String,
    image_path: Option<String>,
    image_array: Option<PyReadonlyArrayDyn<'py, f64>>,
    invert: bool,
    domain: Option<String>,
    seed: Option<u64>,
    threads: Option<usize>,
    expected: bool,
    unsorted: bool,
    farthest_first: bool,
    pdf: bool,
    table: Option<PathBuf>,
) -> PyResult<PointsOut<'py>> {
    let image = match image_array {
        Some(array) => Some(MapArray::copy(&array)?),
        None => None,
    };
    let system: PlaneKind = system.parse().map_err(Failure::from)?;
    let (points, pdfs, warnings) = run(py, threads, move || {
        let mut warnings = Vec::new();
        let density = match (image_path, image) {
            // the command line's `--density image:PATH`
            (Some(path), _) => tessera::density::plane::parse(&format!("image:{path}"), invert)?,
            (None, Some(image)) => {
                let raster = image.raster(false)?;
                if raster.bad_pixels > 0 {
                    warnings.push(format!(
                        "image array: {} negative, NaN or infinite pixel(s) treated as 0",
                        raster.bad_pixels
                    ));
                }
                let image = tessera::density::plane::Raster::new(
                    raster.width,
                    raster.height,
                    raster.values,
                    invert,
                )?;
                Box::new(image)
            }
            (None, None) => tessera::density::plane::parse(&density, invert)?,
        };
        let request = PlaneRequest {
            system,
            count: n,
            expected,
            order: order(unsorted, farthest_first)?,
            seed,
            domain: domain
                .as_deref()
                .map(tessera::density::rectangle::Rectangle::parse)
                .transpose()?,
            table: table
                .map(|path| Table::open(&path, system.table_system()))
                .transpose()?,
        };
        let points = request.points(&*density)?;
        let pdfs = pdf.then(|| {
            let pdf = request.pdf(&*density);
            points.par_iter().map(|&p| pdf(p)).collect::<Vec<f64>>()
        });
        Ok((points, pdfs, warnings))
    })?;
    let pdfs = pdfs.map(|p| PyArray1::from_vec(py, p));
    Ok((points2(py, points)?, pdfs, warnings))
}

type LightsOut<'py> = (
    Bound<'py, PyArray2<f64>>,
    Bound<'py, PyArray2<f64>>,
    Bound<'py, PyArray1<f64>>,
    Bound<'py, PyArray1<f64>>,
    Warnings,
);

/// See `tessera.lights`.
#[pyfunction]
#[pyo3(signature = (map_path, map_array, n, up, channel, strict, seed, exponent, lloyd, threads))]
#[allow(clippy::too_many_arguments)]
fn lights<'py>(
    py: Python<'py>,
    map_path: Option<PathBuf>,
    map_array: Option<PyReadonlyArrayDyn<'py, f64>>,
    n: usize,
    up: &str,
    channel: Option<String>,
    strict: bool,
    seed: Option<u64>,
    exponent: Option<f64>,
    lloyd: Option<usize>,
    threads: Option<usize>,
) -> PyResult<LightsOut<'py>> {
    let up = up_axis(up)?;
    let map = map_source(map_path, map_array)?;
    let (lights, warnings) = run(py, threads, move || {
        let (map, rgb, warnings): (EnvMap, RgbMap, Warnings) = match &map {
            MapSource::Path(path) => {
                let options = ReadOptions {
                    channel,
                    strict,
                    ..Default::default()
                };
                let (map, rgb, warnings) = tessera::request::open_light_map(path, &options, up)?;
                (map, rgb, messages(warnings))
            }
            MapSource::Array(array) => {
                if channel.is_some() {
                    return Err(Error::Request(
                        "channel picks a channel of a map file; of an array, pass the plane you want".into(),
                    ));
                }
                // importance first, then colour, as a file is read
                let raster = array.raster(strict)?;
                let rgb = array.colour(strict)?;
                let mut warnings = Vec::new();
                if raster.bad_pixels > 0 || rgb.bad_samples > 0 {
                    warnings.push(MapWarning::BadPixels {
                        name: MAP_ARRAY.into(),
                        pixels: raster.bad_pixels,
                        colour_samples: Some(rgb.bad_samples),
                    });
                }
                let (map, more) =
                    tessera::request::map_from_raster(MAP_ARRAY.as_ref(), raster, up)?;
                warnings.extend(more);
                (map, rgb, messages(warnings))
            }
        };
        let options = tessera::lights::LightOptions {
            rgb: Some(&rgb),
            exponent,
            lloyd_steps: lloyd,
            seed,
            ..Default::default()
        };
        Ok((tessera::lights::lights(&map, n, &options)?, warnings))
    })?;
    let direction = points3(py, lights.iter().map(|l| l.direction).collect())?;
    let rgb = PyArray1::from_vec(py, lights.iter().flat_map(|l| l.rgb).collect())
        .reshape([lights.len(), 3])?;
    let luminance = PyArray1::from_vec(py, lights.iter().map(|l| l.luminance).collect());
    let solid_angle = PyArray1::from_vec(py, lights.iter().map(|l| l.solid_angle).collect());
    Ok((direction, rgb, luminance, solid_angle, warnings))
}

/// See `tessera.lonlat`.
#[pyfunction]
fn lonlat<'py>(py: Python<'py>, points: PyReadonlyArray2<'py, f64>) -> PyResult<Columns<'py>> {
    let points = rows::<3>(&points)?;
    let (lon, lat): (Vec<f64>, Vec<f64>) = py.detach(move || {
        points
            .par_iter()
            .map(|&p| tessera::healpix::lonlat_deg(DVec3::from_array(p)))
            .unzip()
    });
    Ok((PyArray1::from_vec(py, lon), PyArray1::from_vec(py, lat)))
}

/// See `tessera.from_lonlat`.
#[pyfunction]
fn from_lonlat<'py>(
    py: Python<'py>,
    lon: PyReadonlyArray1<'py, f64>,
    lat: PyReadonlyArray1<'py, f64>,
) -> PyResult<Bound<'py, PyArray2<f64>>> {
    let (lon, lat) = (lon.as_array().to_vec(), lat.as_array().to_vec());
    if lon.len() != lat.len() {
        return Err(PyValueError::new_err(format!(
            "{} longitudes for {} latitudes",
            lon.len(),
            lat.len()
        )));
    }
    let points: Vec<DVec3> = py.detach(move || {
        lon.par_iter()
            .zip(&lat)
            .map(|(&lon, &lat)| tessera::healpix::lonlat_to_vec(lon, lat))
            .collect()
    });
    points3(py, points)
}

/// See `tessera.metrics`: the measures of sphere points (an (n, 3) array
/// of unit vectors) or plane points ((n, 2)), `only` a comma-separated
/// list of keys.
#[pyfunction]
#[pyo3(signature = (domain, points, only, pairs_up_to, threads))]
fn metrics<'py>(
    py: Python<'py>,
    domain: &str,
    points: PyReadonlyArray2<'py, f64>,
    only: Option<String>,
    pairs_up_to: usize,
    threads: Option<usize>,
) -> PyResult<Bound<'py, PyAny>> {
    use tessera::metrics::{plane, sphere};
    let options = (only, pairs_up_to, threads);
    if domain == "sphere" {
        let points: Vec<DVec3> = rows::<3>(&points)?
            .into_iter()
            .map(DVec3::from_array)
            .collect();
        let bad = sphere::first_non_unit(&points)
            .map(|k| format!("point {k} ({}) is not a unit vector", points[k]));
        measured(py, points, bad, options, sphere::measure)
    } else {
        let points: Vec<DVec2> = rows::<2>(&points)?
            .into_iter()
            .map(DVec2::from_array)
            .collect();
        let bad = (points.iter().position(|p| !p.is_finite()))
            .map(|k| format!("point {k} ({}) is not finite", points[k]));
        measured(py, points, bad, options, plane::measure)
    }
}

/// The report of `measure` on `points` as a dict, unless they are empty or
/// `bad` says what is wrong with them; `options` are `only`,
/// `pairs_up_to` and `threads`.
fn measured<'py, P: Send + Sync, M: tessera::metrics::Measure>(
    py: Python<'py>,
    points: Vec<P>,
    bad: Option<String>,
    (only, pairs_up_to, threads): (Option<String>, usize, Option<usize>),
    measure: fn(&[P], &tessera::metrics::Options<M>) -> tessera::metrics::Report<M>,
) -> PyResult<Bound<'py, PyAny>> {
    if points.is_empty() {
        return Err(PyValueError::new_err("points: there are no points"));
    }
    if let Some(why) = bad {
        return Err(PyValueError::new_err(format!("points: {why}")));
    }
    let report = run(py, threads, move || {
        let only = only
            .as_deref()
            .map(tessera::metrics::parse_measures)
            .transpose()?;
        let options = tessera::metrics::Options {
            only,
            pairs_up_to,
            ..Default::default()
        };
        Ok(measure(&points, &options))
    })?;
    Ok(pythonize::pythonize(py, &report)?)
}

/// A lat-long map read once, to sample and to give pdfs again and again
/// (`tessera.Map`): its max pyramid, built as sampling needs it, is kept.
#[pyclass(module = "tessera._tessera", frozen)]
struct Map {
    map: EnvMap,
}

#[pymethods]
impl Map {
    /// Width in pixels.
    #[getter]
    fn width(&self) -> usize {
        self.map.width()
    }

    /// Height in pixels.
    #[getter]
    fn height(&self) -> usize {
        self.map.height()
    }

    /// The map's integral over the sphere (value x sr): the pdf's normaliser.
    #[getter]
    fn integral(&self) -> f64 {
        self.map.integral()
    }
}

/// See `tessera.Map`.
#[pyfunction]
#[pyo3(signature = (map_path, map_array, up, channel, strict))]
fn open_map<'py>(
    py: Python<'py>,
    map_path: Option<PathBuf>,
    map_array: Option<PyReadonlyArrayDyn<'py, f64>>,
    up: &str,
    channel: Option<String>,
    strict: bool,
) -> PyResult<(Map, Warnings)> {
    let up = up_axis(up)?;
    let source = map_source(map_path, map_array)?;
    run(py, None, move || {
        let (map, warnings) = read_map(&source, up, channel, strict)?;
        Ok((Map { map }, warnings))
    })
}

/// A HEALPix map read once, to sample and to give pdfs again and again
/// (`tessera.HealpixMap`): its max pyramid is kept.
#[pyclass(module = "tessera._tessera", frozen)]
struct Healpix {
    map: HealpixMap,
}

#[pymethods]
impl Healpix {
    /// The map's nside.
    #[getter]
    fn nside(&self) -> u64 {
        self.map.nside()
    }

    /// The file's COORDSYS (e.g. "G", "C"), when it has one.
    #[getter]
    fn coordsys(&self) -> Option<String> {
        self.map.coordsys().map(str::to_string)
    }
}

/// See `tessera.HealpixMap`.
#[pyfunction]
#[pyo3(signature = (path, array, nest, field, strict))]
fn open_healpix<'py>(
    py: Python<'py>,
    path: Option<PathBuf>,
    array: Option<PyReadonlyArray1<'py, f64>>,
    nest: bool,
    field: usize,
    strict: bool,
) -> PyResult<(Healpix, Warnings)> {
    let values = array.map(|a| a.as_array().to_vec());
    let scheme = if nest { Scheme::Nested } else { Scheme::Ring };
    run(py, None, move || {
        let (map, warnings) = match (path, values) {
            (Some(path), None) => tessera::request::open_healpix(&path, field, strict)?,
            (None, Some(values)) => {
                let map = HealpixMap::new(HEALPIX_ARRAY, values, scheme, strict)?;
                let warnings = tessera::request::healpix_warnings(HEALPIX_ARRAY.as_ref(), &map);
                (map, warnings)
            }
            _ => {
                return Err(Error::Request(
                    "a HEALPix map is a path or an array, one of them".into(),
                ))
            }
        };
        Ok((Healpix { map }, messages(warnings)))
    })
}

/// The sphere tiling the streams walk (it lives as long as the module).
fn tiling() -> &'static SphereTiling {
    static TILING: OnceLock<SphereTiling> = OnceLock::new();
    TILING.get_or_init(SphereTiling::default)
}

/// See `tessera.stream`: uniform sphere samples in chunks, computed from
/// their codes a block at a time (`tessera::engine::stream`).
#[pyclass(module = "tessera._tessera")]
struct Stream {
    inner: tessera::engine::Stream<'static, SphereTiling>,
    chunk: usize,
}

#[pymethods]
impl Stream {
    #[new]
    fn new(n: usize, chunk: usize) -> PyResult<Self> {
        if chunk == 0 {
            return Err(PyValueError::new_err("chunk must be at least 1"));
        }
        let inner = tessera::engine::stream(tiling(), n).ok_or_else(|| {
            PyValueError::new_err(format!(
                "invalid request: {n} samples do not fit the deepest level"
            ))
        })?;
        Ok(Stream { inner, chunk })
    }

    fn __iter__(slf: PyRef<'_, Self>) -> PyRef<'_, Self> {
        slf
    }

    fn __next__<'py>(&mut self, py: Python<'py>) -> PyResult<Option<Bound<'py, PyArray2<f64>>>> {
        let (inner, chunk) = (&mut self.inner, self.chunk);
        let points: Vec<DVec3> = py.detach(move || inner.take(chunk).map(|s| s.position).collect());
        if points.is_empty() {
            return Ok(None);
        }
        points3(py, points).map(Some)
    }

    /// Samples left to yield.
    fn __len__(&self) -> usize {
        self.inner.len()
    }
}

/// The native module.
#[pymodule]
fn _tessera(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_function(wrap_pyfunction!(sphere, m)?)?;
    m.add_function(wrap_pyfunction!(pdf, m)?)?;
    m.add_function(wrap_pyfunction!(plane, m)?)?;
    m.add_function(wrap_pyfunction!(lights, m)?)?;
    m.add_function(wrap_pyfunction!(lonlat, m)?)?;
    m.add_function(wrap_pyfunction!(from_lonlat, m)?)?;
    m.add_function(wrap_pyfunction!(metrics, m)?)?;
    m.add_function(wrap_pyfunction!(open_map, m)?)?;
    m.add_function(wrap_pyfunction!(open_healpix, m)?)?;
    m.add_class::<Stream>()?;
    m.add_class::<Map>()?;
    m.add_class::<Healpix>()?;
    m.add("__version__", env!("CARGO_PKG_VERSION"))?;
    m.add("PAIRS_UP_TO", tessera::metrics::PAIRS_UP_TO)?;
    Ok(())
}

//! `tessera sphere`: samples of the unit sphere.

use crate::common::*;
use clap::builder::PossibleValuesParser;
use clap::{Args, ValueEnum};
use std::io::Write;
use std::path::{Path, PathBuf};
use tessera::density::sphere::{Cap, Rotated};
use tessera::density::Density;
use tessera::io::points::SphereFormat;
use tessera::tiling::sphere::{SphereRegion, SphereTiling};
use tessera::{engine, Error};

#[derive(Args)]
pub(crate) struct SphereArgs {
    /// Importance: `uniform`, `cap:LON,LAT,RADIUS_DEG,CONTRAST` (degrees;
    /// density CONTRAST inside the cap, 1 outside) or
    /// `polygon:LON LAT,LON LAT,...;CONTRAST` (GeoJSON-style lon/lat
    /// polygon). Repeat it to combine regions: the largest contrast of the
    /// regions containing a point wins, 1 elsewhere.
    #[arg(long, default_value = "uniform")]
    density: Vec<String>,
    #[command(flatten)]
    request: RequestArgs,
    /// xyz (or txt, the plain text of either domain): `x y z` per line;
    /// lonlat: `lon lat` degrees; csv: header and a pdf column; geojson: a
    /// FeatureCollection of Points with a pdf property; bin: UTK binary
    /// (f64, 3 dimensions).
    #[arg(long, default_value = "xyz", value_parser = PossibleValuesParser::new(["xyz", "txt", "lonlat", "csv", "geojson", "bin"]))]
    format: String,
    /// Write only the samples of the request that fall in this cap,
    /// `LON,LAT,RADIUS_DEG`: only the tiles reaching it are visited, so a
    /// small window on a huge request costs what the window holds. The count
    /// is the expected one (exactness is a property of the whole set).
    #[arg(long, value_name = "LON,LAT,RADIUS_DEG", conflicts_with_all = ["map", "seed", "relax"])]
    within: Option<String>,
    /// Importance from a lat-long map (OpenEXR, Radiance .hdr or PNG):
    /// luminance per unit solid angle, constant per pixel. Replaces --density.
    #[arg(long, conflicts_with = "density")]
    map: Option<PathBuf>,
    /// Use this channel of the map (e.g. R, Y) instead of Rec.709 luminance.
    #[arg(long, requires = "map")]
    channel: Option<String>,
    /// The map's up axis: z (column i covers phi = atan2(y, x)) or y
    /// (directions (x, y, z) are looked up as (z, x, y)).
    #[arg(long, value_enum, default_value = "z", requires = "map")]
    up: UpAxis,
    /// Refuse maps with NaN or infinite pixels, or negative ones beyond a
    /// lossy codec's noise (5 % of the brightest pixel within two pixels,
    /// or 1 % of the median positive pixel). Default: count bad pixels,
    /// warn once and treat them as 0.
    #[arg(long, requires = "map")]
    strict: bool,
    /// Run K density-weighted Lloyd iterations on the set (about 3.5 s an
    /// iteration for 10^6 points on two cores): spacing approaches a
    /// centroidal Voronoi tessellation's, but prefixes are no longer
    /// progressive (every point moves) and the set no longer follows the
    /// density exactly, so the pdf column is the target density's.
    #[arg(long, value_name = "K", default_value_t = 0)]
    relax: usize,
    /// Print the set's separation, covering radius and mesh ratio (and a
    /// map's integral) to standard error.
    #[arg(long)]
    report: bool,
}

#[derive(Clone, Copy, ValueEnum)]
pub(crate) enum UpAxis {
    Z,
    Y,
}

pub(crate) fn sphere(args: SphereArgs) -> Result<(), Error> {
    let format: SphereFormat = args.format.parse()?;
    if let Some(path) = &args.map {
        return sphere_map(&args, path, format);
    }
    let density = tessera::density::region::parse_all(&args.density)?;
    let tiling = SphereTiling::default();
    let pdf = |p| engine::pdf(&tiling, &*density, p);
    let Some(window) = args.within.as_deref().map(Cap::window).transpose()? else {
        return match args.request.seed {
            Some(seed) => {
                let rotated = Rotated::new(&*density, seed);
                write_samples(&args, &rotated, |p| rotated.to_world(p), format, pdf)
            }
            None => write_samples(&args, &*density, |p| p, format, pdf),
        };
    };
    // a window visits only the tiles reaching it
    let near = engine::collect_within(&tiling, &*density, args.request.count as f64, &|r| {
        window.reaches(r)
    });
    let inside = near
        .iter()
        .map(|s| s.position)
        .filter(|&p| window.contains(p));
    let points: Vec<glam::DVec3> = inside.collect();
    let mut out = create(&args.request.output)?;
    tessera::io::points::write_sphere(&mut out, points, format, pdf)
        .and_then(|()| out.flush())
        .map_err(io_error(&args.request.output))
}

/// The samples of `density` (in its sampling frame, which `to_world` maps
/// to the world) written as `format`; large uniform requests stream in
/// O(depth) memory.
fn write_samples<D>(
    args: &SphereArgs,
    density: &D,
    to_world: impl Fn(glam::DVec3) -> glam::DVec3,
    format: SphereFormat,
    pdf: impl Fn(glam::DVec3) -> f64,
) -> Result<(), Error>
where
    D: Density<SphereRegion> + ?Sized,
{
    let tiling = SphereTiling::default();
    let mut out = create(&args.request.output)?;
    let written = match engine::stream(&tiling, args.request.count) {
        Some(stream)
            if density.constant().is_some()
                && args.request.count > STREAM_ABOVE
                && args.relax == 0 =>
        {
            let points = stream.map(|s| to_world(s.position));
            tessera::io::points::write_sphere(&mut out, points, format, pdf)
        }
        _ => {
            let samples = args.request.generate(&tiling, density)?;
            let points = relaxed(samples, density, args.relax)?;
            let points: Vec<glam::DVec3> = points.into_iter().map(to_world).collect();
            if args.report {
                print_report(&points);
            }
            tessera::io::points::write_sphere(&mut out, points, format, pdf)
        }
    };
    written
        .and_then(|()| out.flush())
        .map_err(io_error(&args.request.output))
}

pub(crate) fn sphere_map(
    args: &SphereArgs,
    path: &Path,
    format: SphereFormat,
) -> Result<(), Error> {
    let options = tessera::io::image::ReadOptions {
        channel: args.channel.clone(),
        strict: args.strict,
        ..Default::default()
    };
    let raster = tessera::io::image::read_raster(path, &options)?;
    let name = path.display();
    if raster.bad_pixels > 0 {
        eprintln!(
            "tessera: warning: {name}: {} negative, NaN or infinite pixel(s) treated as 0 (--strict refuses NaN, infinities and negatives beyond codec noise)",
            raster.bad_pixels
        );
    }
    let map = env_map(path, raster, args.up)?;
    let map = match args.request.seed {
        Some(seed) => map.with_seed(seed),
        None => map,
    };
    let tiling = SphereTiling::default();
    let samples = args.request.generate(&tiling, &map)?;
    let points = relaxed(samples, &map, args.relax)?;
    let points: Vec<glam::DVec3> = points.into_iter().map(|p| map.to_world(p)).collect();
    if args.report {
        eprintln!("tessera: {name}: integral {} (value x sr)", map.integral());
        print_report(&points);
    }
    let mut out = create(&args.request.output)?;
    tessera::io::points::write_sphere(&mut out, points.iter().copied(), format, |p| map.pdf(p))
        .and_then(|()| out.flush())
        .map_err(io_error(&args.request.output))
}

/// The positions of `samples` after `iterations` Lloyd iterations under
/// `density` (in its sampling frame).
fn relaxed<D>(
    samples: Vec<tessera::Sample<glam::DVec3>>,
    density: &D,
    iterations: usize,
) -> Result<Vec<glam::DVec3>, Error>
where
    D: Density<SphereRegion> + ?Sized,
{
    let mut points: Vec<glam::DVec3> = samples.into_iter().map(|s| s.position).collect();
    tessera::relax::relax(&mut points, density, iterations)?;
    Ok(points)
}

/// Separation, covering radius and mesh ratio of a point set (the O(N log N)
/// measures of `tessera::metrics::sphere`), to standard error.
pub(crate) fn print_report(points: &[glam::DVec3]) {
    use tessera::metrics::sphere::{covering_radius, mesh_ratio, separation};
    eprintln!(
        "tessera: {} points: separation {:.4}, covering radius x sqrt(N) {:.4}, mesh ratio {:.4}",
        points.len(),
        separation(points),
        covering_radius(points),
        mesh_ratio(points)
    );
}

/// The environment map of a raster read from `path`, warning when it is
/// not 2:1 (shared by `sphere --map` and `lights`).
pub(crate) fn env_map(
    path: &Path,
    raster: tessera::io::image::Raster,
    up: UpAxis,
) -> Result<tessera::density::envmap::EnvMap, Error> {
    use tessera::density::envmap::{EnvMap, Up};
    if raster.width != 2 * raster.height {
        eprintln!(
            "tessera: warning: {}: {}x{} is not a 2:1 lat-long map; using it as one",
            path.display(),
            raster.width,
            raster.height
        );
    }
    let up = match up {
        UpAxis::Z => Up::Z,
        UpAxis::Y => Up::Y,
    };
    EnvMap::new(raster, up).map_err(|e| Error::File {
        path: path.into(),
        reason: e.to_string(),
    })
}

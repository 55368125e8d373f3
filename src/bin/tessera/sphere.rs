//! `tessera sphere`: samples of the unit sphere.

use crate::common::*;
use clap::builder::PossibleValuesParser;
use clap::Args;
use std::io::Write;
use std::path::{Path, PathBuf};
use tessera::blocks::{Blocks, IterBlocks};
use tessera::density::sphere::Cap;
use tessera::io::points::SphereFormat;
use tessera::Error;

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
    #[arg(long, value_name = "LON,LAT,RADIUS_DEG", conflicts_with_all = ["map", "healpix_map", "seed", "relax"])]
    within: Option<String>,
    /// Importance from a lat-long map (OpenEXR, Radiance .hdr or PNG):
    /// luminance per unit solid angle, constant per pixel. Replaces --density.
    #[arg(long, conflicts_with = "density")]
    map: Option<PathBuf>,
    /// Importance from a HEALPix map in a FITS file (the binary table healpy
    /// writes): constant per pixel per unit solid angle; ORDERING, NSIDE
    /// (a power of two) and COORDSYS (the frame of the output) come from
    /// the header. UNSEEN pixels, and those a partial-sky file does not
    /// list, count as 0 with a warning. Replaces --density.
    #[arg(long, value_name = "FILE", conflicts_with_all = ["density", "map"])]
    healpix_map: Option<PathBuf>,
    /// The column of the --healpix-map to read, from 0 (healpy's `field`;
    /// a partial-sky map's PIXEL column is not counted).
    #[arg(long, value_name = "N", default_value_t = 0, requires = "healpix_map")]
    field: usize,
    /// Use this channel of the map (e.g. R, Y) instead of Rec.709 luminance.
    #[arg(long, requires = "map")]
    channel: Option<String>,
    /// The map's up axis: z (column i covers phi = atan2(y, x)) or y
    /// (directions (x, y, z) are looked up as (z, x, y)).
    #[arg(long, value_enum, default_value = "z", requires = "map")]
    up: UpAxis,
    /// Refuse maps with NaN or infinite pixels, or negative ones beyond a
    /// lossy codec's noise (5 % of the brightest pixel within two pixels,
    /// or 1 % of the median positive pixel; a HEALPix map: any negative
    /// value). Default: count bad pixels, warn once and treat them as 0.
    #[arg(long)]
    strict: bool,
    /// Run K density-weighted Lloyd iterations on the set (about 1.5 s an
    /// iteration for 10^6 points on two cores, 10-15 s for 10^7): spacing
    /// approaches a centroidal Voronoi tessellation's, but prefixes are no
    /// longer progressive (every point moves) and the set no longer follows
    /// the density exactly, so the pdf column is the target density's.
    /// Worth it past 983,040 uniform points, where the polar caps crowd:
    /// separation 1.44-2.03 / sqrt(N) at 10^6-10^7, and 2.70 at 10^6 after
    /// 10 iterations (docs/SPHERE_SWEEP.md).
    #[arg(long, value_name = "K", default_value_t = 0)]
    relax: usize,
    /// Print the set's separation, covering radius and mesh ratio (and a
    /// map's integral) to standard error, each angle in units of the local
    /// spacing the density asks for: times sqrt(4 pi N pdf), which is
    /// sqrt(N) for a uniform request (see `tessera metrics --help`).
    #[arg(long)]
    report: bool,
}

pub(crate) fn sphere(args: SphereArgs) -> Result<(), Error> {
    use tessera::request::{SphereDensity, SphereRequest};
    let format: SphereFormat = args.format.parse()?;
    if args.strict && args.map.is_none() && args.healpix_map.is_none() {
        return Err(Error::Request(
            "--strict applies to a map (--map or --healpix-map)".into(),
        ));
    }
    let density = match (&args.map, &args.healpix_map) {
        (Some(path), _) => SphereDensity::Map(open_map(path, &args)?),
        (None, Some(path)) => {
            let (map, warnings) = tessera::request::open_healpix(path, args.field, args.strict)?;
            for warning in warnings {
                eprintln!("tessera: warning: {}", warning.message("--strict"));
            }
            SphereDensity::Healpix(map)
        }
        (None, None) => SphereDensity::parse(&args.density)?,
    };
    let request = SphereRequest {
        count: args.request.count,
        expected: args.request.expected,
        order: args.request.order(),
        seed: args.request.seed,
        within: args.within.as_deref().map(Cap::window).transpose()?,
        relax: args.relax,
        table: args.request.table(tessera::lut::TableSystem::Sphere)?,
    };
    let pdf = density.pdf();
    let output = &args.request.output;
    let write = |points: &mut dyn Blocks<glam::DVec3>| {
        let mut out = create(output)?;
        tessera::io::points::write_sphere_blocks(&mut out, points, format, &pdf)
            .and_then(|()| out.flush())
            .map_err(io_error(output))
    };
    if args.report && request.within.is_none() {
        let points = request.points(&density)?;
        if let (SphereDensity::Map(map), Some(path)) = (&density, &args.map) {
            eprintln!(
                "tessera: {}: integral {} (value x sr)",
                path.display(),
                map.integral()
            );
        }
        if let (SphereDensity::Healpix(map), Some(path)) = (&density, &args.healpix_map) {
            use tessera::density::Density;
            let mean = Density::<tessera::tiling::sphere::SphereRegion>::mean(map);
            eprintln!(
                "tessera: {}: NSIDE {}, COORDSYS {}, mean {mean}",
                path.display(),
                map.nside(),
                map.coordsys().unwrap_or("not given")
            );
        }
        print_report(&points, &pdf);
        write(&mut IterBlocks::new(points))
    } else {
        request.with_points(&density, write)?
    }
}

/// The `--map` of a request, its warnings printed.
fn open_map(path: &Path, args: &SphereArgs) -> Result<tessera::density::envmap::EnvMap, Error> {
    let options = tessera::io::image::ReadOptions {
        channel: args.channel.clone(),
        strict: args.strict,
        ..Default::default()
    };
    let (map, warnings) = tessera::request::open_map(path, &options, args.up.into())?;
    for warning in warnings {
        eprintln!("tessera: warning: {}", warning.message("--strict"));
    }
    Ok(map)
}

/// Separation, covering radius and mesh ratio of a request's points in
/// units of the spacing its density asks for, to standard error.
fn print_report(points: &[glam::DVec3], pdf: &(dyn Fn(glam::DVec3) -> f64 + Sync)) {
    let local = tessera::metrics::sphere::local_spacing(points, pdf);
    eprintln!(
        "tessera: {} points, angles x sqrt(4 pi N pdf) (sqrt(N) for a uniform request): \
         separation {:.4}, covering radius {:.4}, mesh ratio {:.4}",
        points.len(),
        local.separation,
        local.covering_radius,
        local.mesh_ratio
    );
}

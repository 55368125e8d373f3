//! The `tessera` command line: a thin layer over the library.

use clap::{Args, Parser, Subcommand, ValueEnum};
use indicatif::{ProgressBar, ProgressStyle};
use std::io::Write;
use std::path::{Path, PathBuf};
use std::process::ExitCode;
use tessera::density::plane::Shifted;
use tessera::density::sphere::{Cap, Rotated};
use tessera::density::{Density, Region};
use tessera::engine::{Order, Sample};
use tessera::io::points::SphereFormat;
use tessera::tiling::plane::PlaneRegion;
use tessera::tiling::sphere::{SphereRegion, SphereTiling};
use tessera::tiling::TileSystem;
use tessera::{engine, Error};

#[derive(Parser)]
#[command(
    name = "tessera",
    version,
    about = "Blue-noise importance sampling with self-similar tilings"
)]
struct Cli {
    /// Worker threads (default: all cores). The output does not depend on it.
    #[arg(long, global = true)]
    threads: Option<usize>,
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand)]
enum Command {
    /// Sample the unit sphere (HEALPix faces tiled by P-pentominoes).
    Sphere(SphereArgs),
    /// Sample the unit square (Penrose, G-hexomino or P-pentomino tilings).
    Plane(PlaneArgs),
    /// Draw a tiling level and its samples as SVG.
    Tiles(TilesArgs),
    /// Build the offline tables in luts/.
    Lut {
        #[command(subcommand)]
        command: LutCommand,
    },
    /// Quality measures of a point file (text formats tessera writes, or UTK binary).
    Metrics(MetricsArgs),
    /// Render a point file as a PNG picture.
    Plot(PlotArgs),
    /// Turn a lat-long environment map into N directional lights with exact powers.
    Lights(LightsArgs),
    /// Measurements: `bench accuracy` writes ACCURACY.md and its plots.
    Bench {
        #[command(subcommand)]
        command: BenchCommand,
    },
}

#[derive(Subcommand)]
enum BenchCommand {
    /// Relative RMSE of Monte Carlo integration against time, every sampler
    /// and knob, N = 2^6 .. 2^20: writes OUT/ACCURACY.md and OUT/accuracy-*.png.
    Accuracy(AccuracyArgs),
}

#[derive(Args)]
struct AccuracyArgs {
    /// Directory for ACCURACY.md and the plots.
    #[arg(long, default_value = "docs")]
    out: PathBuf,
    /// Largest N is 2^this (from 2^6).
    #[arg(long, default_value_t = 20, value_parser = clap::value_parser!(u32).range(7..=24))]
    max_exponent: u32,
    /// Seeds per method and N.
    #[arg(long, default_value_t = 16, value_parser = clap::value_parser!(u64).range(2..))]
    seeds: u64,
}

#[derive(Clone, Copy, ValueEnum)]
enum Domain {
    /// Unit vectors `x y z`: separation, cap discrepancy, Riesz energy, covering radius.
    Sphere,
    /// Points `x y` in [0,1)^2: nearest-neighbour distances, discrepancies, spectrum.
    Plane,
}

#[derive(Args)]
struct MetricsArgs {
    /// What the points live on.
    #[arg(value_enum)]
    domain: Domain,
    /// The point file.
    file: PathBuf,
    /// Print one JSON object instead of a table.
    #[arg(long)]
    json: bool,
    /// Also print the spectrum: the angular power P(l), l = 0..64 (sphere),
    /// or the periodogram's radial average and anisotropy (plane).
    #[arg(long)]
    spectrum: bool,
    /// Write a PNG: the angular power spectrum plot (sphere), or the
    /// periodogram image beside its radial average (plane).
    #[arg(long)]
    png: Option<PathBuf>,
}

#[derive(Args)]
struct PlotArgs {
    /// What the points live on.
    #[arg(value_enum)]
    domain: Domain,
    /// The point file.
    file: PathBuf,
    /// The PNG to write.
    #[arg(long)]
    png: PathBuf,
    /// Sphere view: equirectangular (lon/lat) or orthographic (the
    /// hemisphere facing --toward).
    #[arg(long, value_enum, default_value = "equirect")]
    view: View,
    /// Orthographic view direction `LON,LAT` in degrees.
    #[arg(long, default_value = "0,0", allow_hyphen_values = true)]
    toward: String,
    /// Image width in pixels.
    #[arg(long, default_value_t = 1024)]
    size: u32,
}

#[derive(Clone, Copy, ValueEnum)]
enum View {
    Equirect,
    Ortho,
}

/// What every sampling command asks for: how many samples, and where to.
#[derive(Args)]
struct RequestArgs {
    /// Number of samples (exact unless --expected).
    #[arg(short = 'n', long = "count")]
    count: usize,
    /// Skip the exactness pass: return the natural count near N.
    #[arg(long)]
    expected: bool,
    /// Write the same samples in tile order instead of progressive order
    /// (skips the ranking sort; a prefix of the file is then not well spread).
    #[arg(long)]
    unsorted: bool,
    /// Output file, `-` for standard output.
    #[arg(short, long, default_value = "-")]
    output: PathBuf,
    /// Sample in a uniformly random frame drawn from this seed: a rotation
    /// on the sphere, a toroidal shift on the plane. Estimates averaged
    /// over seeds are unbiased; without it the output is deterministic.
    #[arg(long)]
    seed: Option<u64>,
}

impl RequestArgs {
    /// The samples this request asks for from `system` under `density`.
    fn generate<S, D>(&self, system: &S, density: &D) -> Result<Vec<Sample<S::Point>>, Error>
    where
        S: TileSystem,
        S::Region: Region<Point = S::Point>,
        D: Density<S::Region> + ?Sized,
    {
        let order = if self.unsorted {
            Order::Unsorted
        } else {
            Order::Progressive
        };
        engine::generate_ordered(system, density, self.count, !self.expected, order)
    }
}

#[derive(Args)]
struct SphereArgs {
    /// Importance: `uniform`, `cap:LON,LAT,RADIUS_DEG,CONTRAST` (degrees;
    /// density CONTRAST inside the cap, 1 outside) or
    /// `polygon:LON LAT,LON LAT,...;CONTRAST` (GeoJSON-style lon/lat
    /// polygon). Repeat it to combine regions: the largest contrast of the
    /// regions containing a point wins, 1 elsewhere.
    #[arg(long, default_value = "uniform")]
    density: Vec<String>,
    #[command(flatten)]
    request: RequestArgs,
    /// xyz: `x y z` per line; lonlat: `lon lat` degrees; csv: header and a pdf
    /// column; geojson: a FeatureCollection of Points with a pdf property;
    /// bin: UTK binary (f64, 3 dimensions).
    #[arg(long, default_value = "xyz")]
    format: String,
    /// Write only the samples of the request that fall in this cap,
    /// `LON,LAT,RADIUS_DEG`: only the tiles reaching it are visited, so a
    /// small window on a huge request costs what the window holds. The count
    /// is the expected one (exactness is a property of the whole set).
    #[arg(long, value_name = "LON,LAT,RADIUS_DEG", conflicts_with_all = ["map", "seed"])]
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
    /// Refuse maps with negative, NaN or infinite pixels (default: count
    /// them, warn once and treat them as 0).
    #[arg(long, requires = "map")]
    strict: bool,
    /// Print the set's separation, covering radius and mesh ratio (and a
    /// map's integral) to standard error.
    #[arg(long)]
    report: bool,
}

#[derive(Args)]
struct LightsArgs {
    /// The lat-long map (OpenEXR, Radiance .hdr or PNG).
    #[arg(long)]
    map: PathBuf,
    /// Number of lights (exactly this many).
    #[arg(short = 'n', long = "count")]
    count: usize,
    /// Output file, `-` for standard output.
    #[arg(short, long, default_value = "-")]
    output: PathBuf,
    /// csv: header `x,y,z,r,g,b,luminance,solid_angle`, one light per line;
    /// json: an array of objects with those keys.
    #[arg(long, default_value = "csv", value_parser = ["csv", "json"])]
    format: String,
    /// Draw the directions from this map channel (e.g. R, Y) instead of
    /// Rec.709 luminance; the `luminance` column is then its power.
    #[arg(long)]
    channel: Option<String>,
    /// The map's up axis, as for `sphere --map`.
    #[arg(long, value_enum, default_value = "z")]
    up: UpAxis,
    /// Refuse maps with negative, NaN or infinite samples.
    #[arg(long)]
    strict: bool,
    /// Draw the directions in a random frame from this seed.
    #[arg(long)]
    seed: Option<u64>,
    /// Density exponent: directions follow value^EXPONENT (default: a rule
    /// of N, 0.625 at N <= 64, 0.875 at 256-1024, 0.95 from 4096).
    #[arg(long)]
    exponent: Option<f64>,
    /// Lloyd steps after the first cut (each one more pass over the map).
    #[arg(long, default_value_t = tessera::lights::DEFAULT_LLOYD_STEPS)]
    lloyd: usize,
}

#[derive(Clone, Copy, ValueEnum)]
enum UpAxis {
    Z,
    Y,
}

#[derive(Clone, Copy, ValueEnum)]
enum System {
    Sphere,
    /// Penrose (six tile types, Fibonacci codes) on the unit square.
    Penrose,
    /// G-hexomino, 81-rep, on the unit square.
    Ghexomino,
    /// P-pentomino, 4-rep, on the unit square.
    Ppentomino,
}

impl System {
    /// The planar table of a planar system.
    fn plane(self) -> Option<tessera::lut::PlaneSystem> {
        match self {
            System::Sphere | System::Penrose => None,
            System::Ghexomino => Some(tessera::lut::PlaneSystem::Ghexomino),
            System::Ppentomino => Some(tessera::lut::PlaneSystem::Ppentomino),
        }
    }
}

#[derive(Clone, Copy, ValueEnum)]
enum PlaneKind {
    /// Penrose: six tile types, scale 1/phi per level.
    Penrose,
    /// G-hexomino, 81-rep.
    Ghexomino,
    /// P-pentomino, 4-rep.
    Ppentomino,
}

#[derive(Args)]
struct PlaneArgs {
    /// Tile system.
    #[arg(long, value_enum)]
    system: PlaneKind,
    /// Importance: `uniform`, `ramp` (proportional to x) or `image:PATH`
    /// (OpenEXR, Radiance .hdr or PNG; luminance as stored; x along the
    /// columns, y down the rows from the file's first row).
    #[arg(long, default_value = "uniform")]
    density: String,
    /// Sample the image's complement `max - value` (stippling: dark areas
    /// get the points).
    #[arg(long)]
    invert: bool,
    #[command(flatten)]
    request: RequestArgs,
    /// txt: `x y` per line; bin: UTK binary (f64, 2 dimensions); csv:
    /// `x,y,pdf` (pdf per unit area of the domain).
    #[arg(long, default_value = "txt")]
    format: String,
    /// Sample the rectangle `x0,y0,x1,y1` instead of the unit square (the
    /// density's unit square stretched over it).
    #[arg(long)]
    domain: Option<String>,
}

#[derive(Args)]
struct TilesArgs {
    /// Tile system to draw.
    #[arg(long, value_enum)]
    system: System,
    /// Subdivision level (sphere 0..=5, Penrose 0..=14, polyominoes up to
    /// 200000 tiles).
    #[arg(long, default_value_t = 0)]
    level: u32,
    /// SVG file to write.
    #[arg(long)]
    svg: PathBuf,
}

#[derive(Subcommand)]
enum LutCommand {
    /// Run the offline optimiser and write the table and its provenance.
    Build(LutBuildArgs),
    /// Find a rep-tile's production rule by exact-cover search and store it.
    Tiling(LutTilingArgs),
}

#[derive(Clone, Copy, ValueEnum)]
enum RepTile {
    /// G-hexomino `X.. / XXX / XX.`, 81-rep (scale 9).
    Ghexomino,
    /// P-pentomino `XX / XX / X.`, 4-rep (scale 2), both dissections.
    Ppentomino,
}

#[derive(Args)]
struct LutTilingArgs {
    /// Which rep-tile.
    #[arg(value_enum)]
    tile: RepTile,
    /// Directory to write `<tile>.rules.json` into.
    #[arg(long, default_value = "luts")]
    out_dir: PathBuf,
}

#[derive(Args)]
struct LutBuildArgs {
    /// Tile system whose table to build.
    #[arg(long, value_enum)]
    system: System,
    /// Seed of every random choice (the build is deterministic for a seed).
    #[arg(long, default_value_t = 1)]
    seed: u64,
    /// Lloyd iterations per level and importance bin (default: 32 for the
    /// sphere, 24 for the planar systems).
    #[arg(long)]
    iterations: Option<usize>,
    /// Importance bins per structural index (default: 12 for the sphere, at
    /// least 6; system-specific for the planar ones): more bins leave fewer
    /// holes between optimised densities, and make a larger table and a
    /// longer build.
    #[arg(long)]
    bins: Option<u16>,
    /// Directory to write `<system>.lut` and `<system>.provenance.json` into.
    #[arg(long, default_value = "luts")]
    out_dir: PathBuf,
}

fn main() -> ExitCode {
    let cli = Cli::parse();
    if let Some(threads) = cli.threads {
        if let Err(e) = rayon::ThreadPoolBuilder::new()
            .num_threads(threads.max(1))
            .build_global()
        {
            eprintln!("tessera: cannot start {threads} threads: {e}");
            return ExitCode::FAILURE;
        }
    }
    let result = match cli.command {
        Command::Sphere(args) => sphere(args),
        Command::Plane(args) => plane(args),
        Command::Tiles(args) => tiles(args),
        Command::Lut {
            command: LutCommand::Build(args),
        } => lut_build(args),
        Command::Lut {
            command: LutCommand::Tiling(args),
        } => lut_tiling(args),
        Command::Metrics(args) => metrics(args),
        Command::Plot(args) => plot(args),
        Command::Lights(args) => lights(args),
        Command::Bench {
            command: BenchCommand::Accuracy(args),
        } => bench_accuracy(args),
    };
    match result {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("tessera: {e}");
            ExitCode::FAILURE
        }
    }
}

/// Uniform requests above this many samples stream one at a time (one
/// thread, O(depth) memory) instead of being generated in parallel in memory.
const STREAM_ABOVE: usize = 1 << 24;

fn create(path: &Path) -> Result<Box<dyn Write>, Error> {
    if path == Path::new("-") {
        return Ok(Box::new(std::io::BufWriter::new(std::io::stdout().lock())));
    }
    let file = std::fs::File::create(path).map_err(|source| Error::Io {
        path: path.into(),
        source,
    })?;
    Ok(Box::new(std::io::BufWriter::new(file)))
}

fn io_error(path: &Path) -> impl Fn(std::io::Error) -> Error + '_ {
    move |source| Error::Io {
        path: path.into(),
        source,
    }
}

fn sphere(args: SphereArgs) -> Result<(), Error> {
    let format: SphereFormat = args.format.parse()?;
    if let Some(path) = &args.map {
        return sphere_map(&args, path, format);
    }
    let density = tessera::density::region::parse_all(&args.density)?;
    let tiling = SphereTiling::default();
    let pdf = |p| engine::pdf(&tiling, &*density, p);
    if let Some(seed) = args.request.seed {
        return sphere_rotated(&args, &Rotated::new(&*density, seed), format, pdf);
    }
    let window = args.within.as_deref().map(Cap::window).transpose()?;
    let mut out = create(&args.request.output)?;
    let written = match engine::stream(&tiling, args.request.count) {
        // a window visits only the tiles reaching it
        _ if window.is_some() => {
            let window = window.expect("a window");
            let near =
                engine::collect_within(&tiling, &*density, args.request.count as f64, &|r| {
                    window.reaches(r)
                });
            let inside = near
                .iter()
                .map(|s| s.position)
                .filter(|&p| window.contains(p));
            let points: Vec<glam::DVec3> = inside.collect();
            tessera::io::points::write_sphere(&mut out, points, format, pdf)
        }
        // large uniform requests stream: memory stays O(depth)
        Some(stream) if density.constant().is_some() && args.request.count > STREAM_ABOVE => {
            let points = stream.map(|s| s.position);
            tessera::io::points::write_sphere(&mut out, points, format, pdf)
        }
        _ => {
            let samples = args.request.generate(&tiling, &*density)?;
            let points: Vec<glam::DVec3> = samples.iter().map(|s| s.position).collect();
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

fn sphere_map(args: &SphereArgs, path: &Path, format: SphereFormat) -> Result<(), Error> {
    use tessera::density::envmap::{EnvMap, Up};
    let options = tessera::io::image::ReadOptions {
        channel: args.channel.clone(),
        strict: args.strict,
        ..Default::default()
    };
    let raster = tessera::io::image::read_raster(path, &options)?;
    let name = path.display();
    if raster.bad_pixels > 0 {
        eprintln!(
            "tessera: warning: {name}: {} negative, NaN or infinite pixel(s) treated as 0 (--strict refuses them)",
            raster.bad_pixels
        );
    }
    if raster.width != 2 * raster.height {
        eprintln!(
            "tessera: warning: {name}: {}x{} is not a 2:1 lat-long map; sampling it as one",
            raster.width, raster.height
        );
    }
    let up = match args.up {
        UpAxis::Z => Up::Z,
        UpAxis::Y => Up::Y,
    };
    let map = EnvMap::new(raster, up).map_err(|e| Error::File {
        path: path.into(),
        reason: e.to_string(),
    })?;
    let map = match args.request.seed {
        Some(seed) => map.with_seed(seed),
        None => map,
    };
    let tiling = SphereTiling::default();
    let samples = args.request.generate(&tiling, &map)?;
    let points: Vec<glam::DVec3> = samples.iter().map(|s| map.to_world(s.position)).collect();
    if args.report {
        eprintln!("tessera: {name}: integral {} (value x sr)", map.integral());
        print_report(&points);
    }
    let mut out = create(&args.request.output)?;
    tessera::io::points::write_sphere(&mut out, points.iter().copied(), format, |p| map.pdf(p))
        .and_then(|()| out.flush())
        .map_err(io_error(&args.request.output))
}

/// `lights`: read the map's colour and importance in one decode, warn and
/// refuse as `sphere --map` does, write the lights.
fn lights(args: LightsArgs) -> Result<(), Error> {
    use tessera::density::envmap::{EnvMap, Up};
    use tessera::lights::{read_rgb, LightOptions};
    let path = &args.map;
    let options = tessera::io::image::ReadOptions {
        channel: args.channel.clone(),
        strict: args.strict,
        ..Default::default()
    };
    let (rgb, raster) = read_rgb(path, &options)?;
    let name = path.display();
    if raster.bad_pixels > 0 || rgb.bad_samples > 0 {
        eprintln!(
            "tessera: warning: {name}: {} pixel(s) and {} colour sample(s) negative, NaN or infinite, treated as 0 (--strict refuses them)",
            raster.bad_pixels, rgb.bad_samples
        );
    }
    if raster.width != 2 * raster.height {
        eprintln!(
            "tessera: warning: {name}: {}x{} is not a 2:1 lat-long map; using it as one",
            raster.width, raster.height
        );
    }
    let up = match args.up {
        UpAxis::Z => Up::Z,
        UpAxis::Y => Up::Y,
    };
    let map = EnvMap::new(raster, up).map_err(|e| Error::File {
        path: path.into(),
        reason: e.to_string(),
    })?;
    let options = LightOptions {
        rgb: Some(&rgb),
        exponent: args.exponent,
        lloyd_steps: args.lloyd,
        seed: args.seed,
        ..Default::default()
    };
    let lights = tessera::lights::lights(&map, args.count, &options)?;
    let mut out = create(&args.output)?;
    let written = if args.format == "json" {
        tessera::lights::write_json(&mut out, &lights)
    } else {
        tessera::lights::write_csv(&mut out, &lights)
    };
    written
        .and_then(|()| out.flush())
        .map_err(io_error(&args.output))
}

/// `sphere` with `--seed`: the density sampled in a random rotated frame.
fn sphere_rotated(
    args: &SphereArgs,
    density: &Rotated<&(dyn Density<SphereRegion> + Send)>,
    format: SphereFormat,
    pdf: impl Fn(glam::DVec3) -> f64,
) -> Result<(), Error> {
    let tiling = SphereTiling::default();
    let mut out = create(&args.request.output)?;
    let written = match engine::stream(&tiling, args.request.count) {
        Some(stream) if density.constant().is_some() && args.request.count > STREAM_ABOVE => {
            let points = stream.map(|s| density.to_world(s.position));
            tessera::io::points::write_sphere(&mut out, points, format, pdf)
        }
        _ => {
            let samples = args.request.generate(&tiling, density)?;
            let points: Vec<glam::DVec3> = samples
                .iter()
                .map(|s| density.to_world(s.position))
                .collect();
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

/// Separation, covering radius and mesh ratio of a point set (the O(N log N)
/// measures of `tessera::metrics::sphere`), to standard error.
fn print_report(points: &[glam::DVec3]) {
    use tessera::metrics::sphere::{covering_radius, mesh_ratio, separation};
    eprintln!(
        "tessera: {} points: separation {:.4}, covering radius x sqrt(N) {:.4}, mesh ratio {:.4}",
        points.len(),
        separation(points),
        covering_radius(points),
        mesh_ratio(points)
    );
}

fn plane(args: PlaneArgs) -> Result<(), Error> {
    use tessera::lut::PlaneSystem;
    use tessera::tiling::plane::PlaneTiling;
    let polyomino = |system| PlaneTiling::new(tessera::lut::plane_lut(system));
    match args.system {
        PlaneKind::Penrose => {
            plane_with(&tessera::tiling::penrose::PenroseTiling::default(), &args)
        }
        PlaneKind::Ghexomino => plane_with(&polyomino(PlaneSystem::Ghexomino), &args),
        PlaneKind::Ppentomino => plane_with(&polyomino(PlaneSystem::Ppentomino), &args),
    }
}

fn plane_with<S>(tiling: &S, args: &PlaneArgs) -> Result<(), Error>
where
    S: tessera::tiling::TileSystem<
        Point = glam::DVec2,
        Region = tessera::tiling::plane::PlaneRegion,
    >,
{
    let format: tessera::io::points::PlaneFormat = args.format.parse()?;
    let density = tessera::density::plane::parse(&args.density, args.invert)?;
    let rect = args
        .domain
        .as_deref()
        .map(tessera::density::rectangle::Rectangle::parse)
        .transpose()?;
    let count = args.request.count;
    // the pdf per unit area of the domain: the density's unit square is
    // stretched over the rectangle
    let (lo, size) = rect.map_or((glam::DVec2::ZERO, glam::DVec2::ONE), |r| {
        (r.lo, r.hi - r.lo)
    });
    let pdf = |q: glam::DVec2| density.value((q - lo) / size) / (density.mean() * size.x * size.y);
    let mut out = create(&args.request.output)?;
    let written = match engine::stream(tiling, count) {
        // large uniform requests stream: memory stays O(depth)
        Some(stream)
            if density.constant().is_some()
                && rect.is_none()
                && args.request.seed.is_none()
                && count > STREAM_ABOVE =>
        {
            tessera::io::points::write_plane(&mut out, stream.map(|s| s.position), format, pdf)
        }
        _ => {
            let restricted = rect.map(|rect| rect.restrict(&*density));
            let square: &(dyn Density<PlaneRegion> + Sync) = match &restricted {
                Some(r) => r,
                None => &*density,
            };
            let in_square: Vec<glam::DVec2> = match args.request.seed {
                Some(seed) => {
                    let shifted = Shifted::new(square, seed);
                    let samples = args.request.generate(tiling, &shifted)?;
                    samples
                        .iter()
                        .map(|s| shifted.to_world(s.position))
                        .collect()
                }
                None => args
                    .request
                    .generate(tiling, square)?
                    .iter()
                    .map(|s| s.position)
                    .collect(),
            };
            let points: Vec<glam::DVec2> = match rect {
                Some(rect) => in_square
                    .into_iter()
                    .map(|p: glam::DVec2| rect.to_world(p))
                    .collect(),
                None => in_square,
            };
            tessera::io::points::write_plane(&mut out, points, format, pdf)
        }
    };
    written
        .and_then(|()| out.flush())
        .map_err(io_error(&args.request.output))
}

fn tiles(args: TilesArgs) -> Result<(), Error> {
    if let System::Penrose = args.system {
        return penrose_tiles(args);
    }
    let Some(system) = args.system.plane() else {
        return sphere_tiles(args);
    };
    let tiling = tessera::tiling::plane::PlaneTiling::new(tessera::lut::plane_lut(system));
    use tessera::tiling::TileSystem;
    let count = tiling.capacity(args.level);
    if count > 200_000.0 {
        return Err(Error::Request(format!(
            "level {} of the {} draws {count} tiles; at most 200000 are drawn",
            args.level,
            system.name()
        )));
    }
    let points: Vec<glam::DVec2> =
        engine::generate(&tiling, &tessera::density::Uniform, count as usize, true)?
            .iter()
            .map(|s| s.position)
            .collect();
    let svg = tessera::io::svg::plane_tiles(&tiling, args.level, &points);
    std::fs::write(&args.svg, svg).map_err(io_error(&args.svg))
}

fn penrose_tiles(args: TilesArgs) -> Result<(), Error> {
    let tiling = tessera::tiling::penrose::PenroseTiling::default();
    if args.level > 14 {
        return Err(Error::Request(format!(
            "level {} of the Penrose tiling draws over 200000 tiles; at most level 14 is drawn",
            args.level
        )));
    }
    let tiles = tiling.tiles(args.level);
    // the points of that level: every point tile's sample at full density
    let count = tiles.iter().filter(|t| t.kind.is_point()).count();
    let points: Vec<glam::DVec2> =
        engine::generate(&tiling, &tessera::density::Uniform, count, true)?
            .iter()
            .map(|s| s.position)
            .collect();
    let svg = tessera::io::svg::penrose_tiles(&tiling, args.level, &points);
    std::fs::write(&args.svg, svg).map_err(io_error(&args.svg))
}

fn sphere_tiles(args: TilesArgs) -> Result<(), Error> {
    if args.level > 5 {
        return Err(Error::Request(format!(
            "level {} draws {} tiles; at most level 5 is drawn",
            args.level,
            240u64 << (2 * args.level)
        )));
    }
    let tiling = SphereTiling::default();
    let count = 240usize << (2 * args.level);
    let points: Vec<glam::DVec3> =
        engine::generate(&tiling, &tessera::density::Uniform, count, true)?
            .iter()
            .map(|s| s.position)
            .collect();
    let svg = tessera::io::svg::sphere_tiles(&tiling, args.level, &points);
    std::fs::write(&args.svg, svg).map_err(io_error(&args.svg))
}

fn progress_bar() -> ProgressBar {
    let bar = ProgressBar::new(1);
    bar.set_style(
        ProgressStyle::with_template("{msg:>12} [{bar:40}] {pos}/{len} ({elapsed})")
            .expect("static template"),
    );
    bar
}

fn write_table(
    out_dir: &Path,
    name: &str,
    bytes: &[u8],
    provenance: serde_json::Value,
) -> Result<(PathBuf, PathBuf), Error> {
    std::fs::create_dir_all(out_dir).map_err(io_error(out_dir))?;
    let table = out_dir.join(format!("{name}.lut"));
    std::fs::write(&table, bytes).map_err(io_error(&table))?;
    let path = out_dir.join(format!("{name}.provenance.json"));
    std::fs::write(
        &path,
        serde_json::to_string_pretty(&provenance).expect("json") + "\n",
    )
    .map_err(io_error(&path))?;
    Ok((table, path))
}

/// An optimiser's result: the encoded table, its format version and what
/// the build measured.
type Built<R> = (Vec<u8>, u32, R);

/// Runs an optimiser under a progress bar and writes `<name>.lut` and
/// `<name>.provenance.json` (command, options, seconds, report, size).
fn build_table<O, R>(
    args: &LutBuildArgs,
    name: &str,
    options: &O,
    build: impl FnOnce(&(dyn Fn(&str, u64, u64) + Sync)) -> Result<Built<R>, Error>,
) -> Result<(), Error>
where
    O: serde::Serialize,
    R: serde::Serialize,
{
    let bar = progress_bar();
    let progress = |stage: &str, done: u64, total: u64| {
        bar.set_message(stage.to_string());
        bar.set_length(total);
        bar.set_position(done);
    };
    let started = std::time::Instant::now();
    let (bytes, version, report) = build(&progress)?;
    bar.finish();
    let seconds = started.elapsed().as_secs_f64();
    let provenance = serde_json::json!({
        "command": std::env::args().collect::<Vec<_>>().join(" "),
        "tessera_version": env!("CARGO_PKG_VERSION"),
        "format_version": version,
        "system": name,
        "options": options,
        "build_seconds": seconds,
        "report": report,
        "table_bytes": bytes.len(),
    });
    let (table, path) = write_table(&args.out_dir, name, &bytes, provenance)?;
    eprintln!(
        "wrote {} and {} in {seconds:.1} s",
        table.display(),
        path.display()
    );
    Ok(())
}

fn lut_build(args: LutBuildArgs) -> Result<(), Error> {
    if let Some(system) = args.system.plane() {
        let mut options = tessera::optimize::plane::BuildOptions::for_system(system);
        options.seed = args.seed;
        options.iterations = args.iterations.unwrap_or(options.iterations);
        options.bins = args.bins.unwrap_or(options.bins);
        return build_table(&args, system.name(), &options, |progress| {
            let (lut, report) = tessera::optimize::plane::build(system, &options, progress)?;
            Ok((lut.to_bytes(), lut.version, report))
        });
    }
    if let System::Penrose = args.system {
        let mut options = tessera::optimize::penrose::BuildOptions {
            seed: args.seed,
            ..Default::default()
        };
        options.iterations = args.iterations.unwrap_or(options.iterations);
        options.bins = args.bins.unwrap_or(options.bins);
        return build_table(&args, "penrose", &options, |progress| {
            let (lut, report) = tessera::optimize::penrose::build(&options, progress)?;
            Ok((lut.to_bytes(), lut.version, report))
        });
    }
    let mut options = tessera::optimize::sphere::BuildOptions {
        seed: args.seed,
        ..Default::default()
    };
    options.iterations = args.iterations.unwrap_or(options.iterations);
    if let Some(bins) = args.bins {
        options.bins = u8::try_from(bins).map_err(|_| {
            Error::Request(format!("--bins {bins}: the sphere table holds at most 255"))
        })?;
    }
    build_table(&args, "sphere", &options, |progress| {
        let (lut, report) = tessera::optimize::sphere::build(&options, progress)?;
        Ok((lut.to_bytes(), lut.version, report))
    })
}

/// The points of a file as unit vectors, refusing any that are not.
fn read_sphere_points(path: &Path) -> Result<Vec<glam::DVec3>, Error> {
    let rows = tessera::io::points::read_points(path, 3)?;
    let points: Vec<glam::DVec3> = rows
        .iter()
        .map(|r| glam::DVec3::new(r[0], r[1], r[2]))
        .collect();
    match points
        .iter()
        .position(|p| !p.is_finite() || (p.length() - 1.0).abs() > 1e-6)
    {
        Some(bad) => Err(Error::File {
            path: path.into(),
            reason: format!("point {} is not a unit vector", bad + 1),
        }),
        None => Ok(points),
    }
}

fn read_plane_points(path: &Path) -> Result<Vec<glam::DVec2>, Error> {
    let rows = tessera::io::points::read_points(path, 2)?;
    Ok(rows.iter().map(|r| glam::DVec2::new(r[0], r[1])).collect())
}

fn save_png<P, C>(img: &image::ImageBuffer<P, C>, path: &Path) -> Result<(), Error>
where
    P: image::PixelWithColorType,
    [P::Subpixel]: image::EncodableLayout,
    C: std::ops::Deref<Target = [P::Subpixel]>,
{
    img.save_with_format(path, image::ImageFormat::Png)
        .map_err(|e| Error::File {
            path: path.into(),
            reason: format!("cannot write PNG: {e}"),
        })
}

/// Angular power spectrum degrees printed and plotted by `metrics sphere`.
const SPECTRUM_L_MAX: usize = 64;

fn metrics(args: MetricsArgs) -> Result<(), Error> {
    use tessera::io::plot;
    let report = match args.domain {
        Domain::Sphere => {
            let points = read_sphere_points(&args.file)?;
            let mut report = serde_json::to_value(tessera::metrics::sphere_report(&points));
            if args.spectrum || args.png.is_some() {
                let power = tessera::metrics::sphere::angular_power(&points, SPECTRUM_L_MAX);
                if let Some(png) = &args.png {
                    save_png(&plot::angular_power_figure(&power), png)?;
                }
                if let (true, Ok(serde_json::Value::Object(map))) = (args.spectrum, &mut report) {
                    map.insert("angular_power".into(), power.into());
                }
            }
            report
        }
        Domain::Plane => {
            let points = read_plane_points(&args.file)?;
            let mut report = serde_json::to_value(tessera::metrics::plane_report(&points));
            if args.spectrum || args.png.is_some() {
                let spectrum = tessera::metrics::plane::PlaneSpectrum::new(&points);
                if let Some(png) = &args.png {
                    save_png(&plot::plane_spectrum_figure(&spectrum), png)?;
                }
                if let (true, Ok(serde_json::Value::Object(map))) = (args.spectrum, &mut report) {
                    map.insert("radial_average".into(), spectrum.radial_average.into());
                    map.insert("anisotropy_db".into(), spectrum.anisotropy.into());
                }
            }
            report
        }
    }
    .expect("reports serialise");
    if args.json {
        println!("{report}");
    } else if let Some(fields) = report.as_object() {
        for (key, value) in fields {
            println!("{key:>24} {value}");
        }
    }
    Ok(())
}

fn plot(args: PlotArgs) -> Result<(), Error> {
    use tessera::io::plot;
    match (args.domain, args.view) {
        (Domain::Plane, _) => {
            let points = read_plane_points(&args.file)?;
            save_png(&plot::stipple(&points, args.size), &args.png)
        }
        (Domain::Sphere, View::Equirect) => {
            let points = read_sphere_points(&args.file)?;
            save_png(&plot::equirectangular(&points, args.size), &args.png)
        }
        (Domain::Sphere, View::Ortho) => {
            let points = read_sphere_points(&args.file)?;
            let bad = || {
                Error::Request(format!(
                    "--toward '{}': expected LON,LAT in degrees",
                    args.toward
                ))
            };
            let (lon, lat) = args.toward.split_once(',').ok_or_else(bad)?;
            let parse = |s: &str| s.trim().parse::<f64>().ok().filter(|v| v.is_finite());
            let (lon, lat) = parse(lon).zip(parse(lat)).ok_or_else(bad)?;
            let toward = tessera::density::sphere::lonlat_to_vec(lon, lat);
            save_png(&plot::orthographic(&points, args.size, toward), &args.png)
        }
    }
}

fn bench_accuracy(args: AccuracyArgs) -> Result<(), Error> {
    let config = tessera::accuracy::Config {
        exponents: (6..=args.max_exponent).collect(),
        seeds: args.seeds,
    };
    let results = tessera::accuracy::run(&config);
    let command = format!(
        "tessera bench accuracy --out {} --max-exponent {} --seeds {}",
        args.out.display(),
        args.max_exponent,
        args.seeds
    );
    let files = results.write(&args.out, &command)?;
    eprintln!(
        "wrote {} files into {} in {:.0} s",
        files.len(),
        args.out.display(),
        results.wall_seconds
    );
    Ok(())
}

fn lut_tiling(args: LutTilingArgs) -> Result<(), Error> {
    use tessera::tiling::polyomino::{Rule, Shape};
    let (name, shape, scale, limit) = match args.tile {
        RepTile::Ghexomino => ("ghexomino", Shape::g_hexomino(), 9, 1),
        RepTile::Ppentomino => ("ppentomino", Shape::p_pentomino(), 2, usize::MAX),
    };
    let started = std::time::Instant::now();
    let rules = Rule::dissections(&shape, scale, limit);
    let seconds = started.elapsed().as_secs_f64();
    if rules.is_empty() || !rules.iter().all(|r| r.tiles_parent(&shape)) {
        return Err(Error::Request(format!("no dissection of the {name} found")));
    }
    let file = serde_json::json!({
        "provenance": {
            "command": format!("tessera lut tiling {name}"),
            "search": "exact cover (Algorithm X, fewest-options cell first, natural option order)",
            "seconds": seconds,
            "checked": "children cover the enlarged parent cell by cell",
        },
        "shape": shape,
        "rules": rules,
    });
    std::fs::create_dir_all(&args.out_dir).map_err(io_error(&args.out_dir))?;
    let path = args.out_dir.join(format!("{name}.rules.json"));
    std::fs::write(&path, serde_json::to_string(&file).expect("json") + "\n")
        .map_err(io_error(&path))?;
    eprintln!(
        "wrote {} ({} rule(s), {seconds:.1} s)",
        path.display(),
        rules.len()
    );
    Ok(())
}

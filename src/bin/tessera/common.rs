//! Helpers the subcommands share: the request arguments, output files, point files and pictures.

use clap::{Args, ValueEnum};
use indicatif::{ProgressBar, ProgressStyle};
use std::io::Write;
use std::path::{Path, PathBuf};
use tessera::engine::Order;
use tessera::Error;

/// What every sampling command asks for: how many samples, and where to.
#[derive(Args)]
pub(crate) struct RequestArgs {
    /// Number of samples (exact unless --expected).
    #[arg(short = 'n', long = "count", allow_hyphen_values = true)]
    pub(crate) count: usize,
    /// Skip the exactness pass: return the natural count near N.
    #[arg(long)]
    pub(crate) expected: bool,
    /// Write the same samples in tile order instead of progressive order
    /// (skips the ranking sort; a prefix of the file is then not well spread).
    #[arg(long, conflicts_with = "farthest_first")]
    pub(crate) unsorted: bool,
    /// Write the same samples farthest first: each is the one farthest
    /// (in local spacings) from those before it, so every prefix of the
    /// file is evenly spread, whatever its length (a sequential pass after
    /// sampling: 1.2-2.2 µs a sample at 2·10^5-10^6).
    #[arg(long)]
    pub(crate) farthest_first: bool,
    /// Output file, `-` for standard output.
    #[arg(short, long, default_value = "-")]
    pub(crate) output: PathBuf,
    /// Sample in a uniformly random frame drawn from this seed: a rotation
    /// on the sphere, a toroidal shift on the plane. Estimates averaged
    /// over seeds are unbiased; without it the output is deterministic.
    #[arg(long)]
    pub(crate) seed: Option<u64>,
    /// Sample with this table (a `.lut` file `tessera lut build` wrote)
    /// instead of the one built in: a rebuilt table without recompiling.
    #[arg(long, value_name = "FILE")]
    pub(crate) table: Option<PathBuf>,
}

impl RequestArgs {
    /// The `--table` file, read as a table of `system`.
    pub(crate) fn table(
        &self,
        system: tessera::lut::TableSystem,
    ) -> Result<Option<tessera::lut::Table>, Error> {
        self.table
            .as_deref()
            .map(|path| tessera::lut::Table::open(path, system))
            .transpose()
    }

    /// `--unsorted` or `--farthest-first` as an output order.
    pub(crate) fn order(&self) -> Order {
        match (self.unsorted, self.farthest_first) {
            (true, _) => Order::Unsorted,
            (_, true) => Order::FarthestFirst,
            _ => Order::Progressive,
        }
    }
}

#[derive(Clone, Copy, ValueEnum)]
pub(crate) enum System {
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
    pub(crate) fn plane(self) -> Option<tessera::lut::PlaneSystem> {
        match self {
            System::Sphere | System::Penrose => None,
            System::Ghexomino => Some(tessera::lut::PlaneSystem::Ghexomino),
            System::Ppentomino => Some(tessera::lut::PlaneSystem::Ppentomino),
        }
    }
}

#[derive(Clone, Copy, ValueEnum)]
pub(crate) enum Domain {
    /// Points on the unit sphere: any sphere format tessera writes (`x y z`, lonlat, csv, geojson, bin).
    Sphere,
    /// Points `x y` in the unit square (`plot` draws another rectangle with
    /// `--domain`): any plane format tessera writes (xy, csv, bin).
    Plane,
}

/// A map's up axis (`--up`).
#[derive(Clone, Copy, ValueEnum)]
pub(crate) enum UpAxis {
    Z,
    Y,
}

impl From<UpAxis> for tessera::density::envmap::Up {
    fn from(up: UpAxis) -> Self {
        match up {
            UpAxis::Z => tessera::density::envmap::Up::Z,
            UpAxis::Y => tessera::density::envmap::Up::Y,
        }
    }
}

pub(crate) fn create(path: &Path) -> Result<Box<dyn Write>, Error> {
    if path == Path::new("-") {
        return Ok(Box::new(std::io::BufWriter::new(std::io::stdout().lock())));
    }
    let file = std::fs::File::create(path).map_err(|source| Error::Io {
        path: path.into(),
        source,
    })?;
    Ok(Box::new(std::io::BufWriter::new(file)))
}

pub(crate) fn io_error(path: &Path) -> impl Fn(std::io::Error) -> Error + '_ {
    move |source| Error::Io {
        path: path.into(),
        source,
    }
}

/// The points of a file as unit vectors, refusing any that are not.
pub(crate) fn read_sphere_points(path: &Path) -> Result<Vec<glam::DVec3>, Error> {
    let rows = tessera::io::points::read_points(path, 3)?;
    let points: Vec<glam::DVec3> = rows
        .iter()
        .map(|r| glam::DVec3::new(r[0], r[1], r[2]))
        .collect();
    match tessera::metrics::sphere::first_non_unit(&points) {
        Some(bad) => Err(Error::File {
            path: path.into(),
            reason: format!("point {} is not a unit vector", bad + 1),
        }),
        None => Ok(points),
    }
}

pub(crate) fn read_plane_points(path: &Path) -> Result<Vec<glam::DVec2>, Error> {
    let rows = tessera::io::points::read_points(path, 2)?;
    Ok(rows.iter().map(|r| glam::DVec2::new(r[0], r[1])).collect())
}

pub(crate) fn save_png<P, C>(img: &image::ImageBuffer<P, C>, path: &Path) -> Result<(), Error>
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

/// A progress bar on standard error (hidden when it is not a terminal).
pub(crate) fn progress_bar() -> ProgressBar {
    let bar = ProgressBar::new(1);
    bar.set_style(
        ProgressStyle::with_template("{msg:>16} [{bar:40}] {percent:>3}% ({elapsed}, {eta} left)")
            .expect("static template"),
    );
    bar
}

/// The library's progress callback (stage, done, total) shown on `bar`.
pub(crate) fn progress_to(bar: &ProgressBar) -> impl Fn(&str, u64, u64) + Sync + '_ {
    move |stage: &str, done: u64, total: u64| {
        bar.set_message(stage.to_string());
        bar.set_length(total);
        bar.set_position(done);
    }
}

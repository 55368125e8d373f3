//! `tessera plane`: samples of the unit square or a rectangle.

use crate::common::*;
use clap::builder::PossibleValuesParser;
use clap::{Args, ValueEnum};
use std::io::Write;
use tessera::density::plane::Shifted;
use tessera::density::Density;
use tessera::tiling::plane::PlaneRegion;
use tessera::{engine, Error};

#[derive(Clone, Copy, ValueEnum)]
pub(crate) enum PlaneKind {
    /// Penrose: six tile types, scale 1/phi per level.
    Penrose,
    /// G-hexomino, 81-rep.
    Ghexomino,
    /// P-pentomino, 4-rep.
    Ppentomino,
}

#[derive(Args)]
pub(crate) struct PlaneArgs {
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
    /// xy (or txt, the plain text of either domain): `x y` per line; bin:
    /// UTK binary (f64, 2 dimensions); csv: `x,y,pdf` (pdf per unit area of
    /// the domain).
    #[arg(long, default_value = "xy", value_parser = PossibleValuesParser::new(["xy", "txt", "bin", "csv"]))]
    format: String,
    /// Sample the rectangle `x0,y0,x1,y1` instead of the unit square (the
    /// density's unit square stretched over it).
    #[arg(long)]
    domain: Option<String>,
}

pub(crate) fn plane(args: PlaneArgs) -> Result<(), Error> {
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

pub(crate) fn plane_with<S>(tiling: &S, args: &PlaneArgs) -> Result<(), Error>
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

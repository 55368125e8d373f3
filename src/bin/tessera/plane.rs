//! `tessera plane`: samples of the unit square or a rectangle.

use crate::common::*;
use clap::builder::PossibleValuesParser;
use clap::{Args, ValueEnum};
use std::io::Write;
use tessera::Error;

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
    #[arg(long, value_name = "X0,Y0,X1,Y1", allow_hyphen_values = true)]
    domain: Option<String>,
}

pub(crate) fn plane(args: PlaneArgs) -> Result<(), Error> {
    use tessera::request::{PlaneKind as Kind, PlaneRequest};
    let format: tessera::io::points::PlaneFormat = args.format.parse()?;
    let density = tessera::density::plane::parse(&args.density, args.invert)?;
    let system = match args.system {
        PlaneKind::Penrose => Kind::Penrose,
        PlaneKind::Ghexomino => Kind::Ghexomino,
        PlaneKind::Ppentomino => Kind::Ppentomino,
    };
    let request = PlaneRequest {
        system,
        count: args.request.count,
        expected: args.request.expected,
        order: args.request.order(),
        seed: args.request.seed,
        domain: args
            .domain
            .as_deref()
            .map(tessera::density::rectangle::Rectangle::parse)
            .transpose()?,
        table: args.request.table(system.table_system())?,
    };
    let pdf = request.pdf(&*density);
    let output = &args.request.output;
    request.with_points(&*density, |points| {
        let mut out = create(output)?;
        tessera::io::points::write_plane_blocks(&mut out, points, format, &pdf)
            .and_then(|()| out.flush())
            .map_err(io_error(output))
    })?
}

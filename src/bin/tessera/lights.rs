//! `tessera lights`: an environment map turned into N directional lights.

use crate::common::*;
use clap::Args;
use std::io::Write;
use std::path::PathBuf;
use tessera::Error;

#[derive(Args)]
pub(crate) struct LightsArgs {
    /// The lat-long map (OpenEXR, Radiance .hdr or PNG).
    #[arg(long)]
    map: PathBuf,
    /// Number of lights (exactly this many).
    #[arg(short = 'n', long = "count", allow_hyphen_values = true)]
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
    /// of N, 0.2 at N <= 64 rising to 0.875 at 256-1024 and 0.95 from 4096).
    #[arg(long)]
    exponent: Option<f64>,
    /// Lloyd steps after the first cut, each one more pass over the map
    /// (default: a rule of N, 10 at N <= 128, 20 at 256-1024, 4 from 4096).
    #[arg(long)]
    lloyd: Option<usize>,
    /// Draw the directions with this sphere table (a `.lut` file `tessera
    /// lut build --system sphere` wrote) instead of the one built in: a
    /// rebuilt table without recompiling.
    #[arg(long, value_name = "FILE")]
    table: Option<PathBuf>,
}

/// `lights`: read the map's colour and importance in one decode, warn and
/// refuse as `sphere --map` does, write the lights.
pub(crate) fn lights(args: LightsArgs) -> Result<(), Error> {
    use tessera::lights::LightOptions;
    use tessera::lut::{Table, TableSystem};
    let options = tessera::io::image::ReadOptions {
        channel: args.channel.clone(),
        strict: args.strict,
        ..Default::default()
    };
    // the table first: a bad one is refused before the map is decoded
    let table = match &args.table {
        Some(path) => match Table::open(path, TableSystem::Sphere)? {
            Table::Sphere(lut) => Some(lut),
            _ => unreachable!("Table::open returns a table of the system asked for"),
        },
        None => None,
    };
    let (map, rgb, warnings) =
        tessera::request::open_light_map(&args.map, &options, args.up.into())?;
    for warning in warnings {
        eprintln!("tessera: warning: {}", warning.message("--strict"));
    }
    let options = LightOptions {
        rgb: Some(&rgb),
        exponent: args.exponent,
        lloyd_steps: args.lloyd,
        seed: args.seed,
        table: table.as_deref(),
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

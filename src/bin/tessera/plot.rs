//! `tessera plot`: a point file as a picture.

use crate::common::*;
use clap::{Args, ValueEnum};
use std::path::PathBuf;
use tessera::Error;

#[derive(Args)]
pub(crate) struct PlotArgs {
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
pub(crate) enum View {
    Equirect,
    Ortho,
}

pub(crate) fn plot(args: PlotArgs) -> Result<(), Error> {
    use tessera::plot;
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

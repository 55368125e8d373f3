//! `tessera plot`: a point file as a picture.

use crate::common::*;
use clap::{Args, ValueEnum};
use std::path::PathBuf;
use tessera::density::rectangle::Rectangle;
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
    /// Sphere view: equirectangular (the lat-long map convention: phi =
    /// atan2(y, x) from 0 at the left edge, +z at the top) or orthographic
    /// (the hemisphere facing --toward).
    #[arg(long, value_enum, default_value = "equirect")]
    view: View,
    /// Orthographic view direction `LON,LAT` in degrees.
    #[arg(long, default_value = "0,0", allow_hyphen_values = true)]
    toward: String,
    /// Image width in pixels (a plane's height follows its --domain).
    #[arg(long, default_value_t = 1024, value_parser = clap::value_parser!(u32).range(16..=i64::from(tessera::plot::MAX_STIPPLE_SIDE)))]
    size: u32,
    /// Plane: the rectangle `x0,y0,x1,y1` to draw, as given to `tessera
    /// plane --domain` (default the unit square). y points down, as in
    /// images, so the stipple of an image density comes out upright; a
    /// point outside the rectangle is an error.
    #[arg(
        long = "domain",
        value_name = "X0,Y0,X1,Y1",
        allow_hyphen_values = true
    )]
    rectangle: Option<String>,
    /// Sphere, equirect view: draw the points in red over this lat-long
    /// map (OpenEXR, Radiance .hdr or PNG), tone-mapped, in the map's own
    /// convention (column 0 at phi = atan2(y, x) = 0), as `tessera sphere
    /// --map` reads it.
    #[arg(long, value_name = "MAP")]
    over: Option<PathBuf>,
    /// The --over map's up axis, as given to `tessera sphere --up`.
    #[arg(long, value_enum, default_value = "z", requires = "over")]
    up: UpAxis,
}

#[derive(Clone, Copy, ValueEnum)]
pub(crate) enum View {
    Equirect,
    Ortho,
}

pub(crate) fn plot(args: PlotArgs) -> Result<(), Error> {
    use tessera::plot;
    match (args.domain, args.view) {
        (Domain::Plane, _) if args.over.is_some() => Err(Error::Request(
            "--over draws sphere points over a lat-long map; it does not apply to plane".into(),
        )),
        (Domain::Sphere, View::Ortho) if args.over.is_some() => Err(Error::Request(
            "--over applies to --view equirect (the map's own projection)".into(),
        )),
        (Domain::Sphere, _) if args.rectangle.is_some() => Err(Error::Request(
            "--domain is a plane's rectangle; it does not apply to sphere".into(),
        )),
        (Domain::Plane, _) => {
            let points = read_plane_points(&args.file)?;
            let domain = match &args.rectangle {
                Some(spec) => Rectangle::parse(spec)?,
                None => Rectangle::UNIT,
            };
            let img = plot::stipple(&points, domain, args.size).map_err(|e| match e {
                Error::Request(reason) => Error::File {
                    path: args.file.clone(),
                    reason,
                },
                other => other,
            })?;
            save_png(&img, &args.png)
        }
        (Domain::Sphere, View::Equirect) => {
            let points = read_sphere_points(&args.file)?;
            match &args.over {
                Some(map) => {
                    let (rgb, _) = tessera::lights::read_rgb(map, &Default::default())?;
                    let img = plot::over_map(&points, &rgb, args.up.into(), args.size);
                    save_png(&img, &args.png)
                }
                None => save_png(&plot::equirectangular(&points, args.size), &args.png),
            }
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

//! `tessera metrics`: quality measures of a point file.

use crate::common::*;
use clap::Args;
use std::path::PathBuf;
use tessera::Error;

#[derive(Args)]
pub(crate) struct MetricsArgs {
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
    /// Compute the O(N²) measures (sphere: cap discrepancy and energy;
    /// plane: both discrepancies and the low-frequency power) only up to
    /// this many points; beyond it they are null and the rest costs
    /// O(N log N) (10^6 sphere points: about 5 s on two cores).
    #[arg(long, value_name = "N", default_value_t = 100_000)]
    pairs_up_to: usize,
}

/// Angular power spectrum degrees printed and plotted by `metrics sphere`.
pub(crate) const SPECTRUM_L_MAX: usize = 64;

pub(crate) fn metrics(args: MetricsArgs) -> Result<(), Error> {
    use tessera::plot;
    let report = match args.domain {
        Domain::Sphere => {
            let points = read_sphere_points(&args.file)?;
            let mut report = serde_json::to_value(tessera::metrics::sphere::sphere_report_up_to(
                &points,
                args.pairs_up_to,
            ));
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
            let mut report = serde_json::to_value(tessera::metrics::plane::plane_report_up_to(
                &points,
                args.pairs_up_to,
            ));
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
    let count = report.get("n").and_then(|n| n.as_u64()).unwrap_or(0);
    if count > args.pairs_up_to as u64 {
        eprintln!(
            "tessera: {}: {count} points: the O(N^2) measures are skipped (null) above --pairs-up-to {}",
            args.file.display(),
            args.pairs_up_to
        );
    }
    if args.json {
        println!("{report}");
    } else if let Some(fields) = report.as_object() {
        for (key, value) in fields {
            println!("{key:>24} {value}");
        }
    }
    Ok(())
}

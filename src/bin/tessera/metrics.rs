//! `tessera metrics`: quality measures of a point file.

use crate::common::*;
use clap::Args;
use std::path::PathBuf;
use tessera::metrics::{parse_measures, plane, sphere, Measure, Options, Report};
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
    /// Compute only these measures, a comma-separated list of the keys
    /// below (whatever N: --pairs-up-to does not apply to them).
    #[arg(long, value_name = "KEY,...")]
    only: Option<String>,
    /// Also print the spectrum: `angular_power`, P(l) for l = 0..3 sqrt(N)
    /// (sphere; at least 64, at most 1024, and lower where
    /// N (l + 1)(l + 2) / 2 would pass 3x10^10 steps, above about
    /// N = 82000), or `radial_power`
    /// and `anisotropy_db` per ring (plane; out to twice the blue-noise
    /// peak, of a corner window holding 20000 points above that many).
    #[arg(long)]
    spectrum: bool,
    /// Write a PNG: the angular power spectrum plot (sphere), or the
    /// periodogram image beside its radial average (plane).
    #[arg(long)]
    png: Option<PathBuf>,
    /// Compute the O(N²) measures (sphere: cap discrepancy and energy;
    /// plane: both discrepancies and the low-frequency power) only up to
    /// this many points unless named in --only; beyond it they are null and
    /// the rest costs O(N log N).
    #[arg(long, value_name = "N", default_value_t = tessera::metrics::PAIRS_UP_TO)]
    pairs_up_to: usize,
}

/// The long help's list of every key `metrics` prints, from the library's
/// own descriptions.
pub(crate) fn measures_help() -> String {
    fn section<M: Measure>(title: &str) -> String {
        let mut s = format!("{title}:\n");
        for m in M::ALL {
            s += &format!("  {}\n      {}\n", m.key(), m.meaning());
        }
        s
    }
    format!(
        "Keys (JSON keys and table labels; `n` is the number of points; null: \
         not computed, see --pairs-up-to):\n\n{}\n{}\n{}",
        section::<tessera::metrics::SphereMeasure>("metrics sphere"),
        section::<tessera::metrics::PlaneMeasure>("metrics plane"),
        "With --spectrum:\n  \
         angular_power (sphere)\n      \
         P(l) = (1/N) sum over all ordered pairs (i = j included) of \
         P_l(x_i . x_j), Legendre polynomials, for l = 0 to 3 sqrt(N) (at \
         least 64; at most 1024, and capped where N (l + 1)(l + 2) / 2 passes \
         3x10^10 recurrence steps, above about N = 82000, with a note on \
         stderr): P(0) = N, 1 in \
         expectation for independent uniform points, low below the blue-noise \
         peak (near l = 2 sqrt(N)). Computed per point by the addition \
         theorem, O(N l^2).\n  \
         radial_power (plane)\n      \
         The periodogram |sum_j exp(-2 pi i k.x_j)|^2 / N averaged over each \
         ring of integer radius |k| = 0, 1, ...: white noise 1.\n  \
         anisotropy_db (plane)\n      \
         10 log10(variance / mean^2) of each ring's periodogram values: \
         isotropic noise about 0 dB, larger when the spectrum has a \
         direction.\n"
    )
}

pub(crate) fn metrics(args: MetricsArgs) -> Result<(), Error> {
    use tessera::plot;
    let bar = progress_bar();
    let progress = progress_to(&bar);
    // the spectrum is computed for --spectrum or --png, printed for --spectrum
    let spectral = args.spectrum || args.png.is_some();
    let (report, spectrum) = match args.domain {
        Domain::Sphere => {
            let points = read_sphere_points(&args.file)?;
            let report = Printed::new(&sphere::measure(&points, &options(&args, &progress)?));
            let mut spectrum = Vec::new();
            if spectral {
                let l_max = sphere::spectrum_degree(points.len());
                let wanted = (3.0 * (points.len() as f64).sqrt()).ceil() as usize;
                if l_max < wanted {
                    eprintln!(
                        "tessera: {}: the spectrum stops at l = {l_max}, below 3 sqrt(N) = {wanted} (its cost is capped at {:e} steps and l <= {})",
                        args.file.display(),
                        sphere::SPECTRUM_STEPS as f64,
                        sphere::SPECTRUM_L_CAP
                    );
                }
                let power = sphere::angular_power_with(&points, l_max, &progress);
                save_figure(&args, || plot::angular_power_figure(&power))?;
                spectrum.push(("angular_power", power));
            }
            (report, spectrum)
        }
        Domain::Plane => {
            let points = read_plane_points(&args.file)?;
            if let Some(i) = plane::first_outside_unit_square(&points) {
                return Err(Error::File {
                    path: args.file.clone(),
                    reason: format!(
                        "point {} ({}, {}) lies outside the unit square, where the plane measures are defined",
                        i + 1,
                        points[i].x,
                        points[i].y
                    ),
                });
            }
            let report = Printed::new(&plane::measure(&points, &options(&args, &progress)?));
            let mut spectrum = Vec::new();
            if spectral {
                let s = plane::PlaneSpectrum::with_progress(&points, &progress);
                if s.window < 1.0 {
                    eprintln!(
                        "tessera: {}: the spectrum is that of the {} points in [0, {:.4})^2, rescaled to the unit square (above {} points)",
                        args.file.display(),
                        s.points,
                        s.window,
                        plane::SPECTRUM_POINTS
                    );
                }
                save_figure(&args, || plot::plane_spectrum_figure(&s))?;
                spectrum.push(("radial_power", s.radial_power));
                spectrum.push(("anisotropy_db", s.anisotropy_db));
            }
            (report, spectrum)
        }
    };
    bar.finish_and_clear();
    if !report.skipped.is_empty() {
        eprintln!(
            "tessera: {}: {} points: {} skipped (null) above --pairs-up-to {} (name a key in --only to compute it anyway)",
            args.file.display(),
            report.n,
            report.skipped.join(", "),
            args.pairs_up_to
        );
    }
    let spectrum = if args.spectrum { spectrum } else { Vec::new() };
    if args.json {
        // written by hand to keep the report's order (a serde_json map sorts)
        let mut fields = vec![format!("\"n\":{}", report.n)];
        fields.extend(
            report
                .values
                .iter()
                .map(|(key, value)| format!("{}:{}", json(key), json(&value.unwrap_or(f64::NAN)))),
        );
        fields.extend(
            spectrum
                .iter()
                .map(|(key, values)| format!("{}:{}", json(key), json(values))),
        );
        println!("{{{}}}", fields.join(","));
        return Ok(());
    }
    let width = report
        .values
        .iter()
        .map(|(k, _)| k.len())
        .max()
        .unwrap_or(1);
    println!("{:>width$} {}", "n", report.n);
    for (key, value) in &report.values {
        match value {
            Some(v) => println!("{key:>width$} {v}"),
            None => println!("{key:>width$} null"),
        }
    }
    if let Some(rows) = spectrum.iter().map(|(_, v)| v.len()).max() {
        // one row per degree (sphere) or ring (plane)
        let index = if matches!(args.domain, Domain::Sphere) {
            "l"
        } else {
            "ring"
        };
        println!();
        print!("{index:>6}");
        spectrum.iter().for_each(|(k, _)| print!(" {k:>24}"));
        println!();
        for i in 0..rows {
            print!("{i:>6}");
            spectrum.iter().for_each(|(_, v)| print!(" {:>24}", v[i]));
            println!();
        }
    }
    Ok(())
}

/// Writes the figure `draw` makes to `--png`, if asked for.
fn save_figure(args: &MetricsArgs, draw: impl FnOnce() -> image::RgbImage) -> Result<(), Error> {
    match &args.png {
        Some(png) => save_png(&draw(), png),
        None => Ok(()),
    }
}

/// `value` as JSON (non-finite numbers as null).
fn json<T: serde::Serialize + ?Sized>(value: &T) -> String {
    serde_json::to_string(value).expect("strings and numbers serialise")
}

/// The measures asked for on the command line.
fn options<'a, M: Measure>(
    args: &MetricsArgs,
    progress: &'a (dyn Fn(&str, u64, u64) + Sync),
) -> Result<Options<'a, M>, Error> {
    let only = args
        .only
        .as_deref()
        .map(parse_measures)
        .transpose()
        .map_err(|e| match e {
            Error::Request(why) => Error::Request(format!("--only: {why}")),
            e => e,
        })?;
    Ok(Options {
        only,
        pairs_up_to: args.pairs_up_to,
        progress,
    })
}

/// A report as printed: keys in report order, values (null when skipped
/// for cost).
struct Printed {
    n: usize,
    values: Vec<(&'static str, Option<f64>)>,
    skipped: Vec<&'static str>,
}

impl Printed {
    fn new<M: Measure>(report: &Report<M>) -> Self {
        Printed {
            n: report.n(),
            values: report
                .entries()
                .iter()
                .map(|(m, v)| (m.key(), *v))
                .collect(),
            skipped: report.skipped().map(Measure::key).collect(),
        }
    }
}

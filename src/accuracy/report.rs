//! `ACCURACY.md` and its plots from [`Results`].

use super::{Results, Row};
use crate::plot::{line_plot, Axes, Labels, Marker, Series, PALETTE, PALETTE_NAMES};
use crate::Error;
use std::fmt::Write as _;
use std::path::{Path, PathBuf};

/// Slope at or below which the tile samplers' MSE must fall on smooth integrands.
const SLOPE_GOAL: f64 = -1.4;

/// Distinct values of `key` over `rows`, in first-seen order.
fn distinct<'r>(rows: impl Iterator<Item = &'r Row>, key: impl Fn(&Row) -> &str) -> Vec<String> {
    let mut out: Vec<String> = Vec::new();
    for r in rows {
        if !out.iter().any(|o| o == key(r)) {
            out.push(key(r).to_string());
        }
    }
    out
}

/// A method's sampler and knob: `"ghexomino f32"` is `("ghexomino",
/// "f32")`, a method without a knob has `""`.
fn sampler_and_knob(method: &str) -> (&str, &str) {
    match method.rsplit_once(' ') {
        Some((sampler, knob)) if KNOBS.contains(&knob) => (sampler, knob),
        _ => (method, ""),
    }
}

/// The tile samplers' settings besides the default, each with its marker.
const KNOBS: [&str; 4] = ["f32", "no-offsets", "fixed", "expected-N"];

/// The marker of a knob: squares for the default setting.
fn marker(knob: &str) -> Marker {
    match knob {
        "" => Marker::Square,
        "f32" => Marker::Hollow,
        "no-offsets" => Marker::Cross,
        "fixed" => Marker::Plus,
        _ => Marker::Diamond,
    }
}

fn scientific(v: f64) -> String {
    if v.is_finite() {
        format!("{v:.2e}")
    } else {
        "-".into()
    }
}

/// `(x, y)` of one method's rows on one integrand, in `N` order.
fn curve(rows: &[&Row], method: &str, x: impl Fn(&Row) -> f64) -> Vec<(f64, f64)> {
    rows.iter()
        .filter(|r| r.method == method)
        .map(|r| (x(r), r.rel_rmse))
        .collect()
}

/// The rows no other row beats in both time and error (the accuracy/time
/// frontier), fastest first.
fn frontier<'r>(rows: &[&'r Row]) -> Vec<&'r Row> {
    let mut sorted = rows.to_vec();
    sorted.sort_by(|a, b| a.seconds.total_cmp(&b.seconds));
    let mut best = f64::INFINITY;
    sorted
        .into_iter()
        .filter(|r| {
            let keep = r.rel_rmse < best;
            best = best.min(r.rel_rmse);
            keep
        })
        .collect()
}

impl Results {
    /// Writes `ACCURACY.md` and `accuracy-*.png` (relative RMSE against N
    /// and against time, log-log, per scenario and integrand) into `dir`,
    /// recording `command` as what regenerates them. Returns the paths.
    ///
    /// # Errors
    /// [`Error::Io`] or [`Error::File`] when `dir` or a file cannot be written.
    ///
    /// # Example
    /// ```
    /// use tessera::accuracy::{Config, Results, Row};
    /// let row = |n: usize, e: f64| Row {
    ///     scenario: "plane-uniform".into(), method: "i.i.d.".into(), tessera: false,
    ///     integrand: "disc".into(), smooth: false, n, count: n as f64, rel_rmse: e, seconds: 1e-6,
    /// };
    /// let rows = vec![row(64, 0.1), row(128, 0.07)];
    /// let results = Results { config: Config::tiny(), rows, wall_seconds: 1.0, load_average: None };
    /// let dir = std::env::temp_dir().join(format!("tessera-doc-acc-{}", std::process::id()));
    /// let files = results.write(&dir, "tessera bench accuracy").unwrap();
    /// assert!(files.iter().all(|f| f.exists()));
    /// std::fs::remove_dir_all(&dir).unwrap();
    /// ```
    pub fn write(&self, dir: &Path, command: &str) -> Result<Vec<PathBuf>, Error> {
        let io = |path: &Path| {
            let path = path.to_path_buf();
            move |source| Error::Io { path, source }
        };
        std::fs::create_dir_all(dir).map_err(io(dir))?;
        let mut md = self.preamble(command);
        let mut files = Vec::new();
        // one colour per sampler over every plot of the report, in the
        // order samplers first appear; knobs differ by marker
        let samplers = distinct(self.rows.iter(), |r| sampler_and_knob(&r.method).0);
        let colour = |method: &str| {
            let sampler = sampler_and_knob(method).0;
            let k = samplers.iter().position(|s| s == sampler).unwrap_or(0);
            (PALETTE[k % PALETTE.len()], PALETTE_NAMES[k % PALETTE.len()])
        };
        for scenario in distinct(self.rows.iter(), |r| &r.scenario) {
            let rows: Vec<&Row> = self
                .rows
                .iter()
                .filter(|r| r.scenario == scenario)
                .collect();
            let methods = distinct(rows.iter().copied(), |r| &r.method);
            let integrands = distinct(rows.iter().copied(), |r| &r.integrand);
            self.section(&mut md, &scenario, &rows, &methods, &integrands, &colour);
            for integrand in &integrands {
                let on: Vec<&Row> = rows
                    .iter()
                    .copied()
                    .filter(|r| &r.integrand == integrand)
                    .collect();
                for (suffix, x) in [
                    ("n", (|r: &Row| r.count) as fn(&Row) -> f64),
                    ("time", |r: &Row| r.seconds),
                ] {
                    let series: Vec<Series> = methods
                        .iter()
                        .map(|m| Series {
                            points: curve(&on, m, x),
                            color: colour(m).0,
                            name: m.clone(),
                            marker: marker(sampler_and_knob(m).1),
                        })
                        .collect();
                    let name = format!("accuracy-{scenario}-{integrand}-{suffix}.png");
                    let path = dir.join(&name);
                    let axes = Axes {
                        log_x: true,
                        log_y: true,
                    };
                    let labels = Labels {
                        title: format!("{scenario}: {integrand}"),
                        x: if suffix == "n" {
                            "N (samples)"
                        } else {
                            "seconds to draw"
                        }
                        .into(),
                        y: "relative RMSE".into(),
                    };
                    line_plot(&series, axes, &labels, 840, 440)
                        .save_with_format(&path, image::ImageFormat::Png)
                        .map_err(|e| Error::File {
                            path: path.clone(),
                            reason: format!("cannot write PNG: {e}"),
                        })?;
                    files.push(path);
                }
                let _ = writeln!(
                    md,
                    "`{integrand}`: ![relative RMSE against N](accuracy-{scenario}-{integrand}-n.png) \
                     ![relative RMSE against seconds](accuracy-{scenario}-{integrand}-time.png)\n"
                );
            }
        }
        let path = dir.join("ACCURACY.md");
        std::fs::write(&path, md).map_err(io(&path))?;
        files.push(path);
        Ok(files)
    }

    /// Slope of MSE against N for every smooth integrand of every scenario,
    /// for the default setting of each tile sampler (its name has no knob).
    fn tile_slopes(&self) -> Vec<(String, String, String, f64)> {
        let mut out = Vec::new();
        for r in self
            .rows
            .iter()
            .filter(|r| r.tessera && r.smooth && !r.method.contains(' '))
        {
            let key = (r.scenario.clone(), r.method.clone(), r.integrand.clone());
            if !out
                .iter()
                .any(|(s, m, i, _)| (s, m, i) == (&key.0, &key.1, &key.2))
            {
                let slope = self.mse_slope(&key.0, &key.1, &key.2);
                out.push((key.0, key.1, key.2, slope));
            }
        }
        out
    }

    fn preamble(&self, command: &str) -> String {
        let exps = &self.config.exponents;
        let (lo, hi) = (
            exps.first().copied().unwrap_or(0),
            exps.last().copied().unwrap_or(0),
        );
        let mut md = String::new();
        let _ = writeln!(
            md,
            "# Accuracy and what it costs in time\n\n\
             Generated by `{command}` in {:.0} s of wall time on a machine with {} hardware \
             thread(s){}. Every number and plot below comes from that one run; rerun the \
             command to regenerate them (do not edit by hand).\n",
            self.wall_seconds,
            std::thread::available_parallelism().map_or(1, |n| n.get()),
            self.load_average.map_or(String::new(), |l| format!(
                ", load average {l:.2} when it started"
            )),
        );
        let _ = writeln!(
            md,
            "**Method.** Each sampler draws N = 2^{lo} .. 2^{hi} points, {} times with \
             different seeds up to N = 2^16, then half as many per doubling of N (at least 4; \
             Bridson's sampler, at about 10 µs a point, stops at N = 2^16). For each test integrand f with known integral I the estimate is \
             (1/N) Σ f(x_i) / pdf(x_i); the table entries are the relative RMSE \
             sqrt(mean((estimate − I)² / I²)) over the seeds and the median time to draw one \
             set on one thread (randomisation included). Randomisation: a uniformly random \
             rotation on the sphere (`tessera sphere --map ... --seed`: the env-map sampler \
             rotates its frame), a toroidal shift in the unit square; i.i.d., 1-D stratified \
             inverse CDF (env map: one uniform number per stratum of the row-major CDF over \
             all pixels), Sobol (Owen scrambling), jittered HEALPix and Bridson draw from the \
             seed. Slopes are \
             least-squares fits of log MSE against log N (the mean count actually drawn).\n",
            self.config.seeds
        );
        let _ = writeln!(
            md,
            "**Knobs** of the tile samplers (each a method): the default (offset tables, f64, \
             exact N, randomised); `f32` (positions rounded to f32); `no-offsets` (each sample \
             at its tile's centroid: the offset tables off); `fixed` (not randomised: one \
             deterministic set, so its \"RMSE\" is that set's error); `expected-N` (env map \
             only: the exactness pass off; a uniform request streams exactly N codes either \
             way, so there it changes nothing). The table level depth is not a run-time knob: \
             the shipped tables index tiles by tree position for their first levels and by \
             class below, fixed when `tessera lut build` makes them, and N alone picks the \
             level used.\n"
        );
        let _ = writeln!(
            md,
            "**Lights** (`sphere-lights`, N up to 2^14): the same sky turned into N directional \
             lights with exact powers (`tessera lights`, the default options) against classic \
             and greedy median cut. A light set estimates the integral of L(w) f(w) by \
             Σ P_k f(w_k); f is the clamped cosine around 64 fixed random normals (`diffuse`) \
             and Phong lobes max(0, a · w)^m, m = 10 and 100, around 64 fixed random axes; the \
             entries are the relative RMSE over the normals (axes), since the sets are \
             deterministic, and the median time of three builds on one thread. The realistic \
             maps, rotated frames and held-out seeds are in `docs/LIGHTS.md`.\n"
        );
        let slopes = self.tile_slopes();
        let iid: Vec<f64> = self
            .rows
            .iter()
            .filter(|r| r.smooth && r.method == "i.i.d." && r.n == 1 << lo)
            .map(|r| self.mse_slope(&r.scenario, &r.method, &r.integrand))
            .collect();
        let worst = slopes.iter().map(|s| s.3).fold(f64::NEG_INFINITY, f64::max);
        let _ = writeln!(
            md,
            "## Convergence on smooth integrands\n\n\
             Fitted slopes of MSE against N for each tile sampler at its default settings on \
             each smooth integrand (goal: {SLOPE_GOAL} or steeper; i.i.d. sampling gives −1): \
             {}. Steepest-to-shallowest range {:.2} .. {worst:.2}: **{}**. i.i.d. on the same \
             integrands: {}.\n",
            slopes
                .iter()
                .map(|(s, m, i, v)| format!("{m} on {s} `{i}` {v:.2}"))
                .collect::<Vec<_>>()
                .join(", "),
            slopes.iter().map(|s| s.3).fold(f64::INFINITY, f64::min),
            if worst <= SLOPE_GOAL {
                "all meet the goal"
            } else {
                "not all meet the goal"
            },
            iid.iter()
                .map(|v| format!("{v:.2}"))
                .collect::<Vec<_>>()
                .join(", "),
        );
        md
    }

    fn section(
        &self,
        md: &mut String,
        scenario: &str,
        rows: &[&Row],
        methods: &[String],
        integrands: &[String],
        colour: &dyn Fn(&str) -> ([u8; 3], &'static str),
    ) {
        let n_max = rows.iter().map(|r| r.n).max().unwrap_or(0);
        let head = |first: &str| {
            let mut h = format!("| {first} |");
            let mut rule = String::from("|---|");
            for i in integrands {
                let smooth = rows.iter().any(|r| &r.integrand == i && r.smooth);
                let _ = write!(h, " `{i}`{} |", if smooth { " (smooth)" } else { "" });
                rule.push_str("---:|");
            }
            format!("{h}\n{rule}\n")
        };
        let _ = writeln!(md, "## {scenario}\n");
        let _ = writeln!(
            md,
            "Fitted slope of MSE against N:\n\n{}",
            head("method").trim_end()
        );
        for m in methods {
            let mut line = format!("| {m} |");
            for i in integrands {
                let _ = write!(line, " {:.2} |", self.mse_slope(scenario, m, i));
            }
            let _ = writeln!(md, "{line}");
        }
        let _ = writeln!(
            md,
            "\nRelative RMSE at N = 2^{} (mean count drawn, median ms to draw):\n\n{}",
            n_max.trailing_zeros(),
            head("method (count, ms)").trim_end()
        );
        for m in methods {
            let at: Vec<&&Row> = rows
                .iter()
                .filter(|r| &r.method == m && r.n == n_max)
                .collect();
            let Some(first) = at.first() else { continue };
            let mut line = format!("| {m} ({:.0}, {:.2}) |", first.count, 1e3 * first.seconds);
            for i in integrands {
                let e = at
                    .iter()
                    .find(|r| &r.integrand == i)
                    .map_or(f64::NAN, |r| r.rel_rmse);
                let _ = write!(line, " {} |", scientific(e));
            }
            let _ = writeln!(md, "{line}");
        }
        let target = integrands
            .iter()
            .find(|i| rows.iter().any(|r| &r.integrand == *i && r.smooth))
            .or(integrands.first());
        if let Some(target) = target {
            let on: Vec<&Row> = rows
                .iter()
                .copied()
                .filter(|r| &r.integrand == target)
                .collect();
            let _ = writeln!(
                md,
                "\nAccuracy/time frontier on `{target}` (the (method, N) settings no other \
                 setting beats in both time and error, fastest first):\n\n\
                 | method | N | ms to draw | relative RMSE |\n|---|---:|---:|---:|"
            );
            for r in frontier(&on) {
                let _ = writeln!(
                    md,
                    "| {} | {:.0} | {:.3} | {} |",
                    r.method,
                    r.count,
                    1e3 * r.seconds,
                    scientific(r.rel_rmse)
                );
            }
        }
        let legend: Vec<String> = methods
            .iter()
            .map(|m| {
                let (sampler, knob) = sampler_and_knob(m);
                let mark = format!("{:?}", marker(knob)).to_lowercase();
                format!("{m}: {} {mark}", colour(sampler).1)
            })
            .collect();
        let _ = writeln!(
            md,
            "\nPlots (log-log; relative RMSE against N, then against seconds to draw; \
             one colour per sampler in every plot, one marker per setting): {}.\n",
            legend.join(", ")
        );
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::accuracy::log_log_slope;

    #[test]
    fn frontier_keeps_only_undominated_rows() {
        let row = |s: f64, e: f64| Row {
            scenario: "s".into(),
            method: "m".into(),
            tessera: false,
            integrand: "i".into(),
            smooth: true,
            n: 1,
            count: 1.0,
            rel_rmse: e,
            seconds: s,
        };
        let rows = [row(1.0, 0.5), row(2.0, 0.6), row(3.0, 0.1), row(0.5, 0.9)];
        let refs: Vec<&Row> = rows.iter().collect();
        let f: Vec<(f64, f64)> = frontier(&refs)
            .iter()
            .map(|r| (r.seconds, r.rel_rmse))
            .collect();
        assert_eq!(f, [(0.5, 0.9), (1.0, 0.5), (3.0, 0.1)]);
        assert!((log_log_slope(&[(1.0, 2.0), (4.0, 0.5)]) + 1.0).abs() < 1e-12);
    }
}

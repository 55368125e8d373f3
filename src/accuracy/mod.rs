//! What accuracy costs in time: the relative RMSE of Monte Carlo integration
//! with each sampler (tessera's systems and their knobs, and the baselines)
//! over test integrands with known integrals, against the wall time of
//! drawing the point set, for `N = 2^k` points, over randomised seeds.
//! `tessera bench accuracy` runs it and writes `ACCURACY.md` and its plots
//! ([`Results::write`]).
//!
//! An estimate is `(1/N) Σ f(x_i) w(x_i)` with `w = 1/pdf` (the domain's
//! measure for uniform sampling); its relative error is
//! `(estimate − exact) / exact`, and the relative RMSE is over the seeds.
//! Randomisation keeps estimates unbiased: a uniformly random rotation on
//! the sphere, a toroidal shift in the square (point sets that already
//! depend on a seed, such as i.i.d. or Owen-scrambled Sobol, draw it).
//! Times are medians over the seeds of drawing one set (randomisation
//! included) on one thread.
//!
//! ```
//! let results = tessera::accuracy::run(&tessera::accuracy::Config::tiny());
//! assert!(results.rows.iter().all(|r| r.rel_rmse.is_finite()));
//! ```

mod integrands;
mod lights;
mod report;
mod scenarios;

use crate::density::envmap::{EnvMap, Up};
use crate::io::image::Raster;
use rayon::prelude::*;
use std::f64::consts::PI;
use std::time::Instant;

/// What to measure.
///
/// # Example
/// ```
/// let c = tessera::accuracy::Config::full();
/// assert_eq!((c.exponents[0], *c.exponents.last().unwrap()), (6, 20));
/// ```
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Config {
    /// Point counts `N = 2^k` for these `k`.
    pub exponents: Vec<u32>,
    /// Seeds (independent randomisations) per method for `N` up to
    /// [`Config::FULL_SEEDS_UP_TO`]; see [`Config::seeds_at`].
    pub seeds: u64,
}

impl Config {
    /// Largest `N` measured with all [`Config::seeds`].
    pub const FULL_SEEDS_UP_TO: usize = 1 << 16;

    /// Seeds at `N`: all of them up to [`Config::FULL_SEEDS_UP_TO`], then
    /// half as many per doubling of `N` (the same number of points drawn
    /// per size), but at least 4.
    ///
    /// # Example
    /// ```
    /// let c = tessera::accuracy::Config::full();
    /// assert_eq!((c.seeds_at(1 << 10), c.seeds_at(1 << 18), c.seeds_at(1 << 20)), (16, 4, 4));
    /// ```
    pub fn seeds_at(&self, n: usize) -> u64 {
        let scaled = (self.seeds as f64 * Self::FULL_SEEDS_UP_TO as f64 / n as f64) as u64;
        scaled.clamp(4, self.seeds.max(4)).min(self.seeds)
    }

    /// `N = 2^6 .. 2^20`, 16 seeds: what `docs/ACCURACY.md` reports.
    ///
    /// # Example
    /// ```
    /// assert_eq!(tessera::accuracy::Config::full().exponents.len(), 15);
    /// ```
    pub fn full() -> Self {
        Config {
            exponents: (6..=20).collect(),
            seeds: 16,
        }
    }

    /// `N = 2^6 .. 2^10` with 8 seeds: a smoke test (about a second).
    ///
    /// # Example
    /// ```
    /// assert_eq!(tessera::accuracy::Config::tiny().seeds, 8);
    /// ```
    pub fn tiny() -> Self {
        Config {
            exponents: (6..=10).collect(),
            seeds: 8,
        }
    }
}

/// One measurement: a method on an integrand at one requested `N`.
///
/// # Example
/// ```
/// let row = tessera::accuracy::Row {
///     scenario: "plane-uniform".into(), method: "i.i.d.".into(), tessera: false,
///     integrand: "disc".into(), smooth: false, n: 64, count: 64.0, rel_rmse: 0.1, seconds: 1e-6,
/// };
/// assert!(!row.smooth);
/// ```
#[derive(Clone, Debug, PartialEq)]
pub struct Row {
    /// Domain and density, e.g. `sphere-uniform`.
    pub scenario: String,
    /// Sampler and knob, e.g. `tessera f32`.
    pub method: String,
    /// Whether the method is one of tessera's tile samplers.
    pub tessera: bool,
    /// Test integrand.
    pub integrand: String,
    /// Whether the integrand is smooth (infinitely differentiable).
    pub smooth: bool,
    /// Requested number of points.
    pub n: usize,
    /// Mean number of points actually drawn (some methods only come close).
    pub count: f64,
    /// Relative RMSE over the seeds (the `sphere-lights` rows: over the
    /// lobe's normals or axes, the sets being deterministic).
    pub rel_rmse: f64,
    /// Median seconds to draw one set, one thread.
    pub seconds: f64,
}

/// Everything measured, with the configuration and how long it took.
///
/// # Example
/// ```
/// use tessera::accuracy::{Config, Results};
/// let empty = Results { config: Config::tiny(), rows: vec![], wall_seconds: 0.0, load_average: None };
/// assert!(empty.rows.is_empty());
/// ```
#[derive(Clone, Debug, PartialEq)]
pub struct Results {
    /// The configuration measured.
    pub config: Config,
    /// One row per scenario, method, integrand and `N`.
    pub rows: Vec<Row>,
    /// Wall time of the whole run.
    pub wall_seconds: f64,
    /// The one-minute load average when the run started (Linux
    /// `/proc/loadavg`; `None` elsewhere): other work skews the times.
    pub load_average: Option<f64>,
}

/// A test function with its exact integral over the domain.
struct Integrand<'a, P> {
    name: &'static str,
    smooth: bool,
    exact: f64,
    f: Box<dyn Fn(P) -> f64 + Sync + 'a>,
}

/// Draws about `n` points from a seed.
type Generator<'a, P> = Box<dyn Fn(usize, u64) -> Vec<P> + Sync + 'a>;

/// A sampler (with its knob settings) under a name.
struct Method<'a, P> {
    name: String,
    tessera: bool,
    /// Largest `N` measured (slow methods stop early).
    max_n: usize,
    generate: Generator<'a, P>,
}

/// A domain and density: the integrands, the weight `1/pdf` of the density
/// every method samples, and the methods.
struct Scenario<'a, P> {
    name: &'static str,
    weight: Box<dyn Fn(P) -> f64 + Sync + 'a>,
    integrands: Vec<Integrand<'a, P>>,
    methods: Vec<Method<'a, P>>,
}

/// Runs every scenario (sphere uniform, sphere env map, plane uniform, and
/// the env map as lights against median cut).
/// Drawing runs on a one-thread pool (times comparable across samplers);
/// estimates are evaluated in parallel.
///
/// # Example
/// ```
/// let results = tessera::accuracy::run(&tessera::accuracy::Config::tiny());
/// assert!(results.rows.iter().any(|r| r.scenario == "plane-uniform" && r.method == "bridson"));
/// let stratified = |r: &&tessera::accuracy::Row| r.method == "stratified inverse-CDF";
/// assert!(results.rows.iter().filter(stratified).all(|r| r.scenario == "sphere-envmap"));
/// assert!(results.rows.iter().filter(stratified).any(|r| r.rel_rmse > 0.0));
/// assert!(results.rows.iter().any(|r| r.scenario == "sphere-lights" && r.method == "median cut (greedy)"));
/// ```
pub fn run(config: &Config) -> Results {
    let start = Instant::now();
    let load_average = std::fs::read_to_string("/proc/loadavg")
        .ok()
        .and_then(|s| s.split_whitespace().next()?.parse().ok());
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(1)
        .build()
        .expect("a one-thread pool");
    let sky = sky();
    let mut rows = measure(&scenarios::sphere_uniform(), config, &pool);
    rows.extend(measure(&scenarios::sphere_envmap(&sky), config, &pool));
    rows.extend(measure(&scenarios::plane_uniform(), config, &pool));
    rows.extend(lights::rows(&sky, config, &pool));
    Results {
        config: config.clone(),
        rows,
        wall_seconds: start.elapsed().as_secs_f64(),
        load_average,
    }
}

/// The generated sky: 256x128, z up, brighter towards the zenith and
/// towards φ = 0, and a 5x5-pixel sun 200 times the sky (about a third of
/// the map's integral). The env-map scenario's density.
///
/// # Example
/// ```
/// let sky = tessera::accuracy::sky();
/// assert_eq!((sky.width(), sky.height()), (256, 128));
/// ```
pub fn sky() -> EnvMap {
    let (w, h) = (256, 128);
    let mut values: Vec<f64> = (0..w * h)
        .map(|k| {
            let theta = ((k / w) as f64 + 0.5) / h as f64 * PI;
            let phi = ((k % w) as f64 + 0.5) / w as f64 * 2.0 * PI;
            0.05 + 0.4 * theta.cos().max(0.0) + 0.05 * (1.0 + phi.cos())
        })
        .collect();
    for j in 36..41 {
        for i in 75..80 {
            values[j * w + i] *= 200.0;
        }
    }
    let raster = Raster {
        width: w,
        height: h,
        values,
        bad_pixels: 0,
    };
    EnvMap::new(raster, Up::Z).expect("the generated sky is a valid map")
}

fn measure<P: Copy + Send + Sync>(
    scenario: &Scenario<'_, P>,
    config: &Config,
    pool: &rayon::ThreadPool,
) -> Vec<Row> {
    let mut rows = Vec::new();
    for method in &scenario.methods {
        for &k in &config.exponents {
            let n = 1usize << k;
            if n > method.max_n {
                continue;
            }
            let mut squared = vec![0.0; scenario.integrands.len()];
            let (mut times, mut count) = (Vec::new(), 0.0);
            let seeds = config.seeds_at(n);
            for seed in 0..seeds {
                let started = Instant::now();
                let points = pool.install(|| (method.generate)(n, seed));
                times.push(started.elapsed().as_secs_f64());
                count += points.len() as f64;
                for (sq, integrand) in squared.iter_mut().zip(&scenario.integrands) {
                    let sum: f64 = points
                        .par_iter()
                        .map(|&p| (integrand.f)(p) * (scenario.weight)(p))
                        .sum();
                    let estimate = sum / points.len().max(1) as f64;
                    *sq += ((estimate - integrand.exact) / integrand.exact).powi(2);
                }
            }
            times.sort_by(f64::total_cmp);
            let seeds = seeds as f64;
            for (sq, integrand) in squared.iter().zip(&scenario.integrands) {
                rows.push(Row {
                    scenario: scenario.name.into(),
                    method: method.name.clone(),
                    tessera: method.tessera,
                    integrand: integrand.name.into(),
                    smooth: integrand.smooth,
                    n,
                    count: count / seeds,
                    rel_rmse: (sq / seeds).sqrt(),
                    seconds: times[times.len() / 2],
                });
            }
        }
    }
    rows
}

/// Least-squares slope of `log y` against `log x` (NaN for fewer than two
/// usable points; non-positive values are skipped).
///
/// # Example
/// ```
/// let s = tessera::accuracy::log_log_slope(&[(1.0, 1.0), (10.0, 0.01), (100.0, 1e-4)]);
/// assert!((s + 2.0).abs() < 1e-12);
/// ```
pub fn log_log_slope(points: &[(f64, f64)]) -> f64 {
    let logs: Vec<(f64, f64)> = points
        .iter()
        .filter(|(x, y)| *x > 0.0 && *y > 0.0 && x.is_finite() && y.is_finite())
        .map(|(x, y)| (x.ln(), y.ln()))
        .collect();
    let n = logs.len() as f64;
    if logs.len() < 2 {
        return f64::NAN;
    }
    let (mx, my) = (
        logs.iter().map(|p| p.0).sum::<f64>() / n,
        logs.iter().map(|p| p.1).sum::<f64>() / n,
    );
    let sxy: f64 = logs.iter().map(|(x, y)| (x - mx) * (y - my)).sum();
    let sxx: f64 = logs.iter().map(|(x, _)| (x - mx).powi(2)).sum();
    sxy / sxx
}

impl Results {
    /// Fitted slope of the MSE (`rel_rmse²`) against the mean point count,
    /// in log-log, for one scenario, method and integrand.
    ///
    /// # Example
    /// ```
    /// use tessera::accuracy::{Config, Results, Row};
    /// let row = |n: usize, e: f64| Row {
    ///     scenario: "s".into(), method: "m".into(), tessera: false,
    ///     integrand: "i".into(), smooth: true, n, count: n as f64, rel_rmse: e, seconds: 1e-6,
    /// };
    /// let rows = vec![row(64, 0.1), row(256, 0.05)];
    /// let r = Results { config: Config::tiny(), rows, wall_seconds: 1.0, load_average: None };
    /// assert!((r.mse_slope("s", "m", "i") + 1.0).abs() < 1e-12);
    /// ```
    pub fn mse_slope(&self, scenario: &str, method: &str, integrand: &str) -> f64 {
        let points: Vec<(f64, f64)> = self
            .rows
            .iter()
            .filter(|r| r.scenario == scenario && r.method == method && r.integrand == integrand)
            .map(|r| (r.count, r.rel_rmse * r.rel_rmse))
            .collect();
        log_log_slope(&points)
    }
}

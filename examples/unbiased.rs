//! Bias and error of irradiance estimates over independent randomisations:
//! tessera against i.i.d. inverse-CDF, 1-D stratified inverse-CDF and
//! Owen-scrambled Sobol samples through the 2-D inverse CDF, on every
//! generated sky (`tessera::synth::Sky::all()`, 1024x512, map seed 1).
//!
//!     cargo run --release --example unbiased [-- --out docs/UNBIASED.md]
//!
//! For each map and N in 1024, 4096, 16384 it draws R = 64 independent sets
//! per method (seeds 0..64: tessera a random rotation, `map.with_seed(s)`;
//! the baselines their random numbers; Sobol its Owen scramble), estimates
//! the irradiance `E(n) = ∫ L(ω) max(0, n·ω) dω` for 64 fixed random unit
//! normals as `(integral / N) Σ max(0, n·ω_i)` (samples where the pdf is 0
//! count 0; the same as `tessera::metrics::irradiance::estimate`, checked
//! on the first run of each method) against the quadrature reference
//! `tessera::metrics::irradiance::exact`, and reports per method the bias,
//! the largest z over the normals and the RMSE, plus the unseeded
//! deterministic tessera set's error. It also times the baselines against
//! plain implementations written the obvious way, in the same run.
//!
//! Options: `--out PATH` (default `docs/UNBIASED.md`), `--runs R`
//! (default 64), `--maps a,b` (names from `Sky::name`, default all),
//! `--counts 1024,4096` (default 1024,4096,16384), `--no-timing`.

use glam::DVec3;
use rayon::prelude::*;
use std::f64::consts::{PI, TAU};
use std::fmt::Write as _;
use std::hint::black_box;
use std::path::PathBuf;
use std::time::Instant;
use tessera::baselines::envmap::{InverseCdf, Stratified};
use tessera::baselines::{sobol, uniform_random_sphere, SplitMix64};
use tessera::density::envmap::{EnvMap, Up};
use tessera::metrics::irradiance::{estimate, exact};
use tessera::synth::Sky;

const WIDTH: usize = 1024;
const HEIGHT: usize = 512;
const MAP_SEED: u64 = 1;
const NORMALS: usize = 64;
const NORMAL_SEED: u64 = 0x6e6f_726d;
/// |z| above which a row's bias is flagged: Student t with 63 degrees of
/// freedom at a two-sided 1e-3 / 64 (Bonferroni over the 64 normals), so
/// a family-wise false-alarm rate of at most 1e-3 per row at R = 64.
const Z_FLAG: f64 = 4.68;

struct Args {
    out: PathBuf,
    runs: u64,
    maps: Option<Vec<String>>,
    counts: Vec<usize>,
    timing: bool,
    command: String,
}

fn parse_args() -> Args {
    let mut args = Args {
        out: "docs/UNBIASED.md".into(),
        runs: 64,
        maps: None,
        counts: vec![1024, 4096, 16384],
        timing: true,
        command: "cargo run --release --example unbiased".into(),
    };
    let list: Vec<String> = std::env::args().skip(1).collect();
    if !list.is_empty() {
        args.command += &format!(" -- {}", list.join(" "));
    }
    let mut it = list.into_iter();
    while let Some(a) = it.next() {
        let mut value = || it.next().unwrap_or_else(|| panic!("{a} needs a value"));
        match a.as_str() {
            "--out" => args.out = value().into(),
            "--runs" => args.runs = value().parse().expect("--runs R"),
            "--maps" => args.maps = Some(value().split(',').map(Into::into).collect()),
            "--counts" => {
                args.counts = (value().split(','))
                    .map(|c| c.parse().expect("--counts N,N"))
                    .collect()
            }
            "--no-timing" => args.timing = false,
            other => panic!("unknown argument {other}"),
        }
    }
    args
}

#[derive(Clone, Copy, PartialEq)]
enum Method {
    Tessera,
    Stratified,
    Iid,
    Sobol,
}

const METHODS: [Method; 4] = [
    Method::Tessera,
    Method::Stratified,
    Method::Iid,
    Method::Sobol,
];

impl Method {
    fn name(self) -> &'static str {
        match self {
            Method::Tessera => "tessera",
            Method::Stratified => "1-D stratified",
            Method::Iid => "i.i.d. inverse CDF",
            Method::Sobol => "Owen-Sobol 2-D CDF",
        }
    }
}

/// One map with its baselines, normals and reference irradiance.
struct Bench<'a> {
    map: &'a EnvMap,
    inverse: InverseCdf<'a>,
    stratified: Stratified<'a>,
    normals: &'a [DVec3],
    reference: Vec<f64>,
}

impl Bench<'_> {
    fn draw(&self, method: Method, n: usize, seed: u64) -> Vec<DVec3> {
        match method {
            Method::Tessera => positions(self.map.with_seed(seed).generate(n)),
            Method::Stratified => self.stratified.samples(n, seed),
            Method::Iid => self.inverse.samples(n, seed),
            Method::Sobol => (sobol::owen_sobol_2d(n, seed).into_iter())
                .map(|u| self.inverse.warp([u.x, u.y]))
                .collect(),
        }
    }

    /// Relative irradiance error per normal: `(integral / N) Σ max(0, n·ω)`
    /// over the samples where the pdf is positive (`L / pdf = integral`
    /// there), divided by the reference, minus 1.
    fn errors(&self, samples: &[DVec3]) -> Vec<f64> {
        let live: Vec<DVec3> = (samples.iter().copied())
            .filter(|&d| self.map.pdf(d) > 0.0)
            .collect();
        let scale = self.map.integral() / samples.len().max(1) as f64;
        (self.normals.iter().zip(&self.reference))
            .map(|(n, r)| {
                let sum: f64 = live.iter().map(|d| n.dot(*d).max(0.0)).sum();
                sum * scale / r - 1.0
            })
            .collect()
    }

    /// `errors` against the library's estimator, on a few normals.
    fn check(&self, samples: &[DVec3]) {
        let fast = self.errors(samples);
        let normals = self.normals.iter().zip(&self.reference).zip(fast);
        for ((&n, r), f) in normals.take(4) {
            let e = estimate(self.map, samples, n) / r - 1.0;
            assert!(
                (e - f).abs() <= 1e-9 * (1.0 + e.abs()),
                "estimator mismatch {e} {f}"
            );
        }
    }
}

fn positions(samples: Result<Vec<tessera::Sample<DVec3>>, tessera::Error>) -> Vec<DVec3> {
    let samples = samples.expect("tessera samples the generated maps");
    samples.into_iter().map(|s| s.position).collect()
}

/// The statistics of one method on one map at one N.
#[derive(Clone, Copy)]
struct Stats {
    /// RMS over normals of the mean relative error over the runs.
    bias: f64,
    /// Largest |mean| / (sd / sqrt(R)) over the normals.
    max_z: f64,
    /// Root mean square of the relative error over runs and normals.
    rmse: f64,
}

fn stats(errors: &[Vec<f64>]) -> Stats {
    let runs = errors.len() as f64;
    let normals = errors[0].len();
    let (mut bias2, mut max_z, mut sq) = (0.0, 0.0f64, 0.0);
    for k in 0..normals {
        let mean = errors.iter().map(|e| e[k]).sum::<f64>() / runs;
        let var = errors.iter().map(|e| (e[k] - mean).powi(2)).sum::<f64>() / (runs - 1.0);
        let z = mean.abs() / (var / runs).sqrt();
        bias2 += mean * mean;
        max_z = max_z.max(if z.is_nan() { 0.0 } else { z });
        sq += errors.iter().map(|e| e[k] * e[k]).sum::<f64>();
    }
    Stats {
        bias: (bias2 / normals as f64).sqrt(),
        max_z,
        rmse: (sq / (runs * normals as f64)).sqrt(),
    }
}

/// A second reference for `exact`'s quadrature: per pixel, the closed form
/// `L n · ∫ ω dω` where the pixel lies wholly on the lit side of the
/// normal's horizon (0 on the dark side), and an 8x8 midpoint rule in
/// `(φ, cos θ)` on pixels the horizon may cross (their bounding cap, taken
/// twice as wide as needed, meets it). Returns the largest relative
/// difference from `exact` over the normals.
fn reference_check(map: &EnvMap, normals: &[DVec3], reference: &[f64]) -> f64 {
    assert_eq!(map.up(), Up::Z);
    let (w, h) = (map.width(), map.height());
    let (dphi, dtheta) = (TAU / w as f64, PI / h as f64);
    let phi_edge: Vec<(f64, f64)> = (0..=w).map(|i| (i as f64 * dphi).sin_cos()).collect();
    let z_edge: Vec<f64> = (0..=h).map(|j| (j as f64 * dtheta).cos()).collect();
    // per row: ∫ sin²θ dθ and ∫ cos θ sin θ dθ over the row, and the cap
    // radius bound
    let rows: Vec<(f64, f64, f64)> = (0..h)
        .map(|j| {
            let (a, b) = (j as f64 * dtheta, (j + 1) as f64 * dtheta);
            let i_s = (b - a) / 2.0 - ((2.0 * b).sin() - (2.0 * a).sin()) / 4.0;
            let i_c = (b.sin().powi(2) - a.sin().powi(2)) / 2.0;
            let widest = a.sin().max(b.sin());
            (i_s, i_c, 2.0 * (dtheta / 2.0 + widest * dphi / 2.0))
        })
        .collect();
    let direction = |i: usize, j: usize, u: f64, v: f64| {
        let phi = (i as f64 + u) * dphi;
        let z = z_edge[j] + v * (z_edge[j + 1] - z_edge[j]);
        let s = ((1.0 - z) * (1.0 + z)).max(0.0).sqrt();
        let (sin, cos) = phi.sin_cos();
        DVec3::new(s * cos, s * sin, z)
    };
    let omega = |j: usize| map.pixel_solid_angle(j);
    (normals.par_iter().zip(reference))
        .map(|(n, r)| {
            let mut total = 0.0;
            for (j, &(i_s, i_c, radius)) in rows.iter().enumerate() {
                for i in 0..w {
                    let l = map.values()[j * w + i];
                    if l == 0.0 {
                        continue;
                    }
                    let c = direction(i, j, 0.5, 0.5);
                    let side = n.dot(c);
                    if side.abs() > radius.sin() {
                        if side > 0.0 {
                            let ((s0, c0), (s1, c1)) = (phi_edge[i], phi_edge[i + 1]);
                            let v = DVec3::new((s1 - s0) * i_s, (c0 - c1) * i_s, dphi * i_c);
                            total += l * n.dot(v);
                        }
                    } else {
                        let mut sum = 0.0;
                        for q in 0..64 {
                            let (u, v) = ((q % 8) as f64 + 0.5, (q / 8) as f64 + 0.5);
                            sum += n.dot(direction(i, j, u / 8.0, v / 8.0)).max(0.0);
                        }
                        total += l * omega(j) * sum / 64.0;
                    }
                }
            }
            (r / total - 1.0).abs()
        })
        .reduce(|| 0.0, f64::max)
}

/// Results of one map at one N.
struct Cell {
    map: &'static str,
    n: usize,
    stats: [Stats; 4],
    /// The unseeded deterministic tessera set's error: RMS over the normals
    /// of its single relative error.
    fixed: f64,
    /// [`reference_check`] of the map.
    reference_gap: f64,
}

fn run_map(sky: Sky, counts: &[usize], runs: u64, normals: &[DVec3]) -> Vec<Cell> {
    let map = EnvMap::new(sky.generate(WIDTH, HEIGHT, MAP_SEED).raster(), Up::Z)
        .expect("a generated map is valid");
    let bench = Bench {
        map: &map,
        inverse: InverseCdf::new(&map),
        stratified: Stratified::new(&map),
        normals,
        reference: exact(&map, normals),
    };
    let reference_gap = reference_check(&map, normals, &bench.reference);
    println!("{}: reference gap {reference_gap:.1e}", sky.name());
    counts
        .iter()
        .map(|&n| {
            let stats = METHODS.map(|method| {
                bench.check(&bench.draw(method, n, 0));
                let errors: Vec<Vec<f64>> = (0..runs)
                    .into_par_iter()
                    .map(|seed| {
                        let samples = bench.draw(method, n, seed);
                        assert_eq!(
                            samples.len(),
                            n,
                            "{} returned {}",
                            method.name(),
                            samples.len()
                        );
                        bench.errors(&samples)
                    })
                    .collect();
                stats(&errors)
            });
            let fixed = bench.errors(&positions(map.generate(n)));
            let fixed = (fixed.iter().map(|e| e * e).sum::<f64>() / fixed.len() as f64).sqrt();
            Cell {
                map: sky.name(),
                n,
                stats,
                fixed,
                reference_gap,
            }
        })
        .collect()
}

/// A plain i.i.d. inverse-CDF sampler written the obvious way: f64 CDFs,
/// a binary search over rows and one over the row's columns, the direction
/// uniform in the pixel from a per-row `cos θ` table; four SplitMix64
/// numbers a sample, as `InverseCdf::samples`.
struct PlainInverse {
    width: usize,
    marginal: Vec<f64>,
    conditional: Vec<f64>,
    z_edges: Vec<f64>,
}

/// Cumulative sums divided by the total, starting at 0, ending at 1.
fn plain_cdf(weights: impl Iterator<Item = f64>) -> Vec<f64> {
    let mut cdf = vec![0.0];
    let mut sum = 0.0;
    for w in weights {
        sum += w;
        cdf.push(sum);
    }
    if sum > 0.0 {
        cdf.iter_mut().for_each(|c| *c /= sum);
    }
    cdf
}

fn weights(map: &EnvMap) -> Vec<f64> {
    let w = map.width();
    (map.values().iter().enumerate())
        .map(|(k, v)| v * map.pixel_solid_angle(k / w))
        .collect()
}

/// The first `k` with `cdf[k + 1] > u`.
fn first_above(cdf: &[f64], u: f64) -> usize {
    cdf[1..].partition_point(|&c| c <= u).min(cdf.len() - 2)
}

/// Uniform in solid angle inside pixel `(i, j)` from `(a, b)`.
fn plain_direction(width: usize, z_edges: &[f64], i: usize, j: usize, a: f64, b: f64) -> DVec3 {
    let phi = TAU * (i as f64 + a) / width as f64;
    let z = z_edges[j] + b * (z_edges[j + 1] - z_edges[j]);
    let s = ((1.0 - z) * (1.0 + z)).max(0.0).sqrt();
    let (sin, cos) = phi.sin_cos();
    DVec3::new(s * cos, s * sin, z)
}

impl PlainInverse {
    fn new(map: &EnvMap) -> Self {
        let (w, h) = (map.width(), map.height());
        let all = weights(map);
        let marginal = plain_cdf(all.chunks(w).map(|row| row.iter().sum()));
        let conditional = all
            .chunks(w)
            .flat_map(|r| plain_cdf(r.iter().copied()))
            .collect();
        let z_edges = (0..=h).map(|j| (j as f64 * PI / h as f64).cos()).collect();
        PlainInverse {
            width: w,
            marginal,
            conditional,
            z_edges,
        }
    }

    fn samples(&self, n: usize, seed: u64) -> Vec<DVec3> {
        let mut rng = SplitMix64::new(seed);
        let w = self.width;
        (0..n)
            .map(|_| {
                let (a, b, c, d) = (
                    rng.next_f64(),
                    rng.next_f64(),
                    rng.next_f64(),
                    rng.next_f64(),
                );
                let j = first_above(&self.marginal, a);
                let i = first_above(&self.conditional[j * (w + 1)..(j + 1) * (w + 1)], b);
                plain_direction(w, &self.z_edges, i, j, c, d)
            })
            .collect()
    }
}

/// A plain 1-D stratified sampler written the obvious way: the row-major
/// CDF over all pixels and one binary search per sample.
struct PlainStratified {
    width: usize,
    cdf: Vec<f64>,
    z_edges: Vec<f64>,
}

impl PlainStratified {
    fn new(map: &EnvMap) -> Self {
        let h = map.height();
        PlainStratified {
            width: map.width(),
            cdf: plain_cdf(weights(map).into_iter()),
            z_edges: (0..=h).map(|j| (j as f64 * PI / h as f64).cos()).collect(),
        }
    }

    fn samples(&self, n: usize, seed: u64) -> Vec<DVec3> {
        let mut rng = SplitMix64::new(seed);
        (0..n)
            .map(|i| {
                let u = ((i as f64 + rng.next_f64()) / n as f64).min(1.0 - f64::EPSILON / 2.0);
                let k = first_above(&self.cdf, u);
                let t = (u - self.cdf[k]) / (self.cdf[k + 1] - self.cdf[k]);
                let w = self.width;
                plain_direction(w, &self.z_edges, k % w, k / w, t.min(1.0), rng.next_f64())
            })
            .collect()
    }
}

/// Seconds per sample of `f(n)`, the best of 7 alternated rounds against
/// `g(n)`, each round repeated to at least 2·10^5 samples.
fn race(n: usize, f: impl Fn(usize) -> Vec<DVec3>, g: impl Fn(usize) -> Vec<DVec3>) -> (f64, f64) {
    let reps = (200_000 / n.max(1)).max(1);
    let time = |h: &dyn Fn(usize) -> Vec<DVec3>| {
        let t = Instant::now();
        for _ in 0..reps {
            black_box(h(n));
        }
        t.elapsed().as_secs_f64() / (reps * n) as f64
    };
    let (mut a, mut b) = (f64::INFINITY, f64::INFINITY);
    for _ in 0..7 {
        a = a.min(time(&f));
        b = b.min(time(&g));
    }
    (a, b)
}

fn timing(out: &mut String) {
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(1)
        .build()
        .expect("a one-thread pool");
    let _ = writeln!(
        out,
        "## Speed of the baselines\n\n\
         Nanoseconds a sample on one thread, in memory (output `Vec<DVec3>`), best of 7 rounds \
         alternated in this run, each round repeated to at least 2·10^5 samples; the plain versions are \
         written the obvious way in the example (f64 CDFs; `partition_point` binary searches; \
         a per-row `cos θ` table and one `sin_cos` per direction). `InverseCdf` is compared at \
         2^20 samples, `Stratified` (a forward galloping walk over the sorted strata) against a \
         binary search per sample.\n\n\
         | map | sampler | N | library ns | plain ns | library / plain |\n|---|---|---|---|---|---|"
    );
    for sky in [Sky::ClearSky, Sky::Textured { sigma: 2.0 }] {
        let map = EnvMap::new(sky.generate(WIDTH, HEIGHT, MAP_SEED).raster(), Up::Z)
            .expect("a generated map is valid");
        let (inverse, plain) = (InverseCdf::new(&map), PlainInverse::new(&map));
        let (strat, plain_strat) = (Stratified::new(&map), PlainStratified::new(&map));
        let mut row = |name: &str, n: usize, (a, b): (f64, f64)| {
            let _ = writeln!(
                out,
                "| {} | {name} | {n} | {:.1} | {:.1} | {:.2} |",
                sky.name(),
                a * 1e9,
                b * 1e9,
                a / b
            );
            println!(
                "{} {name} N={n}: {:.1} ns vs plain {:.1} ns",
                sky.name(),
                a * 1e9,
                b * 1e9
            );
        };
        pool.install(|| {
            let n = 1 << 20;
            row(
                "InverseCdf",
                n,
                race(n, |n| inverse.samples(n, 1), |n| plain.samples(n, 1)),
            );
            for n in [1 << 10, 1 << 12, 1 << 14, 1 << 20] {
                row(
                    "Stratified",
                    n,
                    race(n, |n| strat.samples(n, 1), |n| plain_strat.samples(n, 1)),
                );
            }
        });
        // the plain versions sample the same pixels: a check of the races
        let (a, b) = (strat.samples(4096, 3), plain_strat.samples(4096, 3));
        let pixel = |d: &DVec3| (map.radiance(*d), (d.z * 1e6).round());
        assert!(
            a.iter()
                .zip(&b)
                .filter(|(x, y)| pixel(x) != pixel(y))
                .count()
                < 4
        );
    }
    out.push('\n');
}

/// The checked-out commit (`git describe --always --dirty`), if git runs.
fn commit() -> String {
    std::process::Command::new("git")
        .args(["describe", "--always", "--dirty"])
        .output()
        .ok()
        .filter(|o| o.status.success())
        .map_or("unknown".into(), |o| {
            String::from_utf8_lossy(&o.stdout).trim().to_string()
        })
}

fn fmt_ratio(x: f64) -> String {
    format!("{x:.2}")
}

fn main() {
    let args = parse_args();
    let started = Instant::now();
    // other work on the machine skews the timings: say how much there was
    let load = std::fs::read_to_string("/proc/loadavg")
        .ok()
        .and_then(|l| l.split_whitespace().next().map(String::from))
        .unwrap_or_else(|| "unknown".into());
    let skies: Vec<Sky> = (Sky::all().iter().copied())
        .filter(|s| {
            args.maps
                .as_ref()
                .is_none_or(|m| m.iter().any(|n| n == s.name()))
        })
        .collect();
    let normals = uniform_random_sphere(NORMALS, NORMAL_SEED);
    let mut speed = String::new();
    if args.timing {
        timing(&mut speed);
    }
    let mut cells = Vec::new();
    for &sky in &skies {
        let t = Instant::now();
        cells.extend(run_map(sky, &args.counts, args.runs, &normals));
        println!("{}: {:.1} s", sky.name(), t.elapsed().as_secs_f64());
    }
    let wall = started.elapsed().as_secs_f64();

    let mut md = String::new();
    let _ = writeln!(
        md,
        "# Unbiasedness and error over random rotations\n\n\
         Generated by `{}` at commit {} ({wall:.0} s wall on {} threads; one-minute load \
         average {load} at the start). Do not edit by hand.\n\n\
         Every generated sky (`Sky::all()`, {WIDTH}x{HEIGHT}, map seed {MAP_SEED}), \
         z up. For each N, R = {} independent randomisations per method, seeds 0..{}: \
         **tessera** `map.with_seed(s).generate(N)` (a uniformly random rotation of the \
         sampling frame); **1-D stratified** `baselines::envmap::Stratified` (one uniform \
         number in each of N equal strata of the row-major CDF over all pixels); \
         **i.i.d. inverse CDF** `baselines::envmap::InverseCdf::samples`; **Owen-Sobol 2-D \
         CDF** Owen-scrambled Sobol points (`baselines::sobol::owen_sobol_2d`, scrambled by \
         the seed) through `InverseCdf::warp`. Each set estimates the irradiance \
         `E(n) = ∫ L(ω) max(0, n·ω) dω` for the same {NORMALS} random unit normals \
         (`uniform_random_sphere({NORMALS}, {NORMAL_SEED:#x})`) as \
         `(integral / N) Σ max(0, n·ω_i)`, samples where the pdf is 0 counting 0 \
         (`metrics::irradiance::estimate`), against `metrics::irradiance::exact`. \
         The relative error of run r on normal k is `e_rk = estimate / reference − 1`.\n\n\
         Columns:\n\n\
         - **bias**: the RMS over the normals of the mean of `e_rk` over the R runs \
           (the part of the error that averaging runs does not remove, plus the noise of \
           the mean, about RMSE / √R);\n\
         - **max |z|**: the largest over the normals of `|mean| / (sd / √R)`, `sd` the \
           sample standard deviation over the runs. Without bias it is the largest of \
           {NORMALS} correlated |t| values with R − 1 degrees of freedom; values above \
           {Z_FLAG} (Bonferroni over the normals at a 1e-3 false-alarm rate per row) are \
           **bold**: bias detected;\n\
         - **RMSE**: the root mean square of `e_rk` over runs and normals;\n\
         - **tessera / this**: tessera's RMSE divided by this method's RMSE (below 1: \
           tessera is more accurate);\n\
         - **tessera fixed**: the unseeded deterministic tessera set (`map.generate(N)`), \
           one set, so its error is the RMS over the normals of its single relative \
           error, not an RMSE; its ratio is to the i.i.d. RMSE.\n",
        args.command,
        commit(),
        rayon::current_num_threads(),
        args.runs,
        args.runs,
    );
    let _ = writeln!(
        md,
        "## Summary: tessera's RMSE over the baselines'\n\n\
         `reference gap`: the largest relative difference over the normals between \
         `exact` (a midpoint rule) and a second reference (the closed form `L n·∫ω dω` on \
         every pixel wholly on one side of the normal's horizon, an 8x8 midpoint rule on \
         the others): the floor below which a bias cannot be told from the reference's \
         own error.\n\n\
         | map | N | / 1-D stratified | / i.i.d. | / Owen-Sobol | fixed error / i.i.d. RMSE | reference gap |\n\
         |---|---|---|---|---|---|---|"
    );
    for c in &cells {
        let t = c.stats[0].rmse;
        let _ = writeln!(
            md,
            "| {} | {} | {} | {} | {} | {} | {:.1e} |",
            c.map,
            c.n,
            fmt_ratio(t / c.stats[1].rmse),
            fmt_ratio(t / c.stats[2].rmse),
            fmt_ratio(t / c.stats[3].rmse),
            fmt_ratio(c.fixed / c.stats[2].rmse),
            c.reference_gap,
        );
    }
    md.push('\n');
    for &n in &args.counts {
        let _ = writeln!(
            md,
            "## N = {n}\n\n\
             | map | method | bias | max \\|z\\| | RMSE | tessera / this |\n\
             |---|---|---|---|---|---|"
        );
        for c in cells.iter().filter(|c| c.n == n) {
            let t = c.stats[0].rmse;
            for (m, s) in METHODS.iter().zip(&c.stats) {
                let z = if s.max_z > Z_FLAG {
                    format!("**{:.1}**", s.max_z)
                } else {
                    format!("{:.1}", s.max_z)
                };
                let ratio = if *m == Method::Tessera {
                    "-".into()
                } else {
                    fmt_ratio(t / s.rmse)
                };
                let _ = writeln!(
                    md,
                    "| {} | {} | {:.2e} | {z} | {:.2e} | {ratio} |",
                    c.map,
                    m.name(),
                    s.bias,
                    s.rmse
                );
            }
            let _ = writeln!(
                md,
                "| {} | tessera fixed (one set's error) | - | - | {:.2e} | {} (to i.i.d.) |",
                c.map,
                c.fixed,
                fmt_ratio(c.fixed / c.stats[2].rmse)
            );
        }
        md.push('\n');
    }
    md.push_str(&speed);
    if let Some(dir) = args.out.parent().filter(|d| !d.as_os_str().is_empty()) {
        std::fs::create_dir_all(dir).expect("the output directory");
    }
    std::fs::write(&args.out, md).expect("writing the report");
    println!("wrote {} in {wall:.0} s", args.out.display());
}

//! Throughput of every tile system at uniform and adaptive density against
//! the baselines, for N from 10^3 to 10^7 in memory and 10^8 streamed into a
//! sink (uniform fast paths only: memory stays bounded), with one and two
//! threads for tessera (the baselines are sequential: one thread).
//!
//! Groups: `sphere/uniform`, `sphere/cap` (adaptive), `sphere/stream` (10^8,
//! one thread: about 20 s an iteration, so the group takes minutes),
//! `plane/uniform`, `plane/ramp` and `plane/raster` (adaptive; the image
//! against inverse-CDF warps of i.i.d. and Sobol points), `envmap/sky`
//! (adaptive on the accuracy bench's generated sky; the hostile-map bench is
//! `envmap.rs`).
//! Run: `cargo bench --bench scaling`; medians are in
//! `target/criterion/<group>/<function>/<N>/new/estimates.json`.

use criterion::{criterion_group, criterion_main, BenchmarkId, Criterion, Throughput};
use glam::DVec3;
use std::hint::black_box;
use std::time::Duration;
use tessera::baselines::cdf::RasterCdf;
use tessera::baselines::envmap::{AliasTable, InverseCdf};
use tessera::baselines::{
    bridson, jittered_healpix_about, sobol, spherical_fibonacci, spherical_fibonacci_into,
    uniform_random_2d, uniform_random_sphere,
};
use tessera::density::plane::Ramp;
use tessera::density::sphere::Cap;
use tessera::density::{Density, Region, Uniform};
use tessera::engine;
use tessera::tiling::penrose::PenroseTiling;
use tessera::tiling::plane::PlaneTiling;
use tessera::tiling::sphere::SphereTiling;
use tessera::tiling::TileSystem;

const IN_MEMORY: [usize; 3] = [1_000, 100_000, 10_000_000];
const STREAMED: usize = 100_000_000;

fn pool(threads: usize) -> rayon::ThreadPool {
    rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()
        .expect("pool")
}

fn quick<'c>(
    c: &'c mut Criterion,
    name: &str,
) -> criterion::BenchmarkGroup<'c, criterion::measurement::WallTime> {
    let mut group = c.benchmark_group(name);
    group
        .sample_size(10)
        .warm_up_time(Duration::from_millis(500))
        .measurement_time(Duration::from_secs(2));
    group
}

/// Tessera on `system` under `density`, one and two threads, every size.
fn tile_system<S, D>(
    c: &mut Criterion,
    group: &str,
    label: &str,
    system: &S,
    density: &D,
    sizes: &[usize],
) where
    S: TileSystem,
    S::Region: Region<Point = S::Point>,
    D: Density<S::Region>,
{
    let mut g = quick(c, group);
    for &n in sizes {
        g.throughput(Throughput::Elements(n as u64));
        for threads in [1, 2] {
            let pool = pool(threads);
            let id = BenchmarkId::new(format!("{label}_{threads}t"), n);
            g.bench_with_input(id, &n, |b, &n| {
                b.iter(|| pool.install(|| black_box(engine::generate(system, density, n, true))))
            });
        }
    }
    g.finish();
}

/// A sequential baseline at every size.
fn baseline<P>(
    c: &mut Criterion,
    group: &str,
    label: &str,
    sizes: &[usize],
    f: impl Fn(usize) -> Vec<P>,
) {
    let mut g = quick(c, group);
    for &n in sizes {
        g.throughput(Throughput::Elements(n as u64));
        g.bench_with_input(BenchmarkId::new(label, n), &n, |b, &n| {
            b.iter(|| black_box(f(n)))
        });
    }
    g.finish();
}

fn sphere(c: &mut Criterion) {
    let tiling = SphereTiling::default();
    tile_system(
        c,
        "sphere/uniform",
        "tessera",
        &tiling,
        &Uniform,
        &IN_MEMORY,
    );
    baseline(
        c,
        "sphere/uniform",
        "fibonacci",
        &IN_MEMORY,
        spherical_fibonacci,
    );
    baseline(c, "sphere/uniform", "iid", &IN_MEMORY, |n| {
        uniform_random_sphere(n, 1)
    });
    baseline(c, "sphere/uniform", "sobol", &IN_MEMORY, |n| {
        sobol::sphere(n, 1)
    });
    baseline(c, "sphere/uniform", "jittered_healpix", &IN_MEMORY, |n| {
        jittered_healpix_about(n, 1)
    });
    let cap = Cap::new(0.0, 45.0, 30.0, 10.0).expect("cap");
    tile_system(c, "sphere/cap", "tessera", &tiling, &cap, &IN_MEMORY[..2]);
    // 10^8 uniform points into a sink: the streaming fast paths
    let mut g = quick(c, "sphere/stream");
    g.sampling_mode(criterion::SamplingMode::Flat);
    g.throughput(Throughput::Elements(STREAMED as u64));
    g.bench_function(BenchmarkId::new("tessera_1t", STREAMED), |b| {
        b.iter(|| {
            let stream = engine::stream(&tiling, STREAMED).expect("uniform stream");
            black_box(stream.fold(DVec3::ZERO, |s, p| s + p.position))
        })
    });
    g.bench_function(BenchmarkId::new("fibonacci", STREAMED), |b| {
        b.iter(|| {
            let mut sum = DVec3::ZERO;
            spherical_fibonacci_into(STREAMED, |p| sum += p);
            black_box(sum)
        })
    });
    g.finish();
}

/// The polyomino systems (Penrose, another tile type, is benchmarked beside them).
fn plane_systems() -> [(&'static str, PlaneTiling); 2] {
    [
        ("ghexomino", PlaneTiling::ghexomino()),
        ("ppentomino", PlaneTiling::ppentomino()),
    ]
}

/// A 256x256 image density (a gradient and a bright disc) against the
/// inverse-CDF baselines over its pixels: i.i.d. and Owen-scrambled Sobol.
fn raster(c: &mut Criterion) {
    let side = 256;
    let values: Vec<f64> = (0..side * side)
        .map(|k| {
            let (x, y) = (
                (k % side) as f64 / side as f64,
                (k / side) as f64 / side as f64,
            );
            let disc = if (x - 0.6).hypot(y - 0.4) < 0.15 {
                20.0
            } else {
                0.0
            };
            0.1 + x + disc
        })
        .collect();
    let image = tessera::density::plane::Raster::new(side, side, values, false).expect("image");
    let sizes = &IN_MEMORY[..2];
    for (name, tiling) in plane_systems() {
        tile_system(c, "plane/raster", name, &tiling, &image, sizes);
    }
    tile_system(
        c,
        "plane/raster",
        "penrose",
        &PenroseTiling::default(),
        &image,
        sizes,
    );
    let cdf = RasterCdf::new(&image).expect("a lit image");
    baseline(c, "plane/raster", "iid_inverse_cdf", sizes, |n| {
        uniform_random_2d(n, 1)
            .into_iter()
            .map(|u| cdf.warp(u))
            .collect()
    });
    baseline(c, "plane/raster", "sobol_inverse_cdf", sizes, |n| {
        sobol::owen_sobol_2d(n, 1)
            .into_iter()
            .map(|u| cdf.warp(u))
            .collect()
    });
}

fn plane(c: &mut Criterion) {
    for (name, tiling) in plane_systems() {
        tile_system(c, "plane/uniform", name, &tiling, &Uniform, &IN_MEMORY);
        tile_system(c, "plane/ramp", name, &tiling, &Ramp, &IN_MEMORY[..2]);
    }
    let penrose = PenroseTiling::default();
    tile_system(
        c,
        "plane/uniform",
        "penrose",
        &penrose,
        &Uniform,
        &IN_MEMORY,
    );
    tile_system(c, "plane/ramp", "penrose", &penrose, &Ramp, &IN_MEMORY[..2]);
    raster(c);
    baseline(c, "plane/uniform", "iid", &IN_MEMORY, |n| {
        uniform_random_2d(n, 1)
    });
    baseline(c, "plane/uniform", "sobol", &IN_MEMORY, |n| {
        sobol::owen_sobol_2d(n, 1)
    });
    // Bridson is ~100x slower per point: up to 10^5
    baseline(c, "plane/uniform", "bridson", &IN_MEMORY[..2], |n| {
        bridson(n, 1)
    });
}

fn envmap(c: &mut Criterion) {
    let map = tessera::accuracy::sky();
    let sizes = &IN_MEMORY[..2];
    let mut g = quick(c, "envmap/sky");
    for &n in sizes {
        g.throughput(Throughput::Elements(n as u64));
        for threads in [1, 2] {
            let pool = pool(threads);
            g.bench_with_input(
                BenchmarkId::new(format!("tessera_{threads}t"), n),
                &n,
                |b, &n| b.iter(|| pool.install(|| black_box(map.generate(n)))),
            );
        }
    }
    g.finish();
    let (inverse, alias) = (InverseCdf::new(&map), AliasTable::new(&map));
    baseline(c, "envmap/sky", "inverse_cdf", sizes, |n| {
        inverse.samples(n, 1)
    });
    baseline(c, "envmap/sky", "alias", sizes, |n| alias.samples(n, 1));
    baseline(c, "envmap/sky", "sobol_inverse_cdf", sizes, |n| {
        let u = sobol::owen_sobol_2d(n, 1);
        u.iter().map(|u| inverse.warp([u.x, u.y])).collect()
    });
}

criterion_group!(benches, sphere, plane, envmap);
criterion_main!(benches);

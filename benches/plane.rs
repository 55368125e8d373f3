//! Planar throughput: tessera's Penrose and polyomino systems at uniform
//! density and on the ramp, one thread, against Bridson's Poisson-disk sampler
//! (`fast_poisson`) in the same run. Run: `cargo bench --bench plane`.
//!
//! Each request is measured twice: into fresh memory (`engine::generate`,
//! paying the first touch of every new page) and into buffers kept across
//! iterations (`engine::generate_into` with `engine::Buffers`, what a
//! renderer drawing a set per frame pays). `fresh_buffer_write_only` writes
//! `N` samples into a fresh `Vec` with no sampling at all: the floor of the
//! first kind. On the ramp, `_unsorted` asks for the same samples without
//! the ranking sort (`engine::Order::Unsorted`).

use criterion::measurement::WallTime;
use criterion::{criterion_group, criterion_main, BenchmarkGroup, Criterion, Throughput};
use glam::DVec2;
use std::hint::black_box;
use tessera::baselines::bridson;
use tessera::density::{plane::Ramp, Density, Uniform};
use tessera::engine::{self, Order, Sample};
use tessera::tiling::penrose::PenroseTiling;
use tessera::tiling::plane::{PlaneRegion, PlaneTiling};
use tessera::tiling::TileSystem;

const N: usize = 2_000_000;

fn one_thread() -> rayon::ThreadPool {
    rayon::ThreadPoolBuilder::new()
        .num_threads(1)
        .build()
        .expect("pool")
}

fn systems() -> [(&'static str, PlaneTiling); 2] {
    [
        ("ghexomino", PlaneTiling::ghexomino()),
        ("ppentomino", PlaneTiling::ppentomino()),
    ]
}

/// `N` samples at uniform density and on the ramp, into fresh and reused
/// buffers.
fn uniform_and_ramp<S>(
    group: &mut BenchmarkGroup<'_, WallTime>,
    pool: &rayon::ThreadPool,
    name: &str,
    tiling: &S,
) where
    S: TileSystem<Point = DVec2, Region = PlaneRegion>,
{
    let densities: [(&str, &dyn Density<PlaneRegion>); 2] =
        [("uniform", &Uniform), ("ramp", &Ramp)];
    for (density_name, density) in densities {
        group.bench_function(format!("{name}_{density_name}"), |b| {
            b.iter(|| pool.install(|| black_box(engine::generate(tiling, density, N, true))))
        });
        let mut buffers = engine::Buffers::default();
        let orders = [("", Order::Progressive), ("_unsorted", Order::Unsorted)];
        // (the uniform fast path comes out in rank order either way)
        let kept = if density_name == "ramp" { 2 } else { 1 };
        for (order_name, order) in &orders[..kept] {
            let id = format!("{name}_{density_name}{order_name}_reused_buffers");
            group.bench_function(id, |b| {
                b.iter(|| {
                    let samples = pool.install(|| {
                        engine::generate_into(tiling, density, N, true, *order, &mut buffers)
                    });
                    black_box(samples.expect("samples").len())
                })
            });
        }
    }
}

fn throughput(c: &mut Criterion) {
    let pool = one_thread();
    let mut group = c.benchmark_group("plane_1_thread");
    group.sample_size(10);
    group.throughput(Throughput::Elements(N as u64));
    group.bench_function("fresh_buffer_write_only", |b| {
        b.iter(|| {
            let written: Vec<Sample<DVec2>> = (0..N)
                .map(|i| Sample {
                    position: DVec2::splat(i as f64),
                    rank: i as f64,
                })
                .collect();
            black_box(written)
        })
    });
    for (name, tiling) in systems() {
        uniform_and_ramp(&mut group, &pool, name, &tiling);
    }
    uniform_and_ramp(&mut group, &pool, "penrose", &PenroseTiling::default());
    let bridson_n = bridson(N / 10, 1).len();
    group.throughput(Throughput::Elements(bridson_n as u64));
    group.bench_function("bridson_fast_poisson", |b| {
        b.iter(|| black_box(bridson(N / 10, 1)))
    });
    group.finish();
}

criterion_group!(benches, throughput);
criterion_main!(benches);

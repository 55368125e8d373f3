//! Planar throughput: tessera's Penrose and polyomino systems at uniform
//! density and on the ramp, one thread, against Bridson's Poisson-disk sampler
//! (`fast_poisson`) in the same run. Run: `cargo bench --bench plane`.

use criterion::measurement::WallTime;
use criterion::{criterion_group, criterion_main, BenchmarkGroup, Criterion, Throughput};
use std::hint::black_box;
use tessera::baselines::bridson;
use tessera::density::{plane::Ramp, Uniform};
use tessera::engine;
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

/// `N` samples at uniform density and on the ramp.
fn uniform_and_ramp<S>(
    group: &mut BenchmarkGroup<'_, WallTime>,
    pool: &rayon::ThreadPool,
    name: &str,
    tiling: &S,
) where
    S: TileSystem<Point = glam::DVec2, Region = PlaneRegion>,
{
    group.bench_function(format!("{name}_uniform"), |b| {
        b.iter(|| pool.install(|| black_box(engine::generate(tiling, &Uniform, N, true))))
    });
    group.bench_function(format!("{name}_ramp"), |b| {
        b.iter(|| pool.install(|| black_box(engine::generate(tiling, &Ramp, N, true))))
    });
}

fn throughput(c: &mut Criterion) {
    let pool = one_thread();
    let mut group = c.benchmark_group("plane_1_thread");
    group.sample_size(10);
    group.throughput(Throughput::Elements(N as u64));
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

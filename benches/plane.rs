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
//! the ranking sort (`engine::Order::Unsorted`). Densities are passed as
//! their concrete types; `_ramp_dyn_` rows pass the ramp as `&dyn Density`,
//! as the command line does.

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
/// buffers; the ramp also behind `&dyn Density`, as the command line holds
/// its density (the other rows use the concrete type, monomorphised, as a
/// library caller naming `Ramp` gets).
fn uniform_and_ramp<S>(
    group: &mut BenchmarkGroup<'_, WallTime>,
    pool: &rayon::ThreadPool,
    name: &str,
    tiling: &S,
) where
    S: TileSystem<Point = DVec2, Region = PlaneRegion>,
{
    // (the uniform fast path comes out in rank order either way)
    let progressive = [("", Order::Progressive)];
    let both = [("", Order::Progressive), ("_unsorted", Order::Unsorted)];
    let id = |density: &str| format!("{name}_{density}");
    requests(
        group,
        pool,
        &id("uniform"),
        tiling,
        &Uniform,
        true,
        &progressive,
    );
    requests(group, pool, &id("ramp"), tiling, &Ramp, true, &both);
    let ramp: &dyn Density<PlaneRegion> = &Ramp;
    requests(
        group,
        pool,
        &id("ramp_dyn"),
        tiling,
        ramp,
        false,
        &progressive,
    );
}

/// `N` samples of `density`: into fresh memory when `fresh`, then into
/// reused buffers in each of `orders`.
fn requests<S, D>(
    group: &mut BenchmarkGroup<'_, WallTime>,
    pool: &rayon::ThreadPool,
    id: &str,
    tiling: &S,
    density: &D,
    fresh: bool,
    orders: &[(&str, Order)],
) where
    S: TileSystem<Point = DVec2, Region = PlaneRegion>,
    D: Density<PlaneRegion> + ?Sized + Sync,
{
    if fresh {
        group.bench_function(id, |b| {
            b.iter(|| pool.install(|| black_box(engine::generate(tiling, density, N, true))))
        });
    }
    let mut buffers = engine::Buffers::default();
    for (order_name, order) in orders {
        group.bench_function(format!("{id}{order_name}_reused_buffers"), |b| {
            b.iter(|| {
                let samples = pool.install(|| {
                    engine::generate_into(tiling, density, N, true, *order, &mut buffers)
                });
                black_box(samples.expect("samples").len())
            })
        });
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

//! Environment maps on the 1024x512 hostile test map (sky gradient, one-pixel
//! sun 10^5 x the sky, negative and NaN pixels):
//! - preprocessing: tessera's `EnvMap::new` (integral; the max pyramid is
//!   built lazily while sampling) against building the inverse-CDF and
//!   alias tables;
//! - per-sample cost at N = 2^18: tessera (one thread, and two; and on one
//!   thread with `Order::Unsorted`, which skips the progressive ranking as
//!   the i.i.d. samplers have none) against i.i.d. inverse-CDF and alias
//!   sampling (one thread), in one run.
//!
//! Run: `cargo bench --bench envmap`.

#[path = "../tests/common/sky.rs"]
mod sky;

use criterion::{criterion_group, criterion_main, Criterion, Throughput};
use std::hint::black_box;
use tessera::baselines::envmap::{AliasTable, InverseCdf, Stratified};
use tessera::density::envmap::{EnvMap, Up};
use tessera::engine::{self, Order};
use tessera::io::image::{read_raster, ReadOptions};
use tessera::tiling::sphere::SphereTiling;

const N: usize = 1 << 18;

fn raster() -> tessera::io::image::Raster {
    let dir = std::env::temp_dir().join("tessera-bench-envmap");
    let [big, _] = sky::write_issue_maps(&dir);
    read_raster(&big, &ReadOptions::default()).expect("the test map")
}

fn preprocessing(c: &mut Criterion) {
    let raster = raster();
    let map = EnvMap::new(raster.clone(), Up::Z).expect("map");
    let mut group = c.benchmark_group("envmap_1024x512_preprocess");
    group.sample_size(20);
    group.bench_function("tessera_envmap_new", |b| {
        b.iter(|| black_box(EnvMap::new(raster.clone(), Up::Z).expect("map")))
    });
    group.bench_function("inverse_cdf_new", |b| {
        b.iter(|| black_box(InverseCdf::new(&map)))
    });
    group.bench_function("alias_table_new", |b| {
        b.iter(|| black_box(AliasTable::new(&map)))
    });
    group.finish();
}

fn per_sample(c: &mut Criterion) {
    let map = EnvMap::new(raster(), Up::Z).expect("map");
    let (inverse, alias) = (InverseCdf::new(&map), AliasTable::new(&map));
    let mut group = c.benchmark_group("envmap_1024x512_sample_2e18");
    group.sample_size(10);
    group.throughput(Throughput::Elements(N as u64));
    for threads in [1, 2] {
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .expect("pool");
        group.bench_function(format!("tessera_{threads}_thread"), |b| {
            b.iter(|| pool.install(|| black_box(map.generate(N).expect("samples"))))
        });
    }
    let one = rayon::ThreadPoolBuilder::new()
        .num_threads(1)
        .build()
        .expect("pool");
    let sphere = SphereTiling::default();
    group.bench_function("tessera_1_thread_unsorted", |b| {
        b.iter(|| {
            one.install(|| {
                let samples = engine::generate_ordered(&sphere, &map, N, true, Order::Unsorted);
                black_box(samples.expect("samples"))
            })
        })
    });
    group.bench_function("inverse_cdf_1_thread", |b| {
        b.iter(|| black_box(inverse.samples(N, 1)))
    });
    group.bench_function("alias_1_thread", |b| {
        b.iter(|| black_box(alias.samples(N, 1)))
    });
    let stratified = Stratified::new(&map);
    group.bench_function("stratified_1_thread", |b| {
        b.iter(|| black_box(stratified.samples(N, 1)))
    });
    group.finish();
}

criterion_group!(benches, preprocessing, per_sample);
criterion_main!(benches);

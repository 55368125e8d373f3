//! Environment maps on the 1024x512 hostile test map (sky gradient, one-pixel
//! sun 10^5 x the sky, negative and NaN pixels):
//! - preprocessing: tessera's `EnvMap::new` (integral; the max pyramid is
//!   built lazily while sampling) against building the inverse-CDF and
//!   alias tables;
//! - per-sample cost at N = 2^18: tessera (one thread, and two; and on one
//!   thread with `Order::Unsorted`, which skips the progressive ranking as
//!   the i.i.d. samplers have none) against i.i.d. inverse-CDF and alias
//!   sampling (one thread), in one run; and `plain_inverse_cdf`, the
//!   i.i.d. inverse-CDF sampler written again the obvious way (f64 CDFs
//!   over luminance x solid angle, two binary searches, a direction by
//!   trigonometry), to check that the library's baseline is as fast as
//!   plain code.
//!
//! Every row generates directions into memory; whole-process timings
//! (reading the file, writing the samples) are `scripts/whole-process.sh`.
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
    let plain = PlainInverseCdf::new(&map);
    group.bench_function("plain_inverse_cdf_1_thread", |b| {
        b.iter(|| black_box(plain.samples(N, 1)))
    });
    let stratified = Stratified::new(&map);
    group.bench_function("stratified_1_thread", |b| {
        b.iter(|| black_box(stratified.samples(N, 1)))
    });
    group.finish();
}

/// The i.i.d. inverse-CDF sampler as a user would write it, independently
/// of `tessera::baselines` (a second implementation to check the
/// baseline's speed against).
struct PlainInverseCdf {
    width: usize,
    height: usize,
    rows: Vec<f64>,
    columns: Vec<f64>,
}

impl PlainInverseCdf {
    fn new(map: &EnvMap) -> Self {
        use std::f64::consts::PI;
        let (width, height) = (map.width(), map.height());
        let mut rows = vec![0.0; height + 1];
        let mut columns = vec![0.0; height * (width + 1)];
        for j in 0..height {
            let omega = (2.0 * PI / width as f64)
                * ((j as f64 * PI / height as f64).cos()
                    - ((j + 1) as f64 * PI / height as f64).cos());
            let cdf = &mut columns[j * (width + 1)..(j + 1) * (width + 1)];
            for i in 0..width {
                cdf[i + 1] = cdf[i] + map.values()[j * width + i] * omega;
            }
            rows[j + 1] = rows[j] + cdf[width];
        }
        PlainInverseCdf {
            width,
            height,
            rows,
            columns,
        }
    }

    fn samples(&self, n: usize, seed: u64) -> Vec<glam::DVec3> {
        use std::f64::consts::PI;
        let (w, h) = (self.width, self.height);
        let mut rng = tessera::baselines::SplitMix64::new(seed);
        (0..n)
            .map(|_| {
                let u = rng.next_f64() * self.rows[h];
                let j = self.rows[1..].partition_point(|&c| c <= u).min(h - 1);
                let cdf = &self.columns[j * (w + 1)..(j + 1) * (w + 1)];
                let v = rng.next_f64() * cdf[w];
                let i = cdf[1..].partition_point(|&c| c <= v).min(w - 1);
                let a = (j as f64 * PI / h as f64).cos();
                let b = ((j + 1) as f64 * PI / h as f64).cos();
                let z = a + (b - a) * rng.next_f64();
                let r = (1.0 - z * z).max(0.0).sqrt();
                let phi = 2.0 * PI * (i as f64 + rng.next_f64()) / w as f64;
                let (s, c) = phi.sin_cos();
                glam::DVec3::new(r * c, r * s, z)
            })
            .collect()
    }
}

criterion_group!(benches, preprocessing, per_sample);
criterion_main!(benches);

//! Sphere throughput in memory: tessera at uniform density against the
//! spherical Fibonacci lattice, 10^7 points each into buffers kept between
//! iterations (so no side pays for fresh pages), in one run. The library's
//! Fibonacci (`baselines::spherical_fibonacci_into`, which reduces the
//! azimuth exactly, in 128-bit fixed point) runs beside `plain_fibonacci`,
//! the lattice written the obvious way, to check that the baseline is as
//! fast as plain code. Whole-process timings (writing the points, against plain
//! programs) are `scripts/whole-process.sh`. Run: `cargo bench --bench
//! sphere`.

use criterion::{criterion_group, criterion_main, Criterion, Throughput};
use glam::DVec3;
use std::hint::black_box;
use tessera::baselines::spherical_fibonacci_into;
use tessera::density::Uniform;
use tessera::engine::{self, Buffers, Order};
use tessera::tiling::sphere::SphereTiling;

const N: usize = 10_000_000;

/// `z = 1 - (2i+1)/n`, azimuth `2 pi frac(i / golden ratio)`.
fn plain_fibonacci(n: usize, out: &mut Vec<DVec3>) {
    let inv_phi = (5f64.sqrt() - 1.0) / 2.0;
    out.extend((0..n).map(|i| {
        let z = 1.0 - (2 * i + 1) as f64 / n as f64;
        let r = (1.0 - z * z).sqrt();
        let (s, c) = (std::f64::consts::TAU * (i as f64 * inv_phi).fract()).sin_cos();
        DVec3::new(r * c, r * s, z)
    }));
}

fn uniform_throughput(c: &mut Criterion) {
    let mut group = c.benchmark_group("sphere_uniform_1e7_in_memory");
    group.sample_size(10);
    group.throughput(Throughput::Elements(N as u64));
    let tiling = SphereTiling::default();
    for threads in [1, 2] {
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .expect("pool");
        let mut buffers = Buffers::default();
        group.bench_function(format!("tessera_{threads}_thread"), |b| {
            b.iter(|| {
                pool.install(|| {
                    let order = Order::Progressive;
                    let samples =
                        engine::generate_into(&tiling, &Uniform, N, true, order, &mut buffers);
                    black_box(samples.expect("uniform sampling").len())
                })
            })
        });
    }
    let mut points = Vec::with_capacity(N);
    group.bench_function("fibonacci_1_thread", |b| {
        b.iter(|| {
            points.clear();
            spherical_fibonacci_into(N, |p| points.push(p));
            black_box(points.len())
        })
    });
    group.bench_function("plain_fibonacci_1_thread", |b| {
        b.iter(|| {
            points.clear();
            plain_fibonacci(N, &mut points);
            black_box(points.len())
        })
    });
    group.finish();
}

criterion_group!(benches, uniform_throughput);
criterion_main!(benches);

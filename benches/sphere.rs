//! Sphere throughput: tessera at uniform density against a plain spherical
//! Fibonacci generator, both producing 10^7 points and writing the same UTK
//! binary bytes into memory. Run: `cargo bench --bench sphere`.

use criterion::{criterion_group, criterion_main, Criterion, Throughput};
use std::hint::black_box;
use tessera::baselines::spherical_fibonacci;
use tessera::io::points::{write_sphere, SphereFormat};
use tessera::Sampler;

const N: usize = 10_000_000;

fn to_bytes<I>(points: I) -> Vec<u8>
where
    I: IntoIterator<Item = glam::DVec3>,
    I::IntoIter: ExactSizeIterator,
{
    let points = points.into_iter();
    let mut out = Vec::with_capacity(20 + 24 * points.len());
    write_sphere(&mut out, points, SphereFormat::Bin, |_| 0.0).expect("writing to memory");
    out
}

fn uniform_throughput(c: &mut Criterion) {
    let mut group = c.benchmark_group("sphere_uniform_1e7_to_bin");
    group.sample_size(10);
    group.throughput(Throughput::Elements(N as u64));
    let sampler = Sampler::sphere().count(N);
    for threads in [1, 2] {
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .expect("pool");
        group.bench_function(format!("tessera_{threads}_thread"), |b| {
            b.iter(|| {
                pool.install(|| {
                    let samples = sampler.generate().expect("uniform sampling");
                    black_box(to_bytes(samples.iter().map(|s| s.position)))
                })
            })
        });
    }
    group.bench_function("fibonacci_1_thread", |b| {
        b.iter(|| black_box(to_bytes(spherical_fibonacci(N))))
    });
    group.finish();
}

criterion_group!(benches, uniform_throughput);
criterion_main!(benches);

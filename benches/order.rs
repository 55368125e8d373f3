//! The farthest-first order (`Order::FarthestFirst`, `--farthest-first`)
//! against the progressive and unsorted orders of the same request, and
//! against exact farthest-point ordering with a binary heap
//! (`baselines::farthest_point`) run on the unsorted request's points: all
//! from `Sampler::sphere()`, on the machine's threads (the orderings
//! themselves are sequential). Run: `cargo bench --bench order`.

use criterion::{criterion_group, criterion_main, Criterion, Throughput};
use std::hint::black_box;
use tessera::baselines::farthest_point::farthest_point_order;
use tessera::density::region::Regions;
use tessera::engine::Order;
use tessera::Sampler;

fn orders(c: &mut Criterion) {
    let mut group = c.benchmark_group("sphere_order");
    group.sample_size(10);
    for n in [200_000, 1_000_000] {
        group.throughput(Throughput::Elements(n as u64));
        let request = Sampler::sphere().count(n);
        for (name, order) in [
            ("progressive", Order::Progressive),
            ("unsorted", Order::Unsorted),
            ("farthest_first", Order::FarthestFirst),
        ] {
            let request = request.clone().order(order);
            group.bench_function(format!("uniform_{n}_{name}"), |b| {
                b.iter(|| black_box(request.generate().expect("uniform").len()))
            });
        }
        let unsorted = request.clone().order(Order::Unsorted);
        group.bench_function(format!("uniform_{n}_exact_heap_baseline"), |b| {
            b.iter(|| {
                let samples = unsorted.generate().expect("uniform");
                let points: Vec<_> = samples.iter().map(|s| s.position).collect();
                black_box(farthest_point_order(&points).len())
            })
        });
    }
    let cap = Regions::parse(&["cap:20,40,25,16"]).expect("cap");
    let adaptive = Sampler::sphere().density(cap).count(200_000);
    group.throughput(Throughput::Elements(200_000));
    for (name, order) in [
        ("progressive", Order::Progressive),
        ("farthest_first", Order::FarthestFirst),
    ] {
        let request = adaptive.clone().order(order);
        group.bench_function(format!("cap_contrast_16_200000_{name}"), |b| {
            b.iter(|| black_box(request.generate().expect("cap").len()))
        });
    }
    group.finish();
}

criterion_group!(benches, orders);
criterion_main!(benches);

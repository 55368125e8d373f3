//! `relax` (the `--relax K` Lloyd iterations) on a tessera set of 10^6
//! uniform points and of 2·10^5 points following a cap of contrast 16
//! (the density-weighted path: cells across the cap's rim split in four),
//! one iteration a run, on the machine's threads. Run: `cargo bench --bench relax`.

use criterion::{criterion_group, criterion_main, BatchSize, Criterion, Throughput};
use glam::DVec3;
use std::hint::black_box;
use tessera::density::region::Regions;
use tessera::density::{Density, Uniform};
use tessera::relax::relax;
use tessera::tiling::sphere::SphereRegion;
use tessera::Sampler;

fn positions(samples: Vec<tessera::Sample<DVec3>>) -> Vec<DVec3> {
    samples.into_iter().map(|s| s.position).collect()
}

fn one_iteration(c: &mut Criterion) {
    let mut group = c.benchmark_group("relax_one_iteration");
    group.sample_size(10);
    let uniform = positions(
        Sampler::sphere()
            .count(1_000_000)
            .generate()
            .expect("uniform"),
    );
    let cap = Regions::parse(&["cap:20,40,25,16"]).expect("cap");
    let adaptive = Sampler::sphere().density(cap.clone()).count(200_000);
    let adaptive = positions(adaptive.generate().expect("cap"));
    let cases: [(&str, &Vec<DVec3>, &(dyn Density<SphereRegion> + Sync)); 2] = [
        ("uniform_1e6", &uniform, &Uniform),
        ("cap_contrast_16_2e5", &adaptive, &cap),
    ];
    for (name, set, density) in cases {
        group.throughput(Throughput::Elements(set.len() as u64));
        group.bench_function(name, |b| {
            b.iter_batched_ref(
                || set.clone(),
                |p| {
                    relax(p, density, 1).expect("unit vectors");
                    black_box(p.len())
                },
                BatchSize::LargeInput,
            )
        });
    }
    group.finish();
}

criterion_group!(benches, one_iteration);
criterion_main!(benches);

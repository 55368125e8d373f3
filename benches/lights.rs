//! An environment map to N = 4096 lights on one thread, load included: the
//! 1024 x 512 clear-sky map (f32 EXR, ZIP) read from disk, then tessera's
//! lights at Lloyd step counts 0 to 8 (the default at N = 4096,
//! `default_lloyd_steps`, is marked) beside classic and greedy median cut.
//! The floor: under 0.5 s for tessera.
//!
//! Run: `cargo bench --bench lights`.

use criterion::{criterion_group, criterion_main, Criterion};
use std::hint::black_box;
use std::path::Path;
use tessera::baselines::median_cut::{median_cut, MedianCut};
use tessera::density::envmap::{EnvMap, Up};
use tessera::lights::{lights, read_rgb, LightOptions, RgbMap};
use tessera::synth::Sky;

const N: usize = 4096;

/// Reads the map's colour and importance in one decode, as the CLI does.
fn load(path: &Path) -> (RgbMap, EnvMap) {
    let (rgb, raster) = read_rgb(path, &Default::default()).expect("the map");
    let map = EnvMap::new(raster, Up::Z).expect("a lit map");
    (rgb, map)
}

fn to_lights(c: &mut Criterion) {
    let dir = std::env::temp_dir().join(format!("tessera-bench-lights-{}", std::process::id()));
    std::fs::create_dir_all(&dir).expect("temp dir");
    let path = dir.join("clear-sky-1024x512.exr");
    Sky::ClearSky
        .generate(1024, 512, 1)
        .write_exr(&path, false)
        .expect("write the map");
    let one = rayon::ThreadPoolBuilder::new()
        .num_threads(1)
        .build()
        .expect("pool");
    let mut group = c.benchmark_group("lights_1024x512_n4096_1_thread");
    group.sample_size(10);
    group.bench_function("load_only", |b| {
        b.iter(|| one.install(|| black_box(load(&path))))
    });
    let default_steps = tessera::lights::default_lloyd_steps(N);
    for steps in [0, 2, 3, 4, 5, 6, 8] {
        let label = if steps == default_steps {
            format!("tessera_lloyd_{steps}_default")
        } else {
            format!("tessera_lloyd_{steps}")
        };
        group.bench_function(label, |b| {
            b.iter(|| {
                one.install(|| {
                    let (rgb, map) = load(&path);
                    let options = LightOptions {
                        rgb: Some(&rgb),
                        lloyd_steps: Some(steps),
                        ..Default::default()
                    };
                    black_box(lights(&map, N, &options).expect("lights"))
                })
            })
        });
    }
    for variant in MedianCut::all() {
        group.bench_function(format!("median_cut_{}", variant.name()), |b| {
            b.iter(|| {
                one.install(|| {
                    let (rgb, map) = load(&path);
                    black_box(median_cut(&map, Some(&rgb), N, variant).expect("cut"))
                })
            })
        });
    }
    group.finish();
    std::fs::remove_dir_all(&dir).ok();
}

criterion_group!(benches, to_lights);
criterion_main!(benches);

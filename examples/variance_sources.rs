//! Where tessera's irradiance error over random rotations comes from: the
//! RMSE (64 normals, R rotations) on a constant map, on a horizon step
//! (sky 1, ground 0.1) sharp and smoothed over a band of z, and on named
//! generated skies, beside the 1-D stratified inverse CDF; on the constant
//! map also the uniform engine path (`Sampler::sphere()` in a rotated
//! frame) and the randomly rotated spherical Fibonacci lattice.
//!
//!     cargo run --release --example variance_sources [-- --runs 32 clear-sky smooth ...]

use glam::DVec3;
use rayon::prelude::*;
use tessera::baselines::envmap::Stratified;
use tessera::baselines::{random_rotation, spherical_fibonacci, uniform_random_sphere};
use tessera::density::envmap::{EnvMap, Up};
use tessera::density::{sphere::Rotated, Uniform};
use tessera::metrics::irradiance::exact;
use tessera::synth::{Sky, SynthMap};
use tessera::Sampler;

const WIDTH: usize = 1024;
const HEIGHT: usize = 512;

/// RMS over sets and normals of the relative irradiance error.
fn rmse(map: &EnvMap, normals: &[DVec3], reference: &[f64], sets: &[Vec<DVec3>]) -> f64 {
    let mut sq = 0.0;
    for set in sets {
        let scale = map.integral() / set.len() as f64;
        let live: Vec<DVec3> = set.iter().copied().filter(|&d| map.pdf(d) > 0.0).collect();
        for (n, r) in normals.iter().zip(reference) {
            let e = live.iter().map(|d| n.dot(*d).max(0.0)).sum::<f64>() * scale / r - 1.0;
            sq += e * e;
        }
    }
    (sq / (sets.len() * normals.len()) as f64).sqrt()
}

/// Sky 1 over ground 0.1, the step smoothed (smoothstep) over `|z| < band`.
fn horizon(band: f64) -> SynthMap {
    let mut rgb = vec![[0.0f32; 3]; WIDTH * HEIGHT];
    for (j, row) in rgb.chunks_mut(WIDTH).enumerate() {
        let z = 1.0 - (j as f64 + 0.5) * 2.0 / HEIGHT as f64;
        let t = match band > 0.0 {
            true => ((z / band + 1.0) / 2.0).clamp(0.0, 1.0),
            false => f64::from(u8::from(z > 0.0)),
        };
        row.fill([(0.1 + 0.9 * t * t * (3.0 - 2.0 * t)) as f32; 3]);
    }
    SynthMap {
        width: WIDTH,
        height: HEIGHT,
        rgb,
    }
}

fn positions(samples: Vec<tessera::Sample<DVec3>>) -> Vec<DVec3> {
    samples.into_iter().map(|s| s.position).collect()
}

fn main() {
    let mut runs = 32u64;
    let mut skies = Vec::new();
    let mut args = std::env::args().skip(1);
    while let Some(a) = args.next() {
        match a.as_str() {
            "--runs" => runs = args.next().and_then(|r| r.parse().ok()).expect("--runs R"),
            name => skies.push(Sky::from_name(name).unwrap_or_else(|| panic!("no sky {name}"))),
        }
    }
    let normals = uniform_random_sphere(64, 0x6e6f_726d);
    let constant = SynthMap {
        width: WIDTH,
        height: HEIGHT,
        rgb: vec![[1.0; 3]; WIDTH * HEIGHT],
    };
    let mut maps = vec![
        ("constant".to_string(), constant),
        ("horizon step".into(), horizon(0.0)),
        ("step over |z| < 0.05".into(), horizon(0.05)),
        ("step over |z| < 0.2".into(), horizon(0.2)),
    ];
    maps.extend(
        skies
            .iter()
            .map(|s| (s.name().to_string(), s.generate(WIDTH, HEIGHT, 1))),
    );
    println!("RMSE of the relative irradiance over {runs} rotations and 64 normals\n");
    println!(
        "| map | N | tessera | 1-D stratified | tessera / stratified | uniform path | Fibonacci |"
    );
    println!("|---|---|---|---|---|---|---|");
    for (name, synth) in &maps {
        let map = EnvMap::new(synth.raster(), Up::Z).expect("a valid map");
        let reference = exact(&map, &normals);
        let stratified = Stratified::new(&map);
        for n in [1024usize, 4096, 16384] {
            let tessera: Vec<Vec<DVec3>> = (0..runs)
                .into_par_iter()
                .map(|s| positions(map.with_seed(s).generate(n).expect("samples")))
                .collect();
            let strat: Vec<Vec<DVec3>> = (0..runs).map(|s| stratified.samples(n, s)).collect();
            let (t, s) = (
                rmse(&map, &normals, &reference, &tessera),
                rmse(&map, &normals, &reference, &strat),
            );
            let (mut uniform, mut fibonacci) = ("-".to_string(), "-".to_string());
            if name == "constant" {
                let sets: Vec<Vec<DVec3>> = (0..runs)
                    .into_par_iter()
                    .map(|seed| {
                        let frame = Rotated::new(Uniform, seed);
                        let rotation = random_rotation(seed);
                        let set = Sampler::sphere().density(frame).count(n).generate();
                        positions(set.expect("samples"))
                            .into_iter()
                            .map(|p| rotation * p)
                            .collect()
                    })
                    .collect();
                uniform = format!("{:.2e}", rmse(&map, &normals, &reference, &sets));
                let sets: Vec<Vec<DVec3>> = (0..runs)
                    .map(|seed| {
                        let q = random_rotation(seed);
                        spherical_fibonacci(n).into_iter().map(|p| q * p).collect()
                    })
                    .collect();
                fibonacci = format!("{:.2e}", rmse(&map, &normals, &reference, &sets));
            }
            println!(
                "| {name} | {n} | {t:.2e} | {s:.2e} | {:.2} | {uniform} | {fibonacci} |",
                t / s
            );
        }
    }
}

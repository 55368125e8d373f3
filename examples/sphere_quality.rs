//! Prints the uniform-sphere quality tables of the README: tessera against
//! the spherical Fibonacci lattice, jittered HEALPix and uniform random
//! points, then a sweep over every N from 1000 to 3800 in steps of 100
//! (level 2, between and on the importance bins).
//! Run: `cargo run --release --example sphere_quality`.

use tessera::baselines::{jittered_healpix, spherical_fibonacci, uniform_random_sphere};
use tessera::metrics::{sphere_report, SphereMeasure::*};
use tessera::Sampler;

fn tessera_points(n: usize) -> Vec<glam::DVec3> {
    Sampler::sphere()
        .count(n)
        .generate()
        .expect("uniform sampling")
        .iter()
        .map(|s| s.position)
        .collect()
}

fn main() {
    println!("| N | point set | separation | cap discrepancy L2 | (E - N^2)/N^1.5 | covering x sqrt(N) | mesh ratio |");
    println!("|---|---|---|---|---|---|---|");
    for (n, nside) in [(3072usize, 16usize), (12288, 32)] {
        let sets = [
            ("tessera", tessera_points(n)),
            ("spherical Fibonacci", spherical_fibonacci(n)),
            ("jittered HEALPix (seed 1)", jittered_healpix(nside, 1)),
            ("uniform random (seed 1)", uniform_random_sphere(n, 1)),
        ];
        for (name, points) in sets {
            let r = sphere_report(&points);
            println!(
                "| {n} | {name} | {:.3} | {:.3e} | {:.4} | {:.3} | {:.3} |",
                r[Separation], r[CapDiscrepancy], r[Energy], r[Covering], r[MeshRatio]
            );
        }
    }
    let mut ratios = Vec::new();
    let (mut separation, mut energy) = (f64::INFINITY, f64::NEG_INFINITY);
    for n in (1000..=3800).step_by(100) {
        let r = sphere_report(&tessera_points(n));
        let fibonacci = sphere_report(&spherical_fibonacci(n));
        ratios.push(r[CapDiscrepancy] / fibonacci[CapDiscrepancy]);
        separation = separation.min(r[Separation]);
        energy = energy.max(r[Energy]);
    }
    ratios.sort_by(f64::total_cmp);
    println!();
    println!("| sweep N = 1000..3800 step 100 | cap discrepancy / Fibonacci's: min | median | max | lowest separation | highest (E - N^2)/N^1.5 |");
    println!("|---|---|---|---|---|---|");
    println!(
        "| tessera, {} sets | {:.3} | {:.3} | {:.3} | {:.3} | {:.4} |",
        ratios.len(),
        ratios[0],
        ratios[ratios.len() / 2],
        ratios[ratios.len() - 1],
        separation,
        energy
    );
}

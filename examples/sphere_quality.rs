//! Prints the uniform-sphere quality table of the README: tessera against the
//! spherical Fibonacci lattice, jittered HEALPix and uniform random points.
//! Run: `cargo run --release --example sphere_quality`.

use tessera::baselines::{jittered_healpix, spherical_fibonacci, uniform_random_sphere};
use tessera::metrics::sphere_report;
use tessera::Sampler;

fn main() {
    println!("| N | point set | separation | cap discrepancy L2 | (E - N^2)/N^1.5 | covering x sqrt(N) | mesh ratio |");
    println!("|---|---|---|---|---|---|---|");
    for (n, nside) in [(3072usize, 16usize), (12288, 32)] {
        let tessera: Vec<glam::DVec3> = Sampler::sphere()
            .count(n)
            .generate()
            .expect("uniform sampling")
            .iter()
            .map(|s| s.position)
            .collect();
        let sets = [
            ("tessera", tessera),
            ("spherical Fibonacci", spherical_fibonacci(n)),
            ("jittered HEALPix (seed 1)", jittered_healpix(nside, 1)),
            ("uniform random (seed 1)", uniform_random_sphere(n, 1)),
        ];
        for (name, points) in sets {
            let r = sphere_report(&points);
            println!(
                "| {n} | {name} | {:.3} | {:.3e} | {:.4} | {:.3} | {:.3} |",
                r.separation,
                r.cap_discrepancy_l2,
                r.riesz1_normalized,
                r.covering_radius,
                r.mesh_ratio
            );
        }
    }
}

//! The library snippet of README.md, verbatim: `tests/readme.rs` checks that
//! the README's `rust` block is exactly the body of this `main`.
//! Run: `cargo run --release --example readme`.

fn main() {
    use tessera::density::{plane::Ramp, sphere::Cap, sphere::SphereFn};
    use tessera::{engine::Buffers, tiling::plane::PlaneTiling, Sampler};

    // 4096 directions, ten times denser in a 30-degree cap around the north pole
    let cap = Cap::new(0.0, 90.0, 30.0, 10.0).expect("a valid cap"); // lon, lat, radius (deg), contrast
    let sphere = Sampler::sphere().density(cap).count(4096);
    let samples = sphere.generate().expect("4096 samples");
    let first = samples[0].position; // glam::DVec3, unit length
    let pdf = sphere.pdf(first); // per steradian
    println!("{} directions, pdf {pdf:.4} at {first}", samples.len());

    // any closure, with a Lipschitz constant (per radian) that keeps tile bounds conservative
    let lobe = SphereFn::new(|v| 1.0 + v.z, 1.0).expect("a positive mean");
    let lit = Sampler::sphere().density(lobe).count(1000);
    let up = lit.generate().expect("1000 samples");
    let north = up.iter().filter(|s| s.position.z > 0.0).count();
    println!("{north} of 1000 in the northern hemisphere");

    // the unit square, density proportional to x, into buffers kept between frames
    let ramp = Sampler::new(PlaneTiling::ghexomino()).density(Ramp);
    let mut buffers = Buffers::default();
    for count in [20_000, 5_000, 20_000] {
        let request = ramp.clone().count(count);
        let points = request.generate_into(&mut buffers).expect("the points");
        println!("{count} points, the first at {}", points[0].position);
    }
}

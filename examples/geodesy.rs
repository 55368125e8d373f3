//! A quasi-uniform global point set refined over a region, written as
//! GeoJSON, with its separation, covering radius and mesh ratio.
//!
//!     cargo run --release --example geodesy [OUT.geojson]
//!
//! The region is a lon/lat box over Europe (-10..40 E, 35..70 N) sampled
//! 16 times denser (4 times finer spacing) than the rest of the globe, plus
//! a 10-degree cap around Iceland 36 times denser. It prints the minimum
//! distance within each density level in units of the local spacing, and
//! the whole set's separation, covering radius and mesh ratio next to a
//! uniform (spherical Fibonacci) set of the same size, the same three in
//! units of the local spacing (`metrics::sphere::local_spacing`, what
//! `tessera sphere --report` prints), and the local separation near and
//! away from the edge of a single refined cap.

use glam::DVec3;
use tessera::baselines::spherical_fibonacci;
use tessera::density::region::Regions;
use tessera::density::Density;
use tessera::io::points::{write_sphere, SphereFormat};
use tessera::metrics::sphere::{covering_radius, local_spacing, mesh_ratio, separation};
use tessera::tiling::sphere::SphereRegion;
use tessera::{engine, Sampler};

fn main() -> Result<(), tessera::Error> {
    let out = std::env::args()
        .nth(1)
        .unwrap_or_else(|| "geodesy.geojson".into());
    let regions = Regions::parse(&["polygon:-10 35,40 35,40 70,-10 70;16", "cap:-19,65,10,36"])?;
    let n = 20_000;
    let sampler = Sampler::sphere().density(regions.clone()).count(n);
    let points: Vec<DVec3> = sampler.generate()?.iter().map(|s| s.position).collect();
    let value = |p: DVec3| Density::<SphereRegion>::value(&regions, p);
    // solid angle of each density level, by an equal-area quadrature
    let quad = spherical_fibonacci(200_000);
    let area = |v: f64| {
        quad.iter().filter(|&&p| value(p) == v).count() as f64 / quad.len() as f64
            * 4.0
            * std::f64::consts::PI
    };
    println!("| points | density | count | local separation | ");
    println!("|---|---|---|---|");
    for v in [1.0, 16.0, 36.0] {
        let subset: Vec<DVec3> = points.iter().copied().filter(|&p| value(p) == v).collect();
        // minimum distance within the subset, in units of the spacing of a
        // uniform set with the subset's local density (uniform sets: ~2.9)
        let local = separation(&subset) / (subset.len() as f64).sqrt()
            * (subset.len() as f64 * 4.0 * std::f64::consts::PI / area(v)).sqrt();
        println!("| refined | {v} | {} | {local:.3} |", subset.len());
    }
    for (name, set) in [("refined", &points), ("uniform", &spherical_fibonacci(n))] {
        println!(
            "{name}: separation {:.3}, covering radius x sqrt(N) {:.3}, mesh ratio {:.3}",
            separation(set),
            covering_radius(set),
            mesh_ratio(set)
        );
    }
    // the whole set in units of the local spacing (what `tessera sphere
    // --report` prints)
    let local = local_spacing(&points, |p| engine::pdf(sampler.system(), &regions, p));
    println!(
        "refined, in units of the local spacing: separation {:.3}, covering radius {:.3}, mesh ratio {:.3}",
        local.separation, local.covering_radius, local.mesh_ratio
    );
    // where the close pairs are: a single cap, measured outside it and
    // beyond 10 degrees from its edge
    let cap = Regions::parse(&["cap:0,90,30,16"])?;
    let set: Vec<DVec3> = Sampler::sphere()
        .density(cap)
        .count(n)
        .generate()?
        .iter()
        .map(|s| s.position)
        .collect();
    for (name, edge_deg) in [
        ("outside the cap", 30.0f64),
        ("beyond 10 deg of its edge", 40.0),
    ] {
        let z = edge_deg.to_radians().cos();
        let subset: Vec<DVec3> = set.iter().copied().filter(|p| p.z < z).collect();
        let area = 2.0 * std::f64::consts::PI * (1.0 + z);
        let local = separation(&subset) / (subset.len() as f64).sqrt()
            * (subset.len() as f64 * 4.0 * std::f64::consts::PI / area).sqrt();
        println!(
            "cap:0,90,30,16, {name}: {} points, local separation {local:.3}",
            subset.len()
        );
    }
    let tiling = sampler.system();
    let mut file = std::io::BufWriter::new(std::fs::File::create(&out).map_err(|source| {
        tessera::Error::Io {
            path: out.clone().into(),
            source,
        }
    })?);
    write_sphere(
        &mut file,
        points.iter().copied(),
        SphereFormat::GeoJson,
        |p| engine::pdf(tiling, &regions, p),
    )
    .map_err(|source| tessera::Error::Io {
        path: out.clone().into(),
        source,
    })?;
    eprintln!("wrote {n} points to {out}");
    Ok(())
}

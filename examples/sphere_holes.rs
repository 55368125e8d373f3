//! Where a uniform sphere set leaves holes: a spherical Fibonacci grid of
//! probes (200 a point up to N = 10^5, 60 above), each probe's distance to
//! its nearest point times √N, and the holes, probes wider than 3.2 / √N
//! taken widest first and at least 2.5 / √N apart, counted by width with
//! the widest listed with their z. The covering radius of
//! `tessera metrics sphere` is the widest hole's exact value; this shows
//! how many holes come near it.
//!
//!     cargo run --release --example sphere_holes -- [--table PATH] N [N ...]
//!
//! `--table` samples with another sphere table (`tessera lut build`).

use glam::DVec3;
use kiddo::{ImmutableKdTree, SquaredEuclidean};
use rayon::prelude::*;
use std::sync::Arc;
use tessera::baselines::spherical_fibonacci_into;
use tessera::lut::SphereLut;
use tessera::tiling::sphere::SphereTiling;
use tessera::Sampler;

const USAGE: &str = "usage: sphere_holes [--table PATH] N [N ...]";

fn main() {
    let mut args: Vec<String> = std::env::args().skip(1).collect();
    let tiling = match args.iter().position(|a| a == "--table") {
        Some(k) => {
            let path = args.get(k + 1).expect(USAGE).clone();
            args.drain(k..k + 2);
            let bytes = std::fs::read(&path).unwrap_or_else(|e| panic!("{path}: {e}"));
            let lut = SphereLut::from_bytes(&bytes).unwrap_or_else(|e| panic!("{path}: {e}"));
            SphereTiling::new(Arc::new(lut))
        }
        None => SphereTiling::default(),
    };
    let counts: Vec<usize> = args.iter().map(|a| a.parse().expect(USAGE)).collect();
    assert!(!counts.is_empty(), "{USAGE}");
    for n in counts {
        let holes = holes(&tiling, n);
        let wider = |t: f64| holes.iter().filter(|h| h.0 > t).count();
        let widest: Vec<String> = (holes.iter().take(6))
            .map(|(width, at)| format!("{width:.2} at z {:.2}", at.z))
            .collect();
        println!(
            "N = {n}: holes wider than 3.4 {}, 3.6 {}, 3.8 {}, 4.0 {}; widest {}",
            wider(3.4),
            wider(3.6),
            wider(3.8),
            wider(4.0),
            widest.join(", ")
        );
    }
}

/// The holes of the uniform set of `n` points, widest first: each a width
/// (times √n) and the probe where it was found.
fn holes(tiling: &SphereTiling, n: usize) -> Vec<(f64, DVec3)> {
    let sampler = Sampler::new(tiling.clone()).count(n);
    let points: Vec<[f64; 3]> = (sampler.generate().expect("uniform"))
        .into_iter()
        .map(|s| s.position.to_array())
        .collect();
    let tree: ImmutableKdTree<f64, 3> = ImmutableKdTree::new_from_slice(&points);
    let probes = if n > 100_000 { 60 * n } else { 200 * n };
    let scale = (n as f64).sqrt();
    let widths = |chunk: &[DVec3]| -> Vec<(f64, DVec3)> {
        (chunk.par_iter())
            .map(|&probe| {
                let nearest = tree.nearest_one::<SquaredEuclidean>(&probe.to_array());
                // the chord's angle
                (2.0 * (nearest.distance.sqrt() / 2.0).asin() * scale, probe)
            })
            .filter(|&(width, _)| width > 3.2)
            .collect()
    };
    // the probes a million at a time, in parallel
    let (mut wide, mut chunk) = (Vec::new(), Vec::with_capacity(1 << 20));
    spherical_fibonacci_into(probes, |probe| {
        chunk.push(probe);
        if chunk.len() == chunk.capacity() {
            wide.extend(widths(&chunk));
            chunk.clear();
        }
    });
    wide.extend(widths(&chunk));
    wide.sort_by(|a, b| b.0.total_cmp(&a.0));
    // one probe a hole: the widest, and none within 2.5 / sqrt(n) of it
    let apart = 2.5 / scale;
    let mut holes: Vec<(f64, DVec3)> = Vec::new();
    for (width, at) in wide {
        if holes.iter().all(|h| h.1.distance(at) > apart) {
            holes.push((width, at));
        }
    }
    holes
}

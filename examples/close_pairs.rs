//! Where a uniform sphere set crowds: the points whose nearest neighbour
//! is closer than `T / √N` (default T = 1.5), counted by HEALPix zone
//! (polar caps |z| > 2/3, or the equatorial belt) and by their distance to
//! the nearest face edge in cells of the sampling level, with the closest
//! pairs listed.
//!
//!     cargo run --release --example close_pairs -- N [T]

use glam::DVec3;
use kiddo::{ImmutableKdTree, SquaredEuclidean};
use std::collections::BTreeMap;
use std::num::NonZero;
use tessera::healpix::FacePoint;
use tessera::Sampler;

fn main() {
    let mut args = std::env::args().skip(1);
    let n: usize = args
        .next()
        .and_then(|a| a.parse().ok())
        .expect("usage: close_pairs N [T]");
    let threshold: f64 = args.next().map_or(1.5, |a| a.parse().expect("T a number"));
    let points: Vec<DVec3> = (Sampler::sphere().count(n).generate().expect("uniform"))
        .into_iter()
        .map(|s| s.position)
        .collect();
    let coords: Vec<[f64; 3]> = points.iter().map(|p| p.to_array()).collect();
    let tree: ImmutableKdTree<f64, 3> = ImmutableKdTree::new_from_slice(&coords);
    let two = NonZero::new(2).expect("2 > 0");
    // cells of the first level whose capacity (240 * 4^level) holds N
    let level = (n as f64 / 240.0).log(4.0).ceil().max(0.0);
    let nside = 10.0 * 2f64.powf(level);
    let mut close = Vec::new();
    for (i, q) in coords.iter().enumerate() {
        let found = tree.nearest_n::<SquaredEuclidean>(q, two);
        let other = found.iter().find(|f| f.item as usize != i).expect("N >= 2");
        let d = (points[i].cross(points[other.item as usize]).length())
            .atan2(points[i].dot(points[other.item as usize]));
        if d * (n as f64).sqrt() < threshold {
            close.push((d * (n as f64).sqrt(), i, other.item as usize));
        }
    }
    close.sort_by(|a, b| a.0.total_cmp(&b.0));
    println!(
        "N = {n} (level {level}, {nside} cells a face side): {} points nearer than {threshold} / sqrt(N) to their neighbour",
        close.len()
    );
    let mut by_place: BTreeMap<(&str, u32), usize> = BTreeMap::new();
    for &(_, i, _) in &close {
        let f = FacePoint::from_vec(points[i]);
        let zone = if points[i].z.abs() > 2.0 / 3.0 {
            "polar"
        } else {
            "equatorial"
        };
        let edge = f.x.min(f.y).min(1.0 - f.x).min(1.0 - f.y) * nside;
        let band = match edge {
            e if e < 0.5 => 0,
            e if e < 2.0 => 1,
            e if e < 8.0 => 2,
            _ => 3,
        };
        *by_place.entry((zone, band)).or_insert(0) += 1;
    }
    let bands = [
        "< 0.5 cells from a face edge",
        "0.5-2 cells",
        "2-8 cells",
        ">= 8 cells",
    ];
    for ((zone, band), count) in &by_place {
        println!("  {zone:10} {:30} {count}", bands[*band as usize]);
    }
    for &(d, i, j) in close.iter().step_by(2).take(5) {
        let (a, b) = (
            FacePoint::from_vec(points[i]),
            FacePoint::from_vec(points[j]),
        );
        println!(
            "  {d:.3}: z {:.4}, face {} ({:.5}, {:.5}) and face {} ({:.5}, {:.5})",
            points[i].z, a.face, a.x, a.y, b.face, b.x, b.y
        );
    }
}

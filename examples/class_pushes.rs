//! Why a neighbourhood class cannot push its close pairs apart: for a
//! uniform request of N points at a class level (N > 245,760), the tiles
//! whose point is nearer than `T / √N` (default T = 2.4) to its nearest
//! neighbour, by class, with how well their wanted pushes agree.
//!
//!     cargo run --release --example class_pushes -- N [T]
//!
//! A close tile wants its point moved away from its neighbour; in its own
//! frame that is a unit vector. The mean resultant of those vectors over a
//! group of tiles (the length of their mean, 1 when they all agree, near 0
//! when they cancel) says whether one offset shared by the group can help
//! them all. Groups: the class, as the table shares offsets, and the class
//! split by which tiles around (centroids within 4 cells, on the same
//! face) the request keeps, which the class does not know because it
//! depends on those tiles' codes. Pairs across a face edge are left out.
//! The four faces of a HEALPix ring repeat each tile with the same class
//! and pattern (`SphereLut::row`), so a group of four agrees trivially:
//! the summary also gives the groups of at least 12 tiles.

use glam::DVec3;
use kiddo::{ImmutableKdTree, SquaredEuclidean};
use std::collections::HashMap;
use std::num::NonZero;
use tessera::healpix::FacePoint;
use tessera::tiling::sphere::{SphereTile, SphereTiling};
use tessera::tiling::TileSystem;

/// Neighbouring tiles whose keep decision forms the pattern: centroids
/// within this many cells of the tile's.
const PATTERN_RADIUS_CELLS: f64 = 4.0;

/// Which tiles around a close tile the request keeps: each tile's centroid
/// in the close tile's frame (half cells) and whether it is kept.
type KeptPattern = Vec<(i32, i32, bool)>;

/// Sum of unit pushes and their count.
#[derive(Default, Clone, Copy)]
struct Pushes {
    sum: [f64; 2],
    count: usize,
}

impl Pushes {
    fn add(&mut self, unit: [f64; 2]) {
        self.sum = [self.sum[0] + unit[0], self.sum[1] + unit[1]];
        self.count += 1;
    }
    /// Length of the summed unit vectors: `count` times the mean resultant.
    fn length(&self) -> f64 {
        self.sum[0].hypot(self.sum[1])
    }
}

/// A tile's frame as an affine map onto its face: origin and the images
/// of the two unit steps, inverted for face points.
struct Frame {
    origin: FacePoint,
    x: [f64; 2],
    y: [f64; 2],
}

impl Frame {
    fn new(tiling: &SphereTiling, tile: &SphereTile) -> Self {
        let origin = tiling.face_point(tile, [0.0, 0.0]);
        let ex = tiling.face_point(tile, [1.0, 0.0]);
        let ey = tiling.face_point(tile, [0.0, 1.0]);
        Frame {
            x: [ex.x - origin.x, ex.y - origin.y],
            y: [ey.x - origin.x, ey.y - origin.y],
            origin,
        }
    }
    /// Tile-frame coordinates (cells) of a difference of face coordinates.
    fn local(&self, d: [f64; 2]) -> [f64; 2] {
        let det = self.x[0] * self.y[1] - self.x[1] * self.y[0];
        [
            (d[0] * self.y[1] - d[1] * self.y[0]) / det,
            (self.x[0] * d[1] - self.x[1] * d[0]) / det,
        ]
    }
    fn at(&self, p: FacePoint) -> [f64; 2] {
        self.local([p.x - self.origin.x, p.y - self.origin.y])
    }
}

fn main() {
    let mut args = std::env::args().skip(1);
    let n: usize = args
        .next()
        .and_then(|a| a.parse().ok())
        .expect("usage: class_pushes N [T]");
    let threshold: f64 = args.next().map_or(2.4, |a| a.parse().expect("T a number"));
    let sphere = SphereTiling::default();
    let level = (0..=8)
        .find(|&l| sphere.capacity(l) >= n as f64)
        .expect("N at most 240 * 4^8");
    let fraction = n as f64 / sphere.capacity(level);
    let tiles = sphere.tiles(level);
    let kept_tile = |t: &SphereTile| (t.code as f64) < n as f64;
    let centroid = sphere.shape().centroid();
    let centres: Vec<[f64; 3]> = tiles
        .iter()
        .map(|t| sphere.face_point(t, centroid).to_vec().to_array())
        .collect();
    let centre_tree: ImmutableKdTree<f64, 3> = ImmutableKdTree::new_from_slice(&centres);
    let kept: Vec<usize> = (0..tiles.len()).filter(|&i| kept_tile(&tiles[i])).collect();
    let points: Vec<FacePoint> = kept
        .iter()
        .map(|&i| sphere.face_point(&tiles[i], sphere.offset(&tiles[i], fraction)))
        .collect();
    let vectors: Vec<[f64; 3]> = points.iter().map(|p| p.to_vec().to_array()).collect();
    let tree: ImmutableKdTree<f64, 3> = ImmutableKdTree::new_from_slice(&vectors);
    let two = NonZero::new(2).expect("2 > 0");
    // chord of the pattern radius, with HEALPix's largest cell stretch
    let cell = 1.0 / SphereTiling::nside(level) as f64;
    let radius = PATTERN_RADIUS_CELLS * cell * 1.6;

    let mut by_class: HashMap<u32, Pushes> = HashMap::new();
    let mut by_pattern: HashMap<(u32, KeptPattern), Pushes> = HashMap::new();
    let mut kept_in_class: HashMap<u32, usize> = HashMap::new();
    for (k, &i) in kept.iter().enumerate() {
        let tile = &tiles[i];
        *kept_in_class.entry(tile.index).or_default() += 1;
        let found = tree.nearest_n::<SquaredEuclidean>(&vectors[k], two);
        let j = found
            .iter()
            .find(|f| f.item as usize != k)
            .expect("N >= 2")
            .item as usize;
        let d = DVec3::from_array(vectors[k]).angle_between(DVec3::from_array(vectors[j]));
        if d * (n as f64).sqrt() >= threshold || points[j].face != points[k].face {
            continue;
        }
        let frame = Frame::new(&sphere, tile);
        let away = frame.local([points[k].x - points[j].x, points[k].y - points[j].y]);
        let length = away[0].hypot(away[1]);
        let unit = [away[0] / length, away[1] / length];
        let mut pattern: KeptPattern = centre_tree
            .within_unsorted::<SquaredEuclidean>(&centres[i], radius * radius)
            .iter()
            .map(|m| m.item as usize)
            .filter(|&m| m != i && tiles[m].face == tile.face)
            .map(|m| {
                let at = frame.at(sphere.face_point(&tiles[m], centroid));
                let half_cells = |v: f64| (2.0 * v).round() as i32;
                (half_cells(at[0]), half_cells(at[1]), kept_tile(&tiles[m]))
            })
            .collect();
        pattern.sort_unstable();
        by_class.entry(tile.index).or_default().add(unit);
        by_pattern
            .entry((tile.index, pattern))
            .or_default()
            .add(unit);
    }
    let close: usize = by_class.values().map(|p| p.count).sum();
    let resultant = |groups: &mut dyn Iterator<Item = &Pushes>| {
        groups.map(Pushes::length).sum::<f64>() / close.max(1) as f64
    };
    let large: Vec<&Pushes> = by_pattern.values().filter(|p| p.count >= 12).collect();
    let large_tiles: usize = large.iter().map(|p| p.count).sum();
    let large_resultant = large.iter().map(|p| p.length()).sum::<f64>() / large_tiles.max(1) as f64;
    let patterns_of = |class: u32| by_pattern.keys().filter(|(c, _)| *c == class).count();
    println!(
        "N = {n} (level {level}, fraction {fraction:.4}): {close} close tiles (< {threshold} / sqrt(N), same face) in {} classes",
        by_class.len()
    );
    println!(
        "mean resultant of the wanted pushes, weighted by close tiles: within a class {:.2}, within a class and kept pattern {:.2} ({} groups)",
        resultant(&mut by_class.values()),
        resultant(&mut by_pattern.values()),
        by_pattern.len()
    );
    println!(
        "groups of a class and kept pattern with at least 12 tiles: {} groups, {large_tiles} tiles, resultant {large_resultant:.2}",
        large.len()
    );
    let mut classes: Vec<(&u32, &Pushes)> = by_class.iter().collect();
    classes.sort_by_key(|(c, p)| (std::cmp::Reverse(p.count), **c));
    println!("| class | kept tiles | close | resultant | kept patterns | largest pattern group: tiles, resultant |");
    println!("|---|---|---|---|---|---|");
    for (&class, pushes) in classes.iter().take(10) {
        let largest = by_pattern
            .iter()
            .filter(|((c, _), _)| *c == class)
            .map(|(_, p)| p)
            .max_by_key(|p| p.count)
            .expect("a close class has a pattern");
        println!(
            "| {class} | {} | {} | {:.2} | {} | {}, {:.2} |",
            kept_in_class[&class],
            pushes.count,
            pushes.length() / pushes.count as f64,
            patterns_of(class),
            largest.count,
            largest.length() / largest.count as f64
        );
    }
}

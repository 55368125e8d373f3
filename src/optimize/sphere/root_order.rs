//! The roots' ranks: which roots keep one tile more than the others.
//!
//! A uniform request of N keeps, in every root, the tiles whose codes fall
//! below N; the roots ranked below `N mod 240` keep one more. Lloyd
//! relaxation moves points a fraction of a spacing, so which roots those
//! are sets the set's density at the scale of the sphere: its
//! low-frequency moments, which the cap discrepancy and the Riesz energy
//! weigh most. Ring orbits (four roots at one `z`) make them zonal.
//! Measured on the table of format 8 with farthest-point ranks: the zonal
//! moments of the tiles' centroids matched the relaxed sets' within 10 %,
//! and removing them (a zonal warp, scratch) took the cap discrepancy from
//! 1.5-1.9 to 1.0-1.1 times Fibonacci's at N = 160, 218, 1421, 1661, 2270
//! and 3101 (see CHANGELOG.md).
//!
//! So the orbits start in farthest-point order and are then swapped, a
//! whole orbit at a time, to lower the zonal cap discrepancy of the kept
//! tiles' centroids over log-spaced counts up to [`COUNTS_UP_TO`], as long
//! as every prefix of orbits keeps [`SPREAD_KEPT`] of its farthest-point
//! spacing.

use super::{ROOTS_PER_FACE, ROOT_COUNT};
use crate::density::sphere::angle_between;
use crate::lut::SphereLut;
use crate::optimize::ranking::farthest_point_ranks;
use crate::polyomino::Shape;
use crate::tiling::sphere::SphereTiling;
use crate::tiling::TileSystem;
use glam::DVec3;
use rayon::prelude::*;
use std::sync::Arc;

/// Zonal harmonics the objective weighs (their weights fall as `1/l²`).
pub(super) const DEGREES: usize = 8;
/// `P_1..P_DEGREES` summed over some tiles.
pub(super) type Moments = [f64; DEGREES];
/// A level and a count's quotient by 240.
type Quotient = (usize, usize);
/// Counts the objective samples, log-spaced from 100 to [`COUNTS_UP_TO`].
const SAMPLES: usize = 600;
/// Largest count the objective samples (issue 18's discrepancy floor).
const COUNTS_UP_TO: usize = 100_000;
/// Every prefix of the orbit order keeps this fraction of the
/// farthest-point order's smallest distance times `sqrt(count)`.
const SPREAD_KEPT: f64 = 0.9;
/// Passes of orbit swaps (a scratch run: passes 4-6 moved the objective
/// by 1-1.5 % each).
const PASSES: usize = 6;

/// Ranks of the 240 roots, each ring orbit's four roots consecutive
/// (opposite twins first), with the zonal cap discrepancy before and after
/// the orbits were swapped (mean over the sampled counts of the zonal
/// part's square, times `N^1.5`).
pub(super) fn root_ranks(lut: &SphereLut) -> (Vec<u32>, (f64, f64)) {
    let tiling = SphereTiling::new(Arc::new(SphereLut {
        root_rank: (0..ROOT_COUNT as u32).collect(),
        ..lut.clone()
    }));
    let shape = Shape::p_pentomino();
    let centres: Vec<DVec3> = tiling
        .roots()
        .iter()
        .map(|t| tiling.face_point(t, shape.centroid()).to_vec())
        .collect();
    let angles: Vec<Vec<f64>> = (centres.iter())
        .map(|&a| centres.iter().map(|&b| angle_between(a, b)).collect())
        .collect();
    // both orbits are unions of quarter turns: the distance from any root
    // of one to the other is the same
    let orbit_ranks = farthest_point_ranks(ROOT_COUNT / 4, |a, b| {
        (0..4)
            .map(|k| angles[member(a, k)][member(b, 0)])
            .fold(f64::INFINITY, f64::min)
    });
    let mut orbits = vec![0; ROOT_COUNT / 4];
    for (orbit, &rank) in orbit_ranks.iter().enumerate() {
        orbits[rank as usize] = orbit;
    }
    let zonal = ZonalModel::new(&tiling, &shape);
    let floor: Vec<f64> = (spread(&angles, &orbits).iter())
        .map(|s| SPREAD_KEPT * s)
        .collect();
    let before = zonal.objective(&orbits);
    let mut best = before;
    for _ in 0..PASSES {
        let mut improved = false;
        for i in 0..orbits.len() {
            // the best swap of orbit position i with a later one
            let candidate = (i + 1..orbits.len())
                .into_par_iter()
                .filter_map(|j| {
                    let mut swapped = orbits.clone();
                    swapped.swap(i, j);
                    let keeps = spread(&angles, &swapped)
                        .iter()
                        .zip(&floor)
                        .all(|(s, f)| s >= f);
                    keeps.then(|| (zonal.objective(&swapped), j))
                })
                .min_by(|a, b| a.0.total_cmp(&b.0).then(a.1.cmp(&b.1)));
            if let Some((value, j)) = candidate.filter(|c| c.0 < best) {
                orbits.swap(i, j);
                best = value;
                improved = true;
            }
        }
        if !improved {
            break;
        }
    }
    let mut ranks = vec![0; ROOT_COUNT];
    for (rank, &orbit) in orbits.iter().enumerate() {
        for (order, k) in [0, 2, 1, 3].into_iter().enumerate() {
            ranks[member(orbit, k)] = (4 * rank + order) as u32;
        }
    }
    (ranks, (before, best))
}

/// Root `k` (0-3, by face in its ring) of orbit `ring * 20 + place`.
fn member(orbit: usize, k: usize) -> usize {
    let (ring, place) = (orbit / ROOTS_PER_FACE, orbit % ROOTS_PER_FACE);
    (4 * ring + k) * ROOTS_PER_FACE + place
}

/// For each prefix of 2 or more orbits, the smallest angle between its
/// roots times `sqrt` of their count.
fn spread(angles: &[Vec<f64>], orbits: &[usize]) -> Vec<f64> {
    let roots: Vec<usize> = (orbits.iter())
        .flat_map(|&o| (0..4).map(move |k| member(o, k)))
        .collect();
    let mut smallest = f64::INFINITY;
    let mut out = Vec::with_capacity(orbits.len() - 1);
    for t in 1..=orbits.len() {
        for i in 4 * (t - 1)..4 * t {
            for &j in &roots[..i] {
                smallest = smallest.min(angles[roots[i]][j]);
            }
        }
        if t > 1 {
            out.push(smallest * ((4 * t) as f64).sqrt());
        }
    }
    out
}

/// The zonal moments of the tiles a uniform request keeps, by count.
///
/// A request of `N = 240 q + s` at level `L` keeps in every root the
/// tiles `m < q` (`m` the code's quotient by 240, the same tiles whatever
/// the ranks), and tile `q` in the roots ranked below `s`. The zonal part
/// of Stolarsky's cap discrepancy is `sum_l (M_l / N)² / ((2l - 1)(2l + 3))`
/// with `M_l` the sum of `P_l(z)` over the kept centroids.
struct ZonalModel {
    /// `tile[level][q][root]`: `P_1..P_DEGREES` of tile `m = q`'s centroid.
    tile: Vec<Vec<Vec<Moments>>>,
    /// `below[level][q]`: the moments of every root's tiles `m < q`.
    below: Vec<Vec<Moments>>,
    /// Sampled counts: (N, level, q, s).
    counts: Vec<(usize, usize, usize, usize)>,
}

impl ZonalModel {
    fn new(tiling: &SphereTiling, shape: &Shape) -> Self {
        let q_max = COUNTS_UP_TO / ROOT_COUNT;
        let levels = (0..)
            .find(|&l| ROOT_COUNT << (2 * l) >= COUNTS_UP_TO)
            .expect("a level holds the largest count");
        let (mut tile, mut below) = (Vec::new(), Vec::new());
        for level in 0..=levels {
            let quotients = (1usize << (2 * level)).min(q_max + 1);
            let rows: Vec<Vec<Moments>> = (0..quotients)
                .into_par_iter()
                .map(|q| {
                    (0..ROOT_COUNT)
                        .map(|root| {
                            // the identity ranks: root r's codes are r + 240 m
                            let code = (root + ROOT_COUNT * q) as u128;
                            let t = (tiling.tile_with_code(level as u32, code))
                                .expect("a code below the level's capacity");
                            legendre(tiling.face_point(&t, shape.centroid()).to_vec().z)
                        })
                        .collect()
                })
                .collect();
            let mut sums = vec![[0.0; DEGREES]];
            for row in &rows {
                let mut next = *sums.last().expect("starts with zeros");
                for v in row {
                    add(&mut next, v);
                }
                sums.push(next);
            }
            tile.push(rows);
            below.push(sums);
        }
        let mut counts: Vec<(usize, usize, usize, usize)> = (0..SAMPLES)
            .map(|k| {
                let t = k as f64 / (SAMPLES - 1) as f64;
                (100.0 * (COUNTS_UP_TO as f64 / 100.0).powf(t)).round() as usize
            })
            .map(|n| {
                let level = (0..=levels)
                    .find(|&l| ROOT_COUNT << (2 * l) >= n)
                    .expect("n is at most the largest count");
                (n, level, n / ROOT_COUNT, n % ROOT_COUNT)
            })
            .collect();
        counts.dedup();
        ZonalModel {
            tile,
            below,
            counts,
        }
    }

    /// Mean over the sampled counts of the zonal cap discrepancy squared
    /// times `N^1.5` (Fibonacci's squared cap discrepancy falls as
    /// `N^-1.5`, so this weighs the counts alike against it), for the
    /// orbits in this order.
    fn objective(&self, orbits: &[usize]) -> f64 {
        let roots: Vec<usize> = (orbits.iter())
            .flat_map(|&o| [0, 2, 1, 3].map(|k| member(o, k)))
            .collect();
        // the prefix sums over the ranks of the last (level, q) met
        let mut prefix: Option<(Quotient, Vec<Moments>)> = None;
        let mut total = 0.0;
        for &(n, level, q, s) in &self.counts {
            let mut moments = self.below[level][q];
            if s > 0 {
                // consecutive counts share (level, q)
                if prefix.as_ref().is_none_or(|p| p.0 != (level, q)) {
                    let mut sums = Vec::with_capacity(ROOT_COUNT + 1);
                    let mut acc = [0.0; DEGREES];
                    sums.push(acc);
                    for &r in &roots {
                        add(&mut acc, &self.tile[level][q][r]);
                        sums.push(acc);
                    }
                    prefix = Some(((level, q), sums));
                }
                let sums = &prefix.as_ref().expect("just built").1;
                add(&mut moments, &sums[s]);
            }
            let n = n as f64;
            let d2: f64 = (moments.iter().enumerate())
                .map(|(i, m)| {
                    let l = (i + 1) as f64;
                    (m / n).powi(2) / ((2.0 * l - 1.0) * (2.0 * l + 3.0))
                })
                .sum();
            total += d2 * n.powf(1.5);
        }
        total / self.counts.len() as f64
    }
}

fn add(a: &mut Moments, b: &Moments) {
    for (x, y) in a.iter_mut().zip(b) {
        *x += y;
    }
}

/// `P_1(z)..P_DEGREES(z)` by Bonnet's recursion.
pub(super) fn legendre(z: f64) -> Moments {
    let mut out: Moments = [0.0; DEGREES];
    let (mut previous, mut current) = (1.0, z);
    out[0] = z;
    for (l, slot) in out.iter_mut().enumerate().skip(1) {
        let next = ((2 * l + 1) as f64 * z * current - l as f64 * previous) / (l + 1) as f64;
        (previous, current) = (current, next);
        *slot = current;
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use approx::assert_relative_eq;

    #[test]
    fn legendre_matches_closed_forms() {
        for z in [-1.0, -0.3, 0.0, 0.45, 1.0] {
            let p = legendre(z);
            assert_relative_eq!(p[0], z);
            assert_relative_eq!(p[1], (3.0 * z * z - 1.0) / 2.0);
            let z2 = z * z;
            assert_relative_eq!(
                p[3],
                (35.0 * z2 * z2 - 30.0 * z2 + 3.0) / 8.0,
                epsilon = 1e-12
            );
        }
    }

    #[test]
    fn the_shipped_ranks_keep_orbits_whole() {
        let lut = crate::lut::sphere_lut();
        for orbit in 0..ROOT_COUNT / 4 {
            let ranks: Vec<u32> = (0..4).map(|k| lut.root_rank[member(orbit, k)]).collect();
            let first = ranks[0] - ranks[0] % 4;
            assert!(
                ranks.iter().all(|r| r / 4 == first / 4),
                "orbit {orbit}: {ranks:?}"
            );
        }
    }
}

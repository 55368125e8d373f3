//! The farthest-first order ([`Order::FarthestFirst`](super::Order)): each
//! sample in turn is (to 0.2 %) the one farthest from those before it.
//! Distances are measured in local spacings: `|x - y|` over the mean of the
//! two samples' spacings `1 / sqrt(density)`, which splits the gap across a
//! density edge as the two sides' spacings would. Every prefix is then
//! spread about as evenly as the whole set, whatever its length: no sample
//! lies farther from the prefix than the next one does, which is at most
//! every distance within the prefix (mesh ratio at most 2 over the
//! samples). The rank order's prefixes are the samples of lower codes at
//! the full set's places, which leave holes (docs/SPHERE_SWEEP.md).
//!
//! Exact farthest-point ordering is a max-heap of distances that only
//! shrink. Here the heap is a bucket queue of bands under 0.2 % wide (a
//! pick is within 0.2 % of the farthest), O(1) a move: a binary heap's
//! stale entries took three times as long on 10^6 samples. A pick at
//! distance ρ shortens the distances of the samples within
//! `ρ (s_pick + s) / 2` of it, found in k-d trees, one per octave of
//! spacing `s`, each searched with its octave's widest spacing: about 25
//! samples a pick, so O(N log N) in all, and sequential.

use super::Sample;
use crate::voronoi::spatial_order;
use crate::Position;
use glam::DVec3;
use kiddo::{ImmutableKdTree, SquaredEuclidean};
use rayon::prelude::*;

/// Weights below the largest by more than this (densities by its square)
/// count as this: spacings at most 10^4 apart, in at most 14 octaves, so
/// at most 14 trees.
const WEIGHT_RANGE: f64 = 1e-4;

/// Reorders `samples` farthest first, `weight(p)` being `sqrt(density(p))`
/// (`None`: a constant density). The first sample stays first. The order
/// depends only on the samples and weights, not on the thread count.
pub(super) fn farthest_first<P: Position + Send + Sync>(
    samples: &mut Vec<Sample<P>>,
    weight: Option<&(dyn Fn(P) -> f64 + Sync)>,
) {
    let n = samples.len();
    if n < 3 {
        return;
    }
    // worked on along a Morton curve: a pick's neighbours lie near each
    // other in memory (a quarter faster on 10^6 samples than the input order)
    let by_place = {
        let points: Vec<DVec3> = (samples.par_iter())
            .map(|s| DVec3::from_array(s.position.coordinates()))
            .collect();
        spatial_order(&points)
    };
    // the working arrays are gone before the reordered copy is made
    if let Some(order) = order_of_places(samples, &by_place, weight) {
        *samples = (order.into_iter())
            .map(|i| samples[by_place[i as usize]])
            .collect();
    }
}

/// The farthest-first order of `samples` taken in the order `by_place`,
/// as indices into `by_place`; `None` when no weight is positive.
fn order_of_places<P: Position + Send + Sync>(
    samples: &[Sample<P>],
    by_place: &[usize],
    weight: Option<&(dyn Fn(P) -> f64 + Sync)>,
) -> Option<Vec<u32>> {
    let n = by_place.len();
    let at: Vec<[f64; 3]> = (by_place.par_iter())
        .map(|&i| samples[i].position.coordinates())
        .collect();
    // each sample's spacing relative to the densest's; a NaN or zero
    // weight counts as the lightest
    let spacings: Vec<f64> = match weight {
        Some(weight) => {
            let weights: Vec<f64> = (by_place.par_iter())
                .map(|&i| weight(samples[i].position))
                .collect();
            let heaviest = weights.iter().copied().fold(0.0, f64::max);
            if !(heaviest.is_finite() && heaviest > 0.0) {
                // no density to measure spacings by: keep the order
                return None;
            }
            (weights.iter())
                .map(|&w| heaviest / w.max(heaviest * WEIGHT_RANGE))
                .collect()
        }
        None => vec![1.0; n],
    };
    // the input's first sample starts
    let first = by_place.iter().position(|&i| i == 0).unwrap_or(0);
    let octaves = Octaves::new(&at, &spacings);
    // squared distance in mean spacings
    let scaled2 =
        |chord2: f64, i: usize, j: usize| 4.0 * chord2 / (spacings[i] + spacings[j]).powi(2);

    // squared scaled distances to the chosen samples, and their bands
    let mut distance2: Vec<f64> = (0..n)
        .map(|i| scaled2(chord2(&at[i], &at[first]), i, first))
        .collect();
    let bands = Bands::new(distance2.iter().copied().fold(0.0, f64::max));
    // one entry a sample, in the band of its distance when pushed; a
    // distance that shrinks leaves it behind, and it moves on when popped
    // (moving it on every update pushed 9 entries a sample)
    let mut queue: Vec<Vec<u32>> = Vec::new();
    let push = |queue: &mut Vec<Vec<u32>>, band: usize, i: usize| {
        if queue.len() <= band {
            queue.resize_with(band + 1, Vec::new);
        }
        queue[band].push(i as u32);
    };
    for (i, &d2) in distance2.iter().enumerate().filter(|&(i, _)| i != first) {
        push(&mut queue, bands.of(d2), i);
    }
    let mut order = Vec::with_capacity(n);
    order.push(first as u32);
    let mut band = 0;
    while band < queue.len() {
        let Some(i) = queue[band].pop() else {
            // drained for good: give its memory back
            queue[band] = Vec::new();
            band += 1;
            continue;
        };
        let i = i as usize;
        let now = bands.of(distance2[i]);
        if now != band {
            push(&mut queue, now, i);
            continue;
        }
        let reach = distance2[i].sqrt();
        // chosen: at distance 0, which no update lowers
        distance2[i] = 0.0;
        order.push(i as u32);
        if reach == 0.0 {
            // the rest coincide with chosen samples: nothing shortens
            continue;
        }
        for (tree, members, widest) in &octaves.trees {
            // j is nearer than its distance when |x_i - x_j| < reach (s_i + s_j) / 2
            let radius = reach * (spacings[i] + widest) / 2.0;
            for near in tree.within_unsorted::<SquaredEuclidean>(&at[i], radius * radius) {
                let j = members[near.item as usize] as usize;
                let d2 = scaled2(near.distance, i, j);
                if d2 < distance2[j] {
                    distance2[j] = d2;
                }
            }
        }
    }
    debug_assert_eq!(order.len(), n);
    Some(order)
}

/// The squared chord between two points.
fn chord2(a: &[f64; 3], b: &[f64; 3]) -> f64 {
    (a[0] - b[0]).powi(2) + (a[1] - b[1]).powi(2) + (a[2] - b[2]).powi(2)
}

/// The bucket queue's bands of squared distance, band 0 holding the
/// largest. A positive float's bits grow with it, about linearly in its
/// logarithm (exactly at powers of 2, the mantissa linear in between):
/// 256 bands an octave of squared distance are bands 0.1-0.2 % wide in
/// distance, found by a subtraction and a shift (a logarithm a move cost
/// a third of the time).
struct Bands {
    largest: u64,
}

impl Bands {
    /// Bands an octave: `2^BITS_PER_BAND` float units each (2^52 an octave).
    const BITS_PER_BAND: u32 = 52 - 8;
    /// The last band: squared distances more than 2^-(2^16 / 256) below
    /// the largest (coincident samples) all land in it.
    const LAST: u64 = 1 << 16;

    fn new(largest2: f64) -> Self {
        Bands {
            largest: largest2.to_bits(),
        }
    }

    /// The band of squared distance `d2 >= 0`.
    fn of(&self, d2: f64) -> usize {
        let below = self.largest.saturating_sub(d2.to_bits());
        (below >> Self::BITS_PER_BAND).min(Self::LAST) as usize
    }
}

/// The samples by octave of spacing, each in a k-d tree: a pick `i` at
/// distance `ρ` reaches the samples `j` within `ρ (s_i + s_j) / 2`, so each
/// tree is searched with the radius of its widest member.
struct Octaves {
    /// A tree, its members' indices, and the octave's widest spacing.
    trees: Vec<(ImmutableKdTree<f64, 3>, Vec<u32>, f64)>,
}

impl Octaves {
    fn new(at: &[[f64; 3]], spacings: &[f64]) -> Self {
        let octave = |s: f64| s.log2().floor().max(0.0) as usize;
        let count = spacings.iter().map(|&s| octave(s)).max().unwrap_or(0) + 1;
        let mut members: Vec<Vec<u32>> = vec![Vec::new(); count];
        for (i, &s) in spacings.iter().enumerate() {
            members[octave(s)].push(i as u32);
        }
        let trees = (members.into_iter())
            .filter(|m| !m.is_empty())
            .map(|m| {
                let coords: Vec<[f64; 3]> = m.iter().map(|&i| at[i as usize]).collect();
                let widest = m.iter().map(|&i| spacings[i as usize]).fold(1.0, f64::max);
                (ImmutableKdTree::new_from_slice(&coords), m, widest)
            })
            .collect();
        Octaves { trees }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::DVec3;
    use proptest::prelude::*;

    fn samples(points: &[DVec3]) -> Vec<Sample<DVec3>> {
        (points.iter().enumerate())
            .map(|(i, &position)| Sample {
                position,
                rank: i as f64 / points.len() as f64,
            })
            .collect()
    }

    /// Points on the sphere from proptest's numbers, some of them repeated.
    fn sphere_points() -> impl Strategy<Value = Vec<DVec3>> {
        let point = (-1.0..1.0f64, 0.0..std::f64::consts::TAU).prop_map(|(z, phi)| {
            let r = (1.0 - z * z).sqrt();
            DVec3::new(r * phi.cos(), r * phi.sin(), z)
        });
        (prop::collection::vec(point, 3..150), 0..10usize).prop_map(|(mut p, repeats)| {
            for k in 0..repeats.min(p.len() - 1) {
                p.push(p[k]);
            }
            p
        })
    }

    /// Checks that each sample after the first is, to a band, the farthest
    /// from those before it, in mean local spacings (`1 / weight`, clamped
    /// as `farthest_first` clamps it).
    fn is_farthest_first(ordered: &[Sample<DVec3>], weight: impl Fn(DVec3) -> f64) {
        let heaviest = ordered
            .iter()
            .map(|s| weight(s.position))
            .fold(0.0, f64::max);
        let spacing = |x: DVec3| heaviest / weight(x).max(heaviest * WEIGHT_RANGE);
        let distance = |x: DVec3, chosen: &[Sample<DVec3>]| {
            let scaled = |s: &Sample<DVec3>| {
                2.0 * s.position.distance(x) / (spacing(x) + spacing(s.position))
            };
            chosen.iter().map(scaled).fold(f64::MAX, f64::min)
        };
        for k in 1..ordered.len() {
            let (chosen, rest) = ordered.split_at(k);
            let picked = distance(rest[0].position, chosen);
            let farthest = (rest.iter())
                .map(|s| distance(s.position, chosen))
                .fold(0.0, f64::max);
            // a band is at most 0.2 % wide in distance
            assert!(
                picked >= farthest / 1.002,
                "sample {k}: {picked} from those before, the farthest {farthest}"
            );
        }
    }

    proptest! {
        #[test]
        fn orders_the_same_samples_farthest_first(points in sphere_points()) {
            let before = samples(&points);
            let mut ordered = before.clone();
            farthest_first(&mut ordered, None);
            prop_assert_eq!(ordered[0], before[0]);
            let mut ranks: Vec<f64> = ordered.iter().map(|s| s.rank).collect();
            ranks.sort_by(f64::total_cmp);
            prop_assert_eq!(ranks, before.iter().map(|s| s.rank).collect::<Vec<_>>());
            is_farthest_first(&ordered, |_| 1.0);
        }

        #[test]
        fn weights_measure_distances_in_local_spacings(points in sphere_points()) {
            // ten times denser (sqrt(100)) in the northern hemisphere, and
            // weights over 1e4 apart clamped
            let weight = |p: DVec3| match p.z {
                z if z > 0.0 => 10.0,
                z if z > -0.9 => 1.0,
                _ => 1e-6,
            };
            let mut ordered = samples(&points);
            farthest_first(&mut ordered, Some(&weight));
            is_farthest_first(&ordered, weight);
        }
    }

    #[test]
    fn a_zero_density_keeps_the_order() {
        let points = [DVec3::X, DVec3::Y, DVec3::Z, -DVec3::X];
        let mut ordered = samples(&points);
        farthest_first(&mut ordered, Some(&|_| 0.0));
        assert_eq!(ordered, samples(&points));
    }
}

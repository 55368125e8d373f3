//! Exact farthest-point ordering on the sphere, the straightforward way: a
//! max-heap of each point's distance to the points already ordered, stale
//! entries re-pushed when popped, and a k-d tree finding the points a pick
//! brings nearer, the points taken along a Morton curve. The baseline for
//! [`crate::engine::Order::FarthestFirst`], which orders to 0.2 % with a
//! bucket queue instead.

use crate::voronoi::{build_tree, spatial_order};
use glam::DVec3;
use kiddo::SquaredEuclidean;
use std::cmp::Ordering;
use std::collections::BinaryHeap;

/// A point's index and its squared chord to the ordered points; the heap's
/// largest first, ties to the lower index.
#[derive(PartialEq)]
struct Entry(f64, usize);

impl Eq for Entry {}

impl Ord for Entry {
    fn cmp(&self, other: &Self) -> Ordering {
        (self.0.total_cmp(&other.0)).then(other.1.cmp(&self.1))
    }
}

impl PartialOrd for Entry {
    fn partial_cmp(&self, other: &Self) -> Option<Ordering> {
        Some(self.cmp(other))
    }
}

/// The indices of `points` farthest first, from the first point: each is
/// the farthest (by chord, so by angle) from those before it.
///
/// # Example
/// ```
/// use tessera::baselines::{farthest_point::farthest_point_order, spherical_fibonacci};
/// use tessera::metrics::sphere::separation;
/// let points = spherical_fibonacci(4000);
/// let order = farthest_point_order(&points);
/// let first: Vec<_> = order[..1000].iter().map(|&i| points[i]).collect();
/// assert!(separation(&first) > 2.0);
/// ```
pub fn farthest_point_order(points: &[DVec3]) -> Vec<usize> {
    let n = points.len();
    if n == 0 {
        return Vec::new();
    }
    // along a Morton curve, as tessera's order works (neighbours near in
    // memory), the input's first point first
    let by_place = spatial_order(points);
    let first = by_place.iter().position(|&i| i == 0).unwrap_or(0);
    let at: Vec<DVec3> = by_place.iter().map(|&i| points[i]).collect();
    let tree = build_tree(&at);
    let mut distance2: Vec<f64> = at.iter().map(|p| p.distance_squared(at[first])).collect();
    // one entry a point: a chosen point has none left, and distance 0
    let mut heap: BinaryHeap<Entry> = (0..n)
        .filter(|&i| i != first)
        .map(|i| Entry(distance2[i], i))
        .collect();
    let mut order = Vec::with_capacity(n);
    order.push(first);
    while let Some(Entry(d2, i)) = heap.pop() {
        if d2 > distance2[i] {
            // stale: its distance shrank since it was pushed
            heap.push(Entry(distance2[i], i));
            continue;
        }
        distance2[i] = 0.0;
        order.push(i);
        for near in tree.within_unsorted::<SquaredEuclidean>(&at[i].to_array(), d2) {
            let j = near.item as usize;
            distance2[j] = distance2[j].min(near.distance);
        }
    }
    order.into_iter().map(|i| by_place[i]).collect()
}

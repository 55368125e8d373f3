//! Exact farthest-point ordering on the sphere, the straightforward way: a
//! max-heap of each point's distance to the points already ordered, stale
//! entries re-pushed when popped, and a k-d tree finding the points a pick
//! brings nearer. The baseline for [`crate::engine::Order::FarthestFirst`],
//! which orders to 0.2 % with a bucket queue instead.

use crate::voronoi::build_tree;
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
    let tree = build_tree(points);
    let mut distance2: Vec<f64> = points
        .iter()
        .map(|p| p.distance_squared(points[0]))
        .collect();
    let mut heap: BinaryHeap<Entry> = (1..n).map(|i| Entry(distance2[i], i)).collect();
    let mut done = vec![false; n];
    done[0] = true;
    let mut order = Vec::with_capacity(n);
    order.push(0);
    while let Some(Entry(d2, i)) = heap.pop() {
        if done[i] {
            continue;
        }
        if d2 > distance2[i] {
            // stale: its distance shrank since it was pushed
            heap.push(Entry(distance2[i], i));
            continue;
        }
        done[i] = true;
        order.push(i);
        for near in tree.within_unsorted::<SquaredEuclidean>(&points[i].to_array(), d2) {
            let j = near.item as usize;
            distance2[j] = distance2[j].min(near.distance);
        }
    }
    order
}

//! Progressive orderings: the rank of a point is the step at which a greedy
//! farthest-point (void-filling) pass picks it, so every prefix is well spread.

/// Orders `count` items so that each next one is the farthest (by `distance`)
/// from all previously chosen; ties go to the lowest index. Returns the rank
/// of every item. O(count^2) distance evaluations.
///
/// # Example
/// ```
/// use tessera::optimize::ranking::farthest_point_ranks;
/// let xs = [0.0, 1.0, 0.5, 0.9];
/// let ranks = farthest_point_ranks(xs.len(), |a, b| (xs[a] - xs[b]) as f64);
/// assert_eq!(ranks[0], 0); // start
/// assert_eq!(ranks[1], 1); // farthest from 0.0
/// assert_eq!(ranks[2], 2); // the middle of the biggest void
/// ```
pub fn farthest_point_ranks(count: usize, distance: impl Fn(usize, usize) -> f64) -> Vec<u32> {
    let mut ranks = vec![u32::MAX; count];
    if count == 0 {
        return ranks;
    }
    let mut nearest = vec![f64::INFINITY; count];
    let mut current = 0;
    for rank in 0..count {
        ranks[current] = rank as u32;
        let mut best = None;
        let mut best_distance = f64::NEG_INFINITY;
        for i in 0..count {
            if ranks[i] != u32::MAX {
                continue;
            }
            nearest[i] = nearest[i].min(distance(current, i).abs());
            if nearest[i] > best_distance {
                best_distance = nearest[i];
                best = Some(i);
            }
        }
        match best {
            Some(next) => current = next,
            None => break,
        }
    }
    ranks
}

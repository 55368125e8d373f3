//! Weighted sample elimination (Yuksel 2015) on the sphere: the strongest
//! published progressive blue-noise method, as a baseline for the sphere's
//! quality at every count.
//!
//! From `5 N` uniform random candidates, repeatedly remove the one with
//! the largest weight `Σ_j (1 − d_ij / 2r)^8` over its neighbours closer
//! than `2r`, `r = √(4π / (2√3 N))` (the spacing of a hexagonal packing of
//! N points), updating its neighbours' weights, until N remain. Distances
//! below `r_min = 0.65 r (1 − (N / 5N)^1.5)` count as `r_min` (the paper's
//! weight limiting). The paper's parameters; chordal distances (equal to
//! geodesic ones to 1e-4 at these spacings for N ≥ 100).

use super::uniform_random_sphere;
use crate::healpix::FacePoint;
use crate::voronoi::build_tree;
use glam::DVec3;
use kiddo::SquaredEuclidean;

/// Candidates per output point.
const CANDIDATES_A_POINT: usize = 5;
/// The weight's exponent.
const ALPHA: i32 = 8;

/// `n` points chosen from `5 n` uniform random ones (seed `seed`) by
/// weighted sample elimination, in no particular order.
///
/// # Example
/// ```
/// use tessera::baselines::elimination::weighted_sample_elimination;
/// use tessera::metrics::sphere::separation;
/// let points = weighted_sample_elimination(1000, 1);
/// assert_eq!(points.len(), 1000);
/// assert!(separation(&points) > 2.0);
/// ```
pub fn weighted_sample_elimination(n: usize, seed: u64) -> Vec<DVec3> {
    let mut candidates = uniform_random_sphere(CANDIDATES_A_POINT * n, seed);
    // in HEALPix NESTED-like order (faces, then a Z-order curve), so that neighbours lie
    // near each other in memory: 10^6 points took 135 s in random order
    candidates.sort_by_cached_key(|&p| {
        let f = FacePoint::from_vec(p);
        let cell = |v: f64| ((v * 65536.0) as u64).min(65535);
        (f.face, interleave(cell(f.x)) | interleave(cell(f.y)) << 1)
    });
    if n == 0 || candidates.len() <= n {
        return candidates;
    }
    let r_max = (4.0 * std::f64::consts::PI / (2.0 * 3f64.sqrt() * n as f64)).sqrt();
    let ratio = n as f64 / candidates.len() as f64;
    let r_min = r_max * (1.0 - ratio.powf(1.5)) * 0.65;
    let reach = 2.0 * r_max;
    let weight = |d2: f64| (1.0 - d2.sqrt().max(r_min) / reach).max(0.0).powi(ALPHA);
    let tree = build_tree(&candidates);
    let neighbours = |i: usize| {
        let q = candidates[i].to_array();
        tree.within_unsorted::<SquaredEuclidean>(&q, reach * reach)
            .into_iter()
            .filter(move |nn| nn.item as usize != i)
    };
    let mut weights: Vec<f64> = (0..candidates.len())
        .map(|i| neighbours(i).map(|nn| weight(nn.distance)).sum())
        .collect();
    let mut heap = MaxHeap::new(&weights);
    let mut alive = vec![true; candidates.len()];
    let mut left = candidates.len();
    while left > n {
        let i = heap.pop(&weights);
        alive[i] = false;
        left -= 1;
        for nn in neighbours(i) {
            let j = nn.item as usize;
            if alive[j] {
                weights[j] -= weight(nn.distance);
                heap.decreased(j, &weights);
            }
        }
    }
    (candidates.into_iter().zip(alive))
        .filter_map(|(p, a)| a.then_some(p))
        .collect()
}

/// The bits of a 16-bit `v` spread to the even bits.
fn interleave(mut v: u64) -> u64 {
    v = (v | v << 8) & 0x00FF_00FF;
    v = (v | v << 4) & 0x0F0F_0F0F;
    v = (v | v << 2) & 0x3333_3333;
    (v | v << 1) & 0x5555_5555
}

/// A binary max-heap of indices keyed by `weights`, with each index's
/// place, so that a weight that decreases moves down in place (a heap of
/// stale entries instead made 10^6 points take two minutes).
struct MaxHeap {
    heap: Vec<u32>,
    place: Vec<u32>,
}

impl MaxHeap {
    fn new(weights: &[f64]) -> Self {
        let len = weights.len();
        let mut h = MaxHeap {
            heap: (0..len as u32).collect(),
            place: (0..len as u32).collect(),
        };
        for at in (0..len / 2).rev() {
            h.sift_down(at, weights);
        }
        h
    }

    /// Removes and returns the index of the largest weight.
    fn pop(&mut self, weights: &[f64]) -> usize {
        let top = self.heap[0] as usize;
        let last = self.heap.pop().expect("pop on a non-empty heap");
        if !self.heap.is_empty() {
            self.heap[0] = last;
            self.place[last as usize] = 0;
            self.sift_down(0, weights);
        }
        top
    }

    /// Restores the order after `weights[i]` decreased.
    fn decreased(&mut self, i: usize, weights: &[f64]) {
        self.sift_down(self.place[i] as usize, weights);
    }

    fn sift_down(&mut self, mut at: usize, weights: &[f64]) {
        let len = self.heap.len();
        let key = |h: &Self, k: usize| weights[h.heap[k] as usize];
        loop {
            let (l, r) = (2 * at + 1, 2 * at + 2);
            let mut big = at;
            if l < len && key(self, l) > key(self, big) {
                big = l;
            }
            if r < len && key(self, r) > key(self, big) {
                big = r;
            }
            if big == at {
                return;
            }
            self.heap.swap(at, big);
            self.place[self.heap[at] as usize] = at as u32;
            self.place[self.heap[big] as usize] = big as u32;
            at = big;
        }
    }
}

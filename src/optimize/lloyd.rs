//! Lloyd relaxation pieces shared by the planar optimisers: nearest-site
//! queries on a torus and Voronoi cell moments by quadrature.

use rayon::prelude::*;

/// For each site, the sum of (quadrature point - site) over the quadrature
/// points nearest to it, and their count: the `n x n` grid of spacing `h`
/// whose first point is `origin + h / 2`. Nearest sites are found in
/// parallel by rows and summed in row order, so the result does not depend
/// on the thread count.
pub(crate) fn cell_moments(
    grid: &TorusGrid,
    n: usize,
    h: f64,
    origin: [f64; 2],
) -> (Vec<[f64; 2]>, Vec<usize>) {
    let sites = grid.points;
    let p = grid.period;
    let at = |i: usize, j: usize| {
        [
            (i as f64 + 0.5) * h + origin[0],
            (j as f64 + 0.5) * h + origin[1],
        ]
    };
    let rows: Vec<Vec<u32>> = (0..n)
        .into_par_iter()
        .map(|j| {
            (0..n)
                .map(|i| grid.nearest(at(i, j), None).0 as u32)
                .collect()
        })
        .collect();
    let mut sum = vec![[0.0f64; 2]; sites.len()];
    let mut count = vec![0usize; sites.len()];
    for (j, row) in rows.iter().enumerate() {
        for (i, &s) in row.iter().enumerate() {
            let qp = at(i, j);
            let s = s as usize;
            sum[s][0] += wrap_half(qp[0] - sites[s][0], p);
            sum[s][1] += wrap_half(qp[1] - sites[s][1], p);
            count[s] += 1;
        }
    }
    (sum, count)
}

/// `v` reduced into `[-p/2, p/2)`.
pub(crate) fn wrap_half(v: f64, p: f64) -> f64 {
    v - p * (v / p + 0.5).floor()
}

pub(crate) fn torus_d2(a: [f64; 2], b: [f64; 2], p: f64) -> f64 {
    let dx = wrap_half(a[0] - b[0], p);
    let dy = wrap_half(a[1] - b[1], p);
    dx * dx + dy * dy
}

/// Nearest-point queries on the torus `[0, p)^2` by bucketing into a grid
/// of about one point per bucket.
pub(crate) struct TorusGrid<'a> {
    points: &'a [[f64; 2]],
    period: f64,
    n: usize,
    start: Vec<u32>,
    items: Vec<u32>,
}

impl<'a> TorusGrid<'a> {
    pub(crate) fn new(points: &'a [[f64; 2]], period: f64) -> Self {
        let n = ((points.len() as f64).sqrt() as usize).max(1);
        let bucket = |q: [f64; 2]| -> usize {
            let f = |v: f64| (((v.rem_euclid(period)) / period * n as f64) as usize).min(n - 1);
            f(q[1]) * n + f(q[0])
        };
        let mut start = vec![0u32; n * n + 1];
        for &q in points {
            start[bucket(q) + 1] += 1;
        }
        for k in 0..n * n {
            start[k + 1] += start[k];
        }
        let mut fill = start.clone();
        let mut items = vec![0u32; points.len()];
        for (i, &q) in points.iter().enumerate() {
            let b = bucket(q);
            items[fill[b] as usize] = i as u32;
            fill[b] += 1;
        }
        TorusGrid {
            points,
            period,
            n,
            start,
            items,
        }
    }

    /// Index and squared distance of the nearest point other than `exclude`.
    pub(crate) fn nearest(&self, q: [f64; 2], exclude: Option<usize>) -> (usize, f64) {
        let n = self.n as i64;
        let cell = self.period / self.n as f64;
        let at = |v: f64| ((v.rem_euclid(self.period) / cell) as i64).min(n - 1);
        let (cx, cy) = (at(q[0]), at(q[1]));
        let mut best = (usize::MAX, f64::INFINITY);
        let visit = |bx: i64, by: i64, best: &mut (usize, f64)| {
            let b = (by.rem_euclid(n) * n + bx.rem_euclid(n)) as usize;
            for &i in &self.items[self.start[b] as usize..self.start[b + 1] as usize] {
                let i = i as usize;
                if Some(i) == exclude {
                    continue;
                }
                let d = torus_d2(q, self.points[i], self.period);
                if d < best.1 || (d == best.1 && i < best.0) {
                    *best = (i, d);
                }
            }
        };
        let mut r = 0i64;
        loop {
            if 2 * r + 1 >= n {
                // the ring wraps onto itself: scan everything
                for by in 0..n {
                    for bx in 0..n {
                        visit(bx, by, &mut best);
                    }
                }
                return best;
            }
            for dy in -r..=r {
                for dx in -r..=r {
                    if dx.abs() == r || dy.abs() == r {
                        visit(cx + dx, cy + dy, &mut best);
                    }
                }
            }
            // anything outside rings 0..=r is at least r cells away
            if best.1 <= (r as f64 * cell).powi(2) {
                return best;
            }
            r += 1;
        }
    }
}

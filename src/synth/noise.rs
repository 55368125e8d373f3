//! Private building blocks of the synthetic maps: Gaussian draws, textures,
//! and the defects lossy compression leaves (zero pixels, zero lines).

use super::SynthMap;
use crate::random::SplitMix64;
use std::f64::consts::TAU;

/// One standard normal draw (Box-Muller).
pub(crate) fn gaussian(rng: &mut SplitMix64) -> f64 {
    let u1 = 1.0 - rng.next_f64(); // in (0, 1]: the log is finite
    let u2 = rng.next_f64();
    (-2.0 * u1.ln()).sqrt() * (TAU * u2).cos()
}

/// Uniform draw in `[lo, hi)`.
pub(crate) fn uniform(rng: &mut SplitMix64, lo: f64, hi: f64) -> f64 {
    lo + (hi - lo) * rng.next_f64()
}

/// Sum of `octaves` piecewise-constant N(0, 1) grids, the first of `rows0 x
/// cols0` cells, each next one twice as fine both ways, divided by
/// `sqrt(octaves)` so the sum has unit variance. Pixel `(i, j)` of a `width
/// x height` image reads cell `(j rows / height, i cols / width)`, so cells
/// keep their angular size at any resolution.
pub(crate) fn blocky(
    width: usize,
    height: usize,
    rows0: usize,
    cols0: usize,
    octaves: usize,
    rng: &mut SplitMix64,
) -> Vec<f64> {
    let mut f = vec![0.0; width * height];
    for k in 0..octaves {
        let (rows, cols) = (rows0 << k, cols0 << k);
        let grid: Vec<f64> = (0..rows * cols).map(|_| gaussian(rng)).collect();
        let cell_of_column: Vec<usize> = (0..width).map(|i| i * cols / width).collect();
        for (j, line) in f.chunks_exact_mut(width).enumerate() {
            let row = &grid[(j * rows / height) * cols..][..cols];
            for (v, &c) in line.iter_mut().zip(&cell_of_column) {
                *v += row[c];
            }
        }
    }
    let scale = 1.0 / (octaves.max(1) as f64).sqrt();
    f.iter_mut().for_each(|v| *v *= scale);
    f
}

/// Interpolation weights of a smooth (smoothstep) value-noise lattice of
/// `cells` cells over `n` pixels: per pixel, the two lattice indices and
/// the weight of the second. `wrap` makes the lattice periodic (columns of
/// a lat-long map), else it has `cells + 1` nodes.
fn lattice_weights(n: usize, cells: usize, wrap: bool) -> Vec<(usize, usize, f64)> {
    (0..n)
        .map(|i| {
            let x = (i as f64 + 0.5) / n as f64 * cells as f64;
            let i0 = (x.floor() as usize).min(cells - 1);
            let t = x - i0 as f64;
            let t = t * t * (3.0 - 2.0 * t);
            let i1 = if wrap { (i0 + 1) % cells } else { i0 + 1 };
            (i0, i1, t)
        })
        .collect()
}

/// Multi-scale smooth texture (fractal Brownian motion of value noise),
/// normalised to mean 0 and variance 1 over the pixels. The coarsest
/// lattice has `rows0 x cols0` cells, periodic in columns; each octave
/// halves the cells and multiplies the amplitude by `gain`, down to cells
/// of about 2 pixels.
pub(crate) fn fbm(
    width: usize,
    height: usize,
    (rows0, cols0): (usize, usize),
    gain: f64,
    rng: &mut SplitMix64,
) -> Vec<f64> {
    let mut f = vec![0.0; width * height];
    let mut amplitude = 1.0;
    let (mut rows, mut cols) = (rows0.max(1), cols0.max(1));
    loop {
        let nodes: Vec<f64> = (0..(rows + 1) * cols).map(|_| gaussian(rng)).collect();
        let xs = lattice_weights(width, cols, true);
        let ys = lattice_weights(height, rows, false);
        for (line, &(j0, j1, ty)) in f.chunks_exact_mut(width).zip(&ys) {
            let (r0, r1) = (&nodes[j0 * cols..][..cols], &nodes[j1 * cols..][..cols]);
            for (v, &(i0, i1, tx)) in line.iter_mut().zip(&xs) {
                let a = r0[i0] + (r0[i1] - r0[i0]) * tx;
                let b = r1[i0] + (r1[i1] - r1[i0]) * tx;
                *v += amplitude * (a + (b - a) * ty);
            }
        }
        if 2 * rows >= height || rows >= 1 << 12 {
            break;
        }
        rows *= 2;
        cols *= 2;
        amplitude *= gain;
    }
    standardise(&mut f);
    f
}

/// Shifts and scales `f` to mean 0 and variance 1 (a constant stays 0).
pub(crate) fn standardise(f: &mut [f64]) {
    let n = f.len().max(1) as f64;
    let mean = f.iter().sum::<f64>() / n;
    let var = f.iter().map(|v| (v - mean) * (v - mean)).sum::<f64>() / n;
    let scale = if var > 0.0 { 1.0 / var.sqrt() } else { 0.0 };
    f.iter_mut().for_each(|v| *v = (*v - mean) * scale);
}

/// Sets a random `fraction` of the pixels darker than `cutoff` (luminance)
/// to exactly 0, as clamping the negative ringing of a lossy codec does.
/// One draw per pixel whatever its value, so the pattern depends on the
/// seed only.
pub(crate) fn sprinkle_zeros(map: &mut SynthMap, fraction: f64, cutoff: f64, rng: &mut SplitMix64) {
    for p in &mut map.rgb {
        let hit = rng.next_f64() < fraction;
        if hit && super::luminance_of(*p) < cutoff {
            *p = [0.0; 3];
        }
    }
}

/// Zero lines beside the brightest features, as the negative ringing of a
/// lossy codec's 8 x 8 blocks leaves them once clamped: the pixels at or
/// above `threshold` times the maximum are grouped into 8-connected blobs;
/// beside each of the `count` blobs with the highest peaks, the column
/// right of the blob and the row below it, one pixel wide and 3 pixels
/// longer than the blob at each end, are set to 0. For a blob wider or
/// taller than 64 pixels (a big lamp) the lines are 9 pixels long, at the
/// first pixels outside it right of and below its peak. Columns wrap (phi
/// is periodic).
pub(crate) fn zero_lines(map: &mut SynthMap, threshold: f64, count: usize) {
    let (w, h) = (map.width, map.height);
    if w == 0 || h == 0 {
        return;
    }
    let lum = map.luminance();
    let max = lum.iter().copied().fold(0.0, f64::max);
    if max <= 0.0 {
        return;
    }
    let cut = threshold * max;
    let mut seen = vec![false; w * h];
    // (peak, peak pixel, left, right, top, bottom)
    let mut blobs: Vec<(f64, usize, usize, usize, usize, usize)> = Vec::new();
    let mut stack = Vec::new();
    for start in 0..w * h {
        if seen[start] || lum[start] < cut {
            continue;
        }
        seen[start] = true;
        stack.push(start);
        let (mut peak, mut at) = (lum[start], start);
        let (mut l, mut r, mut t, mut b) = (start % w, start % w, start / w, start / w);
        while let Some(k) = stack.pop() {
            let (i, j) = (k % w, k / w);
            if lum[k] > peak {
                (peak, at) = (lum[k], k);
            }
            (l, r, t, b) = (l.min(i), r.max(i), t.min(j), b.max(j));
            for dj in -1i64..=1 {
                for di in -1i64..=1 {
                    let (ni, nj) = (i as i64 + di, j as i64 + dj);
                    if ni < 0 || nj < 0 || ni >= w as i64 || nj >= h as i64 {
                        continue;
                    }
                    let n = nj as usize * w + ni as usize;
                    if !seen[n] && lum[n] >= cut {
                        seen[n] = true;
                        stack.push(n);
                    }
                }
            }
        }
        blobs.push((peak, at, l, r, t, b));
    }
    blobs.sort_by(|a, b| b.0.total_cmp(&a.0).then(a.1.cmp(&b.1)));
    let mut lines = Vec::new();
    for &(_, at, l, r, t, b) in blobs.iter().take(count) {
        let (i, j) = (at % w, at / w);
        if r - l >= 64 || b - t >= 64 {
            let mut right = i;
            while right < i + w && lum[j * w + right % w] >= cut {
                right += 1;
            }
            let mut below = j;
            while below < h && lum[below * w + i] >= cut {
                below += 1;
            }
            lines.push((
                right % w,
                j as i64 - 4,
                j as i64 + 4,
                below,
                i as i64 - 4,
                i as i64 + 4,
            ));
        } else {
            lines.push((
                (r + 1) % w,
                t as i64 - 3,
                b as i64 + 3,
                b + 1,
                l as i64 - 3,
                r as i64 + 3,
            ));
        }
    }
    for (column, top, bottom, row, left, right) in lines {
        for j in top.max(0)..=bottom.min(h as i64 - 1) {
            map.rgb[j as usize * w + column] = [0.0; 3];
        }
        if row < h {
            for i in left..=right {
                map.rgb[row * w + i.rem_euclid(w as i64) as usize] = [0.0; 3];
            }
        }
    }
}

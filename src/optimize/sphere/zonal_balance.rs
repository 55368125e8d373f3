//! The zonal warps of the per-tile levels (see [`ZonalWarp`]): for each
//! bin, the warp that evens out the zonal moments of the uniform requests
//! the bin serves, fitted by least squares.
//!
//! Measured before it was built (scratch, 2026-12-07: the same fit on the
//! finished sets, 24 counts a bin): the cap discrepancy over Fibonacci's
//! went from 1.35 to 1.28 at N = 20,188, 1.33 to 1.29 at 82,272 and 1.31
//! to 1.29 at 96,172; the normalised Riesz energy and the separation moved
//! by under 0.0002 and 0.002, the largest move 2 % of a spacing.

use super::root_order::{legendre, DEGREES};
use super::Progress;
use crate::density::Uniform;
use crate::engine;
use crate::lut::{SphereLut, ZonalWarp};
use crate::tiling::sphere::SphereTiling;
use rayon::prelude::*;
use std::sync::Arc;

/// Terms of a warp's series.
const TERMS: usize = ZonalWarp::TERMS;

/// Uniform counts a bin's warp is fitted on, at most (evenly spread over
/// the counts it serves, its top one included).
const COUNTS_A_BIN: usize = 24;
/// Farthest a warp moves a point, in spacings of its bin's top count: a
/// fit is scaled down to it (which keeps `1 - (1 - c)²` of the fit's gain
/// at scale `c`). Free fits moved points up to 0.40 spacings on level 0
/// and 0.12 on level 1 (N <= 960), 0.08 on levels 2-3, 0.05 on level 4
/// and under 0.03 deeper. With 0.03 the sweep's worst cap discrepancy
/// read 1.30 times Fibonacci's (N = 20,188), with 0.08 1.29 (82,272).
const MOST_MOVE: f64 = 0.08;
/// Ridge on the least squares, relative to the normal matrix's mean
/// diagonal: it only keeps a bin whose counts leave a direction free (a
/// bin serving one count) from a singular matrix.
const RIDGE: f64 = 1e-6;

/// How much of the zonal moments a set of `n` points keeps: degree `l`
/// weighs `M_l² / ((2l - 1)(2l + 3))`, its share of the squared cap
/// discrepancy (Stolarsky), times `n^-0.5` so that each count weighs its
/// discrepancy over Fibonacci's (whose square falls as `n^-1.5`).
fn weight(l: usize, n: usize) -> f64 {
    let l = l as f64;
    1.0 / ((2.0 * l - 1.0) * (2.0 * l + 3.0) * (n as f64).sqrt())
}

/// `P_0(z) ..= P_DEGREES(z)`: the root ranks' (whose degrees these are)
/// after `P_0 = 1`.
fn legendre_all(z: f64) -> [f64; DEGREES + 1] {
    let mut p = [1.0; DEGREES + 1];
    p[1..].copy_from_slice(&legendre(z));
    p
}

/// A set's zonal moments, and their derivatives in the warp's
/// coefficients at the identity: `dM_l / da_k = Σ (1 - z²) P_l'(z) P_k(z)`,
/// where `(1 - z²) P_l' = l (P_(l-1) - z P_l)` has no pole.
struct Moments {
    m: [f64; DEGREES],
    jacobian: [[f64; TERMS]; DEGREES],
}

fn moments(zs: impl Iterator<Item = f64>) -> Moments {
    let mut out = Moments {
        m: [0.0; DEGREES],
        jacobian: [[0.0; TERMS]; DEGREES],
    };
    for z in zs {
        let p = legendre_all(z);
        for l in 1..=DEGREES {
            out.m[l - 1] += p[l];
            let slope = l as f64 * (p[l - 1] - z * p[l]);
            for (derivative, pk) in out.jacobian[l - 1].iter_mut().zip(&p) {
                *derivative += slope * pk;
            }
        }
    }
    out
}

/// The counts of uniform requests that read `level`'s bin `bin` (see
/// [`SphereLut::bin`]), at most [`COUNTS_A_BIN`] of them.
fn served_counts(lut: &SphereLut, level: u32, bin: usize) -> Vec<usize> {
    let capacity = (crate::lut::ROOT_COUNT << (2 * level)) as f64;
    // a request reads the first level whose capacity holds it
    let above_level = if level == 0 {
        0
    } else {
        (capacity / 4.0) as usize
    };
    let lower = match bin {
        0 => 0,
        _ => lut.bin_codes(bin - 1, capacity) as usize,
    };
    let (first, last) = (
        lower.max(above_level) + 1,
        lut.bin_codes(bin, capacity) as usize,
    );
    if first > last {
        return Vec::new();
    }
    let steps = (last - first).min(COUNTS_A_BIN - 1);
    let mut counts: Vec<usize> = (0..=steps)
        .map(|i| first + (last - first) * i / steps.max(1))
        .filter(|&n| lut.bin(n as f64 / capacity, capacity) == bin)
        .collect();
    counts.dedup();
    counts
}

/// The points of the uniform request of `n` points.
fn uniform_zs(tiling: &SphereTiling, n: usize, warp: ZonalWarp) -> Vec<f64> {
    (engine::generate(tiling, &Uniform, n, true).expect("a uniform request within the table"))
        .iter()
        .map(|s| warp.apply(s.position).z)
        .collect()
}

/// Solves the symmetric positive definite system `a x = b` (Cholesky).
fn solve(mut a: [[f64; TERMS]; TERMS], b: [f64; TERMS]) -> [f64; TERMS] {
    for j in 0..TERMS {
        let diagonal = (a[j][j] - (0..j).map(|k| a[j][k] * a[j][k]).sum::<f64>()).sqrt();
        a[j][j] = diagonal;
        for i in j + 1..TERMS {
            a[i][j] = (a[i][j] - (0..j).map(|k| a[i][k] * a[j][k]).sum::<f64>()) / diagonal;
        }
    }
    let mut y = [0.0; TERMS];
    for i in 0..TERMS {
        y[i] = (b[i] - (0..i).map(|k| a[i][k] * y[k]).sum::<f64>()) / a[i][i];
    }
    let mut x = [0.0; TERMS];
    for i in (0..TERMS).rev() {
        x[i] = (y[i] - (i + 1..TERMS).map(|k| a[k][i] * x[k]).sum::<f64>()) / a[i][i];
    }
    x
}

/// The farthest `warp` moves a point (radians, to first order: `sin θ
/// |g(z)|` along the meridian), over a fine grid of `z`.
fn farthest_move(warp: ZonalWarp) -> f64 {
    const STEPS: usize = 4000;
    (0..=STEPS)
        .map(|i| {
            let z = -1.0 + 2.0 * i as f64 / STEPS as f64;
            let r = (1.0 - z * z).sqrt();
            (warp.apply(glam::DVec3::new(r, 0.0, z)).z - z).abs() / r.max(1e-300)
        })
        .fold(0.0, f64::max)
}

/// The weighted zonal moments a set keeps (see [`weight`]).
fn kept(m: &[f64; DEGREES], n: usize) -> f64 {
    (1..=DEGREES)
        .map(|l| weight(l, n) * m[l - 1] * m[l - 1])
        .sum()
}

/// One bin's warp, fitted on its counts, with the weighted zonal moments
/// its counts keep (summed) before and after.
fn fit_bin(tiling: &SphereTiling, counts: &[usize]) -> (ZonalWarp, (f64, f64)) {
    let sets: Vec<(usize, Moments)> = (counts.par_iter())
        .map(|&n| {
            let zs = uniform_zs(tiling, n, ZonalWarp::default());
            (n, moments(zs.into_iter()))
        })
        .collect();
    let mut normal = [[0.0; TERMS]; TERMS];
    let mut rhs = [0.0; TERMS];
    for (n, set) in &sets {
        for l in 1..=DEGREES {
            let (w, row) = (weight(l, *n), &set.jacobian[l - 1]);
            for r in 0..TERMS {
                rhs[r] -= w * row[r] * set.m[l - 1];
                for c in 0..TERMS {
                    normal[r][c] += w * row[r] * row[c];
                }
            }
        }
    }
    let ridge = RIDGE * (0..TERMS).map(|k| normal[k][k]).sum::<f64>() / TERMS as f64;
    for (k, row) in normal.iter_mut().enumerate() {
        row[k] += ridge.max(f64::MIN_POSITIVE);
    }
    let fitted = solve(normal, rhs);
    let top = counts.iter().copied().max().unwrap_or(1);
    let spacing = (4.0 * std::f64::consts::PI / top as f64).sqrt();
    let scale = (MOST_MOVE * spacing / farthest_move(ZonalWarp::new(fitted))).min(1.0);
    let mut warp = ZonalWarp::new(fitted.map(|a| a * scale));
    if warp.slope_bound().is_nan() || warp.slope_bound() > 0.5 {
        // not met: the moves are a few hundredths of a spacing
        warp = ZonalWarp::default();
    }
    let before: f64 = sets.iter().map(|(n, set)| kept(&set.m, *n)).sum();
    let after: f64 = (counts.par_iter())
        .map(|&n| kept(&moments(uniform_zs(tiling, n, warp).into_iter()).m, n))
        .sum();
    (warp, (before, after))
}

/// The zonal warps of levels `0..levels`, bin by bin, for `lut` (whose
/// own warps are ignored), with each level's weighted zonal moments (mean
/// over the fitted counts) before and after.
pub(super) fn zonal_warps(
    lut: &SphereLut,
    levels: usize,
    progress: Progress,
) -> (Vec<Vec<ZonalWarp>>, Vec<(f64, f64)>) {
    let tiling = SphereTiling::new(Arc::new(SphereLut {
        zonal_warps: Vec::new(),
        ..lut.clone()
    }));
    let bins = lut.bins();
    let mut warps = Vec::new();
    let mut report = Vec::new();
    for level in 0..levels {
        let (mut level_warps, mut sums, mut fitted) = (Vec::new(), (0.0, 0.0), 0);
        for bin in 0..bins {
            progress(
                "zonal warps",
                (level * bins + bin) as u64,
                (levels * bins) as u64,
            );
            let counts = served_counts(lut, level as u32, bin);
            if counts.is_empty() {
                level_warps.push(ZonalWarp::default());
                continue;
            }
            let (warp, (before, after)) = fit_bin(&tiling, &counts);
            level_warps.push(warp);
            (sums.0, sums.1, fitted) = (sums.0 + before, sums.1 + after, fitted + counts.len());
        }
        let mean = |s: f64| s / fitted.max(1) as f64;
        report.push((mean(sums.0), mean(sums.1)));
        warps.push(level_warps);
    }
    progress(
        "zonal warps",
        (levels * bins) as u64,
        (levels * bins) as u64,
    );
    (warps, report)
}

#[cfg(test)]
mod tests {
    use super::*;
    use approx::assert_relative_eq;
    use proptest::prelude::*;

    proptest! {
        /// The moments' derivatives match finite differences of the
        /// moments of the warped points.
        #[test]
        fn the_moments_derivatives_match_finite_differences(
            zs in proptest::collection::vec(-1.0f64..1.0, 1..20),
            k in 0..TERMS,
        ) {
            let h = 1e-6;
            let mut a = [0.0; TERMS];
            a[k] = h;
            let warp = ZonalWarp::new(a);
            let moved = |zs: &[f64]| {
                zs.iter().map(|&z| {
                    let r = (1.0 - z * z).sqrt();
                    warp.apply(glam::DVec3::new(r, 0.0, z)).z
                }).collect::<Vec<_>>()
            };
            let (at, up) = (moments(zs.iter().copied()), moments(moved(&zs).into_iter()));
            for l in 0..DEGREES {
                let difference = (up.m[l] - at.m[l]) / h;
                assert_relative_eq!(difference, at.jacobian[l][k], epsilon = 1e-4 * zs.len() as f64 * (1 + l * l) as f64);
            }
        }

        /// The solver inverts a symmetric positive definite system.
        #[test]
        fn the_solver_inverts_a_positive_definite_system(
            m in proptest::array::uniform6(proptest::array::uniform6(-1.0f64..1.0)),
            x in proptest::array::uniform6(-1.0f64..1.0),
        ) {
            // a = m mᵀ + I
            let mut a = [[0.0; TERMS]; TERMS];
            for i in 0..TERMS {
                for j in 0..TERMS {
                    a[i][j] = (0..TERMS).map(|k| m[i][k] * m[j][k]).sum::<f64>() + f64::from(u8::from(i == j));
                }
            }
            let b = std::array::from_fn(|i| (0..TERMS).map(|j| a[i][j] * x[j]).sum());
            let solved = solve(a, b);
            for i in 0..TERMS {
                assert_relative_eq!(solved[i], x[i], epsilon = 1e-9);
            }
        }
    }

    /// Every count a bin serves reads that bin on its level, and the
    /// served counts of a level's bins do not overlap.
    #[test]
    fn served_counts_read_their_bin() {
        let lut = crate::lut::sphere_lut();
        for level in 0..3u32 {
            let capacity = (crate::lut::ROOT_COUNT << (2 * level)) as f64;
            let mut seen = Vec::new();
            for bin in 0..lut.bins() {
                for n in served_counts(&lut, level, bin) {
                    assert_eq!(lut.bin(n as f64 / capacity, capacity), bin);
                    assert!(n as f64 <= capacity && (level == 0 || n as f64 > capacity / 4.0));
                    seen.push(n);
                }
            }
            let total = seen.len();
            seen.sort_unstable();
            seen.dedup();
            assert_eq!(seen.len(), total);
            assert!(
                total >= 4 * COUNTS_A_BIN.min(20),
                "level {level}: {total} counts"
            );
        }
    }
}

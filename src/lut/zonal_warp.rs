//! A bin's zonal warp ([`ZonalWarp`]): a small move of every point along
//! its meridian that evens out the set's density between latitudes.
//!
//! Between two bins a uniform request keeps a prefix of the upper bin's
//! codes, the same sibling ranks in every root, and the set's density
//! drifts between latitudes by a few points in tens of thousands. Cap
//! discrepancy weighs those few points heavily: at N = 20,188 the zonal
//! moments of degrees 1, 2 and 4 made up a third of its squared cap
//! discrepancy, which read 1.35 times Fibonacci's (scratch spectrum,
//! 2026-12-07). Moving each point by `(1 - z²) g(z)` in `z`, with `g` a
//! short Legendre series fitted per bin to its requests' moments
//! (`optimize::sphere`), took it to 1.28, the largest move 2 % of a
//! spacing. The offsets cannot carry it: it would change most of them by
//! about one step of their `i8` grid, bin by bin, which zstd could not
//! store in the 4 MB.

use glam::DVec3;
use serde::{Deserialize, Serialize};

/// See [`ZonalWarp::TERMS`].
const TERMS: usize = 6;

/// The move `z -> z + (1 - z²) g(z)` along the meridian, `g` a Legendre
/// series of [`ZonalWarp::TERMS`] terms; the poles stay put. Zero coefficients are
/// the identity.
///
/// # Example
/// ```
/// use glam::DVec3;
/// use tessera::lut::ZonalWarp;
/// let warp = ZonalWarp::new([1e-3, 0.0, 0.0, 0.0, 0.0, 0.0]);
/// let p = warp.apply(DVec3::X); // on the equator, z moves by 1e-3
/// assert!((p.z - 1e-3).abs() < 1e-15 && (p.length() - 1.0).abs() < 1e-15);
/// assert_eq!(warp.apply(DVec3::Z), DVec3::Z);
/// assert_eq!(ZonalWarp::default().apply(DVec3::Y), DVec3::Y);
/// ```
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
#[serde(from = "[f64; TERMS]", into = "[f64; TERMS]")]
pub struct ZonalWarp {
    /// `a_k`, the Legendre coefficients of `g`, as the table stores them.
    legendre: [f64; TERMS],
    /// `g`'s coefficients in powers of `z`, for Horner's rule: five fused
    /// multiply-adds a point rather than the recurrence's four divisions.
    monomial: [f64; TERMS],
}

impl From<[f64; TERMS]> for ZonalWarp {
    fn from(legendre: [f64; TERMS]) -> Self {
        ZonalWarp::new(legendre)
    }
}

impl From<ZonalWarp> for [f64; TERMS] {
    fn from(warp: ZonalWarp) -> Self {
        warp.legendre
    }
}

impl ZonalWarp {
    /// Terms of the Legendre series `g(z) = Σ a_k P_k(z)`, `k < TERMS`.
    pub const TERMS: usize = TERMS;

    /// The warp of Legendre coefficients `legendre` (`a_0` first).
    ///
    /// # Example
    /// ```
    /// let warp = tessera::lut::ZonalWarp::new([0.0, 2e-4, 0.0, 0.0, 0.0, 0.0]);
    /// assert_eq!(warp.legendre()[1], 2e-4);
    /// ```
    pub fn new(legendre: [f64; Self::TERMS]) -> Self {
        // P_k in powers of z, by (k + 1) P_(k+1) = (2k + 1) z P_k - k P_(k-1)
        let (mut previous, mut current) = ([0.0; TERMS], [0.0; TERMS]);
        current[0] = 1.0;
        let mut monomial = [0.0; TERMS];
        for (k, a) in legendre.iter().enumerate() {
            for (m, c) in monomial.iter_mut().zip(&current) {
                *m += a * c;
            }
            let next: [f64; TERMS] = std::array::from_fn(|j| {
                let shifted = if j == 0 { 0.0 } else { current[j - 1] };
                ((2 * k + 1) as f64 * shifted - k as f64 * previous[j]) / (k + 1) as f64
            });
            (previous, current) = (current, next);
        }
        ZonalWarp { legendre, monomial }
    }

    /// The Legendre coefficients of `g`.
    ///
    /// # Example
    /// ```
    /// assert_eq!(tessera::lut::ZonalWarp::default().legendre(), [0.0; 6]);
    /// ```
    pub fn legendre(&self) -> [f64; Self::TERMS] {
        self.legendre
    }

    /// Whether the warp moves no point.
    ///
    /// # Example
    /// ```
    /// assert!(tessera::lut::ZonalWarp::default().is_identity());
    /// ```
    pub fn is_identity(&self) -> bool {
        self.legendre.iter().all(|&a| a == 0.0)
    }

    /// A bound on `|d/dz ((1 - z²) g(z))|` over `[-1, 1]`: the map is
    /// increasing in `z` (no two latitudes swap) while it stays below 1.
    /// `|d/dz ((1 - z²) P_k)| = |k P_(k-1) - (k + 2) z P_k| <= 2k + 2`.
    ///
    /// # Example
    /// ```
    /// let warp = tessera::lut::ZonalWarp::new([0.0, 0.1, 0.0, 0.0, 0.0, 0.0]);
    /// assert_eq!(warp.slope_bound(), 0.4);
    /// ```
    pub fn slope_bound(&self) -> f64 {
        (self.legendre.iter().enumerate())
            .map(|(k, a)| a.abs() * (2 * k + 2) as f64)
            .sum()
    }

    /// A bound on the angle (rad) the warp moves a point by. With `M` the
    /// largest `|g|`, `z = cos θ` moves by `(1 - z²) |g(z)|`, and by the
    /// mean value theorem the angle by that over `sin ξ`, `ξ` between the
    /// two colatitudes. Sine is concave there, so `sin ξ` is at least the
    /// smaller of the two sines, and `sin²θ' >= sin²θ (1 - 2M - M²)`: the
    /// angle is at most `sin θ |g(z)| / sqrt(1 - 2M - M²)`. Both maxima
    /// are bounded interval by interval on a grid: `|g|` by its larger end
    /// plus the most it changes within half the step (`|P_k'| <= k (k +
    /// 1) / 2` on `[-1, 1]`), `sin θ` by its larger end (1 across the
    /// equator). `g` is largest at the poles, where nothing moves: the
    /// sum of `|a_k|` would be several times looser for the table's warps. A warp
    /// with `M` past the root of that factor gets `pi`.
    ///
    /// # Example
    /// ```
    /// use glam::DVec3;
    /// let warp = tessera::lut::ZonalWarp::new([1e-3, -2e-3, 0.0, 0.0, 0.0, 0.0]);
    /// let p = DVec3::new(0.6, 0.0, 0.8);
    /// assert!(warp.apply(p).angle_between(p) <= warp.move_bound());
    /// assert!(warp.move_bound() < 1.8e-3); // the sum of |a_k|: 3e-3
    /// ```
    pub fn move_bound(&self) -> f64 {
        const STEPS: usize = 4096;
        let step = 2.0 / STEPS as f64;
        let slope: f64 = (self.legendre.iter().enumerate())
            .map(|(k, a)| a.abs() * (k * (k + 1)) as f64 / 2.0)
            .sum();
        let (mut most_g, mut most_move) = (0.0f64, 0.0f64);
        let mut g_left = self.g(-1.0).abs();
        for i in 0..STEPS {
            let (left, right) = (-1.0 + i as f64 * step, -1.0 + (i + 1) as f64 * step);
            let g_right = self.g(right).abs();
            let g = g_left.max(g_right) + slope * step / 2.0;
            let sin = match left <= 0.0 && right >= 0.0 {
                true => 1.0,
                false => (1.0 - left.abs().min(right.abs()).powi(2)).sqrt(),
            };
            (most_g, most_move) = (most_g.max(g), most_move.max(sin * g));
            g_left = g_right;
        }
        let shrink = 1.0 - 2.0 * most_g - most_g * most_g;
        match shrink > 0.0 {
            true => most_move / shrink.sqrt(),
            false => std::f64::consts::PI,
        }
    }

    /// `g(z)`, by Horner's rule.
    #[inline]
    fn g(&self, z: f64) -> f64 {
        (self.monomial.iter().rev()).fold(0.0, |sum, &c| sum.mul_add(z, c))
    }

    /// The unit vector `p` moved along its meridian. With
    /// `z' = z + (1 - z²) g`, `1 - z'² = (1 - z²)(1 - 2zg - (1 - z²) g²)`,
    /// so `x` and `y` scale by the root of the second factor: no
    /// cancellation near the poles, where both factors of `1 - z'²` are
    /// read as they are.
    #[inline]
    pub fn apply(&self, p: DVec3) -> DVec3 {
        let z = p.z;
        let sin2 = (1.0 - z * z).max(0.0);
        let g = self.g(z);
        let scale = (1.0 - 2.0 * z * g - sin2 * g * g).max(0.0).sqrt();
        DVec3::new(p.x * scale, p.y * scale, z + sin2 * g)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use approx::assert_relative_eq;
    use proptest::prelude::*;

    /// `P_k(z)` by the recurrence, for the check of `g`.
    fn legendre(k: usize, z: f64) -> f64 {
        let (mut previous, mut current) = (1.0, z);
        if k == 0 {
            return 1.0;
        }
        for j in 1..k {
            let next = ((2 * j + 1) as f64 * z * current - j as f64 * previous) / (j + 1) as f64;
            (previous, current) = (current, next);
        }
        current
    }

    proptest! {
        /// The warp keeps points on the sphere and on their meridian,
        /// moves `z` by `(1 - z²) g(z)`, and keeps latitudes in order
        /// while its slope bound is below 1.
        #[test]
        fn a_warp_moves_points_along_their_meridian_in_order(
            a in proptest::array::uniform6(-0.03f64..0.03),
            z in -1.0f64..1.0,
            dz in 1e-6f64..0.1,
            phi in 0.0f64..std::f64::consts::TAU,
        ) {
            let warp = ZonalWarp::new(a);
            prop_assume!(warp.slope_bound() < 1.0);
            let at = |z: f64| {
                let r = (1.0 - z * z).sqrt();
                DVec3::new(r * phi.cos(), r * phi.sin(), z)
            };
            let p = warp.apply(at(z));
            let g: f64 = (0..ZonalWarp::TERMS).map(|k| a[k] * legendre(k, z)).sum();
            assert_relative_eq!(p.length(), 1.0, epsilon = 1e-14);
            assert_relative_eq!(p.z, z + (1.0 - z * z) * g, epsilon = 1e-15);
            if p.x.hypot(p.y) > 1e-9 {
                assert_relative_eq!(p.y.atan2(p.x).rem_euclid(std::f64::consts::TAU), phi, epsilon = 1e-9);
            }
            let above = (z + dz).min(1.0);
            prop_assert!(warp.apply(at(above)).z >= p.z);
        }

        /// No point moves farther than the move bound (near the poles too,
        /// where `z` moves least for the angle).
        #[test]
        fn a_warp_moves_no_point_past_its_move_bound(
            a in proptest::array::uniform6(-0.053f64..0.053),
            z in prop_oneof![-1.0f64..1.0, 0.999f64..1.0, -1.0f64..-0.999],
        ) {
            let warp = ZonalWarp::new(a);
            let p = DVec3::new((1.0 - z * z).sqrt(), 0.0, z);
            prop_assert!(warp.apply(p).angle_between(p) <= warp.move_bound() * (1.0 + 1e-12));
        }
    }
}

//! Quality metrics for point sets on the unit sphere and in the unit square.
//!
//! * [`sphere`]: separation, spherical-cap L2 discrepancy (Stolarsky), Riesz
//!   s = 1 energy, exact covering radius, mesh ratio and the angular power
//!   spectrum of points on S².
//! * [`irradiance`]: irradiance from an environment map, exact (per-pixel
//!   quadrature) and Monte Carlo, and the relative RMSE between them.
//! * [`plane`]: nearest-neighbour distances, Warnock's L2-star and
//!   Hickernell's centred L2 discrepancy, periodogram with radial average and
//!   anisotropy, and the low-frequency power of points in `[0, 1)²`.
//!
//! * [`report`]: the measures by key ([`SphereMeasure`], [`PlaneMeasure`]),
//!   which of them to compute ([`Options`]) and the [`Report`] of their
//!   values that `tessera metrics` prints.
//!
//! The O(N²) sums are parallel (rayon) and accumulated in double-double
//! arithmetic, so that the small differences they feed (D² = 1/3 − …) keep
//! their precision; see each function for the precision actually obtained.
//!
//! ```
//! use tessera::baselines::spherical_fibonacci;
//! use tessera::metrics::{sphere_report, SphereMeasure};
//! let report = sphere_report(&spherical_fibonacci(256));
//! let separation = report[SphereMeasure::Separation];
//! assert!(separation > 2.9 && separation < 3.3);
//! ```

pub mod irradiance;
pub mod plane;
pub mod report;
pub mod sphere;

pub use plane::{plane_report, PlaneMeasure};
pub use report::{parse_measures, Measure, Options, Progress, Report, PAIRS_UP_TO};
pub use sphere::{sphere_report, SphereMeasure};

/// Double-double number `hi + lo` (about 106 bits), used to accumulate the
/// O(N²) pair sums without loss (Ogita–Rump–Oishi cascaded summation).
#[derive(Clone, Copy, Debug, Default)]
pub(crate) struct Dd {
    pub(crate) hi: f64,
    pub(crate) lo: f64,
}

#[inline]
fn two_sum(a: f64, b: f64) -> (f64, f64) {
    let s = a + b;
    let bb = s - a;
    (s, (a - (s - bb)) + (b - bb))
}

impl Dd {
    pub(crate) const ZERO: Dd = Dd { hi: 0.0, lo: 0.0 };

    /// The double-double nearest to `num / den` (both exact in f64).
    pub(crate) fn ratio(num: f64, den: f64) -> Dd {
        let hi = num / den;
        let lo = hi.mul_add(-den, num) / den;
        Dd { hi, lo }
    }

    /// Adds a plain f64 (error-free transformation, error kept in `lo`).
    #[inline]
    pub(crate) fn add(&mut self, x: f64) {
        let (s, e) = two_sum(self.hi, x);
        self.hi = s;
        self.lo += e;
    }

    /// Sum of two double-double numbers.
    #[inline]
    pub(crate) fn plus(self, other: Dd) -> Dd {
        let (s, e) = two_sum(self.hi, other.hi);
        let e = e + self.lo + other.lo;
        let (hi, lo) = two_sum(s, e);
        Dd { hi, lo }
    }

    /// Negation.
    #[inline]
    pub(crate) fn neg(self) -> Dd {
        Dd {
            hi: -self.hi,
            lo: -self.lo,
        }
    }

    /// Division by a plain f64.
    pub(crate) fn div(self, d: f64) -> Dd {
        let q1 = self.hi / d;
        // r = self - q1 * d, exactly up to the lo part.
        let p = q1 * d;
        let p_err = q1.mul_add(d, -p);
        let r = ((self.hi - p) - p_err) + self.lo;
        let q2 = r / d;
        let (hi, lo) = two_sum(q1, q2);
        Dd { hi, lo }
    }

    /// Rounds to the nearest f64.
    #[inline]
    pub(crate) fn value(self) -> f64 {
        self.hi + self.lo
    }
}

//! Seeded randomness with no dependency: a small generator and uniformly
//! random rotations, so that every random choice (baselines, random
//! frames, dithers) is reproducible from a seed on every platform.
//!
//! ```
//! use tessera::random::{random_rotation, SplitMix64};
//! assert_eq!(SplitMix64::new(5).next_u64(), SplitMix64::new(5).next_u64());
//! assert_eq!(random_rotation(2), random_rotation(2));
//! ```

use glam::{DMat3, DQuat};
use std::f64::consts::TAU;

/// SplitMix64 (Steele, Lea & Flood 2014; Vigna's reference constants): a
/// 64-bit-state generator with full period 2⁶⁴ that passes BigCrush. Not
/// cryptographic. Deterministic for a given seed on every platform.
///
/// ```
/// use tessera::random::SplitMix64;
/// let mut rng = SplitMix64::new(0);
/// assert_eq!(rng.next_u64(), 0xe220_a839_7b1d_cdaf);
/// let u = rng.next_f64();
/// assert!((0.0..1.0).contains(&u));
/// ```
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct SplitMix64 {
    state: u64,
}

impl SplitMix64 {
    /// Generator whose state starts at `seed` (every seed, 0 included, is
    /// fine).
    ///
    /// ```
    /// use tessera::random::SplitMix64;
    /// let (mut a, mut b) = (SplitMix64::new(42), SplitMix64::new(42));
    /// assert_eq!(a.next_u64(), b.next_u64());
    /// ```
    pub fn new(seed: u64) -> Self {
        Self { state: seed }
    }

    /// Next 64 uniformly distributed bits.
    ///
    /// ```
    /// use tessera::random::SplitMix64;
    /// let mut rng = SplitMix64::new(1234567);
    /// assert_eq!(rng.next_u64(), 6457827717110365317);
    /// assert_eq!(rng.next_u64(), 3203168211198807973);
    /// ```
    pub fn next_u64(&mut self) -> u64 {
        self.state = self.state.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.state;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^ (z >> 31)
    }

    /// Uniform f64 in `[0, 1)`: the top 53 bits times 2⁻⁵³ (every multiple of
    /// 2⁻⁵³ equally likely; 1 is never returned).
    ///
    /// ```
    /// use tessera::random::SplitMix64;
    /// let mut rng = SplitMix64::new(9);
    /// let mean = (0..10_000).map(|_| rng.next_f64()).sum::<f64>() / 1e4;
    /// assert!((mean - 0.5).abs() < 0.02);
    /// ```
    pub fn next_f64(&mut self) -> f64 {
        (self.next_u64() >> 11) as f64 * (1.0 / (1u64 << 53) as f64)
    }
}

/// A rotation drawn uniformly (Haar measure) from `seed`: Shoemake's
/// uniform unit quaternion from three [`SplitMix64`] numbers. Rotating a
/// point set by it randomises the set without changing its geometry, which
/// makes Monte Carlo estimates from it unbiased.
///
/// ```
/// let r = tessera::random::random_rotation(3);
/// assert!((r.determinant() - 1.0).abs() < 1e-12);
/// assert!(((r * glam::DVec3::X).length() - 1.0).abs() < 1e-12);
/// ```
pub fn random_rotation(seed: u64) -> DMat3 {
    let mut rng = SplitMix64::new(seed);
    let (u1, u2, u3) = (rng.next_f64(), rng.next_f64(), rng.next_f64());
    let (a, b) = ((1.0 - u1).sqrt(), u1.sqrt());
    let q = DQuat::from_xyzw(
        a * (TAU * u2).sin(),
        a * (TAU * u2).cos(),
        b * (TAU * u3).sin(),
        b * (TAU * u3).cos(),
    );
    DMat3::from_quat(q.normalize())
}

//! Owen-scrambled Sobol points in two dimensions, by Burley's hash-based
//! nested uniform scrambling ("Practical hash-based Owen scrambling", JCGT
//! 2020): the index is shuffled and each coordinate scrambled with a
//! Laine–Karras style hash of reversed bits, seeded per dimension. Every
//! prefix of `2^m` points is a (0, m, 2)-net: each elementary interval of
//! area `2^-m` holds exactly one point. Warps: [`sphere`] (equal-area
//! z/φ), [`super::envmap::InverseCdf::warp`] and [`super::cdf::RasterCdf::warp`].
//!
//! ```
//! use tessera::baselines::sobol::owen_sobol_2d;
//! let p = owen_sobol_2d(16, 3);
//! assert_eq!(p.len(), 16);
//! assert_ne!(p, owen_sobol_2d(16, 4));
//! ```

use glam::{DVec2, DVec3};

/// Laine–Karras permutation: bijective on u32, each output bit depending
/// only on the input bits below it (so on the reversed value, bits above).
fn laine_karras(mut x: u32, seed: u32) -> u32 {
    x = x.wrapping_add(seed);
    x ^= x.wrapping_mul(0x6c50_b47c);
    x ^= x.wrapping_mul(0xb82f_1e52);
    x ^= x.wrapping_mul(0xc7af_e638);
    x ^= x.wrapping_mul(0x8d22_f6e6);
    x
}

/// Nested uniform (Owen) scramble of a 32-bit fixed-point coordinate.
fn owen_scramble(x: u32, seed: u32) -> u32 {
    laine_karras(x.reverse_bits(), seed).reverse_bits()
}

/// A 32-bit hash mixing a seed into a per-dimension seed (Burley's
/// `hash_combine` on a fixed-point mix).
fn hash(x: u32) -> u32 {
    let mut x = x ^ (x >> 16);
    x = x.wrapping_mul(0x21f0_aaad);
    x ^= x >> 15;
    x = x.wrapping_mul(0xd35a_2d97);
    x ^ (x >> 15)
}

/// The first two Sobol dimensions at `index`: van der Corput (bit reversal)
/// and the dimension with direction numbers `v_k = v_{k−1} ⊕ (v_{k−1} >> 1)`.
fn sobol(index: u32) -> [u32; 2] {
    let mut y = 0;
    let mut v = 1u32 << 31;
    let mut i = index;
    while i != 0 {
        if i & 1 == 1 {
            y ^= v;
        }
        i >>= 1;
        v ^= v >> 1;
    }
    [index.reverse_bits(), y]
}

/// Point `index` of the Owen-scrambled Sobol sequence drawn from `seed`,
/// in `[0, 1)²` (32-bit resolution).
///
/// # Example
/// ```
/// use tessera::baselines::sobol::owen_sobol_point;
/// let p = owen_sobol_point(5, 1);
/// assert!((0.0..1.0).contains(&p.x) && (0.0..1.0).contains(&p.y));
/// ```
pub fn owen_sobol_point(index: u32, seed: u64) -> DVec2 {
    let s = hash((seed as u32) ^ hash((seed >> 32) as u32));
    let shuffled = owen_scramble(index, s);
    let [x, y] = sobol(shuffled);
    let unit = |v: u32| v as f64 * (1.0 / 4_294_967_296.0);
    DVec2::new(
        unit(owen_scramble(x, hash(s ^ 0x9e37_79b9))),
        unit(owen_scramble(y, hash(s ^ 0x7f4a_7c15))),
    )
}

/// The first `n` points (at most 2³²) of the Owen-scrambled Sobol sequence
/// drawn from `seed`.
///
/// # Example
/// ```
/// use tessera::baselines::sobol::owen_sobol_2d;
/// // a (0, 2, 2)-net: one point in each quarter-square
/// let p = owen_sobol_2d(4, 9);
/// let mut quarters: Vec<_> = p.iter().map(|q| ((2.0 * q.x) as u8, (2.0 * q.y) as u8)).collect();
/// quarters.sort();
/// assert_eq!(quarters, [(0, 0), (0, 1), (1, 0), (1, 1)]);
/// ```
pub fn owen_sobol_2d(n: usize, seed: u64) -> Vec<DVec2> {
    (0..n as u32).map(|i| owen_sobol_point(i, seed)).collect()
}

/// Owen-scrambled Sobol points on the unit sphere through the equal-area
/// z/φ warp ([`super::equal_area`]).
///
/// # Example
/// ```
/// let p = tessera::baselines::sobol::sphere(64, 2);
/// assert!(p.iter().all(|v| (v.length() - 1.0).abs() < 1e-12));
/// // equal area: half the points in each hemisphere
/// assert_eq!(p.iter().filter(|v| v.z > 0.0).count(), 32);
/// ```
pub fn sphere(n: usize, seed: u64) -> Vec<DVec3> {
    (0..n as u32)
        .map(|i| super::equal_area(owen_sobol_point(i, seed)))
        .collect()
}

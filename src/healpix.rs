//! The HEALPix equal-area mapping between the unit sphere and twelve unit squares.
//!
//! The sphere is cut into [`FACE_COUNT`] = 12 base faces (the HEALPix base pixels): four
//! around the north pole (faces `0..4`), four on the equator (`4..8`) and four around the
//! south pole (`8..12`). Each face is parameterised by face-local coordinates
//! `(x, y)` in `[0, 1]^2`, with the convention of HEALPix NESTED indexing: `(x, y)` is the
//! continuous `(ix, iy) / nside` inside the base pixel, i.e. the same as
//! `cdshealpix::nested::hash_with_dxdy` at depth 0 (`hash` = face, `dx` = x, `dy` = y).
//!
//! * `(0, 0)` is the face's south vertex, `(1, 1)` its north vertex;
//! * `x` points north-east (increasing longitude and latitude);
//! * `y` points north-west;
//! * the frame `(x, y)` is counter-clockwise when seen from outside the sphere.
//!
//! The mapping is equal-area: every face covers `4 pi / 12` steradians and the Jacobian of
//! `(x, y) -> sphere` is the constant `pi / 3` everywhere (except on the measure-zero set
//! where it is not differentiable).
//!
//! # Numerical notes
//!
//! All computations are in `f64` and avoid the classical cancellations:
//!
//! * near the poles `sin(theta)` is never computed as `sqrt(1 - z^2)`; inside the polar caps
//!   `1 - |z| = sigma^2 / 3` exactly, so `sin(theta) = sigma * sqrt((1 + |z|) / 3)`, and the
//!   inverse uses `sqrt(3 (1 - |z|)) = sin(theta) * sqrt(3 / (1 + |z|))`;
//! * longitudes are handled inside the current quarter of the sphere: the vector is rotated
//!   by an exact multiple of `pi / 2` (sign swaps) before `atan2`, so the in-quadrant
//!   longitude keeps full relative precision;
//! * [`FacePoint::from_angles`] never casts a longitude to an integer: it goes through
//!   `sin_cos`, whose argument reduction is exact, so even `phi = -1e12` gives the correctly
//!   reduced direction (a `rem_euclid(TAU)` would be off by about `phi * 2.4e-16 / TAU`
//!   radians because `TAU` is not exactly `2 pi`).
//!
//! Round trips `FacePoint -> DVec3 -> FacePoint` are accurate to a few `f64::EPSILON`
//! in absolute terms everywhere, including at and next to the poles and seams.
//!
//! # Invalid input
//!
//! No function of this module panics on any input. Face numbers `>= 12` are taken modulo 12
//! and face coordinates are clamped into `[0, 1]`. NaN coordinates propagate (a NaN
//! [`FacePoint`] maps to a NaN vector); a zero, infinite or NaN vector, or a non-finite angle,
//! gives [`FacePoint::INVALID`] (face 0, NaN coordinates).

use glam::DVec3;
use serde::{Deserialize, Serialize};
use std::f64::consts::{FRAC_2_PI, FRAC_PI_2, FRAC_PI_4, TAU};

/// The number of HEALPix base faces.
///
/// # Example
/// ```
/// use tessera::healpix::FACE_COUNT;
/// assert_eq!(FACE_COUNT, 12);
/// ```
pub const FACE_COUNT: usize = 12;

/// `|z|` of the boundary between the equatorial belt and the polar caps (`2 / 3`).
const Z_SEAM: f64 = 2.0 / 3.0;

/// A point on the sphere given by its base face and face-local coordinates.
///
/// `face` is in `0..12`; `x` and `y` are in `[0, 1]` (see the [module docs](self) for the
/// orientation). Points on face edges have several valid representations.
///
/// # Example
/// ```
/// use tessera::healpix::FacePoint;
/// // The centre of equatorial face 4 is (lon, lat) = (0, 0).
/// let v = FacePoint::new(4, 0.5, 0.5).to_vec();
/// assert!((v - glam::DVec3::X).length() < 1e-15);
/// ```
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct FacePoint {
    /// Base face, in `0..12`.
    pub face: u8,
    /// North-east coordinate, in `[0, 1]`.
    pub x: f64,
    /// North-west coordinate, in `[0, 1]`.
    pub y: f64,
}

impl FacePoint {
    /// The value returned for invalid input (zero or non-finite vectors, non-finite angles):
    /// face 0 with NaN coordinates.
    ///
    /// # Example
    /// ```
    /// use tessera::healpix::FacePoint;
    /// let p = FacePoint::from_vec(glam::DVec3::ZERO);
    /// assert!(p.x.is_nan() && p.y.is_nan());
    /// ```
    pub const INVALID: FacePoint = FacePoint {
        face: 0,
        x: f64::NAN,
        y: f64::NAN,
    };

    /// Creates a face point; no validation is done here (see [`FacePoint::to_vec`]).
    ///
    /// # Example
    /// ```
    /// use tessera::healpix::FacePoint;
    /// let p = FacePoint::new(3, 0.25, 0.75);
    /// assert_eq!((p.face, p.x, p.y), (3, 0.25, 0.75));
    /// ```
    #[inline]
    pub const fn new(face: u8, x: f64, y: f64) -> Self {
        FacePoint { face, x, y }
    }

    /// Maps the face point to a unit vector.
    ///
    /// The face is taken modulo 12 and `x`, `y` are clamped into `[0, 1]`; NaN coordinates
    /// give a NaN vector.
    ///
    /// # Example
    /// ```
    /// use tessera::healpix::FacePoint;
    /// // The north vertex of any north face is the north pole.
    /// assert_eq!(FacePoint::new(2, 1.0, 1.0).to_vec(), glam::DVec3::Z);
    /// // The south vertex of a south face is the south pole.
    /// assert_eq!(FacePoint::new(9, 0.0, 0.0).to_vec(), -glam::DVec3::Z);
    /// ```
    pub fn to_vec(self) -> DVec3 {
        match self.zone() {
            Ok((z, sin_theta, a)) => {
                let (s, c) = sin_cos_in_quadrant(a);
                let (cx, cy) = rotate_quarter_turns(c, s, (self.face % FACE_COUNT as u8) % 4);
                DVec3::new(sin_theta * cx, sin_theta * cy, z)
            }
            Err(v) => v,
        }
    }

    /// `(z, phi)` of [`FacePoint::to_vec`]'s direction without trigonometry:
    /// `z = cos(theta)`, `phi` in `[0, 2 pi)` (0 at the poles, NaN for NaN
    /// coordinates).
    ///
    /// # Example
    /// ```
    /// use tessera::healpix::FacePoint;
    /// let p = FacePoint::new(5, 0.3, 0.6);
    /// let (z, phi) = p.z_phi();
    /// let v = p.to_vec();
    /// assert!((z - v.z).abs() < 1e-15);
    /// assert!((phi - v.y.atan2(v.x).rem_euclid(std::f64::consts::TAU)).abs() < 1e-14);
    /// ```
    #[inline(always)]
    pub fn z_phi(self) -> (f64, f64) {
        let (z, _, phi) = self.z_sin_phi();
        (z, phi)
    }

    /// `(z, sin(theta), phi)` of [`FacePoint::to_vec`]'s direction without
    /// trigonometry (`sin(theta)` without the `1 - z` cancellation near the
    /// poles), `phi` as in [`FacePoint::z_phi`].
    ///
    /// # Example
    /// ```
    /// use tessera::healpix::FacePoint;
    /// let p = FacePoint::new(1, 0.999, 0.998);
    /// let (z, s, _) = p.z_sin_phi();
    /// let v = p.to_vec();
    /// assert!((s - v.x.hypot(v.y)).abs() < 1e-15 && (z - v.z).abs() < 1e-15);
    /// ```
    #[inline(always)]
    pub fn z_sin_phi(self) -> (f64, f64, f64) {
        match self.zone() {
            Ok((z, sin_theta, a)) => {
                let phi = a + FRAC_PI_2 * ((self.face % FACE_COUNT as u8) % 4) as f64;
                let phi = if phi < 0.0 {
                    phi + TAU
                } else if phi >= TAU {
                    phi - TAU
                } else {
                    phi
                };
                (z, sin_theta, phi)
            }
            Err(v) => (v.z, 0.0 * v.z, if v.z.is_nan() { f64::NAN } else { 0.0 }),
        }
    }

    #[inline(always)]
    fn zone(self) -> Result<(f64, f64, f64), DVec3> {
        let face = self.face % FACE_COUNT as u8;
        let x = self.x.clamp(0.0, 1.0);
        let y = self.y.clamp(0.0, 1.0);
        // (z, sin(theta), longitude inside the quadrant starting at k pi / 2)
        Ok(match face / 4 {
            0 => {
                let sigma = (1.0 - x) + (1.0 - y);
                if sigma >= 1.0 {
                    equatorial_zone(x + y, FRAC_PI_4 * (1.0 + (x - y)))
                } else if sigma > 0.0 {
                    let one_minus_z = sigma * sigma / 3.0;
                    let z = 1.0 - one_minus_z;
                    let sin_theta = sigma * ((1.0 + z) / 3.0).sqrt();
                    (z, sin_theta, FRAC_PI_2 * ((1.0 - y) / sigma))
                } else if sigma == 0.0 {
                    return Err(DVec3::Z);
                } else {
                    return Err(DVec3::NAN);
                }
            }
            1 => equatorial_zone(x + y - 1.0, FRAC_PI_4 * (x - y)),
            _ => {
                let sigma = x + y;
                if sigma >= 1.0 {
                    equatorial_zone(sigma - 2.0, FRAC_PI_4 * (1.0 + (x - y)))
                } else if sigma > 0.0 {
                    let one_minus_abs_z = sigma * sigma / 3.0;
                    let abs_z = 1.0 - one_minus_abs_z;
                    let sin_theta = sigma * ((1.0 + abs_z) / 3.0).sqrt();
                    (-abs_z, sin_theta, FRAC_PI_2 * (x / sigma))
                } else if sigma == 0.0 {
                    return Err(DVec3::NEG_Z);
                } else {
                    return Err(DVec3::NAN);
                }
            }
        })
    }

    /// Maps a direction to its face point. `v` need not be normalised but must be non-zero and
    /// finite; otherwise [`FacePoint::INVALID`] is returned.
    ///
    /// Points on face edges are assigned to one of the adjacent faces.
    ///
    /// # Example
    /// ```
    /// use tessera::healpix::FacePoint;
    /// let p = FacePoint::from_vec(glam::DVec3::new(2.0, 0.0, 0.0));
    /// assert_eq!(p.face, 4);
    /// assert!((p.x - 0.5).abs() < 1e-15 && (p.y - 0.5).abs() < 1e-15);
    /// ```
    pub fn from_vec(v: DVec3) -> Self {
        if !v.is_finite() {
            return Self::INVALID;
        }
        let m = v.abs().max_element();
        if m == 0.0 {
            return Self::INVALID;
        }
        // Rescale by an exact power of two when squaring could overflow or underflow.
        let v = if (1e-150..=1e150).contains(&m) {
            v
        } else {
            v * pow2(-exponent(m))
        };
        let rho2 = v.x * v.x + v.y * v.y;
        let r = (rho2 + v.z * v.z).sqrt();
        let z = (v.z / r).clamp(-1.0, 1.0);
        let sin_theta = rho2.sqrt() / r;
        from_parts(v.x, v.y, z, sin_theta)
    }

    /// Colatitude and longitude `(theta, phi)` of the face point, `theta` in `[0, pi]`,
    /// `phi` in `[0, 2 pi)`.
    ///
    /// # Example
    /// ```
    /// use tessera::healpix::FacePoint;
    /// let (theta, phi) = FacePoint::new(0, 1.0, 1.0).to_angles();
    /// assert_eq!((theta, phi), (0.0, 0.0));
    /// ```
    pub fn to_angles(self) -> (f64, f64) {
        vec_to_angles(self.to_vec())
    }

    /// Face point of the colatitude `theta` and longitude `phi` (radians, any finite values:
    /// the direction is that of [`angles_to_vec`]). Non-finite angles give
    /// [`FacePoint::INVALID`].
    ///
    /// # Example
    /// ```
    /// use tessera::healpix::FacePoint;
    /// let p = FacePoint::from_angles(std::f64::consts::FRAC_PI_2, 0.0);
    /// assert_eq!(p.face, 4);
    /// assert!((p.x - 0.5).abs() < 1e-15 && (p.y - 0.5).abs() < 1e-15);
    /// ```
    pub fn from_angles(theta: f64, phi: f64) -> Self {
        if !(theta.is_finite() && phi.is_finite()) {
            return Self::INVALID;
        }
        let (st, ct) = theta.sin_cos();
        let (sp, cp) = phi.sin_cos();
        from_parts(st * cp, st * sp, ct, st.abs())
    }
}

/// An upper bound of the face-to-sphere stretch over the face points in
/// the box `[x0, x1] x [y0, y1]` of face `face` (clamped onto the face):
/// no step of length `d` in face coordinates between two of them is longer
/// than `stretch_over(..) * d` radians on the sphere. Pointwise the
/// stretch is `sqrt(pi / 3)` = 1.02 where the map is conformal (`|z|`
/// about 0.39), 1.11 at the centre of an equatorial face and 1.26 at its
/// top and bottom corners, and reaches 1.596 only on polar faces' edge
/// meridians (the bound of every face, `tiling::sphere::FACE_LIPSCHITZ`,
/// is 1.6), so a tile's bounding cap shrinks by up to 36 % with it. Over
/// a large polar box the bound below can exceed 1.6 and is cut to it.
///
/// Derivation. With `a = dx + dy` and `b = dx - dy`, a unit step has
/// `a^2 + b^2 = 2`, and the sphere's line element is `ds^2 = dz^2 / (1 -
/// z^2) + (1 - z^2) dphi^2`.
/// - Equatorial zone: `z = 2/3 (x + y) + c`, `phi = pi/4 (x - y) + c'`, so
///   `ds^2 = 4 a^2 / (9 (1 - z^2)) + (1 - z^2) (pi^2 / 16) b^2`, at most
///   `2 max(4 / (9 (1 - z^2)), (1 - z^2) pi^2 / 16)`: the first term
///   grows with `|z|`, the second falls.
/// - Polar caps: with `sigma` the distance sum to the pole's corner
///   (`2 - x - y` north, `x + y` south), `1 - |z| = sigma^2 / 3` and `phi
///   = pi/4 (1 + t)`, `t = (x - y) / sigma` in `[-1, 1]`; then, with `w =
///   2 - sigma^2 / 3`, `ds^2 = A a^2 + B (b ± t a)^2` (`+` north, `-`
///   south), `A = 4 / (3 w)`, `B = pi^2 w / 48`. The form's largest
///   eigenvalue is `(T + sqrt(T^2 - 4 D)) / 2` with trace `T = A + B (1 +
///   t^2)` and determinant `D = A B = pi^2 / 36` (constant), so it grows
///   with `T`, which is at most `A(sigma_max) + B(sigma_min) (1 +
///   t_max^2)` over the box.
/// - Every face: at `t = 1`, `T = 4 / (3 w) + pi^2 w / 24` is largest at
///   the ends of `w` in `[5/3, 2]` (1.4891 and 1.4854), so the stretch
///   never exceeds 1.5962, and the equatorial zone's never 1.265: cutting
///   the bound to 1.6 keeps it an upper bound.
///
/// # Example
/// ```
/// use tessera::healpix::stretch_over;
/// let centre = stretch_over(4, [0.5, 0.5], [0.5, 0.5]);
/// assert!((centre - std::f64::consts::PI / 8f64.sqrt()).abs() < 1e-12);
/// assert!(stretch_over(0, [0.0, 1.0], [0.0, 1.0]) <= 1.6);
/// ```
pub fn stretch_over(face: u8, [x0, x1]: [f64; 2], [y0, y1]: [f64; 2]) -> f64 {
    const MOST: f64 = 1.6;
    let (x0, x1) = (x0.clamp(0.0, 1.0), x1.clamp(0.0, 1.0));
    let (y0, y1) = (y0.clamp(0.0, 1.0), y1.clamp(0.0, 1.0));
    if !(x0 <= x1 && y0 <= y1) {
        return MOST; // NaN or an empty box
    }
    // the box's range of `x + y` and largest `|x - y|`
    let (sum_lo, sum_hi) = (x0 + y0, x1 + y1);
    let diff = (x1 - y0).abs().max((y1 - x0).abs());
    // over `|z|` in `[z_lo, z_hi]` (`|z|` = 2/3 `|y_proj|`, `y_proj` linear
    // in `x + y`)
    let equatorial = |z_lo: f64, z_hi: f64| {
        let (lo, hi) = (
            (z_lo * z_lo).min(Z_SEAM * Z_SEAM),
            (z_hi * z_hi).min(Z_SEAM * Z_SEAM),
        );
        (2.0 * (4.0 / (9.0 * (1.0 - hi))).max((1.0 - lo) * PI_SQUARED / 16.0)).sqrt()
    };
    let polar = |sigma_lo: f64, sigma_hi: f64| {
        let t = if sigma_lo > 0.0 {
            (diff / sigma_lo).min(1.0)
        } else {
            1.0
        };
        let w = |sigma: f64| 2.0 - sigma * sigma / 3.0;
        let trace = 4.0 / (3.0 * w(sigma_hi)) + PI_SQUARED * w(sigma_lo) * (1.0 + t * t) / 48.0;
        let det = PI_SQUARED / 36.0;
        let most = (trace + (trace * trace - 4.0 * det).max(0.0).sqrt()) / 2.0;
        (2.0 * most).sqrt()
    };
    let bound = match (face % FACE_COUNT as u8) / 4 {
        1 => {
            let (lo, hi) = (sum_lo - 1.0, sum_hi - 1.0);
            let least = if lo <= 0.0 && hi >= 0.0 {
                0.0
            } else {
                lo.abs().min(hi.abs())
            };
            equatorial(Z_SEAM * least, Z_SEAM * lo.abs().max(hi.abs()))
        }
        row => {
            // `sigma` from the pole's corner, and `|y_proj|` below the cap
            let (sigma_lo, sigma_hi) = match row {
                0 => (2.0 - sum_hi, 2.0 - sum_lo),
                _ => (sum_lo, sum_hi),
            };
            let mut bound: f64 = 0.0;
            if sigma_hi >= 1.0 {
                let (lo, hi) = (2.0 - sigma_hi.min(2.0), 2.0 - sigma_lo.max(1.0));
                bound = equatorial(Z_SEAM * lo, Z_SEAM * hi);
            }
            if sigma_lo < 1.0 {
                bound = bound.max(polar(sigma_lo, sigma_hi.min(1.0)));
            }
            bound
        }
    };
    // the separated trace bound exceeds the face's own over large polar
    // boxes (1.69 over a whole polar face)
    bound.min(MOST)
}

/// `pi^2`.
const PI_SQUARED: f64 = std::f64::consts::PI * std::f64::consts::PI;

/// `(z, sin(theta), a)` in the equatorial zone, from `Y = 3 z / 2` and the in-quadrant
/// longitude `a`.
#[inline(always)]
fn equatorial_zone(y_proj: f64, a: f64) -> (f64, f64, f64) {
    let z = 2.0 * y_proj / 3.0;
    (z, ((1.0 - z) * (1.0 + z)).sqrt(), a)
}

/// `(sin a, cos a)` for `a` in `[-pi/4, pi/2]` (NaN for NaN), within
/// about 1.1e-16 of the correctly rounded values, without branches: the
/// minimax kernels of fdlibm (as musl has them) on `[-pi/4, pi/4]`, and
/// above it the complement `pi/2 - a` (exact there, by Sterbenz) with sine
/// and cosine swapped. `f64::sin_cos` branches on the argument's range,
/// which the samples of a uniform request, in code order all over the
/// sphere, mispredict: [`FacePoint::to_vec`] took about 40 % longer with it
/// (`FRAC_PI_2`'s own rounding is the 6e-17 this adds to the cosine near
/// `pi/2`).
#[inline(always)]
fn sin_cos_in_quadrant(a: f64) -> (f64, f64) {
    const S: [f64; 6] = [
        -1.666_666_666_666_663_2e-1,
        8.333_333_333_322_49e-3,
        -1.984_126_982_985_795e-4,
        2.755_731_370_707_006_8e-6,
        -2.505_076_025_340_686_3e-8,
        1.589_690_995_211_55e-10,
    ];
    const C: [f64; 6] = [
        4.166_666_666_666_66e-2,
        -1.388_888_888_887_411e-3,
        2.480_158_728_947_673e-5,
        -2.755_731_435_139_066_3e-7,
        2.087_572_321_298_175e-9,
        -1.135_964_755_778_819_5e-11,
    ];
    let swap = a > FRAC_PI_4;
    let x = if swap { FRAC_PI_2 - a } else { a };
    let z = x * x;
    let w = z * z;
    let r = S[1] + z * (S[2] + z * S[3]) + z * w * (S[4] + z * S[5]);
    let sin = x + z * x * (S[0] + z * r);
    let r = z * (C[0] + z * (C[1] + z * C[2])) + w * w * (C[3] + z * (C[4] + z * C[5]));
    let half = 0.5 * z;
    let v = 1.0 - half;
    let cos = v + (((1.0 - v) - half) + z * r);
    if swap {
        (cos, sin)
    } else {
        (sin, cos)
    }
}

/// Rotates `(c, s)` counter-clockwise by `k` quarter turns (exactly: a
/// swap and sign flips, selected without branches, which the faces of
/// points all over the sphere would mispredict).
#[inline]
fn rotate_quarter_turns(c: f64, s: f64, k: u8) -> (f64, f64) {
    // (c, s), (-s, c), (-c, -s), (s, -c)
    const SIGNS: [[f64; 2]; 4] = [[1.0, 1.0], [-1.0, 1.0], [-1.0, -1.0], [1.0, -1.0]];
    let k = (k & 3) as usize;
    let (u, v) = if k & 1 == 1 { (s, c) } else { (c, s) };
    (u * SIGNS[k][0], v * SIGNS[k][1])
}

/// Splits the longitude of the direction `(cx, cy)` into a quadrant `q` in `0..4` and the
/// fraction `u` in `[0, 1)` of the quadrant: `phi = (q + u) pi / 2`.
/// The zero direction (a pole) gives `(0, 0)`.
#[inline]
fn quadrant(cx: f64, cy: f64) -> (u8, f64) {
    // Rotate by -q pi / 2 exactly so that the direction lies in the first quadrant.
    let (q, a, b) = if cx > 0.0 && cy >= 0.0 {
        (0, cx, cy)
    } else if cx <= 0.0 && cy > 0.0 {
        (1, cy, -cx)
    } else if cx < 0.0 && cy <= 0.0 {
        (2, -cx, -cy)
    } else if cx >= 0.0 && cy < 0.0 {
        (3, -cy, cx)
    } else {
        return (0, 0.0);
    };
    let u = b.atan2(a) * FRAC_2_PI;
    if u >= 1.0 {
        ((q + 1) & 3, 0.0)
    } else {
        // `max` also turns -0.0 into +0.0.
        (q, u.max(0.0))
    }
}

/// The forward mapping from `(cx, cy)` (direction of the longitude, any positive scale),
/// `z = cos(theta)` and `sin_theta = sin(theta) >= 0`.
fn from_parts(cx: f64, cy: f64, z: f64, sin_theta: f64) -> FacePoint {
    let (q, u) = quadrant(cx, cy);
    if z.abs() <= Z_SEAM {
        let t = 0.75 * z;
        // jp, jm in [0, 2) since u in [0, 1) and |t| <= 1/2.
        let jp = 0.5 + u - t;
        let jm = 0.5 + u + t;
        let fp = jp.floor();
        let fm = jm.floor();
        let x = (jm - fm).clamp(0.0, 1.0);
        let y = (1.0 - (jp - fp)).clamp(0.0, 1.0);
        let face = if fp == fm {
            4 + ((q + fp as u8) & 3)
        } else if fp < fm {
            (q + fp as u8) & 3
        } else {
            8 + ((q + fm as u8) & 3)
        };
        FacePoint { face, x, y }
    } else {
        // s = sqrt(3 (1 - |z|)) in [0, 1], computed without cancellation.
        let s = (sin_theta * (3.0 / (1.0 + z.abs())).sqrt()).min(1.0);
        let jp = (u * s).min(1.0);
        let jm = ((1.0 - u) * s).min(1.0);
        if z > 0.0 {
            FacePoint {
                face: q,
                x: 1.0 - jm,
                y: 1.0 - jp,
            }
        } else {
            FacePoint {
                face: q + 8,
                x: jp,
                y: jm,
            }
        }
    }
}

/// Unbiased binary exponent of a positive finite `m` (subnormals give -1023).
#[inline]
fn exponent(m: f64) -> i32 {
    ((m.to_bits() >> 52) & 0x7ff) as i32 - 1023
}

/// `2^e` for `e` in `-1074..=1023`, exactly.
#[inline]
fn pow2(e: i32) -> f64 {
    if e >= -1022 {
        f64::from_bits(((e + 1023) as u64) << 52)
    } else {
        f64::from_bits(1u64 << (e + 1074))
    }
}

/// Unit vector of colatitude `theta` and longitude `phi` (radians).
///
/// # Example
/// ```
/// use tessera::healpix::angles_to_vec;
/// let v = angles_to_vec(std::f64::consts::FRAC_PI_2, std::f64::consts::FRAC_PI_2);
/// assert!((v - glam::DVec3::Y).length() < 1e-15);
/// ```
#[inline]
pub fn angles_to_vec(theta: f64, phi: f64) -> DVec3 {
    let (st, ct) = theta.sin_cos();
    let (sp, cp) = phi.sin_cos();
    DVec3::new(st * cp, st * sp, ct)
}

/// Colatitude `theta` in `[0, pi]` and longitude `phi` in `[0, 2 pi)` of a (not necessarily
/// normalised) vector. `theta` is computed as `atan2(hypot(x, y), z)`, accurate at the poles.
/// The zero vector gives `(0, 0)`; NaN components give NaN angles.
///
/// # Example
/// ```
/// use tessera::healpix::vec_to_angles;
/// let (theta, phi) = vec_to_angles(glam::DVec3::new(0.0, -1.0, 0.0));
/// assert!((theta - std::f64::consts::FRAC_PI_2).abs() < 1e-15);
/// assert!((phi - 1.5 * std::f64::consts::PI).abs() < 1e-15);
/// ```
pub fn vec_to_angles(v: DVec3) -> (f64, f64) {
    let theta = v.x.hypot(v.y).atan2(v.z);
    let mut phi = v.y.atan2(v.x);
    if phi < 0.0 {
        phi += TAU;
    }
    if phi >= TAU {
        // -tiny + TAU rounds to TAU: the closest representable in-range angle is 0.
        phi = 0.0;
    }
    // `+ 0.0` turns -0.0 into +0.0.
    (theta, phi + 0.0)
}

/// Unit vector of a longitude and latitude in degrees (Z up).
///
/// # Example
/// ```
/// let v = tessera::healpix::lonlat_to_vec(0.0, 90.0);
/// assert!((v.z - 1.0).abs() < 1e-15);
/// ```
pub fn lonlat_to_vec(lon_deg: f64, lat_deg: f64) -> DVec3 {
    let (lon, lat) = (lon_deg.to_radians(), lat_deg.to_radians());
    DVec3::new(lat.cos() * lon.cos(), lat.cos() * lon.sin(), lat.sin())
}

/// Longitude in `[-180, 180)` and latitude in `[-90, 90]`, in degrees, of a (not necessarily
/// normalised) vector.
///
/// # Example
/// ```
/// use tessera::healpix::lonlat_deg;
/// let (lon, lat) = lonlat_deg(glam::DVec3::new(-1.0, 0.0, 1.0));
/// assert_eq!(lon, -180.0);
/// assert!((lat - 45.0).abs() < 1e-12);
/// ```
pub fn lonlat_deg(v: DVec3) -> (f64, f64) {
    let mut lon = v.y.atan2(v.x).to_degrees();
    if lon >= 180.0 {
        lon -= 360.0;
    }
    let lat = v.z.atan2(v.x.hypot(v.y)).to_degrees().clamp(-90.0, 90.0);
    (lon + 0.0, lat)
}

/// Centre of cell `(i, j)` of face `face` at resolution `nside`: the image of the face point
/// `((i + 0.5) / nside, (j + 0.5) / nside)`.
///
/// `i` and `j` should be in `0..nside` (out-of-range values are clamped to the face).
///
/// # Example
/// ```
/// use tessera::healpix::{cell_center, FacePoint};
/// assert_eq!(cell_center(5, 1, 0, 0), FacePoint::new(5, 0.5, 0.5).to_vec());
/// ```
pub fn cell_center(face: u8, nside: u64, i: u64, j: u64) -> DVec3 {
    let n = nside as f64;
    FacePoint::new(face, (i as f64 + 0.5) / n, (j as f64 + 0.5) / n).to_vec()
}

/// A cell `(i, j)` of a face at some resolution `nside` (given separately), with
/// `0 <= i, j < nside`; `i` runs along `x`, `j` along `y`.
///
/// # Example
/// ```
/// use tessera::healpix::Cell;
/// let c = Cell { face: 7, i: 3, j: 0 };
/// assert_eq!(c.i, 3);
/// ```
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct Cell {
    /// Base face, in `0..12`.
    pub face: u8,
    /// Index along the face's `x` axis, in `0..nside`.
    pub i: i64,
    /// Index along the face's `y` axis, in `0..nside`.
    pub j: i64,
}

/// One of the four edge directions of the face-local frame, in counter-clockwise order.
///
/// # Example
/// ```
/// use tessera::healpix::Dir;
/// assert_eq!(Dir::PlusX.rotate_ccw(1), Dir::PlusY);
/// ```
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Dir {
    /// Towards increasing `x` (north-east).
    PlusX = 0,
    /// Towards increasing `y` (north-west).
    PlusY = 1,
    /// Towards decreasing `x` (south-west).
    MinusX = 2,
    /// Towards decreasing `y` (south-east).
    MinusY = 3,
}

impl Dir {
    /// The four directions, in counter-clockwise order.
    ///
    /// # Example
    /// ```
    /// use tessera::healpix::Dir;
    /// assert_eq!(Dir::ALL[2], Dir::MinusX);
    /// ```
    pub const ALL: [Dir; 4] = [Dir::PlusX, Dir::PlusY, Dir::MinusX, Dir::MinusY];

    /// Index in counter-clockwise order (`PlusX` = 0, ..., `MinusY` = 3).
    ///
    /// # Example
    /// ```
    /// use tessera::healpix::Dir;
    /// assert_eq!(Dir::MinusY.index(), 3);
    /// ```
    #[inline]
    pub const fn index(self) -> u8 {
        self as u8
    }

    /// The direction of index `i % 4`.
    ///
    /// # Example
    /// ```
    /// use tessera::healpix::Dir;
    /// assert_eq!(Dir::from_index(5), Dir::PlusY);
    /// ```
    #[inline]
    pub const fn from_index(i: u8) -> Dir {
        match i & 3 {
            0 => Dir::PlusX,
            1 => Dir::PlusY,
            2 => Dir::MinusX,
            _ => Dir::MinusY,
        }
    }

    /// The opposite direction.
    ///
    /// # Example
    /// ```
    /// use tessera::healpix::Dir;
    /// assert_eq!(Dir::PlusY.opposite(), Dir::MinusY);
    /// ```
    #[inline]
    pub const fn opposite(self) -> Dir {
        Dir::from_index(self.index() + 2)
    }

    /// The direction rotated counter-clockwise by `quarter_turns` quarter turns.
    ///
    /// # Example
    /// ```
    /// use tessera::healpix::Dir;
    /// assert_eq!(Dir::MinusY.rotate_ccw(1), Dir::PlusX);
    /// ```
    #[inline]
    pub const fn rotate_ccw(self, quarter_turns: u8) -> Dir {
        Dir::from_index(self.index() + (quarter_turns & 3))
    }

    /// The same geometric direction expressed in a frame that is rotated counter-clockwise by
    /// `turns` quarter turns, e.g. the `turns` returned by [`step`]: after
    /// `let (next, turns) = step(cell, nside, dir)`, going on straight is
    /// `dir.reframe(turns)` and going back is `dir.reframe(turns).opposite()`.
    ///
    /// # Example
    /// ```
    /// use tessera::healpix::Dir;
    /// // In a frame rotated by a quarter turn ccw, the old +x axis is the new -y axis.
    /// assert_eq!(Dir::PlusX.reframe(1), Dir::MinusY);
    /// ```
    #[inline]
    pub const fn reframe(self, turns: u8) -> Dir {
        Dir::from_index(self.index() + 4 - (turns & 3))
    }
}

/// The edge-neighbour of `cell` in direction `dir` at resolution `nside`, and the number of
/// quarter turns `turns` in `0..4` by which the local frame rotates counter-clockwise (seen
/// from outside the sphere) when crossing into the neighbour's face: the new face's axes are
/// the old ones rotated by `turns` quarter turns (see [`Dir::reframe`]).
///
/// `turns` is 0 inside a face and across all seams except those between two polar faces of
/// the same cap (1 or 3 there). The face gluing, in face coordinates with `k` taken modulo 4:
///
/// * north `k`: `(1, t)` = north `k+1`: `(t, 1)`;
/// * north `k`: `(0, t)` = equatorial `4+k`: `(1, t)`;
/// * north `k`: `(t, 0)` = equatorial `4+(k+1)`: `(t, 1)`;
/// * equatorial `4+k`: `(0, t)` = south `8+(k-1)`: `(1, t)`;
/// * equatorial `4+k`: `(t, 0)` = south `8+k`: `(t, 1)`;
/// * south `8+k`: `(0, t)` = south `8+(k-1)`: `(t, 0)`.
///
/// `cell` must satisfy `0 <= i, j < nside` (out-of-range input gives an unspecified cell but
/// does not panic).
///
/// # Example
/// ```
/// use tessera::healpix::{step, Cell, Dir};
/// // Leaving north face 0 through its x = 1 edge enters north face 1 through its y = 1 edge.
/// let (next, turns) = step(Cell { face: 0, i: 3, j: 1 }, 4, Dir::PlusX);
/// assert_eq!((next, turns), (Cell { face: 1, i: 1, j: 3 }, 1));
/// // Stepping back:
/// let back = Dir::PlusX.reframe(turns).opposite();
/// assert_eq!(step(next, 4, back).0, Cell { face: 0, i: 3, j: 1 });
/// ```
pub fn step(cell: Cell, nside: i64, dir: Dir) -> (Cell, u8) {
    let Cell { face, i, j } = cell;
    let (ni, nj) = match dir {
        Dir::PlusX => (i.saturating_add(1), j),
        Dir::PlusY => (i, j.saturating_add(1)),
        Dir::MinusX => (i.saturating_sub(1), j),
        Dir::MinusY => (i, j.saturating_sub(1)),
    };
    if (0..nside).contains(&ni) && (0..nside).contains(&nj) {
        return (Cell { face, i: ni, j: nj }, 0);
    }
    let last = nside.saturating_sub(1);
    let face = face % FACE_COUNT as u8;
    let k = face & 3;
    let next = (k + 1) & 3;
    let prev = (k + 3) & 3;
    let cell = |face: u8, i: i64, j: i64| Cell { face, i, j };
    match (face / 4, dir) {
        // North faces.
        (0, Dir::PlusX) => (cell(next, j, last), 1),
        (0, Dir::PlusY) => (cell(prev, last, i), 3),
        (0, Dir::MinusX) => (cell(4 + k, last, j), 0),
        (0, Dir::MinusY) => (cell(4 + next, i, last), 0),
        // Equatorial faces.
        (1, Dir::PlusX) => (cell(k, 0, j), 0),
        (1, Dir::PlusY) => (cell(prev, i, 0), 0),
        (1, Dir::MinusX) => (cell(8 + prev, last, j), 0),
        (1, Dir::MinusY) => (cell(8 + k, i, last), 0),
        // South faces.
        (_, Dir::PlusX) => (cell(4 + next, 0, j), 0),
        (_, Dir::PlusY) => (cell(4 + k, i, 0), 0),
        (_, Dir::MinusX) => (cell(8 + prev, j, 0), 1),
        (_, Dir::MinusY) => (cell(8 + next, 0, i), 3),
    }
}

/// Whether the given corner of a face is one of the 8 vertices shared by only three faces
/// (instead of four): the east and west vertices of the polar faces, which are the north and
/// south vertices of the equatorial faces, at `z = +-2/3` and `phi = k pi / 2`.
///
/// `corner` is `(x == 1, y == 1)`, e.g. `(false, false)` is the south vertex `(0, 0)`.
///
/// # Example
/// ```
/// use tessera::healpix::is_three_face_corner;
/// assert!(is_three_face_corner(0, (true, false))); // east vertex of north face 0
/// assert!(!is_three_face_corner(0, (true, true))); // the north pole (four faces)
/// assert!(is_three_face_corner(5, (true, true))); // north vertex of equatorial face 5
/// ```
pub fn is_three_face_corner(face: u8, corner: (bool, bool)) -> bool {
    let mixed = corner.0 != corner.1;
    match (face % FACE_COUNT as u8) / 4 {
        1 => !mixed,
        _ => mixed,
    }
}

/// How a HEALPix map orders its `12 nside^2` pixels (the FITS keyword
/// `ORDERING`).
///
/// # Example
/// ```
/// use tessera::healpix::Scheme;
/// assert_eq!("NEST".parse::<Scheme>().unwrap(), Scheme::Nested);
/// assert!("ZIGZAG".parse::<Scheme>().is_err());
/// ```
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Scheme {
    /// Rings of equal latitude from the north pole, each from `phi = 0`
    /// eastwards (healpy's default).
    #[default]
    Ring,
    /// The quadtree: face `f`, then the Morton code of `(i, j)`, `i` in
    /// the even bits ([`nested_index`]).
    Nested,
}

impl std::str::FromStr for Scheme {
    type Err = String;
    /// `RING`, or `NESTED` / `NEST`, in any case (FITS writers use both).
    fn from_str(s: &str) -> Result<Self, String> {
        match s.trim().to_ascii_uppercase().as_str() {
            "RING" => Ok(Scheme::Ring),
            "NESTED" | "NEST" => Ok(Scheme::Nested),
            other => Err(format!("ordering '{other}': expected RING or NESTED")),
        }
    }
}

/// `x`'s bits spread to the even bit positions (bit `k` to bit `2k`).
fn spread_bits(x: u64) -> u64 {
    let mut x = x & 0xffff_ffff;
    x = (x | (x << 16)) & 0x0000_ffff_0000_ffff;
    x = (x | (x << 8)) & 0x00ff_00ff_00ff_00ff;
    x = (x | (x << 4)) & 0x0f0f_0f0f_0f0f_0f0f;
    x = (x | (x << 2)) & 0x3333_3333_3333_3333;
    (x | (x << 1)) & 0x5555_5555_5555_5555
}

/// The NESTED index of `cell` at `nside = 2^depth` (`depth <= 29`): `face *
/// 4^depth` plus the Morton code of `(i, j)`, `i` in the even bits (as
/// HEALPix and `cdshealpix` number them). Out-of-range `i`, `j` are
/// clamped into the face.
///
/// # Example
/// ```
/// use tessera::healpix::{nested_index, Cell};
/// assert_eq!(nested_index(Cell { face: 1, i: 0, j: 0 }, 2), 16);
/// assert_eq!(nested_index(Cell { face: 0, i: 1, j: 0 }, 1), 1);
/// assert_eq!(nested_index(Cell { face: 0, i: 0, j: 1 }, 1), 2);
/// ```
pub fn nested_index(cell: Cell, depth: u32) -> u64 {
    let last = (1i64 << depth) - 1;
    let (i, j) = (cell.i.clamp(0, last) as u64, cell.j.clamp(0, last) as u64);
    let face = (cell.face % FACE_COUNT as u8) as u64;
    (face << (2 * depth)) | spread_bits(i) | (spread_bits(j) << 1)
}

/// The cell `(face, i, j)` at `nside = 2^depth` (`depth <= 29`) of the
/// RING index `ring` (the HEALPix ring-to-face decomposition); indices
/// past `12 nside^2 - 1` are taken as the last pixel.
///
/// # Example
/// ```
/// use tessera::healpix::{ring_cell, Cell};
/// // nside 1: the RING and NESTED indices are the face number
/// assert_eq!(ring_cell(5, 0), Cell { face: 5, i: 0, j: 0 });
/// // the first ring of nside 2 holds the north vertices of faces 0..3
/// assert_eq!(ring_cell(2, 1), Cell { face: 2, i: 1, j: 1 });
/// ```
pub fn ring_cell(ring: u64, depth: u32) -> Cell {
    let nside = 1i64 << depth;
    let npix = 12 * nside * nside;
    let p = (ring.min(npix as u64 - 1)) as i64;
    let ncap = 2 * nside * (nside - 1);
    let nl2 = 2 * nside;
    // ring number from the north pole, position in the ring (from 1),
    // half-pixel shift, pixels per ring per face, face
    let (iring, iphi, kshift, nr, face) = if p < ncap {
        let iring = (1 + (1 + 2 * p as u64).isqrt() as i64) >> 1;
        let iphi = p + 1 - 2 * iring * (iring - 1);
        (iring, iphi, 0, iring, (iphi - 1) / iring)
    } else if p < npix - ncap {
        let ip = p - ncap;
        let tmp = ip >> (depth + 2);
        let iring = tmp + nside;
        let iphi = ip - tmp * 4 * nside + 1;
        let ifm = (iphi - ((tmp + 1) >> 1) + nside - 1) >> depth;
        let ifp = (iphi - ((nl2 + 1 - tmp) >> 1) + nside - 1) >> depth;
        let face = match ifp.cmp(&ifm) {
            std::cmp::Ordering::Equal => ifp | 4,
            std::cmp::Ordering::Less => ifp,
            std::cmp::Ordering::Greater => ifm + 8,
        };
        (iring, iphi, (iring + nside) & 1, nside, face)
    } else {
        let ip = npix - p;
        let r = (1 + (2 * ip as u64 - 1).isqrt() as i64) >> 1;
        let iphi = 4 * r + 1 - (ip - 2 * r * (r - 1));
        (2 * nl2 - r, iphi, 0, r, (iphi - 1) / r + 8)
    };
    // the face's ring of its south vertex and longitude of its centre,
    // in units of nside and of pi / 4
    let irt = iring - (2 + face / 4) * nside + 1;
    let jpll = [1, 3, 5, 7, 0, 2, 4, 6, 1, 3, 5, 7][face as usize];
    let mut ipt = 2 * iphi - jpll * nr - kshift - 1;
    if ipt >= nl2 {
        ipt -= 8 * nside;
    }
    Cell {
        face: face as u8,
        i: (ipt - irt) >> 1,
        j: (-ipt - irt) >> 1,
    }
}

/// The cell at `nside = 2^depth` holding a face point (points on a cell
/// edge go to the cell above it; coordinates are clamped into the face).
///
/// # Example
/// ```
/// use tessera::healpix::{cell_of, Cell, FacePoint};
/// assert_eq!(cell_of(FacePoint::new(3, 0.3, 1.0), 2), Cell { face: 3, i: 1, j: 3 });
/// ```
#[inline]
pub fn cell_of(p: FacePoint, depth: u32) -> Cell {
    let nside = (1u64 << depth) as f64;
    let last = (1i64 << depth) - 1;
    // `as` saturates and sends NaN to 0
    let index = |t: f64| ((t * nside) as i64).clamp(0, last);
    Cell {
        face: p.face % FACE_COUNT as u8,
        i: index(p.x),
        j: index(p.y),
    }
}

/// HEALPix's marker of a pixel without data (healpy's `UNSEEN`): maps
/// read as densities count such pixels as 0.
///
/// # Example
/// ```
/// assert_eq!(tessera::healpix::UNSEEN, -1.6375e30);
/// ```
pub const UNSEEN: f64 = -1.6375e30;

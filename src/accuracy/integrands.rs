//! Test integrands with exact integrals: on the sphere a spherical-harmonic
//! mixture, a von Mises–Fisher lobe, a cap and a clamped cosine; under an
//! environment map Lambertian (clamped cosine) lobes; in the unit square
//! Gaussians, a disc and a Heaviside edge.

use super::Integrand;
use crate::density::envmap::EnvMap;
use glam::{DVec2, DVec3};
use std::f64::consts::{PI, TAU};

/// Legendre polynomials P_1, P_2, P_4, P_6 (zero mean over the sphere).
fn legendre(l: usize, t: f64) -> f64 {
    let t2 = t * t;
    match l {
        1 => t,
        2 => (3.0 * t2 - 1.0) / 2.0,
        4 => (35.0 * t2 * t2 - 30.0 * t2 + 3.0) / 8.0,
        6 => (231.0 * t2 * t2 * t2 - 315.0 * t2 * t2 + 105.0 * t2 - 5.0) / 16.0,
        _ => unreachable!("only the degrees used here"),
    }
}

/// Fixed, unremarkable axes (no alignment with any tiling).
fn axis(x: f64, y: f64, z: f64) -> DVec3 {
    DVec3::new(x, y, z).normalize()
}

/// Integrands over the sphere (integrals per steradian, whole sphere).
pub(super) fn sphere() -> Vec<Integrand<'static, DVec3>> {
    let (a, b, c, d) = (
        axis(1.0, 2.0, 3.0),
        axis(-2.0, 1.0, 0.5),
        axis(0.3, -1.0, 2.0),
        axis(1.0, 1.0, -1.0),
    );
    let kappa = 8.0f64;
    let cap = 30f64.to_radians().cos();
    vec![
        Integrand {
            name: "sh-mixture",
            smooth: true,
            exact: 4.0 * PI,
            f: Box::new(move |p: DVec3| {
                1.0 + 0.6 * legendre(1, a.dot(p))
                    + 0.5 * legendre(2, b.dot(p))
                    + 0.4 * legendre(4, c.dot(p))
                    + 0.3 * legendre(6, d.dot(p))
            }),
        },
        Integrand {
            name: "vmf-8",
            smooth: true,
            exact: TAU * (1.0 - (-2.0 * kappa).exp()) / kappa,
            f: Box::new(move |p: DVec3| (kappa * (b.dot(p) - 1.0)).exp()),
        },
        Integrand {
            name: "cap-30deg",
            smooth: false,
            exact: TAU * (1.0 - cap),
            f: Box::new(move |p: DVec3| f64::from(u8::from(c.dot(p) > cap))),
        },
        Integrand {
            name: "clamped-cosine",
            smooth: false,
            exact: PI,
            f: Box::new(move |p: DVec3| d.dot(p).max(0.0)),
        },
    ]
}

/// `∫ w dω` over the lat-long cell `[φ0, φ1] x [θ0, θ1]` (z up).
fn cell_moment(phi: (f64, f64), theta: (f64, f64)) -> DVec3 {
    let sin2 = |t: f64| t / 2.0 - (2.0 * t).sin() / 4.0; // ∫ sin²θ
    let sincos = |t: f64| t.sin().powi(2) / 2.0; // ∫ sinθ cosθ
    let i2 = sin2(theta.1) - sin2(theta.0);
    DVec3::new(
        (phi.1.sin() - phi.0.sin()) * i2,
        (phi.0.cos() - phi.1.cos()) * i2,
        (phi.1 - phi.0) * (sincos(theta.1) - sincos(theta.0)),
    )
}

/// `∫ max(0, n · w) dω` over a lat-long cell: exact (`n · moment`) when the
/// cell lies on one side of the horizon of `n`, else split into 4x4 sub-cells
/// down to `depth` 0, where the midpoint rule takes over (the horizon
/// crosses few cells, so the error is ~1e-12 of the total).
fn clamped_cosine_cell(n: DVec3, phi: (f64, f64), theta: (f64, f64), depth: u32) -> f64 {
    let corner = |p: f64, t: f64| DVec3::new(t.sin() * p.cos(), t.sin() * p.sin(), t.cos());
    let dots: Vec<f64> = [phi.0, (phi.0 + phi.1) / 2.0, phi.1]
        .iter()
        .flat_map(|&p| {
            [theta.0, (theta.0 + theta.1) / 2.0, theta.1].map(move |t| n.dot(corner(p, t)))
        })
        .collect();
    // 1e-3 margin: a great circle cannot cross a small cell between 9
    // probes that all clear it by more than the cell's sagitta
    let margin = 1e-3;
    if dots.iter().all(|&d| d > margin) {
        return n.dot(cell_moment(phi, theta));
    }
    if dots.iter().all(|&d| d < -margin) {
        return 0.0;
    }
    if depth == 0 {
        let solid = (phi.1 - phi.0) * (theta.0.cos() - theta.1.cos());
        let mid = corner((phi.0 + phi.1) / 2.0, (theta.0 + theta.1) / 2.0);
        return solid * n.dot(mid).max(0.0);
    }
    let k = 4;
    let (dp, dt) = ((phi.1 - phi.0) / k as f64, (theta.1 - theta.0) / k as f64);
    (0..k * k)
        .map(|s| {
            let (i, j) = ((s % k) as f64, (s / k) as f64);
            let p = (phi.0 + i * dp, phi.0 + (i + 1.0) * dp);
            let t = (theta.0 + j * dt, theta.0 + (j + 1.0) * dt);
            clamped_cosine_cell(n, p, t, depth - 1)
        })
        .sum()
}

/// Irradiance `∫ L(w) max(0, n · w) dω` of a z-up map (no rotation) with
/// constant pixels, exact up to the few pixels the horizon crosses.
fn irradiance(map: &EnvMap, n: DVec3) -> f64 {
    let (w, h) = (map.width(), map.height());
    let mut sum = 0.0;
    for j in 0..h {
        let theta = (j as f64 * PI / h as f64, (j + 1) as f64 * PI / h as f64);
        for i in 0..w {
            let v = map.values()[j * w + i];
            if v > 0.0 {
                let phi = (i as f64 * TAU / w as f64, (i + 1) as f64 * TAU / w as f64);
                sum += v * clamped_cosine_cell(n, phi, theta, 4);
            }
        }
    }
    sum
}

/// Lambertian lobes (irradiance at three normals) under a z-up map.
pub(super) fn envmap(map: &EnvMap) -> Vec<Integrand<'_, DVec3>> {
    let normals = [
        ("lambert-up", DVec3::Z),
        ("lambert-side", axis(0.8, -0.3, 0.5)),
        ("lambert-down", axis(-0.5, 0.5, -0.7)),
    ];
    normals
        .into_iter()
        .map(|(name, n)| Integrand {
            name,
            smooth: false,
            exact: irradiance(map, n),
            f: Box::new(move |p: DVec3| map.radiance(p) * n.dot(p).max(0.0)),
        })
        .collect()
}

/// `∫_0^1 exp(−(x − c)² / 2σ²) dx` by composite Simpson (4096 panels:
/// far below 1e-13 relative for σ ≥ 0.04).
fn gaussian_1d(c: f64, sigma: f64) -> f64 {
    let m = 4096;
    let h = 1.0 / m as f64;
    let f = |x: f64| (-(x - c).powi(2) / (2.0 * sigma * sigma)).exp();
    let inner: f64 = (1..m)
        .map(|k| if k % 2 == 1 { 4.0 } else { 2.0 } * f(k as f64 * h))
        .sum();
    (f(0.0) + inner + f(1.0)) * h / 3.0
}

/// An isotropic Gaussian at `c` with exact integral over the square.
fn gaussian(c: DVec2, sigma: f64) -> (impl Fn(DVec2) -> f64, f64) {
    let exact = gaussian_1d(c.x, sigma) * gaussian_1d(c.y, sigma);
    (
        move |p: DVec2| (-(p - c).length_squared() / (2.0 * sigma * sigma)).exp(),
        exact,
    )
}

/// Integrands over the unit square. The Gaussians stay 5.5σ or more inside
/// it, so a toroidal shift leaves them smooth to ~1e-7 of their peak.
pub(super) fn plane() -> Vec<Integrand<'static, DVec2>> {
    let (g, g_exact) = gaussian(DVec2::new(0.45, 0.55), 0.08);
    let parts = [
        (1.0, gaussian(DVec2::new(0.3, 0.3), 0.05)),
        (0.7, gaussian(DVec2::new(0.7, 0.35), 0.05)),
        (0.5, gaussian(DVec2::new(0.5, 0.6), 0.09)),
    ];
    let mix_exact = parts.iter().map(|(w, (_, e))| w * e).sum();
    let centre = DVec2::new(0.5, 0.5);
    vec![
        Integrand {
            name: "gaussian",
            smooth: true,
            exact: g_exact,
            f: Box::new(g),
        },
        Integrand {
            name: "gaussian-mixture",
            smooth: true,
            exact: mix_exact,
            f: Box::new(move |p: DVec2| parts.iter().map(|(w, (f, _))| w * f(p)).sum()),
        },
        Integrand {
            name: "disc",
            smooth: false,
            exact: PI * 0.3 * 0.3,
            f: Box::new(move |p: DVec2| f64::from(u8::from((p - centre).length() < 0.3))),
        },
        Integrand {
            name: "edge",
            smooth: false,
            // ∫_0^1 (0.25 + 0.37 x) dx
            exact: 0.25 + 0.37 / 2.0,
            f: Box::new(|p: DVec2| f64::from(u8::from(p.y < 0.25 + 0.37 * p.x))),
        },
    ]
}

//! Tests of `tessera::metrics` and `tessera::baselines` against brute-force
//! references and closed forms.

use approx::assert_relative_eq;
use glam::{DVec2, DVec3};
use proptest::prelude::*;
use std::f64::consts::{FRAC_PI_2, PI, TAU};
use tessera::baselines::{
    jittered_grid_2d, spherical_fibonacci, spherical_fibonacci_into, uniform_random_2d,
    uniform_random_sphere, SplitMix64,
};
use tessera::metrics::plane::{
    anisotropy, centered_l2_discrepancy, hex_spacing, l2_star_discrepancy, low_frequency_power,
    mean_nn_distance, min_distance, periodogram, radial_average,
};
use tessera::metrics::sphere::{
    angular_power, cap_discrepancy_l2, covering_radius, geodesic_distance, mesh_ratio,
    riesz1_normalized, separation,
};
use tessera::metrics::{
    plane_report, sphere_report, Measure, Options, PlaneMeasure, SphereMeasure,
};

// ---------------------------------------------------------------------------
// Reference configurations and brute-force references (sphere)
// ---------------------------------------------------------------------------

fn octahedron() -> Vec<DVec3> {
    vec![
        DVec3::X,
        -DVec3::X,
        DVec3::Y,
        -DVec3::Y,
        DVec3::Z,
        -DVec3::Z,
    ]
}

fn cube() -> Vec<DVec3> {
    let mut v = Vec::new();
    for sx in [-1.0, 1.0] {
        for sy in [-1.0, 1.0] {
            for sz in [-1.0, 1.0] {
                v.push(DVec3::new(sx, sy, sz) / 3f64.sqrt());
            }
        }
    }
    v
}

fn golden() -> f64 {
    (1.0 + 5f64.sqrt()) / 2.0
}

fn icosahedron() -> Vec<DVec3> {
    let g = golden();
    let mut v = Vec::new();
    for s1 in [-1.0, 1.0] {
        for s2 in [-1.0, 1.0] {
            v.push(DVec3::new(0.0, s1, s2 * g));
            v.push(DVec3::new(s1, s2 * g, 0.0));
            v.push(DVec3::new(s2 * g, 0.0, s1));
        }
    }
    v.into_iter().map(|p| p.normalize()).collect()
}

/// Points in the cap of angular radius `radius` around +Z.
fn cap_points(n: usize, radius: f64, seed: u64) -> Vec<DVec3> {
    let mut rng = SplitMix64::new(seed);
    (0..n)
        .map(|_| {
            let z = 1.0 - rng.next_f64() * (1.0 - radius.cos());
            let s = (1.0 - z * z).sqrt();
            let (sp, cp) = (TAU * rng.next_f64()).sin_cos();
            DVec3::new(s * cp, s * sp, z)
        })
        .collect()
}

fn brute_min_geodesic(p: &[DVec3]) -> f64 {
    let mut best = f64::INFINITY;
    for i in 0..p.len() {
        for j in 0..i {
            best = best.min(geodesic_distance(p[i], p[j]));
        }
    }
    best
}

fn dist_to_set(y: DVec3, p: &[DVec3]) -> f64 {
    p.iter()
        .map(|&q| geodesic_distance(y, q))
        .fold(f64::INFINITY, f64::min)
}

/// Exact covering radius by exhaustive candidates, O(N⁴): the maximiser of
/// `min_i d(y, x_i)` is the antipode of a point, the point of a bisector
/// farthest from its pair, or a point equidistant from three samples.
fn brute_covering_angle(p: &[DVec3]) -> f64 {
    let n = p.len();
    let mut cands = Vec::new();
    for i in 0..n {
        cands.push(-p[i]);
        for j in 0..i {
            let s = p[i] + p[j];
            if s.length() > 1e-9 {
                cands.push(-s.normalize());
            }
            for k in 0..j {
                let m = (p[j] - p[i]).cross(p[k] - p[i]);
                if m.length() > 1e-12 {
                    cands.push(m.normalize());
                    cands.push(-m.normalize());
                }
            }
        }
    }
    cands.iter().map(|&y| dist_to_set(y, p)).fold(0.0, f64::max)
}

/// Legendre polynomials up to degree 5, explicit forms.
fn legendre_explicit(l: usize, t: f64) -> f64 {
    match l {
        0 => 1.0,
        1 => t,
        2 => (3.0 * t * t - 1.0) / 2.0,
        3 => (5.0 * t.powi(3) - 3.0 * t) / 2.0,
        4 => (35.0 * t.powi(4) - 30.0 * t * t + 3.0) / 8.0,
        5 => (63.0 * t.powi(5) - 70.0 * t.powi(3) + 15.0 * t) / 8.0,
        _ => unreachable!(),
    }
}

// ---------------------------------------------------------------------------
// Sphere: closed forms
// ---------------------------------------------------------------------------

#[test]
fn octahedron_closed_forms() {
    let p = octahedron();
    let n = 6f64;
    assert_relative_eq!(separation(&p), n.sqrt() * FRAC_PI_2, max_relative = 1e-12);
    // E = 6 (4/√2 + 1/2) = 12√2 + 3.
    let e = 12.0 * 2f64.sqrt() + 3.0;
    assert_relative_eq!(
        riesz1_normalized(&p),
        (e - 36.0) / n.powf(1.5),
        max_relative = 1e-12
    );
    // D² = 1/3 − (24√2 + 12)/144 = (3 − 2√2)/12, so D = (√2 − 1)/√12.
    assert_relative_eq!(
        cap_discrepancy_l2(&p),
        (2f64.sqrt() - 1.0) / 12f64.sqrt(),
        max_relative = 1e-12
    );
    let cover = (1.0 / 3f64.sqrt()).acos();
    assert_relative_eq!(covering_radius(&p), n.sqrt() * cover, max_relative = 1e-12);
    assert_relative_eq!(
        mesh_ratio(&p),
        2.0 * cover / FRAC_PI_2,
        max_relative = 1e-12
    );
}

#[test]
fn cube_closed_forms() {
    let p = cube();
    let n = 8f64;
    // Edge: chord 2/√3, angle acos(1/3).
    assert_relative_eq!(
        separation(&p),
        n.sqrt() * (1.0f64 / 3.0).acos(),
        max_relative = 1e-12
    );
    // Per vertex: 3 edges (2/√3), 3 face diagonals (2√2/√3), 1 antipode (2).
    let e = n * (3.0 * 3f64.sqrt() / 2.0 + 3.0 * 3f64.sqrt() / (2.0 * 2f64.sqrt()) + 0.5);
    assert_relative_eq!(
        riesz1_normalized(&p),
        (e - 64.0) / n.powf(1.5),
        max_relative = 1e-12
    );
    let s = n * (3.0 * 2.0 / 3f64.sqrt() + 3.0 * 2.0 * 2f64.sqrt() / 3f64.sqrt() + 2.0);
    assert_relative_eq!(
        cap_discrepancy_l2(&p),
        (1.0 / 3.0 - s / (4.0 * n * n)).sqrt(),
        max_relative = 1e-12
    );
    // Farthest points: face centres, at acos(1/√3) from the 4 face vertices.
    assert_relative_eq!(
        covering_radius(&p),
        n.sqrt() * (1.0 / 3f64.sqrt()).acos(),
        max_relative = 1e-12
    );
}

#[test]
fn icosahedron_closed_forms() {
    let p = icosahedron();
    let n = 12f64;
    // Neighbours at angle acos(1/√5); chords a (edge) and b = φ a, a² + b² = 4.
    assert_relative_eq!(
        separation(&p),
        n.sqrt() * (1.0 / 5f64.sqrt()).acos(),
        max_relative = 1e-12
    );
    let a = 4.0 / (10.0 + 2.0 * 5f64.sqrt()).sqrt();
    let b = golden() * a;
    assert_relative_eq!(a * a + b * b, 4.0, max_relative = 1e-14);
    let e = n * (5.0 / a + 5.0 / b + 0.5);
    assert_relative_eq!(
        riesz1_normalized(&p),
        (e - 144.0) / n.powf(1.5),
        max_relative = 1e-12
    );
    let s = n * (5.0 * a + 5.0 * b + 2.0);
    assert_relative_eq!(
        cap_discrepancy_l2(&p),
        (1.0 / 3.0 - s / (4.0 * n * n)).sqrt(),
        max_relative = 1e-12
    );
    // Farthest points: face centres, tan θ = 2/φ².
    let cover = (2.0 / (golden() * golden())).atan();
    assert_relative_eq!(covering_radius(&p), n.sqrt() * cover, max_relative = 1e-12);
    // The icosahedron is a spherical 5-design.
    let pw = angular_power(&p, 6);
    assert_eq!(pw[0], 12.0);
    for (l, v) in pw.iter().enumerate().take(6).skip(1) {
        assert!(v.abs() < 1e-12, "P({l}) = {v}");
    }
    assert!(pw[6] > 1.0);
}

#[test]
fn two_and_three_points() {
    // Antipodal pair: D² = 1/3 − 4/(4·4) = 1/12; E = 1.
    let p = [DVec3::Z, -DVec3::Z];
    assert_relative_eq!(
        cap_discrepancy_l2(&p),
        (1.0f64 / 12.0).sqrt(),
        max_relative = 1e-14
    );
    assert_relative_eq!(
        riesz1_normalized(&p),
        -3.0 / 2f64.powf(1.5),
        max_relative = 1e-14
    );
    assert_relative_eq!(separation(&p), 2f64.sqrt() * PI, max_relative = 1e-14);
    assert_relative_eq!(
        covering_radius(&p),
        2f64.sqrt() * FRAC_PI_2,
        max_relative = 1e-12
    );
    // Orthogonal pair: farthest point −(x+y)/√2 at 3π/4.
    let p = [DVec3::X, DVec3::Y];
    assert_relative_eq!(
        covering_radius(&p),
        2f64.sqrt() * 0.75 * PI,
        max_relative = 1e-12
    );
    // Pair at angle θ: π − θ/2.
    let t: f64 = 0.3;
    let p = [DVec3::Z, DVec3::new(t.sin(), 0.0, t.cos())];
    assert_relative_eq!(
        covering_radius(&p),
        2f64.sqrt() * (PI - t / 2.0),
        max_relative = 1e-12
    );
    // Three points on the equator: the poles, at π/2.
    let p: Vec<DVec3> = (0..3)
        .map(|k| {
            let a = TAU * k as f64 / 3.0;
            DVec3::new(a.cos(), a.sin(), 0.0)
        })
        .collect();
    assert_relative_eq!(
        covering_radius(&p),
        3f64.sqrt() * FRAC_PI_2,
        max_relative = 1e-12
    );
    // Three points on a small circle z = 1/2: the south pole, at 2π/3.
    let p: Vec<DVec3> = (0..3)
        .map(|k| {
            let a = TAU * k as f64 / 3.0;
            let s = 0.75f64.sqrt();
            DVec3::new(s * a.cos(), s * a.sin(), 0.5)
        })
        .collect();
    assert_relative_eq!(
        covering_radius(&p),
        3f64.sqrt() * TAU / 3.0,
        max_relative = 1e-12
    );
}

#[test]
fn empty_and_single_point() {
    let e: [DVec3; 0] = [];
    assert!(separation(&e).is_nan());
    assert!(cap_discrepancy_l2(&e).is_nan());
    assert!(riesz1_normalized(&e).is_nan());
    assert!(covering_radius(&e).is_nan());
    assert!(mesh_ratio(&e).is_nan());
    assert_eq!(angular_power(&e, 3), vec![0.0; 4]);
    let r = sphere_report(&e);
    assert_eq!(r.n(), 0);
    assert!(r[SphereMeasure::Separation].is_nan() && r[SphereMeasure::Covering].is_nan());

    let one = [DVec3::new(0.6, 0.0, 0.8)];
    assert_eq!(separation(&one), f64::INFINITY);
    assert_relative_eq!(
        cap_discrepancy_l2(&one),
        (1.0f64 / 3.0).sqrt(),
        max_relative = 1e-15
    );
    assert_eq!(riesz1_normalized(&one), -1.0);
    assert_relative_eq!(covering_radius(&one), PI, max_relative = 1e-15);
    assert!(mesh_ratio(&one).is_nan());
    // Σ_m Q_lm(z)² = P_l(1) = 1, to rounding
    for v in angular_power(&one, 3) {
        assert_relative_eq!(v, 1.0, max_relative = 1e-15);
    }
    let r = sphere_report(&one);
    assert_eq!(r[SphereMeasure::Separation], f64::INFINITY);
    assert_relative_eq!(r[SphereMeasure::Covering], PI);
    assert!(r[SphereMeasure::MeshRatio].is_nan());
}

#[test]
fn coincident_points() {
    let mut p = uniform_random_sphere(50, 11);
    p.push(p[7]);
    p.push(p[7]);
    assert_eq!(separation(&p), 0.0);
    assert_eq!(riesz1_normalized(&p), f64::INFINITY);
    assert_eq!(mesh_ratio(&p), f64::INFINITY);
    // Duplicates do not change the covering angle.
    let base = covering_radius(&p[..50]) / 50f64.sqrt();
    assert_relative_eq!(
        covering_radius(&p) / 52f64.sqrt(),
        base,
        max_relative = 1e-12
    );
    assert!(cap_discrepancy_l2(&p).is_finite());
}

// ---------------------------------------------------------------------------
// Sphere: brute-force references on random sets
// ---------------------------------------------------------------------------

#[test]
fn separation_matches_brute_force() {
    for (n, seed) in [(2, 1), (3, 2), (10, 3), (200, 4), (1500, 5)] {
        let p = uniform_random_sphere(n, seed);
        let want = brute_min_geodesic(&p) * (n as f64).sqrt();
        assert_relative_eq!(separation(&p), want, max_relative = 1e-12);
    }
}

#[test]
fn discrepancy_and_energy_match_brute_force() {
    for (n, seed) in [(2, 1), (7, 2), (100, 3), (777, 4)] {
        let p = uniform_random_sphere(n, seed);
        let (mut s, mut e) = (0.0, 0.0);
        for i in 0..n {
            for j in 0..n {
                if i != j {
                    let d = (p[i] - p[j]).length();
                    s += d;
                    e += 1.0 / d;
                }
            }
        }
        let nf = n as f64;
        let d2 = 1.0 / 3.0 - s / (4.0 * nf * nf);
        assert_relative_eq!(cap_discrepancy_l2(&p), d2.sqrt(), max_relative = 1e-9);
        assert_relative_eq!(
            riesz1_normalized(&p),
            (e - nf * nf) / nf.powf(1.5),
            max_relative = 1e-9
        );
    }
}

#[test]
fn discrepancy_is_rotation_invariant_to_high_precision() {
    // D² ≈ 1.2e-6 here: a rotation changes every chord by rounding only
    // (D² by ~3e-17), so D agrees to ~1e-11 relative; a plain f64 sum would
    // only agree to ~1e-9.
    let p = spherical_fibonacci(3072);
    let axis = DVec3::new(0.3, -0.5, 0.8).normalize();
    let q: Vec<DVec3> = p
        .iter()
        .map(|&x| glam::DQuat::from_axis_angle(axis, 1.234).mul_vec3(x))
        .collect();
    let (a, b) = (cap_discrepancy_l2(&p), cap_discrepancy_l2(&q));
    assert_relative_eq!(a, b, max_relative = 5e-11);
}

#[test]
fn covering_matches_exhaustive_reference() {
    // Small random sets (all-pairs path) and N = 70 (k-d tree path).
    for (n, seed) in [(4, 1), (5, 2), (8, 3), (20, 4), (35, 5), (70, 6)] {
        let p = uniform_random_sphere(n, seed);
        let want = brute_covering_angle(&p) * (n as f64).sqrt();
        assert_relative_eq!(covering_radius(&p), want, max_relative = 1e-9);
    }
    // Clustered sets: wide cells, cube-map fallback.
    for (n, radius, seed) in [(6, 0.2, 7), (25, 0.5, 8), (70, 1.2, 9), (80, 2.0, 10)] {
        let p = cap_points(n, radius, seed);
        let want = brute_covering_angle(&p) * (n as f64).sqrt();
        assert_relative_eq!(covering_radius(&p), want, max_relative = 1e-9);
    }
    // Points on a great circle.
    let p: Vec<DVec3> = (0..9)
        .map(|k| {
            let a = 0.7 * k as f64;
            DVec3::new(a.cos(), 0.0, a.sin())
        })
        .collect();
    assert_relative_eq!(covering_radius(&p), 3.0 * FRAC_PI_2, max_relative = 1e-12);
}

#[test]
fn covering_bounds_dense_probe() {
    let probe = spherical_fibonacci(200_000);
    // Probe spacing: covering radius of the probe set itself, < 0.006 rad.
    let slack = 0.006;
    for (p, label) in [
        (uniform_random_sphere(400, 21), "random"),
        (cap_points(300, 0.8, 22), "cap"),
        (spherical_fibonacci(500), "fibonacci"),
    ] {
        let n = p.len() as f64;
        let exact = covering_radius(&p) / n.sqrt();
        let coords: Vec<[f64; 3]> = p.iter().map(|x| x.to_array()).collect();
        let tree: kiddo::ImmutableKdTree<f64, 3> = kiddo::ImmutableKdTree::new_from_slice(&coords);
        let probe_max = probe
            .iter()
            .map(|&y| {
                let nn = tree.nearest_one::<kiddo::SquaredEuclidean>(&y.to_array());
                geodesic_distance(y, p[nn.item as usize])
            })
            .fold(0.0, f64::max);
        assert!(probe_max <= exact + 1e-12, "{label}: {probe_max} > {exact}");
        assert!(exact - probe_max < slack, "{label}: {exact} vs {probe_max}");
    }
}

#[test]
fn angular_power_matches_explicit_legendre() {
    let p = uniform_random_sphere(60, 31);
    let pw = angular_power(&p, 5);
    let n = p.len() as f64;
    for (l, &got) in pw.iter().enumerate() {
        let mut s = 0.0;
        for a in &p {
            for b in &p {
                s += legendre_explicit(l, a.dot(*b).clamp(-1.0, 1.0));
            }
        }
        assert_relative_eq!(got, s / n, max_relative = 1e-9, epsilon = 1e-12);
    }
    // P(1) = |Σ x|² / N.
    let sum: DVec3 = p.iter().copied().sum();
    assert_relative_eq!(pw[1], sum.length_squared() / n, max_relative = 1e-12);
    // Octahedron: 3-design, odd degrees vanish by symmetry.
    let pw = angular_power(&octahedron(), 9);
    assert_eq!(pw[0], 6.0);
    for l in [1, 2, 3, 5, 7, 9] {
        assert!(pw[l].abs() < 1e-12, "P({l}) = {}", pw[l]);
    }
    // P(4): Σ_{i,j} P4 = 6·1 + 24 P4(0) + 6 P4(−1) = 6 + 9 + 6.
    assert_relative_eq!(pw[4], 21.0 / 6.0, max_relative = 1e-12);
    assert_eq!(angular_power(&octahedron(), 0), vec![6.0]);
}

#[test]
fn fibonacci_and_random_reference_values() {
    for n in [3072usize, 12288] {
        let p = spherical_fibonacci(n);
        let r = sphere_report(&p);
        eprintln!("fibonacci N = {n}: {}", serde_json::to_string(&r).unwrap());
        assert!((r[SphereMeasure::Separation] - 3.09).abs() < 0.03, "{r:?}");
        assert!((r[SphereMeasure::Energy] + 1.100).abs() < 0.005, "{r:?}");
        // The largest holes of the lattice sit near the poles.
        assert!(
            r[SphereMeasure::Covering] > 2.5 && r[SphereMeasure::Covering] < 2.9,
            "{r:?}"
        );
        assert!(
            r[SphereMeasure::MeshRatio] > 1.6 && r[SphereMeasure::MeshRatio] < 1.9,
            "{r:?}"
        );
        if n == 3072 {
            assert!(
                (r[SphereMeasure::CapDiscrepancy] - 1.09e-3).abs() < 0.03e-3,
                "{r:?}"
            );
        }
    }
    let p = uniform_random_sphere(3072, 2024);
    let r = sphere_report(&p);
    eprintln!("random N = 3072: {}", serde_json::to_string(&r).unwrap());
    assert!(
        r[SphereMeasure::CapDiscrepancy] > 5e-3 && r[SphereMeasure::CapDiscrepancy] < 2.5e-2,
        "{r:?}"
    );
    assert!(r[SphereMeasure::Energy].abs() < 0.5, "{r:?}");
    assert!(r[SphereMeasure::Separation] < 0.5, "{r:?}");
    // Fibonacci power is far below white noise at low l.
    let pw = angular_power(&spherical_fibonacci(3072), 30);
    assert!(pw[1..=30].iter().all(|&v| v < 0.05), "{pw:?}");
}

#[test]
fn sphere_report_is_consistent() {
    let p = uniform_random_sphere(300, 5);
    let r = sphere_report(&p);
    assert_eq!(r.n(), 300);
    assert_eq!(r[SphereMeasure::Separation], separation(&p));
    assert_eq!(r[SphereMeasure::CapDiscrepancy], cap_discrepancy_l2(&p));
    assert_eq!(r[SphereMeasure::Energy], riesz1_normalized(&p));
    assert_eq!(r[SphereMeasure::Covering], covering_radius(&p));
    assert_relative_eq!(
        r[SphereMeasure::MeshRatio],
        mesh_ratio(&p),
        max_relative = 1e-14
    );
    let json = serde_json::to_string(&r).unwrap();
    let keys: Vec<&str> = json.split('"').skip(1).step_by(2).collect();
    assert_eq!(
        keys,
        [
            "n",
            "separation_sqrt_n",
            "cap_discrepancy_l2",
            "riesz1_excess_over_n1_5",
            "covering_radius_sqrt_n",
            "mesh_ratio",
        ]
    );
}

/// `only` computes just the measures named, whatever `pairs_up_to`;
/// without it the O(N²) ones above `pairs_up_to` are skipped (null).
#[test]
fn reports_compute_what_is_asked() {
    let p = uniform_random_sphere(300, 5);
    let all = sphere_report(&p);
    let only = Options {
        only: Some(vec![SphereMeasure::MeshRatio, SphereMeasure::Energy]),
        pairs_up_to: 10,
        ..Options::default()
    };
    let r = tessera::metrics::sphere::measure(&p, &only);
    let measured: Vec<_> = r.entries().iter().map(|(m, _)| *m).collect();
    assert_eq!(measured, [SphereMeasure::Energy, SphereMeasure::MeshRatio]);
    assert_eq!(r[SphereMeasure::Energy], all[SphereMeasure::Energy]);
    assert_eq!(r[SphereMeasure::MeshRatio], all[SphereMeasure::MeshRatio]);
    let cheap = Options {
        pairs_up_to: 10,
        ..Options::default()
    };
    let r = tessera::metrics::plane::measure(&jittered_grid_2d(10, 1), &cheap);
    assert_eq!(r.entries().len(), PlaneMeasure::ALL.len());
    assert_eq!(
        r.skipped().collect::<Vec<_>>(),
        [
            PlaneMeasure::L2Star,
            PlaneMeasure::CenteredL2,
            PlaneMeasure::LowFrequencyPower
        ]
    );
    assert!(serde_json::to_string(&r)
        .unwrap()
        .ends_with("\"l2_star_discrepancy\":null,\"centered_l2_discrepancy\":null,\"low_frequency_power\":null}"));
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(24))]

    #[test]
    fn covering_is_rotation_invariant_and_above_samples(
        n in 3usize..120, seed in 0u64..1000, angle in 0.0f64..6.0
    ) {
        let p = uniform_random_sphere(n, seed);
        let c = covering_radius(&p) / (n as f64).sqrt();
        let rot = glam::DQuat::from_axis_angle(DVec3::new(1.0, 2.0, 3.0).normalize(), angle);
        let q: Vec<DVec3> = p.iter().map(|&x| rot.mul_vec3(x)).collect();
        let c2 = covering_radius(&q) / (n as f64).sqrt();
        prop_assert!((c - c2).abs() < 1e-9);
        // Never below the distance of a few random probe points.
        for y in uniform_random_sphere(50, seed + 1) {
            prop_assert!(dist_to_set(y, &p) <= c + 1e-12);
        }
        // The half-distance to the nearest neighbour is always covered.
        prop_assert!(c >= brute_min_geodesic(&p) / 2.0 - 1e-12);
    }
}

// ---------------------------------------------------------------------------
// Plane
// ---------------------------------------------------------------------------

fn brute_nn(p: &[DVec2]) -> Vec<f64> {
    (0..p.len())
        .map(|i| {
            (0..p.len())
                .filter(|&j| j != i)
                .map(|j| p[i].distance(p[j]))
                .fold(f64::INFINITY, f64::min)
        })
        .collect()
}

/// ∫_{t0}^{t1} |t − c| dt and ∫ |t − c|² dt, for c outside (t0, t1).
fn lin_moments(t0: f64, t1: f64, c: f64) -> (f64, f64) {
    let (a, b) = ((t0 - c).abs(), (t1 - c).abs());
    (
        (b * b - a * a).abs() / 2.0,
        (b.powi(3) - a.powi(3)).abs() / 3.0,
    )
}

/// Exact ∫ over `[lo, hi]` (one or two dimensions) of
/// `(count(box(y)) / N − vol(box(y)))²`, where `box(y)` is the box between
/// `y` and the anchor corner `c` and count uses the coordinates `axes`.
fn exact_local_l2(p: &[DVec2], axes: &[usize], lo: [f64; 2], hi: [f64; 2], c: [f64; 2]) -> f64 {
    let n = p.len() as f64;
    let coord = |q: &DVec2, k: usize| if k == 0 { q.x } else { q.y };
    let breaks: Vec<Vec<f64>> = axes
        .iter()
        .enumerate()
        .map(|(d, &k)| {
            let mut b = vec![lo[d], hi[d]];
            b.extend(
                p.iter()
                    .map(|q| coord(q, k))
                    .filter(|&t| t > lo[d] && t < hi[d]),
            );
            b.sort_by(f64::total_cmp);
            b
        })
        .collect();
    let inside = |q: &DVec2, y: &[f64]| {
        axes.iter().enumerate().all(|(d, &k)| {
            let t = coord(q, k);
            (t - c[d]) * (y[d] - c[d]) > 0.0 && (t - c[d]).abs() < (y[d] - c[d]).abs()
        })
    };
    let mut total = 0.0;
    if axes.len() == 1 {
        for w in breaks[0].windows(2) {
            let mid = [(w[0] + w[1]) / 2.0];
            let k = p.iter().filter(|q| inside(q, &mid)).count() as f64 / n;
            let (m1, m2) = lin_moments(w[0], w[1], c[0]);
            total += k * k * (w[1] - w[0]) - 2.0 * k * m1 + m2;
        }
    } else {
        for wx in breaks[0].windows(2) {
            for wy in breaks[1].windows(2) {
                let mid = [(wx[0] + wx[1]) / 2.0, (wy[0] + wy[1]) / 2.0];
                let k = p.iter().filter(|q| inside(q, &mid)).count() as f64 / n;
                let (ax1, ax2) = lin_moments(wx[0], wx[1], c[0]);
                let (ay1, ay2) = lin_moments(wy[0], wy[1], c[1]);
                total +=
                    k * k * (wx[1] - wx[0]) * (wy[1] - wy[0]) - 2.0 * k * ax1 * ay1 + ax2 * ay2;
            }
        }
    }
    total
}

fn brute_l2_star_sq(p: &[DVec2]) -> f64 {
    exact_local_l2(p, &[0, 1], [0.0, 0.0], [1.0, 1.0], [0.0, 0.0])
}

fn brute_centered_sq(p: &[DVec2]) -> f64 {
    let mut total = 0.0;
    for (lx, hx, cx) in [(0.0, 0.5, 0.0), (0.5, 1.0, 1.0)] {
        for (ly, hy, cy) in [(0.0, 0.5, 0.0), (0.5, 1.0, 1.0)] {
            total += exact_local_l2(p, &[0, 1], [lx, ly], [hx, hy], [cx, cy]);
        }
        for axis in [0, 1] {
            total += exact_local_l2(p, &[axis], [lx, 0.0], [hx, 0.0], [cx, 0.0]);
        }
    }
    total
}

#[test]
fn nearest_neighbour_distances_match_brute_force() {
    for (n, seed) in [(2, 1), (3, 2), (50, 3), (2000, 4)] {
        let p = uniform_random_2d(n, seed);
        let d = brute_nn(&p);
        let h = hex_spacing(n);
        let min = d.iter().copied().fold(f64::INFINITY, f64::min);
        let mean = d.iter().sum::<f64>() / n as f64;
        assert_relative_eq!(min_distance(&p), min / h, max_relative = 1e-12);
        assert_relative_eq!(mean_nn_distance(&p), mean / h, max_relative = 1e-12);
    }
    // Sets whose bounding box is flat or a point (the k-d tree pass visits
    // points in Morton order over that box): a vertical line, duplicates.
    let line: Vec<DVec2> = (0..300)
        .map(|i| DVec2::new(0.5, ((i * 37) % 300) as f64 / 300.0))
        .collect();
    let same = vec![DVec2::splat(0.25); 5];
    for p in [line, same] {
        let d = brute_nn(&p);
        let h = hex_spacing(p.len());
        let min = d.iter().copied().fold(f64::INFINITY, f64::min);
        let mean = d.iter().sum::<f64>() / p.len() as f64;
        assert_eq!(min_distance(&p), min / h);
        assert_relative_eq!(mean_nn_distance(&p), mean / h, max_relative = 1e-12);
    }
    // A hexagonal lattice patch has min distance = its spacing.
    let s = 0.05;
    let mut hex = Vec::new();
    for j in 0..18 {
        for i in 0..18 {
            let x = 0.01 + s * (i as f64 + 0.5 * (j % 2) as f64);
            let y = 0.01 + s * 3f64.sqrt() / 2.0 * j as f64;
            hex.push(DVec2::new(x, y));
        }
    }
    let h = hex_spacing(hex.len());
    assert_relative_eq!(min_distance(&hex), s / h, max_relative = 1e-9);
    assert_relative_eq!(mean_nn_distance(&hex), s / h, max_relative = 1e-9);
}

#[test]
fn discrepancies_closed_forms() {
    // Single point (a, b): T² = 1/9 − (1−a²)(1−b²)/2 + (1−a)(1−b).
    for (a, b) in [(0.5, 0.5), (0.1, 0.7), (0.0, 0.0), (0.9, 0.2)] {
        let p = [DVec2::new(a, b)];
        let t2 = 1.0 / 9.0 - (1.0 - a * a) * (1.0 - b * b) / 2.0 + (1.0 - a) * (1.0 - b);
        assert_relative_eq!(l2_star_discrepancy(&p), t2.sqrt(), max_relative = 1e-12);
    }
    // Centre point: CD² = (13/12)² − 2 + 1 = 25/144.
    assert_relative_eq!(
        centered_l2_discrepancy(&[DVec2::splat(0.5)]),
        5.0 / 12.0,
        max_relative = 1e-14
    );
    // 2×2 grid {1/4, 3/4}²: T² = 1/9 − 121/512 + 9/64 = 71/4608 and
    // CD² = 169/144 − 1225/512 + 81/64 = 215/4608.
    let grid: Vec<DVec2> = [0.25, 0.75]
        .iter()
        .flat_map(|&x| [0.25, 0.75].map(|y| DVec2::new(x, y)))
        .collect();
    assert_relative_eq!(
        l2_star_discrepancy(&grid),
        (71.0f64 / 4608.0).sqrt(),
        max_relative = 1e-13
    );
    assert_relative_eq!(
        centered_l2_discrepancy(&grid),
        (215.0f64 / 4608.0).sqrt(),
        max_relative = 1e-13
    );
    // The brute-force integrator agrees with the hand-derived values.
    assert_relative_eq!(brute_l2_star_sq(&grid), 71.0 / 4608.0, max_relative = 1e-12);
    assert_relative_eq!(
        brute_centered_sq(&grid),
        215.0 / 4608.0,
        max_relative = 1e-12
    );
    assert_relative_eq!(
        brute_centered_sq(&[DVec2::splat(0.5)]),
        25.0 / 144.0,
        max_relative = 1e-12
    );
}

#[test]
fn discrepancies_match_exact_integration() {
    for (n, seed) in [(1, 1), (2, 2), (5, 3), (12, 4), (20, 5)] {
        let p = uniform_random_2d(n, seed);
        assert_relative_eq!(
            l2_star_discrepancy(&p),
            brute_l2_star_sq(&p).sqrt(),
            max_relative = 1e-9
        );
        assert_relative_eq!(
            centered_l2_discrepancy(&p),
            brute_centered_sq(&p).sqrt(),
            max_relative = 1e-9
        );
    }
    // Centred discrepancy is invariant under x ↦ 1 − x.
    let p = uniform_random_2d(300, 9);
    let q: Vec<DVec2> = p.iter().map(|v| DVec2::new(1.0 - v.x, v.y)).collect();
    assert_relative_eq!(
        centered_l2_discrepancy(&p),
        centered_l2_discrepancy(&q),
        max_relative = 1e-12
    );
    // Jittered grid beats white noise.
    let j = jittered_grid_2d(32, 1);
    let w = uniform_random_2d(1024, 1);
    assert!(l2_star_discrepancy(&j) < 0.5 * l2_star_discrepancy(&w));
    assert!(centered_l2_discrepancy(&j) < 0.5 * centered_l2_discrepancy(&w));
}

#[test]
fn periodogram_reference_cases() {
    // Single point: 1 everywhere (even and odd sizes).
    for size in [1, 7, 16] {
        let p = periodogram(&[DVec2::new(0.123, 0.987)], size);
        assert_eq!(p.len(), size * size);
        assert!(p.iter().all(|v| (v - 1.0).abs() < 1e-12));
    }
    // Perfect m × m lattice: N at k ≡ 0 (mod m), 0 elsewhere.
    let m = 8;
    let lattice: Vec<DVec2> = (0..m * m)
        .map(|i| DVec2::new((i % m) as f64 + 0.5, (i / m) as f64 + 0.5) / m as f64)
        .collect();
    let size = 32;
    let p = periodogram(&lattice, size);
    for (idx, v) in p.iter().enumerate() {
        let kx = (idx % size) as i64 - 16;
        let ky = (idx / size) as i64 - 16;
        let want = if kx % m as i64 == 0 && ky % m as i64 == 0 {
            (m * m) as f64
        } else {
            0.0
        };
        assert!((v - want).abs() < 1e-9, "k = ({kx}, {ky}): {v}");
    }
    assert!(low_frequency_power(&lattice) < 1e-20);
    // Direct evaluation on a random set (more points than one chunk).
    let pts = uniform_random_2d(300, 4);
    let size = 9;
    let p = periodogram(&pts, size);
    for (idx, &v) in p.iter().enumerate() {
        let kx = (idx % size) as f64 - 4.0;
        let ky = (idx / size) as f64 - 4.0;
        let (mut re, mut im) = (0.0, 0.0);
        for q in &pts {
            let a = -TAU * (kx * q.x + ky * q.y);
            re += a.cos();
            im += a.sin();
        }
        assert_relative_eq!(
            v,
            (re * re + im * im) / 300.0,
            max_relative = 1e-9,
            epsilon = 1e-9
        );
    }
    assert_relative_eq!(p[4 * size + 4], 300.0, max_relative = 1e-12);
}

#[test]
fn radial_average_and_anisotropy() {
    let size = 16;
    // Value = |k|² exactly on the grid: the ring mean is known by counting.
    let field: Vec<f64> = (0..size * size)
        .map(|i| {
            let kx = (i % size) as f64 - 8.0;
            let ky = (i / size) as f64 - 8.0;
            kx * kx + ky * ky
        })
        .collect();
    let r = radial_average(&field, size);
    assert_eq!(r.len(), 8);
    assert_eq!(r[0], 0.0);
    // Ring 1: |k|² ∈ {1 (×4), 2 (×4)}: round(√2) = 1.
    assert_relative_eq!(r[1], 1.5);
    let a = anisotropy(&field, size);
    assert!(a[0].is_nan());
    assert!(a[1].is_finite());
    // A constant ring has zero variance: −∞ dB.
    let flat = vec![3.0; size * size];
    assert!(anisotropy(&flat, size)[3] == f64::NEG_INFINITY);
    // White noise: about 0 dB; a vertically striped set is very anisotropic.
    let w = periodogram(&uniform_random_2d(1024, 5), 48);
    let aw = anisotropy(&w, 48);
    let mean = aw[6..].iter().sum::<f64>() / aw[6..].len() as f64;
    assert!(mean.abs() < 1.0, "{mean}");
    let ra = radial_average(&w, 48);
    let mean_power = ra[6..].iter().sum::<f64>() / ra[6..].len() as f64;
    assert!((mean_power - 1.0).abs() < 0.1, "{mean_power}");
    // Four rows y ∈ {0, 1/4, 1/2, 3/4}: P = N at (0, ±8), spikes in ring 8.
    let mut rng = SplitMix64::new(6);
    let rows: Vec<DVec2> = (0..1024)
        .map(|i| DVec2::new(rng.next_f64(), (i % 4) as f64 / 4.0))
        .collect();
    let as_ = anisotropy(&periodogram(&rows, 48), 48);
    assert!(as_[8] > 5.0, "{}", as_[8]);
    assert!(as_[7].abs() < 3.0, "{}", as_[7]);
}

#[test]
fn low_frequency_power_white_and_blue() {
    let w = low_frequency_power(&uniform_random_2d(4096, 3));
    assert!((w - 1.0).abs() < 0.1, "{w}");
    let j = low_frequency_power(&jittered_grid_2d(64, 3));
    assert!(j < 0.5, "{j}");
    assert!(low_frequency_power(&uniform_random_2d(4, 1)).is_nan());
    assert!(low_frequency_power(&[]).is_nan());
}

#[test]
fn plane_empty_single_and_report() {
    let e: [DVec2; 0] = [];
    assert!(min_distance(&e).is_nan());
    assert!(mean_nn_distance(&e).is_nan());
    assert!(l2_star_discrepancy(&e).is_nan());
    assert!(centered_l2_discrepancy(&e).is_nan());
    assert!(periodogram(&e, 4).iter().all(|v| v.is_nan()));
    let r = plane_report(&e);
    assert_eq!(r.n(), 0);
    assert!(r[PlaneMeasure::MinDistance].is_nan());

    let one = [DVec2::new(0.3, 0.4)];
    assert_eq!(min_distance(&one), f64::INFINITY);
    assert_eq!(mean_nn_distance(&one), f64::INFINITY);
    let r = plane_report(&one);
    assert_eq!(r[PlaneMeasure::MinDistance], f64::INFINITY);
    assert!(r[PlaneMeasure::LowFrequencyPower].is_nan());

    let p = jittered_grid_2d(20, 8);
    let r = plane_report(&p);
    assert_eq!(r.n(), 400);
    assert_eq!(r[PlaneMeasure::MinDistance], min_distance(&p));
    assert_relative_eq!(
        r[PlaneMeasure::MeanNnDistance],
        mean_nn_distance(&p),
        max_relative = 1e-14
    );
    assert_eq!(r[PlaneMeasure::L2Star], l2_star_discrepancy(&p));
    assert_eq!(r[PlaneMeasure::CenteredL2], centered_l2_discrepancy(&p));
    assert_eq!(r[PlaneMeasure::LowFrequencyPower], low_frequency_power(&p));
    let json = serde_json::to_string(&r).unwrap();
    assert!(json.contains("\"centered_l2_discrepancy\""));
}

// ---------------------------------------------------------------------------
// Baselines
// ---------------------------------------------------------------------------

#[test]
fn splitmix_reference_vectors() {
    let mut r = SplitMix64::new(0);
    assert_eq!(r.next_u64(), 0xe220a8397b1dcdaf);
    assert_eq!(r.next_u64(), 0x6e789e6aa1b965f4);
    let mut r = SplitMix64::new(1234567);
    let v: Vec<u64> = (0..3).map(|_| r.next_u64()).collect();
    assert_eq!(
        v,
        [
            6457827717110365317,
            3203168211198807973,
            9817491932198370423
        ]
    );
    let mut r = SplitMix64::new(5);
    for _ in 0..10_000 {
        let u = r.next_f64();
        assert!((0.0..1.0).contains(&u));
    }
}

#[test]
fn fibonacci_lattice_definition() {
    let n = 1000;
    let p = spherical_fibonacci(n);
    let phi = golden();
    for (i, x) in p.iter().enumerate() {
        let z = 1.0 - (2 * i + 1) as f64 / n as f64;
        assert!((x.z - z).abs() < 1e-15);
        assert!((x.length() - 1.0).abs() < 1e-15);
        let az = (TAU * i as f64 / phi).rem_euclid(TAU);
        let got = x.y.atan2(x.x).rem_euclid(TAU);
        let diff = (got - az).abs();
        assert!(diff.min(TAU - diff) < 1e-9, "i = {i}");
    }
    let mut streamed = Vec::new();
    spherical_fibonacci_into(n, |x| streamed.push(x));
    assert_eq!(streamed, p);
    // Poles: accurate sin θ for huge n.
    let big = 5_000_000usize;
    let mut first = None;
    spherical_fibonacci_into(big, |x| {
        if first.is_none() {
            first = Some(x);
        }
    });
    let x = first.unwrap();
    let s = (x.x * x.x + x.y * x.y).sqrt();
    assert_relative_eq!(
        s,
        ((2 * big - 1) as f64).sqrt() / big as f64,
        max_relative = 1e-14
    );
    assert!(spherical_fibonacci(0).is_empty());
    assert_eq!(spherical_fibonacci(1), vec![DVec3::new(1.0, 0.0, 0.0)]);
}

#[test]
fn random_baselines() {
    let p = uniform_random_sphere(20_000, 1);
    assert!(p.iter().all(|x| (x.length() - 1.0).abs() < 1e-14));
    let mean: DVec3 = p.iter().copied().sum::<DVec3>() / p.len() as f64;
    assert!(mean.length() < 0.03);
    assert_ne!(uniform_random_sphere(10, 1), uniform_random_sphere(10, 2));
    let j = jittered_grid_2d(16, 4);
    for (k, q) in j.iter().enumerate() {
        let (i, jj) = (k % 16, k / 16);
        assert!((q.x * 16.0).floor() as usize == i && (q.y * 16.0).floor() as usize == jj);
    }
    assert!(jittered_grid_2d(0, 1).is_empty());
    let u = uniform_random_2d(1000, 2);
    assert!(u
        .iter()
        .all(|q| (0.0..1.0).contains(&q.x) && (0.0..1.0).contains(&q.y)));
}

/// The plane spectrum's rings reach twice the blue-noise peak: a 50 x 50
/// jittered grid peaks at its lattice frequency |k| = 50, inside the first
/// half of the rings.
#[test]
fn plane_spectrum_reaches_twice_the_peak() {
    let s = tessera::metrics::plane::PlaneSpectrum::new(&jittered_grid_2d(50, 3));
    assert!(
        s.radial_power.len() as f64 >= 2.0 * 1.07 * 50.0,
        "{}",
        s.size
    );
    let peak = (1..s.radial_power.len())
        .max_by(|&a, &b| s.radial_power[a].total_cmp(&s.radial_power[b]))
        .unwrap();
    assert!((48..=52).contains(&peak), "peak at {peak}");
}

/// `Σ_{i,j} P_l(x_i · x_j) / N` for l = 0..=l_max by the three-term
/// Legendre recurrence over every ordered pair: the definition of the
/// angular power, O(N² l_max).
fn angular_power_by_pairs(p: &[DVec3], l_max: usize) -> Vec<f64> {
    let mut sums = vec![0.0; l_max + 1];
    for a in p {
        for b in p {
            let t = a.dot(*b).clamp(-1.0, 1.0);
            let (mut pm1, mut pl) = (1.0, t);
            sums[0] += 1.0;
            if l_max >= 1 {
                sums[1] += t;
            }
            for (l, sum) in sums.iter_mut().enumerate().skip(2) {
                let lf = (l - 1) as f64;
                let next = ((2.0 * lf + 1.0) * t * pl - lf * pm1) / (lf + 1.0);
                (pm1, pl) = (pl, next);
                *sum += next;
            }
        }
    }
    sums.iter().map(|s| s / p.len() as f64).collect()
}

/// The addition-theorem spectrum equals the sum over pairs up to the
/// highest degree the command line asks for, with points near the poles
/// (where the sectoral functions underflow f64 at high m), on them, and
/// more than one block of points.
#[test]
fn angular_power_matches_the_pair_sum_to_high_degree() {
    let mut p = uniform_random_sphere(90, 7);
    for (k, theta) in [1e-9f64, 1e-4, 0.01, 0.05, 0.2, 0.5]
        .into_iter()
        .enumerate()
    {
        let phi = k as f64;
        let (st, ct) = theta.sin_cos();
        p.push(DVec3::new(st * phi.cos(), st * phi.sin(), ct));
        p.push(DVec3::new(st * phi.sin(), -st * phi.cos(), -ct));
    }
    p.extend([DVec3::Z, -DVec3::Z]);
    let l_max = tessera::metrics::sphere::SPECTRUM_L_CAP;
    let fast = angular_power(&p, l_max);
    let slow = angular_power_by_pairs(&p, l_max);
    let worst = fast
        .iter()
        .zip(&slow)
        .map(|(a, b)| (a - b).abs())
        .fold(0.0, f64::max);
    eprintln!("largest difference {worst:e} up to l = {l_max}");
    assert!(worst < 1e-10, "largest difference {worst}");
    // independent uniform points: power near 1 at every degree (its
    // standard deviation is about 1 per degree), 1 on average
    let fast = angular_power(&uniform_random_sphere(2000, 8), 300);
    let mean = fast[1..].iter().sum::<f64>() / 300.0;
    assert!((mean - 1.0).abs() < 0.2, "{mean}");
}

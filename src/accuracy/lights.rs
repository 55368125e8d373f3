//! The `sphere-lights` rows: the env map turned into `N` lights with exact
//! powers ([`crate::lights::lights`]) against classic and greedy median
//! cut ([`crate::baselines::median_cut`]). A light set estimates
//! `integral of L(w) f(w) dw` by `sum_k P_k f(w_k)`; the lobes `f` are the
//! clamped cosine around 64 fixed random normals and Phong lobes of
//! exponent 10 and 100 around 64 fixed random axes, and an entry is the
//! relative RMSE over them (the sets are deterministic: there are no
//! seeds to average over).

use super::{Config, Row};
use crate::baselines::median_cut::{median_cut, MedianCut};
use crate::baselines::uniform_random_sphere;
use crate::density::envmap::EnvMap;
use crate::lights::{lights, Light, LightOptions};
use crate::metrics::irradiance::{exact_lobe, relative_rmse};
use glam::DVec3;
use std::time::Instant;

/// The scenario's name in the rows.
const SCENARIO: &str = "sphere-lights";
/// Largest light count measured (issue 19's range is 64 to 16384).
const MAX_N: usize = 1 << 14;
/// Normals (axes) per lobe.
const PROBES: usize = 64;
/// Builds timed per method and count (the median is reported).
const TIMINGS: usize = 3;

fn diffuse(c: f64) -> f64 {
    c.max(0.0)
}

fn phong_10(c: f64) -> f64 {
    c.max(0.0).powi(10)
}

fn phong_100(c: f64) -> f64 {
    c.max(0.0).powi(100)
}

/// One lobe around its probes, with the reference integrals.
struct Lobe {
    name: &'static str,
    f: fn(f64) -> f64,
    probes: Vec<DVec3>,
    exact: Vec<f64>,
}

impl Lobe {
    fn new(map: &EnvMap, name: &'static str, f: fn(f64) -> f64, seed: u64) -> Self {
        let probes = uniform_random_sphere(PROBES, seed);
        let exact = exact_lobe(map, &probes, f);
        Lobe {
            name,
            f,
            probes,
            exact,
        }
    }

    /// Relative RMSE of the lights' estimates over the probes.
    fn error(&self, lights: &[Light]) -> f64 {
        let estimates: Vec<f64> = self
            .probes
            .iter()
            .map(|&a| {
                lights
                    .iter()
                    .map(|l| l.luminance * (self.f)(a.dot(l.direction)))
                    .sum()
            })
            .collect();
        relative_rmse(&estimates, &self.exact)
    }
}

/// The rows of every method, lobe and `N = 2^k <= 16384` of `config`,
/// each set built on `pool` (one thread).
pub(super) fn rows(map: &EnvMap, config: &Config, pool: &rayon::ThreadPool) -> Vec<Row> {
    let lobes = [
        Lobe::new(map, "diffuse", diffuse, 1),
        Lobe::new(map, "phong-10", phong_10, 2),
        Lobe::new(map, "phong-100", phong_100, 2),
    ];
    type Build<'m> = Box<dyn Fn(usize) -> Vec<Light> + Sync + 'm>;
    let methods: [(&str, bool, Build); 3] = [
        (
            "tessera lights",
            true,
            Box::new(|n| lights(map, n, &LightOptions::default()).expect("lights of the sky")),
        ),
        (
            "median cut (classic)",
            false,
            Box::new(|n| median_cut(map, None, n, MedianCut::Classic).expect("median cut")),
        ),
        (
            "median cut (greedy)",
            false,
            Box::new(|n| median_cut(map, None, n, MedianCut::Greedy).expect("median cut")),
        ),
    ];
    let mut rows = Vec::new();
    for (method, tessera, build) in &methods {
        for &k in &config.exponents {
            let n = 1usize << k;
            if n > MAX_N {
                continue;
            }
            let mut times = Vec::new();
            let mut set = Vec::new();
            for _ in 0..TIMINGS {
                let started = Instant::now();
                set = pool.install(|| build(n));
                times.push(started.elapsed().as_secs_f64());
            }
            times.sort_by(f64::total_cmp);
            for lobe in &lobes {
                rows.push(Row {
                    scenario: SCENARIO.into(),
                    method: method.to_string(),
                    tessera: *tessera,
                    integrand: lobe.name.into(),
                    smooth: false,
                    n,
                    count: set.len() as f64,
                    rel_rmse: lobe.error(&set),
                    seconds: times[TIMINGS / 2],
                });
            }
        }
    }
    rows
}

#[cfg(test)]
mod tests {
    use super::*;

    /// On the accuracy sky (a 5 x 5-pixel sun holding a third of the
    /// energy), tessera's lights beat both median cuts on the diffuse lobe
    /// at N = 1024, and every set has exactly N lights.
    #[test]
    fn tessera_lights_beat_median_cut_on_the_sky() {
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(1)
            .build()
            .unwrap();
        let config = Config {
            exponents: vec![10],
            seeds: 1,
        };
        let rows = rows(&super::super::sky(), &config, &pool);
        assert_eq!(rows.len(), 9);
        assert!(rows
            .iter()
            .all(|r| r.count == 1024.0 && r.rel_rmse.is_finite()));
        let diffuse = |m: &str| {
            rows.iter()
                .find(|r| r.method == m && r.integrand == "diffuse")
                .unwrap()
                .rel_rmse
        };
        let ours = diffuse("tessera lights");
        let best = diffuse("median cut (classic)").min(diffuse("median cut (greedy)"));
        assert!(
            ours < best,
            "tessera {ours:.3e} against median cut {best:.3e}"
        );
    }
}

//! The compared samplers in each scenario. Tile systems enter through
//! [`uniform_tile_methods`] (one line each; a new system such as Penrose
//! tiles sit beside the polyomino systems in [`plane_uniform`]).
//!
//! Knobs of the tile samplers, each a method of its own:
//! - default: offset tables on, f64 output, exact N, randomised;
//! - `f32`: positions rounded to f32 (output precision);
//! - `no-offsets`: samples at the tiles' centroids ([`WithoutOffsets`]);
//! - `fixed`: not randomised (one deterministic set; its "RMSE" is the
//!   absolute error of that set);
//! - `expected-N` (env map only): the exactness pass off. A uniform request
//!   returns exactly N either way (it streams the first N codes), so the
//!   knob only matters under a varying density.

use super::{integrands, Generator, Method, Scenario};
use crate::baselines::envmap::{AliasTable, InverseCdf, Stratified};
use crate::baselines::{
    bridson, jittered_grid_2d, jittered_healpix_about, random_rotation, sobol, spherical_fibonacci,
    uniform_random_2d, uniform_random_sphere, SplitMix64,
};
use crate::density::envmap::EnvMap;
use crate::density::{Region, Uniform};
use crate::engine;
use crate::tiling::penrose::PenroseTiling;
use crate::tiling::plane::PlaneTiling;
use crate::tiling::reference::{ReferencePoint, WithoutOffsets};
use crate::tiling::sphere::{SphereRegion, SphereTiling};
use crate::tiling::TileSystem;
use glam::{DVec2, DVec3};
use std::f64::consts::PI;

/// Largest `N` Bridson's sampler is measured at.
const BRIDSON_MAX_N: usize = 1 << 16;

fn method<'a, P>(
    name: impl Into<String>,
    tessera: bool,
    generate: impl Fn(usize, u64) -> Vec<P> + Sync + 'a,
) -> Method<'a, P> {
    let generate: Generator<'a, P> = Box::new(generate);
    Method {
        name: name.into(),
        tessera,
        max_n: usize::MAX,
        generate,
    }
}

/// The points rotated by a uniformly random rotation drawn from `seed`.
fn rotate(points: Vec<DVec3>, seed: u64) -> Vec<DVec3> {
    let r = random_rotation(seed);
    points.into_iter().map(|p| r * p).collect()
}

/// The points shifted on the torus `[0, 1)²` by a random vector from `seed`.
fn shift(points: Vec<DVec2>, seed: u64) -> Vec<DVec2> {
    let mut rng = SplitMix64::new(seed);
    let s = DVec2::new(rng.next_f64(), rng.next_f64());
    let below_one = 1.0 - f64::EPSILON / 2.0;
    let wrap = |v: f64| if v >= 1.0 { v - 1.0 } else { v }.min(below_one);
    points
        .into_iter()
        .map(|p| DVec2::new(wrap(p.x + s.x), wrap(p.y + s.y)))
        .collect()
}

/// `n` uniform samples of a tile system, positions only.
fn draw<S: TileSystem>(system: &S, n: usize) -> Vec<S::Point>
where
    S::Region: Region<Point = S::Point>,
{
    engine::generate(system, &Uniform, n, true)
        .expect("the accuracy bench's counts fit every system")
        .into_iter()
        .map(|s| s.position)
        .collect()
}

/// A tile system's knobs under a uniform density (see the module doc).
fn uniform_tile_methods<'a, S, P>(
    label: &str,
    system: S,
    randomise: fn(Vec<P>, u64) -> Vec<P>,
    to_f32: fn(P) -> P,
) -> Vec<Method<'a, P>>
where
    S: ReferencePoint<Point = P> + Clone + 'a,
    S::Region: Region<Point = P>,
    P: Copy + Send + Sync + 'a,
{
    let plain = WithoutOffsets(system.clone());
    let (a, b) = (system.clone(), system.clone());
    vec![
        method(label, true, move |n, seed| randomise(draw(&a, n), seed)),
        method(format!("{label} f32"), true, move |n, seed| {
            let points = randomise(draw(&b, n), seed);
            points.into_iter().map(to_f32).collect()
        }),
        method(format!("{label} no-offsets"), true, move |n, seed| {
            randomise(draw(&plain, n), seed)
        }),
        method(format!("{label} fixed"), true, move |n, _| draw(&system, n)),
    ]
}

/// Uniform density on the sphere.
pub(super) fn sphere_uniform<'a>() -> Scenario<'a, DVec3> {
    let mut methods = uniform_tile_methods("tessera", SphereTiling::default(), rotate, |p| {
        p.as_vec3().as_dvec3()
    });
    methods.extend([
        method("i.i.d.", false, uniform_random_sphere),
        method("sobol", false, sobol::sphere),
        method("fibonacci", false, |n, seed| {
            rotate(spherical_fibonacci(n), seed)
        }),
        method("jittered-healpix", false, jittered_healpix_about),
    ]);
    Scenario {
        name: "sphere-uniform",
        weight: Box::new(|_| 4.0 * PI),
        integrands: integrands::sphere(),
        methods,
    }
}

/// Samples of `map` (rotated by `seed` when given) in world directions.
fn envmap_draw<S>(system: &S, map: &EnvMap, n: usize, exact: bool, seed: Option<u64>) -> Vec<DVec3>
where
    S: TileSystem<Point = DVec3, Region = SphereRegion>,
{
    let seeded = seed.map(|s| map.with_seed(s));
    let m = seeded.as_ref().unwrap_or(map);
    engine::generate(system, m, n, exact)
        .expect("the accuracy bench's counts fit the sphere")
        .into_iter()
        .map(|s| m.to_world(s.position))
        .collect()
}

/// Importance sampling of the generated sky, Lambertian lobes.
pub(super) fn sphere_envmap(map: &EnvMap) -> Scenario<'_, DVec3> {
    let sphere = SphereTiling::default;
    let (inverse, alias, warp, stratified) = (
        InverseCdf::new(map),
        AliasTable::new(map),
        InverseCdf::new(map),
        Stratified::new(map),
    );
    let methods = vec![
        method("tessera", true, move |n, s| {
            envmap_draw(&sphere(), map, n, true, Some(s))
        }),
        method("tessera expected-N", true, move |n, s| {
            envmap_draw(&sphere(), map, n, false, Some(s))
        }),
        method("tessera f32", true, move |n, s| {
            let points = envmap_draw(&sphere(), map, n, true, Some(s));
            points.into_iter().map(|p| p.as_vec3().as_dvec3()).collect()
        }),
        method("tessera no-offsets", true, move |n, s| {
            envmap_draw(&WithoutOffsets(sphere()), map, n, true, Some(s))
        }),
        method("tessera fixed", true, move |n, _| {
            envmap_draw(&sphere(), map, n, true, None)
        }),
        method("i.i.d. inverse-CDF", false, move |n, s| {
            inverse.samples(n, s)
        }),
        method("i.i.d. alias", false, move |n, s| alias.samples(n, s)),
        method("stratified inverse-CDF", false, move |n, s| {
            stratified.samples(n, s)
        }),
        method("sobol inverse-CDF", false, move |n, s| {
            let u = sobol::owen_sobol_2d(n, s);
            u.into_iter().map(|u| warp.warp([u.x, u.y])).collect()
        }),
    ];
    Scenario {
        name: "sphere-envmap",
        weight: Box::new(move |p| 1.0 / map.pdf(p)),
        integrands: integrands::envmap(map),
        methods,
    }
}

/// Uniform density in the unit square.
pub(super) fn plane_uniform<'a>() -> Scenario<'a, DVec2> {
    let to_f32 = |p: DVec2| p.as_vec2().as_dvec2();
    let mut methods = uniform_tile_methods("ghexomino", PlaneTiling::ghexomino(), shift, to_f32);
    methods.extend(uniform_tile_methods(
        "ppentomino",
        PlaneTiling::ppentomino(),
        shift,
        to_f32,
    ));
    methods.extend(uniform_tile_methods(
        "penrose",
        PenroseTiling::default(),
        shift,
        to_f32,
    ));
    methods.extend([
        method("i.i.d.", false, uniform_random_2d),
        method("sobol", false, sobol::owen_sobol_2d),
        method("jittered", false, |n, seed| {
            jittered_grid_2d(((n as f64).sqrt().round() as usize).max(1), seed)
        }),
        // toroidally shifted: Bridson's sets are sparser along the edges;
        // about 10 µs a point, so it stops at 2^16 to keep the run short
        Method {
            max_n: BRIDSON_MAX_N,
            ..method("bridson", false, |n, seed| shift(bridson(n, seed), seed))
        },
    ]);
    Scenario {
        name: "plane-uniform",
        weight: Box::new(|_| 1.0),
        integrands: integrands::plane(),
        methods,
    }
}

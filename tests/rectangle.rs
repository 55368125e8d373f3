//! Planar sampling on axis-aligned rectangles: every planar system on a 2:1
//! rectangle keeps exact counts, its domain, density following and blue
//! noise; bad rectangles are refused.

mod common;

use common::plane::{check_counts, in_domain, parse_xy, ramp_expected};
use glam::DVec2;
use tessera::density::plane::Ramp;
use tessera::density::rectangle::Rectangle;
use tessera::density::{Density, Uniform};
use tessera::engine::Sample;
use tessera::metrics::plane::min_distance;
use tessera::tiling::penrose::PenroseTiling;
use tessera::tiling::plane::{PlaneRegion, PlaneTiling};
use tessera::tiling::TileSystem;
use tessera::Sampler;

/// Runs `f` with each planar system and its name.
fn each_system(f: impl Fn(&str, &dyn Fn(&Rectangle, usize, bool) -> Vec<Sample<DVec2>>)) {
    fn run<S, D>(system: S, density: D, rect: &Rectangle, n: usize) -> Vec<Sample<DVec2>>
    where
        S: TileSystem<Point = DVec2, Region = PlaneRegion> + Clone,
        D: Density<PlaneRegion>,
    {
        Sampler::new(system)
            .density(density)
            .count(n)
            .generate_on(rect)
            .unwrap()
    }
    let penrose = PenroseTiling::default();
    let ghexomino = PlaneTiling::ghexomino();
    let ppentomino = PlaneTiling::ppentomino();
    f("penrose", &|r, n, ramp| {
        if ramp {
            run(penrose.clone(), Ramp, r, n)
        } else {
            run(penrose.clone(), Uniform, r, n)
        }
    });
    f("ghexomino", &|r, n, ramp| {
        if ramp {
            run(ghexomino.clone(), Ramp, r, n)
        } else {
            run(ghexomino.clone(), Uniform, r, n)
        }
    });
    f("ppentomino", &|r, n, ramp| {
        if ramp {
            run(ppentomino.clone(), Ramp, r, n)
        } else {
            run(ppentomino.clone(), Uniform, r, n)
        }
    });
}

#[test]
fn a_two_to_one_rectangle_keeps_counts_domain_and_blue_noise() {
    let rect = Rectangle::new(-1.0, 2.0, 1.0, 3.0).unwrap();
    let size = rect.hi - rect.lo;
    let unit = |s: &Sample<DVec2>| (s.position - rect.lo) / size;
    each_system(|name, run| {
        let n = 4096;
        let samples = run(&rect, n, false);
        assert_eq!(samples.len(), n, "{name}");
        assert!(samples.iter().all(|s| rect.contains(s.position)), "{name}");
        // normalised by the hexagonal spacing of n points on area 2
        let points: Vec<DVec2> = samples.iter().map(|s| s.position).collect();
        let d = min_distance(&points) / 2f64.sqrt();
        println!("{name}: 2:1 rectangle, N = {n}: normalised min distance {d:.3}");
        assert!(d >= 0.45, "{name}: min distance {d}");
        check_counts(
            &samples.iter().map(unit).collect::<Vec<_>>(),
            |_, _| n as f64 / 256.0,
            name,
        );
        let n = 20_000;
        let ramp: Vec<DVec2> = run(&rect, n, true).iter().map(unit).collect();
        assert_eq!(ramp.len(), n);
        assert!(ramp.iter().all(in_domain), "{name}");
        check_counts(&ramp, |col, _| ramp_expected(n, col), name);
    });
}

#[test]
fn tall_and_tiny_rectangles_and_odd_counts() {
    each_system(|name, run| {
        for rect in [
            Rectangle::new(0.0, 0.0, 0.25, 1.0).unwrap(),
            Rectangle::new(1e6, -1e-3, 1e6 + 3e-3, 0.0).unwrap(),
        ] {
            for n in [0, 1, 7, 999] {
                let s = run(&rect, n, true);
                assert_eq!(s.len(), n, "{name}");
                assert!(
                    s.iter().all(|s| rect.contains(s.position)),
                    "{name} {rect:?}"
                );
            }
        }
    });
}

#[test]
fn bad_rectangles_are_refused_with_the_reason() {
    for (spec, why) in [
        ("0,0,1", "four numbers"),
        ("0,0,1,x", "four numbers"),
        ("0,0,0,1", "x1 > x0"),
        ("0,1,1,0", "y1 > y0"),
        ("0,0,inf,1", "finite"),
        ("NaN,0,1,1", "finite"),
        ("-1e308,0,1e308,1", "finite"),
        ("0,0,1,1e-13", "1e12"),
    ] {
        let e = Rectangle::parse(spec).unwrap_err().to_string();
        assert!(e.contains(why) && e.contains("domain"), "{spec}: {e}");
    }
}

#[test]
fn cli_samples_a_rectangle_and_refuses_bad_ones() {
    let tessera = |args: &[&str]| {
        std::process::Command::new(env!("CARGO_BIN_EXE_tessera"))
            .args(args)
            .output()
            .expect("the binary runs")
    };
    for system in ["penrose", "ghexomino", "ppentomino"] {
        let run = tessera(&[
            "plane",
            "--system",
            system,
            "--domain",
            "1,-2,3,-1",
            "-n",
            "500",
            "-o",
            "-",
        ]);
        assert!(
            run.status.success(),
            "{}",
            String::from_utf8_lossy(&run.stderr)
        );
        let rect = Rectangle::new(1.0, -2.0, 3.0, -1.0).unwrap();
        let text = String::from_utf8(run.stdout).unwrap();
        let points = parse_xy(&text);
        assert_eq!(points.len(), 500);
        assert!(points.iter().all(|&p| rect.contains(p)), "{system}");
    }
    let bad = tessera(&[
        "plane",
        "--system",
        "penrose",
        "--domain",
        "0,0,1,nan",
        "-n",
        "5",
    ]);
    assert!(!bad.status.success());
    let err = String::from_utf8_lossy(&bad.stderr);
    assert!(err.contains("domain") && err.contains("finite"), "{err}");
}

proptest::proptest! {
    #![proptest_config(proptest::prelude::ProptestConfig::with_cases(24))]
    #[test]
    fn any_rectangle_gets_exactly_n_points_inside(
        x0 in -1e3f64..1e3,
        y0 in -1e3f64..1e3,
        w in 1e-3f64..1e3,
        h in 1e-3f64..1e3,
        n in 0usize..400,
        ramp in proptest::bool::ANY,
    ) {
        let rect = Rectangle::new(x0, y0, x0 + w, y0 + h).unwrap();
        each_system(|name, run| {
            let s = run(&rect, n, ramp);
            assert_eq!(s.len(), n, "{name}");
            assert!(s.iter().all(|s| rect.contains(s.position)), "{name} {rect:?}");
        });
    }
}

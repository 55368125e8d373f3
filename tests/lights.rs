//! Environment maps as lights: exact power sums, exactly N lights, positive
//! powers, cells against a brute-force Voronoi reference, median cut on
//! maps whose answer is known, the colour reader, and the CLI.

mod common;

use common::{on_threads, sky, tessera};
use glam::DVec3;
use std::f64::consts::{FRAC_1_SQRT_2, PI, TAU};
use tessera::baselines::median_cut::{median_cut, MedianCut};
use tessera::density::envmap::{EnvMap, Up};
use tessera::io::image::{read_raster, Raster, ReadOptions};
use tessera::lights::{
    lights, lights_with_stats, read_rgb, Light, LightOptions, LloydWeight, RgbMap,
    DEFAULT_TOLERANCE,
};
use tessera::synth::Sky;

const REALISTIC: [Sky; 4] = [Sky::ClearSky, Sky::Overcast, Sky::CityNight, Sky::Interior];

fn raster(width: usize, height: usize, values: Vec<f64>) -> Raster {
    Raster {
        width,
        height,
        values,
        bad_pixels: 0,
    }
}

fn sums(lights: &[Light]) -> (f64, [f64; 3], f64) {
    let mut rgb = [0.0; 3];
    for l in lights {
        for (sum, c) in rgb.iter_mut().zip(l.rgb) {
            *sum += c;
        }
    }
    (
        lights.iter().map(|l| l.luminance).sum(),
        rgb,
        lights.iter().map(|l| l.solid_angle).sum(),
    )
}

fn temp_dir(name: &str) -> std::path::PathBuf {
    let dir =
        std::env::temp_dir().join(format!("tessera-test-lights-{name}-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

/// Powers sum to the map's integral per channel, solid angles to 4 pi,
/// every light is positive in every channel, exactly N of them.
#[test]
fn powers_partition_the_map_exactly() {
    for sky in REALISTIC {
        let rgb = RgbMap::from(sky.generate(256, 128, 3));
        let map = rgb.env_map(Up::Z).unwrap();
        let channels = rgb.integral();
        for n in [1, 7, 64, 1000] {
            for lloyd_steps in [0, 2] {
                let options = LightOptions {
                    rgb: Some(&rgb),
                    lloyd_steps: Some(lloyd_steps),
                    ..Default::default()
                };
                let l = lights(&map, n, &options).unwrap();
                assert_eq!(l.len(), n);
                let (lum, colour, area) = sums(&l);
                let what = format!("{} n {n} lloyd {lloyd_steps}", sky.name());
                assert!((lum / map.integral() - 1.0).abs() < 1e-9, "{what}: {lum}");
                for c in 0..3 {
                    assert!(
                        (colour[c] / channels[c] - 1.0).abs() < 1e-9,
                        "{what} channel {c}: {} vs {}",
                        colour[c],
                        channels[c]
                    );
                }
                assert!((area / (4.0 * PI) - 1.0).abs() < 1e-9, "{what}: {area}");
                for light in &l {
                    assert!(light.luminance > 0.0, "{what}: {light:?}");
                    assert!(light.rgb.iter().all(|&c| c > 0.0), "{what}: {light:?}");
                    assert!((light.direction.length() - 1.0).abs() < 1e-12, "{what}");
                    assert!(light.solid_angle > 0.0, "{what}");
                }
            }
        }
    }
}

/// A map lit in three pixels still gives exactly N lights, all of positive
/// power, for N from 1 to far more than the lit pixels.
#[test]
fn exactly_n_lights_on_a_sparse_map() {
    let (w, h) = (64, 32);
    let mut values = vec![0.0; w * h];
    for (i, j, v) in [(5, 3, 1.0), (40, 20, 7.0), (41, 20, 0.5)] {
        values[j * w + i] = v;
    }
    let map = EnvMap::new(raster(w, h, values.clone()), Up::Z).unwrap();
    // a colour that is zero in blue on one of the lit pixels
    let mut rgb = RgbMap {
        width: w,
        height: h,
        rgb: values.iter().map(|&v| [v as f32; 3]).collect(),
        bad_samples: 0,
    };
    rgb.rgb[3 * w + 5] = [1.0, 1.0, 0.0];
    for n in [1, 2, 3, 4, 10, 100, 1000] {
        for lloyd_steps in [0, 1, 3] {
            let options = LightOptions {
                rgb: Some(&rgb),
                lloyd_steps: Some(lloyd_steps),
                ..Default::default()
            };
            let l = lights(&map, n, &options).unwrap();
            assert_eq!(l.len(), n);
            assert!(
                l.iter().all(|l| l.luminance > 0.0 && l.rgb[0] > 0.0),
                "n {n} lloyd {lloyd_steps}: {:?}",
                l.iter().find(|l| l.luminance <= 0.0)
            );
            let (lum, colour, area) = sums(&l);
            assert!((lum / map.integral() - 1.0).abs() < 1e-9);
            assert!((colour[0] / rgb.integral()[0] - 1.0).abs() < 1e-9);
            assert!((area / (4.0 * PI) - 1.0).abs() < 1e-9);
        }
    }
}

/// A light's blue power is positive exactly where its cell meets a pixel
/// with blue: lights on the pixel without blue have none.
#[test]
fn powers_are_positive_where_the_map_is() {
    let (w, h) = (64, 32);
    let mut rgb = RgbMap {
        width: w,
        height: h,
        rgb: vec![[0.0; 3]; w * h],
        bad_samples: 0,
    };
    rgb.rgb[10 * w + 10] = [1.0, 0.0, 0.0];
    rgb.rgb[20 * w + 50] = [0.0, 0.0, 1.0];
    let map = rgb.env_map(Up::Z).unwrap();
    let options = LightOptions {
        rgb: Some(&rgb),
        ..Default::default()
    };
    let l = lights(&map, 20, &options).unwrap();
    let red = map.direction_in_pixel(10, 10, 0.5, 0.5);
    for light in &l {
        assert!(light.luminance > 0.0);
        assert_eq!(light.rgb[1], 0.0);
        let on_red = light.direction.angle_between(red) < 0.1;
        assert_eq!(light.rgb[0] > 0.0, on_red, "{light:?}");
        assert_eq!(light.rgb[2] > 0.0, !on_red, "{light:?}");
    }
}

/// The cells' powers and mean directions against a brute-force Voronoi
/// reference: 64 x 64 sub-pixels per pixel, each given to its nearest
/// generator. Without Lloyd steps and with exponent 1 and no cap the
/// generators are the map's own tessera samples.
#[test]
fn cells_match_brute_force_voronoi() {
    let rgb = RgbMap::from(Sky::Interior.generate(128, 64, 2));
    let map = rgb.env_map(Up::Z).unwrap();
    let n = 24;
    let generators: Vec<DVec3> = map
        .generate(n)
        .unwrap()
        .iter()
        .map(|s| s.position.normalize())
        .collect();
    let (w, h) = (map.width(), map.height());
    let k = 64;
    let mut power = vec![0.0; n];
    let mut moment = vec![DVec3::ZERO; n];
    for j in 0..h {
        for i in 0..w {
            let v = map.values()[j * w + i];
            let mass = v * map.pixel_solid_angle(j) / (k * k) as f64;
            for q in 0..k * k {
                let d = map.direction_in_pixel(
                    i,
                    j,
                    ((q % k) as f64 + 0.5) / k as f64,
                    ((q / k) as f64 + 0.5) / k as f64,
                );
                let nearest = (0..n)
                    .min_by(|&a, &b| {
                        (generators[a] - d)
                            .length_squared()
                            .total_cmp(&(generators[b] - d).length_squared())
                    })
                    .unwrap();
                power[nearest] += mass;
                moment[nearest] += mass * d;
            }
        }
    }
    for tolerance in [1.0, DEFAULT_TOLERANCE] {
        let options = LightOptions {
            exponent: Some(1.0),
            pixel_cap: f64::INFINITY,
            lloyd_steps: Some(0),
            tolerance,
            ..Default::default()
        };
        let l = lights(&map, n, &options).unwrap();
        let mean = map.integral() / n as f64;
        let (mut worst, mut worst_angle): (f64, f64) = (0.0, 0.0);
        for (a, light) in l.iter().enumerate() {
            let err = (light.luminance - power[a]).abs() / mean;
            worst = worst.max(err);
            let angle = light.direction.angle_between(moment[a].normalize());
            worst_angle = worst_angle.max(angle);
        }
        // measured: power within 1.2e-3 (tolerance 1) and 3e-4 (0.01) of a
        // mean power, directions within 9e-4 and 4e-4 rad, on pixels of
        // 0.05 rad; the brute force itself moves by about 2e-4 between 64
        // and 128 sub-samples a side
        let (power_bound, angle_bound) = if tolerance >= 1.0 {
            (3e-3, 2e-3)
        } else {
            (1e-3, 1e-3)
        };
        assert!(worst < power_bound, "tolerance {tolerance}: {worst}");
        assert!(
            worst_angle < angle_bound,
            "tolerance {tolerance}: {worst_angle} rad"
        );
    }
}

#[test]
fn results_do_not_depend_on_the_thread_count() {
    let rgb = RgbMap::from(Sky::ClearSky.generate(256, 128, 1));
    let map = rgb.env_map(Up::Z).unwrap();
    let options = LightOptions {
        rgb: Some(&rgb),
        lloyd_steps: Some(1),
        ..Default::default()
    };
    let one = on_threads(1, || lights(&map, 500, &options).unwrap());
    let two = on_threads(2, || lights(&map, 500, &options).unwrap());
    assert_eq!(one, two);
    assert_eq!(one, lights(&map, 500, &options).unwrap());
    // a seed gives another set with the same total
    let seeded = lights(
        &map,
        500,
        &LightOptions {
            seed: Some(3),
            ..options
        },
    )
    .unwrap();
    assert_ne!(seeded, one);
    assert!((sums(&seeded).0 / map.integral() - 1.0).abs() < 1e-9);
}

/// With `Up::Y` a bright spot near the top row lights from +Y.
#[test]
fn up_y_turns_the_lights() {
    let (w, h) = (64, 32);
    let mut values = vec![0.01; w * h];
    values[w * 2 + 20] = 1e4;
    for (up, axis) in [(Up::Z, DVec3::Z), (Up::Y, DVec3::Y)] {
        let map = EnvMap::new(raster(w, h, values.clone()), up).unwrap();
        let l = lights(&map, 16, &LightOptions::default()).unwrap();
        // the spot, 0.1 rad tall and 0.025 wide, holds almost everything
        let spot = map.direction_in_pixel(20, 2, 0.5, 0.5);
        let bright: Vec<&Light> = l
            .iter()
            .filter(|l| l.luminance > 0.01 * map.integral())
            .collect();
        assert!(!bright.is_empty());
        let held: f64 = bright.iter().map(|l| l.luminance).sum();
        assert!(held > 0.95 * map.integral(), "{up:?}: {held}");
        for light in bright {
            assert!(
                light.direction.angle_between(spot) < 0.06,
                "{up:?}: {light:?}"
            );
            assert!(light.direction.dot(axis) > 0.9, "{up:?}: {light:?}");
        }
    }
}

#[test]
fn lloyd_steps_lower_the_quantisation_energy() {
    let rgb = RgbMap::from(Sky::Overcast.generate(256, 128, 1));
    let map = rgb.env_map(Up::Z).unwrap();
    let energy = |steps: usize| {
        // the map-weighted iteration is Lloyd's for this energy
        let options = LightOptions {
            lloyd_steps: Some(steps),
            lloyd_weight: LloydWeight::Map,
            ..Default::default()
        };
        let (l, stats) = lights_with_stats(&map, 300, &options).unwrap();
        assert_eq!(stats.passes, steps + 1);
        let (w, h) = (map.width(), map.height());
        let mut e = 0.0;
        for j in 0..h {
            for i in 0..w {
                let mass = map.values()[j * w + i] * map.pixel_solid_angle(j) / 4.0;
                for (u, v) in [(0.25, 0.25), (0.75, 0.25), (0.25, 0.75), (0.75, 0.75)] {
                    let d = map.direction_in_pixel(i, j, u, v);
                    let nearest = l
                        .iter()
                        .map(|l| (l.direction - d).length_squared())
                        .fold(f64::INFINITY, f64::min);
                    e += mass * nearest;
                }
            }
        }
        e
    };
    let e: Vec<f64> = (0..3).map(energy).collect();
    assert!(e[1] < e[0] && e[2] < e[1], "{e:?}");
}

#[test]
fn drawn_squared_lloyd_steps_keep_the_drawn_spread() {
    // top half 4, bottom half 1, drawn in proportion (exponent 1, no cap):
    // 4/5 of the lights on top; Lloyd steps weighted by the map drift
    // towards sqrt(4) / (sqrt(4) + 1) = 2/3, weighted by the drawn density
    // squared they stay
    let (w, h) = (128, 64);
    let values: Vec<f64> = (0..w * h)
        .map(|p| if p / w < h / 2 { 4.0 } else { 1.0 })
        .collect();
    let map = EnvMap::new(raster(w, h, values), Up::Z).unwrap();
    let top = |weight: LloydWeight, steps: usize| {
        let options = LightOptions {
            exponent: Some(1.0),
            pixel_cap: f64::INFINITY,
            lloyd_steps: Some(steps),
            lloyd_weight: weight,
            ..Default::default()
        };
        let l = lights(&map, 400, &options).unwrap();
        l.iter().filter(|l| l.direction.z > 0.0).count() as f64 / 400.0
    };
    let drawn = top(LloydWeight::DrawnSquared, 0);
    let kept = top(LloydWeight::DrawnSquared, 50);
    let drifted = top(LloydWeight::Map, 50);
    assert!((drawn - 0.8).abs() < 0.02, "{drawn}");
    assert!((kept - 0.8).abs() < 0.02, "{kept}");
    assert!(drifted < kept - 0.03, "{drifted}");
}

#[test]
fn bad_requests_are_refused() {
    let map = EnvMap::new(raster(8, 4, vec![1.0; 32]), Up::Z).unwrap();
    let small = RgbMap {
        width: 4,
        height: 2,
        rgb: vec![[1.0; 3]; 8],
        bad_samples: 0,
    };
    let d = LightOptions::default();
    for (n, options, needle) in [
        (0, d, "at least one"),
        (
            4,
            LightOptions {
                exponent: Some(-1.0),
                ..d
            },
            "exponent",
        ),
        (
            4,
            LightOptions {
                exponent: Some(f64::NAN),
                ..d
            },
            "exponent",
        ),
        (
            4,
            LightOptions {
                tolerance: 0.0,
                ..d
            },
            "tolerance",
        ),
        (
            4,
            LightOptions {
                tolerance: f64::INFINITY,
                ..d
            },
            "tolerance",
        ),
        (
            4,
            LightOptions {
                pixel_cap: 0.0,
                ..d
            },
            "cap",
        ),
        (
            4,
            LightOptions {
                lloyd_steps: Some(101),
                ..d
            },
            "Lloyd",
        ),
        (
            4,
            LightOptions {
                rgb: Some(&small),
                ..d
            },
            "4x2",
        ),
    ] {
        let e = lights(&map, n, &options).unwrap_err().to_string();
        assert!(e.contains(needle), "{e}");
    }
    for variant in MedianCut::all() {
        assert!(median_cut(&map, None, 0, variant).is_err());
        let e = median_cut(&map, Some(&small), 4, variant).unwrap_err();
        assert!(e.to_string().contains("4x2"), "{e}");
    }
}

/// One light of a constant map is the whole sphere: its mean direction
/// vanishes, so the light stays at its drawn direction.
#[test]
fn one_light_holds_everything() {
    let map = EnvMap::new(raster(16, 8, vec![2.0; 128]), Up::Z).unwrap();
    let l = lights(&map, 1, &LightOptions::default()).unwrap();
    assert_eq!(l.len(), 1);
    assert!((l[0].luminance - 8.0 * PI).abs() < 1e-9);
    assert!((l[0].solid_angle - 4.0 * PI).abs() < 1e-9);
    assert!((l[0].direction.length() - 1.0).abs() < 1e-12);
}

// ---- median cut ----

fn close(a: DVec3, b: DVec3) -> bool {
    (a - b).length() < 1e-9
}

/// On a constant map the regions are known: hemispheres, then quarter
/// spheres (ties split the rows), with powers in proportion to area.
#[test]
fn median_cut_on_a_constant_map() {
    let map = EnvMap::new(raster(8, 4, vec![1.0; 32]), Up::Z).unwrap();
    for variant in MedianCut::all() {
        let two = median_cut(&map, None, 2, variant).unwrap();
        assert_eq!(two.len(), 2);
        assert!(close(two[0].direction, DVec3::Y) && close(two[1].direction, -DVec3::Y));
        for l in &two {
            assert!((l.luminance - TAU).abs() < 1e-12 && (l.solid_angle - TAU).abs() < 1e-12);
        }
        let four = median_cut(&map, None, 4, variant).unwrap();
        let s = FRAC_1_SQRT_2;
        let expected = [
            DVec3::new(0.0, s, s),
            DVec3::new(0.0, -s, s),
            DVec3::new(0.0, s, -s),
            DVec3::new(0.0, -s, -s),
        ];
        for e in expected {
            let l = four
                .iter()
                .find(|l| close(l.direction, e))
                .unwrap_or_else(|| panic!("{variant:?}: no light at {e}: {four:?}"));
            assert!((l.luminance - PI).abs() < 1e-12);
        }
    }
}

/// Median cut on a map whose energy cut is known: value 3 on phi in
/// [0, pi), 1 on [pi, 2 pi); equal energy is nearest after 3 of 8 columns.
#[test]
fn median_cut_on_a_two_level_map() {
    let (w, h) = (8, 4);
    let values: Vec<f64> = (0..w * h)
        .map(|p| if p % w < 4 { 3.0 } else { 1.0 })
        .collect();
    let map = EnvMap::new(raster(w, h, values), Up::Z).unwrap();
    let two = median_cut(&map, None, 2, MedianCut::Classic).unwrap();
    let column = 4.0 * PI / 8.0; // solid angle of one column
    assert!((two[0].luminance - 9.0 * column).abs() < 1e-12);
    assert!((two[1].luminance - 7.0 * column).abs() < 1e-12);
    // the first region is phi in [0, 3 pi / 4], its centroid at phi = 3 pi / 8
    let phi = 3.0 * PI / 8.0;
    assert!(close(
        two[0].direction,
        DVec3::new(phi.cos(), phi.sin(), 0.0)
    ));
}

/// All the energy in one pixel: one light there with all of it.
#[test]
fn median_cut_finds_a_single_lit_pixel() {
    let (w, h) = (32, 16);
    let mut values = vec![0.0; w * h];
    values[5 * w + 9] = 4.0;
    let map = EnvMap::new(raster(w, h, values), Up::Z).unwrap();
    // the pixel's centroid: its exact first moment
    let (z0, z1) = ((6.0 * PI / 16.0).cos(), (5.0 * PI / 16.0).cos());
    let f = |z: f64| (z * (1.0 - z * z).sqrt() + z.asin()) / 2.0;
    let (p0, p1) = (9.0 * TAU / 32.0, 10.0 * TAU / 32.0);
    let centroid = DVec3::new(
        (f(z1) - f(z0)) * (p1.sin() - p0.sin()),
        (f(z1) - f(z0)) * (p0.cos() - p1.cos()),
        (p1 - p0) * (z1 * z1 - z0 * z0) / 2.0,
    )
    .normalize();
    for variant in MedianCut::all() {
        for n in [1, 5, 8, 64] {
            let l = median_cut(&map, None, n, variant).unwrap();
            assert_eq!(l.len(), n);
            let lit: Vec<&Light> = l.iter().filter(|l| l.luminance > 0.0).collect();
            assert_eq!(lit.len(), 1, "{variant:?} n {n}");
            assert!((lit[0].luminance - map.integral()).abs() < 1e-12);
            assert!(
                lit[0].direction.angle_between(centroid) < 1e-9,
                "{variant:?} n {n}"
            );
            assert!((sums(&l).2 - 4.0 * PI).abs() < 1e-9);
        }
    }
}

/// Exactly n regions for any n (classic: a partial last round), exact
/// sums per channel, and fewer only when the map has fewer pixels.
#[test]
fn median_cut_counts_and_sums() {
    let rgb = RgbMap::from(Sky::ClearSky.generate(128, 64, 1));
    let map = rgb.env_map(Up::Z).unwrap();
    for variant in MedianCut::all() {
        for n in [1, 3, 6, 100, 1000] {
            let l = median_cut(&map, Some(&rgb), n, variant).unwrap();
            assert_eq!(l.len(), n, "{variant:?}");
            let (lum, colour, area) = sums(&l);
            assert!((lum / map.integral() - 1.0).abs() < 1e-12);
            for (c, total) in colour.iter().zip(rgb.integral()) {
                assert!((c / total - 1.0).abs() < 1e-12);
            }
            assert!((area / (4.0 * PI) - 1.0).abs() < 1e-12);
        }
        let tiny = EnvMap::new(raster(4, 2, vec![1.0; 8]), Up::Z).unwrap();
        assert_eq!(median_cut(&tiny, None, 50, variant).unwrap().len(), 8);
    }
    // classic at 2^k: every region split k times, so all have equal depth
    // and near-equal energy on a smooth map
    let smooth = RgbMap::from(Sky::Smooth.generate(256, 128, 1));
    let map = smooth.env_map(Up::Z).unwrap();
    let l = median_cut(&map, None, 64, MedianCut::Classic).unwrap();
    let mean = map.integral() / 64.0;
    assert!(l.iter().all(|l| (l.luminance / mean - 1.0).abs() < 0.2));
}

// ---- reading ----

#[test]
fn read_rgb_agrees_with_read_raster() {
    let dir = temp_dir("read");
    let [big, small] = sky::write_issue_maps(&dir);
    for path in [&big, &small] {
        for options in [
            ReadOptions::default(),
            ReadOptions {
                channel: Some("G".into()),
                ..Default::default()
            },
        ] {
            let (rgb, r) = read_rgb(path, &options).unwrap();
            assert_eq!(r, read_raster(path, &options).unwrap());
            assert_eq!((rgb.width, rgb.height), (r.width, r.height));
            assert!(rgb.bad_samples > 0, "the hostile map has bad samples");
            assert!(rgb.rgb.iter().flatten().all(|v| v.is_finite() && *v >= 0.0));
        }
        let strict = ReadOptions {
            strict: true,
            ..Default::default()
        };
        let e = read_rgb(path, &strict).unwrap_err().to_string();
        assert!(e.contains(&*path.to_string_lossy()), "{e}");
    }
    // PNG (sRGB decoded) and a grey PNG
    let png = dir.join("map.png");
    image::RgbImage::from_fn(8, 4, |x, y| {
        image::Rgb([(x * 30) as u8, (y * 60) as u8, 200])
    })
    .save(&png)
    .unwrap();
    let (rgb, r) = read_rgb(&png, &ReadOptions::default()).unwrap();
    assert_eq!(r, read_raster(&png, &ReadOptions::default()).unwrap());
    assert!((rgb.luminance()[9] - r.values[9]).abs() < 1e-6);
    let grey = dir.join("grey.png");
    image::GrayImage::from_fn(8, 4, |x, _| image::Luma([(x * 30) as u8]))
        .save(&grey)
        .unwrap();
    let (rgb, r) = read_rgb(&grey, &ReadOptions::default()).unwrap();
    assert_eq!(r, read_raster(&grey, &ReadOptions::default()).unwrap());
    assert!(rgb.rgb.iter().all(|p| p[0] == p[1] && p[1] == p[2]));
    // errors name the file
    let junk = dir.join("junk.exr");
    std::fs::write(&junk, b"not an image").unwrap();
    let empty = dir.join("empty.exr");
    std::fs::write(&empty, b"").unwrap();
    for (path, options, needle) in [
        (
            dir.join("missing.exr"),
            ReadOptions::default(),
            "missing.exr",
        ),
        (junk.clone(), ReadOptions::default(), "junk.exr"),
        (empty, ReadOptions::default(), "empty"),
        (
            big.clone(),
            ReadOptions {
                channel: Some("Q".into()),
                ..Default::default()
            },
            "no channel named 'Q'",
        ),
    ] {
        let e = read_rgb(&path, &options).unwrap_err().to_string();
        assert!(e.contains(needle), "{e}");
    }
    std::fs::remove_dir_all(&dir).unwrap();
}

// ---- the command line ----

#[test]
fn cli_writes_csv_and_json() {
    let dir = temp_dir("cli");
    let map = Sky::Overcast.generate(128, 64, 1);
    let path = dir.join("sky.exr");
    map.write_exr(&path, false).unwrap();
    let out = dir.join("lights.csv");
    let run = tessera(&[
        "lights",
        "--map",
        path.to_str().unwrap(),
        "-n",
        "100",
        "-o",
        out.to_str().unwrap(),
    ]);
    assert!(
        run.status.success(),
        "{}",
        String::from_utf8_lossy(&run.stderr)
    );
    let text = std::fs::read_to_string(&out).unwrap();
    let mut lines = text.lines();
    assert_eq!(lines.next(), Some("x,y,z,r,g,b,luminance,solid_angle"));
    let rows: Vec<Vec<f64>> = lines
        .map(|l| l.split(',').map(|v| v.parse().unwrap()).collect())
        .collect();
    assert_eq!(rows.len(), 100);
    let rgb = RgbMap::from(map);
    let total_g: f64 = rows.iter().map(|r| r[4]).sum();
    assert!((total_g / rgb.integral()[1] - 1.0).abs() < 1e-9);
    // the library gives the same lights
    let env = rgb.env_map(Up::Z).unwrap();
    let lib = lights(
        &env,
        100,
        &LightOptions {
            rgb: Some(&rgb),
            ..Default::default()
        },
    )
    .unwrap();
    for (row, l) in rows.iter().zip(&lib) {
        assert_eq!(row[6], l.luminance);
        assert_eq!(row[0], l.direction.x);
    }
    // JSON, Y up, a seed
    let run = tessera(&[
        "lights",
        "--map",
        path.to_str().unwrap(),
        "-n",
        "10",
        "--format",
        "json",
        "--up",
        "y",
        "--seed",
        "4",
    ]);
    assert!(
        run.status.success(),
        "{}",
        String::from_utf8_lossy(&run.stderr)
    );
    let v: serde_json::Value = serde_json::from_slice(&run.stdout).unwrap();
    let array = v.as_array().unwrap();
    assert_eq!(array.len(), 10);
    for key in ["x", "y", "z", "r", "g", "b", "luminance", "solid_angle"] {
        assert!(array[0][key].is_number(), "{key}");
    }
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn cli_refuses_bad_input_clearly() {
    let dir = temp_dir("cli-bad");
    let [hostile, _] = sky::write_issue_maps(&dir);
    let hostile = hostile.to_str().unwrap().to_string();
    let junk = dir.join("junk.exr");
    std::fs::write(&junk, b"garbage").unwrap();
    let black = dir.join("black.exr");
    tessera::synth::SynthMap {
        width: 8,
        height: 4,
        rgb: vec![[0.0; 3]; 32],
    }
    .write_exr(&black, false)
    .unwrap();
    let junk = junk.to_str().unwrap().to_string();
    let black = black.to_str().unwrap().to_string();
    for (args, needle) in [
        (
            vec!["lights", "--map", "/no/such/map.exr", "-n", "4"],
            "/no/such/map.exr",
        ),
        (vec!["lights", "--map", &junk, "-n", "4"], "junk.exr"),
        (vec!["lights", "--map", &black, "-n", "4"], "black.exr"),
        (
            vec!["lights", "--map", &hostile, "-n", "4", "--strict"],
            "negative",
        ),
        (vec!["lights", "--map", &hostile, "-n", "0"], "at least one"),
        (
            vec!["lights", "--map", &hostile, "-n", "4", "--channel", "Q"],
            "'Q'",
        ),
        (
            vec!["lights", "--map", &hostile, "-n", "4", "--format", "xml"],
            "xml",
        ),
        (vec!["lights", "-n", "4"], "--map"),
    ] {
        let out = tessera(&args);
        assert!(!out.status.success(), "{args:?} succeeded");
        let err = String::from_utf8_lossy(&out.stderr);
        assert!(err.contains(needle), "{args:?}: {err}");
        assert!(!err.contains("panicked"), "{args:?}: {err}");
    }
    // the hostile map without --strict: a warning, and lights
    let out = tessera(&["lights", "--map", &hostile, "-n", "16"]);
    assert!(out.status.success());
    assert!(String::from_utf8_lossy(&out.stderr).contains("warning"));
    assert_eq!(String::from_utf8_lossy(&out.stdout).lines().count(), 17);
    std::fs::remove_dir_all(&dir).unwrap();
}

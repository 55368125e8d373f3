//! The synthetic maps of `tessera::synth`: well-formed, deterministic, with
//! the features their docs state, and surviving an EXR round trip.
//! Measured values are printed (run with `--nocapture` to see them).

use approx::assert_relative_eq;
use std::f64::consts::{FRAC_PI_2, PI, TAU};
use std::path::PathBuf;
use tessera::density::plane::Raster;
use tessera::io::image::{read_raster, ReadOptions};
use tessera::synth::{Raster2d, Sky, SynthMap};

const W: usize = 1024;
const H: usize = 512;

fn theta(j: usize, h: usize) -> f64 {
    (j as f64 + 0.5) / h as f64 * PI
}

fn direction(i: usize, j: usize, w: usize, h: usize) -> [f64; 3] {
    let (t, p) = (theta(j, h), (i as f64 + 0.5) / w as f64 * TAU);
    [t.sin() * p.cos(), t.sin() * p.sin(), t.cos()]
}

fn solid_angle(j: usize, w: usize, h: usize) -> f64 {
    let (t0, t1) = (j as f64 / h as f64 * PI, (j + 1) as f64 / h as f64 * PI);
    TAU / w as f64 * (t0.cos() - t1.cos())
}

fn median(mut v: Vec<f64>) -> f64 {
    let mid = v.len() / 2;
    *v.select_nth_unstable_by(mid, f64::total_cmp).1
}

/// Median luminance of the upper hemisphere.
fn sky_median(map: &SynthMap) -> f64 {
    let lum = map.luminance();
    median(
        (0..lum.len())
            .filter(|k| theta(k / map.width, map.height) < FRAC_PI_2)
            .map(|k| lum[k])
            .collect(),
    )
}

fn zero_fraction(values: &[f64]) -> f64 {
    values.iter().filter(|&&v| v == 0.0).count() as f64 / values.len() as f64
}

/// 8-connected blobs of pixels at or above `cut`: (pixel count, peak) each.
fn blobs(lum: &[f64], w: usize, h: usize, cut: f64) -> Vec<(usize, f64)> {
    let mut seen = vec![false; lum.len()];
    let mut out = Vec::new();
    for start in 0..lum.len() {
        if seen[start] || lum[start] < cut {
            continue;
        }
        seen[start] = true;
        let mut stack = vec![start];
        let (mut size, mut peak) = (0, 0.0f64);
        while let Some(k) = stack.pop() {
            size += 1;
            peak = peak.max(lum[k]);
            let (i, j) = ((k % w) as i64, (k / w) as i64);
            for dj in -1..=1 {
                for di in -1..=1 {
                    let (ni, nj) = ((i + di).rem_euclid(w as i64), j + dj);
                    if nj < 0 || nj >= h as i64 {
                        continue;
                    }
                    let n = nj as usize * w + ni as usize;
                    if !seen[n] && lum[n] >= cut {
                        seen[n] = true;
                        stack.push(n);
                    }
                }
            }
        }
        out.push((size, peak));
    }
    out
}

/// Maximal runs of at least `min` zero pixels along rows and columns.
fn zero_runs(lum: &[f64], w: usize, h: usize, min: usize) -> usize {
    let count = |cells: &mut dyn Iterator<Item = f64>| {
        let (mut runs, mut n) = (0, 0);
        for v in cells {
            if v == 0.0 {
                n += 1;
            } else {
                runs += (n >= min) as usize;
                n = 0;
            }
        }
        runs + (n >= min) as usize
    };
    let rows: usize = (0..h)
        .map(|j| count(&mut (0..w).map(|i| lum[j * w + i])))
        .sum();
    let columns: usize = (0..w)
        .map(|i| count(&mut (0..h).map(|j| lum[j * w + i])))
        .sum();
    rows + columns
}

fn temp_dir(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("tessera-synth-{}-{name}", std::process::id()));
    std::fs::create_dir_all(&dir).expect("temp dir");
    dir
}

#[test]
fn every_map_is_finite_nonnegative_deterministic_and_seeded() {
    for sky in Sky::all() {
        let a = sky.generate(W, H, 11);
        assert_eq!((a.width, a.height, a.rgb.len()), (W, H, W * H));
        assert!(
            a.rgb.iter().flatten().all(|c| c.is_finite() && *c >= 0.0),
            "{}",
            sky.name()
        );
        assert!(a.luminance().iter().any(|&v| v > 0.0), "{}", sky.name());
        assert_eq!(
            a,
            sky.generate(W, H, 11),
            "{} is not deterministic",
            sky.name()
        );
        if *sky != Sky::Smooth {
            assert_ne!(a, sky.generate(W, H, 12), "{} ignores the seed", sky.name());
        }
        assert_eq!(Sky::from_name(sky.name()), Some(*sky));
        // odd and tiny sizes work too
        for (w, h) in [(1, 1), (3, 2), (37, 19)] {
            let m = sky.generate(w, h, 5);
            assert_eq!(m.rgb.len(), w * h);
            assert!(m.rgb.iter().flatten().all(|c| c.is_finite() && *c >= 0.0));
        }
        assert!(sky.generate(0, 4, 1).rgb.is_empty());
    }
    for sigma in [f64::NAN, f64::INFINITY, 40.0, -3.0] {
        let m = Sky::Textured { sigma }.generate(64, 32, 1);
        assert!(
            m.rgb.iter().flatten().all(|c| c.is_finite() && *c >= 0.0),
            "{sigma}"
        );
        assert_eq!(Sky::Textured { sigma }.name(), "textured");
    }
    assert_eq!(Sky::Smooth.generate(W, H, 1), Sky::Smooth.generate(W, H, 2));
}

#[test]
fn every_map_is_an_environment_map_density() {
    use tessera::density::envmap::{EnvMap, Up};
    for sky in Sky::all() {
        let map = EnvMap::new(sky.generate(256, 128, 1).raster(), Up::Z).unwrap();
        assert!(
            map.integral() > 0.0 && map.integral().is_finite(),
            "{}",
            sky.name()
        );
    }
}

#[test]
fn clear_sky_has_a_bright_antialiased_sun_with_an_aureole_and_horizon_glow() {
    for seed in 1..=4 {
        let map = Sky::ClearSky.generate(W, H, seed);
        let lum = map.luminance();
        let (peak_at, peak) = lum
            .iter()
            .copied()
            .enumerate()
            .max_by(|a, b| a.1.total_cmp(&b.1))
            .unwrap();
        let sky = sky_median(&map);
        let contrast = peak / sky;
        let disk_pixels = lum.iter().filter(|&&v| v >= 0.05 * peak).count();
        let sun = direction(peak_at % W, peak_at / W, W, H);
        let angle = |k: usize| {
            let d = direction(k % W, k / W, W, H);
            (d[0] * sun[0] + d[1] * sun[1] + d[2] * sun[2])
                .clamp(-1.0, 1.0)
                .acos()
                .to_degrees()
        };
        let energy = |k: usize| lum[k] * solid_angle(k / W, W, H);
        let total: f64 = (0..lum.len()).map(energy).sum();
        let within = |deg: f64| {
            (0..lum.len())
                .filter(|&k| angle(k) < deg)
                .map(energy)
                .sum::<f64>()
                / total
        };
        let (core, aureole) = (within(1.0), within(10.0) - within(1.0));
        let ring = |lo: f64, hi: f64| {
            let v: Vec<f64> = (0..lum.len())
                .filter(|&k| (lo..hi).contains(&angle(k)) && lum[k] > 0.0)
                .map(|k| lum[k])
                .collect();
            median(v)
        };
        let (at2, at5, at20) = (ring(1.5, 2.5), ring(4.5, 5.5), ring(19.0, 21.0));
        // horizon glow, away from the sun: the row just above the horizon
        // against the rows near the zenith
        let row_mean = |j: usize| {
            let v: Vec<f64> = (0..W)
                .map(|i| j * W + i)
                .filter(|&k| angle(k) > 60.0 && lum[k] > 0.0)
                .map(|k| lum[k])
                .collect();
            v.iter().sum::<f64>() / v.len() as f64
        };
        let glow = row_mean(H / 2 - 1) / row_mean(H / 16);
        println!(
            "clear-sky seed {seed}: sky median {sky:.4}, peak/median {contrast:.3e}, pixels >= 5 % of peak {disk_pixels}, \
             energy within 1 deg of the sun {:.1} %, aureole 1-10 deg {:.1} %, ring medians / sky at 2, 5, 20 deg: {:.0}, {:.1}, {:.2}; horizon/zenith {glow:.2}",
            100.0 * core,
            100.0 * aureole,
            at2 / sky,
            at5 / sky,
            at20 / sky
        );
        assert!((1e4..=1e5).contains(&contrast), "peak/median {contrast}");
        assert!(disk_pixels > 1, "the sun is one pixel");
        assert!(core > 0.25, "sun energy fraction {core}");
        assert!(aureole > 0.02, "aureole energy fraction {aureole}");
        assert!(at2 > at5 && at5 > at20, "the aureole does not fall off");
        assert!(glow > 1.5, "no horizon glow: {glow}");
        // a zero line beside the sun
        let (pi, pj) = (peak_at % W, peak_at / W);
        let near_zeros = (pj.saturating_sub(4)..=(pj + 4).min(H - 1))
            .flat_map(|j| (pi + W - 4..=pi + W + 4).map(move |i| j * W + i % W))
            .filter(|&k| lum[k] == 0.0)
            .count();
        assert!(near_zeros >= 3, "{near_zeros} zero pixels beside the sun");
    }
}

#[test]
fn overcast_zenith_is_three_times_the_horizon() {
    let map = Sky::Overcast.generate(W, H, 3);
    let lum = map.luminance();
    let row_median = |j: usize| median((0..W).map(|i| lum[j * W + i]).collect());
    let ratio = row_median(2) / row_median(H / 2 - 1);
    println!("overcast: zenith/horizon {ratio:.3}");
    assert!((2.6..=3.4).contains(&ratio), "{ratio}");
    // mild texture: log luminance varies by a few percent along a row
    let row: Vec<f64> = (0..W)
        .map(|i| lum[(H / 4) * W + i].ln())
        .filter(|v| v.is_finite())
        .collect();
    let mean = row.iter().sum::<f64>() / row.len() as f64;
    let sd = (row.iter().map(|v| (v - mean).powi(2)).sum::<f64>() / row.len() as f64).sqrt();
    println!("overcast: cloud texture sd of log luminance {sd:.3}");
    assert!((0.02..0.3).contains(&sd), "{sd}");
}

#[test]
fn city_has_hundreds_of_small_lights_near_the_horizon() {
    for seed in 1..=3 {
        let map = Sky::CityNight.generate(W, H, seed);
        let lum = map.luminance();
        let background = median(lum.clone());
        let lights = blobs(&lum, W, H, 100.0 * background);
        let bright = lights.iter().filter(|b| b.1 > 3e3 * background).count();
        let small = lights.iter().filter(|b| b.0 <= 4).count();
        // lights within 20 degrees of the horizon
        let near: usize = (0..lum.len())
            .filter(|&k| {
                lum[k] >= 100.0 * background
                    && (theta(k / W, H) - FRAC_PI_2).abs() < 20f64.to_radians()
            })
            .count();
        let lit = lum.iter().filter(|&&v| v >= 100.0 * background).count();
        println!(
            "city seed {seed}: background {background:.4}, {} blobs above 100x background ({small} of at most 4 pixels), \
             {bright} above 3000x, {:.0} % of their pixels within 20 deg of the horizon, zero pixels {:.1} %",
            lights.len(),
            100.0 * near as f64 / lit as f64,
            100.0 * zero_fraction(&lum)
        );
        assert!(
            (200..=800).contains(&lights.len()),
            "{} lights",
            lights.len()
        );
        assert!(small as f64 > 0.9 * lights.len() as f64);
        assert!((3..=12).contains(&bright), "{bright} bright lights");
        assert!(near as f64 > 0.8 * lit as f64);
        let zeros = zero_fraction(&lum);
        assert!((0.08..=0.14).contains(&zeros), "{zeros}");
    }
}

#[test]
fn interior_has_bright_lamps_and_windows() {
    for seed in 1..=4 {
        let map = Sky::Interior.generate(W, H, seed);
        let lum = map.luminance();
        let max = lum.iter().copied().fold(0.0, f64::max);
        let lamps = blobs(&lum, W, H, 0.5 * max);
        let lamps: Vec<_> = lamps.iter().filter(|b| b.0 >= 20).collect();
        let windows = blobs(&lum, W, H, 0.02 * max)
            .into_iter()
            .filter(|b| b.0 >= 100 && b.1 < 0.2 * max)
            .count();
        let walls = median(lum.clone());
        let lamp_upper = lum
            .iter()
            .enumerate()
            .filter(|(k, &v)| v >= 0.5 * max && theta(k / W, H) < FRAC_PI_2)
            .count() as f64
            / lum.iter().filter(|&&v| v >= 0.5 * max).count() as f64;
        println!(
            "interior seed {seed}: {} lamps (pixels: {:?}), {windows} window panes, lamp/median {:.0}, zero pixels {:.1} %",
            lamps.len(),
            lamps.iter().map(|b| b.0).collect::<Vec<_>>(),
            max / walls,
            100.0 * zero_fraction(&lum)
        );
        assert!((2..=4).contains(&lamps.len()), "{} lamps", lamps.len());
        assert!(lamp_upper == 1.0, "a lamp below the horizon");
        assert!(windows >= 1, "no window");
        assert!(max / walls > 100.0);
        let zeros = zero_fraction(&lum);
        assert!((0.03..=0.07).contains(&zeros), "{zeros}");
    }
}

#[test]
fn textures_have_the_stated_log_spread() {
    for sigma in [0.5, 1.0, 2.0] {
        let sky = Sky::Textured { sigma };
        let map = sky.generate(W, H, 2);
        let logs: Vec<f64> = map
            .luminance()
            .iter()
            .filter(|&&v| v > 0.0)
            .map(|v| v.ln())
            .collect();
        // split by hemisphere: the bases differ (sky 0.8-1, ground 0.3)
        let lum = map.luminance();
        let sd_of = |upper: bool| {
            let v: Vec<f64> = (0..lum.len())
                .filter(|&k| (theta(k / W, H) < FRAC_PI_2) == upper && lum[k] > 0.0)
                .map(|k| lum[k].ln())
                .collect();
            let m = v.iter().sum::<f64>() / v.len() as f64;
            (v.iter().map(|x| (x - m).powi(2)).sum::<f64>() / v.len() as f64).sqrt()
        };
        let (sd_sky, sd_ground) = (sd_of(true), sd_of(false));
        let zeros = zero_fraction(&lum);
        println!(
            "{}: sd of log luminance sky {sd_sky:.3}, ground {sd_ground:.3} ({} lit pixels), zero pixels {:.2} %",
            sky.name(),
            logs.len(),
            100.0 * zeros
        );
        for sd in [sd_sky, sd_ground] {
            assert!(
                (0.6 * sigma..1.3 * sigma).contains(&sd),
                "{sd} for sigma {sigma}"
            );
        }
        assert!((0.02..=0.04).contains(&zeros), "{zeros}");
    }
}

#[test]
fn issue_reproductions_are_as_issue_17_describes() {
    // ground = scale exp(sigma f), f of unit variance
    for (sky, scale, sigma) in [
        (Sky::GroundLognormal, 0.1, 1.0),
        (Sky::GroundLognormalMild, 0.2, 0.5),
    ] {
        let lum = sky.generate(W, H, 4).luminance();
        let f: Vec<f64> = lum[W * H / 2..]
            .iter()
            .map(|v| (v / scale).ln() / sigma)
            .collect();
        let mean = f.iter().sum::<f64>() / f.len() as f64;
        let var = f.iter().map(|v| (v - mean).powi(2)).sum::<f64>() / f.len() as f64;
        println!("{}: ground f mean {mean:.3}, variance {var:.3}", sky.name());
        assert!(
            mean.abs() < 0.15 && (var - 1.0).abs() < 0.15,
            "{mean} {var}"
        );
        // the sky is the smooth reference's, and nothing is zero
        assert_eq!(
            lum[..W * H / 2],
            Sky::Smooth.generate(W, H, 1).luminance()[..W * H / 2]
        );
        assert_eq!(zero_fraction(&lum), 0.0);
    }
    let smooth = Sky::Smooth.generate(W, H, 1).luminance();
    assert_eq!(zero_fraction(&smooth), 0.0);
    assert!(smooth[W * H / 2..].iter().all(|&v| (v - 0.1).abs() < 1e-7));
    assert_relative_eq!(smooth[0], 1.0, max_relative = 1e-4);
    assert_relative_eq!(smooth[W * H / 2 - 1], 0.4, max_relative = 1e-2);
    for seed in 1..=3 {
        let zeros = Sky::Zeros20.generate(W, H, seed).luminance();
        let fraction = zero_fraction(&zeros);
        println!("zeros-20 seed {seed}: {:.3} % zeros", 100.0 * fraction);
        assert!((0.19..=0.21).contains(&fraction), "{fraction}");
        for (z, s) in zeros.iter().zip(&smooth) {
            assert!(*z == 0.0 || z == s);
        }
    }
}

#[test]
fn zero_pixels_and_zero_lines_where_stated() {
    // (kind, stated fraction of zero pixels among the eligible ones)
    for (sky, lo, hi) in [
        (Sky::ClearSky, 0.015, 0.03),
        (Sky::Overcast, 0.007, 0.015),
        (Sky::CityNight, 0.08, 0.14),
        (Sky::Interior, 0.03, 0.07),
        (Sky::Textured { sigma: 1.0 }, 0.02, 0.04),
    ] {
        let map = sky.generate(W, H, 9);
        let lum = map.luminance();
        let zeros = zero_fraction(&lum);
        // isolated: most zero pixels have no zero 4-neighbour
        let isolated = (0..lum.len())
            .filter(|&k| lum[k] == 0.0)
            .filter(|&k| {
                let (i, j) = (k % W, k / W);
                let n = [
                    j * W + (i + 1) % W,
                    j * W + (i + W - 1) % W,
                    j.saturating_sub(1) * W + i,
                    (j + 1).min(H - 1) * W + i,
                ];
                n.iter().all(|&m| m == k || lum[m] > 0.0)
            })
            .count() as f64
            / (zeros * lum.len() as f64);
        // zero lines: runs of 7 or more zeros along a row or a column
        // (random zeros make one by chance with probability about 2 p^7 a
        // pixel: under 1 a map even at the city's 12 %)
        let lines = zero_runs(&lum, W, H, 7);
        println!(
            "{}: zero pixels {:.2} %, {:.0} % of them isolated, {lines} zero lines of 7+ pixels",
            sky.name(),
            100.0 * zeros,
            100.0 * isolated
        );
        assert!((lo..=hi).contains(&zeros), "{}: {zeros}", sky.name());
        assert!(isolated > 0.6, "{}: {isolated}", sky.name());
        assert!(lines >= 2, "{}: {lines} zero lines", sky.name());
    }
}

#[test]
fn exr_round_trips_f32_exactly_and_f16_dwab_closely() {
    let dir = temp_dir("exr");
    for sky in Sky::all() {
        let big = sky.generate(W, H, 21);
        let path = dir.join(format!("{}_1024x512_f32.exr", sky.name()));
        big.write_exr(&path, false).unwrap();
        let read = read_raster(&path, &ReadOptions::default()).unwrap();
        assert_eq!((read.width, read.height, read.bad_pixels), (W, H, 0));
        for (a, b) in read.values.iter().zip(&big.raster().values) {
            assert_relative_eq!(*a, *b, max_relative = 1e-6);
        }

        let small = sky.generate(W / 2, H / 2, 21);
        let path = dir.join(format!("{}_512x256_f16_dwab.exr", sky.name()));
        small.write_exr(&path, true).unwrap();
        let read = read_raster(&path, &ReadOptions::default()).unwrap();
        assert_eq!((read.width, read.height), (W / 2, H / 2));
        let want = small.raster().values;
        let max = want.iter().copied().fold(0.0, f64::max);
        // bright pixels (at least a tenth of the maximum) within a few percent
        let mut worst_bright = 0.0f64;
        for (a, b) in read.values.iter().zip(&want) {
            if *b >= 0.1 * max {
                worst_bright = worst_bright.max((a - b).abs() / b);
            }
        }
        let total = |v: &[f64]| {
            v.iter()
                .enumerate()
                .map(|(k, x)| x * solid_angle(k / (W / 2), W / 2, H / 2))
                .sum::<f64>()
        };
        let energy = total(&read.values) / total(&want) - 1.0;
        let lit: Vec<f64> = read
            .values
            .iter()
            .zip(&want)
            .filter(|(_, b)| **b > 0.0)
            .map(|(a, b)| (a - b).abs() / b)
            .collect();
        let median_error = median(lit);
        println!(
            "{}: f16 DWAB: {} negative (or invalid) pixels zeroed by the reader, worst relative error on pixels >= max/10 {:.2e}, \
             median relative error {:.2e}, energy {:+.2e}",
            sky.name(),
            read.bad_pixels,
            worst_bright,
            median_error,
            energy
        );
        assert!(worst_bright < 0.06, "{}: {worst_bright}", sky.name());
        assert!(energy.abs() < 0.02, "{}: {energy}", sky.name());
        assert!(median_error < 0.05, "{}: {median_error}", sky.name());
    }
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn exr_write_errors_name_the_path() {
    let dir = temp_dir("errors");
    let path = dir.join("missing-folder").join("map.exr");
    let map = Sky::Smooth.generate(16, 8, 1);
    for half in [false, true] {
        let err = map.write_exr(&path, half).unwrap_err().to_string();
        assert!(err.contains("missing-folder"), "{err}");
    }
    let empty = SynthMap {
        width: 0,
        height: 0,
        rgb: vec![],
    };
    let err = empty
        .write_exr(&dir.join("empty.exr"), false)
        .unwrap_err()
        .to_string();
    assert!(err.contains("empty.exr"), "{err}");
    let broken = SynthMap {
        width: 4,
        height: 4,
        rgb: vec![[1.0; 3]; 3],
    };
    assert!(broken
        .write_exr(&dir.join("broken.exr"), false)
        .unwrap_err()
        .to_string()
        .contains("broken.exr"));
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn planar_rasters_are_valid_deterministic_and_have_their_features() {
    let (w, h) = (512, 384);
    for kind in Raster2d::all() {
        let v = kind.generate(w, h, 7);
        assert_eq!(v.len(), w * h);
        assert!(
            v.iter().all(|x| x.is_finite() && *x >= 0.0),
            "{}",
            kind.name()
        );
        assert_eq!(v, kind.generate(w, h, 7), "{}", kind.name());
        assert_ne!(v, kind.generate(w, h, 8), "{}", kind.name());
        assert!(
            Raster::new(w, h, v.clone(), false).is_ok(),
            "{}",
            kind.name()
        );
        for (a, b) in [(1, 1), (5, 3), (3, 7)] {
            assert_eq!(kind.generate(a, b, 1).len(), a * b);
        }
        let zeros = zero_fraction(&v);
        let mut distinct = v.clone();
        distinct.sort_by(f64::total_cmp);
        distinct.dedup();
        println!(
            "{}: {} distinct values, zero pixels {:.2} %",
            kind.name(),
            distinct.len(),
            100.0 * zeros
        );
        match kind {
            // hard edges: a handful of levels, no intermediate values
            Raster2d::Discs | Raster2d::Rectangles => {
                assert!(distinct.len() <= 13, "{}", distinct.len())
            }
            Raster2d::Step => assert_eq!(distinct, vec![0.02, 1.0]),
            Raster2d::ZeroNoise => assert!((0.19..=0.21).contains(&zeros), "{zeros}"),
            Raster2d::Mixed => assert!((0.04..=0.06).contains(&zeros), "{zeros}"),
            Raster2d::Gradient | Raster2d::Lognormal => {
                assert_eq!(zeros, 0.0);
                assert!(distinct.len() > w * h / 4);
            }
        }
    }
    // the step's bright side is a half-plane: row 0 is left-to-right
    // monotone in brightness membership (one change at most)
    let v = Raster2d::Step.generate(200, 100, 3);
    for row in v.chunks(200) {
        assert!(row.windows(2).filter(|p| p[0] != p[1]).count() <= 1);
    }
}

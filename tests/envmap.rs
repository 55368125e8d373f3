//! Environment maps end to end: maps the tests write themselves with the
//! exr crate (sky gradient, a one-pixel sun 10^5 x the sky, negative, NaN
//! and infinite pixels), read back, sampled and checked against the exact
//! per-pixel density; single-pixel maps; hostile files.

mod common;
use common::tessera;

use common::sky;
use glam::DVec3;
use std::f64::consts::{PI, TAU};
use std::path::{Path, PathBuf};
use tessera::density::envmap::{EnvMap, Up};
use tessera::io::image::{read_raster, Raster, ReadOptions};

/// A scratch directory removed when dropped.
struct TempDir(PathBuf);

impl std::ops::Deref for TempDir {
    type Target = Path;
    fn deref(&self) -> &Path {
        &self.0
    }
}

impl Drop for TempDir {
    fn drop(&mut self) {
        std::fs::remove_dir_all(&self.0).ok();
    }
}

fn temp_dir(name: &str) -> TempDir {
    let dir = std::env::temp_dir().join(format!("tessera-envmap-{}-{name}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    TempDir(dir)
}

/// Map pixel (column, row) of a world direction, by the documented convention.
fn pixel(map: &EnvMap, v: DVec3) -> (usize, usize) {
    let m = map.up().to_map(v);
    let theta = m.x.hypot(m.y).atan2(m.z);
    let phi = m.y.atan2(m.x).rem_euclid(TAU);
    let i = ((phi / TAU * map.width() as f64) as usize).min(map.width() - 1);
    let j = ((theta / PI * map.height() as f64) as usize).min(map.height() - 1);
    (i, j)
}

/// Whether `v` lies on a pixel edge, to 1e-9 of a pixel: there the map's
/// trigonometry-free lookup and `pixel`'s `atan2` may round to either side.
fn on_pixel_edge(map: &EnvMap, v: DVec3) -> bool {
    let m = map.up().to_map(v);
    let row = m.x.hypot(m.y).atan2(m.z) / PI * map.height() as f64;
    let column = m.y.atan2(m.x).rem_euclid(TAU) / TAU * map.width() as f64;
    [row, column].iter().any(|x| (x - x.round()).abs() < 1e-9)
}

fn nside8_bin(v: DVec3) -> usize {
    let lon = v.y.atan2(v.x).rem_euclid(TAU);
    let lat = v.z.atan2(v.x.hypot(v.y));
    cdshealpix::nested::hash(3, lon, lat) as usize
}

/// Expected mass of the map in each Nside 8 bin, normalised to 1: a
/// midpoint quadrature with exact sub-pixel solid angles, 3x3 per sky
/// pixel and 64x64 per bright pixel (the sun may straddle a bin edge).
fn bin_masses(map: &EnvMap) -> Vec<f64> {
    let (w, h) = (map.width(), map.height());
    let mut mass = vec![0.0; 768];
    for j in 0..h {
        for i in 0..w {
            let v = map.values()[j * w + i];
            if v == 0.0 {
                continue;
            }
            let k = if v > 10.0 { 64 } else { 3 };
            for sj in 0..k {
                let a = (j as f64 + sj as f64 / k as f64) * PI / h as f64;
                let b = (j as f64 + (sj + 1) as f64 / k as f64) * PI / h as f64;
                let omega = TAU / (w * k) as f64 * (a.cos() - b.cos());
                let theta = 0.5 * (a + b);
                for si in 0..k {
                    let phi = (i as f64 + (si as f64 + 0.5) / k as f64) * TAU / w as f64;
                    let m = DVec3::new(
                        theta.sin() * phi.cos(),
                        theta.sin() * phi.sin(),
                        theta.cos(),
                    );
                    mass[nside8_bin(map.up().from_map(m))] += v * omega;
                }
            }
        }
    }
    let total: f64 = mass.iter().sum();
    mass.iter().map(|m| m / total).collect()
}

fn check_issue_map(path: &Path, n: usize) {
    let raster = read_raster(path, &ReadOptions::default()).unwrap();
    assert!(
        raster.bad_pixels > 0,
        "{}: {} bad pixels",
        path.display(),
        raster.bad_pixels
    );
    let map = EnvMap::new(raster, Up::Z).unwrap();
    let samples = map.generate(n).unwrap();
    assert_eq!(samples.len(), n);
    // every sample on the support
    assert!(samples.iter().all(|s| map.radiance(s.position) > 0.0));
    // counts per Nside 8 bin
    let expected = bin_masses(&map);
    let mut counts = vec![0usize; 768];
    for s in &samples {
        counts[nside8_bin(s.position)] += 1;
    }
    let mut worst: f64 = 0.0;
    for (bin, (&c, &e)) in counts.iter().zip(&expected).enumerate() {
        let e = e * n as f64;
        let tolerance = 4.0 * e.sqrt().max(1.0);
        worst = worst.max((c as f64 - e).abs() / tolerance);
        assert!(
            (c as f64 - e).abs() <= tolerance,
            "{}: bin {bin} has {c} samples, {e:.1} expected",
            path.display()
        );
    }
    // the sun pixel gets its share
    let (w, _) = (map.width(), map.height());
    let (si, sj) = sky::sun_pixel(map.width(), map.height());
    let sun_mass = map.values()[sj * w + si] * map.pixel_solid_angle(sj) / map.integral();
    let expected_sun = sun_mass * n as f64;
    let got = samples
        .iter()
        .filter(|s| pixel(&map, s.position) == (si, sj))
        .count() as f64;
    assert!(
        (got - expected_sun).abs() <= (0.1 * expected_sun).max(2.0),
        "{}: sun pixel has {got} samples, {expected_sun:.1} expected",
        path.display()
    );
    eprintln!(
        "{}: worst bin deviation {worst:.2} of 4 sigma; sun {got} vs {expected_sun:.1}",
        path.display()
    );
}

#[test]
fn issue_maps_follow_the_exact_density() {
    let dir = temp_dir("issue");
    let [big, small] = sky::write_issue_maps(&dir);
    check_issue_map(&big, 4096);
    check_issue_map(&small, 4096);
    check_issue_map(&small, 20_000);
}

fn single_pixel_raster(w: usize, h: usize, i: usize, j: usize) -> Raster {
    let mut values = vec![0.0; w * h];
    values[j * w + i] = 7.0;
    Raster {
        width: w,
        height: h,
        values,
        bad_pixels: 0,
    }
}

#[test]
fn single_pixel_maps_keep_every_sample_on_the_pixel() {
    // an ordinary pixel, a pixel touching each pole, one at the seam phi = 0
    for (w, h, i, j) in [
        (64, 32, 20, 11),
        (64, 32, 5, 0),
        (64, 32, 63, 31),
        (1024, 512, 0, 300),
        (7, 5, 3, 2),
    ] {
        for up in [Up::Z, Up::Y] {
            let map = EnvMap::new(single_pixel_raster(w, h, i, j), up).unwrap();
            for seeded in [None, Some(3)] {
                let m = seeded.map_or(map.clone(), |s| map.with_seed(s));
                let samples = m.generate(500).unwrap();
                assert_eq!(samples.len(), 500);
                for s in &samples {
                    let on_it = pixel(&map, s.position) == (i, j)
                        || (on_pixel_edge(&map, s.position) && map.radiance(s.position) > 0.0);
                    assert!(on_it, "{w}x{h} pixel ({i}, {j}) {up:?}: {}", s.position);
                }
            }
        }
    }
}

#[test]
fn seeds_give_unbiased_independent_estimates() {
    // integral of f = z over a map lit in the upper hemisphere
    let (w, h) = (64, 32);
    let values = (0..w * h)
        .map(|k| {
            if k / w < h / 2 {
                1.0 + (k % w) as f64 / w as f64
            } else {
                0.0
            }
        })
        .collect();
    let map = EnvMap::new(
        Raster {
            width: w,
            height: h,
            values,
            bad_pixels: 0,
        },
        Up::Z,
    )
    .unwrap();
    // exact integral of L(w) w.z over the map, pixel by pixel
    let exact: f64 = (0..h)
        .map(|j| {
            let (a, b) = (j as f64 * PI / h as f64, (j + 1) as f64 * PI / h as f64);
            let row: f64 = map.values()[j * w..(j + 1) * w].iter().sum();
            row * TAU / w as f64 * 0.5 * (b.sin().powi(2) - a.sin().powi(2))
        })
        .sum();
    let n = 1024;
    let estimates: Vec<f64> = (0..16)
        .map(|seed| {
            let m = map.with_seed(seed);
            let s = m.generate(n).unwrap();
            let pdfs = m.pdfs(&s);
            s.iter()
                .zip(&pdfs)
                .map(|(s, p)| m.radiance(s.position) * s.position.z / p)
                .sum::<f64>()
                / n as f64
        })
        .collect();
    let mean = estimates.iter().sum::<f64>() / estimates.len() as f64;
    // tiles straddling the support's edge that the average keeps place
    // their samples inside it: a small inward lean (0.2 % over 64 seeds)
    assert!((mean - exact).abs() < 0.006 * exact, "{mean} vs {exact}");
    assert!(estimates.windows(2).all(|w| w[0] != w[1]));
    // deterministic without a seed
    assert_eq!(map.generate(n).unwrap(), map.generate(n).unwrap());
}

#[test]
fn readers_accept_every_layout() {
    let dir = temp_dir("layouts");
    let (w, h) = (32, 16);
    let rgb = sky::hostile_rgb(w, h);
    let reference = read_raster(
        &{
            let p = dir.join("ref.exr");
            sky::write_exr(
                &p,
                w,
                h,
                &rgb,
                false,
                false,
                exr::prelude::Compression::Uncompressed,
            );
            p
        },
        &ReadOptions::default(),
    )
    .unwrap();
    use exr::prelude::Compression::*;
    for (k, (half, tiled, compression)) in [
        (false, true, ZIP1),
        (false, false, PIZ),
        (true, false, RLE),
        (true, true, B44),
        (true, false, B44A),
        (false, false, PXR24),
        (true, true, DWAA(None)),
        (true, false, DWAB(None)),
    ]
    .into_iter()
    .enumerate()
    {
        let p = dir.join(format!("v{k}.exr"));
        sky::write_exr(&p, w, h, &rgb, half, tiled, compression);
        let r = read_raster(&p, &ReadOptions::default()).unwrap();
        assert_eq!((r.width, r.height), (w, h));
        let lossless = matches!(compression, ZIP1 | PIZ | RLE) && !half;
        if lossless {
            assert_eq!(r, reference, "{compression:?}");
        }
        // the sun survives every codec within f16 / lossy precision
        let (si, sj) = sky::sun_pixel(w, h);
        let sun = reference.get(si, sj);
        assert!(
            (r.get(si, sj) - sun).abs() < 0.05 * sun,
            "{compression:?}: {} vs {sun}",
            r.get(si, sj)
        );
    }
    // a Y-only file, and a named channel
    let p = dir.join("y.exr");
    {
        use exr::prelude::*;
        let y = AnyChannel::new("Y", FlatSamples::F32(vec![0.0, 2.0, 3.0, -1.0]));
        let a = AnyChannel::new("A", FlatSamples::F32(vec![1.0; 4]));
        let layer = Layer::new(
            (2, 2),
            LayerAttributes::named(""),
            Encoding::default(),
            AnyChannels::sort(SmallVec::from_vec(vec![y, a])),
        );
        Image::from_layer(layer).write().to_file(&p).unwrap();
    }
    let r = read_raster(&p, &ReadOptions::default()).unwrap();
    assert_eq!(
        (r.values.clone(), r.bad_pixels),
        (vec![0.0, 2.0, 3.0, 0.0], 1)
    );
    let r = read_raster(
        &p,
        &ReadOptions {
            channel: Some("A".into()),
            ..Default::default()
        },
    )
    .unwrap();
    assert_eq!(r.values, vec![1.0; 4]);
    let e = read_raster(
        &p,
        &ReadOptions {
            channel: Some("Z".into()),
            ..Default::default()
        },
    )
    .unwrap_err();
    assert!(
        e.to_string().contains("no channel named 'Z'") && e.to_string().contains("Y"),
        "{e}"
    );
    // PNG (sRGB decoded) and Radiance .hdr through the image crate
    let png = dir.join("m.png");
    image::RgbImage::from_fn(4, 2, |x, _| image::Rgb([(x * 60) as u8, 255, 0]))
        .save(&png)
        .unwrap();
    let r = read_raster(&png, &ReadOptions::default()).unwrap();
    assert!((r.get(0, 0) - 0.7152).abs() < 1e-6 && r.get(3, 1) > r.get(0, 1));
    let hdr = dir.join("m.hdr");
    image::Rgb32FImage::from_fn(4, 2, |x, _| image::Rgb([x as f32, 1.0, 0.5]))
        .save(&hdr)
        .unwrap();
    let r = read_raster(
        &hdr,
        &ReadOptions {
            channel: Some("R".into()),
            ..Default::default()
        },
    )
    .unwrap();
    assert_eq!(r.values[..4], [0.0, 1.0, 2.0, 3.0]);
}

#[test]
fn hostile_files_give_errors_naming_them() {
    let dir = temp_dir("hostile");
    let opts = ReadOptions::default();
    let message = |p: &Path, o: &ReadOptions| {
        let e = read_raster(p, o).unwrap_err().to_string();
        assert!(e.contains(&*p.to_string_lossy()), "{e}");
        e
    };
    assert!(message(&dir.join("missing.exr"), &opts).contains("No such file"));
    let empty = dir.join("empty.exr");
    std::fs::write(&empty, b"").unwrap();
    assert!(message(&empty, &opts).contains("empty"));
    let text = dir.join("text.exr");
    std::fs::write(&text, b"hello world").unwrap();
    assert!(message(&text, &opts).contains("not an OpenEXR"));
    // truncated and corrupted copies of a real map
    let good = dir.join("good.exr");
    let (w, h) = (64, 32);
    sky::write_exr(
        &good,
        w,
        h,
        &sky::hostile_rgb(w, h),
        true,
        true,
        exr::prelude::Compression::ZIP16,
    );
    let bytes = std::fs::read(&good).unwrap();
    for cut in [4, 20, bytes.len() / 3, bytes.len() - 7] {
        let p = dir.join(format!("cut{cut}.exr"));
        std::fs::write(&p, &bytes[..cut]).unwrap();
        message(&p, &opts);
    }
    let mut rng = tessera::baselines::SplitMix64::new(5);
    for k in 0..64 {
        let mut b = bytes.clone();
        for _ in 0..1 + k % 8 {
            let at = 4 + (rng.next_u64() as usize) % (b.len() - 4);
            b[at] = rng.next_u64() as u8;
        }
        let p = dir.join(format!("corrupt{k}.exr"));
        std::fs::write(&p, &b).unwrap();
        // either an error naming the file or a map; never a panic
        if let Err(e) = read_raster(&p, &opts) {
            assert!(e.to_string().contains("corrupt"), "{e}");
        }
    }
    let png = dir.join("cut.png");
    image::RgbImage::from_pixel(16, 16, image::Rgb([9, 9, 9]))
        .save(&png)
        .unwrap();
    let b = std::fs::read(&png).unwrap();
    std::fs::write(&png, &b[..b.len() / 2]).unwrap();
    message(&png, &opts);
    // all-zero and all-invalid maps
    let zero = dir.join("zero.exr");
    sky::write_exr(
        &zero,
        8,
        4,
        &vec![[0.0; 3]; 32],
        false,
        false,
        exr::prelude::Compression::Uncompressed,
    );
    assert!(message(&zero, &opts).contains("nothing to sample"));
    let nan = dir.join("nan.exr");
    sky::write_exr(
        &nan,
        8,
        4,
        &vec![[f32::NAN, -1.0, 0.0]; 32],
        false,
        false,
        exr::prelude::Compression::Uncompressed,
    );
    assert!(message(&nan, &opts).contains("nothing to sample"));
    // --strict refuses the hostile map (its NaN), naming the pixel
    let strict = ReadOptions {
        strict: true,
        ..Default::default()
    };
    let e = message(&good, &strict);
    assert!(e.contains("is NaN") && e.contains("column"), "{e}");
}

/// `--strict` passes the negative pixels a lossy codec leaves (the
/// generated maps written as f16 DWAB) and refuses a negative pixel deeper
/// than that noise.
#[test]
fn strict_passes_codec_noise_and_refuses_damage() {
    let dir = temp_dir("strict");
    let strict = ReadOptions {
        strict: true,
        ..Default::default()
    };
    let mut noisy = 0;
    for sky in tessera::synth::Sky::all() {
        let path = dir.join(format!("{}.exr", sky.name()));
        sky.generate(512, 256, 1).write_exr(&path, true).unwrap();
        let lenient = tessera::io::image::read_raster(&path, &ReadOptions::default()).unwrap();
        noisy += usize::from(lenient.bad_pixels > 0);
        let read = tessera::io::image::read_raster(&path, &strict);
        assert!(read.is_ok(), "{}: {:?}", sky.name(), read.err());
    }
    assert!(noisy >= 5, "the codec left negatives in only {noisy} maps");
    // a dark pixel far from bright ones, at half the median: damage
    let mut map = tessera::synth::Sky::Overcast.generate(64, 32, 1);
    map.rgb[20 * 64 + 10] = [-0.5, -0.5, -0.5];
    let path = dir.join("damaged.exr");
    map.write_exr(&path, false).unwrap();
    let e = tessera::io::image::read_raster(&path, &strict)
        .expect_err("damage is refused")
        .to_string();
    assert!(
        e.contains("column 10, row 20") && e.contains("beyond codec noise"),
        "{e}"
    );
}

#[test]
fn irradiance_error_is_below_0_4_of_inverse_cdf() {
    use tessera::baselines::envmap::InverseCdf;
    use tessera::metrics::irradiance::{estimate, exact, relative_rmse};
    let dir = temp_dir("irradiance");
    let normals = tessera::baselines::spherical_fibonacci(64);
    let (n, seeds) = (4096, 8);
    for path in sky::write_issue_maps(&dir) {
        let map = EnvMap::open(&path, &ReadOptions::default(), Up::Z).unwrap();
        let reference = exact(&map, &normals);
        let rmse = |samples: &[DVec3]| {
            let e: Vec<f64> = normals
                .iter()
                .map(|&v| estimate(&map, samples, v))
                .collect();
            relative_rmse(&e, &reference)
        };
        let inverse = InverseCdf::new(&map);
        let (mut ours, mut iid) = (0.0, 0.0);
        for seed in 0..seeds {
            let m = map.with_seed(seed);
            let s: Vec<DVec3> = m.generate(n).unwrap().iter().map(|s| s.position).collect();
            ours += rmse(&s).powi(2);
            iid += rmse(&inverse.samples(n, seed)).powi(2);
        }
        let ratio = (ours / iid).sqrt();
        assert!(
            ratio <= 0.4,
            "{}: tessera / inverse-CDF relative RMSE {ratio}",
            path.display()
        );
    }
}

#[test]
fn baselines_follow_the_map() {
    use tessera::baselines::envmap::{AliasTable, InverseCdf};
    let dir = temp_dir("baselines");
    let [_, small] = sky::write_issue_maps(&dir);
    let map = EnvMap::open(&small, &ReadOptions::default(), Up::Y).unwrap();
    let expected = bin_masses(&map);
    let n = 200_000;
    for (name, samples) in [
        ("inverse-CDF", InverseCdf::new(&map).samples(n, 9)),
        ("alias", AliasTable::new(&map).samples(n, 9)),
    ] {
        assert!(
            samples.iter().all(|&d| map.radiance(d) > 0.0),
            "{name}: off the support"
        );
        let mut counts = vec![0usize; 768];
        for &d in &samples {
            counts[nside8_bin(d)] += 1;
        }
        for (bin, (&c, &e)) in counts.iter().zip(&expected).enumerate() {
            let e = e * n as f64;
            assert!(
                (c as f64 - e).abs() <= 5.0 * e.sqrt().max(1.0),
                "{name}: bin {bin} {c} vs {e:.1}"
            );
        }
    }
}

#[test]
fn command_line_samples_maps_with_pdfs() {
    let dir = temp_dir("cli");
    let [_, small] = sky::write_issue_maps(&dir);
    let map_arg = small.to_str().unwrap();
    let out = tessera(&[
        "sphere", "--map", map_arg, "-n", "500", "--format", "csv", "--report",
    ]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let stderr = String::from_utf8_lossy(&out.stderr);
    // one warning with the count, the integral, the report
    assert_eq!(stderr.matches("warning").count(), 1, "{stderr}");
    assert!(
        stderr.contains("pixel(s) treated as 0") && stderr.contains("integral"),
        "{stderr}"
    );
    assert!(stderr.contains("mesh ratio"), "{stderr}");
    let map = EnvMap::open(&small, &ReadOptions::default(), Up::Z).unwrap();
    let rows = common::csv_rows(&out.stdout);
    assert_eq!(rows.len(), 500);
    for r in &rows {
        let d = DVec3::new(r[0], r[1], r[2]);
        approx::assert_relative_eq!(r[5], map.pdf(d), max_relative = 1e-12);
        assert!(r[5] > 0.0);
    }
    // deterministic without a seed, different with one, same for the same seed
    let run = |extra: &[&str]| {
        let mut args = vec!["sphere", "--map", map_arg, "-n", "50"];
        args.extend_from_slice(extra);
        tessera(&args).stdout
    };
    assert_eq!(run(&[]), run(&[]));
    assert_eq!(run(&["--seed", "4"]), run(&["--seed", "4"]));
    assert_ne!(run(&["--seed", "4"]), run(&[]));
    // Y-up maps: the sun moves from phi = atan2(y, x) to atan2(x, z)
    let y_up = run(&["--up", "y"]);
    assert!(!y_up.is_empty() && y_up != run(&[]));
    // --strict, a non-2:1 map (warning), missing files, bad channels
    let strict = tessera(&["sphere", "--map", map_arg, "-n", "5", "--strict"]);
    assert_eq!(strict.status.code(), Some(1));
    assert!(String::from_utf8_lossy(&strict.stderr).contains(map_arg));
    let square = dir.join("square.exr");
    sky::write_exr(
        &square,
        16,
        16,
        &vec![[1.0; 3]; 256],
        false,
        false,
        exr::prelude::Compression::Uncompressed,
    );
    let out = tessera(&["sphere", "--map", square.to_str().unwrap(), "-n", "5"]);
    assert!(out.status.success());
    assert!(String::from_utf8_lossy(&out.stderr).contains("not a 2:1"));
    let out = tessera(&["sphere", "--map", "/no/such/map.exr", "-n", "5"]);
    assert_eq!(out.status.code(), Some(1));
    assert!(String::from_utf8_lossy(&out.stderr).contains("/no/such/map.exr"));
    let out = tessera(&["sphere", "--map", map_arg, "--channel", "Q", "-n", "5"]);
    assert!(String::from_utf8_lossy(&out.stderr).contains("no channel named 'Q'"));
    let out = tessera(&[
        "sphere",
        "--map",
        map_arg,
        "--density",
        "uniform",
        "-n",
        "5",
    ]);
    assert_eq!(out.status.code(), Some(2));
}

mod properties {
    use super::*;
    use proptest::prelude::*;

    /// Sparse maps: mostly zero, a few lit pixels (some huge, some tiny),
    /// and hostile values that must count as zero.
    fn sparse_map() -> impl Strategy<Value = (usize, usize, Vec<f64>)> {
        (1usize..24, 1usize..12).prop_flat_map(|(w, h)| {
            let pixel = prop_oneof![
                6 => Just(0.0),
                2 => 1e-3f64..1e3,
                1 => Just(1e30),
                1 => Just(f64::NAN),
                1 => Just(-5.0),
                1 => Just(f64::INFINITY),
            ];
            (Just(w), Just(h), proptest::collection::vec(pixel, w * h))
        })
    }

    proptest! {
        #![proptest_config(ProptestConfig { cases: 128, ..ProptestConfig::default() })]

        #[test]
        fn samples_stay_on_the_support((w, h, values) in sparse_map(), n in 1usize..300, seed in proptest::option::of(any::<u64>()), y_up in any::<bool>()) {
            let Ok(raster) = Raster::from_values("prop", w, h, values, false) else {
                return Ok(()); // nothing lit: refused, as it must be
            };
            let up = if y_up { Up::Y } else { Up::Z };
            let map = EnvMap::new(raster, up).unwrap();
            let map = seed.map_or(map.clone(), |s| map.with_seed(s));
            let samples = map.generate(n).unwrap();
            prop_assert_eq!(samples.len(), n);
            for s in &samples {
                prop_assert!(map.radiance(s.position) > 0.0, "sample off the support at {}", s.position);
                prop_assert!((s.position.length() - 1.0).abs() < 1e-9);
            }
        }

        #[test]
        fn exr_bytes_never_panic(body in proptest::collection::vec(any::<u8>(), 0..400)) {
            let dir = temp_dir("fuzz");
            let path = dir.join("fuzz.exr");
            let mut bytes = vec![0x76, 0x2f, 0x31, 0x01];
            bytes.extend(body);
            std::fs::write(&path, &bytes).unwrap();
            if let Err(e) = read_raster(&path, &ReadOptions::default()) {
                prop_assert!(e.to_string().contains("fuzz.exr"));
            }
        }
    }
}

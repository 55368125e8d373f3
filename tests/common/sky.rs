//! Synthetic hostile environment maps written with the exr crate: a sky
//! gradient, a one-pixel sun 10^5 times the sky around it, a few negative
//! pixels next to the sun and some NaN and infinite pixels.
//! Shared by tests/envmap.rs, examples/envmap.rs and benches/envmap.rs.
#![allow(dead_code)]

use exr::prelude::*;
use std::path::Path;

/// Sun brightness relative to the sky pixel it replaces.
pub const SUN_CONTRAST: f32 = 1e5;

/// Where the sun is: (column, row).
pub fn sun_pixel(width: usize, height: usize) -> (usize, usize) {
    (width * 3 / 10, height * 3 / 10)
}

/// Sky radiance (R, G, B) of pixel (i, j): brighter towards the zenith and
/// towards phi = 0, bluish.
pub fn sky_rgb(i: usize, j: usize, width: usize, height: usize) -> [f32; 3] {
    let theta = (j as f64 + 0.5) / height as f64 * std::f64::consts::PI;
    let phi = (i as f64 + 0.5) / width as f64 * std::f64::consts::TAU;
    let s = 0.05 + 0.4 * theta.cos().max(0.0) + 0.05 * (1.0 + phi.cos());
    [(0.8 * s) as f32, (0.9 * s) as f32, (1.4 * s) as f32]
}

/// Every pixel's (R, G, B) of the hostile map, row 0 first.
pub fn hostile_rgb(width: usize, height: usize) -> Vec<[f32; 3]> {
    let mut rgb: Vec<[f32; 3]> = (0..height)
        .flat_map(|j| (0..width).map(move |i| sky_rgb(i, j, width, height)))
        .collect();
    let (si, sj) = sun_pixel(width, height);
    let [r, g, b] = rgb[sj * width + si];
    let sun = SUN_CONTRAST * (0.2126 * r + 0.7152 * g + 0.0722 * b);
    rgb[sj * width + si] = [sun; 3];
    // compression ringing next to the sun
    for (di, v) in [(1usize, -3000.0f32), (2, -20.0)] {
        rgb[sj * width + si + di] = [v, v * 0.5, v];
    }
    rgb[(sj + 1) * width + si] = [-1.0, -1.0, -1.0];
    for k in 0..3 {
        rgb[(height / 2 + k) * width + width / 7] = [f32::NAN, 0.1, 0.1];
    }
    rgb[(height - 3) * width + width / 2] = [f32::INFINITY, 1.0, 1.0];
    rgb
}

/// Writes `rgb` as an EXR with channels B, G, R: f16 or f32 samples,
/// scanlines or 64x64 tiles, the given compression.
pub fn write_exr(
    path: &Path,
    width: usize,
    height: usize,
    rgb: &[[f32; 3]],
    half: bool,
    tiled: bool,
    compression: Compression,
) {
    let plane = |k: usize| -> FlatSamples {
        if half {
            FlatSamples::F16(rgb.iter().map(|p| f16::from_f32(p[k])).collect())
        } else {
            FlatSamples::F32(rgb.iter().map(|p| p[k]).collect())
        }
    };
    let channels = AnyChannels::sort(SmallVec::from_vec(vec![
        AnyChannel::new("B", plane(2)),
        AnyChannel::new("G", plane(1)),
        AnyChannel::new("R", plane(0)),
    ]));
    let blocks = if tiled {
        Blocks::Tiles(Vec2(64, 64))
    } else {
        Blocks::ScanLines
    };
    let encoding = Encoding {
        compression,
        blocks,
        line_order: LineOrder::Increasing,
    };
    let layer = Layer::new(
        (width, height),
        LayerAttributes::named("env"),
        encoding,
        channels,
    );
    Image::from_layer(layer)
        .write()
        .to_file(path)
        .expect("write the test map");
}

/// The two maps of the issue: 1024x512 f32 (ZIP, scanlines) and 512x256
/// f16 (DWAB, tiled), written into `dir`; returns their paths.
pub fn write_issue_maps(dir: &Path) -> [std::path::PathBuf; 2] {
    std::fs::create_dir_all(dir).expect("temp dir");
    let big = dir.join("sky_1024x512_f32.exr");
    write_exr(
        &big,
        1024,
        512,
        &hostile_rgb(1024, 512),
        false,
        false,
        Compression::ZIP16,
    );
    let small = dir.join("sky_512x256_f16_dwab.exr");
    write_exr(
        &small,
        512,
        256,
        &hostile_rgb(512, 256),
        true,
        true,
        Compression::DWAB(None),
    );
    [big, small]
}

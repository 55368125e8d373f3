//! Reading a map's three colour planes together with its importance
//! raster, in one decode, exactly as [`crate::io::image::read_raster`]
//! would give the importance.

use super::RgbMap;
use crate::io::image::{Raster, ReadOptions, MAX_PIXELS};
use crate::Error;
use std::path::Path;

/// A named channel of decoded samples.
struct Channel {
    name: String,
    samples: Vec<f32>,
}

/// A channel by exact name, else by its last `.`-separated part, ignoring
/// case (the rule of [`crate::io::image::read_raster`]).
fn find<'a>(channels: &'a [Channel], wanted: &str) -> Option<&'a Channel> {
    channels.iter().find(|c| c.name == wanted).or_else(|| {
        channels.iter().find(|c| {
            let short = c.name.rsplit('.').next().unwrap_or(&c.name);
            short.eq_ignore_ascii_case(wanted)
        })
    })
}

/// The sRGB electro-optical transfer function (IEC 61966-2-1).
fn srgb_to_linear(v: f64) -> f64 {
    if v <= 0.04045 {
        v / 12.92
    } else {
        ((v + 0.055) / 1.055).powf(2.4)
    }
}

fn check_size(w: usize, h: usize) -> Result<(), String> {
    if w == 0 || h == 0 {
        return Err(format!("the image is empty ({w}x{h})"));
    }
    match w.checked_mul(h) {
        Some(n) if n <= MAX_PIXELS => Ok(()),
        _ => Err(format!(
            "{w}x{h} pixels is more than the {MAX_PIXELS} this reader accepts"
        )),
    }
}

fn read_exr(path: &Path) -> Result<(usize, usize, Vec<Channel>), String> {
    use exr::prelude::*;
    // the header first: refuse absurd sizes before allocating for them
    let meta = exr::meta::MetaData::read_from_file(path, false).map_err(|e| e.to_string())?;
    let header = meta
        .headers
        .iter()
        .find(|h| !h.deep)
        .ok_or("the file holds only deep data, which has no per-pixel value")?;
    check_size(header.layer_size.width(), header.layer_size.height())?;
    let reader = read()
        .no_deep_data()
        .largest_resolution_level()
        .all_channels()
        .first_valid_layer()
        .all_attributes();
    // decode on the caller's threads: one thread asked, one thread used
    let image = if rayon::current_num_threads() == 1 {
        reader.non_parallel().from_file(path)
    } else {
        reader.from_file(path)
    }
    .map_err(|e| e.to_string())?;
    let layer = image.layer_data;
    let (w, h) = (layer.size.width(), layer.size.height());
    check_size(w, h)?;
    let mut channels = Vec::new();
    for c in layer.channel_data.list {
        let name = c.name.to_string();
        if c.sample_data.len() != w * h {
            return Err(format!(
                "channel '{name}' is subsampled ({} samples for {w}x{h} pixels), which is not supported",
                c.sample_data.len()
            ));
        }
        let samples = c.sample_data.values_as_f32().collect();
        channels.push(Channel { name, samples });
    }
    Ok((w, h, channels))
}

fn read_with_image_crate(path: &Path) -> Result<(usize, usize, Vec<Channel>, bool), String> {
    let reader = image::ImageReader::open(path)
        .and_then(|r| r.with_guessed_format())
        .map_err(|e| e.to_string())?;
    let image = reader.decode().map_err(|e| e.to_string())?;
    let (w, h) = (image.width() as usize, image.height() as usize);
    check_size(w, h)?;
    let color = image.color();
    // integer formats hold display (sRGB) values; float formats are linear
    let srgb = !matches!(color, image::ColorType::Rgb32F | image::ColorType::Rgba32F);
    let rgba = image.into_rgba32f().into_raw();
    let plane = |k: usize| rgba.iter().skip(k).step_by(4).copied().collect();
    let names: &[&str] = if color.has_color() {
        &["R", "G", "B"]
    } else {
        &["Y"]
    };
    let channels = names
        .iter()
        .enumerate()
        .map(|(k, name)| Channel {
            name: (*name).into(),
            samples: plane(k),
        })
        .collect();
    Ok((w, h, channels, srgb))
}

/// See [`super::read_rgb`].
pub(super) fn read_rgb(path: &Path, options: &ReadOptions) -> Result<(RgbMap, Raster), Error> {
    let fail = |reason: String| Error::File {
        path: path.into(),
        reason,
    };
    let mut magic = [0u8; 8];
    let head = {
        use std::io::Read;
        let mut file = std::fs::File::open(path).map_err(|source| Error::Io {
            path: path.into(),
            source,
        })?;
        let mut n = 0;
        while n < magic.len() {
            match file.read(&mut magic[n..]) {
                Ok(0) => break,
                Ok(k) => n += k,
                Err(source) => {
                    return Err(Error::Io {
                        path: path.into(),
                        source,
                    })
                }
            }
        }
        &magic[..n]
    };
    // the decoders are third-party code fed hostile bytes: a panic in one
    // becomes an error naming the file
    let guarded = |decode: &dyn Fn() -> Result<(usize, usize, Vec<Channel>, bool), String>| {
        std::panic::catch_unwind(std::panic::AssertUnwindSafe(decode))
            .unwrap_or_else(|_| Err("the decoder failed on this file".into()))
            .map_err(fail)
    };
    let (width, height, channels, srgb) = if head.starts_with(&[0x76, 0x2f, 0x31, 0x01]) {
        guarded(&|| read_exr(path).map(|(w, h, c)| (w, h, c, false)))?
    } else if head.starts_with(b"#?") || head.starts_with(b"\x89PNG") {
        guarded(&|| read_with_image_crate(path))?
    } else if head.is_empty() {
        return Err(fail("the file is empty".into()));
    } else {
        return Err(fail(
            "not an OpenEXR, Radiance .hdr or PNG file (unrecognised first bytes)".into(),
        ));
    };
    let decode = |v: f32| {
        let v = v as f64;
        if srgb && options.decode_srgb {
            srgb_to_linear(v)
        } else {
            v
        }
    };
    let names = || {
        channels
            .iter()
            .map(|c| c.name.as_str())
            .collect::<Vec<_>>()
            .join(", ")
    };
    let rgb_channels = match (
        find(&channels, "R"),
        find(&channels, "G"),
        find(&channels, "B"),
    ) {
        (Some(r), Some(g), Some(b)) => Some([r, g, b]),
        _ => None,
    };
    let grey = find(&channels, "Y");
    let wanted = match &options.channel {
        Some(wanted) => Some(find(&channels, wanted).ok_or_else(|| {
            fail(format!(
                "no channel named '{wanted}'; the file has: {}",
                names()
            ))
        })?),
        None => None,
    };
    // the colour planes: R, G, B; else grey from Y or the chosen channel
    let planes: [&Channel; 3] = match (rgb_channels, grey.or(wanted)) {
        (Some(rgb), _) => rgb,
        (None, Some(c)) => [c, c, c],
        (None, None) => {
            return Err(fail(format!(
            "no R, G, B or Y channels for luminance (the file has: {}); pick one with --channel",
            names()
        )))
        }
    };
    let values: Vec<f64> = match (wanted, rgb_channels) {
        (Some(c), _) => c.samples.iter().map(|&v| decode(v)).collect(),
        (None, Some([r, g, b])) => r
            .samples
            .iter()
            .zip(&g.samples)
            .zip(&b.samples)
            .map(|((&r, &g), &b)| {
                let (r, g, b) = (decode(r), decode(g), decode(b));
                if r.is_finite() && g.is_finite() && b.is_finite() {
                    0.2126 * r + 0.7152 * g + 0.0722 * b
                } else {
                    f64::NAN
                }
            })
            .collect(),
        (None, None) => grey
            .expect("a Y channel when there is no R, G, B")
            .samples
            .iter()
            .map(|&v| decode(v))
            .collect(),
    };
    let raster = Raster::from_values(path, width, height, values, options.strict)?;
    let mut bad = 0usize;
    let mut first_bad = None;
    let rgb: Vec<[f32; 3]> = (0..width * height)
        .map(|k| {
            std::array::from_fn(|c| {
                let v = decode(planes[c].samples[k]);
                if v.is_finite() && v >= 0.0 {
                    v as f32
                } else {
                    bad += 1;
                    first_bad.get_or_insert((k % width, k / width, c, v));
                    0.0
                }
            })
        })
        .collect();
    if let (true, Some((i, j, c, v))) = (options.strict, first_bad) {
        return Err(fail(format!(
            "{bad} colour sample(s) are negative, NaN or infinite (first: column {i}, row {j}, channel {}, value {v})",
            ["R", "G", "B"][c]
        )));
    }
    Ok((
        RgbMap {
            width,
            height,
            rgb,
            bad_samples: bad,
        },
        raster,
    ))
}

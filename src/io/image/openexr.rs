//! OpenEXR through the `exr` crate (the `exr` feature): the reader behind
//! [`super::read_raster`] and the writer behind the synthetic maps'
//! `write_exr`.

use super::{check_size, Channel, Decoded};
use std::path::Path;

/// Decodes an OpenEXR file: the first layer without deep data, at its
/// largest resolution level, every channel as f32.
pub(super) fn read(path: &Path) -> Result<Decoded, String> {
    use exr::prelude::*;
    // the header first: refuse absurd sizes before allocating for them
    let meta = exr::meta::MetaData::read_from_file(path, false).map_err(|e| e.to_string())?;
    let header = meta
        .headers
        .iter()
        .find(|h| !h.deep)
        .ok_or("the file holds only deep data, which has no per-pixel value")?;
    let (w, h) = (header.layer_size.width(), header.layer_size.height());
    check_size(w, h)?;
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
    Ok(Decoded {
        width: w,
        height: h,
        channels,
        srgb: false,
    })
}

/// Writes `rgb` (row-major, `width * height` pixels) as channels B, G, R:
/// f32 in ZIP-compressed scanlines, or with `half` f16 (clamped to +-65504)
/// in DWAB-compressed 64 x 64 tiles.
pub(crate) fn write_rgb(
    path: &Path,
    width: usize,
    height: usize,
    rgb: &[[f32; 3]],
    half: bool,
) -> Result<(), String> {
    use exr::prelude::*;
    let plane = |k: usize| -> FlatSamples {
        if half {
            let top = f16::MAX.to_f32();
            FlatSamples::F16(
                rgb.iter()
                    .map(|p| f16::from_f32(p[k].clamp(-top, top)))
                    .collect(),
            )
        } else {
            FlatSamples::F32(rgb.iter().map(|p| p[k]).collect())
        }
    };
    let channels = AnyChannels::sort(SmallVec::from_vec(vec![
        AnyChannel::new("B", plane(2)),
        AnyChannel::new("G", plane(1)),
        AnyChannel::new("R", plane(0)),
    ]));
    let encoding = if half {
        Encoding {
            compression: Compression::DWAB(None),
            blocks: Blocks::Tiles(Vec2(64, 64)),
            line_order: LineOrder::Increasing,
        }
    } else {
        Encoding {
            compression: Compression::ZIP16,
            blocks: Blocks::ScanLines,
            line_order: LineOrder::Increasing,
        }
    };
    let layer = Layer::new(
        (width, height),
        LayerAttributes::named("synth"),
        encoding,
        channels,
    );
    // the encoder is third-party code: a panic in it becomes an error
    // naming the file
    match std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| {
        Image::from_layer(layer).write().to_file(path)
    })) {
        Ok(Ok(())) => Ok(()),
        Ok(Err(e)) => Err(format!("cannot write the EXR: {e}")),
        Err(_) => Err("cannot write the EXR: the encoder failed".into()),
    }
}

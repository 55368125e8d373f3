//! Reading a map's three colour planes together with its importance
//! raster, in one decode, exactly as [`crate::io::image::read_raster`]
//! would give the importance.

use super::RgbMap;
use crate::io::image::{Channel, Decoded, Raster, ReadOptions};
use crate::Error;
use std::path::Path;

/// See [`super::read_rgb`].
pub(super) fn read_rgb(path: &Path, options: &ReadOptions) -> Result<(RgbMap, Raster), Error> {
    let fail = |reason: String| Error::File {
        path: path.into(),
        reason,
    };
    let decoded = Decoded::read(path)?;
    let (width, height) = (decoded.width, decoded.height);
    let raster = Raster::from_values(
        path,
        width,
        height,
        decoded.importance(path, options)?,
        options.strict,
    )?;
    // the colour planes: R, G, B; else grey from Y or the chosen channel
    // (the importance above has refused a file with none of them)
    let grey = decoded.find("Y");
    let wanted = options.channel.as_deref().and_then(|c| decoded.find(c));
    let planes: [&Channel; 3] = match (decoded.find("R"), decoded.find("G"), decoded.find("B")) {
        (Some(r), Some(g), Some(b)) => [r, g, b],
        _ => {
            let c = grey
                .or(wanted)
                .expect("the importance needs Y or a channel here");
            [c, c, c]
        }
    };
    let mut bad = 0usize;
    let mut first_bad = None;
    let rgb: Vec<[f32; 3]> = (0..width * height)
        .map(|k| {
            std::array::from_fn(|c| {
                let v = decoded.linear(options, planes[c].samples[k]);
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

//! PNG and Radiance `.hdr` through the `image` crate (the `image` feature):
//! the reader behind [`super::read_raster`].

use super::{check_size, Channel, Decoded};
use std::path::Path;

/// Decodes a PNG or Radiance `.hdr` file into R, G, B (or Y) and A.
pub(super) fn read(path: &Path) -> Result<Decoded, String> {
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
    let plane = |k: usize| {
        rgba.iter()
            .skip(k)
            .step_by(4)
            .copied()
            .collect::<Vec<f32>>()
    };
    let mut channels = if color.has_color() {
        vec![
            Channel {
                name: "R".into(),
                samples: plane(0),
            },
            Channel {
                name: "G".into(),
                samples: plane(1),
            },
            Channel {
                name: "B".into(),
                samples: plane(2),
            },
        ]
    } else {
        vec![Channel {
            name: "Y".into(),
            samples: plane(0),
        }]
    };
    if color.has_alpha() {
        channels.push(Channel {
            name: "A".into(),
            samples: plane(3),
        });
    }
    Ok(Decoded {
        width: w,
        height: h,
        channels,
        srgb,
    })
}

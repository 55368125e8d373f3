//! Raster readers: OpenEXR (exr crate: scanline or tiled, f16/f32/u32, any
//! channel order, every compression the crate decodes), Radiance `.hdr` and
//! PNG (image crate), reduced to one importance value per pixel.
//!
//! Importance is Rec.709 luminance `0.2126 R + 0.7152 G + 0.0722 B` by
//! default (a lone `Y` channel is used as is), or one named channel.
//! Real files are hostile: negative, NaN and infinite pixels are counted and
//! set to 0 (or refused with [`ReadOptions::strict`]); a file with nothing
//! positive is an error naming it. No input makes the reader panic.
//!
//! Each decoder is behind the feature that builds its crate (`exr`;
//! `image` for PNG and `.hdr`), both in the default features. Without one,
//! a file of its format is refused with an error naming the file and the
//! feature; [`Raster::from_values`] takes pixels from memory either way.
//!
//! ```
//! use tessera::io::image::{read_raster, ReadOptions};
//! let err = read_raster("no/such/map.exr".as_ref(), &ReadOptions::default()).unwrap_err();
//! assert!(err.to_string().contains("no/such/map.exr"));
//! ```

use crate::Error;
use std::path::Path;

#[cfg(feature = "exr")]
pub(crate) mod openexr;
#[cfg(feature = "image")]
mod png_hdr;

/// Stands in for the OpenEXR codec in a build without the `exr` feature.
#[cfg(not(feature = "exr"))]
pub(crate) mod openexr {
    use super::{missing, Decoded};
    use std::path::Path;

    pub(super) fn read(_: &Path) -> Result<Decoded, String> {
        Err(missing("an OpenEXR file", "exr"))
    }

    pub(crate) fn write_rgb(
        _: &Path,
        _: usize,
        _: usize,
        _: &[[f32; 3]],
        _: bool,
    ) -> Result<(), String> {
        Err(missing("OpenEXR output", "exr"))
    }
}

/// Stands in for the PNG and `.hdr` decoder in a build without the `image`
/// feature.
#[cfg(not(feature = "image"))]
mod png_hdr {
    use super::{missing, Decoded};
    use std::path::Path;

    pub(super) fn read(_: &Path) -> Result<Decoded, String> {
        Err(missing("a PNG or Radiance .hdr file", "image"))
    }
}

/// The reason given for a format whose codec this build left out.
#[cfg(not(all(feature = "exr", feature = "image")))]
fn missing(what: &str, feature: &str) -> String {
    format!(
        "{what}, which this build of tessera cannot read or write: it needs the `{feature}` feature (on by default)"
    )
}

/// Largest raster read (pixels): refuses headers that would allocate
/// gigabytes before any pixel is decoded.
///
/// # Example
/// ```
/// assert!(tessera::io::image::MAX_PIXELS >= 16384 * 8192);
/// ```
pub const MAX_PIXELS: usize = 1 << 28;

/// How to turn a file into importance values.
///
/// # Example
/// ```
/// let o = tessera::io::image::ReadOptions { channel: Some("R".into()), ..Default::default() };
/// assert!(!o.strict && o.decode_srgb);
/// ```
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct ReadOptions {
    /// Use this channel (e.g. `R`, `Y`, `diffuse.G`) instead of luminance.
    pub channel: Option<String>,
    /// Refuse NaN and infinite pixels, and negative ones beyond the noise
    /// a lossy codec leaves ([`Raster::from_values`]), instead of zeroing
    /// them.
    pub strict: bool,
    /// Undo the sRGB transfer curve of 8- and 16-bit PNGs (they store
    /// display values; importance should be linear). EXR and `.hdr` are
    /// linear already and are never changed.
    pub decode_srgb: bool,
}

impl Default for ReadOptions {
    fn default() -> Self {
        ReadOptions {
            channel: None,
            strict: false,
            decode_srgb: true,
        }
    }
}

/// One importance value per pixel, row 0 being the file's first (top) row.
///
/// # Example
/// ```
/// let r = tessera::io::image::Raster { width: 2, height: 1, values: vec![1.0, 0.0], bad_pixels: 0 };
/// assert_eq!(r.get(1, 0), 0.0);
/// ```
#[derive(Clone, Debug, PartialEq)]
pub struct Raster {
    /// Columns.
    pub width: usize,
    /// Rows.
    pub height: usize,
    /// Row-major values, all finite and >= 0.
    pub values: Vec<f64>,
    /// Pixels that were negative, NaN or infinite and were set to 0.
    pub bad_pixels: usize,
}

impl Raster {
    /// The value at column `i`, row `j`.
    ///
    /// # Example
    /// ```
    /// let r = tessera::io::image::Raster { width: 1, height: 2, values: vec![3.0, 4.0], bad_pixels: 0 };
    /// assert_eq!(r.get(0, 1), 4.0);
    /// ```
    pub fn get(&self, i: usize, j: usize) -> f64 {
        self.values[j * self.width + i]
    }

    /// Builds a raster from raw importance values (row-major, `width *
    /// height` of them), zeroing and counting bad ones (negative, NaN or
    /// infinite); a raster with nothing positive is refused. `name` is what
    /// errors call the data.
    ///
    /// `strict` refuses NaN and infinite pixels, and negative ones deeper
    /// than codec noise: a lossy codec (OpenEXR's DWAA/DWAB, PIZ on f16)
    /// rings around bright pixels and dithers dark areas around zero, so a
    /// negative pixel passes when its magnitude is at most
    /// [`Raster::NOISE_NEIGHBOURHOOD`] of the brightest pixel within two
    /// pixels of it, or [`Raster::NOISE_MEDIAN`] of the median positive
    /// pixel. Passing pixels are zeroed and counted like the others.
    ///
    /// # Example
    /// ```
    /// use tessera::io::image::Raster;
    /// let r = Raster::from_values("mem", 2, 1, vec![f64::NAN, 2.0], false).unwrap();
    /// assert_eq!((r.values.clone(), r.bad_pixels), (vec![0.0, 2.0], 1));
    /// assert!(Raster::from_values("mem", 2, 1, vec![f64::NAN, 2.0], true).is_err());
    /// assert!(Raster::from_values("mem", 1, 1, vec![0.0], false).is_err());
    /// ```
    pub fn from_values(
        name: impl AsRef<Path>,
        width: usize,
        height: usize,
        values: Vec<f64>,
        strict: bool,
    ) -> Result<Raster, Error> {
        let fail = |reason: String| Error::File {
            path: name.as_ref().into(),
            reason,
        };
        if width == 0 || height == 0 {
            return Err(fail(format!("the image is empty ({width}x{height})")));
        }
        if width.checked_mul(height) != Some(values.len()) {
            return Err(fail(format!(
                "{} values for a {width}x{height} image",
                values.len()
            )));
        }
        if strict {
            if let Some((k, v)) = damaged(&values, width) {
                let (i, j) = (k % width, k / width);
                return Err(fail(format!(
                    "pixel at column {i}, row {j} is {v}: NaN, infinite, or negative beyond codec noise \
                     ({} of the brightest pixel within two pixels, {} of the median positive one)",
                    Self::NOISE_NEIGHBOURHOOD,
                    Self::NOISE_MEDIAN
                )));
            }
        }
        let mut values = values;
        let mut bad_pixels = 0;
        let mut any_positive = false;
        for v in values.iter_mut() {
            if !(v.is_finite() && *v >= 0.0) {
                bad_pixels += 1;
                *v = 0.0;
            }
            any_positive |= *v > 0.0;
        }
        if !any_positive {
            return Err(fail(
                "every pixel is zero, negative or invalid: there is nothing to sample".into(),
            ));
        }
        Ok(Raster {
            width,
            height,
            values,
            bad_pixels,
        })
    }
}

impl Raster {
    /// A negative pixel within this fraction of the brightest pixel two
    /// pixels around it is codec ringing ([`Raster::from_values`]).
    ///
    /// # Example
    /// ```
    /// use tessera::io::image::Raster;
    /// // ringing beside a bright pixel passes --strict
    /// let v = vec![1.0, 1.0, 100.0, -4.0, 1.0, 1.0];
    /// assert!(Raster::from_values("mem", 6, 1, v, true).is_ok());
    /// assert!(Raster::NOISE_NEIGHBOURHOOD * 100.0 >= 4.0);
    /// ```
    pub const NOISE_NEIGHBOURHOOD: f64 = 0.05;
    /// A negative pixel within this fraction of the median positive pixel
    /// is codec noise around zero ([`Raster::from_values`]).
    ///
    /// # Example
    /// ```
    /// use tessera::io::image::Raster;
    /// // far from bright pixels, half the median is damage
    /// let v = vec![1.0, 1.0, 1.0, 1.0, 1.0, -0.5, 1.0, 1.0];
    /// assert!(Raster::from_values("mem", 8, 1, v, true).is_err());
    /// assert!(Raster::NOISE_MEDIAN < 0.5);
    /// ```
    pub const NOISE_MEDIAN: f64 = 0.01;
}

/// The first pixel `strict` refuses (see [`Raster::from_values`]), with its
/// value.
fn damaged(values: &[f64], width: usize) -> Option<(usize, f64)> {
    if let Some(k) = values.iter().position(|v| !v.is_finite()) {
        return Some((k, values[k]));
    }
    let mut positive: Vec<f64> = values.iter().copied().filter(|&v| v > 0.0).collect();
    let median = if positive.is_empty() {
        0.0
    } else {
        let mid = positive.len() / 2;
        *positive.select_nth_unstable_by(mid, f64::total_cmp).1
    };
    let height = values.len() / width;
    values.iter().enumerate().find_map(|(k, &v)| {
        if v >= 0.0 || -v <= Raster::NOISE_MEDIAN * median {
            return None;
        }
        let (i, j) = (k % width, k / width);
        let mut brightest: f64 = 0.0;
        for jj in j.saturating_sub(2)..(j + 3).min(height) {
            for ii in i.saturating_sub(2)..(i + 3).min(width) {
                brightest = brightest.max(values[jj * width + ii]);
            }
        }
        (-v > Raster::NOISE_NEIGHBOURHOOD * brightest).then_some((k, v))
    })
}

/// A named channel of decoded samples.
pub(crate) struct Channel {
    pub(crate) name: String,
    pub(crate) samples: Vec<f32>,
}

/// An image file's channels as its decoder gave them: what both the
/// importance ([`read_raster`]) and the colour of lights read.
pub(crate) struct Decoded {
    pub(crate) width: usize,
    pub(crate) height: usize,
    pub(crate) channels: Vec<Channel>,
    /// Integer formats hold display (sRGB) values; float formats are linear.
    srgb: bool,
}

impl Decoded {
    /// Decodes an EXR, Radiance `.hdr` or PNG file, recognised by its first
    /// bytes, not its name.
    pub(crate) fn read(path: &Path) -> Result<Decoded, Error> {
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
        // the decoders are third-party code fed hostile bytes: a panic in
        // one becomes an error naming the file
        let guarded = |decode: &dyn Fn() -> Result<Decoded, String>| {
            std::panic::catch_unwind(std::panic::AssertUnwindSafe(decode))
                .unwrap_or_else(|_| Err("the decoder failed on this file".into()))
                .map_err(fail)
        };
        if head.starts_with(&[0x76, 0x2f, 0x31, 0x01]) {
            guarded(&|| openexr::read(path))
        } else if head.starts_with(b"#?") || head.starts_with(b"\x89PNG") {
            guarded(&|| png_hdr::read(path))
        } else if head.is_empty() {
            Err(fail("the file is empty".into()))
        } else {
            Err(fail(
                "not an OpenEXR, Radiance .hdr or PNG file (unrecognised first bytes)".into(),
            ))
        }
    }

    /// A channel by exact name, else by its last `.`-separated part,
    /// ignoring case.
    pub(crate) fn find(&self, wanted: &str) -> Option<&Channel> {
        let channels = &self.channels;
        channels.iter().find(|c| c.name == wanted).or_else(|| {
            channels.iter().find(|c| {
                let short = c.name.rsplit('.').next().unwrap_or(&c.name);
                short.eq_ignore_ascii_case(wanted)
            })
        })
    }

    /// A sample as a linear value (sRGB decoded when the format holds
    /// display values and `options` asks for it).
    pub(crate) fn linear(&self, options: &ReadOptions, v: f32) -> f64 {
        let v = v as f64;
        if self.srgb && options.decode_srgb {
            srgb_to_linear(v)
        } else {
            v
        }
    }

    /// The channel names, for messages.
    fn names(&self) -> String {
        let names: Vec<&str> = self.channels.iter().map(|c| c.name.as_str()).collect();
        names.join(", ")
    }

    /// The importance per pixel: `options.channel`, else Rec.709 luminance
    /// of R, G and B, else Y (NaN where a colour sample is not finite).
    pub(crate) fn importance(&self, path: &Path, options: &ReadOptions) -> Result<Vec<f64>, Error> {
        let fail = |reason: String| Error::File {
            path: path.into(),
            reason,
        };
        let decode = |v: f32| self.linear(options, v);
        if let Some(wanted) = &options.channel {
            let channel = self.find(wanted).ok_or_else(|| {
                fail(format!(
                    "no channel named '{wanted}'; the file has: {}",
                    self.names()
                ))
            })?;
            return Ok(channel.samples.iter().map(|&v| decode(v)).collect());
        }
        match (self.find("R"), self.find("G"), self.find("B"), self.find("Y")) {
            (Some(r), Some(g), Some(b), _) => Ok(r
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
                .collect()),
            (_, _, _, Some(y)) => Ok(y.samples.iter().map(|&v| decode(v)).collect()),
            _ => Err(fail(format!(
                "no R, G, B or Y channels for luminance (the file has: {}); pick one with --channel",
                self.names()
            ))),
        }
    }
}

/// Reads an EXR, Radiance `.hdr` or PNG file (recognised by its first
/// bytes, not its name) into importance values.
///
/// # Example
/// ```
/// use tessera::io::image::{read_raster, ReadOptions};
/// let dir = std::env::temp_dir().join("tessera-doc-read-raster");
/// std::fs::create_dir_all(&dir).unwrap();
/// let path = dir.join("two.exr");
/// exr::prelude::write_rgb_file(&path, 2, 1, |x, _| (x as f32, 1.0f32, 0.0f32)).unwrap();
/// let r = read_raster(&path, &ReadOptions::default()).unwrap();
/// assert!((r.get(1, 0) - (0.2126 + 0.7152)).abs() < 1e-6);
/// ```
pub fn read_raster(path: &Path, options: &ReadOptions) -> Result<Raster, Error> {
    let decoded = Decoded::read(path)?;
    let values = decoded.importance(path, options)?;
    Raster::from_values(path, decoded.width, decoded.height, values, options.strict)
}

/// The sRGB electro-optical transfer function (IEC 61966-2-1).
fn srgb_to_linear(v: f64) -> f64 {
    if v <= 0.04045 {
        v / 12.92
    } else {
        ((v + 0.055) / 1.055).powf(2.4)
    }
}

/// Refuses empty images and ones over [`MAX_PIXELS`] (the decoders call it
/// before they allocate).
#[cfg(any(feature = "exr", feature = "image"))]
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

/// Run with `cargo test --no-default-features --lib io::image`: the
/// default build has both codecs.
#[cfg(all(test, not(all(feature = "exr", feature = "image"))))]
mod tests {
    use super::{read_raster, ReadOptions};

    /// A file in a format whose codec was left out is refused with an
    /// error naming the file and the feature (not a panic, not "unknown
    /// format").
    #[test]
    fn missing_codec_names_file_and_feature() {
        let dir =
            std::env::temp_dir().join(format!("tessera-missing-codec-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let files: [(&str, &[u8], &str); 3] = [
            ("a.exr", &[0x76, 0x2f, 0x31, 0x01, 2, 0, 0, 0], "exr"),
            ("b.png", b"\x89PNG\r\n\x1a\n", "image"),
            ("c.hdr", b"#?RADIANCE\n", "image"),
        ];
        let built = |feature: &str| match feature {
            "exr" => cfg!(feature = "exr"),
            _ => cfg!(feature = "image"),
        };
        for (name, bytes, feature) in files.into_iter().filter(|f| !built(f.2)) {
            let path = dir.join(name);
            std::fs::write(&path, bytes).unwrap();
            let e = read_raster(&path, &ReadOptions::default()).unwrap_err();
            let e = e.to_string();
            assert!(
                e.contains(name) && e.contains(&format!("`{feature}` feature")),
                "{e}"
            );
        }
        std::fs::remove_dir_all(&dir).unwrap();
    }
}

//! Writing and reading point sets.
//!
//! Text: one point per line, coordinates separated by spaces (UTK text).
//! Binary (UTK): a 20-byte header — magic `0x214B5455` (little-endian),
//! type byte 5 (f64) and three zero bytes, `u32` number of sets (1), `u32`
//! point count, `u32` dimensions — then little-endian f64 values.

use crate::blocks::{Blocks, IterBlocks};
use crate::Error;
use glam::DVec3;
use std::io::{Read, Write};
use std::path::Path;

/// Magic number opening a UTK binary point file.
pub const UTK_MAGIC: u32 = 0x214B_5455;
const UTK_F64: u8 = 5;

/// How sphere samples are written.
///
/// # Example
/// ```
/// use tessera::io::points::SphereFormat;
/// assert_eq!("lonlat".parse::<SphereFormat>().unwrap(), SphereFormat::LonLat);
/// assert!("nope".parse::<SphereFormat>().is_err());
/// ```
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum SphereFormat {
    /// `x y z` unit vectors, Z up.
    Xyz,
    /// `lon lat` in degrees, lon in [-180, 180), lat in [-90, 90].
    LonLat,
    /// CSV with a header `x,y,z,lon,lat,pdf`.
    Csv,
    /// GeoJSON (RFC 7946): a FeatureCollection of Points `[lon, lat]` in
    /// degrees, each with a `pdf` property.
    GeoJson,
    /// UTK binary, 3 dimensions.
    Bin,
}

impl std::str::FromStr for SphereFormat {
    type Err = Error;
    fn from_str(s: &str) -> Result<Self, Error> {
        match s {
            "xyz" | "txt" => Ok(SphereFormat::Xyz),
            "lonlat" => Ok(SphereFormat::LonLat),
            "csv" => Ok(SphereFormat::Csv),
            "geojson" => Ok(SphereFormat::GeoJson),
            "bin" => Ok(SphereFormat::Bin),
            other => Err(Error::Request(format!(
                "unknown format '{other}'; expected xyz (or txt), lonlat, csv, geojson or bin"
            ))),
        }
    }
}

/// Writes the UTK binary header for `points` points of `dims` dimensions.
///
/// # Example
/// ```
/// let mut out = Vec::new();
/// tessera::io::points::write_utk_header(&mut out, 4, 3).unwrap();
/// assert_eq!(out.len(), 20);
/// assert_eq!(&out[..4], &0x214B5455u32.to_le_bytes());
/// ```
pub fn write_utk_header(out: &mut impl Write, points: usize, dims: usize) -> std::io::Result<()> {
    let count = u32::try_from(points)
        .map_err(|_| std::io::Error::other("UTK binary holds at most 2^32-1 points"))?;
    out.write_all(&UTK_MAGIC.to_le_bytes())?;
    out.write_all(&[UTK_F64, 0, 0, 0])?;
    out.write_all(&1u32.to_le_bytes())?;
    out.write_all(&count.to_le_bytes())?;
    out.write_all(&(dims as u32).to_le_bytes())
}

/// Writes UTK binary's body: each point's `D` coordinates as little-endian
/// f64, a block at a time through a fixed buffer of 4096 points filled
/// without bounds or capacity checks, so that a point costs its copies.
fn write_utk_values<P, const D: usize>(
    out: &mut impl Write,
    points: &mut dyn Blocks<P>,
    coordinates: impl Fn(&P) -> [f64; D],
) -> std::io::Result<()> {
    let mut buffer = vec![0u8; 4096 * 8 * D];
    points.try_for_each_block(&mut |block| {
        for chunk in block.chunks(4096) {
            let bytes = &mut buffer[..chunk.len() * 8 * D];
            for (slot, point) in bytes.chunks_exact_mut(8 * D).zip(chunk) {
                for (bytes, v) in slot.chunks_exact_mut(8).zip(coordinates(point)) {
                    bytes.copy_from_slice(&v.to_le_bytes());
                }
            }
            out.write_all(bytes)?;
        }
        Ok(())
    })
}

/// Writes text lines, one a point, a block at a time.
fn write_lines<P>(
    out: &mut impl Write,
    points: &mut dyn Blocks<P>,
    mut line: impl FnMut(&mut dyn Write, &P) -> std::io::Result<()>,
) -> std::io::Result<()> {
    points.try_for_each_block(&mut |block| block.iter().try_for_each(|p| line(out, p)))
}

/// Writes sphere points in the given format; `pdf` is asked only for CSV
/// and GeoJSON. A `lonlat` file starts with a `# lon lat (degrees)` line,
/// which tells readers it from a planar `x y` file.
///
/// # Example
/// ```
/// use tessera::io::points::{write_sphere, SphereFormat};
/// let mut out = Vec::new();
/// write_sphere(&mut out, [glam::DVec3::Z], SphereFormat::LonLat, |_| 0.0).unwrap();
/// assert_eq!(String::from_utf8(out).unwrap(), "# lon lat (degrees)\n0 90\n");
/// ```
pub fn write_sphere<I>(
    out: &mut impl Write,
    points: I,
    format: SphereFormat,
    pdf: impl Fn(DVec3) -> f64,
) -> std::io::Result<()>
where
    I: IntoIterator<Item = DVec3>,
    I::IntoIter: ExactSizeIterator,
{
    write_sphere_blocks(out, &mut IterBlocks::new(points), format, pdf)
}

/// [`write_sphere`] of points handed on a block at a time (how the
/// command line writes a stream).
///
/// # Example
/// ```
/// use tessera::{blocks::IterBlocks, io::points::{write_sphere_blocks, SphereFormat}};
/// let mut out = Vec::new();
/// let mut points = IterBlocks::new([glam::DVec3::X, glam::DVec3::Z]);
/// write_sphere_blocks(&mut out, &mut points, SphereFormat::Bin, |_| 0.0).unwrap();
/// assert_eq!(out.len(), 20 + 2 * 24);
/// ```
pub fn write_sphere_blocks(
    out: &mut impl Write,
    points: &mut dyn Blocks<DVec3>,
    format: SphereFormat,
    pdf: impl Fn(DVec3) -> f64,
) -> std::io::Result<()> {
    match format {
        SphereFormat::Xyz => write_lines(out, points, |out, p| {
            writeln!(out, "{} {} {}", p.x, p.y, p.z)
        }),
        SphereFormat::LonLat => {
            // the header tells a lon/lat file from a planar `x y` one
            writeln!(out, "{LONLAT_HEADER}")?;
            write_lines(out, points, |out, &p| {
                let (lon, lat) = crate::healpix::lonlat_deg(p);
                writeln!(out, "{lon} {lat}")
            })
        }
        SphereFormat::Csv => {
            writeln!(out, "x,y,z,lon,lat,pdf")?;
            write_lines(out, points, |out, &p| {
                let (lon, lat) = crate::healpix::lonlat_deg(p);
                writeln!(out, "{},{},{},{lon},{lat},{}", p.x, p.y, p.z, pdf(p))
            })
        }
        SphereFormat::GeoJson => {
            write!(out, "{{\"type\":\"FeatureCollection\",\"features\":[")?;
            let mut sep = "";
            write_lines(out, points, |out, &p| {
                let (lon, lat) = crate::healpix::lonlat_deg(p);
                write!(
                    out,
                    "{sep}\n{{\"type\":\"Feature\",\"geometry\":{{\"type\":\"Point\",\"coordinates\":[{lon},{lat}]}},\"properties\":{{\"pdf\":{}}}}}",
                    json_number(pdf(p))
                )?;
                sep = ",";
                Ok(())
            })?;
            writeln!(out, "\n]}}")
        }
        SphereFormat::Bin => {
            write_utk_header(out, points.len(), 3)?;
            write_utk_values(out, points, |p| [p.x, p.y, p.z])
        }
    }
}

/// A number as JSON has it: non-finite values become `null`.
fn json_number(v: f64) -> String {
    if v.is_finite() {
        v.to_string()
    } else {
        "null".into()
    }
}

/// Unit vectors of the Point and MultiPoint coordinates of a GeoJSON text
/// (a FeatureCollection, a Feature or a bare geometry).
fn read_geojson(bytes: &[u8]) -> Result<Vec<Vec<f64>>, String> {
    let value: serde_json::Value =
        serde_json::from_slice(bytes).map_err(|e| format!("not valid JSON: {e}"))?;
    let mut out = Vec::new();
    let mut stack = vec![&value];
    while let Some(v) = stack.pop() {
        match v.get("type").and_then(|t| t.as_str()) {
            Some("FeatureCollection") => {
                let features = v.get("features").and_then(|f| f.as_array());
                stack.extend(features.into_iter().flatten().rev());
            }
            Some("Feature") => stack.extend(v.get("geometry")),
            Some("Point") => out.push(v.get("coordinates")),
            Some("MultiPoint") => {
                let c = v.get("coordinates").and_then(|c| c.as_array());
                out.extend(c.into_iter().flatten().map(Some));
            }
            other => {
                return Err(format!(
                    "unsupported GeoJSON object {other:?}; expected Points"
                ))
            }
        }
    }
    out.into_iter()
        .map(|c| {
            let pair = c
                .and_then(|c| c.as_array())
                .map(|a| a.iter().map(|x| x.as_f64()).collect::<Option<Vec<f64>>>());
            match pair {
                Some(Some(v)) if v.len() >= 2 && v[1].abs() <= 90.0 && v[0].is_finite() => {
                    let p = crate::healpix::lonlat_to_vec(v[0], v[1]);
                    Ok(vec![p.x, p.y, p.z])
                }
                _ => Err("a Point's coordinates are not [lon, lat] in degrees".to_string()),
            }
        })
        .collect()
}

/// Reads a point set written by tessera: UTK binary (detected by its magic)
/// GeoJSON Points (detected by a leading `{`; sphere points only), or text
/// with `dims` numbers per line (blank lines and `#` comments skipped,
/// commas or blanks between values; a CSV header names the `x`, `y`
/// (and `z`) columns; sphere points may be `lon lat` lines after the
/// header line `tessera sphere --format lonlat` writes). Refuses a file
/// it cannot read, one that holds no points, plane points read as sphere
/// points (not unit vectors) and the reverse (too many values), naming
/// the line.
///
/// # Example
/// ```
/// let pts = tessera::io::points::read_points_from(&b"1 0 0\n0 1 0\n"[..], 3, "mem").unwrap();
/// assert_eq!(pts, vec![vec![1.0, 0.0, 0.0], vec![0.0, 1.0, 0.0]]);
/// ```
pub fn read_points_from(
    mut input: impl Read,
    dims: usize,
    name: &str,
) -> Result<Vec<Vec<f64>>, Error> {
    let fail = |reason: String| Error::File {
        path: name.into(),
        reason,
    };
    let mut bytes = Vec::new();
    input
        .read_to_end(&mut bytes)
        .map_err(|e| fail(format!("cannot read: {e}")))?;
    if bytes.len() >= 4 && bytes[..4] == UTK_MAGIC.to_le_bytes() {
        if bytes.len() < 20 || bytes[4] != UTK_F64 {
            return Err(fail("UTK binary header is truncated or not f64".into()));
        }
        let word = |at: usize| {
            u32::from_le_bytes([bytes[at], bytes[at + 1], bytes[at + 2], bytes[at + 3]]) as usize
        };
        let (count, file_dims) = (word(12), word(16));
        if file_dims != dims {
            return Err(fail(format!(
                "holds {file_dims}-dimensional points, expected {dims}"
            )));
        }
        let body = &bytes[20..];
        if Some(body.len()) != count.checked_mul(dims * 8) {
            return Err(fail(format!(
                "header announces {count} points but the file holds {} bytes of data",
                body.len()
            )));
        }
        let points: Vec<Vec<f64>> = body
            .chunks_exact(dims * 8)
            .map(|p| {
                p.chunks_exact(8)
                    .map(|b| f64::from_le_bytes(b.try_into().expect("8-byte chunk")))
                    .collect()
            })
            .collect();
        check_points(&points, dims).map_err(fail)?;
        return Ok(points);
    }
    if bytes.trim_ascii_start().starts_with(b"{") {
        if dims != 3 {
            return Err(fail("GeoJSON holds sphere points, not plane points".into()));
        }
        let points = read_geojson(&bytes).map_err(fail)?;
        check_points(&points, dims).map_err(fail)?;
        return Ok(points);
    }
    let points = read_text(&bytes, dims).map_err(fail)?;
    check_points(&points, dims).map_err(fail)?;
    Ok(points)
}

/// The first line of a `lonlat` file.
const LONLAT_HEADER: &str = "# lon lat (degrees)";

/// Text points: `dims` numbers a line, or for the sphere `lon lat` lines
/// after [`LONLAT_HEADER`]; a CSV header names its columns (`x,y[,z],...`).
fn read_text(bytes: &[u8], dims: usize) -> Result<Vec<Vec<f64>>, String> {
    let text =
        std::str::from_utf8(bytes).map_err(|_| "is not text, UTK binary or GeoJSON".to_string())?;
    let mut points = Vec::new();
    let mut lonlat = false;
    // the columns holding the coordinates (from a CSV header)
    let mut columns: Option<Vec<usize>> = None;
    let mut width: Option<usize> = None;
    for (number, line) in text.lines().enumerate() {
        let line = line.trim();
        if line == LONLAT_HEADER && points.is_empty() {
            if dims != 3 {
                return Err("is a lon/lat file of sphere points, not plane points".into());
            }
            lonlat = true;
            continue;
        }
        if line.is_empty() || line.starts_with('#') {
            continue;
        }
        let fields: Vec<&str> = line
            .split(|c: char| c == ',' || c.is_whitespace())
            .filter(|s| !s.is_empty())
            .collect();
        let values: Result<Vec<f64>, _> = fields.iter().map(|f| f.parse::<f64>()).collect();
        let Ok(values) = values else {
            if points.is_empty() && columns.is_none() && width.is_none() && line.contains(',') {
                columns = Some(csv_columns(&fields, dims)?);
                continue;
            }
            return Err(format!("line {}: not a list of numbers", number + 1));
        };
        let wanted = if lonlat { 2 } else { dims };
        let count = values.len();
        if *width.get_or_insert(count) != count {
            return Err(format!(
                "line {}: {count} values, where the lines above hold {}",
                number + 1,
                width.unwrap_or(0)
            ));
        }
        let row: Vec<f64> = match &columns {
            Some(cols) if cols.iter().all(|&c| c < values.len()) => {
                cols.iter().map(|&c| values[c]).collect()
            }
            Some(_) => {
                return Err(format!(
                    "line {}: fewer values than the header's columns",
                    number + 1
                ))
            }
            None if values.len() == wanted => values,
            None => {
                let hint = match (dims, values.len()) {
                    (2, 3) => " (is it a file of sphere points?)",
                    (3, 2) => " (a lon/lat file starts with the line '# lon lat (degrees)'; is it a file of plane points?)",
                    _ => "",
                };
                return Err(format!(
                    "line {}: {} values, expected {wanted}{hint}",
                    number + 1,
                    values.len()
                ));
            }
        };
        if lonlat {
            let (lon, lat) = (row[0], row[1]);
            if !(lon.is_finite() && lat.abs() <= 90.0) {
                return Err(format!(
                    "line {}: ({lon}, {lat}) is not a longitude and latitude in degrees",
                    number + 1
                ));
            }
            let v = crate::healpix::lonlat_to_vec(lon, lat);
            points.push(vec![v.x, v.y, v.z]);
        } else {
            points.push(row);
        }
    }
    Ok(points)
}

/// The coordinate columns a CSV header names: `x`, `y` and, for the
/// sphere, `z`.
fn csv_columns(names: &[&str], dims: usize) -> Result<Vec<usize>, String> {
    let find = |name: &str| names.iter().position(|n| n.eq_ignore_ascii_case(name));
    let wanted: &[&str] = if dims == 3 {
        &["x", "y", "z"]
    } else {
        &["x", "y"]
    };
    let columns: Option<Vec<usize>> = wanted.iter().map(|n| find(n)).collect();
    match columns {
        Some(c) => {
            if dims == 2 && find("z").is_some() {
                return Err(
                    "its CSV header has a z column: a file of sphere points, not plane points"
                        .into(),
                );
            }
            Ok(c)
        }
        None => Err(format!(
            "its CSV header '{}' does not name the columns {}",
            names.join(","),
            wanted.join(",")
        )),
    }
}

/// Refuses an empty set, and sphere points off the unit sphere (a planar
/// file read as a sphere one).
fn check_points(points: &[Vec<f64>], dims: usize) -> Result<(), String> {
    if points.is_empty() {
        return Err("holds no points".into());
    }
    for (k, p) in points.iter().enumerate() {
        if p.iter().any(|v| !v.is_finite()) {
            return Err(format!("point {}: {p:?} is not finite", k + 1));
        }
        if dims == 3 {
            let norm = (p[0] * p[0] + p[1] * p[1] + p[2] * p[2]).sqrt();
            if (norm - 1.0).abs() > 1e-6 {
                return Err(format!("point {}: {p:?} is not a unit vector (length {norm}); is it a file of plane points?", k + 1));
            }
        }
    }
    Ok(())
}

/// Reads a point file from disk (see [`read_points_from`]).
///
/// # Example
/// ```
/// assert!(tessera::io::points::read_points(std::path::Path::new("/no/such/file"), 3).is_err());
/// ```
pub fn read_points(path: &Path, dims: usize) -> Result<Vec<Vec<f64>>, Error> {
    let file = std::fs::File::open(path).map_err(|source| Error::Io {
        path: path.into(),
        source,
    })?;
    read_points_from(
        std::io::BufReader::new(file),
        dims,
        &path.display().to_string(),
    )
}

/// How planar samples are written.
///
/// # Example
/// ```
/// use tessera::io::points::PlaneFormat;
/// assert_eq!("bin".parse::<PlaneFormat>().unwrap(), PlaneFormat::Bin);
/// assert!("xyz".parse::<PlaneFormat>().is_err());
/// ```
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum PlaneFormat {
    /// `x y` per line (UTK text).
    Txt,
    /// UTK binary, 2 dimensions.
    Bin,
    /// `x,y,pdf` with a header line: the pdf per unit area of the domain.
    Csv,
}

impl std::str::FromStr for PlaneFormat {
    type Err = Error;
    fn from_str(s: &str) -> Result<Self, Error> {
        match s {
            "xy" | "txt" => Ok(PlaneFormat::Txt),
            "bin" => Ok(PlaneFormat::Bin),
            "csv" => Ok(PlaneFormat::Csv),
            other => Err(Error::Request(format!(
                "unknown planar format '{other}'; expected xy (or txt), bin or csv"
            ))),
        }
    }
}

/// Writes planar points in the given format; `pdf` is asked only for the
/// formats that carry it.
///
/// # Example
/// ```
/// use tessera::io::points::{write_plane, PlaneFormat};
/// let mut out = Vec::new();
/// write_plane(&mut out, [glam::DVec2::new(0.5, 0.25)], PlaneFormat::Csv, |_| 1.0).unwrap();
/// assert_eq!(String::from_utf8(out).unwrap(), "x,y,pdf\n0.5,0.25,1\n");
/// ```
pub fn write_plane<I>(
    out: &mut impl Write,
    points: I,
    format: PlaneFormat,
    pdf: impl Fn(glam::DVec2) -> f64,
) -> std::io::Result<()>
where
    I: IntoIterator<Item = glam::DVec2>,
    I::IntoIter: ExactSizeIterator,
{
    write_plane_blocks(out, &mut IterBlocks::new(points), format, pdf)
}

/// [`write_plane`] of points handed on a block at a time (how the command
/// line writes a stream).
///
/// # Example
/// ```
/// use tessera::{blocks::IterBlocks, io::points::{write_plane_blocks, PlaneFormat}};
/// let mut out = Vec::new();
/// let mut points = IterBlocks::new([glam::DVec2::new(0.5, 0.25)]);
/// write_plane_blocks(&mut out, &mut points, PlaneFormat::Txt, |_| 1.0).unwrap();
/// assert_eq!(String::from_utf8(out).unwrap(), "0.5 0.25\n");
/// ```
pub fn write_plane_blocks(
    out: &mut impl Write,
    points: &mut dyn Blocks<glam::DVec2>,
    format: PlaneFormat,
    pdf: impl Fn(glam::DVec2) -> f64,
) -> std::io::Result<()> {
    match format {
        PlaneFormat::Txt => write_lines(out, points, |out, p| writeln!(out, "{} {}", p.x, p.y)),
        PlaneFormat::Csv => {
            writeln!(out, "x,y,pdf")?;
            write_lines(out, points, |out, &p| {
                writeln!(out, "{},{},{}", p.x, p.y, pdf(p))
            })
        }
        PlaneFormat::Bin => {
            write_utk_header(out, points.len(), 2)?;
            write_utk_values(out, points, |p| [p.x, p.y])
        }
    }
}

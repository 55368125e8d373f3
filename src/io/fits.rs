//! HEALPix maps in FITS files: the binary-table layout healpy, the HEALPix
//! libraries and most surveys write, read without a C library.
//!
//! The map is the first `BINTABLE` extension. Its header (or the primary
//! header) gives `ORDERING` (`RING` or `NESTED`), `NSIDE` (a power of
//! two) and, if present, `COORDSYS`; `INDXSCHM = 'EXPLICIT'` (or `OBJECT =
//! 'PARTIAL'`) marks a partial-sky map whose first column, `PIXEL`, lists
//! the pixels the other columns give. Columns may hold several values a row
//! (healpy writes rows of 1024) of types `B`, `I`, `J`, `K`, `E` or `D`,
//! with `TSCALn` / `TZEROn` applied. Pixels a partial-sky map does not list
//! are [`UNSEEN`], and so are values equal to the header's `BAD_DATA`.
//! Every problem is an [`Error::File`] naming the file and the keyword or
//! column at fault; no input panics.
//!
//! ```
//! use tessera::io::fits::read_healpix;
//! let err = read_healpix("no/such/map.fits".as_ref(), 0).unwrap_err();
//! assert!(err.to_string().contains("no/such/map.fits"));
//! ```

use crate::healpix::Scheme;
use crate::Error;
use std::path::Path;

pub use crate::healpix::UNSEEN;

/// FITS files come in blocks of this many bytes; a header card is 80.
const BLOCK: usize = 2880;
const CARD: usize = 80;

/// The largest `NSIDE` read: 12 x 8192^2 = 805,306,368 pixels (6.4 GB as
/// f64), beyond which a partial-sky file of a few pixels could ask for
/// more memory than any machine has.
///
/// # Example
/// ```
/// assert_eq!(tessera::io::fits::MAX_NSIDE, 8192);
/// ```
pub const MAX_NSIDE: u64 = 1 << 13;

/// A HEALPix map read from a FITS file: the values of one column, in the
/// file's ordering, full sky.
///
/// # Example
/// ```
/// use tessera::{healpix::Scheme, io::fits::HealpixFits};
/// let m = HealpixFits { values: vec![1.0; 12], scheme: Scheme::Ring, nside: 1,
///     coordsys: Some("G".into()), column: "TEMPERATURE".into(), listed: None };
/// assert_eq!(m.values.len() as u64, 12 * m.nside * m.nside);
/// ```
#[derive(Clone, Debug, PartialEq)]
pub struct HealpixFits {
    /// `12 nside^2` values in `scheme` order; [`UNSEEN`] where the file
    /// has no data.
    pub values: Vec<f64>,
    /// `ORDERING`.
    pub scheme: Scheme,
    /// `NSIDE`.
    pub nside: u64,
    /// `COORDSYS` (`C` celestial, `G` galactic, `E` ecliptic), if given:
    /// the frame sample directions are in.
    pub coordsys: Option<String>,
    /// The name (`TTYPEn`) of the column read, or `column N`.
    pub column: String,
    /// For a partial-sky map, how many pixels it lists.
    pub listed: Option<usize>,
}

/// A header: its cards as (keyword, value) pairs, values unparsed.
struct Header(Vec<(String, String)>);

impl Header {
    fn get(&self, key: &str) -> Option<&str> {
        self.0
            .iter()
            .find(|(k, _)| k == key)
            .map(|(_, v)| v.as_str())
    }

    /// A string value, unquoted (`''` is a quote) and right-trimmed.
    fn string(&self, key: &str) -> Option<String> {
        let v = self.get(key)?.trim();
        let inner = v.strip_prefix('\'')?;
        let end = quoted_end(inner)?;
        Some(inner[..end].replace("''", "'").trim_end().to_string())
    }

    fn number(&self, key: &str) -> Option<f64> {
        self.get(key)?.trim().replace(['D', 'd'], "E").parse().ok()
    }

    fn integer(&self, key: &str) -> Option<i64> {
        self.get(key)?.trim().parse().ok()
    }
}

/// The byte offset of the closing quote in a string value after its
/// opening quote (`''` inside is an escaped quote).
fn quoted_end(s: &str) -> Option<usize> {
    let bytes = s.as_bytes();
    let mut k = 0;
    while k < bytes.len() {
        if bytes[k] == b'\'' {
            if bytes.get(k + 1) == Some(&b'\'') {
                k += 2;
                continue;
            }
            return Some(k);
        }
        k += 1;
    }
    None
}

/// The header starting at `start`, and where its data starts.
fn header_at(data: &[u8], start: usize) -> Result<(Header, usize), String> {
    let mut cards = Vec::new();
    let mut at = start;
    loop {
        let Some(card) = data.get(at..at + CARD) else {
            return Err(format!(
                "the header starting at byte {start} has no END card"
            ));
        };
        at += CARD;
        // ASCII only (FITS headers are): other bytes become '?'
        let card: String = card
            .iter()
            .map(|&b| if b.is_ascii() { b as char } else { '?' })
            .collect();
        let key = card[..8].trim_end().to_string();
        if key == "END" {
            break;
        }
        if &card[8..10] == "= " {
            // the value, without a comment after a `/` outside quotes
            let raw = card[10..].trim_start();
            let value = if let Some(inner) = raw.strip_prefix('\'') {
                match quoted_end(inner) {
                    Some(end) => raw[..end + 2].to_string(),
                    None => raw.to_string(),
                }
            } else {
                raw.split('/').next().unwrap_or("").trim().to_string()
            };
            cards.push((key, value));
        }
    }
    Ok((Header(cards), at.div_ceil(BLOCK) * BLOCK))
}

/// Bytes of an HDU's data (padding excluded), from its header.
fn data_size(header: &Header) -> Result<usize, String> {
    let bitpix = header.integer("BITPIX").ok_or("a header has no BITPIX")?;
    let naxis = header.integer("NAXIS").ok_or("a header has no NAXIS")?;
    if naxis == 0 {
        return Ok(0);
    }
    let mut size: u128 = 1;
    for k in 1..=naxis {
        let n = header
            .integer(&format!("NAXIS{k}"))
            .filter(|&n| n >= 0)
            .ok_or(format!("a header has no valid NAXIS{k}"))?;
        size = size.saturating_mul(n as u128);
    }
    let pcount = header.integer("PCOUNT").unwrap_or(0).max(0) as u128;
    let gcount = header.integer("GCOUNT").unwrap_or(1).max(0) as u128;
    let bytes = (bitpix.unsigned_abs() as u128 / 8)
        .saturating_mul(gcount)
        .saturating_mul(pcount.saturating_add(size));
    usize::try_from(bytes).map_err(|_| "a data size overflows".to_string())
}

/// A table column: where it sits in a row and how to read it.
struct Column {
    name: String,
    /// Byte offset in the row.
    offset: usize,
    repeat: usize,
    /// The type letter (`B`, `I`, `J`, `K`, `E`, `D`, ...).
    kind: char,
    scale: f64,
    zero: f64,
}

impl Column {
    /// Value `k` (of `repeat`) of the column in `row`.
    fn value(&self, row: &[u8], k: usize) -> f64 {
        let at = self.offset + k * kind_size(self.kind);
        let raw = |n: usize| &row[at..at + n];
        let v = match self.kind {
            'B' => raw(1)[0] as f64,
            'I' => i16::from_be_bytes(raw(2).try_into().expect("2 bytes")) as f64,
            'J' => i32::from_be_bytes(raw(4).try_into().expect("4 bytes")) as f64,
            'K' => i64::from_be_bytes(raw(8).try_into().expect("8 bytes")) as f64,
            'E' => f32::from_be_bytes(raw(4).try_into().expect("4 bytes")) as f64,
            _ => f64::from_be_bytes(raw(8).try_into().expect("8 bytes")),
        };
        if self.scale == 1.0 && self.zero == 0.0 {
            v
        } else {
            self.zero + self.scale * v
        }
    }
}

/// Bytes of one value of a `TFORM` type letter (0 for an unknown one).
fn kind_size(kind: char) -> usize {
    match kind {
        'L' | 'B' | 'A' => 1,
        'I' => 2,
        'J' | 'E' => 4,
        'K' | 'D' | 'C' | 'P' => 8,
        'M' | 'Q' => 16,
        _ => 0,
    }
}

/// The table's columns, from `TFIELDS` and `TFORMn`, `TTYPEn`, `TSCALn`,
/// `TZEROn`.
fn columns(header: &Header) -> Result<Vec<Column>, String> {
    let fields = header
        .integer("TFIELDS")
        .filter(|&n| (0..=999).contains(&n))
        .ok_or("the table has no valid TFIELDS")?;
    let mut out = Vec::new();
    let mut offset = 0usize;
    for k in 1..=fields {
        let form = header
            .string(&format!("TFORM{k}"))
            .ok_or(format!("the table has no TFORM{k}"))?;
        let form = form.trim();
        let digits = form.chars().take_while(|c| c.is_ascii_digit()).count();
        let repeat: usize = if digits == 0 {
            1
        } else {
            form[..digits]
                .parse()
                .map_err(|_| format!("TFORM{k} = '{form}': a repeat count too large"))?
        };
        let kind = form[digits..].chars().next().unwrap_or(' ');
        let width = if kind == 'X' {
            repeat.div_ceil(8)
        } else if kind_size(kind) > 0 {
            repeat.saturating_mul(kind_size(kind))
        } else {
            return Err(format!("TFORM{k} = '{form}': not a FITS column type"));
        };
        out.push(Column {
            name: header
                .string(&format!("TTYPE{k}"))
                .unwrap_or_else(|| format!("column {k}")),
            offset,
            repeat,
            kind,
            scale: header.number(&format!("TSCAL{k}")).unwrap_or(1.0),
            zero: header.number(&format!("TZERO{k}")).unwrap_or(0.0),
        });
        offset = offset.saturating_add(width);
    }
    Ok(out)
}

/// The first binary table: its header (merged after the primary's, so
/// that its own keywords win) and its data.
fn first_table(data: &[u8]) -> Result<(Header, &[u8]), String> {
    if !data.starts_with(b"SIMPLE  =") {
        return Err("not a FITS file (it does not start with SIMPLE)".into());
    }
    let (primary, mut at) = header_at(data, 0)?;
    at += data_size(&primary)?.div_ceil(BLOCK) * BLOCK;
    loop {
        if at >= data.len() {
            return Err(
                "no binary table (BINTABLE extension): a HEALPix map is stored as one".into(),
            );
        }
        let (header, start) = header_at(data, at)?;
        let size = data_size(&header)?;
        if header.string("XTENSION").as_deref() == Some("BINTABLE") {
            let end = start.saturating_add(size);
            let table = data.get(start..end).ok_or(format!(
                "truncated: the table needs {size} bytes from byte {start}, the file has {}",
                data.len()
            ))?;
            let mut merged = primary.0;
            merged.extend(header.0);
            // the extension's keywords last, found first
            merged.reverse();
            return Ok((Header(merged), table));
        }
        at = start.saturating_add(size.div_ceil(BLOCK) * BLOCK);
    }
}

/// Reads column `field` (0 = the first map column; a partial-sky map's
/// `PIXEL` column is not counted, as healpy counts) of the HEALPix map in
/// `path` (see the [module docs](self)).
///
/// # Example
/// ```
/// # use tessera::io::fits::read_healpix;
/// let dir = std::env::temp_dir().join(format!("tessera-doc-fits-{}", std::process::id()));
/// std::fs::create_dir_all(&dir).unwrap();
/// let path = dir.join("not.fits");
/// std::fs::write(&path, b"hello").unwrap();
/// let err = read_healpix(&path, 0).unwrap_err().to_string();
/// assert!(err.contains("not a FITS file"), "{err}");
/// std::fs::remove_dir_all(&dir).unwrap();
/// ```
pub fn read_healpix(path: &Path, field: usize) -> Result<HealpixFits, Error> {
    let data = std::fs::read(path).map_err(|source| Error::Io {
        path: path.into(),
        source,
    })?;
    parse_healpix(&data, field).map_err(|reason| Error::File {
        path: path.into(),
        reason,
    })
}

fn parse_healpix(data: &[u8], field: usize) -> Result<HealpixFits, String> {
    let (header, table) = first_table(data)?;
    if let Some(pixtype) = header.string("PIXTYPE") {
        if pixtype != "HEALPIX" {
            return Err(format!("PIXTYPE = '{pixtype}': not a HEALPix map"));
        }
    }
    let ordering = header.string("ORDERING").ok_or(
        "no ORDERING keyword (RING or NESTED): not a HEALPix map, or an incomplete header",
    )?;
    let scheme: Scheme = ordering.parse()?;
    let nside = header
        .integer("NSIDE")
        .ok_or("no NSIDE keyword: not a HEALPix map, or an incomplete header")?;
    if nside < 1 || !(nside as u64).is_power_of_two() {
        return Err(format!("NSIDE = {nside}: not a power of two"));
    }
    if nside > MAX_NSIDE as i64 {
        return Err(format!(
            "NSIDE = {nside}: larger than tessera reads ({MAX_NSIDE}, {} pixels)",
            12 * MAX_NSIDE * MAX_NSIDE
        ));
    }
    let nside = nside as u64;
    let npix = 12 * nside * nside;
    let row_bytes = header
        .integer("NAXIS1")
        .filter(|&n| n >= 0)
        .ok_or("the table has no valid NAXIS1")? as usize;
    let rows = header
        .integer("NAXIS2")
        .filter(|&n| n >= 0)
        .ok_or("the table has no valid NAXIS2")? as usize;
    if table.len() < row_bytes.saturating_mul(rows) {
        return Err(format!(
            "the table's {rows} rows of {row_bytes} bytes do not fit its {} bytes",
            table.len()
        ));
    }
    let columns = columns(&header)?;
    let width = columns
        .last()
        .map_or(0, |c| c.offset + c.repeat * kind_size(c.kind));
    if width > row_bytes {
        return Err(format!(
            "the columns need {width} bytes a row, NAXIS1 gives {row_bytes}"
        ));
    }
    let explicit = header.string("INDXSCHM").as_deref() == Some("EXPLICIT")
        || header.string("OBJECT").as_deref() == Some("PARTIAL");
    let maps = &columns[usize::from(explicit).min(columns.len())..];
    let names = || {
        let names: Vec<&str> = maps.iter().map(|c| c.name.as_str()).collect();
        names.join(", ")
    };
    let column = maps.get(field).ok_or_else(|| {
        format!(
            "field {field}: the table has {} map column(s) ({}), counted from 0",
            maps.len(),
            names()
        )
    })?;
    let numeric = |c: &Column| matches!(c.kind, 'B' | 'I' | 'J' | 'K' | 'E' | 'D');
    if !numeric(column) {
        return Err(format!(
            "column '{}' has type {}: not a numeric map column (B, I, J, K, E or D)",
            column.name, column.kind
        ));
    }
    let rows_of = |r: usize| &table[r * row_bytes..(r + 1) * row_bytes];
    let count = column.repeat.saturating_mul(rows);
    let bad_data = header.number("BAD_DATA");
    let unseen = |v: f64| match bad_data {
        Some(b) if v == b => UNSEEN,
        _ => v,
    };
    let (values, listed) = if explicit {
        let pixel = &columns[0];
        if !matches!(pixel.kind, 'B' | 'I' | 'J' | 'K') {
            return Err(format!(
                "a partial-sky (explicit-index) map's first column lists pixels; '{}' has type {}",
                pixel.name, pixel.kind
            ));
        }
        if pixel.repeat != column.repeat {
            return Err(format!(
                "the pixel column '{}' has {} values a row, the map column '{}' {}",
                pixel.name, pixel.repeat, column.name, column.repeat
            ));
        }
        let mut values = vec![UNSEEN; npix as usize];
        for r in 0..rows {
            let row = rows_of(r);
            for k in 0..column.repeat {
                let p = pixel.value(row, k);
                if !(p >= 0.0 && p < npix as f64 && p.fract() == 0.0) {
                    return Err(format!(
                        "pixel {p} (row {}) is not a pixel of an NSIDE {nside} map (0 to {})",
                        r + 1,
                        npix - 1
                    ));
                }
                values[p as usize] = unseen(column.value(row, k));
            }
        }
        (values, Some(count))
    } else {
        if count as u64 != npix {
            let first = header.integer("FIRSTPIX").unwrap_or(0);
            return Err(format!(
                "column '{}' holds {count} values, but NSIDE {nside} needs 12 NSIDE^2 = {npix}{}",
                column.name,
                if first != 0 {
                    format!(" (FIRSTPIX = {first}: a partial map without explicit indices is not supported)")
                } else {
                    String::new()
                }
            ));
        }
        let values = (0..rows)
            .flat_map(|r| (0..column.repeat).map(move |k| (r, k)))
            .map(|(r, k)| unseen(column.value(rows_of(r), k)))
            .collect();
        (values, None)
    };
    Ok(HealpixFits {
        values,
        scheme,
        nside,
        coordsys: header.string("COORDSYS"),
        column: column.name.clone(),
        listed,
    })
}

//! A small FITS writer for the tests: a primary header and one binary
//! table, with any extra header cards, so that tests make the HEALPix
//! files they read (healpy's layout, and broken ones).
#![allow(dead_code)]

use std::path::Path;

/// A header card: `KEY     = VALUE`, padded to 80 bytes.
pub fn card(key: &str, value: &str) -> String {
    format!("{key:<8}= {value:<70}")
}

/// A quoted string value.
pub fn text(s: &str) -> String {
    format!("'{s:<8}'")
}

/// A header of cards, ended and padded to 2880-byte blocks.
fn header(cards: &[String]) -> Vec<u8> {
    let mut out: Vec<u8> = cards.concat().into_bytes();
    out.extend(format!("{:<80}", "END").bytes());
    out.resize(out.len().div_ceil(2880) * 2880, b' ');
    out
}

/// One column: its name, type letter (`B`, `I`, `J`, `K`, `E`, `D`),
/// values per row, and every value in row order.
pub struct Column<'a> {
    pub name: &'a str,
    pub kind: char,
    pub repeat: usize,
    pub values: &'a [f64],
}

fn encode(kind: char, v: f64) -> Vec<u8> {
    match kind {
        'B' => vec![v as u8],
        'I' => (v as i16).to_be_bytes().to_vec(),
        'J' => (v as i32).to_be_bytes().to_vec(),
        'K' => (v as i64).to_be_bytes().to_vec(),
        'E' => (v as f32).to_be_bytes().to_vec(),
        _ => v.to_be_bytes().to_vec(),
    }
}

/// The bytes of a FITS file: an empty primary HDU, then a binary table
/// of `columns` whose header carries `extra` cards.
pub fn table_bytes(columns: &[Column], extra: &[String]) -> Vec<u8> {
    let primary = header(&[
        card("SIMPLE", "T"),
        card("BITPIX", "8"),
        card("NAXIS", "0"),
        card("EXTEND", "T"),
    ]);
    let rows = columns[0].values.len() / columns[0].repeat;
    let mut row_bytes = 0;
    let mut cards = vec![
        card("XTENSION", &text("BINTABLE")),
        card("BITPIX", "8"),
        card("NAXIS", "2"),
    ];
    let mut data = Vec::new();
    let widths: Vec<usize> = columns
        .iter()
        .map(|c| c.repeat * encode(c.kind, 0.0).len())
        .collect();
    row_bytes += widths.iter().sum::<usize>();
    cards.push(card("NAXIS1", &row_bytes.to_string()));
    cards.push(card("NAXIS2", &rows.to_string()));
    cards.push(card("PCOUNT", "0"));
    cards.push(card("GCOUNT", "1"));
    cards.push(card("TFIELDS", &columns.len().to_string()));
    for (k, c) in columns.iter().enumerate() {
        cards.push(card(&format!("TTYPE{}", k + 1), &text(c.name)));
        let form = if c.repeat == 1 {
            c.kind.to_string()
        } else {
            format!("{}{}", c.repeat, c.kind)
        };
        cards.push(card(&format!("TFORM{}", k + 1), &text(&form)));
    }
    cards.extend(extra.iter().cloned());
    for r in 0..rows {
        for c in columns {
            for v in &c.values[r * c.repeat..(r + 1) * c.repeat] {
                data.extend(encode(c.kind, *v));
            }
        }
    }
    data.resize(data.len().div_ceil(2880) * 2880, 0);
    let mut out = primary;
    out.extend(header(&cards));
    out.extend(data);
    out
}

/// The cards healpy writes for a full-sky map.
pub fn healpix_cards(ordering: &str, nside: u64, coordsys: Option<&str>) -> Vec<String> {
    let mut cards = vec![
        card("PIXTYPE", &text("HEALPIX")),
        card("ORDERING", &text(ordering)),
        card("NSIDE", &nside.to_string()),
        card("FIRSTPIX", "0"),
        card("LASTPIX", &(12 * nside * nside - 1).to_string()),
        card("INDXSCHM", &text("IMPLICIT")),
        card("OBJECT", &text("FULLSKY")),
    ];
    if let Some(c) = coordsys {
        cards.push(card("COORDSYS", &text(c)));
    }
    cards
}

/// A full-sky map as healpy writes it: one float32 column, rows of 1024
/// values when there are more than 1024 (else one a row).
pub fn write_map(path: &Path, values: &[f64], ordering: &str, coordsys: Option<&str>) {
    let nside = ((values.len() / 12) as f64).sqrt() as u64;
    let repeat = if values.len() > 1024 { 1024 } else { 1 };
    let column = Column {
        name: "TEMPERATURE",
        kind: 'E',
        repeat,
        values,
    };
    let cards = healpix_cards(ordering, nside, coordsys);
    std::fs::write(path, table_bytes(&[column], &cards)).unwrap();
}

/// The columns of a partial-sky map: `PIXEL` (int32) then `SIGNAL`
/// (float32), one value a row.
pub fn partial_sky<'a>(pixels: &'a [f64], signal: &'a [f64]) -> [Column<'a>; 2] {
    [
        Column {
            name: "PIXEL",
            kind: 'J',
            repeat: 1,
            values: pixels,
        },
        Column {
            name: "SIGNAL",
            kind: 'E',
            repeat: 1,
            values: signal,
        },
    ]
}

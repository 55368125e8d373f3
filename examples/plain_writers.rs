//! The baselines of `scripts/whole-process.sh`, written the obvious way and
//! independently of tessera (only `std` and the `exr` crate): each writes
//! UTK binary (f64) points through a `BufWriter`, as a user's plain program
//! would, so that whole-process timings compare tessera's command line with
//! what straightforward code costs for the same bytes.
//!
//! ```text
//! plain_writers fibonacci N OUT        spherical Fibonacci lattice
//! plain_writers jittered N OUT         jittered grid in [0,1)², ceil(sqrt N)² cells, first N
//! plain_writers envmap MAP.exr N OUT   i.i.d. inverse-CDF samples of a lat-long map
//! ```
//! `OUT` is a path or `-` for standard output. One thread each.

use std::f64::consts::PI;
use std::io::{BufWriter, Write};

const UTK_MAGIC: u32 = 0x214B_5455;

fn header(out: &mut impl Write, n: usize, dims: u32) -> std::io::Result<()> {
    out.write_all(&UTK_MAGIC.to_le_bytes())?;
    out.write_all(&[5, 0, 0, 0])?; // f64
    out.write_all(&1u32.to_le_bytes())?;
    out.write_all(&(n as u32).to_le_bytes())?;
    out.write_all(&dims.to_le_bytes())
}

fn put(out: &mut impl Write, values: &[f64]) -> std::io::Result<()> {
    for v in values {
        out.write_all(&v.to_le_bytes())?;
    }
    Ok(())
}

/// z = 1 - (2i+1)/n, phi = 2 pi frac(i / golden ratio).
fn fibonacci(n: usize, out: &mut impl Write) -> std::io::Result<()> {
    header(out, n, 3)?;
    let inv_phi = (5f64.sqrt() - 1.0) / 2.0;
    for i in 0..n {
        let z = 1.0 - (2 * i + 1) as f64 / n as f64;
        let r = (1.0 - z * z).sqrt();
        let (s, c) = (2.0 * PI * (i as f64 * inv_phi).fract()).sin_cos();
        put(out, &[r * c, r * s, z])?;
    }
    Ok(())
}

/// xorshift64*: a plain, fast generator.
struct Rng(u64);
impl Rng {
    fn next(&mut self) -> f64 {
        self.0 ^= self.0 >> 12;
        self.0 ^= self.0 << 25;
        self.0 ^= self.0 >> 27;
        (self.0.wrapping_mul(0x2545_F491_4F6C_DD1D) >> 11) as f64 / (1u64 << 53) as f64
    }
}

fn jittered(n: usize, out: &mut impl Write) -> std::io::Result<()> {
    header(out, n, 2)?;
    let side = (n as f64).sqrt().ceil() as usize;
    let mut rng = Rng(0x9E37_79B9_7F4A_7C15);
    for k in 0..n {
        let (i, j) = (k % side, k / side);
        let x = (i as f64 + rng.next()) / side as f64;
        let y = (j as f64 + rng.next()) / side as f64;
        put(out, &[x, y])?;
    }
    Ok(())
}

/// Marginal CDF over rows and conditional CDFs over columns of luminance x
/// pixel solid angle; two binary searches, then a direction uniform in
/// solid angle inside the pixel.
fn envmap(path: &str, n: usize, out: &mut impl Write) -> Result<(), String> {
    use exr::prelude::*;
    let image = read_first_rgba_layer_from_file(
        path,
        |size, _| (size.width(), vec![0f32; size.width() * size.height()]),
        |(w, lum), pos, (r, g, b, _a): (f32, f32, f32, f32)| {
            lum[pos.y() * *w + pos.x()] = 0.2126 * r + 0.7152 * g + 0.0722 * b;
        },
    )
    .map_err(|e| format!("{path}: {e}"))?;
    let (w, lum) = image.layer_data.channel_data.pixels;
    let h = lum.len() / w;
    let mut rows = vec![0.0f64; h + 1];
    let mut columns = vec![0.0f64; h * (w + 1)];
    for j in 0..h {
        let omega = (2.0 * PI / w as f64)
            * ((j as f64 * PI / h as f64).cos() - ((j + 1) as f64 * PI / h as f64).cos());
        let cdf = &mut columns[j * (w + 1)..(j + 1) * (w + 1)];
        for i in 0..w {
            cdf[i + 1] = cdf[i] + f64::from(lum[j * w + i].max(0.0)) * omega;
        }
        rows[j + 1] = rows[j] + cdf[w];
    }
    let total = rows[h];
    if total.is_nan() || total <= 0.0 {
        return Err(format!("{path}: the map is black"));
    }
    header(out, n, 3).map_err(|e| e.to_string())?;
    let mut rng = Rng(0x2545_F491_4F6C_DD1D);
    for _ in 0..n {
        let u = rng.next() * total;
        let j = rows[1..].partition_point(|&c| c <= u).min(h - 1);
        let cdf = &columns[j * (w + 1)..(j + 1) * (w + 1)];
        let v = rng.next() * cdf[w];
        let i = cdf[1..].partition_point(|&c| c <= v).min(w - 1);
        let (a, b) = (
            (j as f64 * PI / h as f64).cos(),
            ((j + 1) as f64 * PI / h as f64).cos(),
        );
        let z = a + (b - a) * rng.next();
        let r = (1.0 - z * z).max(0.0).sqrt();
        let (s, c) = (2.0 * PI * (i as f64 + rng.next()) / w as f64).sin_cos();
        put(out, &[r * c, r * s, z]).map_err(|e| e.to_string())?;
    }
    Ok(())
}

fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let usage = "usage: plain_writers fibonacci|jittered N OUT | envmap MAP N OUT";
    let count = |s: &String| s.parse::<usize>().unwrap_or_else(|_| panic!("{usage}"));
    let (out_path, result) = match args.as_slice() {
        [kind, n, out] if kind == "fibonacci" || kind == "jittered" => (out.clone(), {
            let mut w = writer(out);
            let r = if kind == "fibonacci" {
                fibonacci(count(n), &mut w)
            } else {
                jittered(count(n), &mut w)
            };
            r.and_then(|()| w.flush()).map_err(|e| e.to_string())
        }),
        [kind, map, n, out] if kind == "envmap" => (out.clone(), {
            let mut w = writer(out);
            envmap(map, count(n), &mut w).and_then(|()| w.flush().map_err(|e| e.to_string()))
        }),
        _ => {
            eprintln!("{usage}");
            std::process::exit(2);
        }
    };
    if let Err(e) = result {
        eprintln!("plain_writers: {out_path}: {e}");
        std::process::exit(1);
    }
}

fn writer(path: &str) -> BufWriter<Box<dyn Write>> {
    let sink: Box<dyn Write> = match path {
        "-" => Box::new(std::io::stdout().lock()),
        _ => Box::new(std::fs::File::create(path).unwrap_or_else(|e| {
            eprintln!("plain_writers: {path}: {e}");
            std::process::exit(1)
        })),
    };
    BufWriter::new(sink)
}

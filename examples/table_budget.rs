//! Where the sphere table's bytes go: its zstd frames (the layout
//! `SphereLut::to_bytes` writes: the header, each level's offsets bin by
//! bin, each level's sibling fills, each level's drop moves bin by bin,
//! the zonal warps), summed per part and level, with what is left of
//! issue 18's 4 MB budget over all four tables in `luts/`.
//!
//!     cargo run --release --example table_budget -- [--table PATH]
//!
//! `--table` reads another sphere table (`tessera lut build --out-dir`).

use tessera::lut::{frame_sizes, SphereLut};

const USAGE: &str = "usage: table_budget [--table PATH]";

/// Issue 18's budget for all four tables together.
const BUDGET: usize = 4_000_000;

fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let path = match args.as_slice() {
        [] => "luts/sphere.lut".to_string(),
        [flag, path] if flag == "--table" => path.clone(),
        _ => panic!("{USAGE}"),
    };
    let bytes = std::fs::read(&path).unwrap_or_else(|e| panic!("{path}: {e}"));
    let lut = SphereLut::from_bytes(&bytes).unwrap_or_else(|e| panic!("{path}: {e}"));
    let mut sizes = frame_sizes(&bytes).into_iter();
    let mut take = |count: usize| -> usize { sizes.by_ref().take(count).sum() };
    let mut parts: Vec<(String, usize, String)> = vec![("header".into(), take(1), String::new())];
    for (level, bins) in lut.tables.iter().enumerate() {
        let name = match level < lut.exact_levels as usize {
            true => format!("offsets, level {level}"),
            false => format!("offsets, class levels {level}+"),
        };
        let rows: usize = bins.iter().map(|b| b.len()).sum();
        parts.push((name, take(bins.len()), format!("{rows} pairs")));
    }
    for (level, fills) in lut.fills.iter().enumerate() {
        if !fills.is_empty() {
            let pairs = format!("{} pairs", fills.len());
            parts.push((format!("sibling fills, level {level}"), take(1), pairs));
        } else {
            take(1);
        }
    }
    for (level, bins) in lut.drop_moves.iter().enumerate() {
        let moves: usize = bins.iter().map(|m| m.len()).sum();
        let size = take(bins.len());
        let each = format!(
            "{moves} moves, {:.2} bytes a move",
            size as f64 / moves as f64
        );
        parts.push((format!("drop moves, level {level}"), size, each));
    }
    parts.push(("zonal warps".into(), take(1), String::new()));
    assert_eq!(sizes.next(), None, "{path}: more frames than its parts");
    println!("{path}: {} bytes\n", bytes.len());
    println!("| part | bytes | share | holds |");
    println!("|---|---|---|---|");
    for (name, size, holds) in &parts {
        let share = 100.0 * *size as f64 / bytes.len() as f64;
        println!("| {name} | {size} | {share:.1} % | {holds} |");
    }
    let others: usize = ["ghexomino", "ppentomino", "penrose"]
        .iter()
        .map(|name| {
            let other = format!("luts/{name}.lut");
            std::fs::metadata(&other).map_or(0, |m| m.len() as usize)
        })
        .sum();
    let total = bytes.len() + others;
    println!(
        "\nwith the other tables in luts/ ({others} bytes): {total} bytes, {} under the {BUDGET}-byte budget",
        BUDGET as i64 - total as i64
    );
}

//! Streams N uniform sphere samples (a block of codes at a time, bounded memory) and
//! prints their mean position. `/usr/bin/time -v` shows the peak RSS.
//! Run: `cargo run --release --example stream -- 1000000000`.

use tessera::{engine, tiling::sphere::SphereTiling};

fn main() {
    let n: usize = std::env::args()
        .nth(1)
        .and_then(|s| s.parse().ok())
        .unwrap_or(1_000_000);
    let tiling = SphereTiling::default();
    let Some(stream) = engine::stream(&tiling, n) else {
        eprintln!("{n} samples do not fit the deepest level");
        std::process::exit(1);
    };
    let started = std::time::Instant::now();
    let sum = stream.fold(glam::DVec3::ZERO, |acc, s| acc + s.position);
    println!(
        "{n} samples in {:.1} s, mean position {:?}",
        started.elapsed().as_secs_f64(),
        sum / n as f64
    );
}

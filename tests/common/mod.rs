#![allow(dead_code)]
pub mod fits;
pub mod plane;
pub mod sky;

/// `f` run on a pool of `threads` threads (the tests compare thread counts).
pub fn on_threads<T: Send>(threads: usize, f: impl FnOnce() -> T + Send) -> T {
    rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()
        .expect("a thread pool")
        .install(f)
}

/// The rows of a CSV with a header line (what `--format csv` writes).
pub fn csv_rows(output: &[u8]) -> Vec<Vec<f64>> {
    let text = std::str::from_utf8(output).unwrap();
    text.lines()
        .skip(1)
        .map(|l| l.split(',').map(|v| v.parse().unwrap()).collect())
        .collect()
}

/// Runs the `tessera` binary with `args`.
pub fn tessera(args: &[&str]) -> std::process::Output {
    std::process::Command::new(env!("CARGO_BIN_EXE_tessera"))
        .args(args)
        .output()
        .expect("the binary runs")
}

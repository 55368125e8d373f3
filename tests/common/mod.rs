#![allow(dead_code)]
pub mod plane;
pub mod sky;

/// Runs the `tessera` binary with `args`.
pub fn tessera(args: &[&str]) -> std::process::Output {
    std::process::Command::new(env!("CARGO_BIN_EXE_tessera"))
        .args(args)
        .output()
        .expect("the binary runs")
}

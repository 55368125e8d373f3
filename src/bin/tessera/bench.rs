//! `tessera bench`: measurements written as documents.

use clap::{Args, Subcommand};
use std::path::PathBuf;
use tessera::Error;

#[derive(Subcommand)]
pub(crate) enum BenchCommand {
    /// Relative RMSE of Monte Carlo integration against time, every sampler
    /// and knob, N = 2^6 .. 2^20: writes OUT/ACCURACY.md and OUT/accuracy-*.png.
    Accuracy(AccuracyArgs),
}

#[derive(Args)]
pub(crate) struct AccuracyArgs {
    /// Directory for ACCURACY.md and the plots (no default: `docs` is the
    /// tracked copy).
    #[arg(long)]
    out: PathBuf,
    /// Largest N is 2^this (from 2^6).
    #[arg(long, default_value_t = 20, value_parser = clap::value_parser!(u32).range(7..=24))]
    max_exponent: u32,
    /// Seeds per method and N.
    #[arg(long, default_value_t = 16, value_parser = clap::value_parser!(u64).range(2..))]
    seeds: u64,
}

pub(crate) fn bench_accuracy(args: AccuracyArgs) -> Result<(), Error> {
    let config = tessera::accuracy::Config {
        exponents: (6..=args.max_exponent).collect(),
        seeds: args.seeds,
    };
    let results = tessera::accuracy::run(&config);
    let command = format!(
        "tessera bench accuracy --out {} --max-exponent {} --seeds {}",
        args.out.display(),
        args.max_exponent,
        args.seeds
    );
    let files = results.write(&args.out, &command)?;
    eprintln!(
        "wrote {} files into {} in {:.0} s",
        files.len(),
        args.out.display(),
        results.wall_seconds
    );
    Ok(())
}

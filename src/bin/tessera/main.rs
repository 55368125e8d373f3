//! The `tessera` command line: a thin layer over the library.

mod bench;
mod common;
mod lights;
mod lut;
mod metrics;
mod plane;
mod plot;
mod sphere;
mod tiles;

use bench::{bench_accuracy, BenchCommand};
use clap::{Parser, Subcommand};
use lights::{lights, LightsArgs};
use lut::{lut_build, lut_tiling, LutCommand};
use metrics::{metrics, MetricsArgs};
use plane::{plane, PlaneArgs};
use plot::{plot, PlotArgs};
use sphere::{sphere, SphereArgs};
use std::process::ExitCode;
use tiles::{tiles, TilesArgs};

#[derive(Parser)]
#[command(
    name = "tessera",
    version,
    about = "Blue-noise importance sampling with self-similar tilings"
)]
struct Cli {
    /// Worker threads (default: all cores). The output does not depend on it.
    #[arg(long, global = true)]
    threads: Option<usize>,
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand)]
enum Command {
    /// Sample the unit sphere (HEALPix faces tiled by P-pentominoes).
    Sphere(SphereArgs),
    /// Sample the unit square (Penrose, G-hexomino or P-pentomino tilings).
    Plane(PlaneArgs),
    /// Draw a tiling level and its samples as SVG.
    Tiles(TilesArgs),
    /// Build the offline tables in luts/.
    Lut {
        #[command(subcommand)]
        command: LutCommand,
    },
    /// Quality measures of a point file (any format tessera writes, or UTK binary);
    /// `--help` lists every key.
    #[command(after_long_help = metrics::measures_help())]
    Metrics(MetricsArgs),
    /// Render a point file as a PNG picture.
    Plot(PlotArgs),
    /// Turn a lat-long environment map into N directional lights with exact powers.
    Lights(LightsArgs),
    /// Measurements: `bench accuracy` writes ACCURACY.md and its plots.
    Bench {
        #[command(subcommand)]
        command: BenchCommand,
    },
}

fn main() -> ExitCode {
    let cli = Cli::parse();
    // The command runs on a worker of the pool, so its parallel loops
    // start without waking a thread outside it: a block of a stream
    // handed from the main thread to the pool and back cost a futex wake
    // each way (30 % of a one-thread G-hexomino request, `perf`).
    let pool = match rayon::ThreadPoolBuilder::new()
        .num_threads(cli.threads.map_or(0, |t| t.max(1))) // 0: RAYON_NUM_THREADS or all cores
        .build()
    {
        Ok(pool) => pool,
        Err(e) => {
            eprintln!("tessera: cannot start the worker threads: {e}");
            return ExitCode::FAILURE;
        }
    };
    let result = pool.install(|| run(cli.command));
    match result {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("tessera: {e}");
            // usage errors (what was asked) exit 2, as clap's do; data
            // errors (what a file holds, or the system) exit 1
            match e {
                tessera::Error::Density(..) | tessera::Error::Request(_) => ExitCode::from(2),
                _ => ExitCode::FAILURE,
            }
        }
    }
}

/// Runs one subcommand.
fn run(command: Command) -> Result<(), tessera::Error> {
    match command {
        Command::Sphere(args) => sphere(args),
        Command::Plane(args) => plane(args),
        Command::Tiles(args) => tiles(args),
        Command::Lut {
            command: LutCommand::Build(args),
        } => lut_build(args),
        Command::Lut {
            command: LutCommand::Tiling(args),
        } => lut_tiling(args),
        Command::Metrics(args) => metrics(args),
        Command::Plot(args) => plot(args),
        Command::Lights(args) => lights(args),
        Command::Bench {
            command: BenchCommand::Accuracy(args),
        } => bench_accuracy(args),
    }
}

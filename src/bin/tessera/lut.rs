//! `tessera lut`: the offline tables and production rules.

use crate::common::*;
use clap::{Args, Subcommand, ValueEnum};
use std::path::{Path, PathBuf};
use tessera::Error;

#[derive(Subcommand)]
pub(crate) enum LutCommand {
    /// Run the offline optimiser and write the table and its provenance.
    Build(LutBuildArgs),
    /// Find a rep-tile's production rule by exact-cover search and store it.
    Tiling(LutTilingArgs),
}

#[derive(Clone, Copy, ValueEnum)]
pub(crate) enum RepTile {
    /// G-hexomino `X.. / XXX / XX.`, 81-rep (scale 9).
    Ghexomino,
    /// P-pentomino `XX / XX / X.`, 4-rep (scale 2), both dissections.
    Ppentomino,
}

#[derive(Args)]
pub(crate) struct LutTilingArgs {
    /// Which rep-tile.
    #[arg(value_enum)]
    tile: RepTile,
    /// Directory to write `<tile>.rules.json` into (no default: `luts` is
    /// the tracked copy the build embeds).
    #[arg(long)]
    out_dir: PathBuf,
}

#[derive(Args)]
pub(crate) struct LutBuildArgs {
    /// Tile system whose table to build.
    #[arg(long, value_enum)]
    system: System,
    /// Seed of every random choice (the build is deterministic for a seed).
    #[arg(long, default_value_t = 1)]
    seed: u64,
    /// Lloyd iterations per level and importance bin (default: 32 for the
    /// sphere, 24 for the planar systems).
    #[arg(long)]
    iterations: Option<usize>,
    /// Importance bins per structural index (default: 12 for the sphere, at
    /// least 6; system-specific for the planar ones): more bins leave fewer
    /// holes between optimised densities, and make a larger table and a
    /// longer build.
    #[arg(long)]
    bins: Option<u16>,
    /// Directory to write `<system>.lut` and `<system>.provenance.json` into
    /// (no default: `luts` is the tracked copy the build embeds).
    #[arg(long)]
    out_dir: PathBuf,
}

pub(crate) fn write_table(
    out_dir: &Path,
    name: &str,
    bytes: &[u8],
    provenance: serde_json::Value,
) -> Result<(PathBuf, PathBuf), Error> {
    std::fs::create_dir_all(out_dir).map_err(io_error(out_dir))?;
    let table = out_dir.join(format!("{name}.lut"));
    std::fs::write(&table, bytes).map_err(io_error(&table))?;
    let path = out_dir.join(format!("{name}.provenance.json"));
    std::fs::write(
        &path,
        serde_json::to_string_pretty(&provenance).expect("json") + "\n",
    )
    .map_err(io_error(&path))?;
    Ok((table, path))
}

/// An optimiser's result: the encoded table, its format version and what
/// the build measured.
pub(crate) type Built<R> = (Vec<u8>, u32, R);

/// Runs an optimiser under a progress bar and writes `<name>.lut` and
/// `<name>.provenance.json` (command, options, seconds, report, size).
pub(crate) fn build_table<O, R>(
    args: &LutBuildArgs,
    name: &str,
    options: &O,
    build: impl FnOnce(&(dyn Fn(&str, u64, u64) + Sync)) -> Result<Built<R>, Error>,
) -> Result<(), Error>
where
    O: serde::Serialize,
    R: serde::Serialize,
{
    let bar = progress_bar();
    let progress = progress_to(&bar);
    let started = std::time::Instant::now();
    let (bytes, version, report) = build(&progress)?;
    bar.finish();
    let seconds = started.elapsed().as_secs_f64();
    let provenance = serde_json::json!({
        "command": std::env::args().collect::<Vec<_>>().join(" "),
        "tessera_version": env!("CARGO_PKG_VERSION"),
        "format_version": version,
        "system": name,
        "options": options,
        "build_seconds": seconds,
        "report": report,
        "table_bytes": bytes.len(),
    });
    let (table, path) = write_table(&args.out_dir, name, &bytes, provenance)?;
    eprintln!(
        "wrote {} and {} in {seconds:.1} s",
        table.display(),
        path.display()
    );
    Ok(())
}

pub(crate) fn lut_build(args: LutBuildArgs) -> Result<(), Error> {
    if let Some(system) = args.system.plane() {
        let mut options = tessera::optimize::plane::BuildOptions::for_system(system);
        options.seed = args.seed;
        options.iterations = args.iterations.unwrap_or(options.iterations);
        options.bins = args.bins.unwrap_or(options.bins);
        return build_table(&args, system.name(), &options, |progress| {
            let (lut, report) = tessera::optimize::plane::build(system, &options, progress)?;
            Ok((lut.to_bytes(), lut.version, report))
        });
    }
    if let System::Penrose = args.system {
        let mut options = tessera::optimize::penrose::BuildOptions {
            seed: args.seed,
            ..Default::default()
        };
        options.iterations = args.iterations.unwrap_or(options.iterations);
        options.bins = args.bins.unwrap_or(options.bins);
        return build_table(&args, "penrose", &options, |progress| {
            let (lut, report) = tessera::optimize::penrose::build(&options, progress)?;
            Ok((lut.to_bytes(), lut.version, report))
        });
    }
    let mut options = tessera::optimize::sphere::BuildOptions {
        seed: args.seed,
        ..Default::default()
    };
    options.iterations = args.iterations.unwrap_or(options.iterations);
    if let Some(bins) = args.bins {
        options.bins = u8::try_from(bins).map_err(|_| {
            Error::Request(format!("--bins {bins}: the sphere table holds at most 255"))
        })?;
    }
    build_table(&args, "sphere", &options, |progress| {
        let (lut, report) = tessera::optimize::sphere::build(&options, progress)?;
        Ok((lut.to_bytes(), lut.version, report))
    })
}

pub(crate) fn lut_tiling(args: LutTilingArgs) -> Result<(), Error> {
    use tessera::polyomino::{Rule, Shape};
    let (name, shape, scale, limit) = match args.tile {
        RepTile::Ghexomino => ("ghexomino", Shape::g_hexomino(), 9, 1),
        RepTile::Ppentomino => ("ppentomino", Shape::p_pentomino(), 2, usize::MAX),
    };
    let started = std::time::Instant::now();
    let rules = Rule::dissections(&shape, scale, limit);
    let seconds = started.elapsed().as_secs_f64();
    if rules.is_empty() || !rules.iter().all(|r| r.tiles_parent(&shape)) {
        return Err(Error::Request(format!("no dissection of the {name} found")));
    }
    let file = serde_json::json!({
        "provenance": {
            "command": format!("tessera lut tiling {name}"),
            "search": "exact cover (Algorithm X, fewest-options cell first, natural option order)",
            "seconds": seconds,
            "checked": "children cover the enlarged parent cell by cell",
        },
        "shape": shape,
        "rules": rules,
    });
    std::fs::create_dir_all(&args.out_dir).map_err(io_error(&args.out_dir))?;
    let path = args.out_dir.join(format!("{name}.rules.json"));
    std::fs::write(&path, serde_json::to_string(&file).expect("json") + "\n")
        .map_err(io_error(&path))?;
    eprintln!(
        "wrote {} ({} rule(s), {seconds:.1} s)",
        path.display(),
        rules.len()
    );
    Ok(())
}

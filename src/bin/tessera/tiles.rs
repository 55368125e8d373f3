//! `tessera tiles`: a tiling level drawn as SVG.

use crate::common::*;
use clap::Args;
use std::path::PathBuf;
use tessera::tiling::sphere::SphereTiling;
use tessera::{engine, Error};

#[derive(Args)]
pub(crate) struct TilesArgs {
    /// Tile system to draw.
    #[arg(long, value_enum)]
    system: System,
    /// Subdivision level (sphere 0..=5, Penrose 0..=14, polyominoes up to
    /// 200000 tiles).
    #[arg(long, default_value_t = 0)]
    level: u32,
    /// SVG file to write.
    #[arg(long)]
    svg: PathBuf,
}

pub(crate) fn tiles(args: TilesArgs) -> Result<(), Error> {
    if let System::Penrose = args.system {
        return penrose_tiles(args);
    }
    let Some(system) = args.system.plane() else {
        return sphere_tiles(args);
    };
    let tiling = tessera::tiling::plane::PlaneTiling::new(tessera::lut::plane_lut(system));
    use tessera::tiling::TileSystem;
    let count = tiling.capacity(args.level);
    if count > 200_000.0 {
        return Err(Error::Request(format!(
            "level {} of the {} draws {count} tiles; at most 200000 are drawn",
            args.level,
            system.name()
        )));
    }
    let points: Vec<glam::DVec2> =
        engine::generate(&tiling, &tessera::density::Uniform, count as usize, true)?
            .iter()
            .map(|s| s.position)
            .collect();
    let svg = tessera::plot::svg::plane_tiles(&tiling, args.level, &points);
    std::fs::write(&args.svg, svg).map_err(io_error(&args.svg))
}

pub(crate) fn penrose_tiles(args: TilesArgs) -> Result<(), Error> {
    let tiling = tessera::tiling::penrose::PenroseTiling::default();
    if args.level > 14 {
        return Err(Error::Request(format!(
            "level {} of the Penrose tiling draws over 200000 tiles; at most level 14 is drawn",
            args.level
        )));
    }
    let tiles = tiling.tiles(args.level);
    // the points of that level: every point tile's sample at full density
    let count = tiles.iter().filter(|t| t.kind.is_point()).count();
    let points: Vec<glam::DVec2> =
        engine::generate(&tiling, &tessera::density::Uniform, count, true)?
            .iter()
            .map(|s| s.position)
            .collect();
    let svg = tessera::plot::svg::penrose_tiles(&tiling, args.level, &points);
    std::fs::write(&args.svg, svg).map_err(io_error(&args.svg))
}

pub(crate) fn sphere_tiles(args: TilesArgs) -> Result<(), Error> {
    if args.level > 5 {
        return Err(Error::Request(format!(
            "level {} draws {} tiles; at most level 5 is drawn",
            args.level,
            240u64 << (2 * args.level)
        )));
    }
    let tiling = SphereTiling::default();
    let count = 240usize << (2 * args.level);
    let points: Vec<glam::DVec3> =
        engine::generate(&tiling, &tessera::density::Uniform, count, true)?
            .iter()
            .map(|s| s.position)
            .collect();
    let svg = tessera::plot::svg::sphere_tiles(&tiling, args.level, &points);
    std::fs::write(&args.svg, svg).map_err(io_error(&args.svg))
}

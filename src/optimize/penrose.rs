//! Offline optimiser of the Penrose offset table (`luts/penrose.lut`).
//!
//! For each importance bin, the point tiles its density fraction accepts on
//! a deep level of the run-time patch (the unit square, tens of thousands
//! of points) are relaxed by Lloyd's algorithm, every structural index
//! sharing one offset: each iteration moves every site toward the centroid
//! of its Voronoi cell (found by quadrature over the square), and each
//! index's offset by the mean of its sites' moves in their own frames. Only
//! sites whose vertex lies away from the square's border count, so clipped
//! cells do not bias the table.

use crate::lut::PenroseLut;
use crate::optimize::lloyd::{cell_moments, TorusGrid};
use crate::tiling::penrose::{PenroseTile, PenroseTiling, CLASSES};
use crate::tiling::TileSystem;
use crate::Error;
use glam::DVec2;
use serde::Serialize;
use std::sync::Arc;
use std::time::Instant;

/// Options of [`build`].
///
/// # Example
/// ```
/// let o = tessera::optimize::penrose::BuildOptions::default();
/// assert_eq!(o.bins, 21);
/// ```
#[derive(Clone, Debug, Serialize)]
pub struct BuildOptions {
    /// Recorded in the table (the build itself draws nothing at random).
    pub seed: u64,
    /// Lloyd iterations per importance bin.
    pub iterations: usize,
    /// Importance bins (at least 2).
    pub bins: u16,
    /// Most sites relaxed at once: each bin is relaxed on the deepest level
    /// where its accepted points in the square are at most this many.
    pub max_sites: usize,
    /// Quadrature points per site.
    pub quadrature: usize,
    /// Over-relaxation factor of the Lloyd steps (1 = plain Lloyd).
    pub relaxation: f64,
    /// Sites whose vertex lies within this distance of the square's border
    /// do not move the offsets.
    pub margin: f64,
}

impl Default for BuildOptions {
    fn default() -> Self {
        BuildOptions {
            seed: 1,
            iterations: 24,
            bins: 21,
            max_sites: 30_000,
            quadrature: 16,
            relaxation: 1.5,
            margin: 0.05,
        }
    }
}

/// What the build measured, for the provenance file.
///
/// # Example
/// ```
/// fn moves(r: &tessera::optimize::penrose::BuildReport) -> usize { r.lloyd_residual.len() }
/// ```
#[derive(Clone, Debug, Serialize)]
pub struct BuildReport {
    /// Level each bin was relaxed on.
    pub levels: Vec<u32>,
    /// Sites relaxed per bin.
    pub sites: Vec<usize>,
    /// Mean site move (edges) in the first Lloyd iteration, per bin.
    pub lloyd_initial: Vec<f64>,
    /// Mean site move (edges) in the last Lloyd iteration, per bin.
    pub lloyd_residual: Vec<f64>,
    /// Seconds spent in Lloyd relaxation.
    pub lloyd_seconds: f64,
}

/// Builds the table; `progress(stage, done, total)` is called along the way.
///
/// # Example
/// ```no_run
/// use tessera::optimize::penrose::{build, BuildOptions};
/// let (lut, report) = build(&BuildOptions::default(), &|_, _, _| {}).unwrap();
/// assert_eq!(report.levels.len(), lut.bins as usize);
/// ```
pub fn build(
    options: &BuildOptions,
    progress: &(dyn Fn(&str, u64, u64) + Sync),
) -> Result<(PenroseLut, BuildReport), Error> {
    if options.bins < 2 || options.iterations == 0 || options.max_sites < 100 {
        return Err(Error::Request(
            "need at least 2 bins, 1 iteration and 100 sites".into(),
        ));
    }
    if !(0.0..0.25).contains(&options.margin) || options.quadrature == 0 {
        return Err(Error::Request(
            "the margin must lie in [0, 0.25) and quadrature be positive".into(),
        ));
    }
    let mut lut = PenroseLut::zero(options.bins);
    lut.seed = options.seed;
    let tiling = PenroseTiling::new(Arc::new(lut.clone()));
    let started = Instant::now();
    let mut report = BuildReport {
        levels: Vec::new(),
        sites: Vec::new(),
        lloyd_initial: Vec::new(),
        lloyd_residual: Vec::new(),
        lloyd_seconds: 0.0,
    };
    // the points in the square per unit of density fraction at `level`
    let per_level = |level: u32| tiling.capacity(level) / tiling.codes_per_sample();
    let mut cache: Option<(u32, Vec<PenroseTile>)> = None;
    for bin in 0..options.bins as usize {
        progress("lloyd", bin as u64, options.bins as u64);
        let fraction = tiling.bin_fraction(bin);
        let level = (1..=tiling.max_level())
            .take_while(|&l| fraction * per_level(l) <= options.max_sites as f64)
            .last()
            .unwrap_or(1);
        if cache.as_ref().map(|c| c.0) != Some(level) {
            let points = tiling
                .tiles(level)
                .into_iter()
                .filter(|t| t.kind.is_point())
                .collect();
            cache = Some((level, points));
        }
        let all = &cache.as_ref().expect("filled above").1;
        let d = fraction * tiling.capacity(level);
        let tiles: Vec<PenroseTile> = all
            .iter()
            .filter(|t| (t.code as f64) + 0.5 < d)
            .copied()
            .collect();
        let (offsets, first, last) = relax(&tiling, &tiles, options);
        for (class, o) in offsets.iter().enumerate() {
            lut.set_offset(class, bin, (*o).into());
        }
        report.levels.push(level);
        report.sites.push(tiles.len());
        report.lloyd_initial.push(first);
        report.lloyd_residual.push(last);
    }
    progress("lloyd", options.bins as u64, options.bins as u64);
    report.lloyd_seconds = started.elapsed().as_secs_f64();
    // the run-time checks, before anything is written
    let lut = PenroseLut::from_bytes(&lut.to_bytes())?;
    Ok((lut, report))
}

/// Lloyd relaxation of `tiles` (point tiles of one level) with one offset
/// per structural index; returns the offsets and the mean move of the
/// counted sites (edges) in the first and last iterations.
fn relax(
    tiling: &PenroseTiling,
    tiles: &[PenroseTile],
    options: &BuildOptions,
) -> (Vec<DVec2>, f64, f64) {
    let mut offsets = vec![DVec2::ZERO; CLASSES];
    if tiles.len() < 2 {
        return (offsets, 0.0, 0.0);
    }
    let edge = tiling.edge(tiling.level(&tiles[0]));
    let inner = options.margin..1.0 - options.margin;
    let counted: Vec<bool> = tiles
        .iter()
        .map(|t| inner.contains(&t.v[0].x) && inner.contains(&t.v[0].y))
        .collect();
    let n = ((options.quadrature * tiles.len()) as f64).sqrt().ceil() as usize;
    let h = 1.0 / n as f64;
    // far beyond the square, so no cell wraps around the torus
    let period = 3.0;
    let (mut first, mut last) = (f64::NAN, 0.0);
    for _ in 0..options.iterations {
        let sites: Vec<[f64; 2]> = tiles
            .iter()
            .map(|t| tiling.place(t, offsets[t.class()]).into())
            .collect();
        let grid = TorusGrid::new(&sites, period);
        let (sum, count) = cell_moments(&grid, n, h, [0.0, 0.0]);
        let mut class_sum = [DVec2::ZERO; CLASSES];
        let mut class_n = [0usize; CLASSES];
        let (mut moved, mut sites_counted) = (0.0, 0usize);
        for (k, t) in tiles.iter().enumerate() {
            if !counted[k] || count[k] == 0 {
                continue;
            }
            let shift = DVec2::from(sum[k]) / count[k] as f64;
            moved += shift.length() / edge;
            sites_counted += 1;
            // the move in the tile's frame (orthogonal axes one edge long)
            let (e1, e2) = (t.v[1], t.v[2]);
            let local = DVec2::new(shift.dot(e1), shift.dot(e2)) / e1.length_squared();
            class_sum[t.class()] += local;
            class_n[t.class()] += 1;
        }
        last = moved / sites_counted.max(1) as f64;
        if first.is_nan() {
            first = last;
        }
        for c in 0..CLASSES {
            if class_n[c] > 0 {
                offsets[c] += options.relaxation * class_sum[c] / class_n[c] as f64;
            }
        }
    }
    (offsets, first, last)
}

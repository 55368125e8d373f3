//! The drop moves of the first per-tile levels (see [`DropMoves`]): each
//! bin's codes dropped from the top, as ever smaller requests drop them
//! (a ring orbit at a time where a ring's faces share rows), the kept
//! points beside each hole relaxed among the others held fixed.
//!
//! Measured before it was built (`cargo run --release --example
//! neighbour_events -- LEVEL`, the same process in sphere coordinates):
//! between bins the sibling fills left covering radii up to 3.7-4.7 /
//! sqrt(N) a level, because a dropped point's siblings alone cannot
//! close its hole; moving every kept point within 1.5 spacings of it
//! reads 2.9-3.2 on levels 0-5, separation staying at 2.55 or more.

use super::{skew, to_local, within_room, BinSet, BuildOptions, Progress};
use crate::lut::{dequantise, DropMoves, SphereLut};
use crate::polyomino::Shape;
use crate::relax::relax_among_fixed;
use crate::tiling::sphere::{SphereTile, SphereTiling};
use glam::DVec3;
use kiddo::immutable::float::kdtree::ImmutableKdTree;
use kiddo::SquaredEuclidean;
use rayon::prelude::*;
use std::f64::consts::PI;

/// Kept points within this many spacings of a hole move when it opens.
const REACH: f64 = 1.5;
/// Points dropped within this many spacings of a new hole are one hole
/// with it.
const HOLE: f64 = 2.0;
/// Neighbours of a hole, in spacings, whose cells bound the moving points'.
const AROUND: f64 = 5.5;
/// Lloyd iterations a drop.
const ITERATIONS: usize = 5;
/// A move shorter than this many spacings is neither made nor stored,
/// which keeps the table small.
const SHORTEST: f64 = 0.05;

/// Shares of the way to their relaxed places the moves of one drop go,
/// the first that keeps the points [`GUARD`] apart winning.
const SHARES: [f64; 5] = [1.0, 0.75, 0.5, 0.25, 0.0];
/// Spacings a moved point keeps from every other (or what it kept before):
/// a point the room stops short can leave a neighbour, relaxed as if it
/// had gone all the way, too close (N = 6769: 2.13 / sqrt(N) without the
/// guard). At 0.75 the moves of four counts stopped short of their holes
/// (covering 3.45-3.68).
const GUARD: f64 = 0.70;

/// The distance from each of `points[movable]` to its nearest other point,
/// least.
fn nearest_pair(points: &[DVec3], movable: &[usize]) -> f64 {
    (movable.iter())
        .flat_map(|&k| {
            (0..points.len())
                .filter(move |&j| j != k)
                .map(move |j| points[k].distance(points[j]))
        })
        .fold(f64::INFINITY, f64::min)
}

/// The drop moves of levels `0..options.drop_move_levels`, per level and
/// bin (bin 0, whose requests come from the level above, has none).
pub(super) fn drop_moves(
    tiling: &SphereTiling,
    lut: &SphereLut,
    options: &BuildOptions,
    progress: Progress,
) -> Vec<Vec<DropMoves>> {
    let levels = u32::from(options.drop_move_levels);
    (0..levels)
        .map(|level| {
            let mut by_code = tiling.tiles(level);
            by_code.sort_unstable_by_key(|t| t.code);
            let mut bins = vec![DropMoves::default()];
            bins.par_extend((1..lut.bins()).into_par_iter().map(|bin| {
                let step = options.grid_step(level);
                BinDrops::new(BinSet::new(tiling, lut, &by_code, bin), step).solve()
            }));
            progress("drop moves", u64::from(level) + 1, u64::from(levels));
            bins
        })
        .collect()
}

/// One bin of one level, its codes being dropped from the top.
struct BinDrops<'a> {
    tiling: &'a SphereTiling,
    lut: &'a SphereLut,
    by_code: &'a [SphereTile],
    level: usize,
    bin: usize,
    /// The lower bin's count (or the level above's): the moves' keys
    /// count from it.
    lower: usize,
    /// Whether the four faces of a ring share rows: then a ring orbit's
    /// codes (equal but for the last two bits) drop together.
    ring: bool,
    step: u8,
    /// Where a moved point may lie: the tile grown by three cells (and
    /// the `i8` range). Grown by one, the room of the bin's offsets,
    /// N = 4954 read separation 2.35 and covering 3.41; by two, 20,188
    /// kept a hole of 3.52; by three every count of docs/SPHERE_SWEEP.md
    /// up to level 4 meets issue 18's floors.
    room: Shape,
    /// The bin's points, and a k-d tree of them to find neighbours by.
    sites: Vec<DVec3>,
    tree: ImmutableKdTree<f64, u32, 3, 32>,
    /// Each point's offset and place after the drops so far.
    stored: Vec<[i8; 2]>,
    current: Vec<DVec3>,
}

impl<'a> BinDrops<'a> {
    fn new(set: BinSet<'a>, step: u8) -> Self {
        let lower = set.below();
        let BinSet {
            tiling,
            lut,
            by_code,
            bin,
            sites,
            tree,
            ..
        } = set;
        let level = by_code[0].level as usize;
        let stored: Vec<[i8; 2]> = (by_code[..sites.len()].iter())
            .map(|t| lut.tables[level][bin][lut.row(level, t.index as usize)])
            .collect();
        BinDrops {
            tiling,
            lut,
            by_code,
            level,
            bin,
            lower,
            ring: lut.rows(level) < by_code.len(),
            step,
            room: tiling.shape().dilated().dilated().dilated(),
            tree,
            current: sites.clone(),
            sites,
            stored,
        }
    }

    /// Drops the codes from the top, a ring orbit at a time where rows
    /// are shared (keyed by its highest code), and returns the moves row
    /// by row.
    fn solve(mut self) -> DropMoves {
        let mut rows = vec![Vec::new(); self.lut.rows(self.level)];
        let mut top = self.sites.len();
        while top > self.lower + 1 {
            // at the ring-shared levels the orbit dropped whole, its twins
            // below the lower bin's count too: a request of this bin keeps
            // those, and reads no move for the faces where it does
            let first = match self.ring {
                true => (top - 1) & !3,
                false => top - 1,
            };
            // an orbit the bin's own count splits is missing on some faces
            // even there: its holes stay open, or the bin's own set moved
            let split = self.ring && first + 3 >= self.sites.len();
            if !split {
                let key = (first + 3 * usize::from(self.ring) - self.lower) as u16;
                for (row, offset, turn) in self.drop(first..top) {
                    rows[row].push((key, offset, turn));
                }
            }
            top = first;
        }
        for row in &mut rows {
            row.reverse();
        }
        DropMoves::from_rows(rows)
    }

    /// Drops `codes` and relaxes the kept points beside the hole; stores
    /// the moves (the state follows them) and returns them by row, each
    /// with the turn from its point's face to its nearest dropped code's.
    fn drop(&mut self, codes: std::ops::Range<usize>) -> Vec<(usize, [i8; 2], u8)> {
        let kept = codes.start;
        let spacing = (4.0 * PI / kept as f64).sqrt();
        let within = |code: usize, radius: f64| {
            let at = (skew() * self.sites[code]).to_array();
            (self
                .tree
                .within_unsorted::<SquaredEuclidean>(&at, radius * radius)
                .into_iter())
            .map(|near| near.item as usize)
        };
        // the hole: these codes and those dropped before them nearby
        let hole: Vec<DVec3> = (codes.clone().flat_map(|c| within(c, HOLE * spacing)))
            .filter(|&c| c >= kept)
            .map(|c| self.current[c])
            .collect();
        let mut around: Vec<usize> = (codes.clone().flat_map(|c| within(c, AROUND * spacing)))
            .filter(|&c| c < kept)
            .collect();
        around.sort_unstable();
        around.dedup();
        let mut points: Vec<DVec3> = around.iter().map(|&c| self.current[c]).collect();
        let movable: Vec<usize> = (0..around.len())
            .filter(|&k| {
                hole.iter()
                    .any(|h| points[k].distance(*h) < REACH * spacing)
            })
            .collect();
        if movable.is_empty() {
            return Vec::new();
        }
        // how far apart the moved points must stay: the guard, or what
        // they kept before
        let least = (GUARD * spacing).min(nearest_pair(&points, &movable));
        relax_among_fixed(&mut points, &movable, ITERATIONS)
            .expect("the bin's points are unit vectors");
        let targets: Vec<[f64; 2]> = (movable.iter())
            .map(|&k| self.local_for(around[k], points[k]))
            .collect();
        // the moves all the way, or a share of the way where a point the
        // room stopped short left another too close to it
        let Some((offsets, placed)) = (SHARES.iter())
            .map(|&share| self.moved_share(&around, &movable, &targets, share))
            .find(|(_, placed)| self.clear(&around, &movable, placed, least))
        else {
            return Vec::new();
        };
        // one move a row: a ring's twins moved alike, the lowest code's kept
        let mut moves: Vec<(usize, usize, [i8; 2])> = (movable.iter().zip(offsets).zip(placed))
            .filter(|&((&k, _), p)| p.distance(self.current[around[k]]) >= SHORTEST * spacing)
            .map(|((&k, offset), _)| {
                let code = around[k];
                let row = self.lut.row(self.level, self.by_code[code].index as usize);
                (row, code, offset)
            })
            .collect();
        moves.sort_unstable_by_key(|&(row, code, _)| (row, code));
        moves.dedup_by_key(|m| m.0);
        for &(_, code, offset) in &moves {
            let twins = match self.ring {
                true => (code & !3..(code | 3) + 1).filter(|&c| c < kept).collect(),
                false => vec![code],
            };
            for twin in twins {
                self.stored[twin] = offset;
                self.current[twin] = self.place(twin, offset);
            }
        }
        let turn = |code: usize| {
            let nearest = (codes.clone().filter(|&c| c < self.sites.len()))
                .min_by(|&a, &b| {
                    let d = |c: usize| self.sites[c].distance(self.sites[code]);
                    d(a).total_cmp(&d(b))
                })
                .expect("a drop drops a code");
            (self.by_code[nearest].face + 4 - self.by_code[code].face % 4) % 4
        };
        (moves.into_iter())
            .map(|(row, code, offset)| (row, offset, if self.ring { turn(code) } else { 0 }))
            .collect()
    }

    /// The offset (tile frame, inside the tile's room) whose point is
    /// nearest `target`.
    fn local_for(&self, code: usize, target: DVec3) -> [f64; 2] {
        let tile = &self.by_code[code];
        let mut local = dequantise(self.stored[code]);
        for _ in 0..3 {
            let site = self.tiling.face_point(tile, local).to_vec();
            local = to_local(self.tiling, tile, local, site, target);
        }
        let row = self.lut.row(self.level, tile.index as usize);
        let bin_offset = dequantise(self.lut.tables[self.level][self.bin][row]);
        within_room(&self.room, bin_offset, local)
    }

    /// The movable points' stored offsets `share` of the way from where
    /// they are to `targets`, and their points.
    fn moved_share(
        &self,
        around: &[usize],
        movable: &[usize],
        targets: &[[f64; 2]],
        share: f64,
    ) -> (Vec<[i8; 2]>, Vec<DVec3>) {
        (movable.iter().zip(targets))
            .map(|(&k, target)| {
                let code = around[k];
                let from = dequantise(self.stored[code]);
                let to = [0, 1].map(|c| from[c] + share * (target[c] - from[c]));
                let offset = SphereLut::quantise_on(to, self.step);
                (offset, self.place(code, offset))
            })
            .unzip()
    }

    /// Whether the points `placed` (the movable ones') keep `least` from
    /// every other point about the hole.
    fn clear(&self, around: &[usize], movable: &[usize], placed: &[DVec3], least: f64) -> bool {
        let mut points: Vec<DVec3> = around.iter().map(|&c| self.current[c]).collect();
        for (&k, &p) in movable.iter().zip(placed) {
            points[k] = p;
        }
        nearest_pair(&points, movable) >= least
    }

    /// The point of `code`'s tile at stored offset `offset`.
    fn place(&self, code: usize, offset: [i8; 2]) -> DVec3 {
        self.tiling
            .face_point(&self.by_code[code], dequantise(offset))
            .to_vec()
    }
}

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
//!
//! Level 6's moves for every drop took 2.15 MB (1.30 MB storing none
//! shorter than 0.2 spacings, covering then 3.38-3.75), past the 4 MB
//! budget. It keeps its sibling fills, and a drop moves points only where
//! it leaves a hole the fills do not close (see [`HOLE_WIDER`]).

use super::{skew, to_local, within_room, BinSet, BuildOptions, MoveReach, Progress};
use crate::lut::{dequantise, move_key_base, DropMoves, SphereLut};
use crate::polyomino::Shape;
use crate::relax::relax_among_fixed;
use crate::tiling::sphere::{SphereTile, SphereTiling};
use glam::DVec3;
use kiddo::immutable::float::kdtree::ImmutableKdTree;
use kiddo::SquaredEuclidean;
use rayon::prelude::*;
use std::f64::consts::PI;

/// Points dropped within this many spacings of a new hole are one hole
/// with it.
const HOLE: f64 = 2.0;
/// Neighbours of a hole, in spacings, whose cells bound the moving points'.
const AROUND: f64 = 5.5;
/// Lloyd iterations a drop.
const ITERATIONS: usize = 5;
/// A point its room stops this many spacings short of its relaxed place
/// is pinned where the room lets it go, and the others relax again (see
/// `BinDrops::relax_within_room`).
const STOPPED: f64 = 0.1;
/// Rounds of pinning a drop, at most.
const PIN_ROUNDS: usize = 2;
/// On the levels that keep their sibling fills, a drop moves points only
/// where, the fills in place, it leaves a hole wider than this over
/// sqrt(N) (the widest Voronoi cell radius of the kept points about it).
/// Over 30 log-spaced counts on level 6: 3.25 stored 350 kB of moves and
/// kept covering within 3.383 at all 30; 3.35, 219 kB and 29 of 30
/// within 3.4 (3.408); the fills alone, 1 of 30 (worst 4.39).
const HOLE_WIDER: f64 = 3.35;

/// Shares of the way to their relaxed places the moves of one drop go,
/// the first that keeps the points [`GUARD`] apart winning.
const SHARES: [f64; 5] = [1.0, 0.75, 0.5, 0.25, 0.0];
/// Spacings (at the bin's lowest count, the densest set a pair made at
/// any drop of the bin stays in) a moved point keeps from every other, or
/// what it kept before: a point the room stops short can leave a
/// neighbour too close (N = 6769: 2.13 / sqrt(N) without the guard).
/// Measured at the spacing of the drop, a pair made at the bin's top
/// count read 2.39 at N = 120,000.
const GUARD: f64 = 0.70;

/// A move as a drop makes it: `(row, code, offset)`.
type Move = (usize, usize, [i8; 2]);

/// The distance from `points[k]` to its nearest other point.
fn nearest(points: &[DVec3], k: usize) -> f64 {
    (0..points.len())
        .filter(|&j| j != k)
        .map(|j| points[k].distance(points[j]))
        .fold(f64::INFINITY, f64::min)
}

/// The drop moves of levels `0..options.drop_move_levels`, per level and
/// bin (bin 0, whose requests come from the level above, has none).
/// `tiling` reads `lut`'s sibling fills, which the levels from
/// `options.selective_moves_from` on keep.
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
            let fills = level >= u32::from(options.selective_moves_from);
            bins.par_extend((1..lut.bins()).into_par_iter().map(|bin| {
                let step = options.grid_step(level);
                let set = BinSet::new(tiling, lut, &by_code, bin);
                // `build` checks that every level with drop moves has an entry
                let reach = options.move_reach[level as usize];
                BinDrops::new(set, step, fills, reach).solve()
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
    /// How far about a hole points move, and the shortest move stored.
    reach: MoveReach,
    /// The [`GUARD`] distance.
    guard: f64,
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
    /// On a level that keeps its sibling fills, the [`HOLE_WIDER`] a drop
    /// moves points past, and whether each point has moved (the others
    /// follow their fills).
    hole_wider: Option<f64>,
    moved: Vec<bool>,
}

impl<'a> BinDrops<'a> {
    /// The drops of `set`'s bin, its moves on a grid of `step` within
    /// `reach`; with `fills`, on top of the level's sibling fills.
    fn new(set: BinSet<'a>, step: u8, fills: bool, reach: MoveReach) -> Self {
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
            guard: GUARD * (4.0 * PI / lower.max(1) as f64).sqrt(),
            step,
            reach,
            room: tiling.shape().dilated().dilated().dilated(),
            tree,
            current: sites.clone(),
            hole_wider: fills.then_some(HOLE_WIDER),
            moved: vec![false; sites.len()],
            sites,
            stored,
        }
    }

    /// Drops the codes from the top, a ring orbit at a time where rows
    /// are shared (keyed by its place among the orbits from the lower
    /// count's), and returns the moves row by row, as shifts from the
    /// bin's offsets.
    fn solve(mut self) -> DropMoves {
        let mut rows = vec![Vec::new(); self.lut.rows(self.level)];
        let bin_offsets = &self.lut.tables[self.level][self.bin];
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
                let from = move_key_base(self.lower as u64, self.ring) as usize;
                let key = (first - from) / if self.ring { 4 } else { 1 };
                // `build` checks that every bin's keys fit
                let key = u16::try_from(key).expect("a bin's keys fit 16 bits");
                for (row, offset, turn) in self.drop(first..top) {
                    let shift = [0, 1].map(|c| offset[c].wrapping_sub(bin_offsets[row][c]));
                    rows[row].push((key, shift, turn));
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
    /// On a level that keeps its fills, the points about the hole first
    /// take the fills a request keeping the codes below `codes` reads, and
    /// the drop moves points only if the hole stays wider than
    /// [`HOLE_WIDER`].
    fn drop(&mut self, codes: std::ops::Range<usize>) -> Vec<(usize, [i8; 2], u8)> {
        let kept = codes.start;
        let spacing = (4.0 * PI / kept as f64).sqrt();
        // the hole: these codes and those dropped before them nearby
        let mut hole: Vec<DVec3> = (codes.clone().flat_map(|c| self.within(c, HOLE * spacing)))
            .filter(|&c| c >= kept)
            .map(|c| self.current[c])
            .collect();
        let mut around: Vec<usize> = (codes.clone())
            .flat_map(|c| self.within(c, AROUND * spacing))
            .filter(|&c| c < kept)
            .collect();
        around.sort_unstable();
        around.dedup();
        let (mut moves, mut filled) = (Vec::new(), Vec::new());
        if let Some(wider) = self.hole_wider {
            let vacated;
            (moves, vacated) = self.follow_fills(&around, kept);
            // the places the fills vacate open the hole too, and the guard
            // must see the points about them: without, points the drop
            // moved crowded others beyond `around` (0.71 / sqrt(N))
            for &(code, place) in &vacated {
                hole.push(place);
                around.extend((self.within(code, AROUND * spacing)).filter(|&c| c < kept));
                filled.push(code);
            }
            around.sort_unstable();
            around.dedup();
            if self.widest_hole(&around, &hole, spacing) * (kept as f64).sqrt() <= wider {
                return self.by_row(moves, codes);
            }
        }
        let start: Vec<DVec3> = around.iter().map(|&c| self.current[c]).collect();
        let movable: Vec<usize> = (0..around.len())
            .filter(|&k| !filled.contains(&around[k]))
            .filter(|&k| self.in_reach(start[k], &hole, spacing))
            .collect();
        if movable.is_empty() {
            return self.by_row(moves, codes);
        }
        let (movable, targets) = self.relax_within_room(&around, &start, movable, spacing);
        let shortest = self.reach.shortest * spacing;
        // the moves all the way, or a share of the way where a point the
        // room stopped short left another too close to it
        let relaxed = (SHARES.iter())
            .map(|&share| self.share_moves(&around, &movable, &targets, share, shortest))
            .find(|moves| self.clear(&around, &start, moves, kept));
        // they take the rows of the fills' reverts (see `follow_fills`)
        moves = relaxed
            .unwrap_or_default()
            .into_iter()
            .chain(moves)
            .collect();
        self.by_row(moves, codes)
    }

    /// Kept codes within `radius` of `code`'s bin place.
    fn within(&self, code: usize, radius: f64) -> impl Iterator<Item = usize> {
        let at = (skew() * self.sites[code]).to_array();
        (self
            .tree
            .within_unsorted::<SquaredEuclidean>(&at, radius * radius))
        .into_iter()
        .map(|near| near.item as usize)
    }

    /// Moves the points of `around` that have not moved to the fills a
    /// request keeping `kept` codes reads. Where that crowds a point, its
    /// family (siblings: codes equal modulo the parents' count) keeps its
    /// previous offsets, as moves: reverting the one sibling alone left a
    /// pair 1.93 / sqrt(N) apart. Returns those moves `(row, code,
    /// offset)`, and each code that took a fill with the place it left.
    fn follow_fills(&mut self, around: &[usize], kept: usize) -> (Vec<Move>, Vec<(usize, DVec3)>) {
        let before: Vec<DVec3> = around.iter().map(|&c| self.current[c]).collect();
        // (index into `around`, offset before)
        let mut changed: Vec<(usize, [i8; 2])> = Vec::new();
        for (k, &code) in around.iter().enumerate() {
            if self.moved[code] {
                continue;
            }
            let fill = self.fill_offset(code, kept);
            if fill != self.stored[code] {
                changed.push((k, self.stored[code]));
                self.stored[code] = fill;
                self.current[code] = self.place(code, fill);
            }
        }
        let family = |code: usize| code % (self.by_code.len() / 4);
        let mut reverted = vec![false; changed.len()];
        let mut moves = Vec::new();
        loop {
            let now: Vec<DVec3> = around.iter().map(|&c| self.current[c]).collect();
            let crowded: Vec<usize> = (changed.iter().zip(&reverted))
                .filter(|&(&(k, _), &reverted)| {
                    !reverted && nearest(&now, k) < self.guard.min(nearest(&before, k))
                })
                .map(|(&(k, _), _)| family(around[k]))
                .collect();
            if crowded.is_empty() {
                break;
            }
            for (&(k, previous), reverted) in changed.iter().zip(&mut reverted) {
                let code = around[k];
                if *reverted || !crowded.contains(&family(code)) {
                    continue;
                }
                *reverted = true;
                for twin in self.twins(code, kept) {
                    self.stored[twin] = previous;
                    self.current[twin] = self.place(twin, previous);
                    self.moved[twin] = true;
                }
                moves.push((self.row_of(code), code, previous));
            }
        }
        let vacated = (changed.iter().zip(&reverted))
            .filter(|(_, &reverted)| !reverted)
            .map(|(&(k, _), _)| (around[k], before[k]))
            .collect();
        (moves, vacated)
    }

    /// Whether `point` lies within the reach's spacings of a point of `hole`.
    fn in_reach(&self, point: DVec3, hole: &[DVec3], spacing: f64) -> bool {
        let reach = self.reach.reach * spacing;
        hole.iter().any(|h| point.distance(*h) < reach)
    }

    /// The widest Voronoi cell radius of the points of `around` within
    /// the reach's spacings of `hole`, among the points of `around`.
    fn widest_hole(&self, around: &[usize], hole: &[DVec3], spacing: f64) -> f64 {
        let points: Vec<DVec3> = around.iter().map(|&c| self.current[c]).collect();
        let mut normals = Vec::new();
        (0..points.len())
            .filter(|&k| self.in_reach(points[k], hole, spacing))
            .map(|k| crate::voronoi::cell_of(&points, None, k, &mut normals, f64::INFINITY).radius)
            .fold(0.0, f64::max)
    }

    /// Stores `moves` `(row, code, offset)` of the drop of `codes` (the
    /// state follows them) and returns them one a row, the lowest code's,
    /// each with the turn from its point's face to its nearest dropped
    /// code's.
    fn by_row(
        &mut self,
        mut moves: Vec<Move>,
        codes: std::ops::Range<usize>,
    ) -> Vec<(usize, [i8; 2], u8)> {
        moves.sort_by_key(|&(row, code, _)| (row, code));
        moves.dedup_by_key(|m| m.0);
        for &(_, code, offset) in &moves {
            for twin in self.twins(code, codes.start) {
                self.stored[twin] = offset;
                self.current[twin] = self.place(twin, offset);
                self.moved[twin] = true;
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

    /// The offset a request keeping `count` codes reads for `code` (this
    /// bin's, or a sibling fill), as stored.
    fn fill_offset(&self, code: usize, count: usize) -> [i8; 2] {
        let fraction = count as f64 / self.by_code.len() as f64;
        let offset = self.tiling.offset(&self.by_code[code], fraction);
        SphereLut::quantise_on(offset, 1)
    }

    /// The row of `code`'s tile.
    fn row_of(&self, code: usize) -> usize {
        self.lut.row(self.level, self.by_code[code].index as usize)
    }

    /// Relaxes `movable` (indices into `around`, at `start`) among the
    /// others and returns the points that move with their target offsets.
    /// A point its room stops short of its place is pinned where the room
    /// lets it go, and the rest relax again around it: relaxed as if it
    /// had gone all the way, they left its side of the hole open (N =
    /// 70,381: a point 4 cells from its tile, covering 3.49 / sqrt(N)).
    fn relax_within_room(
        &self,
        around: &[usize],
        start: &[DVec3],
        mut movable: Vec<usize>,
        spacing: f64,
    ) -> (Vec<usize>, Vec<[f64; 2]>) {
        let mut pinned: Vec<(usize, [f64; 2])> = Vec::new();
        for round in 0..=PIN_ROUNDS {
            let mut points = start.to_vec();
            for &(k, target) in &pinned {
                points[k] = self.point_at(around[k], target);
            }
            relax_among_fixed(&mut points, &movable, ITERATIONS)
                .expect("the bin's points are unit vectors");
            let targets: Vec<[f64; 2]> = (movable.iter())
                .map(|&k| self.local_for(around[k], points[k]))
                .collect();
            let stuck: Vec<bool> = (movable.iter().zip(&targets))
                .map(|(&k, &t)| self.point_at(around[k], t).distance(points[k]) > STOPPED * spacing)
                .collect();
            if round == PIN_ROUNDS || !stuck.contains(&true) {
                let (mut moved, mut to): (Vec<usize>, Vec<[f64; 2]>) = pinned.into_iter().unzip();
                moved.extend(movable);
                to.extend(targets);
                return (moved, to);
            }
            let mut free = Vec::new();
            for ((k, target), stuck) in movable.into_iter().zip(targets).zip(stuck) {
                match stuck {
                    true => pinned.push((k, target)),
                    false => free.push(k),
                }
            }
            movable = free;
        }
        unreachable!("the last round returns")
    }

    /// The offset (tile frame, inside the tile's room) whose point is
    /// nearest `target`.
    fn local_for(&self, code: usize, target: DVec3) -> [f64; 2] {
        let tile = &self.by_code[code];
        let mut local = dequantise(self.stored[code]);
        for _ in 0..3 {
            let site = self.point_at(code, local);
            local = to_local(self.tiling, tile, local, site, target);
        }
        let row = self.lut.row(self.level, tile.index as usize);
        let bin_offset = dequantise(self.lut.tables[self.level][self.bin][row]);
        within_room(&self.room, bin_offset, local)
    }

    /// The moves `share` of the way from where the movable points are to
    /// their `targets`: one a row, `(row, code, offset)`, a ring's twins
    /// moving alike (the lowest moving code's). A point that would move
    /// less than `shortest` stays, as the table will not store its move.
    fn share_moves(
        &self,
        around: &[usize],
        movable: &[usize],
        targets: &[[f64; 2]],
        share: f64,
        shortest: f64,
    ) -> Vec<Move> {
        let mut moves: Vec<Move> = (movable.iter().zip(targets))
            .filter_map(|(&k, target)| {
                let code = around[k];
                let from = dequantise(self.stored[code]);
                let to = [0, 1].map(|c| from[c] + share * (target[c] - from[c]));
                let offset = SphereLut::quantise_on(to, self.step);
                let moved = self.place(code, offset).distance(self.current[code]);
                (moved >= shortest).then_some((self.row_of(code), code, offset))
            })
            .collect();
        moves.sort_unstable_by_key(|&(row, code, _)| (row, code));
        moves.dedup_by_key(|m| m.0);
        moves
    }

    /// The codes a move of `code` places: its ring twins still kept, or
    /// itself.
    fn twins(&self, code: usize, kept: usize) -> Vec<usize> {
        match self.ring {
            true => (code & !3..(code | 3) + 1).filter(|&c| c < kept).collect(),
            false => vec![code],
        }
    }

    /// Whether every point `moves` place keeps the guard, or what it kept
    /// before at `start`, from every other point about the hole: checked
    /// on the points as the table will place them (a point whose move was
    /// too short to store, checked as moved, let a neighbour come within
    /// 2.36 / sqrt(N) of it at N = 120,000).
    fn clear(&self, around: &[usize], start: &[DVec3], moves: &[Move], kept: usize) -> bool {
        let mut points = start.to_vec();
        let mut moved = Vec::new();
        for &(_, code, offset) in moves {
            for twin in self.twins(code, kept) {
                // `around` is sorted; a twin outside it cannot be checked
                let Ok(k) = around.binary_search(&twin) else {
                    return false;
                };
                points[k] = self.place(twin, offset);
                moved.push(k);
            }
        }
        (moved.iter()).all(|&k| nearest(&points, k) >= self.guard.min(nearest(start, k)))
    }

    /// The point of `code`'s tile at stored offset `offset`.
    fn place(&self, code: usize, offset: [i8; 2]) -> DVec3 {
        self.point_at(code, dequantise(offset))
    }

    /// The point of `code`'s tile at offset `local` (tile frame, cells).
    fn point_at(&self, code: usize, local: [f64; 2]) -> DVec3 {
        self.tiling.face_point(&self.by_code[code], local).to_vec()
    }
}

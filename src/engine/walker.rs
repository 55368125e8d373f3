//! The recursion over a tile system and its terminal rule (thinning): see
//! the module doc of [`crate::engine`].

use super::ranking::RankBuckets;
use super::{Sample, Window};
use crate::density::{Density, Region};
use crate::memory;
use crate::tiling::{code_value, TileSystem};
use rayon::prelude::*;
use std::ops::Range;
use std::sync::atomic::{AtomicU64, Ordering};

/// What [`collect_parts`] found besides the samples.
pub(super) struct Collected {
    /// False when some rank lies outside `[0, 1)` (never for the engine's
    /// ranks; not checked without histograms).
    pub(super) in_range: bool,
    /// See [`Walker::excess`].
    pub(super) excess: Option<f64>,
}

/// The accepted samples of each root's subtree, in root order, into
/// `parts` (a list per run of consecutive roots, see [`chunk_roots`];
/// their memory reused); with `histograms`, also each list's count of
/// samples per rank bucket, taken while each root's samples are still in
/// cache.
pub(super) fn collect_parts<S, D>(
    system: &S,
    density: &D,
    magnitude: f64,
    window: Option<&Window<'_, S::Region>>,
    parts: &mut Vec<Vec<Sample<S::Point>>>,
    histograms: Option<(RankBuckets, &mut Vec<Vec<u32>>)>,
) -> Collected
where
    S: TileSystem,
    S::Region: Region<Point = S::Point>,
    D: Density<S::Region> + ?Sized,
{
    let walker = Walker::new(system, density, magnitude, window);
    let threads = rayon::current_num_threads();
    let roots = system.roots();
    // fewer roots than lists leave threads idle (Penrose has one root): the
    // recursion starts from their descendants instead (one thread has
    // nothing to share, and its roots' shares are the better guesses)
    let target = match threads > 1 && roots.len() < LISTS_A_THREAD * threads {
        true => STARTS_A_THREAD * threads,
        false => 0,
    };
    let starts = walker.starts(roots, target);
    // about a start's share of the samples (by the density's average over
    // it): a guess, capped so that a wrong one (or a window's small part
    // of a huge request) reserves little
    let shares: Vec<usize> = starts
        .iter()
        .map(|start| match window {
            Some(_) => 16,
            None => (walker.expected(start) * 1.05).min(MAX_SHARE_HINT) as usize + 16,
        })
        .collect();
    let chunks = chunk_roots(&shares, window.is_some(), threads);
    parts.resize_with(chunks.len(), Vec::new);
    let (buckets, mut none) = (histograms.as_ref().map(|h| h.0), Vec::new());
    let counts = histograms.map_or(&mut none, |h| h.1);
    counts.resize_with(chunks.len(), Vec::new);
    let in_range = chunks
        .par_iter()
        .zip(parts.par_iter_mut())
        .zip(counts.par_iter_mut())
        .map(|((chunk, out), counts)| {
            out.clear();
            counts.clear();
            // room for the chunk's shares, so that few outputs regrow (a
            // hint: a refused reservation leaves the list to grow)
            let _ = memory::try_reserve_large(out, shares[chunk.clone()].iter().sum());
            let mut in_range = true;
            for start in &starts[chunk.clone()] {
                let from = out.len();
                walker.visit(start, f64::INFINITY, f64::INFINITY, out);
                // counted while the start's samples are still in cache
                in_range &= buckets.is_none_or(|b| b.count_into(&out[from..], counts));
            }
            in_range
        })
        .reduce(|| true, |a, b| a && b);
    Collected {
        in_range,
        excess: walker.excess(),
    }
}
/// Consecutive roots whose outputs share a list, by their expected sizes
/// (`shares`): about [`LISTS_A_THREAD`] lists a thread, so that a large
/// request's lists are large enough for huge pages (see [`memory`]; with a
/// list a root, taking 2 * 10^6 samples on a ramp into fresh memory spent
/// about a third of its time in page faults) while the threads still share
/// the work. A window's roots keep a list each: their shares are unknown.
pub(super) fn chunk_roots(shares: &[usize], window: bool, threads: usize) -> Vec<Range<usize>> {
    if window {
        return (0..shares.len()).map(|r| r..r + 1).collect();
    }
    let target = (shares.iter().sum::<usize>() / (LISTS_A_THREAD * threads.max(1))).max(1);
    let mut chunks = Vec::new();
    let (mut start, mut size) = (0, 0);
    for (r, &share) in shares.iter().enumerate() {
        size += share;
        if size >= target {
            chunks.push(start..r + 1);
            (start, size) = (r + 1, 0);
        }
    }
    if start < shares.len() {
        chunks.push(start..shares.len());
    }
    chunks
}
/// Starts a thread where roots are few (see [`Walker::starts`]): many, as
/// their shares of the samples are estimates ([`Walker::expected`]) and
/// the lists cut from them by those shares balance only when each start
/// is small. On 2 threads, Penrose at 10^6 uniform samples took
/// 109, 86 and 76 ms with 8, 32 and 128 starts a thread (137 ms on one
/// thread; scratch timer, median of 30).
pub(super) const STARTS_A_THREAD: usize = 128;
/// Rounds of [`Walker::starts`]: enough for Penrose's single root, whose
/// triangles have one to four children, to reach hundreds of starts.
pub(super) const MAX_START_ROUNDS: usize = 16;
/// Output lists a thread in [`chunk_roots`]. In scratch runs of a
/// 10^6-sample spherical cap on 2 threads (interleaved, best of 8), 8 a
/// thread ran as fast as a list a root, 4 about 5 % slower (likely a
/// thread left alone with the last large list) and 64 slower again.
pub(super) const LISTS_A_THREAD: usize = 8;
/// The most samples reserved for a root's output before it is known
/// (24 MB of planar samples).
pub(super) const MAX_SHARE_HINT: f64 = (1 << 20) as f64;
/// How far (relative) a density may exceed its bound where a sample lands
/// before the request fails ([`Walker::excess`]): rounding only. The
/// shipped densities never exceed theirs.
pub(super) const BOUND_TOLERANCE: f64 = 1e-9;
/// The least share of its bound a tile's placing bound may be and still
/// pick its bin ([`Walker::placing_bound`]): below it the tile lies beside
/// a step, where placing for the bound keeps the local bias smaller.
const PLACING_SHARE: f64 = 0.5;
pub(super) struct Walker<'a, S: TileSystem, D: ?Sized> {
    system: &'a S,
    density: &'a D,
    /// `system.capacity(level)` for levels `0..=max_level + 1`.
    capacities: Vec<f64>,
    magnitude: f64,
    mean: f64,
    /// `magnitude / mean`, when finite: see [`Walker::scaled`].
    per_mean: Option<f64>,
    constant: Option<f64>,
    /// The least a code gains before it is compared with a density: 1/2
    /// for a constant density (thresholds round), 0 for a varying one
    /// (codes gain a dither in `[0, 1)`).
    least_dither: f64,
    /// The dither's seed ([`Density::seed`]).
    seed: u64,
    /// Only tiles this accepts are visited (see [`super::collect_within`]).
    window: Option<&'a Window<'a, S::Region>>,
    /// The largest ratio, above 1, of the density where a sample landed
    /// to its tile's bound (`f64` bits; 0 while none): see
    /// [`Walker::excess`].
    excess: AtomicU64,
}
impl<'a, S, D> Walker<'a, S, D>
where
    S: TileSystem,
    S::Region: Region<Point = S::Point>,
    D: Density<S::Region> + ?Sized,
{
    pub(super) fn new(
        system: &'a S,
        density: &'a D,
        magnitude: f64,
        window: Option<&'a Window<'a, S::Region>>,
    ) -> Self {
        // thresholds compare codes, so the request goes in code units
        let magnitude = magnitude * system.codes_per_sample();
        Walker {
            system,
            density,
            capacities: (0..=system.max_level() + 1)
                .map(|level| system.capacity(level))
                .collect(),
            magnitude,
            mean: density.mean(),
            per_mean: Some(magnitude / density.mean()).filter(|k| k.is_finite()),
            constant: density.constant(),
            least_dither: if density.constant().is_some() {
                0.5
            } else {
                0.0
            },
            seed: density
                .seed()
                .unwrap_or(0)
                .wrapping_mul(0x9E37_79B9_7F4A_7C15),
            window,
            excess: AtomicU64::new(0),
        }
    }

    /// The largest ratio of the density where a sample landed to the
    /// bound of its tile, when a density exceeded its bound by more than
    /// rounding ([`BOUND_TOLERANCE`]). Such a density's samples are
    /// biased: a candidate is kept with probability `density / capacity`
    /// only if its bound is at least the density (see the module doc), and
    /// otherwise with its bound's, too seldom. Seen only where a sample
    /// lands, so a request can pass while another of the same density
    /// fails.
    pub(super) fn excess(&self) -> Option<f64> {
        let ratio = f64::from_bits(self.excess.load(Ordering::Relaxed));
        (ratio > 1.0 + BOUND_TOLERANCE).then_some(ratio)
    }

    /// Records that the density where a sample landed is `ratio` times
    /// its tile's bound.
    #[cold]
    fn note_excess(&self, ratio: f64) {
        // positive f64 bits order as the values do
        self.excess.fetch_max(ratio.to_bits(), Ordering::Relaxed);
    }

    /// A density value (a bound or an average) in code units: `value *
    /// magnitude / mean`. One multiply where `magnitude / mean` is finite
    /// (divisions on the chain from a tile's density to its sample's
    /// position slowed ramp requests by about 5 %); dividing first
    /// otherwise, so that means down to subnormals do not overflow.
    #[inline(always)]
    fn scaled(&self, value: f64) -> f64 {
        match self.per_mean {
            Some(k) => value * k,
            None => self.magnitude * (value / self.mean),
        }
    }

    /// The tiles to visit, in order: the roots, each replaced by its
    /// children while there are fewer than `target` (see [`Walker::split`]),
    /// so that a system of few roots (Penrose has one) gives every thread
    /// work. A window keeps the roots.
    pub(super) fn starts(&self, roots: Vec<S::Tile>, target: usize) -> Vec<S::Tile> {
        if self.window.is_some() {
            return roots;
        }
        let mut rounds = 0;
        let more = |tiles: &[S::Tile]| {
            rounds += 1;
            rounds <= MAX_START_ROUNDS && tiles.len() < target
        };
        self.split(roots, more, |_| true)
    }

    /// `tiles` with each tile that `wanted` picks replaced by its children
    /// where its visit recurses into every child with a bound that makes
    /// none of them terminal (so its bound decides nothing for them:
    /// visiting them as roots is visiting it, and the output is the same,
    /// in the same order), round after round while `more` allows and some
    /// tile was replaced.
    pub(super) fn split(
        &self,
        mut tiles: Vec<S::Tile>,
        mut more: impl FnMut(&[S::Tile]) -> bool,
        wanted: impl Fn(&S::Tile) -> bool,
    ) -> Vec<S::Tile> {
        while more(&tiles) {
            let mut next = Vec::with_capacity(tiles.len());
            let mut split = false;
            for tile in tiles {
                if !(wanted(&tile) && self.recurses_into_all(&tile)) {
                    next.push(tile);
                    continue;
                }
                // (a Penrose triangle may have a single child)
                split = true;
                let count = self.system.child_count(&tile);
                next.extend((0..count).map(|i| self.system.child(&tile, i)));
            }
            tiles = next;
            if !split {
                break;
            }
        }
        tiles
    }

    /// About how many samples a tile's subtree holds: its density's
    /// average in code units over the codes of its level (each of the
    /// level's codes stands for a tile's share of the domain, and a root
    /// may reach beyond the domain, as Penrose's does).
    pub(super) fn expected(&self, tile: &S::Tile) -> f64 {
        let average = self
            .constant
            .unwrap_or_else(|| self.density.average(&self.system.region(tile)));
        self.scaled(average) / self.capacities[self.system.level(tile) as usize]
    }

    /// Whether [`Walker::visit`] of a tile not terminal by its parent visits
    /// every child, with a bound that makes none of them terminal.
    fn recurses_into_all(&self, tile: &S::Tile) -> bool {
        let level = self.system.level(tile);
        if level >= self.system.max_level() {
            return false;
        }
        let region = self.constant.is_none().then(|| self.system.region(tile));
        let bound = self.own_bound(region.as_ref());
        // (false for a NaN bound, as for a zero one)
        bound > 0.0 && self.capacities[level as usize + 1] < bound
    }

    /// A tile's own scaled bound, with the scaled bound over its placing
    /// region when that is sure to be needed (the parent's bound
    /// `parent_bound` makes the tile's children terminal, so the tile or
    /// they are placed; [`Walker::placing_bound`]): one call of
    /// [`Density::bounds`] shares the work of the two.
    #[inline(always)]
    fn own_bounds(
        &self,
        tile: &S::Tile,
        level: u32,
        parent_bound: f64,
        region: Option<&S::Region>,
    ) -> (f64, Option<f64>) {
        if let (None, Some(region)) = (self.constant, region) {
            if self.capacities[level as usize + 1] >= parent_bound {
                if let Some(placing) = self.system.placing_region(tile, region) {
                    let (bound, placing) = self.density.bounds(region, &placing);
                    return (self.scaled(bound), Some(self.scaled(placing)));
                }
            }
        }
        (self.own_bound(region), None)
    }

    /// A tile's own scaled bound; `region` may be `None` only for a
    /// constant density.
    #[inline(always)]
    fn own_bound(&self, region: Option<&S::Region>) -> f64 {
        match (self.constant, region) {
            (Some(c), _) => self.magnitude * (c / self.mean),
            (None, Some(region)) => self.scaled(self.density.bound(region)),
            (None, None) => unreachable!("a region exists whenever the density varies"),
        }
    }

    /// `parent_bound`: the parent's scaled bound, which bounds this tile
    /// too: a tile it already makes terminal needs no bound of its own (most
    /// tiles: those the recursion stops at), and one it also rejects is
    /// skipped before its region is computed. Such a tile is placed for
    /// `parent_placing`, its parent's placing bound.
    pub(super) fn visit(
        &self,
        tile: &S::Tile,
        parent_bound: f64,
        parent_placing: f64,
        out: &mut Vec<Sample<S::Point>>,
    ) {
        let level = self.system.level(tile);
        let capacity = self.capacities[level as usize];
        let terminal_by_parent = capacity >= parent_bound;
        if terminal_by_parent
            && code_value(self.system.code(tile)) + self.least_dither >= parent_bound
        {
            return;
        }
        // the region is built in place and lent (an `Option` of it would be
        // a copy of a large struct per tile)
        if self.constant.is_some() && self.window.is_none() {
            self.decide(
                tile,
                level,
                capacity,
                (parent_bound, parent_placing),
                None,
                out,
            );
        } else {
            let region = self.system.region(tile);
            if self.window.is_some_and(|window| !window(&region)) {
                return;
            }
            self.decide(
                tile,
                level,
                capacity,
                (parent_bound, parent_placing),
                Some(&region),
                out,
            );
        }
    }

    /// [`Walker::visit`] past its first tests: the tile's bound decides
    /// whether it is terminal, and a terminal tile's code and the density
    /// where its sample lands whether it is kept; the others recurse.
    #[inline(always)]
    fn decide(
        &self,
        tile: &S::Tile,
        level: u32,
        capacity: f64,
        (parent_bound, parent_placing): (f64, f64),
        region: Option<&S::Region>,
        out: &mut Vec<Sample<S::Point>>,
    ) {
        let (bound, known_placing) = match capacity >= parent_bound {
            true => (parent_bound, None),
            false => self.own_bounds(tile, level, parent_bound, region),
        };
        if bound.is_nan() || bound <= 0.0 {
            return; // nothing to place here (zero density)
        }
        if capacity >= bound || level >= self.system.max_level() {
            if !self.system.carries_sample(tile) {
                return;
            }
            let code = code_value(self.system.code(tile));
            if code + self.least_dither >= bound {
                return; // not even the bound would keep it
            }
            let placing = match (capacity >= parent_bound, region) {
                (true, _) => parent_placing,
                (false, Some(region)) => self.placing_bound(tile, region, bound, known_placing),
                (false, None) => bound, // a constant density
            };
            return self.emit(tile, level, code, bound, placing, out);
        }
        let placing = match (self.capacities[level as usize + 1] >= bound, region) {
            (true, Some(region)) => self.placing_bound(tile, region, bound, known_placing),
            _ => bound,
        };
        self.visit_children(tile, level, bound, placing, out);
    }

    /// What picks the bin the tile's sample, or its children's when it
    /// makes them terminal, is placed for: the scaled bound over its
    /// placing region ([`TileSystem::placing_region`]) where that is at
    /// least [`PLACING_SHARE`] of its bound `bound` (a smooth density), else
    /// `bound` (beside a step); see the module doc, Two bounds. `region`:
    /// the tile's region; `known`: the scaled bound over its placing region,
    /// if [`Walker::own_bounds`] computed it.
    fn placing_bound(
        &self,
        tile: &S::Tile,
        region: &S::Region,
        bound: f64,
        known: Option<f64>,
    ) -> f64 {
        if self.constant.is_some() {
            return bound;
        }
        let placing = match known {
            Some(placing) => placing,
            None => match self.system.placing_region(tile, region) {
                Some(placing) => self.scaled(self.density.bound(&placing)),
                None => return bound,
            },
        };
        match placing >= PLACING_SHARE * bound {
            true => placing.min(bound),
            false => bound,
        }
    }

    /// A child whose parent's bound makes it terminal and does not reject
    /// its code (`code`): [`Walker::decide`]'s terminal step without the
    /// tests the parent made.
    fn visit_terminal(
        &self,
        tile: &S::Tile,
        level: u32,
        code: f64,
        (bound, placing): (f64, f64),
        out: &mut Vec<Sample<S::Point>>,
    ) {
        if self.window.is_some() || !self.system.carries_sample(tile) {
            return self.visit(tile, bound, placing, out);
        }
        self.emit(tile, level, code, bound, placing, out);
    }

    /// The per-tile dither of a varying density's threshold: uniform in
    /// `[0, 1)`, a hash of the tile's code, its level and the density's
    /// seed ([`Density::seed`]), so that it is random over seeds.
    #[inline(always)]
    fn dither(&self, code: f64, level: u32) -> f64 {
        // SplitMix64's finaliser (codes of dithered tiles lie below the
        // bound, far below 2^64)
        // (the increment keeps code 0 of level 0 off the finaliser's fixed
        // point 0, which would keep it at any density)
        let mut z = (code as u64 ^ (u64::from(level) << 58))
            .wrapping_add(self.seed)
            .wrapping_add(0x9E37_79B9_7F4A_7C15);
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^= z >> 31;
        (z >> 11) as f64 * (1.0 / (1u64 << 53) as f64)
    }

    /// Places the sample of a terminal tile of code `code`, scaled bound
    /// `bound` and placing bound `placing` (code units; see
    /// [`Walker::placing_bound`]), if its code is kept (see the module doc).
    #[inline(always)]
    fn emit(
        &self,
        tile: &S::Tile,
        level: u32,
        code: f64,
        bound: f64,
        placing: f64,
        out: &mut Vec<Sample<S::Point>>,
    ) {
        // (the reciprocal keeps the division off the chain from the
        // density to the position)
        let per_tile = 1.0 / self.capacities[level as usize];
        let place = |density: f64| {
            self.system
                .sample_in_domain(tile, (density * per_tile).min(1.0))
        };
        if self.constant.is_some() {
            // known before the sample is placed: a code threshold sits
            // mid-way through its unit of density, so the kept count is
            // the request rounded
            let d = self.magnitude;
            if code + 0.5 < d {
                if let Some(position) = place(d) {
                    out.push(Sample {
                        position,
                        rank: code / d,
                    });
                }
            }
            return;
        }
        // thinning: placed for the placing bound, kept by the density it
        // lands on if the bound allows
        let threshold = code + self.dither(code, level);
        if threshold >= bound {
            return;
        }
        // the tiling may reach past the domain: no sample there
        let Some(position) = place(placing) else {
            return;
        };
        let here = self.scaled(self.density.value(position));
        if here > bound {
            self.note_excess(here / bound);
        }
        if threshold < here {
            out.push(Sample {
                position,
                rank: threshold / here,
            });
        }
    }

    /// Visits the children of a tile whose scaled bound is `bound`; those it
    /// makes terminal are placed for `placing`.
    fn visit_children(
        &self,
        tile: &S::Tile,
        level: u32,
        bound: f64,
        placing: f64,
        out: &mut Vec<Sample<S::Point>>,
    ) {
        // children the bound already rejects (see `visit`'s first test) are
        // skipped before they are built; in code order, the first such child
        // ends the loop
        let count = self.system.child_count(tile);
        let child_rejects = self.capacities[level as usize + 1] >= bound;
        if child_rejects && self.system.child_by_code_rank(tile, 0).is_some() {
            for rank in 0..count {
                let Some(i) = self.system.child_by_code_rank(tile, rank) else {
                    break;
                };
                let code = code_value(self.system.child_code(tile, i));
                if code + self.least_dither >= bound {
                    break;
                }
                self.visit_terminal(
                    &self.system.child(tile, i),
                    level + 1,
                    code,
                    (bound, placing),
                    out,
                );
            }
            return;
        }
        for i in 0..count {
            if child_rejects
                && code_value(self.system.child_code(tile, i)) + self.least_dither >= bound
            {
                continue;
            }
            self.visit(&self.system.child(tile, i), bound, placing, out);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Visiting the starts gives what visiting the roots gives, sample for
    /// sample in the same order, and a single root becomes many starts.
    #[test]
    fn starts_visit_as_the_roots_do() {
        use crate::density::{plane::Ramp, sphere::Cap, Uniform};
        use crate::tiling::{penrose::PenroseTiling, sphere::SphereTiling};
        fn check<S, D>(system: &S, density: &D, magnitudes: &[f64]) -> usize
        where
            S: TileSystem,
            S::Point: PartialEq + std::fmt::Debug,
            S::Region: Region<Point = S::Point>,
            D: Density<S::Region>,
        {
            let mut most = 0;
            for &magnitude in magnitudes {
                let walker = Walker::new(system, density, magnitude, None);
                let (mut by_roots, mut by_starts) = (Vec::new(), Vec::new());
                for root in system.roots() {
                    walker.visit(&root, f64::INFINITY, f64::INFINITY, &mut by_roots);
                }
                let starts = walker.starts(system.roots(), 64);
                most = most.max(starts.len());
                for start in &starts {
                    walker.visit(start, f64::INFINITY, f64::INFINITY, &mut by_starts);
                }
                assert!(!by_roots.is_empty());
                assert_eq!(by_roots, by_starts, "magnitude {magnitude}");
            }
            most
        }
        let magnitudes = [1.0, 10.0, 1000.0, 1e5];
        let penrose = PenroseTiling::default();
        assert!(check(&penrose, &Ramp, &magnitudes) >= 64);
        assert!(check(&penrose, &Uniform, &magnitudes) >= 64);
        let cap = Cap::new(10.0, 20.0, 5.0, 100.0).unwrap();
        check(&SphereTiling::default(), &cap, &[10.0, 1e4]);
    }
}

//! The adaptive recursion shared by every tile system.
//!
//! ```text
//! visit(tile, b = the parent's scaled bound, which bounds the tile too):
//!     if capacity(level) >= b:                     terminal, its own bound unneeded
//!         if code(tile) >= b: return               (rejected unseen)
//!     else b = magnitude * bound(tile) / mean;  terminal if capacity(level) >= b
//!     if terminal:
//!         constant density d: keep if code(tile) + 1/2 < d, at sample(tile, d / capacity(level))
//!         else (thinning): t = code(tile) + u, u a seeded dither in [0, 1)
//!             p = sample(tile, b / capacity(level)), h = magnitude * density(p) / mean
//!             keep p if t < h, with rank t / h
//!     else: visit every child
//! ```
//!
//! **Why the expectation is exact.** Under a uniformly random rotation of
//! the density (a random toroidal shift on the plane), the tile of a given
//! code at a given level lands anywhere with uniform probability, and so
//! does its candidate point `p`; the dither makes `code + u` uniform over
//! `[0, capacity)` across codes and seeds. A candidate at `x` is then kept
//! with probability `h(x) / capacity(level)`, and the candidates of a level
//! have intensity `capacity(level)` per domain: their product, the expected
//! sample density at `x`, is `magnitude * density(x) / mean` whatever the
//! level, with no dependence on the tile's average. This holds while the
//! candidate's place does not follow the density across an edge: a
//! placement for the tile's average (which moves with where an edge
//! crosses the tile) left the dim side of a step 10 % short within a
//! sample spacing of it, and a placement for the bound, which is constant
//! over a neighbourhood wider than the tile, does not (`tests/bias.rs`).
//! Keeping by the average instead (the earlier rules) kept the density
//! smoothed by the tile's shape: 1-3 % biased on textured maps. Without a
//! seed the dither is a fixed hash: the set is deterministic.
//!
//! Bounds are conservative, so `h <= b <= capacity(level)` and a kept
//! probability never saturates (except at the deepest level). A tile
//! whose code is at least its bound cannot be kept and is skipped before
//! its sample is placed.
//! Children are skipped on their code alone when `b` makes them terminal
//! and rejects them; systems that know their children's code order
//! ([`TileSystem::child_by_code_rank`]) are visited in it, stopping at the
//! first child `b` rejects.
//! Tiles that carry no sample (Penrose's triangles) stop at the terminal
//! test, and a sample the system places outside its domain is dropped
//! ([`TileSystem::sample_in_domain`]).
//! `magnitude` is the expected sample count over the whole domain (in code
//! units: times [`TileSystem::codes_per_sample`]), `mean`
//! the density's mean over it (dividing first keeps densities anywhere in
//! 1e-300..1e300, subnormals included, from overflowing). Ranks order the output progressively: the samples with rank
//! below `s` are those an `s`-times smaller request accepts, so every prefix
//! of the output is itself a well-spread set. The roots are visited in parallel and
//! gathered in order, so the output does not depend on the thread count
//! (a system of few roots starts from their descendants instead, which
//! changes nothing but the sharing: see `Walker::starts`).
//! Each root counts its ranks as it finishes; from those histograms a
//! counting sort orders the samples by rank (ties in root order), or, for
//! [`Order::Unsorted`], finds only which to keep.

use crate::density::{Density, Region};
use crate::memory;
pub use crate::sample::Sample;
use crate::tiling::{code_value, Code, TileSystem};
use crate::Error;
use rayon::prelude::*;
use std::ops::Range;

/// Every sample the tiling accepts when `magnitude` samples are expected
/// over the whole domain, in root order
/// (not yet ranked).
///
/// # Example
/// ```
/// use tessera::{density::Uniform, engine, tiling::sphere::SphereTiling};
/// let all = engine::collect(&SphereTiling::default(), &Uniform, 960.0);
/// assert_eq!(all.len(), 960);
/// ```
pub fn collect<S, D>(system: &S, density: &D, magnitude: f64) -> Vec<Sample<S::Point>>
where
    S: TileSystem,
    S::Region: Region<Point = S::Point>,
    D: Density<S::Region> + ?Sized,
{
    let mut parts = Vec::new();
    collect_parts(system, density, magnitude, None, &mut parts, None);
    parts.concat()
}

/// A conservative test of whether a tile (its region) reaches into a window.
///
/// # Example
/// ```
/// use tessera::{density::sphere::Cap, engine::Window, tiling::sphere::SphereRegion};
/// let cap = Cap::new(0.0, 0.0, 1.0, 1.0).unwrap();
/// let window: &Window<SphereRegion> = &|r| cap.reaches(r);
/// # let _ = window;
/// ```
pub type Window<'a, R> = dyn Fn(&R) -> bool + Sync + 'a;

/// What [`collect`] returns from the tiles `overlaps` accepts, in rank
/// order, without visiting the others: a window on a huge request costs
/// what the window holds, not what the request holds. `overlaps` must be
/// conservative (true for every tile that reaches into the window);
/// children of a rejected tile are never asked.
///
/// # Example
/// ```
/// use tessera::{density::{sphere::Cap, Uniform}, engine, tiling::sphere::SphereTiling};
/// let sphere = SphereTiling::default();
/// let window = Cap::new(30.0, 10.0, 5.0, 1.0).unwrap();
/// let near = engine::collect_within(&sphere, &Uniform, 1e6, &|r| window.reaches(r));
/// let all = engine::collect(&sphere, &Uniform, 1e6);
/// let inside = |s: &&engine::Sample<glam::DVec3>| window.contains(s.position);
/// assert_eq!(near.iter().filter(inside).count(), all.iter().filter(inside).count());
/// assert!(near.len() < all.len() / 100);
/// ```
pub fn collect_within<S, D>(
    system: &S,
    density: &D,
    magnitude: f64,
    overlaps: &Window<'_, S::Region>,
) -> Vec<Sample<S::Point>>
where
    S: TileSystem,
    S::Region: Region<Point = S::Point>,
    D: Density<S::Region> + ?Sized,
{
    let (mut parts, mut samples, mut histograms) = (Vec::new(), Vec::new(), Vec::new());
    let buckets = RankBuckets::for_magnitude(magnitude);
    let counted = Some((buckets, &mut histograms));
    let in_range = collect_parts(
        system,
        density,
        magnitude,
        Some(overlaps),
        &mut parts,
        counted,
    );
    by_rank(
        &parts,
        (buckets, &histograms),
        in_range,
        usize::MAX,
        &mut samples,
    );
    samples
}

/// The accepted samples of each root's subtree, in root order, into
/// `parts` (a list per run of consecutive roots, see [`chunk_roots`];
/// their memory reused); with `histograms`, also each list's count of
/// samples per rank bucket, taken while each root's samples are still in
/// cache. False when some rank lies outside `[0, 1)`
/// (never for the engine's ranks; not checked without `histograms`).
fn collect_parts<S, D>(
    system: &S,
    density: &D,
    magnitude: f64,
    window: Option<&Window<'_, S::Region>>,
    parts: &mut Vec<Vec<Sample<S::Point>>>,
    histograms: Option<(RankBuckets, &mut Vec<Vec<u32>>)>,
) -> bool
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
        .map(|start| {
            if window.is_some() {
                return 16;
            }
            let average = walker
                .constant
                .unwrap_or_else(|| density.average(&system.region(&start.tile)));
            let expected = magnitude * (average / walker.mean) * start.share;
            (expected * 1.05).min(MAX_SHARE_HINT) as usize + 16
        })
        .collect();
    let chunks = chunk_roots(&shares, window.is_some(), threads);
    parts.resize_with(chunks.len(), Vec::new);
    let (buckets, mut none) = (histograms.as_ref().map(|h| h.0), Vec::new());
    let counts = histograms.map_or(&mut none, |h| h.1);
    counts.resize_with(chunks.len(), Vec::new);
    chunks
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
                walker.visit(&start.tile, f64::INFINITY, out);
                // counted while the start's samples are still in cache
                in_range &= buckets.is_none_or(|b| b.count_into(&out[from..], counts));
            }
            in_range
        })
        .reduce(|| true, |a, b| a && b)
}

/// Consecutive roots whose outputs share a list, by their expected sizes
/// (`shares`): about [`LISTS_A_THREAD`] lists a thread, so that a large
/// request's lists are large enough for huge pages (see [`memory`]; with a
/// list a root, taking 2 * 10^6 samples on a ramp into fresh memory spent
/// about a third of its time in page faults) while the threads still share
/// the work. A window's roots keep a list each: their shares are unknown.
fn chunk_roots(shares: &[usize], window: bool, threads: usize) -> Vec<Range<usize>> {
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

/// A tile the recursion starts from (see [`Walker::starts`]).
struct Start<T> {
    tile: T,
    /// About the tile's part of the domain (`1 / roots` for a root, split
    /// evenly among children): a hint for the output's reservation.
    share: f64,
}

/// Starts a thread where roots are few (see [`Walker::starts`]): many, as
/// their shares of the samples are rough guesses (split evenly among
/// children) and the lists cut from them by those shares balance only when
/// each start is small. On 2 threads, Penrose at 10^6 uniform samples took
/// 109, 86 and 76 ms with 8, 32 and 128 starts a thread (137 ms on one
/// thread; scratch timer, median of 30).
const STARTS_A_THREAD: usize = 128;

/// Rounds of [`Walker::starts`]: enough for Penrose's single root, whose
/// triangles have one to four children, to reach hundreds of starts.
const MAX_START_ROUNDS: usize = 16;

/// Output lists a thread in [`chunk_roots`]. In scratch runs of a
/// 10^6-sample spherical cap on 2 threads (interleaved, best of 8), 8 a
/// thread ran as fast as a list a root, 4 about 5 % slower (likely a
/// thread left alone with the last large list) and 64 slower again.
const LISTS_A_THREAD: usize = 8;

/// The rank buckets of the per-list histograms the ranking starts from:
/// bucket `b` holds the ranks in `[b, b + 1) / count`, ranks below 0 going
/// to the first and from 1 on to the last (monotone in the rank).
#[derive(Clone, Copy)]
struct RankBuckets {
    count: usize,
}

impl RankBuckets {
    /// About 2048 samples a bucket for `magnitude` samples (a group that
    /// [`sort_group`] sorts in cache), 16 to 4096 buckets (a list's
    /// histogram stays within 16 KB).
    fn for_magnitude(magnitude: f64) -> Self {
        RankBuckets {
            count: ((magnitude / 2048.0) as usize).clamp(16, 4096),
        }
    }

    #[inline]
    fn of(&self, rank: f64) -> usize {
        ((rank * self.count as f64) as usize).min(self.count - 1)
    }

    /// Adds the samples per bucket to `counts` (left empty while no samples
    /// came, so that the empty roots of a window cost nothing); false when
    /// a rank lies outside `[0, 1)`.
    fn count_into<P>(&self, samples: &[Sample<P>], counts: &mut Vec<u32>) -> bool {
        if samples.is_empty() {
            return true;
        }
        counts.resize(self.count, 0);
        let mut in_range = true;
        for s in samples {
            in_range &= (0.0..1.0).contains(&s.rank);
            counts[self.of(s.rank)] += 1;
        }
        in_range
    }

    /// The histograms' sum: samples per bucket over every list.
    fn total(&self, histograms: &[Vec<u32>]) -> Vec<usize> {
        let mut counts = vec![0usize; self.count];
        for histogram in histograms {
            for (total, &c) in counts.iter_mut().zip(histogram) {
                *total += c as usize;
            }
        }
        counts
    }
}

/// The most samples reserved for a root's output before it is known
/// (24 MB of planar samples).
const MAX_SHARE_HINT: f64 = (1 << 20) as f64;

struct Walker<'a, S: TileSystem, D: ?Sized> {
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
    /// Only tiles this accepts are visited (see [`collect_within`]).
    window: Option<&'a Window<'a, S::Region>>,
}

impl<'a, S, D> Walker<'a, S, D>
where
    S: TileSystem,
    S::Region: Region<Point = S::Point>,
    D: Density<S::Region> + ?Sized,
{
    fn new(
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
        }
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
    /// children while there are fewer than `target` and it recurses into
    /// every child with a bound that makes none of them terminal (so its
    /// bound decides nothing for them: visiting them as roots is visiting
    /// it); the output is the same, in the same order, but a system of few
    /// roots (Penrose has one) gives every thread work. A window keeps the
    /// roots.
    fn starts(&self, roots: Vec<S::Tile>, target: usize) -> Vec<Start<S::Tile>> {
        let share = 1.0 / roots.len().max(1) as f64;
        let mut starts: Vec<Start<S::Tile>> = roots
            .into_iter()
            .map(|tile| Start { tile, share })
            .collect();
        if self.window.is_some() {
            return starts;
        }
        for _ in 0..MAX_START_ROUNDS {
            if starts.len() >= target {
                break;
            }
            let before = starts.len();
            let mut next = Vec::with_capacity(before * 4);
            for start in starts {
                if !self.recurses_into_all(&start.tile) {
                    next.push(start);
                    continue;
                }
                let count = self.system.child_count(&start.tile);
                next.extend((0..count).map(|i| Start {
                    tile: self.system.child(&start.tile, i),
                    share: start.share / count as f64,
                }));
            }
            starts = next;
            if starts.len() == before {
                break;
            }
        }
        starts
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
    /// skipped before its region is computed.
    fn visit(&self, tile: &S::Tile, parent_bound: f64, out: &mut Vec<Sample<S::Point>>) {
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
            self.decide(tile, level, capacity, parent_bound, None, out);
        } else {
            let region = self.system.region(tile);
            if self.window.is_some_and(|window| !window(&region)) {
                return;
            }
            self.decide(tile, level, capacity, parent_bound, Some(&region), out);
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
        parent_bound: f64,
        region: Option<&S::Region>,
        out: &mut Vec<Sample<S::Point>>,
    ) {
        let bound = match capacity >= parent_bound {
            true => parent_bound,
            false => self.own_bound(region),
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
            return self.emit(tile, level, code, bound, out);
        }
        self.visit_children(tile, level, bound, out);
    }

    /// A child whose parent's bound makes it terminal and does not reject
    /// its code (`code`): [`Walker::decide`]'s terminal step without the
    /// tests the parent made.
    fn visit_terminal(
        &self,
        tile: &S::Tile,
        level: u32,
        code: f64,
        bound: f64,
        out: &mut Vec<Sample<S::Point>>,
    ) {
        if self.window.is_some() || !self.system.carries_sample(tile) {
            return self.visit(tile, bound, out);
        }
        self.emit(tile, level, code, bound, out);
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

    /// Places the sample of a terminal tile of code `code` and scaled bound
    /// `bound` (code units), if its code is kept (see the module doc).
    #[inline(always)]
    fn emit(
        &self,
        tile: &S::Tile,
        level: u32,
        code: f64,
        bound: f64,
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
        // thinning: placed for the bound, kept by the density it lands on
        let threshold = code + self.dither(code, level);
        if threshold >= bound {
            return;
        }
        // the tiling may reach past the domain: no sample there
        let Some(position) = place(bound) else {
            return;
        };
        let here = self.scaled(self.density.value(position));
        if threshold < here {
            out.push(Sample {
                position,
                rank: threshold / here,
            });
        }
    }

    /// Visits the children of a tile whose scaled bound is `bound`.
    fn visit_children(
        &self,
        tile: &S::Tile,
        level: u32,
        bound: f64,
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
                self.visit_terminal(&self.system.child(tile, i), level + 1, code, bound, out);
            }
            return;
        }
        for i in 0..count {
            if child_rejects
                && code_value(self.system.child_code(tile, i)) + self.least_dither >= bound
            {
                continue;
            }
            self.visit(&self.system.child(tile, i), bound, out);
        }
    }
}

/// Generates about `count` samples (exactly `count` when `exact`) following
/// `density`, in progressive order.
///
/// Exactness: the magnitude is first set a little above `count` (by
/// `2 sqrt(count)`, several times the spread of the natural count), so a
/// single pass almost always finds enough; if fewer samples still come out
/// it is raised and the recursion re-run. The `count` samples of smallest
/// rank are kept, which is a progressive prefix, never a spatially
/// truncated set.
///
/// # Example
/// ```
/// use tessera::{density::sphere::Cap, engine, tiling::sphere::SphereTiling};
/// let cap = Cap::new(0.0, 90.0, 20.0, 50.0).unwrap();
/// let s = engine::generate(&SphereTiling::default(), &cap, 1000, true).unwrap();
/// assert_eq!(s.len(), 1000);
/// ```
pub fn generate<S, D>(
    system: &S,
    density: &D,
    count: usize,
    exact: bool,
) -> Result<Vec<Sample<S::Point>>, Error>
where
    S: TileSystem,
    S::Region: Region<Point = S::Point>,
    D: Density<S::Region> + ?Sized,
{
    generate_ordered(system, density, count, exact, Order::Progressive)
}

/// [`generate`] with the output in the given `order`, into fresh memory.
///
/// # Example
/// ```
/// use tessera::{density::plane::Ramp, engine::{self, Order}, tiling::plane::PlaneTiling};
/// let tiling = PlaneTiling::ppentomino();
/// let s = engine::generate_ordered(&tiling, &Ramp, 500, true, Order::Unsorted).unwrap();
/// assert_eq!(s.len(), 500);
/// ```
pub fn generate_ordered<S, D>(
    system: &S,
    density: &D,
    count: usize,
    exact: bool,
    order: Order,
) -> Result<Vec<Sample<S::Point>>, Error>
where
    S: TileSystem,
    S::Region: Region<Point = S::Point>,
    D: Density<S::Region> + ?Sized,
{
    let mut buffers = Buffers::default();
    generate_into(system, density, count, exact, order, &mut buffers)?;
    Ok(buffers.into_samples())
}

/// Memory a caller keeps between requests (see [`generate_into`]): the
/// samples of the last request, and the lists the recursion fills before
/// ranking them. Fresh memory costs page faults on first touch (one per
/// 4 KB, or per 2 MB where large lists get huge pages), a third of a
/// large request's time or more; reused buffers pay them once, and are overwritten without first being
/// cleared. They hold about twice the samples' size.
///
/// # Example
/// ```
/// use tessera::{density::plane::Ramp, engine::{self, Buffers, Order}, tiling::plane::PlaneTiling};
/// let tiling = PlaneTiling::ppentomino();
/// let mut buffers = Buffers::default();
/// for count in [1000, 500] {
///     let samples = engine::generate_into(&tiling, &Ramp, count, true, Order::Progressive, &mut buffers)
///         .unwrap();
///     assert_eq!(samples.len(), count);
/// }
/// assert_eq!(buffers.samples().len(), 500);
/// ```
#[derive(Debug)]
pub struct Buffers<P> {
    samples: Vec<Sample<P>>,
    parts: Vec<Vec<Sample<P>>>,
    /// Per list of `parts`: samples per rank bucket.
    histograms: Vec<Vec<u32>>,
}

impl<P> Default for Buffers<P> {
    fn default() -> Self {
        Buffers {
            samples: Vec::new(),
            parts: Vec::new(),
            histograms: Vec::new(),
        }
    }
}

impl<P> Buffers<P> {
    /// The samples of the last request (empty after a refused one).
    ///
    /// # Example
    /// ```
    /// let buffers = tessera::engine::Buffers::<glam::DVec2>::default();
    /// assert!(buffers.samples().is_empty());
    /// ```
    pub fn samples(&self) -> &[Sample<P>] {
        &self.samples
    }

    /// The samples of the last request, keeping their memory.
    ///
    /// # Example
    /// ```
    /// let buffers = tessera::engine::Buffers::<glam::DVec2>::default();
    /// assert!(buffers.into_samples().is_empty());
    /// ```
    pub fn into_samples(self) -> Vec<Sample<P>> {
        self.samples
    }
}

/// The order a request's samples come out in.
///
/// # Example
/// ```
/// use tessera::{density::plane::Ramp, engine::{self, Buffers, Order}, tiling::plane::PlaneTiling};
/// let tiling = PlaneTiling::ppentomino();
/// let mut buffers = Buffers::default();
/// let mut any = engine::generate_into(&tiling, &Ramp, 500, true, Order::Unsorted, &mut buffers)
///     .unwrap().to_vec();
/// any.sort_by(|a, b| a.rank.total_cmp(&b.rank));
/// assert_eq!(any, engine::generate(&tiling, &Ramp, 500, true).unwrap());
/// ```
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Order {
    /// By rank: every prefix is itself a well-spread set, as a smaller
    /// request would give.
    #[default]
    Progressive,
    /// The same samples in whatever order is cheapest to produce (today:
    /// the recursion's tile order, depth first, roots in order, which is
    /// spatially coherent, but for the kept samples of the last rank
    /// bucket, which come last in rank order: about 2048 of a large
    /// request, about a sixteenth of a small one; or rank order where
    /// that is what comes out). It skips the ranking sort, about a fifth
    /// of a large request's time, for callers that use the whole set.
    /// Deterministic, and independent of the thread count.
    Unsorted,
}

/// [`generate`] into memory kept between requests (see [`Buffers`]): for a
/// caller drawing a new set every frame, in the given `order`. Returns the
/// samples, which stay in `buffers` until the next request.
///
/// # Example
/// ```
/// use tessera::{density::Uniform, engine::{self, Buffers, Order}, tiling::plane::PlaneTiling};
/// let tiling = PlaneTiling::ppentomino();
/// let mut buffers = Buffers::default();
/// let first = engine::generate_into(&tiling, &Uniform, 1000, true, Order::Progressive, &mut buffers)
///     .unwrap()
///     .to_vec();
/// assert_eq!(first, engine::generate(&tiling, &Uniform, 1000, true).unwrap());
/// ```
pub fn generate_into<'b, S, D>(
    system: &S,
    density: &D,
    count: usize,
    exact: bool,
    order: Order,
    buffers: &'b mut Buffers<S::Point>,
) -> Result<&'b [Sample<S::Point>], Error>
where
    S: TileSystem,
    S::Region: Region<Point = S::Point>,
    D: Density<S::Region> + ?Sized,
{
    let Buffers {
        samples: out,
        parts,
        histograms,
    } = buffers;
    // the last request's samples stay in `out` until the answer overwrites
    // them (memory already written is reused without a fill); a refused
    // request empties it
    let refuse = |out: &mut Vec<_>, why: String| {
        out.clear();
        Err(Error::Request(why))
    };
    if count == 0 {
        out.clear();
        return Ok(out);
    }
    let mean = density.mean();
    if !(mean.is_finite() && mean > 0.0) {
        return refuse(
            out,
            format!("the density's mean over the domain is {mean}; it must be positive and finite"),
        );
    }
    // refuse, rather than abort on, a request whose output cannot be held
    if memory::try_reserve_large(out, count.saturating_sub(out.len())).is_err() {
        return refuse(
            out,
            format!(
                "{count} samples do not fit in memory; draw uniform samples with engine::stream"
            ),
        );
    }
    if let Some(stream) = density.constant().and_then(|_| stream(system, count)) {
        // constant density: the first `count` codes of one level, no recursion
        let (fraction, d) = (stream.fraction, stream.d);
        if system.code_order_samples(stream.level, count, fraction, d, out) {
            return Ok(out);
        }
    }
    // the safety margin of an exact request (see above)
    let mut magnitude = if exact {
        count as f64 + 2.0 * (count as f64).sqrt()
    } else {
        count as f64
    };
    // ranks are counted as each root finishes, for the ranking
    let mut collect = |magnitude: f64, parts: &mut Vec<_>| {
        let buckets = RankBuckets::for_magnitude(magnitude);
        let counted = Some((buckets, &mut *histograms));
        (
            buckets,
            collect_parts(system, density, magnitude, None, parts, counted),
        )
    };
    let (mut buckets, mut in_range) = collect(magnitude, parts);
    let total = |parts: &[Vec<Sample<S::Point>>]| parts.iter().map(Vec::len).sum::<usize>();
    for _ in 0..40 {
        let found = total(parts);
        if !exact || found >= count {
            break;
        }
        let growth = if found == 0 {
            4.0
        } else {
            (count as f64 / found as f64 * 1.01).clamp(1.001, 4.0)
        };
        magnitude *= growth;
        (buckets, in_range) = collect(magnitude, parts);
    }
    if exact && total(parts) < count {
        let found = total(parts);
        return refuse(
            out,
            format!("only {found} samples fit at the deepest level; {count} were requested"),
        );
    }
    let keep = if exact { count } else { usize::MAX };
    match order {
        Order::Progressive => by_rank(parts, (buckets, histograms), in_range, keep, out),
        Order::Unsorted => smallest_ranks(parts, (buckets, histograms), keep, out),
    }
    Ok(out)
}

/// The `keep` samples of smallest rank (all when fewer), into `out`
/// (replacing its contents): the set [`by_rank`] keeps, ties included,
/// without sorting it. The lists' histograms (`buckets` of each list
/// of `parts`) find the bucket holding the cut; one pass copies the samples
/// below it in root order and sets that bucket's aside, of which the
/// smallest follow, in rank order.
fn smallest_ranks<P: Copy>(
    parts: &[Vec<Sample<P>>],
    (buckets, histograms): (RankBuckets, &[Vec<u32>]),
    keep: usize,
    out: &mut Vec<Sample<P>>,
) {
    out.clear();
    let n: usize = parts.iter().map(Vec::len).sum();
    if keep == 0 {
        return;
    }
    if keep >= n {
        for part in parts {
            out.extend_from_slice(part);
        }
        return;
    }
    let counts = buckets.total(histograms);
    // `cut` holds the `keep`-th smallest rank; `below` samples lie in the
    // buckets before it, kept whole
    let (mut cut, mut below) = (0, 0);
    while below + counts[cut] < keep {
        below += counts[cut];
        cut += 1;
    }
    out.reserve(keep);
    // (rank, position in root order, sample) of the cut's bucket
    let mut aside = Vec::new();
    for (i, s) in parts.iter().flatten().enumerate() {
        let b = buckets.of(s.rank);
        if b < cut {
            out.push(*s);
        } else if b == cut {
            aside.push((s.rank, i, *s));
        }
    }
    aside.sort_by(|a, b| a.0.total_cmp(&b.0).then(a.1.cmp(&b.1)));
    out.extend(aside[..keep - below].iter().map(|&(_, _, s)| s));
}

/// The `keep` samples of smallest rank (all when fewer), ordered by rank,
/// into `out` (replacing its contents); ties keep their deterministic root
/// order (as a stable sort would). `histograms` count each list's ranks;
/// `in_range` says every rank lies in `[0, 1)`.
fn by_rank<P: Copy + Send + Sync>(
    parts: &[Vec<Sample<P>>],
    histograms: (RankBuckets, &[Vec<u32>]),
    in_range: bool,
    keep: usize,
    out: &mut Vec<Sample<P>>,
) {
    let n: usize = parts.iter().map(Vec::len).sum();
    if in_range && n < u32::MAX as usize {
        sort_by_groups(parts, histograms, n, keep, out);
        return;
    }
    // (rank as an unsigned key ordered like `f64::total_cmp`, position in
    // root order): distinct keys, so any sort of them is deterministic
    out.clear();
    let samples = parts.concat();
    let mut keys: Vec<(u64, usize)> = samples
        .par_iter()
        .enumerate()
        .map(|(i, s)| (total_order_key(s.rank), i))
        .collect();
    radix_sort(&mut keys);
    keys.truncate(keep);
    out.par_extend(keys.par_iter().map(|&(_, i)| samples[i]));
}

/// [`by_rank`] for the `n` samples of `parts` when their ranks lie in
/// `[0, 1)` (the engine's ranks: `code / d` with `code + 1/2 < d`): a
/// counting sort in two passes that keep writes in cache. The histograms'
/// buckets are groups of about 2048 samples: one pass streams each sample
/// into its group's place in `out`, then each group is sorted within
/// itself. Groups past the `keep`-th sample are skipped.
fn sort_by_groups<P: Copy + Send + Sync>(
    parts: &[Vec<Sample<P>>],
    (buckets, histograms): (RankBuckets, &[Vec<u32>]),
    n: usize,
    keep: usize,
    out: &mut Vec<Sample<P>>,
) {
    let Some(&first) = parts.iter().flatten().next() else {
        out.clear();
        return;
    };
    let groups = buckets.count;
    let mut start = vec![0usize; groups + 1];
    start[1..].copy_from_slice(&buckets.total(histograms));
    for g in 0..groups {
        start[g + 1] += start[g];
    }
    // the groups holding the `keep` smallest ranks
    let used = start.partition_point(|&end| end < keep.min(n)).min(groups);
    let ends: Vec<usize> = start[1..=used].to_vec();
    // (every slot is written below: only new memory needs a fill)
    if out.capacity() < start[used] {
        out.clear();
        let _ = memory::try_reserve_large(out, start[used]);
    }
    out.truncate(start[used]);
    out.resize(start[used], first);
    // `start[g]` moves to the end of group g while filling
    for s in parts.iter().flatten() {
        let g = buckets.of(s.rank);
        if g < used {
            out[start[g]] = *s;
            start[g] += 1;
        }
    }
    let mut slices = Vec::with_capacity(used);
    let mut rest = &mut out[..];
    let mut lo = 0;
    for (g, &end) in ends.iter().enumerate() {
        let (slice, tail) = rest.split_at_mut(end - lo);
        slices.push((g, slice));
        rest = tail;
        lo = end;
    }
    let scale = groups as f64;
    slices
        .into_par_iter()
        .for_each_init(Default::default, |scratch, (g, group)| {
            // where in the group's rank interval: monotone, in [0, 1]
            sort_group(group, |rank| rank * scale - g as f64, scratch);
        });
    out.truncate(keep);
}

/// Sorts `group` by rank: a stable counting sort through `scratch` on
/// `in_group(rank)` (monotone in the rank, in `[0, 1]`) into about
/// [`SORT_SPREAD`] buckets a sample (each sample's bucket computed once,
/// into `local`), then an insertion pass back into `group` that moves the
/// few samples sharing a bucket out of order.
fn sort_group<P: Copy>(
    group: &mut [Sample<P>],
    in_group: impl Fn(f64) -> f64,
    (scratch, local, start): &mut (Vec<Sample<P>>, Vec<u32>, Vec<u32>),
) {
    let len = group.len();
    if len < 2 {
        return;
    }
    let buckets = len * SORT_SPREAD;
    let (scale, top) = (buckets as f64, buckets as u32 - 1);
    local.clear();
    local.extend(
        group
            .iter()
            .map(|s| ((in_group(s.rank) * scale) as u32).min(top)),
    );
    start.clear();
    start.resize(buckets + 1, 0);
    for &b in local.iter() {
        start[b as usize + 1] += 1;
    }
    for b in 0..buckets {
        start[b + 1] += start[b];
    }
    scratch.clear();
    scratch.resize(len, group[0]);
    for (s, &b) in group.iter().zip(local.iter()) {
        let at = &mut start[b as usize];
        scratch[*at as usize] = *s;
        *at += 1;
    }
    // nearly sorted: a sample moves back past the few of its own bucket
    // with a larger rank (strictly larger: ties keep their order); `largest`,
    // the largest rank placed so far, keeps the common case from reading
    // back what it just wrote
    let (mut largest, mut moves) = (f64::NEG_INFINITY, 0);
    for (i, &s) in scratch.iter().enumerate() {
        if s.rank >= largest {
            group[i] = s;
            largest = s.rank;
            continue;
        }
        let mut j = i;
        while j > 0 && s.rank < group[j - 1].rank {
            group[j] = group[j - 1];
            j -= 1;
        }
        group[j] = s;
        moves += i - j;
        if moves > SORT_SPREAD * len {
            // ranks packed closer than the buckets: a quadratic insertion
            // pass would follow, so a stable sort of the bucket order
            // (which kept ties in order) takes over
            group.copy_from_slice(scratch);
            group.sort_by(|a, b| a.rank.total_cmp(&b.rank));
            return;
        }
    }
}

/// Buckets a sample in [`sort_group`]'s counting sort: enough that few
/// samples share one and its insertion pass rarely moves a sample.
const SORT_SPREAD: usize = 2;

/// An unsigned key ordered like [`f64::total_cmp`].
fn total_order_key(x: f64) -> u64 {
    let bits = x.to_bits();
    if bits >> 63 == 1 {
        !bits
    } else {
        bits | 1 << 63
    }
}

/// Stable least-significant-digit radix sort by the key, 8 bits a pass,
/// skipping the passes where every key has the same digit (the exponent
/// bytes of ranks in `[0, 1)` mostly agree).
fn radix_sort(keys: &mut Vec<(u64, usize)>) {
    if keys.len() < 256 {
        keys.sort_unstable();
        return;
    }
    let mut counts = vec![[0usize; 256]; 8];
    for &(k, _) in keys.iter() {
        for (pass, c) in counts.iter_mut().enumerate() {
            c[(k >> (8 * pass)) as usize & 255] += 1;
        }
    }
    let mut buffer = vec![(0u64, 0usize); keys.len()];
    for (pass, c) in counts.iter().enumerate() {
        if c.contains(&keys.len()) {
            continue; // one digit for all: the pass keeps the order
        }
        let mut start = [0usize; 256];
        let mut sum = 0;
        for (s, &n) in start.iter_mut().zip(c) {
            *s = sum;
            sum += n;
        }
        for &(k, i) in keys.iter() {
            let d = (k >> (8 * pass)) as usize & 255;
            buffer[start[d]] = (k, i);
            start[d] += 1;
        }
        std::mem::swap(keys, &mut buffer);
    }
}

/// Uniform samples in progressive order, computed one at a time from their
/// codes: memory stays O(depth) however many are drawn.
///
/// # Example
/// ```
/// use tessera::{engine, tiling::sphere::SphereTiling};
/// let tiling = SphereTiling::default();
/// let first: Vec<_> = engine::stream(&tiling, 1_000_000_000).unwrap().take(3).collect();
/// assert_eq!(first.len(), 3);
/// ```
pub struct Stream<'a, S: TileSystem> {
    system: &'a S,
    level: u32,
    fraction: f64,
    d: f64,
    next: Code,
    end: Code,
}

/// A progressive stream of `count` uniform samples, if the system finds
/// tiles from codes (see [`TileSystem::tile_with_code`]) and `count` fits
/// the deepest level.
///
/// # Example
/// ```
/// use tessera::{engine, tiling::sphere::SphereTiling};
/// assert_eq!(engine::stream(&SphereTiling::default(), 10).unwrap().count(), 10);
/// ```
pub fn stream<S: TileSystem>(system: &S, count: usize) -> Option<Stream<'_, S>> {
    let d = count as f64;
    let level = (0..=system.max_level()).find(|&l| system.capacity(l) >= d)?;
    system.tile_with_code(level, 0)?;
    Some(Stream {
        system,
        level,
        fraction: d / system.capacity(level),
        d,
        next: 0,
        end: count as Code,
    })
}

impl<S: TileSystem> Iterator for Stream<'_, S> {
    type Item = Sample<S::Point>;

    fn next(&mut self) -> Option<Self::Item> {
        if self.next >= self.end {
            return None;
        }
        let tile = self.system.tile_with_code(self.level, self.next)?;
        let sample = Sample {
            position: self.system.sample(&tile, self.fraction),
            rank: code_value(self.next) / self.d,
        };
        self.next += 1;
        Some(sample)
    }

    fn size_hint(&self) -> (usize, Option<usize>) {
        let left = (self.end - self.next) as usize;
        (left, Some(left))
    }
}

impl<S: TileSystem> ExactSizeIterator for Stream<'_, S> {}

/// The pdf (per unit measure of the domain) the samples follow at a point.
///
/// # Example
/// ```
/// use tessera::{density::Uniform, engine, tiling::sphere::SphereTiling};
/// let p = engine::pdf(&SphereTiling::default(), &Uniform, glam::DVec3::Z);
/// assert!((p - 1.0 / (4.0 * std::f64::consts::PI)).abs() < 1e-15);
/// ```
pub fn pdf<S, D>(system: &S, density: &D, point: S::Point) -> f64
where
    S: TileSystem,
    S::Region: Region<Point = S::Point>,
    D: Density<S::Region> + ?Sized,
{
    density.value(point) / (density.mean() * system.measure())
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

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
                    walker.visit(&root, f64::INFINITY, &mut by_roots);
                }
                let starts = walker.starts(system.roots(), 64);
                most = most.max(starts.len());
                for start in &starts {
                    walker.visit(&start.tile, f64::INFINITY, &mut by_starts);
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

    proptest! {
        /// Ranking equals a stable sort of the concatenated parts by rank,
        /// truncated, and the unsorted selection keeps the same samples in
        /// root order (but for the last kept bucket's, in rank order at the
        /// end): across groups, with ties (few distinct ranks) and with
        /// keep below, at and above the count.
        #[test]
        fn ranking_is_a_stable_sort_by_rank(
            sizes in prop::collection::vec(0usize..4000, 1..6),
            // few ranks (ties), distinct ranks, and ranks packed closer
            // than the sort's buckets
            (distinct, packed) in prop_oneof![
                Just((7u64, false)),
                Just((1u64 << 40, false)),
                Just((1024u64, true)),
            ],
            seed in any::<u64>(),
            keep_share in 0.0f64..1.2,
        ) {
            let mut state = seed;
            let mut next = || {
                state = state.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
                (state >> 24) % distinct
            };
            let parts: Vec<Vec<Sample<u32>>> = sizes
                .iter()
                .scan(0u32, |id, &size| {
                    let part = (0..size)
                        .map(|_| {
                            *id += 1;
                            let rank = if packed {
                                0.25 + next() as f64 * 2f64.powi(-50)
                            } else {
                                next() as f64 / distinct as f64
                            };
                            Sample { position: *id, rank }
                        })
                        .collect();
                    Some(part)
                })
                .collect();
            let n: usize = sizes.iter().sum();
            let keep = (keep_share * n as f64) as usize;
            let mut expected = parts.concat();
            expected.sort_by(|a, b| a.rank.total_cmp(&b.rank));
            expected.truncate(keep);
            let buckets = RankBuckets::for_magnitude(n as f64);
            let mut histograms = vec![Vec::new(); parts.len()];
            let in_range = parts
                .iter()
                .zip(&mut histograms)
                .fold(true, |all, (part, counts)| buckets.count_into(part, counts) && all);
            let mut out = vec![Sample { position: 0, rank: 0.5 }; 3];
            by_rank(&parts, (buckets, &histograms), in_range, keep, &mut out);
            prop_assert_eq!(&out, &expected);
            // unsorted: the same samples, in root order but for those of
            // the last kept one's bucket, which follow in rank order
            let mut unsorted = vec![Sample { position: 0, rank: 0.5 }; 3];
            smallest_ranks(&parts, (buckets, &histograms), keep, &mut unsorted);
            let bucket = |s: &Sample<u32>| buckets.of(s.rank);
            // (a request keeping every sample copies them all in root order)
            let cut = if keep >= n { usize::MAX } else { expected.last().map_or(0, bucket) };
            let (mut head, tail): (Vec<Sample<u32>>, Vec<Sample<u32>>) =
                expected.iter().partition(|s| bucket(s) < cut);
            head.sort_by_key(|s| s.position);
            prop_assert_eq!(unsorted, [head, tail].concat());
        }

        /// The output lists cover every root once, in order; each but the
        /// last holds at least its fraction of a thread's share, and only a
        /// window keeps a list a root.
        #[test]
        fn roots_share_lists_in_order(
            shares in prop::collection::vec(0usize..400_000, 1..300),
            window in any::<bool>(),
            threads in 1usize..5,
        ) {
            let chunks = chunk_roots(&shares, window, threads);
            let covered: Vec<usize> = chunks.iter().flat_map(|c| c.clone()).collect();
            prop_assert_eq!(covered, (0..shares.len()).collect::<Vec<_>>());
            prop_assert!(chunks.iter().all(|c| !c.is_empty()));
            if window {
                prop_assert_eq!(chunks.len(), shares.len());
            } else {
                let least = shares.iter().sum::<usize>() / (LISTS_A_THREAD * threads);
                for c in &chunks[..chunks.len() - 1] {
                    prop_assert!(shares[c.clone()].iter().sum::<usize>() >= least);
                }
            }
        }
    }
}

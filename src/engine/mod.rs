//! The adaptive recursion shared by every tile system.
//!
//! ```text
//! visit(tile, b, q = the parent's scaled bounds, which bound the tile too):
//!     if capacity(level) >= b:                     terminal, its own bounds unneeded
//!         if code(tile) >= b: return               (rejected unseen)
//!     else b = magnitude * bound(region(tile)) / mean;  terminal if capacity(level) >= b
//!          q = magnitude * bound(placing_region(tile)) / mean, if at least b / 2, else b
//!     if terminal:
//!         constant density d: keep if code(tile) + 1/2 < d, at sample(tile, d / capacity(level))
//!         else (thinning): t = code(tile) + u, u a seeded dither in [0, 1)
//!             p = sample(tile, q / capacity(level)), h = magnitude * density(p) / mean
//!             keep p if t < h, with rank t / h
//!     else: visit every child
//! ```
//!
//! **Two bounds.** `b` is over the tile's region, which holds every
//! sample it covers: the tile's own in every importance bin and its
//! children's (which it thins when it makes them terminal), and those land
//! up to a few cells past the tile ([`TileSystem::region`]). `b` decides
//! the level and which codes are candidates, and must be at least the
//! density wherever they land. Where the density is smooth, the bin a
//! candidate is placed for is picked by `q`, the bound over the tile's
//! own cells ([`TileSystem::placing_region`]): nearer the density, so
//! that the bin fits the share of its set that is kept. Placed for `b`,
//! smooth densities lost spacing (SPHERE_ADAPTIVE's cells under 0.85: 54
//! of a bump's 56, 32 of 80 for caps, a polygon and maps; placed for `q`,
//! 46 and 26). Beside a step of more than 2x (`q < b / 2`) the candidate
//! is placed for `b`: placed for `q` there, the tile's bin changed where
//! its cells met the edge and its level where its region did, and the
//! local bias beside hard edges grew (EDGE_BIAS.md's rim rings, |z| 12.9
//! -> 17.6; 46 and 28 cells under 0.85 with the rule). `q` is a function
//! of the tile, and where it picks the bin the density varies by less
//! than 2x over the region: the candidate's place follows the density no
//! more than when the bound over the tile's cells was its only bound (up
//! to session 52), which is what the argument below needs, within the
//! local bias beside edges that EDGE_BIAS.md measures. Where the parent's
//! bound makes the tile's children terminal, so that `q` will be needed,
//! `b` and `q` come from one call, [`Density::bounds`], which densities
//! answer from one centre or one set of probes.
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
//! probability never saturates (except at the deepest level); a request
//! where a density exceeds its bound where a sample lands fails instead
//! (`Walker::excess`). A tile whose code is at least its bound cannot be
//! kept and is skipped before its sample is placed.
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

mod batches;
mod farthest;
mod ranking;
mod stream;
mod walker;

use crate::density::{Density, Region};
use crate::memory;
pub use crate::sample::Sample;
use crate::tiling::TileSystem;
use crate::Error;
pub use batches::{unsorted, Unsorted};
use ranking::{by_rank, smallest_ranks, RankBuckets};
pub use stream::{stream, Positions, Stream};
use walker::collect_parts;

/// Every sample the tiling accepts when `magnitude` samples are expected
/// over the whole domain, in root order
/// (not yet ranked).
///
/// # Example
/// ```
/// use tessera::{density::Uniform, engine, tiling::sphere::SphereTiling};
/// let all = engine::collect(&SphereTiling::default(), &Uniform, 960.0).unwrap();
/// assert_eq!(all.len(), 960);
/// ```
///
/// # Errors
/// Where a sample lands on a density above its tile's bound (see
/// [`Density::bound`]).
pub fn collect<S, D>(
    system: &S,
    density: &D,
    magnitude: f64,
) -> Result<Vec<Sample<S::Point>>, Error>
where
    S: TileSystem,
    S::Region: Region<Point = S::Point>,
    D: Density<S::Region> + ?Sized,
{
    let mut parts = Vec::new();
    let collected = collect_parts(system, density, magnitude, None, &mut parts, None);
    match collected.excess {
        Some(ratio) => Err(bound_exceeded(ratio)),
        None => Ok(parts.concat()),
    }
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
/// let near = engine::collect_within(&sphere, &Uniform, 1e6, &|r| window.reaches(r)).unwrap();
/// let all = engine::collect(&sphere, &Uniform, 1e6).unwrap();
/// let inside = |s: &&engine::Sample<glam::DVec3>| window.contains(s.position);
/// assert_eq!(near.iter().filter(inside).count(), all.iter().filter(inside).count());
/// assert!(near.len() < all.len() / 100);
/// ```
///
/// # Errors
/// Where a sample lands on a density above its tile's bound (see
/// [`Density::bound`]); only the tiles reaching the window are seen, so a
/// window can succeed where the whole request fails.
pub fn collect_within<S, D>(
    system: &S,
    density: &D,
    magnitude: f64,
    overlaps: &Window<'_, S::Region>,
) -> Result<Vec<Sample<S::Point>>, Error>
where
    S: TileSystem,
    S::Region: Region<Point = S::Point>,
    D: Density<S::Region> + ?Sized,
{
    let (mut parts, mut samples, mut histograms) = (Vec::new(), Vec::new(), Vec::new());
    let buckets = RankBuckets::for_magnitude(magnitude);
    let counted = Some((buckets, &mut histograms));
    let collected = collect_parts(
        system,
        density,
        magnitude,
        Some(overlaps),
        &mut parts,
        counted,
    );
    if let Some(ratio) = collected.excess {
        return Err(bound_exceeded(ratio));
    }
    by_rank(
        &parts,
        (buckets, &histograms),
        collected.in_range,
        usize::MAX,
        &mut samples,
    );
    Ok(samples)
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
    /// By rank: every prefix is the samples a smaller request's thresholds
    /// keep, at this request's places: it follows the density, spread
    /// though less evenly than the whole set.
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
    /// Farthest first: each sample is (to 0.2 %) the one farthest from those
    /// before it, in local spacings (`distance · sqrt(density)`), so that
    /// every prefix, whatever its length, is about as evenly spread as the
    /// whole set (the rank order's prefixes leave holes: docs/SPHERE_SWEEP.md).
    /// The same samples as the other orders; their ranks no longer increase.
    /// It costs a sequential O(N log N) pass after sampling, 1.2 µs a
    /// sample at 2·10^5 and 2.2 µs at 10^6 (`cargo bench --bench order`,
    /// docs/PERFORMANCE.md), for callers that stop at a prefix they choose
    /// later. Deterministic, and independent of the thread count.
    FarthestFirst,
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
    if order == Order::FarthestFirst {
        // (its queue holds 32-bit indices)
        if count > u32::MAX as usize {
            buffers.samples.clear();
            return Err(Error::Request(format!(
                "the farthest-first order takes at most {} samples, not {count}",
                u32::MAX
            )));
        }
        // the same samples by rank, then reordered from the first (the
        // ranking sort is small beside the reordering)
        generate_into(system, density, count, exact, Order::Progressive, buffers)?;
        let weight = |p: S::Point| density.value(p).sqrt();
        let weight: Option<&(dyn Fn(S::Point) -> f64 + Sync)> = match density.constant() {
            Some(_) => None,
            None => Some(&weight),
        };
        farthest::farthest_first(&mut buffers.samples, weight);
        return Ok(&buffers.samples);
    }
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
        if system.code_order_samples(stream.level, 0..count, fraction, d, out) {
            return Ok(out);
        }
    }
    if order == Order::Progressive && count > PROGRESSIVE_IN_BATCHES_ABOVE {
        match batches::progressive_in_batches(system, density, count, exact, out) {
            Ok(true) => return Ok(out),
            Ok(false) => {}
            Err(e) => {
                out.clear();
                return Err(e);
            }
        }
    }
    let mut magnitude = first_magnitude(count, exact);
    // ranks are counted as each root finishes, for the ranking
    let mut collect = |magnitude: f64, parts: &mut Vec<_>| {
        let buckets = RankBuckets::for_magnitude(magnitude);
        let counted = Some((buckets, &mut *histograms));
        let collected = collect_parts(system, density, magnitude, None, parts, counted);
        match collected.excess {
            Some(ratio) => Err(bound_exceeded(ratio)),
            None => Ok((buckets, collected.in_range)),
        }
    };
    let total = |parts: &[Vec<Sample<S::Point>>]| parts.iter().map(Vec::len).sum::<usize>();
    let mut collected = collect(magnitude, parts);
    for _ in 0..MAGNITUDE_ROUNDS {
        let found = total(parts);
        if collected.is_err() || !exact || found >= count {
            break;
        }
        magnitude *= growth(count, found);
        collected = collect(magnitude, parts);
    }
    let (buckets, in_range) = match collected {
        Ok(collected) => collected,
        Err(e) => {
            out.clear();
            return Err(e);
        }
    };
    if exact && total(parts) < count {
        out.clear();
        return Err(too_few(total(parts), count));
    }
    let keep = if exact { count } else { usize::MAX };
    match order {
        Order::Progressive => by_rank(parts, (buckets, histograms), in_range, keep, out),
        // (farthest first is reordered from the unsorted samples above)
        Order::Unsorted | Order::FarthestFirst => {
            smallest_ranks(parts, (buckets, histograms), keep, out)
        }
    }
    Ok(out)
}

/// The error of a request whose density exceeded its bound by `ratio`
/// where a sample landed (see `Walker::excess`).
fn bound_exceeded(ratio: f64) -> Error {
    Error::Density(
        "Density::bound".into(),
        format!(
            "the density where a sample landed is {ratio:.6} times its bound over the sample's tile; \
             Density::bound must never be below the density, or the samples are biased \
             (a SphereFn: its Lipschitz constant is too small)"
        ),
    )
}

/// The magnitude a request of `count` samples starts from: with the
/// safety margin of an exact request (see above).
fn first_magnitude(count: usize, exact: bool) -> f64 {
    match exact {
        true => count as f64 + 2.0 * (count as f64).sqrt(),
        false => count as f64,
    }
}

/// Progressive requests of a varying density larger than this are
/// computed a batch of subtrees at a time and scattered into their rank
/// groups (see `batches::progressive_in_batches`): about 34 bytes a
/// sample at their peak instead of 64, for a second pass over the
/// recursion. Measured whole-process at 10^7 samples (one run each on a
/// loaded 2-core machine, user + system CPU): a sphere cap 3.3 s in
/// batches against 3.2 s in one pass (half of it page faults), 340 MB
/// against 638 MB; a G-hexomino ramp 1.3 s against 0.6 s, 256 MB against
/// 480 MB. Below this count the one pass is faster and its memory small.
const PROGRESSIVE_IN_BATCHES_ABOVE: usize = 1 << 22;

/// Rounds of the search for an exact request's magnitude.
const MAGNITUDE_ROUNDS: usize = 40;

/// The factor an exact request's magnitude grows by when the last one
/// gave `found` of its `count` samples.
fn growth(count: usize, found: usize) -> f64 {
    match found {
        0 => 4.0,
        _ => (count as f64 / found as f64 * 1.01).clamp(1.001, 4.0),
    }
}

/// The refusal of a request the deepest level cannot hold.
fn too_few(found: usize, count: usize) -> Error {
    Error::Request(format!(
        "only {found} samples fit at the deepest level; {count} were requested"
    ))
}

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
    use super::ranking::*;
    use super::walker::*;
    use super::*;
    use proptest::prelude::*;

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

//! Requests of a varying density computed a batch of the recursion's
//! subtrees at a time, after a first pass that counts each subtree's
//! samples per rank bucket: [`unsorted`] writes them as they come, in
//! memory for a batch however many are drawn, and large progressive
//! requests scatter them into their rank groups without first keeping
//! every subtree's samples (`progressive_in_batches`).

use super::ranking::{sort_fed, RankBuckets, Scatter};
use super::walker::Walker;
use super::{stream, Sample, Stream};
use crate::density::{Density, Region};
use crate::tiling::TileSystem;
use crate::Error;
use rayon::prelude::*;
use std::ops::Range;

/// The most samples a subtree is expected to hold before it is split into
/// its children's: the unit the second pass computes and keeps in memory.
const SUBTREE_SAMPLES: f64 = (1 << 14) as f64;
/// Samples the second pass computes at a time, shared among the threads
/// (16 MB of sphere samples).
const BATCH_SAMPLES: usize = 1 << 19;

/// Samples of `density` over `system` in [`Order::Unsorted`](super::Order::Unsorted), the same
/// as [`generate_into`](super::generate_into) gives, sample for sample, but
/// computed a batch at a time. A varying density takes two passes over
/// the recursion: the first counts the samples per rank bucket (the exact
/// count's search for the request's magnitude takes such passes too), the
/// second writes those below the cut bucket as they come and keeps the
/// cut bucket's (about `count / 4096` of them) to write last, in rank
/// order. A constant density streams its codes ([`stream()`]).
///
/// # Example
/// ```
/// use tessera::{density::plane::Ramp, engine::{self, Order}, tiling::plane::PlaneTiling};
/// let tiling = PlaneTiling::ppentomino();
/// let streamed: Vec<_> = engine::unsorted(&tiling, &Ramp, 20_000, true).unwrap().collect();
/// let mut buffers = engine::Buffers::default();
/// let in_memory = engine::generate_into(&tiling, &Ramp, 20_000, true, Order::Unsorted, &mut buffers);
/// assert_eq!(streamed, in_memory.unwrap());
/// ```
pub fn unsorted<'a, S, D>(
    system: &'a S,
    density: &'a D,
    count: usize,
    exact: bool,
) -> Result<Unsorted<'a, S, D>, Error>
where
    S: TileSystem,
    S::Region: Region<Point = S::Point>,
    D: Density<S::Region> + ?Sized,
{
    let mean = density.mean();
    if count > 0 && !(mean.is_finite() && mean > 0.0) {
        return Err(Error::Request(format!(
            "the density's mean over the domain is {mean}; it must be positive and finite"
        )));
    }
    if count == 0 {
        return Ok(Unsorted(Inner::Codes(None)));
    }
    if let Some(codes) = density.constant().and_then(|_| stream(system, count)) {
        return Ok(Unsorted(Inner::Codes(Some(codes))));
    }
    let counted = Counted::search(system, density, count, exact)?;
    let keep = if exact { count } else { usize::MAX };
    Ok(Unsorted(Inner::Walk(Box::new(Walk::new(counted, keep)))))
}

/// [`generate_into`](super::generate_into)'s progressive samples of a
/// varying density, computed as [`unsorted`]'s are, a batch at a time, and
/// scattered into their rank groups in `out` as they come: the output's 32
/// bytes (sphere) a sample and a batch, where keeping every subtree's
/// samples before ranking them takes twice that. False, with `out` left
/// as it was, where the ranks do not suit the counting sort (never the
/// engine's).
pub(super) fn progressive_in_batches<S, D>(
    system: &S,
    density: &D,
    count: usize,
    exact: bool,
    out: &mut Vec<Sample<S::Point>>,
) -> Result<bool, Error>
where
    S: TileSystem,
    S::Region: Region<Point = S::Point>,
    D: Density<S::Region> + ?Sized,
{
    let counted = Counted::search(system, density, count, exact)?;
    if !counted.in_range || counted.found() >= u32::MAX as usize {
        return Ok(false);
    }
    let keep = if exact { count } else { usize::MAX };
    let mut lists = Vec::new();
    let feed = |scatter: &mut Scatter<'_, S::Point>| {
        for (batch, size) in runs(&counted.sizes, BATCH_SAMPLES) {
            counted.visit(batch, size, &mut lists);
            lists.iter().for_each(|list| scatter(list));
        }
    };
    sort_fed(feed, (counted.buckets, &counted.counts), keep, out);
    Ok(true)
}

/// The samples of [`unsorted`], an exact-size iterator.
///
/// # Example
/// ```
/// use tessera::{density::plane::Ramp, engine, tiling::plane::PlaneTiling};
/// let tiling = PlaneTiling::ghexomino();
/// let samples = engine::unsorted(&tiling, &Ramp, 1000, true).unwrap();
/// assert_eq!(samples.len(), 1000);
/// ```
pub struct Unsorted<'a, S: TileSystem, D: ?Sized>(Inner<'a, S, D>);

enum Inner<'a, S: TileSystem, D: ?Sized> {
    /// A constant density's codes (none for an empty request).
    Codes(Option<Stream<'a, S>>),
    /// A varying density's recursion, in batches.
    Walk(Box<Walk<'a, S, D>>),
}

impl<S, D> Iterator for Unsorted<'_, S, D>
where
    S: TileSystem,
    S::Region: Region<Point = S::Point>,
    D: Density<S::Region> + ?Sized,
{
    type Item = Sample<S::Point>;

    fn next(&mut self) -> Option<Self::Item> {
        match &mut self.0 {
            Inner::Codes(codes) => codes.as_mut()?.next(),
            Inner::Walk(walk) => walk.next(),
        }
    }

    fn size_hint(&self) -> (usize, Option<usize>) {
        let left = match &self.0 {
            Inner::Codes(codes) => codes.as_ref().map_or(0, ExactSizeIterator::len),
            Inner::Walk(walk) => walk.left,
        };
        (left, Some(left))
    }
}

impl<S, D> ExactSizeIterator for Unsorted<'_, S, D>
where
    S: TileSystem,
    S::Region: Region<Point = S::Point>,
    D: Density<S::Region> + ?Sized,
{
}

/// The first pass at one magnitude: the subtrees the recursion is cut
/// into, and the samples per rank bucket over all of them.
struct Counted<'a, S: TileSystem, D: ?Sized> {
    walker: Walker<'a, S, D>,
    starts: Vec<S::Tile>,
    /// The samples of each start's subtree.
    sizes: Vec<usize>,
    /// Whether every rank lay in `[0, 1)` (always the engine's).
    in_range: bool,
    buckets: RankBuckets,
    counts: Vec<usize>,
}

impl<'a, S, D> Counted<'a, S, D>
where
    S: TileSystem,
    S::Region: Region<Point = S::Point>,
    D: Density<S::Region> + ?Sized,
{
    fn new(system: &'a S, density: &'a D, magnitude: f64) -> Self {
        let walker = Walker::new(system, density, magnitude, None);
        let big = |tile: &S::Tile| walker.expected(tile) > SUBTREE_SAMPLES;
        let starts = walker.split(system.roots(), |_| true, big);
        let buckets = RankBuckets::for_magnitude(magnitude);
        let add = |mut a: Vec<usize>, b: &[usize]| {
            a.resize(buckets.count, 0);
            a.iter_mut().zip(b).for_each(|(a, b)| *a += b);
            a
        };
        // per thread: the counts per bucket, each start's size, whether
        // every rank lay in [0, 1), and the lists a start is visited into
        // (memory reused)
        let (counts, sized, in_range) = starts
            .par_iter()
            .enumerate()
            .fold(
                || (Vec::new(), Vec::new(), true, Vec::new(), Vec::new()),
                |(totals, mut sized, in_range, mut samples, mut counts), (k, start)| {
                    samples.clear();
                    counts.clear();
                    walker.visit(start, f64::INFINITY, f64::INFINITY, &mut samples);
                    let in_range = buckets.count_into(&samples, &mut counts) && in_range;
                    sized.push((k, samples.len()));
                    let mut totals = add(totals, &[]);
                    for (total, &c) in totals.iter_mut().zip(&counts) {
                        *total += c as usize;
                    }
                    (totals, sized, in_range, samples, counts)
                },
            )
            .map(|(totals, sized, in_range, _, _)| (totals, sized, in_range))
            .reduce(
                || (Vec::new(), Vec::new(), true),
                |(a, mut sized, a_in), (b, more, b_in)| {
                    sized.extend(more);
                    (add(a, &b), sized, a_in && b_in)
                },
            );
        let mut sizes = vec![0; starts.len()];
        for (k, size) in sized {
            sizes[k] = size;
        }
        Counted {
            walker,
            starts,
            sizes,
            buckets,
            counts: add(counts, &[]),
            in_range,
        }
    }

    /// The magnitude search of `generate_into`, counting instead of
    /// keeping.
    fn search(system: &'a S, density: &'a D, count: usize, exact: bool) -> Result<Self, Error> {
        let mut magnitude = super::first_magnitude(count, exact);
        let mut counted = Counted::new(system, density, magnitude);
        for _ in 0..super::MAGNITUDE_ROUNDS {
            if let Some(ratio) = counted.walker.excess() {
                return Err(super::bound_exceeded(ratio));
            }
            let found = counted.found();
            if !exact || found >= count {
                break;
            }
            magnitude *= super::growth(count, found);
            counted = Counted::new(system, density, magnitude);
        }
        if let Some(ratio) = counted.walker.excess() {
            return Err(super::bound_exceeded(ratio));
        }
        let found = counted.found();
        if exact && found < count {
            return Err(super::too_few(found, count));
        }
        Ok(counted)
    }

    fn found(&self) -> usize {
        self.sizes.iter().sum()
    }

    /// The samples of the subtrees `batch` (`size` of them), into `lists`,
    /// in order, a run of subtrees a thread.
    fn visit(&self, batch: Range<usize>, size: usize, lists: &mut Vec<Vec<Sample<S::Point>>>) {
        let (starts, sizes) = (&self.starts[batch.clone()], &self.sizes[batch]);
        // about a thread's share of the samples each
        let share = size.div_ceil(rayon::current_num_threads()).max(1);
        let runs = runs(sizes, share);
        lists.resize_with(runs.len(), Vec::new);
        lists.truncate(runs.len());
        lists
            .par_iter_mut()
            .zip(&runs)
            .for_each(|(list, (run, size))| {
                list.clear();
                list.reserve_exact(*size);
                for start in &starts[run.clone()] {
                    self.walker.visit(start, f64::INFINITY, f64::INFINITY, list);
                }
            });
    }
}

/// Consecutive runs of `sizes` (and their sums) of at least `least` each
/// but the last.
fn runs(sizes: &[usize], least: usize) -> Vec<(Range<usize>, usize)> {
    let mut runs = Vec::new();
    let (mut from, mut sum) = (0, 0);
    for (k, &size) in sizes.iter().enumerate() {
        sum += size;
        if sum >= least {
            runs.push((from..k + 1, sum));
            (from, sum) = (k + 1, 0);
        }
    }
    if from < sizes.len() {
        runs.push((from..sizes.len(), sum));
    }
    runs
}

/// The second pass: subtrees computed a batch at a time, in order.
struct Walk<'a, S: TileSystem, D: ?Sized> {
    counted: Counted<'a, S, D>,
    /// Consecutive subtrees computed together, and their samples.
    batches: Vec<(Range<usize>, usize)>,
    next_batch: usize,
    /// Samples of buckets below this one are written in recursion order
    /// (all of them when it is `usize::MAX`).
    cut: usize,
    /// How many of the cut bucket's samples are kept: its smallest ranks.
    need: usize,
    /// The cut bucket's samples, with their place in recursion order
    /// (which breaks ties of rank).
    aside: Vec<(f64, usize, Sample<S::Point>)>,
    /// Samples visited so far in recursion order.
    seen: usize,
    /// The batch's samples, a list per thread's run of its subtrees
    /// (memory reused), and the next one to look at.
    lists: Vec<Vec<Sample<S::Point>>>,
    at: (usize, usize),
    /// Whether the last batch was computed and the cut bucket's kept
    /// samples moved to the only list.
    finished: bool,
    left: usize,
}

impl<'a, S, D> Walk<'a, S, D>
where
    S: TileSystem,
    S::Region: Region<Point = S::Point>,
    D: Density<S::Region> + ?Sized,
{
    /// The selection of `smallest_ranks` (see `ranking`), from the counts.
    fn new(counted: Counted<'a, S, D>, keep: usize) -> Self {
        let n = counted.found();
        let (cut, need, left) = if keep >= n {
            (usize::MAX, 0, n)
        } else {
            let (mut cut, mut below) = (0, 0);
            while below + counted.counts[cut] < keep {
                below += counted.counts[cut];
                cut += 1;
            }
            (cut, keep - below, keep)
        };
        let batches = runs(&counted.sizes, BATCH_SAMPLES);
        Walk {
            counted,
            batches,
            next_batch: 0,
            cut,
            need,
            aside: Vec::new(),
            seen: 0,
            lists: Vec::new(),
            at: (0, 0),
            finished: false,
            left,
        }
    }

    /// Computes the next batch's subtrees into `lists`.
    fn compute_batch(&mut self) {
        let (batch, size) = self.batches[self.next_batch].clone();
        self.next_batch += 1;
        self.counted.visit(batch, size, &mut self.lists);
        self.at = (0, 0);
    }

    /// The next sample of the lists that is kept in recursion order, the
    /// cut bucket's set aside on the way.
    fn next_in_lists(&mut self) -> Option<Sample<S::Point>> {
        let buckets = self.counted.buckets;
        while let Some(list) = self.lists.get(self.at.0) {
            let Some(&s) = list.get(self.at.1) else {
                self.at = (self.at.0 + 1, 0);
                continue;
            };
            self.at.1 += 1;
            self.seen += 1;
            if self.cut == usize::MAX || self.finished {
                return Some(s);
            }
            match buckets.of(s.rank) {
                b if b < self.cut => return Some(s),
                b if b == self.cut => self.aside.push((s.rank, self.seen - 1, s)),
                _ => {}
            }
        }
        None
    }
}

impl<S, D> Iterator for Walk<'_, S, D>
where
    S: TileSystem,
    S::Region: Region<Point = S::Point>,
    D: Density<S::Region> + ?Sized,
{
    type Item = Sample<S::Point>;

    fn next(&mut self) -> Option<Self::Item> {
        loop {
            if let Some(s) = self.next_in_lists() {
                self.left -= 1;
                return Some(s);
            }
            if self.next_batch < self.batches.len() {
                self.compute_batch();
            } else if !self.finished {
                // the cut bucket's smallest ranks, last, in rank order
                self.finished = true;
                let mut aside = std::mem::take(&mut self.aside);
                aside.sort_by(|a, b| a.0.total_cmp(&b.0).then(a.1.cmp(&b.1)));
                let kept = aside.iter().take(self.need).map(|&(_, _, s)| s);
                self.lists = vec![kept.collect()];
                self.at = (0, 0);
            } else {
                return None;
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::density::plane::Ramp;
    use crate::density::sphere::Cap;
    use crate::engine::{generate_into, Buffers, Order};
    use crate::tiling::penrose::PenroseTiling;
    use crate::tiling::plane::PlaneTiling;
    use crate::tiling::sphere::SphereTiling;

    /// The progressive path in batches gives what the one-pass path gives
    /// (below the count where `generate_into` switches to it), exact and
    /// not, across batches.
    #[test]
    fn progressive_in_batches_equals_one_pass() {
        fn check<S, D>(system: &S, density: &D, count: usize, exact: bool)
        where
            S: TileSystem,
            S::Region: Region<Point = S::Point>,
            S::Point: PartialEq + std::fmt::Debug,
            D: Density<S::Region> + ?Sized,
        {
            let mut buffers = Buffers::default();
            let one_pass = generate_into(
                system,
                density,
                count,
                exact,
                Order::Progressive,
                &mut buffers,
            )
            .unwrap();
            let mut batched = Vec::new();
            assert!(progressive_in_batches(system, density, count, exact, &mut batched).unwrap());
            assert!(batched == one_pass, "{count} {exact}");
        }
        let cap = Cap::new(10.0, 20.0, 30.0, 10.0).unwrap();
        for (count, exact) in [(1, true), (2000, true), (1_300_000, true), (200_000, false)] {
            check(&PlaneTiling::ghexomino(), &Ramp, count, exact);
            check(&SphereTiling::default(), &cap, count, exact);
        }
        check(&PenroseTiling::default(), &Ramp, 600_000, true);
    }
}

//! The progressive order: a counting sort of the recursion's samples by
//! rank, from the per-list histograms the recursion counts.

use super::Sample;
use crate::memory;
use rayon::prelude::*;

/// The rank buckets of the per-list histograms the ranking starts from:
/// bucket `b` holds the ranks in `[b, b + 1) / count`, ranks below 0 going
/// to the first and from 1 on to the last (monotone in the rank).
#[derive(Clone, Copy)]
pub(super) struct RankBuckets {
    pub(super) count: usize,
}
impl RankBuckets {
    /// About 2048 samples a bucket for `magnitude` samples (a group that
    /// [`sort_group`] sorts in cache), 16 to 4096 buckets (a list's
    /// histogram stays within 16 KB).
    pub(super) fn for_magnitude(magnitude: f64) -> Self {
        RankBuckets {
            count: ((magnitude / 2048.0) as usize).clamp(16, 4096),
        }
    }

    #[inline]
    pub(super) fn of(&self, rank: f64) -> usize {
        ((rank * self.count as f64) as usize).min(self.count - 1)
    }

    /// Adds the samples per bucket to `counts` (left empty while no samples
    /// came, so that the empty roots of a window cost nothing); false when
    /// a rank lies outside `[0, 1)`.
    pub(super) fn count_into<P>(&self, samples: &[Sample<P>], counts: &mut Vec<u32>) -> bool {
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
    pub(super) fn total(&self, histograms: &[Vec<u32>]) -> Vec<usize> {
        let mut counts = vec![0usize; self.count];
        for histogram in histograms {
            for (total, &c) in counts.iter_mut().zip(histogram) {
                *total += c as usize;
            }
        }
        counts
    }
}
/// The `keep` samples of smallest rank (all when fewer), into `out`
/// (replacing its contents): the set [`by_rank`] keeps, ties included,
/// without sorting it. The lists' histograms (`buckets` of each list
/// of `parts`) find the bucket holding the cut; one pass copies the samples
/// below it in root order and sets that bucket's aside, of which the
/// smallest follow, in rank order.
pub(super) fn smallest_ranks<P: Copy>(
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
pub(super) fn by_rank<P: Copy + Send + Sync>(
    parts: &[Vec<Sample<P>>],
    histograms: (RankBuckets, &[Vec<u32>]),
    in_range: bool,
    keep: usize,
    out: &mut Vec<Sample<P>>,
) {
    let n: usize = parts.iter().map(Vec::len).sum();
    if in_range && n < u32::MAX as usize {
        let (buckets, histograms) = histograms;
        let totals = buckets.total(histograms);
        let feed = |scatter: &mut Scatter<'_, P>| parts.iter().for_each(|p| scatter(p));
        sort_fed(feed, (buckets, &totals), keep, out);
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
/// Takes samples a slice at a time (see [`sort_fed`]).
pub(super) type Scatter<'s, P> = dyn FnMut(&[Sample<P>]) + 's;

/// [`by_rank`] for samples whose ranks lie in `[0, 1)` (the engine's
/// ranks: `code / d` with `code + 1/2 < d`), fewer than `u32::MAX`, that
/// `feed` hands over a slice at a time, in order, `totals` their counts
/// per bucket: a counting sort in two passes that keep writes in cache.
/// The buckets are groups of about 2048 samples: one pass streams each
/// sample into its group's place in `out`, then each group is sorted
/// within itself. Groups past the `keep`-th sample are skipped.
pub(super) fn sort_fed<P: Copy + Send + Sync>(
    feed: impl FnOnce(&mut Scatter<'_, P>),
    (buckets, totals): (RankBuckets, &[usize]),
    keep: usize,
    out: &mut Vec<Sample<P>>,
) {
    let (n, groups) = (totals.iter().sum::<usize>(), buckets.count);
    let mut start = vec![0usize; groups + 1];
    for (g, &total) in totals.iter().enumerate() {
        start[g + 1] = total;
    }
    for g in 0..groups {
        start[g + 1] += start[g];
    }
    // the groups holding the `keep` smallest ranks
    let used = start.partition_point(|&end| end < keep.min(n)).min(groups);
    let ends: Vec<usize> = start[1..=used].to_vec();
    let mut filled = false;
    let mut scatter = |samples: &[Sample<P>]| {
        let Some(&first) = samples.first() else {
            return;
        };
        if !filled {
            // (every slot is written below: only new memory needs a fill)
            filled = true;
            if out.capacity() < start[used] {
                out.clear();
                let _ = memory::try_reserve_large(out, start[used]);
            }
            out.truncate(start[used]);
            out.resize(start[used], first);
        }
        // `start[g]` moves to the end of group g while filling
        for s in samples {
            let g = buckets.of(s.rank);
            if g < used {
                out[start[g]] = *s;
                start[g] += 1;
            }
        }
    };
    feed(&mut scatter);
    if !filled {
        out.clear();
        return;
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
pub(super) fn sort_group<P: Copy>(
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
pub(super) const SORT_SPREAD: usize = 2;
/// An unsigned key ordered like [`f64::total_cmp`].
pub(super) fn total_order_key(x: f64) -> u64 {
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
pub(super) fn radix_sort(keys: &mut Vec<(u64, usize)>) {
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

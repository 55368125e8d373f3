//! Uniform samples in code order, block by block: no recursion, no sort,
//! and memory for one block whatever the count.

use super::Sample;
use crate::blocks::Blocks;
use crate::tiling::{code_order::CodeOrder, TileSystem};
use rayon::prelude::*;

/// Codes computed at a time by a [`Stream`] (2 MB of sphere samples),
/// shared out among threads.
const STREAM_BLOCK: usize = 1 << 16;

/// Uniform samples in progressive order, computed a block of
/// 2^16 codes at a time ([`TileSystem::code_order`] over consecutive code
/// ranges, so they equal the in-memory path's sample for sample): memory
/// stays one block (and the source's level list) however many are drawn.
///
/// # Example
/// ```
/// use tessera::{engine, tiling::sphere::SphereTiling};
/// let tiling = SphereTiling::default();
/// let first: Vec<_> = engine::stream(&tiling, 1_000_000_000).unwrap().take(3).collect();
/// assert_eq!(first.len(), 3);
/// ```
pub struct Stream<'a, S: TileSystem> {
    source: Box<dyn CodeOrder<S::Point> + 'a>,
    pub(super) level: u32,
    pub(super) fraction: f64,
    pub(super) d: f64,
    /// The first code not yet in `block`.
    next: usize,
    end: usize,
    block: Vec<Sample<S::Point>>,
    /// The next sample of `block` to yield.
    at: usize,
}
/// A progressive stream of `count` uniform samples, if the system finds
/// tiles from codes (see [`TileSystem::tile_with_code`]) and `count` fits
/// the deepest level.
///
/// # Example
/// ```
/// use tessera::{density::Uniform, engine, tiling::sphere::SphereTiling};
/// let tiling = SphereTiling::default();
/// let streamed: Vec<_> = engine::stream(&tiling, 100_000).unwrap().collect();
/// assert_eq!(streamed, engine::generate(&tiling, &Uniform, 100_000, true).unwrap());
/// ```
pub fn stream<S: TileSystem>(system: &S, count: usize) -> Option<Stream<'_, S>> {
    let d = count as f64;
    let level = (0..=system.max_level()).find(|&l| system.capacity(l) >= d)?;
    let fraction = d / system.capacity(level);
    Some(Stream {
        source: system.code_order(level, 0..count, fraction, d)?,
        level,
        fraction,
        d,
        next: 0,
        end: count,
        block: Vec::new(),
        at: 0,
    })
}
impl<S: TileSystem> Stream<'_, S> {
    /// Refills the block with the next codes; false at the end.
    fn refill(&mut self) -> bool {
        if self.next >= self.end {
            return false;
        }
        let codes = self.next..self.end.min(self.next.saturating_add(STREAM_BLOCK));
        self.next = codes.end;
        self.at = 0;
        self.source.fill(codes, &mut self.block);
        !self.block.is_empty()
    }
}

impl<S: TileSystem> Iterator for Stream<'_, S> {
    type Item = Sample<S::Point>;

    #[inline]
    fn next(&mut self) -> Option<Self::Item> {
        if self.at >= self.block.len() && !self.refill() {
            return None;
        }
        let sample = self.block[self.at];
        self.at += 1;
        Some(sample)
    }

    fn size_hint(&self) -> (usize, Option<usize>) {
        let left = self.end - self.next + (self.block.len() - self.at);
        (left, Some(left))
    }
}
impl<S: TileSystem> ExactSizeIterator for Stream<'_, S> {}

impl<'a, S: TileSystem> Stream<'a, S> {
    /// The stream's positions mapped by `to_world`, as [`Blocks`]: each
    /// block is handed on while the next is computed (on another thread
    /// of the pool, if it has one), so writing overlaps generation.
    ///
    /// # Example
    /// ```
    /// use tessera::{blocks::Blocks, engine, tiling::sphere::SphereTiling};
    /// let tiling = SphereTiling::default();
    /// let mut points = engine::stream(&tiling, 100_000).unwrap().positions(|p| -p);
    /// let mut mirrored = Vec::new();
    /// points.try_for_each_block(&mut |block| {
    ///     mirrored.extend_from_slice(block);
    ///     Ok(())
    /// }).unwrap();
    /// let samples = engine::stream(&tiling, 100_000).unwrap();
    /// assert!(samples.map(|s| -s.position).eq(mirrored));
    /// ```
    pub fn positions<Q, F>(self, to_world: F) -> Positions<'a, S, F>
    where
        F: Fn(S::Point) -> Q + Sync,
    {
        Positions {
            stream: self,
            to_world,
        }
    }

    /// Maps the samples of the block not yet yielded (the next block's,
    /// if none is left) into `out`, and marks them yielded.
    fn take_block<Q: Send>(
        &mut self,
        to_world: &(impl Fn(S::Point) -> Q + Sync),
        out: &mut Vec<Q>,
    ) {
        out.clear();
        if self.at >= self.block.len() && !self.refill() {
            return;
        }
        out.par_extend(
            self.block[self.at..]
                .par_iter()
                .with_min_len(4096)
                .map(|s| to_world(s.position)),
        );
        self.at = self.block.len();
    }
}

/// A [`Stream`]'s positions, mapped, a block at a time (see
/// [`Stream::positions`]).
pub struct Positions<'a, S: TileSystem, F> {
    stream: Stream<'a, S>,
    to_world: F,
}

impl<S, F, Q> Blocks<Q> for Positions<'_, S, F>
where
    S: TileSystem,
    F: Fn(S::Point) -> Q + Sync,
    Q: Send,
{
    fn len(&self) -> usize {
        self.stream.len()
    }

    fn try_for_each_block(
        &mut self,
        f: &mut dyn FnMut(&[Q]) -> std::io::Result<()>,
    ) -> std::io::Result<()> {
        let (stream, to_world) = (&mut self.stream, &self.to_world);
        let (mut current, mut next) = (Vec::new(), Vec::new());
        stream.take_block(to_world, &mut current);
        while !current.is_empty() {
            let mut handed = Ok(());
            rayon::in_place_scope(|scope| {
                scope.spawn(|_| stream.take_block(to_world, &mut next));
                handed = f(&current);
            });
            handed?;
            std::mem::swap(&mut current, &mut next);
        }
        Ok(())
    }
}

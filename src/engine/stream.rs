//! Uniform samples in code order, block by block: no recursion, no sort,
//! and memory for one block whatever the count.

use super::Sample;
use crate::tiling::{code_value, Code, TileSystem};

/// Codes computed at a time by a [`Stream`] (2 MB of sphere samples): the
/// systems' block code shares a block out among threads, and each block
/// recomputes the ancestors of its codes on every level with more tiles
/// than a block has codes, so larger blocks cost fewer ancestors a sample
/// (see `scripts/whole-process.sh` for what streaming costs).
const STREAM_BLOCK: usize = 1 << 16;

/// Uniform samples in progressive order, computed a block of
/// 2^16 codes at a time ([`TileSystem::code_order_samples`]
/// over consecutive code ranges, so they equal the in-memory path's sample
/// for sample): memory stays one block however many are drawn.
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
    system.tile_with_code(level, 0)?;
    Some(Stream {
        system,
        level,
        fraction: d / system.capacity(level),
        d,
        next: 0,
        end: count,
        block: Vec::new(),
        at: 0,
    })
}
impl<S: TileSystem> Stream<'_, S> {
    /// Whether each block rebuilds more than one level of ancestor tiles
    /// that no other block shares. Where a level above the stream's has
    /// more tiles than a block has codes, a block's ancestors on it are its
    /// own (consecutive codes have consecutive, distinct parents), and a
    /// stream builds them again for every block, while generating the
    /// whole request at once builds every tile once. One such level (the
    /// parents) costs little beside placing the samples; from two on, a
    /// stream costs more a sample than the in-memory path.
    ///
    /// # Example
    /// ```
    /// use tessera::{engine, tiling::sphere::SphereTiling};
    /// let sphere = SphereTiling::default();
    /// assert!(!engine::stream(&sphere, 100_000).unwrap().rebuilds_ancestors());
    /// assert!(engine::stream(&sphere, 10_000_000).unwrap().rebuilds_ancestors());
    /// let hexomino = tessera::tiling::plane::PlaneTiling::ghexomino();
    /// assert!(!engine::stream(&hexomino, 10_000_000).unwrap().rebuilds_ancestors());
    /// ```
    pub fn rebuilds_ancestors(&self) -> bool {
        self.level > 1 && self.system.capacity(self.level - 2) > STREAM_BLOCK as f64
    }

    /// Refills the block with the next codes; false at the end.
    fn refill(&mut self) -> bool {
        if self.next >= self.end {
            return false;
        }
        let codes = self.next..self.end.min(self.next.saturating_add(STREAM_BLOCK));
        self.next = codes.end;
        self.at = 0;
        let (system, level, fraction, d) = (self.system, self.level, self.fraction, self.d);
        let rank = |code: usize| code_value(code as Code) / d;
        if !system.code_order_samples(level, codes.clone(), fraction, d, &mut self.block) {
            // systems that find tiles only one at a time
            self.block.clear();
            self.block.extend(codes.map_while(|code| {
                let tile = system.tile_with_code(level, code as Code)?;
                Some(Sample {
                    position: system.sample(&tile, fraction),
                    rank: rank(code),
                })
            }));
        }
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

//! Uniform samples one at a time in code order: no recursion, no sort, no
//! buffer.

use super::Sample;
use crate::tiling::{code_value, Code, TileSystem};

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
    pub(super) level: u32,
    pub(super) fraction: f64,
    pub(super) d: f64,
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

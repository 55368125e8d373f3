//! Points handed on a block at a time, so that a writer behind a trait
//! object pays one dynamic call a block rather than one a point (the call
//! a point took a tenth of a uniform 10^7-point request, `perf`).

use std::io;

/// Points in order, handed on a block at a time.
///
/// # Example
/// ```
/// use tessera::blocks::{Blocks, IterBlocks};
/// let mut points = IterBlocks::new(0..10_000u32);
/// assert_eq!(points.len(), 10_000);
/// let mut seen = Vec::new();
/// points.try_for_each_block(&mut |block| {
///     seen.extend_from_slice(block);
///     Ok(())
/// }).unwrap();
/// assert_eq!(seen, (0..10_000).collect::<Vec<_>>());
/// ```
pub trait Blocks<P> {
    /// The number of points not yet handed on.
    fn len(&self) -> usize;

    /// Hands every point to `f` in order, a block at a time, and stops at
    /// the first error `f` returns.
    fn try_for_each_block(&mut self, f: &mut dyn FnMut(&[P]) -> io::Result<()>) -> io::Result<()>;

    /// True when no point is left.
    ///
    /// # Example
    /// ```
    /// use tessera::blocks::{Blocks, IterBlocks};
    /// assert!(IterBlocks::new(std::iter::empty::<f64>()).is_empty());
    /// ```
    fn is_empty(&self) -> bool {
        self.len() == 0
    }
}

/// The points of an exact-size iterator, gathered into blocks of 4096.
///
/// # Example
/// ```
/// use tessera::blocks::{Blocks, IterBlocks};
/// let mut sizes = Vec::new();
/// IterBlocks::new(vec![1.5f64; 5000])
///     .try_for_each_block(&mut |block| {
///         sizes.push(block.len());
///         Ok(())
///     })
///     .unwrap();
/// assert_eq!(sizes, [4096, 904]);
/// ```
pub struct IterBlocks<I> {
    points: I,
}

impl<I: ExactSizeIterator> IterBlocks<I> {
    /// The points of `points`.
    ///
    /// # Example
    /// ```
    /// use tessera::blocks::{Blocks, IterBlocks};
    /// assert_eq!(IterBlocks::new([glam::DVec3::Z].into_iter()).len(), 1);
    /// ```
    pub fn new(points: impl IntoIterator<IntoIter = I>) -> Self {
        IterBlocks {
            points: points.into_iter(),
        }
    }
}

/// Points gathered a block.
const ITER_BLOCK: usize = 4096;

impl<I> Blocks<I::Item> for IterBlocks<I>
where
    I: ExactSizeIterator,
    I::Item: Copy,
{
    fn len(&self) -> usize {
        self.points.len()
    }

    fn try_for_each_block(
        &mut self,
        f: &mut dyn FnMut(&[I::Item]) -> io::Result<()>,
    ) -> io::Result<()> {
        let mut block = Vec::with_capacity(ITER_BLOCK.min(self.points.len()));
        loop {
            block.clear();
            block.extend(self.points.by_ref().take(ITER_BLOCK));
            if block.is_empty() {
                return Ok(());
            }
            f(&block)?;
        }
    }
}

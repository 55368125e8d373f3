//! The "offset tables off" knob: [`WithoutOffsets`] places each accepted
//! tile's sample at the tile's reference point (the polyominoes' centroid,
//! the Penrose point tiles' vertex) instead of reference point plus table
//! offset, so the accuracy bench can measure what the optimised offsets buy.
//!
//! ```
//! use tessera::tiling::{reference::WithoutOffsets, sphere::SphereTiling, TileSystem};
//! use tessera::{density::Uniform, engine};
//! let plain = WithoutOffsets(SphereTiling::default());
//! assert_eq!(engine::generate(&plain, &Uniform, 100, true).unwrap().len(), 100);
//! ```

use super::{Code, TileSystem};

/// A tile system that can name a tile's reference point (the point its
/// table offsets are relative to, up to a fixed shift).
///
/// # Example
/// ```
/// use tessera::tiling::{plane::PlaneTiling, reference::ReferencePoint, TileSystem};
/// let t = PlaneTiling::ghexomino();
/// let p = t.reference(&t.roots()[0]);
/// assert!(p.x >= 0.0 && p.x < 1.0);
/// ```
pub trait ReferencePoint: TileSystem {
    /// The point the tile's offsets are relative to, in the system's point
    /// space (mirrored into the domain as [`TileSystem::sample`] is).
    fn reference(&self, tile: &Self::Tile) -> Self::Point;
    /// The reference point as the recursion places it: `None` outside the
    /// domain (see [`TileSystem::sample_in_domain`]).
    fn reference_in_domain(&self, tile: &Self::Tile) -> Option<Self::Point> {
        Some(self.reference(tile))
    }
}

/// `S` with every sample at its tile's [`ReferencePoint`]: same tiles,
/// codes and regions, no offsets.
///
/// # Example
/// ```
/// use tessera::tiling::{reference::WithoutOffsets, plane::PlaneTiling, TileSystem};
/// let t = WithoutOffsets(PlaneTiling::ppentomino());
/// let root = t.roots()[0];
/// assert_eq!(t.sample(&root, 1.0), t.sample(&root, 0.1));
/// ```
#[derive(Clone)]
pub struct WithoutOffsets<S>(pub S);

impl<S: ReferencePoint> TileSystem for WithoutOffsets<S> {
    type Tile = S::Tile;
    type Point = S::Point;
    type Region = S::Region;

    fn roots(&self) -> Vec<S::Tile> {
        self.0.roots()
    }
    fn child_count(&self, tile: &S::Tile) -> usize {
        self.0.child_count(tile)
    }
    fn child(&self, tile: &S::Tile, i: usize) -> S::Tile {
        self.0.child(tile, i)
    }
    fn level(&self, tile: &S::Tile) -> u32 {
        self.0.level(tile)
    }
    fn max_level(&self) -> u32 {
        self.0.max_level()
    }
    fn capacity(&self, level: u32) -> f64 {
        self.0.capacity(level)
    }
    fn measure(&self) -> f64 {
        self.0.measure()
    }
    fn code(&self, tile: &S::Tile) -> Code {
        self.0.code(tile)
    }
    fn child_code(&self, tile: &S::Tile, i: usize) -> Code {
        self.0.child_code(tile, i)
    }
    fn region(&self, tile: &S::Tile) -> S::Region {
        self.0.region(tile)
    }
    fn placing_region(&self, tile: &S::Tile, region: &S::Region) -> Option<S::Region> {
        self.0.placing_region(tile, region)
    }
    fn tile_with_code(&self, level: u32, code: Code) -> Option<S::Tile> {
        self.0.tile_with_code(level, code)
    }
    fn map_code_order<T: Send>(
        &self,
        level: u32,
        codes: std::ops::Range<usize>,
        f: &(dyn Fn(Code, &S::Tile) -> T + Sync),
    ) -> Option<Vec<T>> {
        self.0.map_code_order(level, codes, f)
    }
    fn carries_sample(&self, tile: &S::Tile) -> bool {
        self.0.carries_sample(tile)
    }
    fn codes_per_sample(&self) -> f64 {
        self.0.codes_per_sample()
    }
    fn sample_in_domain(&self, tile: &S::Tile, _fraction: f64) -> Option<S::Point> {
        self.0.reference_in_domain(tile)
    }
    fn sample(&self, tile: &S::Tile, _fraction: f64) -> S::Point {
        self.0.reference(tile)
    }
}

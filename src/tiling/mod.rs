//! Tile systems: the self-similar tilings the engine recurses over.
//!
//! A tile system knows its geometry, production rules, codes, structural
//! indices and offset tables; it knows nothing of densities or file formats.
//! [`crate::engine`] drives any [`TileSystem`].

pub mod plane;
pub mod polyomino;
pub mod reference;
pub mod sphere;

/// A tile's threshold code (see [`TileSystem`]). Wide enough for the
/// deepest level of every system; compare it with densities through `as f64`.
///
/// # Example
/// ```
/// let code: tessera::tiling::Code = 7;
/// assert_eq!(code as f64 + 0.5, 7.5);
/// ```
pub type Code = u64;

/// A self-similar tiling with codes and offset tables, as the engine sees it.
///
/// Codes: every tile at `level` has a code in `0..capacity(level)`; over the
/// whole domain the codes of one level are a permutation of that range, and a
/// child's code extends its parent's with a new most significant digit. A
/// terminal tile is accepted when `code < d`, `d` being the requested density
/// in samples per domain, so thresholds keep well-spread subsets.
///
/// # Example
/// ```
/// use tessera::tiling::{sphere::SphereTiling, TileSystem};
/// let sphere = SphereTiling::default();
/// assert_eq!(sphere.roots().len(), 240);
/// assert_eq!(sphere.capacity(1), 960.0);
/// ```
pub trait TileSystem: Sync {
    /// A tile: small, copied through the recursion.
    type Tile: Copy + Send + Sync;
    /// A sample position.
    type Point: Copy + Send + Sync;
    /// What a density needs to bound itself over a tile.
    type Region;

    /// The level-0 tiles.
    fn roots(&self) -> Vec<Self::Tile>;
    /// Number of children of `tile`.
    fn child_count(&self, tile: &Self::Tile) -> usize;
    /// Child `i` (in production-rule order) of `tile`.
    fn child(&self, tile: &Self::Tile, i: usize) -> Self::Tile;
    /// Subdivision level of a tile (roots are level 0).
    fn level(&self, tile: &Self::Tile) -> u32;
    /// Deepest level the system supports without overflow or loss of precision.
    fn max_level(&self) -> u32;
    /// Number of tiles covering the domain at `level` (the code range).
    fn capacity(&self, level: u32) -> f64;
    /// Measure of the whole domain (4 pi for the sphere, area for the plane).
    fn measure(&self) -> f64;
    /// The tile's threshold code.
    fn code(&self, tile: &Self::Tile) -> Code;
    /// The code of child `i` of `tile`, without building the child (the
    /// engine skips most children on their code alone).
    fn child_code(&self, tile: &Self::Tile, i: usize) -> Code {
        self.code(&self.child(tile, i))
    }
    /// The region a density bounds itself over.
    fn region(&self, tile: &Self::Tile) -> Self::Region;
    /// The tile of `level` whose code is `code`, when the system can find it
    /// directly (base-A codes can: their digits spell the path from the
    /// root). Lets uniform requests stream in code order with no recursion,
    /// sort or buffer. `None` when unsupported or out of range.
    fn tile_with_code(&self, level: u32, code: Code) -> Option<Self::Tile> {
        let _ = (level, code);
        None
    }
    /// `f(code, tile)` for the tiles of `level` with codes `0..count`, in
    /// code order (what a constant density accepts), or `None` when the
    /// system cannot find tiles from codes. The default finds each by
    /// [`TileSystem::tile_with_code`]; systems with base-A codes share the
    /// parents of each digit block instead.
    fn map_code_order<T: Send>(
        &self,
        level: u32,
        count: usize,
        f: &(dyn Fn(Code, &Self::Tile) -> T + Sync),
    ) -> Option<Vec<T>> {
        (0..count as Code)
            .map(|code| self.tile_with_code(level, code).map(|t| f(code, &t)))
            .collect()
    }
    /// The sample position of an accepted tile, when the local density is
    /// `fraction * capacity(level)` (fraction in `(0, 1]`): reference point
    /// plus the table offset in the tile's basis.
    fn sample(&self, tile: &Self::Tile, fraction: f64) -> Self::Point;
}

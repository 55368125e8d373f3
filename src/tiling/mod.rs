//! Tile systems: the self-similar tilings the engine recurses over.
//!
//! A tile system knows its geometry, production rules, codes, structural
//! indices and offset tables; it knows nothing of densities or file formats.
//! [`crate::engine`] drives any [`TileSystem`].

pub mod code_order;
pub mod penrose;
pub mod plane;
pub mod reference;
pub mod sphere;

use crate::sample::Sample;
use code_order::CodeOrder;
use std::ops::Range;

/// A tile's threshold code (see [`TileSystem`]). 128 bits hold the codes of
/// every system's deepest level (the sphere's level 36 has `240 * 4^36`
/// tiles, more than `u64` counts); compare codes with densities through
/// [`code_value`].
///
/// # Example
/// ```
/// let code: tessera::tiling::Code = 7;
/// assert_eq!(tessera::tiling::code_value(code) + 0.5, 7.5);
/// ```
pub type Code = u128;

/// `code` as an f64. Codes below 2^63 (every sphere level to 27) take one
/// instruction; a plain `as f64` of a u128 is a library call, which the
/// engine would pay at every tile.
///
/// # Example
/// ```
/// use tessera::tiling::code_value;
/// assert_eq!(code_value(3), 3.0);
/// assert_eq!(code_value(1 << 100), 2f64.powi(100));
/// ```
#[inline(always)]
pub fn code_value(code: Code) -> f64 {
    // the wide conversion sits out of line so that the compiler does not
    // compute it speculatively next to the fast one
    #[cold]
    #[inline(never)]
    fn wide(code: Code) -> f64 {
        code as f64
    }
    // through i64: x86-64 converts signed integers in one instruction,
    // unsigned ones in several
    match i64::try_from(code) {
        Ok(small) => small as f64,
        Err(_) => wide(code),
    }
}

/// A self-similar tiling with codes and offset tables, as the engine sees it.
///
/// Codes: every tile at `level` has a code in `0..capacity(level)`; over the
/// whole domain the codes of one level are a permutation of that range (or,
/// for Penrose's Fibonacci codes, spread evenly over it: see
/// [`TileSystem::codes_per_sample`]), and a child's code extends its
/// parent's with a new most significant digit. A terminal tile is accepted
/// when `code < d`, `d` being the requested density in samples per domain
/// (times `codes_per_sample`), so thresholds keep well-spread subsets.
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
    type Point: crate::Position + Send + Sync;
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
    /// The child (production-rule index) holding the `rank`-th smallest code
    /// among `tile`'s children, when the system knows it without comparing
    /// codes (base-A codes: the child of digit `rank`); `None` otherwise.
    /// With it the engine visits the children a bound makes terminal in
    /// code order and stops at the first the bound rejects, instead of
    /// testing all `A` of them.
    ///
    /// # Example
    /// ```
    /// use tessera::tiling::{plane::PlaneTiling, TileSystem};
    /// let t = PlaneTiling::ghexomino();
    /// let root = t.roots()[0];
    /// let codes: Vec<_> = (0..81)
    ///     .map(|r| t.child_code(&root, t.child_by_code_rank(&root, r).unwrap()))
    ///     .collect();
    /// assert!(codes.windows(2).all(|w| w[0] < w[1]));
    /// ```
    fn child_by_code_rank(&self, tile: &Self::Tile, rank: usize) -> Option<usize> {
        let _ = (tile, rank);
        None
    }
    /// The region a density bounds itself over.
    fn region(&self, tile: &Self::Tile) -> Self::Region;
    /// The region whose density bound picks the importance bin a terminal
    /// tile's sample is placed for, where it is tighter than
    /// [`TileSystem::region`]: the tile's own cells (or their box), while the region must
    /// also hold the samples that land past them. A tighter bound fits the
    /// bin to the share of its set that is kept (see the [`crate::engine`]
    /// module doc, Two bounds). `region` is the tile's
    /// [`TileSystem::region`], which the engine has already built: the two
    /// share most of their fields. `None` (the default): the region's bound
    /// picks it.
    ///
    /// # Example
    /// ```
    /// use tessera::tiling::{sphere::SphereTiling, TileSystem};
    /// let sphere = SphereTiling::default();
    /// let tile = sphere.roots()[5];
    /// let region = sphere.region(&tile);
    /// let placing = sphere.placing_region(&tile, &region).unwrap();
    /// assert!(placing.radius < region.radius);
    /// ```
    fn placing_region(&self, tile: &Self::Tile, region: &Self::Region) -> Option<Self::Region> {
        let _ = (tile, region);
        None
    }
    /// The tile of `level` whose code is `code`, when the system can find it
    /// directly (base-A codes can: their digits spell the path from the
    /// root). Lets uniform requests stream in code order with no recursion,
    /// sort or buffer. `None` when unsupported or out of range.
    fn tile_with_code(&self, level: u32, code: Code) -> Option<Self::Tile> {
        let _ = (level, code);
        None
    }
    /// `f(code, tile)` for the tiles of `level` whose codes lie in `codes`,
    /// in code order (a constant density accepts a prefix `0..count`; a
    /// stream asks for consecutive ranges), or `None` when the system cannot
    /// find tiles from codes or the range passes the level's capacity. The
    /// default finds each by [`TileSystem::tile_with_code`]; systems with
    /// base-A codes share the parents of each digit block instead.
    fn map_code_order<T: Send>(
        &self,
        level: u32,
        codes: Range<usize>,
        f: &(dyn Fn(Code, &Self::Tile) -> T + Sync),
    ) -> Option<Vec<T>> {
        codes
            .map(|code| {
                let code = code as Code;
                self.tile_with_code(level, code).map(|t| f(code, &t))
            })
            .collect()
    }
    /// A source of the samples of the tiles of `level` whose codes lie in
    /// `codes` (`0..count` is what a constant density of `d` samples per
    /// domain accepts: density `fraction` of the level's capacity), ranked
    /// `code / d`, in code order, over consecutive ranges (what a stream
    /// asks for, block by block); `None` as
    /// [`TileSystem::map_code_order`] would be. The default samples every
    /// tile that method yields; systems override it to place points
    /// without building the tiles' ancestors again for every range.
    ///
    /// # Example
    /// ```
    /// use tessera::tiling::{sphere::SphereTiling, TileSystem};
    /// let sphere = SphereTiling::default();
    /// let mut source = sphere.code_order(2, 0..3000, 3000.0 / 3840.0, 3000.0).unwrap();
    /// let mut s = Vec::new();
    /// source.fill(1000..3000, &mut s);
    /// assert_eq!(s[0].rank, 1000.0 / 3000.0);
    /// ```
    fn code_order(
        &self,
        level: u32,
        codes: Range<usize>,
        fraction: f64,
        d: f64,
    ) -> Option<Box<dyn CodeOrder<Self::Point> + '_>> {
        let fits = level <= self.max_level() && codes.end as f64 <= self.capacity(level);
        (fits && self.tile_with_code(level, 0).is_some()).then(|| {
            Box::new(ByMap {
                system: self,
                level,
                fraction,
                d,
            }) as Box<dyn CodeOrder<Self::Point>>
        })
    }
    /// Writes into `out` (replacing its contents) the samples of the tiles
    /// of `level` whose codes lie in `codes`, as one range of
    /// [`TileSystem::code_order`]. False, leaving `out` unspecified, as
    /// that method returns `None`.
    ///
    /// # Example
    /// ```
    /// use tessera::tiling::{sphere::SphereTiling, TileSystem};
    /// let sphere = SphereTiling::default();
    /// let mut s = Vec::new();
    /// assert!(sphere.code_order_samples(1, 0..500, 500.0 / 960.0, 500.0, &mut s));
    /// assert_eq!(s.len(), 500);
    /// assert_eq!(s[10].rank, 10.0 / 500.0);
    /// let mut tail = Vec::new();
    /// assert!(sphere.code_order_samples(1, 490..500, 500.0 / 960.0, 500.0, &mut tail));
    /// assert_eq!(tail, s[490..]);
    /// ```
    fn code_order_samples(
        &self,
        level: u32,
        codes: Range<usize>,
        fraction: f64,
        d: f64,
        out: &mut Vec<Sample<Self::Point>>,
    ) -> bool {
        let source = self.code_order(level, codes.clone(), fraction, d);
        source.map(|mut source| source.fill(codes, out)).is_some()
    }
    /// Whether a terminal tile carries a sample. Penrose triangles only
    /// subdivide: its point tiles carry the samples.
    fn carries_sample(&self, tile: &Self::Tile) -> bool {
        let _ = tile;
        true
    }
    /// Code units per expected sample: over the domain, about
    /// `c / codes_per_sample()` sampling tiles of a level have codes below
    /// `c`. 1 when codes are a permutation of `0..capacity` (systems that
    /// find tiles from codes must keep it 1); the engine scales requests by
    /// it.
    fn codes_per_sample(&self) -> f64 {
        1.0
    }
    /// The sample of an accepted tile as the recursion places it: `None`
    /// when it falls outside the domain (a tiling that extends beyond its
    /// domain keeps only the samples inside, so spacing holds at the
    /// border). Defaults to [`TileSystem::sample`].
    fn sample_in_domain(&self, tile: &Self::Tile, fraction: f64) -> Option<Self::Point> {
        Some(self.sample(tile, fraction))
    }
    /// The sample position of an accepted tile, when the local density is
    /// `fraction * capacity(level)` (fraction in `(0, 1]`): reference point
    /// plus the table offset in the tile's basis.
    fn sample(&self, tile: &Self::Tile, fraction: f64) -> Self::Point;
}

/// `v` mirrored into `[0, 1)` at the unit square's edges (points an offset
/// carries just outside re-enter).
#[inline]
pub(crate) fn mirror_unit(v: f64) -> f64 {
    let w = if v < 0.0 {
        -v
    } else if v >= 1.0 {
        2.0 - v
    } else {
        return v;
    };
    // offsets move points less than a root tile, so one mirror suffices;
    // the largest f64 below 1 keeps the half-open square
    w.clamp(0.0, 1.0 - f64::EPSILON / 2.0)
}

/// [`TileSystem::code_order`]'s default: every tile
/// [`TileSystem::map_code_order`] yields, sampled.
struct ByMap<'a, S: ?Sized> {
    system: &'a S,
    level: u32,
    fraction: f64,
    d: f64,
}

impl<S: TileSystem + ?Sized> CodeOrder<S::Point> for ByMap<'_, S> {
    fn fill(&mut self, codes: Range<usize>, out: &mut Vec<Sample<S::Point>>) {
        let (system, fraction, d) = (self.system, self.fraction, self.d);
        let samples = system.map_code_order(self.level, codes, &|code, tile| Sample {
            position: system.sample(tile, fraction),
            rank: code_value(code) / d,
        });
        // in range: `code_order` checked
        *out = samples.unwrap_or_default();
    }
}

/// The digit blocks of base-A codes that `codes` meets, with `m` codes a
/// block (the parent level's tile count): each as `(digit, within)`,
/// `within` the range's part of the block as offsets `c` of codes
/// `digit * m + c`, which are the codes of their parents one level up.
///
/// # Example
/// ```
/// use tessera::tiling::digit_blocks;
/// assert_eq!(digit_blocks(&(5..23), 10), vec![(0, 5..10), (1, 0..10), (2, 0..3)]);
/// assert_eq!(digit_blocks(&(12..14), 10), vec![(1, 2..4)]);
/// ```
pub fn digit_blocks(codes: &Range<usize>, m: usize) -> Vec<(usize, Range<usize>)> {
    if codes.is_empty() {
        return Vec::new();
    }
    (codes.start / m..=(codes.end - 1) / m)
        .map(|digit| {
            let start = digit * m;
            let within = codes.start.max(start) - start..codes.end.min(start + m) - start;
            (digit, within)
        })
        .collect()
}

/// The offsets `c` that digit blocks (see [`digit_blocks`]) cover
/// together: the parent codes they need.
pub(crate) fn span(blocks: &[(usize, Range<usize>)]) -> Range<usize> {
    let start = blocks.iter().map(|b| b.1.start).min().unwrap_or(0);
    start..blocks.iter().map(|b| b.1.end).max().unwrap_or(start)
}

//! Planar polyomino tile systems on the unit square, driven by data.
//!
//! Any `A`-rep polyomino given as production rules (child placements in the
//! parent's refined frame) becomes a tile system: a root patch of tiles
//! covers `[0, side)^2` cells, mapped onto `[0, 1)^2`; each level refines the
//! lattice by the rule's scale. Codes are base-`A` integers (a child's digit
//! is its sibling rank, newest digit most significant, over the roots'
//! ranks); structural indices follow the table's automaton; offsets come per
//! (structural index, importance bin). Everything is in the table
//! ([`PlaneLut`]); `tessera lut build --system ghexomino|ppentomino` makes it.
//!
//! The offsets were optimised on the torus (the root patch tiles the plane
//! periodically); a point an offset pushes across the square's border is
//! mirrored back inside (`mirror_unit`), so every point lies in `[0, 1)^2`.

use crate::lut::{plane_lut, PlaneLut, PlaneSystem};
use crate::polyomino::{Lattice, Orientation, Placement, Shape};
use crate::sample::Sample;
use crate::tiling::code_order::{self, CodeOrder, Indexing, Listed, Node, Subdivision};
use crate::tiling::{code_value, digit_blocks, mirror_unit, span, Code, TileSystem};
use glam::DVec2;
use rayon::prelude::*;
use std::ops::Range;
use std::sync::Arc;

/// Most cells a planar rep-tile may have (the size of [`PlaneRegion::cells`]).
pub use crate::lut::MAX_CELLS;

/// A tile of a planar polyomino system.
///
/// # Example
/// ```
/// use tessera::tiling::{plane::PlaneTiling, TileSystem};
/// let t = PlaneTiling::ppentomino();
/// assert_eq!(t.roots()[0].level, 0);
/// ```
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct PlaneTile {
    /// Position on the lattice of `side * scale^level` cells per unit.
    pub placement: Placement,
    /// Subdivision level.
    pub level: u8,
    /// The rule this tile's children follow.
    pub rule: u8,
    /// Structural index (automaton state).
    pub class: u32,
    /// Threshold code, `0..roots * A^level`.
    pub code: Code,
}

/// A planar tile as a density sees it: a box holding the tile and every
/// sample it and its descendants place, and its cell centres.
///
/// # Example
/// ```
/// use tessera::tiling::{plane::PlaneTiling, TileSystem};
/// let t = PlaneTiling::ppentomino();
/// let root = t.roots()[0];
/// let r = t.region(&root);
/// assert_eq!(r.count, 5);
/// let sample = t.sample(&root, 0.3);
/// assert!(sample.cmpge(r.lo).all() && sample.cmple(r.hi).all());
/// ```
#[derive(Clone, Copy, Debug)]
pub struct PlaneRegion {
    /// Lower corner of the box (it may reach past the unit square).
    pub lo: DVec2,
    /// Upper corner of the box (it may reach past the unit square).
    pub hi: DVec2,
    /// Side of one cell.
    pub cell: f64,
    /// Cell centres (the first `count`).
    pub cells: [DVec2; MAX_CELLS],
    /// Number of cells.
    pub count: u8,
    /// Mean of the cell centres, kept with them by whoever fills them: a
    /// linear density's average over the tile is its value here.
    pub centroid: DVec2,
}

impl PlaneRegion {
    /// The tile's cell centres.
    ///
    /// # Example
    /// ```
    /// use tessera::tiling::{plane::PlaneTiling, TileSystem};
    /// let t = PlaneTiling::ghexomino();
    /// assert_eq!(t.region(&t.roots()[0]).centres().len(), 6);
    /// ```
    pub fn centres(&self) -> &[DVec2] {
        &self.cells[..self.count as usize]
    }
}

/// A planar polyomino tile system driven by a [`PlaneLut`].
///
/// # Example
/// ```
/// use tessera::{engine, density::Uniform, tiling::plane::PlaneTiling};
/// let s = engine::generate(&PlaneTiling::ghexomino(), &Uniform, 1000, true).unwrap();
/// assert_eq!(s.len(), 1000);
/// assert!(s.iter().all(|p| p.position.cmpge(glam::DVec2::ZERO).all()
///     && p.position.cmplt(glam::DVec2::ONE).all()));
/// ```
#[derive(Clone)]
pub struct PlaneTiling {
    lut: Arc<PlaneLut>,
    arity: usize,
    scale: Lattice,
    bins: usize,
    max_level: u32,
    roots_by_code: Vec<PlaneTile>,
    /// `steps[(rule * A + child) * 8 + parent orientation]`: the child's
    /// placement in a parent at the origin so oriented, on the refined
    /// lattice.
    steps: Vec<Placement>,
    /// `child_rule[rule * A + child]`.
    child_rule: Vec<u8>,
    /// `code_steps[level * rules * A + rule * A + child]`: what the child's
    /// digit adds to its parent's code (a lookup, not a 128-bit product).
    code_steps: Vec<Code>,
    /// `child_of_digit[rule * A + digit]`.
    child_of_digit: Vec<u8>,
    /// Decoded offsets, `class * bins + bin`.
    offsets: Vec<[f64; 2]>,
    /// Roots times `A^level`: the weight of a level's new digit.
    digit_weight: Vec<Code>,
    /// `1 / (side * scale^level)`: lattice to unit square.
    inv_size: Vec<f64>,
    /// The shape's cells and bounding box in each of the 8 orientations.
    frames: [Frame; 8],
    /// `boxes[class * 8 + orientation]`: see [`sample_boxes`].
    boxes: Vec<[DVec2; 2]>,
    /// The bin edges of [`PlaneTiling::bin`], widened by its tolerance and
    /// padded with infinities to a power of two longer than `bins`, for a
    /// binary search of a fixed number of halving steps. Neighbouring tiles
    /// mostly share a bin, so the steps' branches are predicted and the
    /// offset's loads start early; searches whose result is a chain of
    /// loads ran slower on ramp requests in interleaved runs, though they
    /// execute fewer instructions: `partition_point` by about 20 %, a
    /// table indexed by the fraction's bits with one branch-free step
    /// (half the instructions of the whole `sample`) by about 10 %.
    bin_edges: Vec<f64>,
}

/// A rep-tile's cell centres, their mean and the corners of its bounding box, relative
/// to a placement's origin, in one orientation (in cells, as f64 so that a
/// region costs a multiply-add per coordinate). `centres` is padded to
/// [`MAX_CELLS`] by repeating the first, so a region is filled without
/// branches; `count` says how many are real.
#[derive(Clone, Debug, Default)]
struct Frame {
    centres: [DVec2; MAX_CELLS],
    count: u8,
    centroid: DVec2,
    lo: DVec2,
    hi: DVec2,
}

/// The box a tile's region gives, per class and orientation: the cells'
/// box grown to hold the tile's samples in every bin (the optimised
/// offsets carry points into the neighbours' room) and its descendants'
/// (inside its cells, and past theirs by at most `reach / scale`, `reach`
/// the farthest any offset leaves its box). A density bounded over less
/// would see samples land above their tile's bound, whose keep
/// probability then saturates: a bias (DESIGN.md, Planar polyominoes).
fn sample_boxes(
    frames: &[Frame; 8],
    offsets: &[[f64; 2]],
    bins: usize,
    scale: Lattice,
) -> Vec<[DVec2; 2]> {
    let turn = |o: Orientation, offset: [f64; 2]| DVec2::from(o.apply_f64(offset));
    let mut reach: f64 = 0.0;
    for (frame, o) in frames.iter().zip(Orientation::ALL) {
        for &offset in offsets {
            let p = turn(o, offset);
            reach = reach.max((frame.lo - p).max(p - frame.hi).max_element());
        }
    }
    let descendant_margin = reach / scale as f64;
    let mut boxes = Vec::with_capacity(offsets.len() / bins * 8);
    for class in offsets.chunks(bins) {
        for (frame, o) in frames.iter().zip(Orientation::ALL) {
            let (mut lo, mut hi) = (frame.lo - descendant_margin, frame.hi + descendant_margin);
            for &offset in class {
                let p = turn(o, offset);
                (lo, hi) = (lo.min(p), hi.max(p));
            }
            boxes.push([lo, hi]);
        }
    }
    boxes
}

impl Frame {
    fn new(shape: &Shape, orientation: Orientation) -> Self {
        let corners: Vec<DVec2> = Placement::new((0, 0), orientation)
            .cells(shape)
            .map(|(x, y)| DVec2::new(x as f64, y as f64))
            .collect();
        let lo = corners
            .iter()
            .copied()
            .reduce(DVec2::min)
            .unwrap_or_default();
        let hi = corners
            .iter()
            .copied()
            .reduce(DVec2::max)
            .unwrap_or_default();
        Frame {
            centres: std::array::from_fn(|i| corners.get(i).unwrap_or(&corners[0]) + 0.5),
            count: corners.len() as u8,
            centroid: corners.iter().copied().sum::<DVec2>() / corners.len() as f64 + 0.5,
            lo,
            hi: hi + 1.0,
        }
    }
}

/// The box `lo..hi` grown to hold the mirror images (`mirror_unit`) of its
/// parts outside the unit square, where samples carried past the border
/// land.
#[inline(always)]
fn mirrored_box(mut lo: DVec2, mut hi: DVec2) -> (DVec2, DVec2) {
    for axis in 0..2 {
        if hi[axis] > 1.0 {
            lo[axis] = lo[axis].min(2.0 - hi[axis]);
        }
        if lo[axis] < 0.0 {
            hi[axis] = hi[axis].max(-lo[axis]);
        }
    }
    (lo, hi)
}

impl PlaneTiling {
    /// A tiling driven by the given table.
    ///
    /// # Example
    /// ```
    /// use tessera::{lut::{plane_lut, PlaneSystem}, tiling::plane::PlaneTiling};
    /// let t = PlaneTiling::new(plane_lut(PlaneSystem::Ppentomino));
    /// assert_eq!(t.lut().side, 10);
    /// ```
    pub fn new(lut: Arc<PlaneLut>) -> Self {
        let arity = lut.arity();
        let scale = lut.rules[0].scale;
        let roots = lut.roots.len() as Code;
        let max_level = deepest_level(lut.side, scale, roots, arity as Code);
        let digit_weight: Vec<Code> = (0..=max_level)
            .map(|l| roots * (arity as Code).pow(l))
            .collect();
        let inv_size = (0..=max_level)
            .map(|l| 1.0 / (lut.side as f64 * (scale as f64).powi(l as i32)))
            .collect();
        let steps = lut
            .rules
            .iter()
            .flat_map(|r| &r.children)
            .flat_map(|child| {
                Orientation::ALL.map(|o| Placement::new((0, 0), o).child(child, scale))
            })
            .collect();
        let child_rule = lut.child_rule.concat();
        let child_digit = lut.child_digit.concat();
        let code_steps = digit_weight
            .iter()
            .flat_map(|&weight| child_digit.iter().map(move |&d| d as Code * weight))
            .collect();
        let mut child_of_digit = vec![0u8; child_digit.len()];
        for (at, &d) in child_digit.iter().enumerate() {
            let rule = at / arity;
            child_of_digit[rule * arity + d as usize] = (at % arity) as u8;
        }
        let offsets: Vec<[f64; 2]> = (0..lut.classes() * lut.bins as usize)
            .map(|k| lut.offset(k / lut.bins as usize, k % lut.bins as usize))
            .collect();
        // a relative tolerance keeps exact bin fractions in their own bin
        let bin_edges = (0..(lut.bins as usize + 1).next_power_of_two())
            .map(|b| match b < lut.bins as usize {
                true => lut.bin_fraction(b) * (1.0 + 1e-9),
                false => f64::INFINITY,
            })
            .collect();
        let mut roots_by_code: Vec<PlaneTile> = (0..lut.roots.len())
            .map(|r| PlaneTile {
                placement: lut.roots[r],
                level: 0,
                rule: lut.root_rule[r],
                class: lut.root_class[r],
                code: lut.root_rank[r] as Code,
            })
            .collect();
        roots_by_code.sort_by_key(|t| t.code);
        let frames = Orientation::ALL.map(|o| Frame::new(&lut.shape, o));
        let boxes = sample_boxes(&frames, &offsets, lut.bins as usize, scale);
        PlaneTiling {
            arity,
            scale,
            bins: lut.bins as usize,
            max_level,
            roots_by_code,
            steps,
            child_rule,
            code_steps,
            child_of_digit,
            offsets,
            digit_weight,
            inv_size,
            frames,
            boxes,
            bin_edges,
            lut,
        }
    }

    /// The G-hexomino system (81-rep) with the table shipped in `luts/`.
    ///
    /// # Example
    /// ```
    /// use tessera::tiling::{plane::PlaneTiling, TileSystem};
    /// assert_eq!(PlaneTiling::ghexomino().capacity(1), 216.0 * 81.0);
    /// ```
    pub fn ghexomino() -> Self {
        PlaneTiling::new(plane_lut(PlaneSystem::Ghexomino))
    }

    /// The P-pentomino system (4-rep) with the table shipped in `luts/`.
    ///
    /// # Example
    /// ```
    /// use tessera::tiling::{plane::PlaneTiling, TileSystem};
    /// assert_eq!(PlaneTiling::ppentomino().capacity(2), 320.0);
    /// ```
    pub fn ppentomino() -> Self {
        PlaneTiling::new(plane_lut(PlaneSystem::Ppentomino))
    }

    /// The table driving this tiling.
    ///
    /// # Example
    /// ```
    /// use tessera::tiling::plane::PlaneTiling;
    /// assert_eq!(PlaneTiling::ghexomino().lut().roots.len(), 216);
    /// ```
    pub fn lut(&self) -> &PlaneLut {
        &self.lut
    }

    /// The rep-tile.
    ///
    /// # Example
    /// ```
    /// use tessera::tiling::plane::PlaneTiling;
    /// assert_eq!(PlaneTiling::ppentomino().shape().cells().len(), 5);
    /// ```
    pub fn shape(&self) -> &Shape {
        &self.lut.shape
    }

    /// Cells per unit length at `level` (the lattice resolution).
    ///
    /// # Example
    /// ```
    /// use tessera::tiling::plane::PlaneTiling;
    /// assert_eq!(PlaneTiling::ppentomino().cells_per_unit(3), 80.0);
    /// ```
    pub fn cells_per_unit(&self, level: u32) -> f64 {
        1.0 / self.inv_size[level.min(self.max_level) as usize]
    }

    /// Child `child` (rule order) of `tile`.
    #[inline(always)]
    fn subdivide(&self, tile: &PlaneTile, child: usize) -> PlaneTile {
        self.child_coded(tile, child, self.child_code_of(tile, child))
    }

    /// The code of child `child` of `tile`.
    #[inline(always)]
    fn child_code_of(&self, tile: &PlaneTile, child: usize) -> Code {
        let at = tile.rule as usize * self.arity + child;
        let per_level = self.child_rule.len();
        tile.code + self.code_steps[tile.level as usize * per_level + at]
    }

    /// Child `child` of `tile`, whose code the caller already knows.
    #[inline(always)]
    fn child_coded(&self, tile: &PlaneTile, child: usize, code: Code) -> PlaneTile {
        let at = tile.rule as usize * self.arity + child;
        PlaneTile {
            placement: self.child_placement(&tile.placement, at),
            level: tile.level + 1,
            rule: self.child_rule[at],
            class: self.lut.transitions[tile.class as usize * self.arity + child],
            code,
        }
    }

    /// The child of `tile` carrying code digit `digit`.
    #[inline]
    fn child_with_digit(&self, tile: &PlaneTile, digit: usize) -> PlaneTile {
        let child = self.child_of_digit[tile.rule as usize * self.arity + digit];
        self.subdivide(tile, child as usize)
    }

    /// Every tile of a level, in tree order. `roots * A^level` tiles: meant
    /// for small levels (drawings, the optimiser).
    ///
    /// # Example
    /// ```
    /// use tessera::tiling::plane::PlaneTiling;
    /// assert_eq!(PlaneTiling::ppentomino().tiles(2).len(), 320);
    /// ```
    pub fn tiles(&self, level: u32) -> Vec<PlaneTile> {
        let mut tiles: Vec<PlaneTile> = (0..self.lut.roots.len()).map(|r| self.root(r)).collect();
        for _ in 0..level.min(self.max_level) {
            tiles = tiles
                .par_iter()
                .flat_map_iter(|t| (0..self.arity).map(move |c| self.subdivide(t, c)))
                .collect();
        }
        tiles
    }

    fn root(&self, r: usize) -> PlaneTile {
        let lut = &*self.lut;
        PlaneTile {
            placement: lut.roots[r],
            level: 0,
            rule: lut.root_rule[r],
            class: lut.root_class[r],
            code: lut.root_rank[r] as Code,
        }
    }

    /// The unit-square point of a point given in the tile's frame (cells),
    /// not wrapped.
    ///
    /// # Example
    /// ```
    /// use tessera::tiling::{plane::PlaneTiling, TileSystem};
    /// let t = PlaneTiling::ppentomino();
    /// let p = t.to_unit(&t.roots()[0], [0.5, 0.5]);
    /// assert!(p.x > 0.0 && p.x < 1.0);
    /// ```
    pub fn to_unit(&self, tile: &PlaneTile, local: [f64; 2]) -> DVec2 {
        let [x, y] = tile.placement.to_lattice(local);
        DVec2::new(x, y) * self.inv_size[tile.level as usize]
    }

    /// The importance bin serving density fraction `fraction` of a level's
    /// capacity: the first bin optimised for at least that fraction, so the
    /// tiles kept are a subset of those the bin was optimised with.
    ///
    /// # Example
    /// ```
    /// use tessera::tiling::plane::PlaneTiling;
    /// let t = PlaneTiling::ppentomino();
    /// assert_eq!(t.bin(1.0), t.lut().bins as usize - 1);
    /// assert_eq!(t.bin(1e-9), 0);
    /// ```
    #[inline]
    pub fn bin(&self, fraction: f64) -> usize {
        // the number of edges below `fraction`, found by halving steps:
        // every edge before `below` lies below it
        let mut below = 0;
        let mut step = self.bin_edges.len() / 2;
        while step > 0 {
            if self.bin_edges[below + step - 1] < fraction {
                below += step;
            }
            step /= 2;
        }
        below.min(self.bins - 1)
    }

    #[inline]
    fn position(&self, tile: &PlaneTile, bin: usize) -> DVec2 {
        let s = self.inv_size[tile.level as usize];
        self.place(&tile.placement, tile.class, bin, s)
    }

    /// The point of a tile so placed, of structural index `class`, in
    /// importance bin `bin`, on a lattice of `1 / s` cells per unit.
    #[inline(always)]
    fn place(&self, placement: &Placement, class: u32, bin: usize, s: f64) -> DVec2 {
        let [x, y] = placement.to_lattice(self.offsets[class as usize * self.bins + bin]);
        DVec2::new(mirror_unit(x * s), mirror_unit(y * s))
    }

    /// The placement of child `at` (`rule * A + child`) of a tile so placed:
    /// [`Placement::child`] from a table of the child's step for each of
    /// the parent's 8 orientations.
    #[inline(always)]
    fn child_placement(&self, parent: &Placement, at: usize) -> Placement {
        let step = &self.steps[at * 8 + parent.orientation.index()];
        Placement {
            origin: (
                self.scale * parent.origin.0 + step.origin.0,
                self.scale * parent.origin.1 + step.origin.1,
            ),
            orientation: step.orientation,
        }
    }

    /// The box `[lo, hi]` (the tile's frame, cells) in the unit square.
    #[inline(always)]
    fn cells_box(&self, tile: &PlaneTile, [lo, hi]: [DVec2; 2]) -> (DVec2, DVec2) {
        let s = self.inv_size[tile.level as usize];
        let (x, y) = tile.placement.origin;
        let origin = DVec2::new(x as f64, y as f64);
        mirrored_box((origin + lo) * s, (origin + hi) * s)
    }

    /// The tile's region with the box `boxed` (the tile's frame, cells).
    fn region_boxed(&self, tile: &PlaneTile, boxed: [DVec2; 2]) -> PlaneRegion {
        let s = self.inv_size[tile.level as usize];
        let (x, y) = tile.placement.origin;
        let origin = DVec2::new(x as f64, y as f64);
        let frame = &self.frames[tile.placement.orientation.index()];
        let mut cells = [DVec2::ZERO; MAX_CELLS];
        for (cell, &centre) in cells.iter_mut().zip(&frame.centres) {
            *cell = (origin + centre) * s;
        }
        let (lo, hi) = self.cells_box(tile, boxed);
        PlaneRegion {
            lo,
            hi,
            cell: s,
            cells,
            count: frame.count,
            centroid: (origin + frame.centroid) * s,
        }
    }
}

impl Subdivision for PlaneTiling {
    fn arity(&self) -> usize {
        self.arity
    }
    fn scale(&self) -> Lattice {
        self.scale
    }
    fn rules(&self) -> usize {
        self.lut.rules.len()
    }
    fn classes(&self) -> usize {
        self.lut.classes()
    }
    fn child_of_digit(&self, rule: usize, digit: usize) -> usize {
        self.child_of_digit[rule * self.arity + digit] as usize
    }
    fn child_rule(&self, rule: usize, child: usize) -> usize {
        self.child_rule[rule * self.arity + child] as usize
    }
    fn child_step(&self, rule: usize, child: usize) -> Placement {
        self.lut.rules[rule].children[child]
    }
    fn child_class(&self, class: usize, child: usize) -> usize {
        self.lut.transitions[class * self.arity + child] as usize
    }
}

impl TileSystem for PlaneTiling {
    type Tile = PlaneTile;
    type Point = DVec2;
    type Region = PlaneRegion;

    fn roots(&self) -> Vec<PlaneTile> {
        (0..self.lut.roots.len()).map(|r| self.root(r)).collect()
    }

    fn child_count(&self, _: &PlaneTile) -> usize {
        self.arity
    }

    #[inline(always)]
    fn child(&self, tile: &PlaneTile, i: usize) -> PlaneTile {
        self.subdivide(tile, i)
    }

    fn child_code(&self, tile: &PlaneTile, i: usize) -> Code {
        self.child_code_of(tile, i)
    }

    /// Codes grow with the child's digit.
    #[inline(always)]
    fn child_by_code_rank(&self, tile: &PlaneTile, rank: usize) -> Option<usize> {
        let at = tile.rule as usize * self.arity + rank;
        (rank < self.arity).then(|| self.child_of_digit[at] as usize)
    }

    fn level(&self, tile: &PlaneTile) -> u32 {
        tile.level as u32
    }

    fn max_level(&self) -> u32 {
        self.max_level
    }

    fn capacity(&self, level: u32) -> f64 {
        match self.digit_weight.get(level as usize) {
            Some(&tiles) => code_value(tiles),
            None => self.lut.roots.len() as f64 * (self.arity as f64).powi(level as i32),
        }
    }

    fn measure(&self) -> f64 {
        1.0
    }

    fn code(&self, tile: &PlaneTile) -> Code {
        tile.code
    }

    // inlined, so that where the density's type is known and it reads
    // only the centroid (the ramp) the cells are never stored: about 10 %
    // off such ramp requests in interleaved scratch runs
    #[inline(always)]
    fn region(&self, tile: &PlaneTile) -> PlaneRegion {
        let orientation = tile.placement.orientation.index();
        self.region_boxed(tile, self.boxes[tile.class as usize * 8 + orientation])
    }

    fn placing_region(&self, tile: &PlaneTile, region: &PlaneRegion) -> Option<PlaneRegion> {
        // the region's cells, in the box of the cells alone
        let frame = &self.frames[tile.placement.orientation.index()];
        let (lo, hi) = self.cells_box(tile, [frame.lo, frame.hi]);
        Some(PlaneRegion { lo, hi, ..*region })
    }

    fn map_code_order<T: Send>(
        &self,
        level: u32,
        codes: Range<usize>,
        f: &(dyn Fn(Code, &PlaneTile) -> T + Sync),
    ) -> Option<Vec<T>> {
        if level > self.max_level || codes.end as f64 > self.capacity(level) {
            return None;
        }
        if codes.is_empty() {
            return Some(Vec::new());
        }
        if level == 0 {
            let roots = self.roots_by_code[codes.clone()].iter().zip(codes);
            return Some(roots.map(|(t, code)| f(code as Code, t)).collect());
        }
        // codes `digit * m + c` share their parent with code `c` one level
        // up: find the parents once (those of every digit block the range
        // meets), then each block's children from them
        let m = self.digit_weight[level as usize - 1] as usize;
        let blocks = digit_blocks(&codes, m);
        let parent_codes = span(&blocks);
        let parents = self.map_code_order(level - 1, parent_codes.clone(), &|_, t| *t)?;
        let mut out = Vec::with_capacity(codes.len());
        for (digit, within) in blocks {
            let start = digit * m + within.start;
            let block =
                &parents[within.start - parent_codes.start..within.end - parent_codes.start];
            out.par_extend(
                block
                    .par_iter()
                    .enumerate()
                    .with_min_len(1024)
                    .map(|(c, p)| {
                        // the child carrying `digit` has code `start + c`
                        let code = (start + c) as Code;
                        let child = self.child_of_digit[p.rule as usize * self.arity + digit];
                        f(code, &self.child_coded(p, child as usize, code))
                    }),
            );
        }
        Some(out)
    }

    /// From a list of one level's tiles in code order (see
    /// [`code_order`]), each point placed with the bin's offsets already
    /// turned into each orientation (exact: the matrices are signed
    /// permutations), so a point costs one lookup and no rotation.
    fn code_order(
        &self,
        level: u32,
        codes: Range<usize>,
        fraction: f64,
        d: f64,
    ) -> Option<Box<dyn CodeOrder<DVec2> + '_>> {
        if level > self.max_level || codes.end as f64 > self.capacity(level) {
            return None;
        }
        let listed = code_order::list_level(level, 0, |l| self.capacity(l));
        let m = self.digit_weight[listed as usize] as usize;
        let listed_codes = code_order::listed_codes(&codes, m);
        let list = self.map_code_order(listed, listed_codes.clone(), &|_, t| {
            Node::new(&t.placement, t.rule, t.class, 0)
        })?;
        let (bin, s) = (self.bin(fraction), self.inv_size[level as usize]);
        let turned: Vec<[f64; 2]> = self
            .offsets
            .iter()
            .skip(bin)
            .step_by(self.bins)
            .flat_map(|&offset| Orientation::ALL.map(|o| o.apply_f64(offset)))
            .collect();
        let place = move |t: &code_order::Placed, code: usize| {
            let (x, y) = t.placement.origin;
            let [dx, dy] = turned[t.class as usize * 8 + t.placement.orientation.index()];
            Sample {
                position: DVec2::new(
                    mirror_unit((x as f64 + dx) * s),
                    mirror_unit((y as f64 + dy) * s),
                ),
                rank: code_value(code as Code) / d,
            }
        };
        let depth = level - listed;
        let source = Listed::new(
            self,
            list,
            listed_codes.start,
            m,
            depth,
            Indexing::Classes,
            place,
        );
        Some(Box::new(source))
    }

    fn tile_with_code(&self, level: u32, code: Code) -> Option<PlaneTile> {
        if level > self.max_level || code >= self.digit_weight[level as usize] {
            return None;
        }
        let roots = self.roots_by_code.len() as Code;
        let mut tile = self.roots_by_code[(code % roots) as usize];
        let mut digits = code / roots;
        for _ in 0..level {
            let digit = (digits % self.arity as Code) as usize;
            tile = self.child_with_digit(&tile, digit);
            digits /= self.arity as Code;
        }
        Some(tile)
    }

    fn sample(&self, tile: &PlaneTile, fraction: f64) -> DVec2 {
        self.position(tile, self.bin(fraction))
    }
}

/// Lattice cells per unit-square edge beyond which f64 positions lose
/// resolution: `2^40` keeps a cell thousands of ulps wide.
///
/// # Example
/// ```
/// use tessera::tiling::plane::MAX_LATTICE_SIDE;
/// assert_eq!(1.0 / MAX_LATTICE_SIDE as f64, 4096.0 * f64::EPSILON);
/// ```
pub const MAX_LATTICE_SIDE: Lattice = 1 << 40;

/// The deepest level of a `side`-cell root patch refined by `scale` per
/// level whose codes (`roots * arity^level`) fit [`Code`] and whose lattice
/// (`side * scale^level`, plus a child's reach) stays within
/// [`MAX_LATTICE_SIDE`].
///
/// # Example
/// ```
/// use tessera::tiling::plane::deepest_level;
/// // P-pentomino: 10 cells, doubling per level: 10 * 2^36 < 2^40 < 10 * 2^37
/// assert_eq!(deepest_level(10, 2, 20, 4), 36);
/// ```
pub fn deepest_level(side: Lattice, scale: Lattice, roots: Code, arity: Code) -> u32 {
    let mut level = 0u32;
    loop {
        let next = level + 1;
        let codes = arity.checked_pow(next).and_then(|a| a.checked_mul(roots));
        let size = scale
            .checked_pow(next)
            .and_then(|s| s.checked_mul(side))
            .and_then(|s| s.checked_add(4 * scale));
        match (codes, size) {
            (Some(_), Some(size)) if size <= MAX_LATTICE_SIDE => level = next,
            _ => return level,
        }
    }
}

impl super::reference::ReferencePoint for PlaneTiling {
    fn reference(&self, tile: &PlaneTile) -> DVec2 {
        let p = self.to_unit(tile, self.lut.shape.centroid());
        DVec2::new(mirror_unit(p.x), mirror_unit(p.y))
    }
}

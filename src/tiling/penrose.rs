//! The Penrose tile system (Ostromoukhov, Donohue and Jodoin 2004) on the
//! unit square.
//!
//! Six tile types: `c`, `d` are golden triangles (36-72-72, legs one edge,
//! base `edge / phi`), `e`, `f` golden gnomons (36-36-108, legs one edge,
//! base `phi * edge`), halves of the rhombi of a Penrose P3 tiling; `a`, `b`
//! are point tiles, one per vertex, which carry the samples. The production
//! rules, each child with its two new Fibonacci digits:
//!
//! ```text
//! a -> {b00}            b -> {a00}
//! c -> {f00, c10, a10}  d -> {e00, d10}
//! e -> {f00, c10, e01, a10}
//! f -> {e00, d10, f01, a01}
//! ```
//!
//! Each subdivision scales lengths by `1/phi` (areas by `1/phi^2`). A
//! triangle's new vertex is owned by exactly one of the triangles sharing
//! it: `c` (counter-clockwise) owns the point it cuts on its leg, `e`
//! (clockwise gnomon) the one on its leg, `f` the one on its base; `d`
//! none. The new digits go in front (most significant), so a tile of level
//! `k` has a `2k`-digit Zeckendorf code below `F(2k + 2)`: points born at
//! level `k` get the codes in `[F(2k), F(2k + 2))`, with the same density
//! of used codes in every part of that range, so thresholds keep well
//! spread subsets. The structural index is the value of the six most
//! significant digits (21 values); the importance index the fractional part
//! of `log_phi^2` of the density, in bins.
//!
//! The root is one golden triangle holding the unit square with a margin;
//! tiles whose samples cannot reach the square are never produced, and the
//! samples that land outside it are dropped, as a tiling of the whole plane
//! cut to the square would: every point lies in `[0, 1)^2` and spacing holds
//! up to the border.

use crate::lut::{penrose_lut, PenroseLut};
use crate::tiling::plane::{PlaneRegion, MAX_CELLS};
use crate::tiling::{mirror_unit, Code, TileSystem};
use glam::DVec2;
use std::sync::Arc;

/// The golden ratio.
pub const PHI: f64 = 1.618_033_988_749_895;

/// Legs (the rhombus edge) of the root triangle.
pub const ROOT_EDGE: f64 = 3.2;

/// Deepest level whose geometry stays exact enough in `f64`: an edge is
/// then `ROOT_EDGE / phi^45`, about 1.3e-9, and the rounding accumulated
/// over 45 subdivisions about 1e-14, so vertices stay within 1e-5 edges.
pub const GEOMETRY_LEVELS: u32 = 45;

/// Structural indices: values of six Fibonacci digits.
pub const CLASSES: usize = 21;

/// The production rules: each kind's children (kind, new digits) in rule
/// order, indexed by `Kind as usize`.
const RULES: [&[(Kind, (u8, u8))]; 6] = [
    &[(Kind::B, (0, 0))],
    &[(Kind::A, (0, 0))],
    &[(Kind::F, (0, 0)), (Kind::C, (1, 0)), (Kind::A, (1, 0))],
    &[(Kind::E, (0, 0)), (Kind::D, (1, 0))],
    &[
        (Kind::F, (0, 0)),
        (Kind::C, (1, 0)),
        (Kind::E, (0, 1)),
        (Kind::A, (1, 0)),
    ],
    &[
        (Kind::E, (0, 0)),
        (Kind::D, (1, 0)),
        (Kind::F, (0, 1)),
        (Kind::A, (0, 1)),
    ],
];

/// Tile types of the extended production rules.
///
/// # Example
/// ```
/// use tessera::tiling::penrose::Kind;
/// assert!(Kind::A.is_point() && !Kind::C.is_point());
/// ```
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Kind {
    /// Point tile (becomes `b`).
    A,
    /// Point tile (becomes `a`).
    B,
    /// Golden triangle, counter-clockwise (apex, leg end with the new
    /// vertex, other leg end).
    C,
    /// Golden triangle, clockwise.
    D,
    /// Golden gnomon, clockwise.
    E,
    /// Golden gnomon, counter-clockwise.
    F,
}

impl Kind {
    /// Whether the tile is a point (sampling) tile.
    ///
    /// # Example
    /// ```
    /// assert!(tessera::tiling::penrose::Kind::B.is_point());
    /// ```
    pub fn is_point(self) -> bool {
        matches!(self, Kind::A | Kind::B)
    }

    /// Whether the tile is a golden triangle (`c`, `d`) rather than a gnomon.
    ///
    /// # Example
    /// ```
    /// assert!(tessera::tiling::penrose::Kind::D.is_golden());
    /// ```
    pub fn is_golden(self) -> bool {
        matches!(self, Kind::C | Kind::D)
    }
}

/// A tile of the Penrose system.
///
/// # Example
/// ```
/// use tessera::tiling::{penrose::{Kind, PenroseTiling}, TileSystem};
/// let root = PenroseTiling::default().roots()[0];
/// assert_eq!((root.kind, root.level, root.code), (Kind::C, 0, 0));
/// ```
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PenroseTile {
    /// Tile type.
    pub kind: Kind,
    /// Subdivision level.
    pub level: u8,
    /// The code's six most significant digits, the most significant in
    /// bit 5.
    pub digits: u8,
    /// Threshold code, a Zeckendorf number below `F(2 level + 2)`.
    pub code: Code,
    /// Triangles: apex, then the two other corners (the first the end of
    /// the leg that gets the new vertex). Point tiles: the point, then its
    /// frame's two axes, one edge of the tile's level long.
    pub v: [DVec2; 3],
    /// Whether every sample the tile and its descendants may place lies
    /// inside the square (then no descendant needs the border test).
    pub inside: bool,
}

impl PenroseTile {
    /// The structural index: the value of the six most significant digits.
    ///
    /// # Example
    /// ```
    /// use tessera::tiling::{penrose::PenroseTiling, TileSystem};
    /// assert_eq!(PenroseTiling::default().roots()[0].class(), 0);
    /// ```
    pub fn class(&self) -> usize {
        // Fibonacci weights F(2)..F(7) of digits 0..5
        const W: [u8; 6] = [1, 2, 3, 5, 8, 13];
        (0..6)
            .filter(|&b| self.digits >> b & 1 == 1)
            .map(|b| W[b] as usize)
            .sum()
    }

    /// Area of a triangle tile (0 for point tiles).
    ///
    /// # Example
    /// ```
    /// use tessera::tiling::{penrose::PenroseTiling, TileSystem};
    /// assert!(PenroseTiling::default().roots()[0].area() > 1.0);
    /// ```
    pub fn area(&self) -> f64 {
        if self.kind.is_point() {
            return 0.0;
        }
        let [a, b, c] = self.v;
        0.5 * (b - a).perp_dot(c - a).abs()
    }
}

/// The Penrose tile system on the unit square, with its offset table.
///
/// # Example
/// ```
/// use tessera::{density::Uniform, engine, tiling::penrose::PenroseTiling};
/// let s = engine::generate(&PenroseTiling::default(), &Uniform, 500, true).unwrap();
/// assert_eq!(s.len(), 500);
/// assert!(s.iter().all(|p| p.position.cmpge(glam::DVec2::ZERO).all()
///     && p.position.cmplt(glam::DVec2::ONE).all()));
/// ```
#[derive(Clone, Debug)]
pub struct PenroseTiling {
    lut: Arc<PenroseLut>,
    bins: usize,
    max_level: u32,
    /// `fib[i] = F(i)`, `F(1) = F(2) = 1`, as far as codes need.
    fib: Vec<Code>,
    /// Edge length of each level.
    edge: Vec<f64>,
    /// Decoded offsets, `class * bins + bin`.
    offsets: Vec<DVec2>,
    /// Longest offset, in edges (how far a point may leave its vertex).
    reach: f64,
}

impl Default for PenroseTiling {
    /// The tiling with the table shipped in `luts/penrose.lut`.
    fn default() -> Self {
        PenroseTiling::new(penrose_lut())
    }
}

impl PenroseTiling {
    /// A tiling driven by the given offset table.
    ///
    /// # Example
    /// ```
    /// use std::sync::Arc;
    /// use tessera::{lut::PenroseLut, tiling::{penrose::PenroseTiling, TileSystem}};
    /// let t = PenroseTiling::new(Arc::new(PenroseLut::zero(21)));
    /// assert_eq!(t.max_level(), 45);
    /// ```
    pub fn new(lut: Arc<PenroseLut>) -> Self {
        // F(2k + 2) - 1 must fit a code: the deepest level both codes and
        // geometry allow
        let mut fib: Vec<Code> = vec![0, 1, 1];
        let mut max_level = 0;
        while max_level < GEOMETRY_LEVELS {
            let need = 2 * (max_level + 1) as usize + 2;
            while fib.len() <= need {
                let n = fib.len();
                match fib[n - 1].checked_add(fib[n - 2]) {
                    Some(next) => fib.push(next),
                    None => break,
                }
            }
            if fib.len() <= need {
                break;
            }
            max_level += 1;
        }
        fib.truncate(2 * max_level as usize + 3);
        let edge = (0..=max_level)
            .map(|k| ROOT_EDGE * PHI.powi(-(k as i32)))
            .collect();
        let bins = lut.bins as usize;
        let offsets: Vec<DVec2> = (0..CLASSES * bins)
            .map(|k| DVec2::from(lut.offset(k / bins, k % bins)))
            .collect();
        let reach = offsets.iter().map(|o| o.length()).fold(0.5, f64::max);
        PenroseTiling {
            lut,
            bins,
            max_level,
            fib,
            edge,
            offsets,
            reach,
        }
    }

    /// The offset table.
    ///
    /// # Example
    /// ```
    /// use tessera::tiling::penrose::PenroseTiling;
    /// assert_eq!(PenroseTiling::default().lut().classes, 21);
    /// ```
    pub fn lut(&self) -> &PenroseLut {
        &self.lut
    }

    /// The root triangle (a `c` tile holding the unit square).
    fn root(&self) -> PenroseTile {
        let height = ROOT_EDGE * (18f64).to_radians().cos();
        let half_base = 0.5 * ROOT_EDGE / PHI;
        let (x, y0) = (0.5, -0.1);
        PenroseTile {
            kind: Kind::C,
            level: 0,
            digits: 0,
            code: 0,
            inside: false,
            v: [
                DVec2::new(x, y0 + height),
                DVec2::new(x - half_base, y0),
                DVec2::new(x + half_base, y0),
            ],
        }
    }

    /// Edge length (rhombus side) at `level`.
    ///
    /// # Example
    /// ```
    /// use tessera::tiling::penrose::{PenroseTiling, PHI, ROOT_EDGE};
    /// assert_eq!(PenroseTiling::default().edge(0), ROOT_EDGE);
    /// ```
    pub fn edge(&self, level: u32) -> f64 {
        self.edge[level.min(self.max_level) as usize]
    }

    /// Every child of `tile` in production-rule order, including those
    /// outside the unit square, and how many there are.
    ///
    /// # Example
    /// ```
    /// use tessera::tiling::{penrose::{Kind, PenroseTiling}, TileSystem};
    /// let t = PenroseTiling::default();
    /// let (kids, n) = t.all_children(&t.roots()[0]);
    /// assert_eq!(n, 3);
    /// assert_eq!([kids[0].kind, kids[1].kind, kids[2].kind], [Kind::F, Kind::C, Kind::A]);
    /// ```
    pub fn all_children(&self, tile: &PenroseTile) -> ([PenroseTile; 4], usize) {
        let n = RULES[tile.kind as usize].len();
        let mut out = [*tile; 4];
        for (i, child) in out.iter_mut().enumerate().take(n) {
            *child = self.nth_child(tile, i);
        }
        (out, n)
    }

    /// Child `i` (rule order) of `tile`, inside the square or not.
    #[inline]
    fn nth_child(&self, tile: &PenroseTile, i: usize) -> PenroseTile {
        let [a, b, c] = tile.v;
        let (kind, (hi, lo)) = RULES[tile.kind as usize][i];
        // the new vertex of a golden triangle (on its leg), and of a gnomon
        // (q on its leg, r on its base)
        let p = || a + (b - a) / PHI;
        let q = || b + (a - b) / PHI;
        let r = || b + (c - b) / PHI;
        // a point's frame at birth: the parent's leg direction, scaled to
        // the child edge, turned the way the parent winds
        let frame = |p: DVec2, wind: f64| {
            let e1 = (b - a) / PHI;
            [p, e1, e1.perp() * wind]
        };
        let v = match (tile.kind, i) {
            (Kind::A | Kind::B, _) => [a, b / PHI, c / PHI],
            (Kind::C | Kind::D, 0) => [p(), c, a],
            (Kind::C | Kind::D, 1) => [c, p(), b],
            (Kind::C, _) => frame(p(), 1.0),
            (_, 0) => [q(), r(), b],
            (_, 1) => [r(), q(), a],
            (_, 2) => [r(), c, a],
            (Kind::E, _) => frame(q(), -1.0),
            (_, _) => frame(r(), 1.0),
        };
        let level = tile.level + 1;
        let mut child = PenroseTile {
            kind,
            level,
            digits: (hi << 5) | (lo << 4) | (tile.digits >> 2),
            code: tile.code + self.digit_code(level, (hi, lo)),
            v,
            inside: tile.inside,
        };
        if !child.inside {
            let (lo, hi) = self.bounds(&child);
            child.inside = lo.cmpge(DVec2::ZERO).all() && hi.cmplt(DVec2::ONE).all();
        }
        child
    }

    /// The value of a level's two new digits.
    #[inline]
    fn digit_code(&self, level: u8, (hi, lo): (u8, u8)) -> Code {
        let level = level as usize;
        let mut code = 0;
        if hi == 1 {
            code += self.fib[2 * level + 1];
        }
        if lo == 1 {
            code += self.fib[2 * level];
        }
        code
    }

    /// The children of `tile` that reach the unit square (what the engine
    /// visits).
    fn children(&self, tile: &PenroseTile) -> ([PenroseTile; 4], usize) {
        let (all, n) = self.all_children(tile);
        let mut out = all;
        let mut kept = 0;
        for child in &all[..n] {
            if self.reaches_square(child) {
                out[kept] = *child;
                kept += 1;
            }
        }
        (out, kept)
    }

    /// Whether any sample of the tile or its descendants may land in the
    /// square: its box, grown by the reach of the offsets, meets it.
    fn reaches_square(&self, tile: &PenroseTile) -> bool {
        let (lo, hi) = self.bounds(tile);
        lo.x < 1.0 && lo.y < 1.0 && hi.x >= 0.0 && hi.y >= 0.0
    }

    /// The box holding a tile and every sample its descendants may place.
    fn bounds(&self, tile: &PenroseTile) -> (DVec2, DVec2) {
        let edge = self.edge[tile.level as usize];
        if tile.kind.is_point() {
            let r = DVec2::splat(self.reach * edge);
            return (tile.v[0] - r, tile.v[0] + r);
        }
        // points born on the edges sit one level down
        let r = DVec2::splat(self.reach * edge / PHI);
        let [a, b, c] = tile.v;
        (a.min(b).min(c) - r, a.max(b).max(c) + r)
    }

    /// Every tile of `level` reaching the unit square, in tree order: for
    /// drawings, tests and the optimiser (about `2.3 phi^(2 level)` tiles).
    ///
    /// # Example
    /// ```
    /// use tessera::tiling::penrose::PenroseTiling;
    /// let tiles = PenroseTiling::default().tiles(6);
    /// assert!(tiles.iter().any(|t| t.kind.is_point()));
    /// ```
    pub fn tiles(&self, level: u32) -> Vec<PenroseTile> {
        let mut tiles = vec![self.root()];
        for _ in 0..level.min(self.max_level) {
            tiles = tiles
                .iter()
                .flat_map(|t| {
                    let (kids, n) = self.children(t);
                    kids.into_iter().take(n)
                })
                .collect();
        }
        tiles
    }

    /// The importance index of a density `fraction` of a level's capacity:
    /// the fractional part of `log_phi^2 fraction`, in bins (as
    /// `capacity(k) = F(2k + 2)` is about `phi^(2k + 2) / sqrt 5`, this is
    /// the reference's `log_phi^2 (sqrt 5 d) mod 1` for `d` codes), rounded up so
    /// a fraction is served by the bin optimised for the first density at
    /// or above it (whose accepted points include its own).
    ///
    /// # Example
    /// ```
    /// use tessera::tiling::penrose::{PenroseTiling, PHI};
    /// let t = PenroseTiling::default();
    /// assert_eq!(t.bin(1.0), t.lut().bins as usize - 1);
    /// assert_eq!(t.bin(1.0 / (PHI * PHI)), 0);
    /// assert_eq!(t.bin(t.bin_fraction(3)), 3);
    /// ```
    pub fn bin(&self, fraction: f64) -> usize {
        let t = 1.0 + fraction.ln() / (PHI * PHI).ln();
        let b = (t * self.bins as f64 - 1e-9).ceil() - 1.0;
        b.clamp(0.0, (self.bins - 1) as f64) as usize
    }

    /// The density fraction bin `bin` is optimised for (its upper edge).
    ///
    /// # Example
    /// ```
    /// use tessera::tiling::penrose::PenroseTiling;
    /// let t = PenroseTiling::default();
    /// assert_eq!(t.bin_fraction(t.lut().bins as usize - 1), 1.0);
    /// ```
    pub fn bin_fraction(&self, bin: usize) -> f64 {
        let t = (bin + 1) as f64 / self.bins as f64;
        (PHI * PHI).powf(t - 1.0)
    }

    /// Where a point tile's sample goes with `offset` (edges, tile frame),
    /// before mirroring into the square.
    ///
    /// # Example
    /// ```
    /// use tessera::tiling::penrose::PenroseTiling;
    /// let t = PenroseTiling::default();
    /// let p = t.tiles(8).into_iter().find(|p| p.kind.is_point()).unwrap();
    /// assert_eq!(t.place(&p, glam::DVec2::ZERO), p.v[0]);
    /// ```
    pub fn place(&self, tile: &PenroseTile, offset: DVec2) -> DVec2 {
        tile.v[0] + offset.x * tile.v[1] + offset.y * tile.v[2]
    }

    /// The table offset of a point tile in bin `bin`.
    ///
    /// # Example
    /// ```
    /// use tessera::tiling::penrose::PenroseTiling;
    /// let t = PenroseTiling::default();
    /// let p = t.tiles(8).into_iter().find(|p| p.kind.is_point()).unwrap();
    /// assert!(t.offset(&p, 0).length() <= tessera::lut::PENROSE_MAX_OFFSET);
    /// ```
    pub fn offset(&self, tile: &PenroseTile, bin: usize) -> DVec2 {
        self.offsets[tile.class() * self.bins + bin]
    }

    /// The expected number of point tiles with codes below `c` per unit
    /// area is `c / codes_per_area()`: a level's code range `F(2k + 2)`
    /// is `phi^(2k + 2) / sqrt 5` while its vertices number one per rhombus,
    /// `phi^(2k)` over the mean rhombus area (thick and thin in the ratio
    /// `phi : 1`).
    ///
    /// # Example
    /// ```
    /// use tessera::tiling::penrose::PenroseTiling;
    /// assert!((PenroseTiling::codes_per_area() - 9.74).abs() < 0.01);
    /// ```
    pub fn codes_per_area() -> f64 {
        let (s36, s72) = (36f64.to_radians().sin(), 72f64.to_radians().sin());
        let rhombus = (PHI * s72 + s36) / (PHI + 1.0) * ROOT_EDGE * ROOT_EDGE;
        PHI * PHI * rhombus / 5f64.sqrt()
    }
}

/// Whether `p` lies in `[0, 1)^2`.
fn in_square(p: DVec2) -> bool {
    (0.0..1.0).contains(&p.x) && (0.0..1.0).contains(&p.y)
}

impl TileSystem for PenroseTiling {
    type Tile = PenroseTile;
    type Point = DVec2;
    type Region = PlaneRegion;

    fn roots(&self) -> Vec<PenroseTile> {
        vec![self.root()]
    }

    fn child_count(&self, tile: &PenroseTile) -> usize {
        if tile.inside {
            RULES[tile.kind as usize].len()
        } else {
            self.children(tile).1
        }
    }

    fn child(&self, tile: &PenroseTile, i: usize) -> PenroseTile {
        if tile.inside {
            self.nth_child(tile, i)
        } else {
            self.children(tile).0[i]
        }
    }

    fn child_code(&self, tile: &PenroseTile, i: usize) -> Code {
        if tile.inside {
            let digits = RULES[tile.kind as usize][i].1;
            tile.code + self.digit_code(tile.level + 1, digits)
        } else {
            self.children(tile).0[i].code
        }
    }

    fn level(&self, tile: &PenroseTile) -> u32 {
        tile.level as u32
    }

    fn max_level(&self) -> u32 {
        self.max_level
    }

    fn capacity(&self, level: u32) -> f64 {
        self.fib[2 * level.min(self.max_level) as usize + 2] as f64
    }

    fn measure(&self) -> f64 {
        1.0
    }

    fn code(&self, tile: &PenroseTile) -> Code {
        tile.code
    }

    // inlined, as the polyominoes' is: a density reading only the centroid
    // (the ramp) then never computes the cells (with a second caller,
    // `Walker::starts`, the compiler stopped inlining it and ramp requests
    // ran 13 % slower)
    #[inline(always)]
    fn region(&self, tile: &PenroseTile) -> PlaneRegion {
        let (lo, hi) = self.bounds(tile);
        let edge = self.edge[tile.level as usize];
        let mut region = PlaneRegion {
            lo,
            hi,
            cell: edge,
            cells: [DVec2::ZERO; MAX_CELLS],
            count: 1,
            centroid: tile.v[0],
        };
        if tile.kind.is_point() {
            // about the point's own share of the plane (0.81 edge^2)
            region.cells[0] = tile.v[0];
            return region;
        }
        // the centroids of the four halved-side sub-triangles: their mean
        // is the centroid, so linear densities average exactly
        let [a, b, c] = tile.v;
        region.cells[0] = (a + b + c) / 3.0;
        region.centroid = region.cells[0];
        region.cells[1] = (4.0 * a + b + c) / 6.0;
        region.cells[2] = (a + 4.0 * b + c) / 6.0;
        region.cells[3] = (a + b + 4.0 * c) / 6.0;
        region.count = 4;
        region.cell = (tile.area() / 4.0).sqrt();
        region
    }

    fn carries_sample(&self, tile: &PenroseTile) -> bool {
        tile.kind.is_point()
    }

    fn codes_per_sample(&self) -> f64 {
        PenroseTiling::codes_per_area()
    }

    fn sample_in_domain(&self, tile: &PenroseTile, fraction: f64) -> Option<DVec2> {
        let p = self.place(tile, self.offset(tile, self.bin(fraction)));
        in_square(p).then_some(p)
    }

    /// The sample mirrored into the square when its offset carries it out
    /// (the engine keeps only samples inside, see
    /// [`TileSystem::sample_in_domain`]).
    fn sample(&self, tile: &PenroseTile, fraction: f64) -> DVec2 {
        let p = self.place(tile, self.offset(tile, self.bin(fraction)));
        DVec2::new(mirror_unit(p.x), mirror_unit(p.y))
    }
}

impl super::reference::ReferencePoint for PenroseTiling {
    fn reference(&self, tile: &PenroseTile) -> DVec2 {
        let p = tile.v[0];
        DVec2::new(mirror_unit(p.x), mirror_unit(p.y))
    }

    fn reference_in_domain(&self, tile: &PenroseTile) -> Option<DVec2> {
        in_square(tile.v[0]).then_some(tile.v[0])
    }
}

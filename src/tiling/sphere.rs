//! The sphere tile system: P-pentominoes on the 12 HEALPix base faces.
//!
//! Each face carries a 10x10 cell grid (HEALPix Nside 10) tiled by 20
//! P-pentominoes; each pentomino splits into 4 by one of the two dissections
//! of the doubled P-pentomino, so level `k` has `240 * 4^k` tiles of 5 cells at
//! Nside `10 * 2^k`. Because HEALPix is equal-area, uniform density in face
//! coordinates is uniform density on the sphere.
//!
//! Structural indices: at the shallow levels where the mapping's distortion
//! differs from tile to tile, every tile is its own index (its position in
//! the subdivision tree). Deeper, the index names the tile's neighbourhood
//! class (computed offline, across face seams and the three-face corners) and
//! follows the automaton `child index = transitions[index][child]`.

use crate::healpix::FacePoint;
use crate::lut::SphereLut;
use crate::polyomino::{Lattice, Placement, Shape};
use crate::sample::Sample;
use crate::tiling::code_order::{self, CodeOrder, Indexing, Listed, Node, Subdivision};
use crate::tiling::{code_value, digit_blocks, span, Code, TileSystem};
use glam::DVec3;
use rayon::prelude::*;
use std::ops::Range;
use std::sync::{Arc, OnceLock};

/// Cells along a face edge at level 0 (HEALPix Nside of the root patch).
pub const PATCH_SIDE: Lattice = 10;
pub use crate::lut::{ROOTS_PER_FACE, ROOT_COUNT};
/// Deepest supported level: a face edge has `10 * 2^k <= 2^40` cells, so a
/// cell still spans thousands of f64 ulps of face coordinates, and codes
/// `240 * 4^k` fit [`Code`]; tiles are about 3e-12 rad across.
pub const MAX_LEVEL: u32 = 36;
/// Upper bound of the geodesic length (radians) of a unit step in face
/// coordinates, anywhere on any face. The largest stretch, about 1.596, is
/// on the polar faces' edge meridians (a finite-difference scan of every
/// face at 1/400 steps found 1.5944 there; [`crate::healpix::stretch_over`]
/// derives it), so the margin is thin. A tile's region uses the tighter
/// bound over its own neighbourhood ([`SphereRegion::stretch`]), and
/// `tests/sphere.rs` checks that every sample lies inside its cap.
pub const FACE_LIPSCHITZ: f64 = 1.6;
/// Largest distance from the P-pentomino's centroid to its outline, cells.
const PENTOMINO_RADIUS: f64 = 2.03;

/// A pentomino of the sphere tiling.
///
/// # Example
/// ```
/// use tessera::tiling::{sphere::SphereTiling, TileSystem};
/// let sphere = SphereTiling::default();
/// let root = sphere.roots()[0];
/// assert_eq!(root.level, 0);
/// ```
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct SphereTile {
    /// HEALPix base face, 0..12.
    pub face: u8,
    /// Subdivision level.
    pub level: u8,
    /// Which of the two dissections this tile's children follow.
    pub rule: u8,
    /// Position on the face lattice at Nside `10 * 2^level`.
    pub placement: Placement,
    /// Structural index (tree position at shallow levels, class deeper).
    pub index: u32,
    /// Threshold code, `0..240 * 4^level`.
    pub code: Code,
}

/// A tile as a density sees it: its face, cell-centre probes and a
/// conservative bounding cap.
///
/// # Example
/// ```
/// use tessera::tiling::{sphere::SphereTiling, TileSystem};
/// let sphere = SphereTiling::default();
/// let region = sphere.region(&sphere.roots()[0]);
/// assert!(region.radius > 0.0 && region.radius < 0.6);
/// ```
#[derive(Clone, Copy, Debug)]
pub struct SphereRegion {
    /// The tile's centroid, in face coordinates (see [`SphereRegion::center`]).
    pub centroid: FacePoint,
    /// Angular radius (rad) of a cap around `center` holding the tile and
    /// the samples its bound covers ([`SampleReach`]).
    pub radius: f64,
    /// Base face.
    pub face: u8,
    /// Face coordinates of the five cell centres.
    pub cells: [[f64; 2]; 5],
    /// How far (face coordinates) those samples land past the cells'
    /// squares, in either coordinate, before their zonal warp.
    pub spill: f64,
    /// How far (rad) a zonal warp then moves them.
    pub warp: f64,
    /// An upper bound of the face-to-sphere stretch between the face points
    /// those samples land on and the tile's centroid
    /// ([`crate::healpix::stretch_over`]; at most [`FACE_LIPSCHITZ`]): the
    /// cap's radius is `stretch` times their reach on the face.
    pub stretch: f64,
}

impl SphereRegion {
    /// The tile's centroid on the sphere (computed on demand: densities
    /// that work in face or pixel coordinates never pay its trigonometry).
    ///
    /// # Example
    /// ```
    /// use tessera::tiling::{sphere::SphereTiling, TileSystem};
    /// let sphere = SphereTiling::default();
    /// let region = sphere.region(&sphere.roots()[0]);
    /// assert!((region.center().length() - 1.0).abs() < 1e-12);
    /// ```
    pub fn center(&self) -> DVec3 {
        self.centroid.to_vec()
    }

    /// The five cell centres as unit vectors (an equal-weight quadrature).
    ///
    /// # Example
    /// ```
    /// use tessera::tiling::{sphere::SphereTiling, TileSystem};
    /// let sphere = SphereTiling::default();
    /// let probes = sphere.region(&sphere.roots()[3]).probes();
    /// assert!(probes.iter().all(|p| (p.length() - 1.0).abs() < 1e-12));
    /// ```
    pub fn probes(&self) -> [DVec3; 5] {
        self.cells
            .map(|[x, y]| FacePoint::new(self.face, x, y).to_vec())
    }

    /// How far (rad) a sample the region's bound covers can lie from the
    /// nearest of its five cell centres ([`SphereRegion::probes`]): within
    /// `side / 2 + spill` of one in either face coordinate, so within
    /// `sqrt 2` times that, stretched onto the sphere by at most
    /// [`FACE_LIPSCHITZ`], and then warped. Not the tighter
    /// [`SphereRegion::stretch`]: a `SphereFn` bound whose looseness
    /// varies over the face gives neighbouring tiles different bins, and
    /// their points crowd (DESIGN.md, Sphere, Region). Infinite for a bare
    /// cap (see [`SphereRegion::cell_side`]).
    ///
    /// # Example
    /// ```
    /// use tessera::tiling::{sphere::SphereTiling, TileSystem};
    /// let sphere = SphereTiling::default();
    /// let tile = sphere.tile_with_code(9, 12_345).unwrap();
    /// let region = sphere.region(&tile);
    /// assert!(region.cell_reach() > 0.0 && region.cell_reach() < 2.0 * region.radius);
    /// ```
    pub fn cell_reach(&self) -> f64 {
        let half_width = self.cell_side() / 2.0 + self.spill;
        FACE_LIPSCHITZ * std::f64::consts::SQRT_2 * half_width + self.warp
    }

    /// Side of the tile's cells in face coordinates: the smallest step
    /// between two (edge-adjacent) cell centres. Infinite for a bare cap
    /// whose cells all sit at its centre (as [`crate::density::sphere::Rotated`]
    /// passes): such a region is known only by its cap.
    ///
    /// # Example
    /// ```
    /// use tessera::tiling::{sphere::SphereTiling, TileSystem};
    /// let sphere = SphereTiling::default();
    /// let tile = sphere.child(&sphere.roots()[0], 1);
    /// assert!((sphere.region(&tile).cell_side() - 1.0 / 20.0).abs() < 1e-12);
    /// ```
    pub fn cell_side(&self) -> f64 {
        let mut side = f64::INFINITY;
        for (a, p) in self.cells.iter().enumerate() {
            for q in &self.cells[a + 1..] {
                let d = (p[0] - q[0]).abs() + (p[1] - q[1]).abs();
                if d > 0.0 {
                    side = side.min(d);
                }
            }
        }
        side
    }
}

/// The sphere tile system, driven by an offset table ([`SphereLut`]).
///
/// # Example
/// ```
/// use tessera::tiling::{sphere::SphereTiling, TileSystem};
/// let sphere = SphereTiling::default();
/// assert_eq!(sphere.child_count(&sphere.roots()[0]), 4);
/// ```
#[derive(Clone)]
pub struct SphereTiling {
    lut: Arc<SphereLut>,
    shape: Shape,
    /// The roots, ordered by code (rank).
    roots_by_code: Vec<SphereTile>,
    /// `child_of_digit[rule][digit]`: which child carries a digit.
    child_of_digit: [[u8; 4]; 2],
    /// `shape.centroid()`, cached for [`TileSystem::region`].
    centroid: [f64; 2],
    /// [`SphereTiling::sample_reach`] of each table level, measured from
    /// the table when a region first needs it.
    reach: OnceLock<Vec<SampleReach>>,
}

impl Default for SphereTiling {
    /// The tiling with the table shipped in `luts/` and embedded at compile time.
    fn default() -> Self {
        SphereTiling::new(crate::lut::sphere_lut())
    }
}

impl SphereTiling {
    /// A tiling driven by the given table.
    ///
    /// # Example
    /// ```
    /// use tessera::tiling::sphere::SphereTiling;
    /// let sphere = SphereTiling::new(tessera::lut::sphere_lut());
    /// assert_eq!(sphere.lut().rules.len(), 2);
    /// ```
    pub fn new(lut: Arc<SphereLut>) -> Self {
        let mut tiling = SphereTiling {
            lut,
            shape: Shape::p_pentomino(),
            roots_by_code: Vec::new(),
            child_of_digit: [[0; 4]; 2],
            centroid: Shape::p_pentomino().centroid(),
            reach: OnceLock::new(),
        };
        if Arc::ptr_eq(&tiling.lut, &crate::lut::sphere_lut()) {
            // measuring it would decode every offset table (11 MB)
            let _ = tiling.reach.set(EMBEDDED_REACH.to_vec());
        }
        let mut roots = tiling.roots();
        roots.sort_by_key(|t| t.code);
        tiling.roots_by_code = roots;
        for (rule, digits) in tiling.lut.child_digit.iter().enumerate().take(2) {
            for (child, &digit) in digits.iter().enumerate() {
                tiling.child_of_digit[rule][digit as usize % 4] = child as u8;
            }
        }
        tiling
    }

    /// The table driving this tiling.
    ///
    /// # Example
    /// ```
    /// use tessera::tiling::sphere::SphereTiling;
    /// assert_eq!(SphereTiling::default().lut().root_rank.len(), 240);
    /// ```
    pub fn lut(&self) -> &SphereLut {
        &self.lut
    }

    /// Lattice resolution (cells per face edge) at `level`.
    ///
    /// # Example
    /// ```
    /// use tessera::tiling::sphere::SphereTiling;
    /// assert_eq!(SphereTiling::nside(2), 40);
    /// ```
    pub fn nside(level: u32) -> i64 {
        PATCH_SIDE << level
    }

    fn subdivide(&self, tile: &SphereTile, child: usize) -> SphereTile {
        let lut = &*self.lut;
        let rule = tile.rule as usize;
        let level = tile.level as u32;
        let index = if level + 1 < lut.exact_levels as u32 {
            tile.index * 4 + child as u32
        } else {
            lut.transitions[self.class_of(tile) as usize][child]
        };
        let digit = lut.child_digit[rule][child] as Code;
        SphereTile {
            face: tile.face,
            level: tile.level + 1,
            rule: lut.child_rule[rule][child],
            placement: tile.placement.child(&lut.rules[rule].children[child], 2),
            index,
            code: tile.code + digit * ((ROOT_COUNT as Code) << (2 * level)),
        }
    }

    /// The neighbourhood class of a tile of level `exact_levels - 2` (the
    /// level `entry_class` lists) or deeper: for the deep levels its index.
    fn class_of(&self, tile: &SphereTile) -> u32 {
        let lut = &*self.lut;
        let entry = |index: usize| lut.entry_class[index / 4][index % 4];
        let (next, index) = (tile.level as u32 + 1, tile.index as usize);
        let exact = lut.exact_levels as u32;
        // `next`: the level of the tile's children
        if next < exact {
            entry(index)
        } else if next == exact {
            // the last tree-indexed level: its parent's class, carried down
            lut.transitions[entry(index / 4) as usize][index % 4]
        } else {
            tile.index
        }
    }

    /// Appends to `out` `f(code, tile)` for the tiles of `level` whose codes
    /// lie in `codes`, in code order (codes within the level's capacity).
    /// Codes `digit * m + c` are child `digit` of the tile of code `c` one
    /// level up, so the parents are found once (those of every digit block
    /// the range meets) and serve each block, whose children are built in
    /// parallel.
    fn extend_in_code_order<T: Send>(
        &self,
        level: u32,
        codes: Range<usize>,
        out: &mut Vec<T>,
        f: &(dyn Fn(Code, &SphereTile) -> T + Sync),
    ) {
        if codes.is_empty() {
            return;
        }
        if level == 0 {
            let roots = self.roots_by_code[codes.clone()].iter().zip(codes);
            return out.extend(roots.map(|(t, code)| f(code as Code, t)));
        }
        let m = self.capacity(level - 1) as usize;
        let blocks = digit_blocks(&codes, m);
        let parent_codes = span(&blocks);
        let mut parents = Vec::new();
        self.extend_in_code_order(level - 1, parent_codes.clone(), &mut parents, &|_, t| *t);
        out.reserve(codes.len());
        for (digit, within) in blocks {
            let start = digit * m + within.start;
            let block =
                &parents[within.start - parent_codes.start..within.end - parent_codes.start];
            let children = block.par_iter().with_min_len(4096).enumerate();
            out.par_extend(children.map(|(c, p)| f((start + c) as Code, &self.child_of(p, digit))));
        }
    }

    /// The child of `tile` with code digit `digit`.
    #[inline]
    fn child_of(&self, tile: &SphereTile, digit: usize) -> SphereTile {
        self.subdivide(
            tile,
            self.child_of_digit[tile.rule as usize][digit] as usize,
        )
    }

    /// Every tile of a level, in tree order (children of the first root
    /// first). `240 * 4^level` tiles: meant for small levels.
    ///
    /// # Example
    /// ```
    /// use tessera::tiling::sphere::SphereTiling;
    /// assert_eq!(SphereTiling::default().tiles(2).len(), 3840);
    /// ```
    pub fn tiles(&self, level: u32) -> Vec<SphereTile> {
        let mut tiles = self.roots();
        for _ in 0..level {
            tiles = tiles
                .par_iter()
                .flat_map_iter(|t| (0..4).map(move |c| self.subdivide(t, c)))
                .collect();
        }
        tiles
    }

    /// Face coordinates of a point given in the tile's own frame (cells).
    ///
    /// # Example
    /// ```
    /// use tessera::tiling::{sphere::SphereTiling, TileSystem};
    /// let sphere = SphereTiling::default();
    /// let fp = sphere.face_point(&sphere.roots()[0], [0.5, 0.5]);
    /// assert!(fp.x > 0.0 && fp.x < 1.0 && fp.y > 0.0 && fp.y < 1.0);
    /// ```
    pub fn face_point(&self, tile: &SphereTile, local: [f64; 2]) -> FacePoint {
        let scale = 1.0 / Self::nside(tile.level as u32) as f64;
        on_face(tile.face, &tile.placement, scale, local)
    }

    /// The table offset (tile frame, cells) for a tile at the given density
    /// fraction.
    ///
    /// # Example
    /// ```
    /// use tessera::tiling::{sphere::SphereTiling, TileSystem};
    /// let sphere = SphereTiling::default();
    /// let o = sphere.offset(&sphere.roots()[0], 1.0);
    /// assert!(tessera::polyomino::Shape::p_pentomino().contains(o));
    /// ```
    pub fn offset(&self, tile: &SphereTile, fraction: f64) -> [f64; 2] {
        self.offset_in_bin(tile, fraction).0
    }

    /// [`SphereTiling::offset`], with the importance bin it reads.
    fn offset_in_bin(&self, tile: &SphereTile, fraction: f64) -> ([f64; 2], usize) {
        let lut = &*self.lut;
        let (level, capacity) = (tile.level as u32, self.capacity(tile.level as u32));
        let bin = lut.bin(fraction, capacity);
        let shares = |lost| twins_share_a_hole(self, lut, (level, bin), lost);
        let offsets = lut.request_offsets(level, fraction, capacity, bin);
        let offset = offsets.placed(tile.index as usize, tile.code as u64, shares);
        (offset, bin)
    }

    /// The shape of every tile.
    ///
    /// # Example
    /// ```
    /// use tessera::tiling::sphere::SphereTiling;
    /// assert_eq!(SphereTiling::default().shape().cells().len(), 5);
    /// ```
    pub fn shape(&self) -> &Shape {
        &self.shape
    }

    /// How far the samples that the bound of a tile of `level` covers
    /// land from it ([`SampleReach`]): what its region holds.
    ///
    /// # Example
    /// ```
    /// use tessera::tiling::sphere::SphereTiling;
    /// let reach = SphereTiling::default().sample_reach(3);
    /// assert!(reach.from_centroid >= 2.03 && reach.past_cells >= 0.0);
    /// ```
    pub fn sample_reach(&self, level: u32) -> SampleReach {
        let reach = self.reach.get_or_init(|| self.measure_reach());
        reach[(level as usize).min(reach.len() - 1)]
    }

    /// [`SphereTiling::sample_reach`] of every table level (the last
    /// serving every deeper one), from the table's offsets.
    fn measure_reach(&self) -> Vec<SampleReach> {
        let levels = self.lut.tables.len().max(1);
        let own: Vec<SampleReach> = (0..levels).map(|level| self.own_reach(level)).collect();
        // a child's centroid, in its parent's cells (children are half
        // their parent's size), from the parent's
        let centroid = self.centroid;
        let child_centroid = (self.lut.rules.iter())
            .flat_map(|rule| &rule.children)
            .map(|child| {
                let c = child.to_lattice(centroid);
                (c[0] / 2.0 - centroid[0]).hypot(c[1] / 2.0 - centroid[1])
            })
            .fold(0.0, f64::max);
        (0..levels)
            .map(|level| {
                // the last table level's children read it again
                let child = own[(level + 1).min(levels - 1)];
                SampleReach {
                    from_centroid: (own[level].from_centroid)
                        .max(child_centroid + child.from_centroid / 2.0),
                    past_cells: own[level].past_cells.max(child.past_cells / 2.0),
                    warp: own[level].warp.max(child.warp),
                }
            })
            .collect()
    }

    /// The tile's region, its cap and spill holding what `reach` reaches.
    fn region_reaching(&self, tile: &SphereTile, reach: SampleReach) -> SphereRegion {
        let cell = |i: usize| {
            let (cx, cy) = self.shape.cells()[i];
            let p = self.face_point(tile, [cx as f64 + 0.5, cy as f64 + 0.5]);
            [p.x, p.y]
        };
        let nside = Self::nside(tile.level as u32) as f64;
        let centroid = self.face_point(tile, self.centroid);
        // every sample lies within `from_centroid` of the centroid, and so
        // does each cell centre: the box about it holds the steps between
        // them (face points clamp onto the face, which only brings them
        // nearer)
        let reach_on_face = reach.from_centroid / nside;
        let stretch = stretch_about(centroid, reach_on_face);
        SphereRegion {
            centroid,
            radius: cap_radius(stretch, reach_on_face) + reach.warp,
            face: tile.face,
            cells: [cell(0), cell(1), cell(2), cell(3), cell(4)],
            spill: reach.past_cells / nside,
            warp: reach.warp,
            stretch,
        }
    }

    /// How far a level's own samples land: its offsets in every bin, its
    /// sibling fills and drop moves, and its zonal warps.
    fn own_reach(&self, level: usize) -> SampleReach {
        let lut = &*self.lut;
        // the distinct stored pairs (an `i8` pair each) are few
        let mut seen = vec![false; 1 << 16];
        let mut hold = |stored: [i8; 2]| {
            seen[(stored[0] as u8 as usize) << 8 | stored[1] as u8 as usize] = true;
        };

        let mut warp = 0.0f64;
        for (bin, table) in lut.tables.get(level).into_iter().flatten().enumerate() {
            table.iter().for_each(|&pair| hold(pair));
            let moves = lut.drop_moves.get(level).and_then(|bins| bins.get(bin));
            for (row, _, shift) in moves.into_iter().flat_map(|moves| moves.iter()) {
                hold([0, 1].map(|c| table[row][c].wrapping_add(shift[c])));
            }
            warp = warp.max(lut.zonal_warp(level, bin).move_bound());
        }
        if let Some(fills) = lut.fills.get(level) {
            fills.iter().for_each(|&pair| hold(pair));
        }
        let cells = self.shape.cells();
        let mut reach = SampleReach {
            from_centroid: PENTOMINO_RADIUS,
            past_cells: 0.0,
            warp,
        };
        for (at, _) in seen.iter().enumerate().filter(|(_, &seen)| seen) {
            let p = crate::lut::dequantise([(at >> 8) as u8 as i8, at as u8 as i8]);
            let from_centroid = (p[0] - self.centroid[0]).hypot(p[1] - self.centroid[1]);
            // Chebyshev distance past the nearest cell, each `[x, x + 1]^2`
            let past = |&(x, y): &(Lattice, Lattice)| {
                let d = |v: f64, lo: f64| (lo - v).max(v - lo - 1.0).max(0.0);
                d(p[0], x as f64).max(d(p[1], y as f64))
            };
            let past_cells = cells.iter().map(past).fold(f64::INFINITY, f64::min);
            reach.from_centroid = reach.from_centroid.max(from_centroid);
            reach.past_cells = reach.past_cells.max(past_cells);
        }
        reach
    }
}

/// The radius (rad) of a cap holding every face point within `reach`
/// (face coordinates) of its centre, `stretch` bounding the stretch
/// between them. The bound is exact along an equatorial face's diagonal,
/// so the radius gains a margin for the rounding of computed positions
/// (about 4e-16 rad, 1e-4 of a level-36 tile's reach).
fn cap_radius(stretch: f64, reach: f64) -> f64 {
    stretch * reach * (1.0 + 1e-9) + 8.0 * f64::EPSILON
}

/// [`crate::healpix::stretch_over`] the box `centroid ± reach`: for the
/// small boxes of deep tiles (most of those a request visits), read from a
/// grid of bounds over the blocks of a face grown by a block a side.
fn stretch_about(centroid: FacePoint, reach: f64) -> f64 {
    const BLOCKS: usize = 64;
    const BLOCK: f64 = 1.0 / BLOCKS as f64;
    // one grid a ring of faces: the stretch depends only on the ring
    static GRID: OnceLock<Vec<f64>> = OnceLock::new();
    let (x, y) = (centroid.x, centroid.y);
    if reach > BLOCK || reach.is_nan() {
        return crate::healpix::stretch_over(
            centroid.face,
            [x - reach, x + reach],
            [y - reach, y + reach],
        );
    }
    let grid = GRID.get_or_init(|| {
        (0..3 * BLOCKS * BLOCKS)
            .map(|k| {
                let (ring, i, j) = (k / (BLOCKS * BLOCKS), k / BLOCKS % BLOCKS, k % BLOCKS);
                let (x0, y0) = (i as f64 * BLOCK, j as f64 * BLOCK);
                let grown = |v0: f64| [v0 - BLOCK, v0 + 2.0 * BLOCK];
                crate::healpix::stretch_over(4 * ring as u8, grown(x0), grown(y0))
            })
            .collect()
    });
    // the block holding the centroid (clamped onto the face): the box lies
    // within it grown by a block
    let block = |v: f64| ((v * BLOCKS as f64) as usize).min(BLOCKS - 1);
    let ring = (centroid.face as usize % crate::healpix::FACE_COUNT) / 4;
    grid[(ring * BLOCKS + block(x.clamp(0.0, 1.0))) * BLOCKS + block(y.clamp(0.0, 1.0))]
}

/// How far the samples that a tile's bound covers land from it: its own,
/// in every importance bin, with every sibling fill, drop move and zonal
/// warp, and its children's, which its bound thins when it makes them
/// terminal. A region that held less would let a sample land where the
/// density exceeds the bound its keep probability was drawn against: a
/// bias (DESIGN, "The terminal rule").
///
/// # Example
/// ```
/// use tessera::tiling::sphere::{SampleReach, SphereTiling};
/// let reach: SampleReach = SphereTiling::default().sample_reach(3);
/// assert!(reach.past_cells < reach.from_centroid && reach.warp < 1e-2);
/// ```
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct SampleReach {
    /// Largest distance from the tile's centroid, in its cells: at least
    /// the pentomino's own outline, which the region holds too.
    pub from_centroid: f64,
    /// Largest distance past the nearest of the tile's five cells, in
    /// either coordinate, in its cells: 0 while every sample lies in them.
    pub past_cells: f64,
    /// Largest move (rad) of a zonal warp.
    pub warp: f64,
}

/// [`SphereTiling::sample_reach`] of the table in `luts/sphere.lut`, level
/// by level: `the_embedded_sample_reach_holds` (tests/lut.rs) measures it
/// and fails when the table changes.
const EMBEDDED_REACH: [SampleReach; 8] = [
    SampleReach {
        from_centroid: 3.005203820042827,
        past_cells: 1.6749999999999998,
        warp: 0.03178728715298326,
    },
    SampleReach {
        from_centroid: 3.4428367663890196,
        past_cells: 1.85,
        warp: 0.018743236362983164,
    },
    SampleReach {
        from_centroid: 3.4354766772603766,
        past_cells: 2.2,
        warp: 0.00708551301383304,
    },
    SampleReach {
        from_centroid: 4.292580808790907,
        past_cells: 2.25,
        warp: 0.002553622621022408,
    },
    SampleReach {
        from_centroid: 4.424505622100621,
        past_cells: 2.375,
        warp: 0.0012291791488298449,
    },
    SampleReach {
        from_centroid: 4.564263357870577,
        past_cells: 2.6,
        warp: 0.000371549497725746,
    },
    SampleReach {
        from_centroid: 4.669047011971501,
        past_cells: 2.7,
        warp: 7.65233841410274e-5,
    },
    SampleReach {
        from_centroid: 3.079163847540433,
        past_cells: 0.9750000000000001,
        warp: 0.0,
    },
];

/// Spacings (of a bin's set) within which a tile's ring twins, the tiles
/// whose codes differ from its own in the last two bits only, share the
/// hole it leaves: the four tiles next to a pole, about one spacing apart.
/// The builder relaxes the sibling fills of such a tile with its whole
/// orbit missing, and a request that keeps part of the orbit reads none.
pub(crate) const TWINS_SHARE_A_HOLE: f64 = 3.5;

/// Whether a ring twin of the tile of code `lost` on tree-indexed level
/// `level` lies within [`TWINS_SHARE_A_HOLE`] spacings of it, their points
/// placed by `lut`'s offsets in bin `bin` (twins outside the bin's set do
/// not count).
pub(crate) fn twins_share_a_hole(
    tiling: &SphereTiling,
    lut: &SphereLut,
    (level, bin): (u32, usize),
    lost: u64,
) -> bool {
    let in_bin = lut.bin_codes(bin, tiling.capacity(level));
    let site = |code: u64| {
        let tile = tiling.tile_with_code(level, code as Code)?;
        let offset = lut.offset(level as usize, tile.index as usize, bin);
        Some(tiling.face_point(&tile, offset).to_vec())
    };
    let Some(own) = site(lost) else {
        return false;
    };
    let spacing = (4.0 * std::f64::consts::PI / in_bin as f64).sqrt();
    (lost & !3..(lost | 3) + 1)
        .filter(|&twin| twin != lost && twin < in_bin)
        .filter_map(site)
        .any(|twin| twin.distance(own) < TWINS_SHARE_A_HOLE * spacing)
}

/// The face point of a point given in the frame (cells) of a tile so
/// placed on face `face`, on a lattice of `1 / scale` cells per face edge.
#[inline(always)]
fn on_face(face: u8, placement: &Placement, scale: f64, local: [f64; 2]) -> FacePoint {
    let lattice = placement.to_lattice(local);
    FacePoint::new(
        face,
        (lattice[0] * scale).clamp(0.0, 1.0),
        (lattice[1] * scale).clamp(0.0, 1.0),
    )
}

impl Subdivision for SphereTiling {
    fn arity(&self) -> usize {
        4
    }
    fn scale(&self) -> Lattice {
        2
    }
    fn rules(&self) -> usize {
        self.lut.rules.len()
    }
    fn classes(&self) -> usize {
        self.lut.transitions.len()
    }
    fn child_of_digit(&self, rule: usize, digit: usize) -> usize {
        self.child_of_digit[rule][digit] as usize
    }
    fn child_rule(&self, rule: usize, child: usize) -> usize {
        self.lut.child_rule[rule][child] as usize
    }
    fn child_step(&self, rule: usize, child: usize) -> Placement {
        self.lut.rules[rule].children[child]
    }
    fn child_class(&self, class: usize, child: usize) -> usize {
        self.lut.transitions[class][child] as usize
    }
}

impl TileSystem for SphereTiling {
    type Tile = SphereTile;
    type Point = DVec3;
    type Region = SphereRegion;

    fn roots(&self) -> Vec<SphereTile> {
        let lut = &*self.lut;
        (0..ROOT_COUNT)
            .map(|r| SphereTile {
                face: (r / ROOTS_PER_FACE) as u8,
                level: 0,
                rule: lut.root_rule[r],
                placement: lut.patch[r % ROOTS_PER_FACE],
                index: r as u32,
                code: lut.root_rank[r] as Code,
            })
            .collect()
    }

    fn child_count(&self, _: &SphereTile) -> usize {
        4
    }

    fn child(&self, tile: &SphereTile, i: usize) -> SphereTile {
        self.subdivide(tile, i)
    }

    fn measure(&self) -> f64 {
        4.0 * std::f64::consts::PI
    }

    fn level(&self, tile: &SphereTile) -> u32 {
        tile.level as u32
    }

    fn max_level(&self) -> u32 {
        MAX_LEVEL
    }

    fn capacity(&self, level: u32) -> f64 {
        // 240 * 4^level, exact (15 times a power of two): 4^level built
        // from its exponent bits rather than by a `powi` call per tile
        let four_to_level = f64::from_bits((1023 + 2 * level.min(500) as u64) << 52);
        ROOT_COUNT as f64 * four_to_level
    }

    fn code(&self, tile: &SphereTile) -> Code {
        tile.code
    }

    fn child_code(&self, tile: &SphereTile, i: usize) -> Code {
        let digit = self.lut.child_digit[tile.rule as usize][i] as Code;
        tile.code + digit * ((ROOT_COUNT as Code) << (2 * tile.level as u32))
    }

    /// Codes grow with the child's digit.
    fn child_by_code_rank(&self, tile: &SphereTile, rank: usize) -> Option<usize> {
        let children = &self.child_of_digit[tile.rule as usize];
        children.get(rank).map(|&child| child as usize)
    }

    fn region(&self, tile: &SphereTile) -> SphereRegion {
        self.region_reaching(tile, self.sample_reach(tile.level as u32))
    }

    fn placing_region(&self, tile: &SphereTile, region: &SphereRegion) -> Option<SphereRegion> {
        // the region's centroid, cells and stretch (its reach holds the
        // pentomino's), with the pentomino's reach
        let nside = Self::nside(tile.level as u32) as f64;
        Some(SphereRegion {
            radius: cap_radius(region.stretch, PENTOMINO_RADIUS / nside),
            spill: 0.0,
            warp: 0.0,
            ..*region
        })
    }

    fn map_code_order<T: Send>(
        &self,
        level: u32,
        codes: Range<usize>,
        f: &(dyn Fn(Code, &SphereTile) -> T + Sync),
    ) -> Option<Vec<T>> {
        if level > MAX_LEVEL || codes.end as f64 > self.capacity(level) {
            return None;
        }
        let mut out = Vec::new();
        self.extend_in_code_order(level, codes, &mut out, f);
        Some(out)
    }

    /// From a list of one level's tiles in code order (see
    /// [`code_order`]). A tree-indexed level descends from its list by tree
    /// index; a deeper one lists no shallower than the level whose classes
    /// the table holds, so that the classes descend by the automaton.
    fn code_order(
        &self,
        level: u32,
        codes: Range<usize>,
        fraction: f64,
        d: f64,
    ) -> Option<Box<dyn CodeOrder<DVec3> + '_>> {
        if level > MAX_LEVEL || codes.end as f64 > self.capacity(level) {
            return None;
        }
        let exact = self.lut.exact_levels as u32;
        let (first, indexing) = match level < exact {
            true => (0, Indexing::Tree),
            false => (exact - 2, Indexing::Classes),
        };
        let listed = code_order::list_level(level, first, |l| self.capacity(l));
        let m = self.capacity(listed) as usize;
        let listed_codes = code_order::listed_codes(&codes, m);
        let mut list = Vec::with_capacity(listed_codes.len());
        self.extend_in_code_order(listed, listed_codes.clone(), &mut list, &|_, t| {
            let index = match indexing {
                Indexing::Tree => t.index,
                Indexing::Classes => self.class_of(t),
            };
            Node::new(&t.placement, t.rule, index, t.face)
        });
        let scale = 1.0 / Self::nside(level) as f64;
        let depth = level - listed;
        // what `sample` computes; one closure per kind of level, so that the
        // deep levels' loop carries no per-tile lookup (compiled in, even
        // unused, it made uniform 10^7 about 25 % slower)
        let sample = move |t: &code_order::Placed, code: usize, offset: [f64; 2]| Sample {
            position: on_face(t.face, &t.placement, scale, offset).to_vec(),
            rank: code_value(code as Code) / d,
        };
        if indexing == Indexing::Classes {
            // each class's offset at this fraction, looked up once
            let offsets: Vec<[f64; 2]> = (0..self.lut.transitions.len())
                .map(|class| {
                    let root = self.roots_by_code[0];
                    let tile = SphereTile {
                        level: level as u8,
                        index: class as u32,
                        ..root
                    };
                    self.offset(&tile, fraction)
                })
                .collect();
            let place = move |t: &code_order::Placed, code: usize| {
                sample(t, code, offsets[t.class as usize])
            };
            let source = Listed::new(self, list, listed_codes.start, m, depth, indexing, place);
            return Some(Box::new(source));
        }
        // tiles indexed by tree position: an offset per tile (or its drop
        // move or fill), with the request's bin and tables found once
        let lut = &*self.lut;
        let capacity = self.capacity(level);
        let bin = lut.bin(fraction, capacity);
        let offsets = lut.request_offsets(level, fraction, capacity, bin);
        let warp = lut.zonal_warp(level as usize, bin);
        let place = move |t: &code_order::Placed, code: usize| {
            let shares = |lost| twins_share_a_hole(self, lut, (level, bin), lost);
            let offset = offsets.placed(t.class as usize, code as u64, shares);
            let mut placed = sample(t, code, offset);
            placed.position = warp.apply(placed.position);
            placed
        };
        let source = Listed::new(self, list, listed_codes.start, m, depth, indexing, place);
        Some(Box::new(source))
    }

    fn tile_with_code(&self, level: u32, code: Code) -> Option<SphereTile> {
        if level > MAX_LEVEL || code_value(code) >= self.capacity(level) {
            return None;
        }
        let mut tile = *self
            .roots_by_code
            .get((code % ROOT_COUNT as Code) as usize)?;
        let mut digits = code / ROOT_COUNT as Code;
        for _ in 0..level {
            let child = self.child_of_digit[tile.rule as usize][(digits & 3) as usize];
            tile = self.subdivide(&tile, child as usize);
            digits >>= 2;
        }
        Some(tile)
    }

    fn sample(&self, tile: &SphereTile, fraction: f64) -> DVec3 {
        let (offset, bin) = self.offset_in_bin(tile, fraction);
        let p = self.face_point(tile, offset).to_vec();
        // the class levels, and bins no uniform request reads, have none
        let warp = self.lut.zonal_warp(tile.level as usize, bin);
        if warp.is_identity() {
            p
        } else {
            warp.apply(p)
        }
    }
}

impl super::reference::ReferencePoint for SphereTiling {
    fn reference(&self, tile: &SphereTile) -> DVec3 {
        self.face_point(tile, self.centroid).to_vec()
    }
}

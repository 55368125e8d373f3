//! Table formats and the tables embedded from `luts/`.
//!
//! A table file is a postcard-encoded struct whose first field is its format
//! version; `luts/*.provenance.json` beside it records the command, seed,
//! parameters and resulting metrics. `tessera lut build` regenerates both.

mod drop_moves;
mod zonal_warp;

pub use drop_moves::{DropMoves, MOST_MOVES_A_ROW};
pub use zonal_warp::ZonalWarp;

use crate::polyomino::{Lattice, Placement, Rule};
use crate::Error;
use serde::{Deserialize, Serialize};
use std::sync::{Arc, OnceLock};

/// Pentominoes per sphere face at level 0: a sphere table holds a rule for
/// each of a face's roots.
///
/// # Example
/// ```
/// assert_eq!(tessera::lut::ROOTS_PER_FACE * 5, 10 * 10); // a 10x10 patch
/// ```
pub const ROOTS_PER_FACE: usize = 20;
/// Number of level-0 tiles on the sphere.
///
/// # Example
/// ```
/// assert_eq!(tessera::lut::ROOT_COUNT, 240);
/// ```
pub const ROOT_COUNT: usize = 12 * ROOTS_PER_FACE;
/// Most cells a planar rep-tile of a table may have.
///
/// # Example
/// ```
/// assert!(tessera::polyomino::Shape::g_hexomino().cells().len() <= tessera::lut::MAX_CELLS);
/// ```
pub const MAX_CELLS: usize = 8;

/// Format version written into and required from sphere tables.
pub const SPHERE_LUT_VERSION: u32 = 12;

/// Of the bins stored as differences from the bin below (see
/// `SphereLut::chained`), every this many is stored whole, so that a
/// request's first read of a bin decodes at most this many frames. Levels
/// 0-5 took 3,870,814 bytes with one run of 12 (90 kB less than none), and
/// 3,880,112, 3,890,151 and 3,894,781 with runs of 6, 4 and 3; with 12,
/// a first request at N = 240,000 (level 5's top bin) took 10 % longer.
const DIFFERENCE_RUN: usize = 4;

/// zstd level sphere tables are written with: the highest, as a table is
/// written once and read at every start (decoding speed does not depend on
/// the level).
const SPHERE_LUT_ZSTD_LEVEL: i32 = 22;

/// Most bytes one frame of a sphere table may decode to: far above a real
/// table's (11 MB in all), it keeps a hostile file from exhausting memory.
const SPHERE_LUT_MAX_DECODED: u64 = 1 << 28;

/// Offsets are stored as `i8` multiples of `1 / OFFSET_SCALE` cells from
/// [`OFFSET_CENTRE`] (resolution 0.025 cells, 0.3 % of the point spacing;
/// range +-3.2 cells, which holds the pentomino's box dilated by one cell):
/// a quarter of the size of `f32`, so twice the importance bins fit.
pub const OFFSET_SCALE: f64 = 40.0;

/// Centre of the P-pentomino's 2x3 bounding box, in its own frame (cells):
/// the origin of stored offsets.
pub const OFFSET_CENTRE: [f64; 2] = [1.0, 1.5];

/// Density fractions users ask for most often, each given a bin of its own
/// so that those requests see no holes: powers of two land on 4/15 or 8/15
/// of a level's capacity (`240 * 4^k` tiles), HEALPix pixel counts
/// `12 * 4^k` on 4/5, and `3 * 2^k` on 2/5 or 4/5.
pub const COMMON_FRACTIONS: [f64; 4] = [4.0 / 15.0, 2.0 / 5.0, 8.0 / 15.0, 4.0 / 5.0];

/// Everything the sphere tile system needs at run time.
///
/// # Example
/// ```
/// let lut = tessera::lut::sphere_lut();
/// assert_eq!(lut.version, tessera::lut::SPHERE_LUT_VERSION);
/// assert_eq!(lut.patch.len(), 20);
/// ```
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct SphereLut {
    /// Format version, [`SPHERE_LUT_VERSION`].
    pub version: u32,
    /// Seed the optimiser ran with.
    pub seed: u64,
    /// The two dissections of the doubled P-pentomino.
    pub rules: Vec<Rule>,
    /// `child_rule[rule][child]`: the rule a child subdivides with.
    pub child_rule: Vec<[u8; 4]>,
    /// `child_digit[rule][child]`: the child's rank among its siblings.
    pub child_digit: Vec<[u8; 4]>,
    /// The 20 pentominoes of a face's 10x10 patch.
    pub patch: Vec<Placement>,
    /// Rule of each of the 240 roots (face-major).
    pub root_rule: Vec<u8>,
    /// Code (rank) of each of the 240 roots.
    pub root_rank: Vec<u32>,
    /// Levels `0..exact_levels` index tiles by tree position.
    pub exact_levels: u8,
    /// Levels `ring_from..exact_levels` share each offset row between the
    /// four faces of a HEALPix ring (north, equatorial, south): turning
    /// the sphere a quarter about its axis maps those faces, their tiles
    /// and their neighbourhoods onto each other, so a quarter of the rows
    /// serve (see [`SphereLut::row`]).
    pub ring_from: u8,
    /// The class of each tile of level `exact_levels - 2`, in fours by
    /// parent (`entry_class[index / 4][index % 4]`): the last tree-indexed
    /// level's classes, and every deeper level's, follow by `transitions`.
    /// One level up, the lookup a request past the tree-indexed levels
    /// makes once a tile stays a quarter of the size (1 MB, in cache).
    pub entry_class: Vec<[u32; 4]>,
    /// Neighbourhood-class automaton: `transitions[class][child]`.
    pub transitions: Vec<[u32; 4]>,
    /// The density fraction (of a level's capacity) each importance bin
    /// was optimised for, increasing, the last one 1.
    pub bin_fractions: Vec<f64>,
    /// Offsets per level (the last one, the class table, serves every
    /// deeper level) and importance bin, indexed by row (see
    /// [`SphereLut::row`]), in the tile's frame, as cells from
    /// [`OFFSET_CENTRE`] times [`OFFSET_SCALE`]. A request reads one bin of
    /// a level: level 6's 490 KB of its 5.9 MB, decoded and cached alone.
    pub tables: Vec<Vec<Offsets>>,
    /// Sibling-fill offsets of the first per-tile levels (none at level 0;
    /// levels from `fills.len()` on have none),
    /// indexed `parent index * FILL_PAIRS + pair` (see
    /// [`SphereLut::fill_pair`]): a request between two bins keeps a prefix
    /// of the upper bin's set, and where that drops one child of a parent,
    /// its lower siblings take these offsets, relaxed with it missing and
    /// every other point of the bin in place. Levels whose drop moves
    /// replace them have none (an empty table).
    pub fills: Vec<Offsets>,
    /// Drop moves of the first per-tile levels, per level and bin (levels
    /// from `drop_moves.len()` on have none; see [`DropMoves`]): a request
    /// between two bins moves the points beside each code it drops as the
    /// builder moved them, dropping the bin's codes from the top. Where a
    /// level has fills too (level 6), a move takes precedence over a fill.
    pub drop_moves: Vec<Vec<DropMoves>>,
    /// Zonal warps of the first per-tile levels, per level and bin
    /// (levels from `zonal_warps.len()` on have none; see [`ZonalWarp`]):
    /// every point a bin places on the level moves by its bin's warp.
    /// Stored in the file's last frame.
    #[serde(skip)]
    pub zonal_warps: Vec<Vec<ZonalWarp>>,
}

/// One offset table (`i8` pairs, see [`SphereLut::tables`]), kept in its
/// zstd frame until it is first read: a request decodes only the bin of
/// the level it reads (decoding all 11 MB at start took 28 ms of a
/// 36 ms `tessera sphere -n 1000`). It reads and writes as a `Vec`.
///
/// # Example
/// ```
/// let mut offsets = tessera::lut::Offsets::from(vec![[0i8, 0], [1, -1]]);
/// offsets[1] = [2, 2];
/// assert_eq!(offsets.len(), 2);
/// assert_eq!(offsets[1], [2, 2]);
/// ```
#[derive(Clone, Debug, Default)]
pub struct Offsets {
    decoded: OnceLock<Vec<[i8; 2]>>,
    /// The zstd frames of the raw pairs, until decoded (none once they
    /// are): the table's own last, and where it is stored as differences
    /// from the bin below, those of the bins below it first.
    frames: Vec<Arc<[u8]>>,
    /// How the frame's rows are ordered, if not as in memory.
    order: Option<RowOrder>,
}

impl Offsets {
    /// A table still in its zstd frames, its rows in `order`, decoded
    /// when first read: `frames` are the lowest bin's pairs, then each
    /// bin's differences from the one below up to this one (see
    /// [`SphereLut::to_bytes`]).
    fn packed(frames: Vec<Arc<[u8]>>, order: Option<RowOrder>) -> Self {
        Offsets {
            decoded: OnceLock::new(),
            frames,
            order,
        }
    }

    /// Whether the table is still in its frames.
    fn is_packed(&self) -> bool {
        !self.frames.is_empty()
    }

    /// The offsets, decoded on first use.
    fn get(&self) -> &Vec<[i8; 2]> {
        self.decoded.get_or_init(|| {
            // only the embedded table stays packed (`from_bytes` decodes a
            // file's frames at once), and the test suite decodes all of it
            self.decode()
                .expect("the embedded luts/sphere.lut is checked by the test suite")
        })
    }

    /// The frames' pairs, in memory's row order.
    fn decode(&self) -> Result<Vec<[i8; 2]>, Error> {
        // a default table is empty
        let Some((first, differences)) = self.frames.split_first() else {
            return Ok(Vec::new());
        };
        let mut pairs = decode_pairs(first)?;
        for frame in differences {
            let difference = decode_pairs(frame)?;
            if difference.len() != pairs.len() {
                return Err(Error::Table(
                    "sphere table: an offset table's differences have another size than its bin below".into(),
                ));
            }
            // wrapping, as written: every stored value is an `i8`
            for (pair, d) in pairs.iter_mut().zip(difference) {
                *pair = [0, 1].map(|c| pair[c].wrapping_add(d[c]));
            }
        }
        Ok(match self.order {
            Some(order) => order.to_memory(pairs),
            None => pairs,
        })
    }

    /// The table's pairs in the file's row `order`.
    fn to_file(&self, order: Option<RowOrder>) -> Vec<[i8; 2]> {
        match order {
            Some(order) => order.to_file(self.get().clone()),
            None => self.get().clone(),
        }
    }

    /// The table's zstd frame, its rows in `order`, as differences from
    /// `below` (a table of the same size) if given.
    fn compress(&self, order: Option<RowOrder>, below: Option<&Offsets>) -> Vec<u8> {
        let mut pairs = self.to_file(order);
        if let Some(below) = below {
            for (pair, b) in pairs.iter_mut().zip(below.to_file(order)) {
                *pair = [0, 1].map(|c| pair[c].wrapping_sub(b[c]));
            }
        }
        let raw: Vec<u8> = pairs.iter().flatten().map(|&v| v as u8).collect();
        zstd::bulk::compress(&raw, SPHERE_LUT_ZSTD_LEVEL)
            .expect("compressing in memory cannot fail")
    }
}

/// The row order of a per-tile table in the file. In memory a row is
/// `place * roots + root` (see [`SphereLut::row`]): consecutive codes of
/// a level lie below different roots at one place, so a request reads
/// neighbouring rows. In the file it is `root * places + place`, each
/// root's subtree in one run, which zstd packs smaller (level 6's tables,
/// measured when this order was chosen: 1.97 MB against 2.36 MB).
#[derive(Clone, Copy, Debug)]
struct RowOrder {
    roots: usize,
    places: usize,
    /// Pairs a row.
    width: usize,
}

impl RowOrder {
    /// A file's pairs in memory's order; a table of another size stays
    /// as it is, for [`SphereLut::validate`] to refuse.
    fn to_memory(self, pairs: Vec<[i8; 2]>) -> Vec<[i8; 2]> {
        self.transpose(pairs, self.roots, self.places)
    }

    /// Memory's pairs in the file's order.
    fn to_file(self, pairs: Vec<[i8; 2]>) -> Vec<[i8; 2]> {
        self.transpose(pairs, self.places, self.roots)
    }

    /// `pairs`, a `rows x columns` matrix of rows of `width` pairs,
    /// transposed (read column by column: `rows` sequential streams).
    fn transpose(self, pairs: Vec<[i8; 2]>, rows: usize, columns: usize) -> Vec<[i8; 2]> {
        let width = self.width;
        if rows.checked_mul(columns).and_then(|n| n.checked_mul(width)) != Some(pairs.len()) {
            return pairs;
        }
        let mut out = Vec::with_capacity(pairs.len());
        for column in 0..columns {
            for row in 0..rows {
                let at = (row * columns + column) * width;
                out.extend_from_slice(&pairs[at..at + width]);
            }
        }
        out
    }
}

/// One level's offsets in one importance bin, with what a request between
/// two bins reads in their place beside the codes it drops (a drop move,
/// else a sibling fill), as
/// [`SphereLut::request_offsets`] resolves them once for a request.
pub(crate) struct LevelOffsets<'a> {
    lut: &'a SphereLut,
    level: usize,
    table: &'a [[i8; 2]],
    /// The level's drop moves in the bin, the first key the request
    /// drops, and whether a ring's faces share the level's rows.
    moves: Option<(&'a DropMoves, u32, bool)>,
    /// The level's sibling fills, and the request's counts.
    fills: Option<(&'a [[i8; 2]], FillCounts)>,
}

impl LevelOffsets<'_> {
    /// The bin's offset (tile frame, cells) of structural index `index`.
    #[inline]
    pub fn offset(&self, index: usize) -> [f64; 2] {
        dequantise(self.table[self.lut.row(self.level, index)])
    }

    /// The offset (tile frame, cells) of the tile of tree index `index`
    /// and code `code` in the request: its drop move or sibling fill where
    /// the request drops a code beside it, else the bin's.
    /// `shares_a_hole` is [`SphereLut::fill_pair`]'s.
    #[inline]
    pub fn placed(
        &self,
        index: usize,
        code: u64,
        shares_a_hole: impl FnOnce(u64) -> bool,
    ) -> [f64; 2] {
        let row = self.lut.row(self.level, index);
        // a move where the request drops a code beside the point, else
        // (level 6 has both) its sibling fill
        let moved = (self.moves)
            .and_then(|(moves, dropped_from, ring)| {
                moves.shift(row, dropped_from, ring.then_some((code & 3) as u8))
            })
            .map(|shift| [0, 1].map(|c| self.table[row][c].wrapping_add(shift[c])))
            .or_else(|| {
                let (fills, counts) = self.fills.as_ref()?;
                (counts.pair(code, shares_a_hole))
                    // tree indices: the parent's is the tile's over 4
                    .map(|pair| fills[self.lut.row(self.level - 1, index / 4) * FILL_PAIRS + pair])
            });
        dequantise(moved.unwrap_or(self.table[row]))
    }
}

/// The pairs of one table's zstd frame.
fn decode_pairs(frame: &[u8]) -> Result<Vec<[i8; 2]>, Error> {
    let raw = decompress(frame)?;
    if raw.len() % 2 != 0 {
        return Err(Error::Table(
            "sphere table: an offset table has an odd length".into(),
        ));
    }
    Ok(raw
        .chunks_exact(2)
        .map(|p| [p[0] as i8, p[1] as i8])
        .collect())
}

impl From<Vec<[i8; 2]>> for Offsets {
    fn from(offsets: Vec<[i8; 2]>) -> Self {
        Offsets {
            decoded: OnceLock::from(offsets),
            frames: Vec::new(),
            order: None,
        }
    }
}

impl std::ops::Deref for Offsets {
    type Target = Vec<[i8; 2]>;
    fn deref(&self) -> &Vec<[i8; 2]> {
        self.get()
    }
}

impl std::ops::DerefMut for Offsets {
    fn deref_mut(&mut self) -> &mut Vec<[i8; 2]> {
        self.get();
        self.frames.clear(); // stale once changed
        self.decoded.get_mut().expect("decoded just above")
    }
}

impl PartialEq for Offsets {
    fn eq(&self, other: &Self) -> bool {
        self.get() == other.get()
    }
}

impl Serialize for Offsets {
    fn serialize<S: serde::Serializer>(&self, serializer: S) -> Result<S::Ok, S::Error> {
        self.get().serialize(serializer)
    }
}

impl<'de> Deserialize<'de> for Offsets {
    fn deserialize<D: serde::Deserializer<'de>>(deserializer: D) -> Result<Self, D::Error> {
        Vec::deserialize(deserializer).map(Offsets::from)
    }
}

/// Sibling-fill entries per parent: a kept child `s` below a missing
/// child `d` (`s < d <= 3`), `d (d - 1) / 2 + s`.
pub const FILL_PAIRS: usize = 6;

/// A request's counts at one per-tile level, as sibling fills need them.
#[derive(Clone, Copy, Debug)]
pub(crate) struct FillCounts {
    /// Codes the request keeps.
    accepted: u64,
    /// Codes its importance bin's set holds.
    in_bin: u64,
    /// Tiles one level up.
    parents: u64,
}

impl FillCounts {
    /// The sibling-fill entry of the tile of code `code` (see
    /// [`SphereLut::fill_pair`]); `shares_a_hole` runs only for the one
    /// orbit a request splits.
    pub(crate) fn pair(&self, code: u64, shares_a_hole: impl FnOnce(u64) -> bool) -> Option<usize> {
        let FillCounts {
            accepted,
            in_bin,
            parents,
        } = *self;
        if code >= accepted {
            return None;
        }
        // `x / parents` for `x <= capacity` by comparisons: this runs once a
        // sample, and a division by a variable costs as much as the rest
        let quarters = |x: u64| (1..=4).filter(|&k| x >= k * parents).count() as u64;
        let digit = quarters(code);
        let parent = code - digit * parents;
        // the lowest sibling the request drops (above this one, which it
        // keeps), if the bin keeps it: `ceil((accepted - parent) / parents)`
        let missing = quarters(accepted - parent + parents - 1);
        let lost = parent + missing * parents;
        // where the lost child's ring twins (codes equal but for the last
        // two bits) share its hole, next to a pole, its fills are relaxed
        // with the whole orbit missing: there a request keeping part of the
        // orbit (at most one orbit a request) keeps the bin's offsets
        let whole_orbit = lost & !3 >= accepted;
        (missing <= 3 && lost < in_bin && (whole_orbit || !shares_a_hole(lost)))
            .then(|| (missing * (missing - 1) / 2 + digit) as usize)
    }
}

impl SphereLut {
    /// The importance bin of a density fraction `f` in `(0, 1]` of a level
    /// of `capacity` tiles: the first bin whose relaxed set holds every
    /// tile the engine accepts at `f` (codes `c + 1/2 < f * capacity`). So
    /// the accepted tiles are a subset of the bin's (holes at worst, never
    /// a crowd), and a request keeping exactly a bin's tiles gets the
    /// offsets they were relaxed with, even when its fraction lies a
    /// sliver above the bin's.
    ///
    /// # Example
    /// ```
    /// let lut = tessera::lut::sphere_lut();
    /// let capacity = 3840.0; // level 2
    /// assert_eq!(lut.bin(1.0, capacity), lut.bin_fractions.len() - 1);
    /// assert_eq!(lut.bin(0.25, capacity), 0);
    /// assert_eq!(lut.bin(1e-9, capacity), 0);
    /// assert_eq!(lut.bin_fractions[lut.bin(0.8, capacity)], 0.8);
    /// // a bin relaxed on the codes below 1235.4 serves 1236 samples
    /// let b = lut.bin(1236.0 / capacity, capacity);
    /// assert!(lut.bin_fractions[b] < 1236.0 / capacity);
    /// ```
    pub fn bin(&self, fraction: f64, capacity: f64) -> usize {
        // the optimiser relaxed bin `b` on the codes below `edge_b * capacity`,
        // and `accepted <= ceil(x)` is `accepted - 1 < x` for whole counts
        let below = (accepted_count(fraction, capacity) - 1.0) / capacity;
        self.bin_fractions
            .iter()
            .position(|&edge| edge > below)
            .unwrap_or(self.bins() - 1)
    }

    /// Number of importance bins.
    ///
    /// # Example
    /// ```
    /// let lut = tessera::lut::sphere_lut();
    /// assert_eq!(lut.bins(), lut.bin_fractions.len());
    /// ```
    pub fn bins(&self) -> usize {
        self.bin_fractions.len()
    }

    /// Codes the set of bin `bin` holds on a level of `capacity` tiles:
    /// those below `f_b * capacity`.
    ///
    /// # Example
    /// ```
    /// let lut = tessera::lut::sphere_lut();
    /// assert_eq!(lut.bin_codes(lut.bins() - 1, 960.0), 960);
    /// ```
    pub fn bin_codes(&self, bin: usize, capacity: f64) -> u64 {
        codes_below(self.bin_fractions[bin], capacity)
    }

    /// Decodes a table, checking its version and internal consistency.
    ///
    /// # Example
    /// ```
    /// assert!(tessera::lut::SphereLut::from_bytes(b"not a table").is_err());
    /// ```
    pub fn from_bytes(bytes: &[u8]) -> Result<Self, Error> {
        let mut lut = Self::read(bytes)?;
        // decoded and checked in full: a file from outside
        for table in lut.tables.iter_mut().flatten().chain(&mut lut.fills) {
            if table.is_packed() {
                *table = Offsets::from(table.decode()?);
            }
        }
        for moves in lut.drop_moves.iter_mut().flatten() {
            moves.unpack()?;
        }
        lut.validate()?;
        Ok(lut)
    }

    /// Reads the header frame and keeps each offset table in its frame.
    /// The file is zstd frames: the table with its offset tables empty,
    /// then each of `tables` (level by level, bin by bin), then each of
    /// `fills`, as raw pairs, then each of `drop_moves` (level by level,
    /// bin by bin; see [`DropMoves`]), then the `zonal_warps`.
    fn read(bytes: &[u8]) -> Result<Self, Error> {
        let mut frames = Frames(bytes);
        let header = decompress(frames.next().unwrap_or(bytes))?;
        let version = header.first().copied().unwrap_or(0) as u32;
        if version != SPHERE_LUT_VERSION {
            return Err(Error::Table(format!(
                "sphere table has format version {version}, this build reads version {SPHERE_LUT_VERSION}"
            )));
        }
        let mut lut: SphereLut = postcard::from_bytes(&header)
            .map_err(|e| Error::Table(format!("sphere table does not decode: {e}")))?;
        let (orders, chained) = (lut.row_orders(), lut.chained());
        let tables = lut.tables.iter_mut().flatten().chain(&mut lut.fills);
        // the frames a table stored as differences decodes from
        let mut chain: Vec<Arc<[u8]>> = Vec::new();
        for ((table, order), chained) in tables.zip(orders).zip(chained) {
            let frame = frames.next().ok_or_else(|| {
                Error::Table("sphere table does not decompress: it ends before its offsets".into())
            })?;
            if !chained {
                chain.clear();
            }
            chain.push(frame.into());
            *table = Offsets::packed(chain.clone(), order);
        }
        for moves in lut.drop_moves.iter_mut().flatten() {
            let frame = frames.next().ok_or_else(|| {
                Error::Table(
                    "sphere table does not decompress: it ends before its drop moves".into(),
                )
            })?;
            *moves = DropMoves::packed(frame);
        }
        let warps = frames.next().ok_or_else(|| {
            Error::Table("sphere table does not decompress: it ends before its zonal warps".into())
        })?;
        lut.zonal_warps = postcard::from_bytes(&decompress(warps)?).map_err(|e| {
            Error::Table(format!("sphere table: its zonal warps do not decode: {e}"))
        })?;
        Ok(lut)
    }

    /// Whether each offset table, in the file's order (see
    /// [`SphereLut::row_orders`]), is stored as its differences from the
    /// one before it: a bin of a tree-indexed level but the last, from
    /// the bin below, but every [`DIFFERENCE_RUN`]th. Neighbouring bins'
    /// offsets are close (coupled, see
    /// [`crate::optimize::sphere::BinCoupling`]). Level 6's bins are
    /// stored whole: as differences (all twelve coupled, scratch) they
    /// packed 36 kB larger, its rows that keep their classes' offsets
    /// matching as they are.
    fn chained(&self) -> Vec<bool> {
        let tables = self.tables.iter().enumerate().flat_map(|(level, bins)| {
            let chained = level + 1 < self.exact_levels as usize;
            (0..bins.len()).map(move |bin| chained && bin % DIFFERENCE_RUN != 0)
        });
        tables.chain(self.fills.iter().map(|_| false)).collect()
    }

    /// The file's row order of each offset table, in the file's order
    /// (`tables` level by level and bin by bin, then `fills`).
    fn row_orders(&self) -> Vec<Option<RowOrder>> {
        // a per-tile level's rows, each `width` pairs; none past them
        let order = |level: usize, width: usize| {
            let places = 1usize.checked_shl(2 * level as u32)?;
            let roots = match level < self.ring_from as usize {
                true => ROOT_COUNT,
                false => ROOT_COUNT / 4,
            };
            (level < self.exact_levels as usize).then_some(RowOrder {
                roots,
                places,
                width,
            })
        };
        let tables = self.tables.iter().enumerate();
        let tables = tables.flat_map(|(level, bins)| vec![order(level, 1); bins.len()]);
        // a level's fills are rows of its parents' level
        let fills = (0..self.fills.len()).map(|level| order(level.checked_sub(1)?, FILL_PAIRS));
        tables.chain(fills).collect()
    }

    /// Encodes the table: zstd frames, the first the table's postcard
    /// encoding without its offsets, then one a table of offsets (their
    /// raw pairs), so that each is decoded only when a request first
    /// reads it. zstd takes the 11 MB to about a third.
    ///
    /// # Example
    /// ```
    /// let lut = tessera::lut::sphere_lut();
    /// let bytes = lut.to_bytes();
    /// assert_eq!(tessera::lut::SphereLut::from_bytes(&bytes).unwrap(), *lut);
    /// ```
    pub fn to_bytes(&self) -> Vec<u8> {
        let mut header = self.clone();
        for table in header.tables.iter_mut().flatten().chain(&mut header.fills) {
            *table = Offsets::default();
        }
        for moves in header.drop_moves.iter_mut().flatten() {
            *moves = DropMoves::default();
        }
        let raw = postcard::to_allocvec(&header).expect("serialising to memory cannot fail");
        let mut bytes = zstd::bulk::compress(&raw, SPHERE_LUT_ZSTD_LEVEL)
            .expect("compressing in memory cannot fail");
        let tables: Vec<&Offsets> = self.tables.iter().flatten().chain(&self.fills).collect();
        let files = self.row_orders().into_iter().zip(self.chained());
        for (at, (order, chained)) in files.enumerate() {
            let below = chained.then(|| tables[at - 1]);
            bytes.extend(tables[at].compress(order, below));
        }
        for moves in self.drop_moves.iter().flatten() {
            bytes.extend(moves.compress());
        }
        let warps =
            postcard::to_allocvec(&self.zonal_warps).expect("serialising to memory cannot fail");
        bytes.extend(
            zstd::bulk::compress(&warps, SPHERE_LUT_ZSTD_LEVEL)
                .expect("compressing in memory cannot fail"),
        );
        bytes
    }

    /// The offset (tile frame, cells) of structural index `index` at
    /// `level` in importance bin `bin`.
    ///
    /// # Example
    /// ```
    /// let lut = tessera::lut::sphere_lut();
    /// let o = lut.offset(0, 0, lut.bins() - 1);
    /// assert!(tessera::polyomino::Shape::p_pentomino().contains(o));
    /// ```
    pub fn offset(&self, level: usize, index: usize, bin: usize) -> [f64; 2] {
        self.bin_offsets(level, bin).offset(index)
    }

    /// The offsets that the tiles of `level` read in bin `bin`.
    fn bin_offsets(&self, level: usize, bin: usize) -> LevelOffsets<'_> {
        LevelOffsets {
            lut: self,
            level,
            table: &self.tables[level.min(self.tables.len() - 1)][bin],
            moves: None,
            fills: None,
        }
    }

    /// The offsets, and the drop moves or sibling fills, that the tiles
    /// of `level` read at density `fraction` of the level (capacity
    /// `capacity`, importance bin `bin`), found (and decoded) once for a
    /// request's samples rather than once a sample.
    pub(crate) fn request_offsets(
        &self,
        level: u32,
        fraction: f64,
        capacity: f64,
        bin: usize,
    ) -> LevelOffsets<'_> {
        let mut offsets = self.bin_offsets(level as usize, bin);
        let moves = self
            .drop_moves
            .get(level as usize)
            .and_then(|bins| bins.get(bin));
        if let Some(moves) = moves.filter(|_| bin > 0) {
            // whole numbers below 2^53 at the per-tile levels
            let accepted = accepted_count(fraction, capacity) as u64;
            let lower = self.bin_codes(bin - 1, capacity);
            let ring = level >= u32::from(self.ring_from);
            let dropped_from =
                (accepted.saturating_sub(move_key_base(lower, ring))).min(u64::from(u32::MAX));
            offsets.moves = Some((moves, dropped_from as u32, ring));
        }
        let counts = self.fill_counts(level, fraction, capacity, bin);
        offsets.fills = counts.map(|counts| (&self.fills[level as usize][..], counts));
        offsets
    }

    /// Rows of the offset table of tree-indexed level `level`: one a tile,
    /// a quarter of that at the ring-shared levels.
    ///
    /// # Example
    /// ```
    /// let lut = tessera::lut::sphere_lut();
    /// assert_eq!(lut.rows(0), 240);
    /// assert_eq!(lut.rows(lut.ring_from as usize), 60 << (2 * lut.ring_from));
    /// ```
    pub fn rows(&self, level: usize) -> usize {
        match level < self.ring_from as usize {
            true => ROOT_COUNT << (2 * level),
            false => (ROOT_COUNT / 4) << (2 * level),
        }
    }

    /// The offset-table row of structural index `index` at `level`. At a
    /// per-tile level rows are place-major, `place * roots + root`, where
    /// the tree index is `root * 4^level + place`: the tiles a request
    /// visits one after another in code order (one place below every root
    /// in turn) read neighbouring rows (a 600,000-point request, one
    /// thread: 46.0 ms with root-major rows, 43.1 ms with these, in
    /// `scripts/compare-builds.sh`). At the ring-shared levels the tiles at the same
    /// place on the four faces of a ring share one row. Past the per-tile
    /// levels (the class table) the row is the index.
    ///
    /// # Example
    /// ```
    /// let lut = tessera::lut::sphere_lut();
    /// let level = lut.ring_from as usize;
    /// let per_face = 20 << (2 * level);
    /// // face 1 is face 0 turned a quarter about the axis; face 4 is not
    /// assert_eq!(lut.row(level, per_face + 7), lut.row(level, 7));
    /// assert_ne!(lut.row(level, 4 * per_face + 7), lut.row(level, 7));
    /// ```
    pub fn row(&self, level: usize, index: usize) -> usize {
        if level >= self.exact_levels as usize {
            return index;
        }
        // shifts and divisions by constants, as this runs once a sample
        let (root, place) = (index >> (2 * level), index & ((1 << (2 * level)) - 1));
        if level < self.ring_from as usize {
            return place * ROOT_COUNT + root;
        }
        // roots are face-major, `face * 20 + k`; ring `face / 4`
        let ring_root = root / (4 * ROOTS_PER_FACE) * ROOTS_PER_FACE + root % ROOTS_PER_FACE;
        place * (ROOT_COUNT / 4) + ring_root
    }

    /// Which sibling-fill entry a tile of a per-tile level takes at density
    /// `fraction` of its level (capacity `capacity`, importance bin `bin`):
    /// `Some(pair)` when the bin's set has a sibling of higher digit that
    /// the request drops; if `shares_a_hole` says that sibling's ring
    /// twins (the codes equal to its own but for the last two bits) share
    /// its hole, as next to a pole, only if the request drops them too.
    /// `code` is the tile's code: its parent's code
    /// plus its digit times the parent level's capacity.
    ///
    /// # Example
    /// ```
    /// let lut = tessera::lut::sphere_lut();
    /// // level 6, the one with sibling fills; 245,760 parents
    /// assert!(!lut.fills[6].is_empty());
    /// let capacity = 983_040.0;
    /// let fraction = 332_800.0 / capacity;
    /// let bin = lut.bin(fraction, capacity);
    /// // bin 3 keeps codes below 358,682, so the parent of code 345,760
    /// // (345,760 - 245,760 = 100,000) lacks its digit-1 child; its digit-0
    /// // child, code 100,000, fills in
    /// let apart = |_| false;
    /// assert_eq!(lut.fill_pair(100_000, 6, fraction, bin, capacity, apart), Some(0));
    /// // the parent of code 18,624 keeps both children the bin has
    /// assert_eq!(lut.fill_pair(18_624, 6, fraction, bin, capacity, apart), None);
    /// // keeping codes below 345,762 keeps 345,760 and 345,761, twins of
    /// // code 345,762: a fill next to a pole assumed them missing
    /// let fraction = 345_762.0 / capacity;
    /// let bin = lut.bin(fraction, capacity);
    /// assert_eq!(lut.fill_pair(100_002, 6, fraction, bin, capacity, apart), Some(0));
    /// assert_eq!(lut.fill_pair(100_002, 6, fraction, bin, capacity, |_| true), None);
    /// // the levels whose drop moves replace them have none
    /// assert_eq!(lut.fill_pair(390, 2, 1300.0 / 3840.0, 3, 3840.0, apart), None);
    /// ```
    pub fn fill_pair(
        &self,
        code: u128,
        level: u32,
        fraction: f64,
        bin: usize,
        capacity: f64,
        shares_a_hole: impl FnOnce(u64) -> bool,
    ) -> Option<usize> {
        let counts = self.fill_counts(level, fraction, capacity, bin)?;
        counts.pair(code as u64, shares_a_hole)
    }

    /// What [`Self::fill_pair`] needs of a request, computed once for all
    /// its samples; `None` where the level has no fills.
    pub(crate) fn fill_counts(
        &self,
        level: u32,
        fraction: f64,
        capacity: f64,
        bin: usize,
    ) -> Option<FillCounts> {
        if level == 0 || self.fills.get(level as usize).is_none_or(|f| f.is_empty()) {
            return None;
        }
        // whole numbers below 2^53 at the per-tile levels
        Some(FillCounts {
            accepted: accepted_count(fraction, capacity) as u64,
            // the bin's set: codes below `f_b * capacity` (see `bin`)
            in_bin: self.bin_codes(bin, capacity),
            parents: capacity as u64 / 4,
        })
    }

    /// The sibling-fill offset (tile frame, cells) of entry `pair` of the
    /// parent of tree index `parent` at per-tile level `level`, one with
    /// fills (it panics on the others, as an index past a slice would).
    ///
    /// # Example
    /// ```
    /// let lut = tessera::lut::sphere_lut();
    /// let o = lut.fill(6, 0, 0);
    /// assert!((-1.0..=3.0).contains(&o[0]) && (-1.0..=4.0).contains(&o[1]));
    /// ```
    pub fn fill(&self, level: usize, parent: usize, pair: usize) -> [f64; 2] {
        dequantise(self.fills[level][self.row(level - 1, parent) * FILL_PAIRS + pair])
    }

    /// Quantises an offset (cells, tile frame) for storage.
    pub(crate) fn quantise(offset: [f64; 2]) -> [i8; 2] {
        Self::quantise_on(offset, 1)
    }

    /// Quantises an offset on a grid `step` times coarser than the
    /// table's: every stored value a multiple of `step`, which zstd then
    /// stores in fewer bits (the run time reads it as any other).
    pub(crate) fn quantise_on(offset: [f64; 2], step: u8) -> [i8; 2] {
        let step = f64::from(step);
        let (lowest, highest) = (
            (f64::from(i8::MIN) / step).ceil() * step,
            (f64::from(i8::MAX) / step).floor() * step,
        );
        [0, 1].map(|k| {
            let units = (offset[k] - OFFSET_CENTRE[k]) * OFFSET_SCALE / step;
            (units.round() * step).clamp(lowest, highest) as i8
        })
    }

    /// Checks every index the run-time recursion will follow and every
    /// offset's room: what [`SphereLut::from_bytes`] checks of a file,
    /// for a table built or edited in memory.
    ///
    /// # Example
    /// ```
    /// let mut lut = (*tessera::lut::sphere_lut()).clone();
    /// lut.transitions[0][0] = u32::MAX; // an automaton pointing nowhere
    /// let e = lut.validate().unwrap_err().to_string();
    /// assert!(e.contains("missing class"), "{e}");
    /// ```
    pub fn validate(&self) -> Result<(), Error> {
        let bad = |what: &str| Err(Error::Table(format!("sphere table: {what}")));
        let roots = ROOT_COUNT;
        if self.rules.len() != 2 || self.rules.iter().any(|r| r.children.len() != 4) {
            return bad("expected two rules of four children");
        }
        if self.child_rule.len() != 2 || self.child_digit.len() != 2 {
            return bad("child rule/digit tables must have two rows");
        }
        if self
            .child_rule
            .iter()
            .flatten()
            .chain(&self.root_rule)
            .any(|&r| r > 1)
        {
            return bad("child or root rule out of range");
        }
        for digits in &self.child_digit {
            let mut sorted = *digits;
            sorted.sort_unstable();
            if sorted != [0, 1, 2, 3] {
                return bad("child digits must be a permutation of 0..4");
            }
        }
        if self.patch.len() != 20 || self.root_rule.len() != roots || self.root_rank.len() != roots
        {
            return bad("patch or root tables have the wrong size");
        }
        let mut ranks = self.root_rank.clone();
        ranks.sort_unstable();
        if ranks.iter().enumerate().any(|(i, &r)| r as usize != i) {
            return bad("root ranks must be a permutation of 0..240");
        }
        let fractions = &self.bin_fractions;
        if fractions.last() != Some(&1.0)
            || !fractions.windows(2).all(|w| w[0] < w[1])
            || !fractions.iter().all(|&f| f > 0.0)
        {
            return bad("bin fractions must increase from above 0 to exactly 1");
        }
        // 12 tree-indexed levels would be 4 billion rows a bin
        if !(3..=12).contains(&self.exact_levels) || self.ring_from > self.exact_levels {
            return bad("need 3 <= exact_levels <= 12 and ring_from <= exact_levels");
        }
        let entry_parents = roots << (2 * (self.exact_levels as usize - 3));
        let classes = self.transitions.len();
        if self.entry_class.len() != entry_parents
            || self
                .entry_class
                .iter()
                .chain(&self.transitions)
                .flatten()
                .any(|&c| c as usize >= classes)
        {
            return bad("class automaton refers to a missing class");
        }
        if self.tables.len() <= self.exact_levels as usize {
            return bad("need one table per exact level and at least one class table");
        }
        // offsets stay within one cell of the pentomino's 2x3 box
        // (x in -1..=3 and y in -1..=4 cells, stored from `OFFSET_CENTRE`
        // in 1/40 cell; compared as stored, as this scans every entry at
        // start-up)
        let inside = |[x, y]: [i8; 2]| (-80..=80).contains(&x) && (-100..=100).contains(&y);
        for (level, bins) in self.tables.iter().enumerate() {
            let rows = if level < self.exact_levels as usize {
                self.rows(level)
            } else {
                classes
            };
            if bins.len() != self.bins() || bins.iter().any(|table| table.len() != rows) {
                return bad(&format!("offset table {level} has the wrong size"));
            }
            for (bin, table) in bins.iter().enumerate() {
                if let Some(at) = table.iter().position(|&o| !inside(o)) {
                    return bad(&format!(
                        "offset table {level} bin {bin} row {at} lies outside the tile's neighbourhood"
                    ));
                }
            }
        }
        if self.fills.is_empty() || self.fills.len() > self.exact_levels as usize {
            return bad(
                "need a sibling-fill table per level from 0 up to at most the exact levels",
            );
        }
        for (level, fills) in self.fills.iter().enumerate() {
            let parents = if level == 0 { 0 } else { self.rows(level - 1) };
            let moved = level < self.drop_moves.len();
            if fills.len() != parents * FILL_PAIRS && !(moved && fills.is_empty()) {
                return bad(&format!("sibling-fill table {level} has the wrong size"));
            }
            if fills.iter().any(|&o| !inside(o)) {
                return bad(&format!(
                    "sibling-fill table {level} has an offset outside the tile's neighbourhood"
                ));
            }
        }
        self.check_per_bin("drop-move", &self.drop_moves)?;
        for (level, bins) in self.drop_moves.iter().enumerate() {
            let capacity = (ROOT_COUNT << (2 * level)) as f64;
            for (bin, moves) in bins.iter().enumerate() {
                // keys count from the lower bin's count, below this bin's
                let ring = level >= self.ring_from as usize;
                let width = match bin {
                    0 => 0,
                    _ => move_keys(
                        self.bin_codes(bin - 1, capacity),
                        self.bin_codes(bin, capacity),
                        ring,
                    ),
                };
                let wrong = moves.rows() != self.rows(level) && !(bin == 0 && moves.is_empty());
                // a move may take a point two cells past its tile, as far as
                // an `i8` offset reaches
                if wrong || moves.iter().any(|(_, key, _)| u64::from(key) >= width) {
                    return bad(&format!(
                        "drop-move table {level} bin {bin} has the wrong size or a key past its bin"
                    ));
                }
            }
        }
        self.check_per_bin("zonal-warp", &self.zonal_warps)?;
        for (level, warps) in self.zonal_warps.iter().enumerate() {
            // a slope of 1/2 at most keeps latitudes in order with room
            let wild = |w: &ZonalWarp| w.slope_bound().is_nan() || w.slope_bound() > 0.5;
            if let Some(bin) = warps.iter().position(wild) {
                return bad(&format!(
                    "the zonal warp of level {level} bin {bin} is not finite or moves points past each other"
                ));
            }
        }
        Ok(())
    }

    /// Checks that `tables` (one per level from 0, a `kind` table per
    /// bin) stop at the tree-indexed levels and hold every bin.
    fn check_per_bin<T>(&self, kind: &str, tables: &[Vec<T>]) -> Result<(), Error> {
        let bad = |what: String| Err(Error::Table(format!("sphere table: {what}")));
        if tables.len() > self.exact_levels as usize {
            return bad(format!("{kind} tables past the tree-indexed levels"));
        }
        match tables.iter().position(|bins| bins.len() != self.bins()) {
            Some(level) => bad(format!("{kind} table {level} has the wrong number of bins")),
            None => Ok(()),
        }
    }

    /// The zonal warp every point the tiles of `level` place in bin `bin`
    /// moves by: the identity where the table has none.
    ///
    /// # Example
    /// ```
    /// let lut = tessera::lut::sphere_lut();
    /// assert!(lut.zonal_warp(lut.exact_levels as usize, 0).is_identity());
    /// ```
    pub fn zonal_warp(&self, level: usize, bin: usize) -> ZonalWarp {
        (self.zonal_warps.get(level))
            .and_then(|warps| warps.get(bin))
            .copied()
            .unwrap_or_default()
    }
}

/// Codes below `fraction * capacity`: the set of a bin of that fraction.
pub(crate) fn codes_below(fraction: f64, capacity: f64) -> u64 {
    (fraction * capacity).ceil() as u64
}

/// The code a bin's drop-move keys count from: the lower bin's count
/// `lower`, rounded down to a whole orbit where a ring's faces share rows
/// (see [`DropMoves`]).
pub(crate) fn move_key_base(lower: u64, ring: bool) -> u64 {
    match ring {
        true => lower & !3,
        false => lower,
    }
}

/// How many drop-move keys a bin of `upper` codes above one of `lower`
/// spans: codes, or on the ring-shared levels whole orbits.
pub(crate) fn move_keys(lower: u64, upper: u64, ring: bool) -> u64 {
    let codes = upper - move_key_base(lower, ring);
    match ring {
        true => codes.div_ceil(4),
        false => codes,
    }
}

/// How many tiles of a level of `capacity` the engine keeps at density
/// `fraction`: codes `c + 1/2 < fraction * capacity`.
fn accepted_count(fraction: f64, capacity: f64) -> f64 {
    (fraction * capacity - 0.5).ceil()
}

/// A stored offset in cells, tile frame.
pub(crate) fn dequantise(stored: [i8; 2]) -> [f64; 2] {
    [0, 1].map(|k| stored[k] as f64 / OFFSET_SCALE + OFFSET_CENTRE[k])
}

/// The density fractions of `count` importance bins: equally spaced in
/// `log4 f` from 1/4 to 1, with the grid point nearest each of
/// [`COMMON_FRACTIONS`] moved onto it (`count >= 6`, so that each has an
/// interior grid point of its own).
///
/// # Example
/// ```
/// let f = tessera::lut::bin_fractions(12);
/// assert_eq!(f.len(), 12);
/// assert_eq!((f[0], f[11]), (0.25, 1.0));
/// assert!(f.contains(&0.8) && f.windows(2).all(|w| w[0] < w[1]));
/// ```
pub fn bin_fractions(count: usize) -> Vec<f64> {
    let count = count.max(6);
    let mut fractions: Vec<f64> = (0..count)
        .map(|b| 4f64.powf(b as f64 / (count - 1) as f64 - 1.0))
        .collect();
    let mut moved = vec![false; count];
    for common in COMMON_FRACTIONS {
        let distance = |b: usize| (fractions[b] / common).ln().abs();
        let nearest = (1..count - 1)
            .filter(|&b| !moved[b])
            .min_by(|&a, &b| distance(a).total_cmp(&distance(b)))
            .expect("count >= 6 leaves an interior bin for each common fraction");
        fractions[nearest] = common;
        moved[nearest] = true;
    }
    fractions.sort_by(f64::total_cmp);
    fractions
}

/// The sizes of the zstd frames a sphere table file is made of, in order
/// (see [`SphereLut::to_bytes`] for what each holds); a tail that is not
/// a whole frame counts as one.
///
/// # Example
/// ```
/// let mut bytes = zstd::bulk::compress(b"header", 1).unwrap();
/// let first = bytes.len();
/// bytes.extend(zstd::bulk::compress(b"offsets", 1).unwrap());
/// let sizes = tessera::lut::frame_sizes(&bytes);
/// assert_eq!(sizes, [first, bytes.len() - first]);
/// ```
pub fn frame_sizes(bytes: &[u8]) -> Vec<usize> {
    Frames(bytes).map(<[u8]>::len).collect()
}

/// The zstd frames of a sphere table file, in order; what does not parse
/// as a frame comes as one last piece, for [`decompress`] to refuse.
struct Frames<'a>(&'a [u8]);

impl<'a> Iterator for Frames<'a> {
    type Item = &'a [u8];
    fn next(&mut self) -> Option<&'a [u8]> {
        if self.0.is_empty() {
            return None;
        }
        let size = zstd::zstd_safe::find_frame_compressed_size(self.0).unwrap_or(self.0.len());
        let (frame, rest) = self.0.split_at(size.min(self.0.len()));
        self.0 = rest;
        Some(frame)
    }
}

/// The bytes inside one zstd frame of a sphere table file. A file that is not a
/// zstd frame is an old uncompressed table, whose first byte is its format
/// version: it is returned as is, for the version check to name.
fn decompress(bytes: &[u8]) -> Result<Vec<u8>, Error> {
    use std::io::Read;
    const ZSTD_MAGIC: [u8; 4] = [0x28, 0xb5, 0x2f, 0xfd];
    if !bytes.starts_with(&ZSTD_MAGIC) {
        return Ok(bytes.to_vec());
    }
    let corrupt =
        |e: std::io::Error| Error::Table(format!("sphere table does not decompress: {e}"));
    let too_large = || {
        Error::Table(format!(
            "sphere table decodes to more than {SPHERE_LUT_MAX_DECODED} bytes"
        ))
    };
    // in one call where the frame states its size, as `to_bytes` writes
    // them: a bin of level 5 stored as differences decodes up to 12
    // frames, which the streaming decoder's buffers made slower
    if let Ok(Some(size)) = zstd::zstd_safe::get_frame_content_size(bytes) {
        if size > SPHERE_LUT_MAX_DECODED {
            return Err(too_large());
        }
        return zstd::bulk::decompress(bytes, size as usize).map_err(corrupt);
    }
    let mut decoded = Vec::new();
    zstd::stream::read::Decoder::new(bytes)
        .map_err(corrupt)?
        .take(SPHERE_LUT_MAX_DECODED + 1)
        .read_to_end(&mut decoded)
        .map_err(corrupt)?;
    if decoded.len() as u64 > SPHERE_LUT_MAX_DECODED {
        return Err(too_large());
    }
    Ok(decoded)
}

static SPHERE_BYTES: &[u8] = include_bytes!("../luts/sphere.lut");

/// The sphere table shipped in `luts/sphere.lut`, decoded once.
///
/// # Example
/// ```
/// let lut = tessera::lut::sphere_lut();
/// assert_eq!(lut.rules.len(), 2);
/// ```
pub fn sphere_lut() -> Arc<SphereLut> {
    static LUT: OnceLock<Arc<SphereLut>> = OnceLock::new();
    LUT.get_or_init(|| {
        // its offset tables decoded as requests reach them, unchecked:
        // `the_embedded_table_is_valid` in tests/lut.rs checks them all
        Arc::new(
            SphereLut::read(SPHERE_BYTES)
                .expect("the embedded luts/sphere.lut is checked by the test suite"),
        )
    })
    .clone()
}

/// Format version written into and required from planar polyomino tables.
pub const PLANE_LUT_VERSION: u32 = 1;

/// Planar offsets are stored as `i16` multiples of `1 / PLANE_OFFSET_SCALE`
/// cells (resolution 1e-3 cells, range +-32 cells: sparse importance bins of
/// the 81-rep G-hexomino move points several cells).
pub const PLANE_OFFSET_SCALE: f64 = 1024.0;

/// Everything a planar polyomino tile system needs at run time: the rep-tile
/// rules, the root patch covering the unit square, codes, the class
/// automaton and the offsets.
///
/// # Example
/// ```
/// use tessera::lut::{plane_lut, PlaneSystem};
/// let lut = plane_lut(PlaneSystem::Ppentomino);
/// assert_eq!(lut.roots.len(), 20);
/// assert_eq!(lut.rules[0].children.len(), 4);
/// ```
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct PlaneLut {
    /// Format version, [`PLANE_LUT_VERSION`].
    pub version: u32,
    /// Seed the optimiser ran with.
    pub seed: u64,
    /// The rep-tile.
    pub shape: crate::polyomino::Shape,
    /// Its production rules (all with the same scale and child count `A`).
    pub rules: Vec<Rule>,
    /// `child_rule[rule][child]`: the rule a child subdivides with.
    pub child_rule: Vec<Vec<u8>>,
    /// `child_digit[rule][child]`: the child's rank among its siblings.
    pub child_digit: Vec<Vec<u8>>,
    /// Side of the root patch in cells: the roots cover `[0, side)^2`.
    pub side: Lattice,
    /// The root tiles.
    pub roots: Vec<Placement>,
    /// Rule of each root.
    pub root_rule: Vec<u8>,
    /// Code (rank) of each root, a permutation of `0..roots.len()`.
    pub root_rank: Vec<u32>,
    /// Structural index (automaton state) of each root.
    pub root_class: Vec<u32>,
    /// The automaton, row-major: `transitions[class * A + child]`.
    pub transitions: Vec<u32>,
    /// Importance bins per class; bin `b` was optimised for the density
    /// fraction `A^(b / (bins - 1) - 1)` of a level's capacity (equal
    /// ratios between bins: a fraction served by the bin above it misses
    /// at most the same share of points everywhere).
    pub bins: u16,
    /// Offsets in the tile's frame (cells times [`PLANE_OFFSET_SCALE`]),
    /// indexed `class * bins + bin`.
    pub offsets: Vec<[i16; 2]>,
}

impl PlaneLut {
    /// Children per tile (`A`).
    ///
    /// # Example
    /// ```
    /// use tessera::lut::{plane_lut, PlaneSystem};
    /// assert_eq!(plane_lut(PlaneSystem::Ghexomino).arity(), 81);
    /// ```
    pub fn arity(&self) -> usize {
        self.rules.first().map_or(0, |r| r.children.len())
    }

    /// Number of structural indices (automaton states).
    ///
    /// # Example
    /// ```
    /// use tessera::lut::{plane_lut, PlaneSystem};
    /// assert!(plane_lut(PlaneSystem::Ppentomino).classes() > 1);
    /// ```
    pub fn classes(&self) -> usize {
        self.transitions.len() / self.arity().max(1)
    }

    /// The density fraction (of a level's capacity) bin `bin` serves.
    ///
    /// # Example
    /// ```
    /// use tessera::lut::{plane_lut, PlaneSystem};
    /// let lut = plane_lut(PlaneSystem::Ppentomino);
    /// assert_eq!(lut.bin_fraction(lut.bins as usize - 1), 1.0);
    /// assert_eq!(lut.bin_fraction(0), 0.25);
    /// ```
    pub fn bin_fraction(&self, bin: usize) -> f64 {
        let a = self.arity() as f64;
        a.powf(bin as f64 / (self.bins.max(2) - 1) as f64 - 1.0)
    }

    /// The offset (tile frame, cells) of class `class` in bin `bin`.
    ///
    /// # Example
    /// ```
    /// use tessera::lut::{plane_lut, PlaneSystem};
    /// let lut = plane_lut(PlaneSystem::Ppentomino);
    /// let o = lut.offset(0, lut.bins as usize - 1);
    /// assert!(lut.shape.contains(o));
    /// ```
    pub fn offset(&self, class: usize, bin: usize) -> [f64; 2] {
        let [x, y] = self.offsets[class * self.bins as usize + bin];
        [x as f64 / PLANE_OFFSET_SCALE, y as f64 / PLANE_OFFSET_SCALE]
    }

    /// Quantises an offset (cells) for storage.
    pub(crate) fn quantise(offset: [f64; 2]) -> [i16; 2] {
        offset.map(|v| {
            (v * PLANE_OFFSET_SCALE)
                .round()
                .clamp(i16::MIN as f64, i16::MAX as f64) as i16
        })
    }

    /// Decodes a table, checking its version and internal consistency.
    ///
    /// # Example
    /// ```
    /// assert!(tessera::lut::PlaneLut::from_bytes(&[1, 2, 3]).is_err());
    /// ```
    pub fn from_bytes(bytes: &[u8]) -> Result<Self, Error> {
        let version = bytes.first().copied().unwrap_or(0) as u32;
        if version != PLANE_LUT_VERSION {
            return Err(Error::Table(format!(
                "planar table has format version {version}, this build reads version {PLANE_LUT_VERSION}"
            )));
        }
        let lut: PlaneLut = postcard::from_bytes(bytes)
            .map_err(|e| Error::Table(format!("planar table does not decode: {e}")))?;
        lut.validate()?;
        Ok(lut)
    }

    /// Encodes the table.
    ///
    /// # Example
    /// ```
    /// use tessera::lut::{plane_lut, PlaneLut, PlaneSystem};
    /// let lut = plane_lut(PlaneSystem::Ppentomino);
    /// assert_eq!(PlaneLut::from_bytes(&lut.to_bytes()).unwrap(), *lut);
    /// ```
    pub fn to_bytes(&self) -> Vec<u8> {
        postcard::to_allocvec(self).expect("serialising to memory cannot fail")
    }

    /// Checks every index the run-time recursion will follow.
    fn validate(&self) -> Result<(), Error> {
        let bad = |what: &str| Err(Error::Table(format!("planar table: {what}")));
        let a = self.arity();
        let cells = self.shape.cells().len();
        if !(2..=256).contains(&a) || !(1..=MAX_CELLS).contains(&cells) {
            return bad("the shape needs 1..=8 cells and 2..=256 children per rule");
        }
        let scale = self.rules[0].scale;
        if scale < 2 || (scale * scale) as usize != a {
            return bad("a rule of scale s must have s^2 children");
        }
        if self
            .rules
            .iter()
            .any(|r| r.scale != scale || r.children.len() != a || !r.tiles_parent(&self.shape))
        {
            return bad("every rule must tile its enlarged parent exactly");
        }
        let rules = self.rules.len();
        if self.child_rule.len() != rules
            || self.child_digit.len() != rules
            || self
                .child_rule
                .iter()
                .any(|r| r.len() != a || r.iter().any(|&x| x as usize >= rules))
        {
            return bad("child rule table has the wrong size or names a missing rule");
        }
        for digits in &self.child_digit {
            let mut sorted = digits.clone();
            sorted.sort_unstable();
            if sorted.iter().enumerate().any(|(i, &d)| d as usize != i) {
                return bad("child digits must be a permutation of 0..A");
            }
        }
        let roots = self.roots.len();
        if self.side <= 0
            || roots == 0
            || self.root_rule.len() != roots
            || self.root_rank.len() != roots
            || self.root_class.len() != roots
            || self.root_rule.iter().any(|&r| r as usize >= rules)
        {
            return bad("root tables have the wrong size");
        }
        let mut covered: Vec<(Lattice, Lattice)> = self
            .roots
            .iter()
            .flat_map(|p| p.cells(&self.shape).collect::<Vec<_>>())
            .collect();
        covered.sort_unstable();
        let square: Vec<(Lattice, Lattice)> = (0..self.side)
            .flat_map(|x| (0..self.side).map(move |y| (x, y)))
            .collect();
        if covered != square {
            return bad("the roots must cover the square patch exactly once");
        }
        let mut ranks = self.root_rank.clone();
        ranks.sort_unstable();
        if ranks.iter().enumerate().any(|(i, &r)| r as usize != i) {
            return bad("root ranks must be a permutation of 0..roots");
        }
        let classes = self.classes();
        if self.transitions.len() != classes * a
            || classes == 0
            || self
                .transitions
                .iter()
                .chain(&self.root_class)
                .any(|&c| c as usize >= classes)
        {
            return bad("class automaton refers to a missing class");
        }
        if self.bins < 2 || self.offsets.len() != classes * self.bins as usize {
            return bad("offset table has the wrong size");
        }
        Ok(())
    }
}

/// The planar polyomino systems shipped in `luts/`.
///
/// # Example
/// ```
/// use tessera::lut::PlaneSystem;
/// assert_eq!(PlaneSystem::Ghexomino.name(), "ghexomino");
/// ```
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum PlaneSystem {
    /// G-hexomino, 81-rep: 216 roots on a 36x36 patch, scale 9 per level.
    Ghexomino,
    /// P-pentomino, 4-rep: 20 roots on a 10x10 patch, scale 2 per level.
    Ppentomino,
}

impl PlaneSystem {
    /// The file stem in `luts/`.
    ///
    /// # Example
    /// ```
    /// assert_eq!(tessera::lut::PlaneSystem::Ppentomino.name(), "ppentomino");
    /// ```
    pub fn name(self) -> &'static str {
        match self {
            PlaneSystem::Ghexomino => "ghexomino",
            PlaneSystem::Ppentomino => "ppentomino",
        }
    }
}

static GHEXOMINO_BYTES: &[u8] = include_bytes!("../luts/ghexomino.lut");
static PPENTOMINO_BYTES: &[u8] = include_bytes!("../luts/ppentomino.lut");

/// The planar table shipped in `luts/<system>.lut`, decoded once.
///
/// # Example
/// ```
/// use tessera::lut::{plane_lut, PlaneSystem};
/// assert_eq!(plane_lut(PlaneSystem::Ghexomino).side, 36);
/// ```
pub fn plane_lut(system: PlaneSystem) -> Arc<PlaneLut> {
    static LUTS: [OnceLock<Arc<PlaneLut>>; 2] = [OnceLock::new(), OnceLock::new()];
    let (slot, bytes) = match system {
        PlaneSystem::Ghexomino => (&LUTS[0], GHEXOMINO_BYTES),
        PlaneSystem::Ppentomino => (&LUTS[1], PPENTOMINO_BYTES),
    };
    slot.get_or_init(|| {
        Arc::new(
            PlaneLut::from_bytes(bytes)
                .expect("the embedded planar tables are checked by the test suite"),
        )
    })
    .clone()
}

/// Format version written into and required from Penrose tables.
pub const PENROSE_LUT_VERSION: u32 = 1;

/// Largest offset a Penrose table may hold, in edges of the tile's level:
/// the optimiser's offsets stay well inside one edge; anything beyond this
/// is a corrupt file.
pub const PENROSE_MAX_OFFSET: f64 = 4.0;

/// The Penrose system's corrective offsets: one per (structural index,
/// importance index), in the point tile's frame, in edges of its level
/// times [`PLANE_OFFSET_SCALE`].
///
/// # Example
/// ```
/// let lut = tessera::lut::penrose_lut();
/// assert_eq!(lut.classes, 21);
/// assert!(lut.bins >= 21);
/// ```
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct PenroseLut {
    /// Format version, [`PENROSE_LUT_VERSION`].
    pub version: u32,
    /// Seed the optimiser ran with.
    pub seed: u64,
    /// Structural indices: values of the code's six most significant
    /// Fibonacci digits, `F(8) = 21`.
    pub classes: u16,
    /// Importance bins: bin `b` covers `[b, b + 1) / bins` of the
    /// fractional part of `log_phi^2` of the density.
    pub bins: u16,
    /// Offsets, indexed `class * bins + bin`.
    pub offsets: Vec<[i16; 2]>,
}

impl PenroseLut {
    /// A table of zero offsets (the optimiser's starting point).
    ///
    /// # Example
    /// ```
    /// let lut = tessera::lut::PenroseLut::zero(21);
    /// assert_eq!(lut.offset(20, 20), [0.0, 0.0]);
    /// ```
    pub fn zero(bins: u16) -> Self {
        PenroseLut {
            version: PENROSE_LUT_VERSION,
            seed: 0,
            classes: 21,
            bins,
            offsets: vec![[0, 0]; 21 * bins as usize],
        }
    }

    /// The offset (point tile frame, edges) of class `class` in bin `bin`.
    ///
    /// # Example
    /// ```
    /// let lut = tessera::lut::penrose_lut();
    /// let [x, y] = lut.offset(0, 0);
    /// assert!(x.hypot(y) <= tessera::lut::PENROSE_MAX_OFFSET);
    /// ```
    pub fn offset(&self, class: usize, bin: usize) -> [f64; 2] {
        let [x, y] = self.offsets[class * self.bins as usize + bin];
        [x as f64 / PLANE_OFFSET_SCALE, y as f64 / PLANE_OFFSET_SCALE]
    }

    /// Stores an offset (edges) for class `class` in bin `bin`, quantised.
    ///
    /// # Example
    /// ```
    /// let mut lut = tessera::lut::PenroseLut::zero(21);
    /// lut.set_offset(3, 4, [0.25, -0.5]);
    /// assert_eq!(lut.offset(3, 4), [0.25, -0.5]);
    /// ```
    pub fn set_offset(&mut self, class: usize, bin: usize, offset: [f64; 2]) {
        self.offsets[class * self.bins as usize + bin] = PlaneLut::quantise(offset);
    }

    /// Decodes a table, checking its version, sizes and offsets.
    ///
    /// # Example
    /// ```
    /// use tessera::lut::PenroseLut;
    /// assert!(PenroseLut::from_bytes(&[1, 2, 3]).is_err());
    /// let bytes = PenroseLut::zero(21).to_bytes();
    /// assert!(PenroseLut::from_bytes(&bytes).is_ok());
    /// ```
    pub fn from_bytes(bytes: &[u8]) -> Result<Self, Error> {
        let version = bytes.first().copied().unwrap_or(0) as u32;
        if version != PENROSE_LUT_VERSION {
            return Err(Error::Table(format!(
                "Penrose table has format version {version}, this build reads version {PENROSE_LUT_VERSION}"
            )));
        }
        let lut: PenroseLut = postcard::from_bytes(bytes)
            .map_err(|e| Error::Table(format!("Penrose table does not decode: {e}")))?;
        lut.validate()?;
        Ok(lut)
    }

    /// Encodes the table.
    ///
    /// # Example
    /// ```
    /// use tessera::lut::{penrose_lut, PenroseLut};
    /// let lut = penrose_lut();
    /// assert_eq!(PenroseLut::from_bytes(&lut.to_bytes()).unwrap(), *lut);
    /// ```
    pub fn to_bytes(&self) -> Vec<u8> {
        postcard::to_allocvec(self).expect("serialising to memory cannot fail")
    }

    fn validate(&self) -> Result<(), Error> {
        let bad = |what: String| Err(Error::Table(format!("Penrose table: {what}")));
        if self.classes != 21 {
            return bad(format!(
                "{} structural indices; the six-digit Fibonacci codes give 21",
                self.classes
            ));
        }
        if self.bins < 2 || self.offsets.len() != 21 * self.bins as usize {
            return bad(format!(
                "{} offsets for {} bins; expected 21 per bin, at least 2 bins",
                self.offsets.len(),
                self.bins
            ));
        }
        let limit = PENROSE_MAX_OFFSET * PLANE_OFFSET_SCALE;
        if let Some(at) = self
            .offsets
            .iter()
            .position(|o| (o[0] as f64).hypot(o[1] as f64) > limit)
        {
            return bad(format!(
                "offset {at} reaches beyond {PENROSE_MAX_OFFSET} edges"
            ));
        }
        Ok(())
    }
}

static PENROSE_BYTES: &[u8] = include_bytes!("../luts/penrose.lut");

/// The Penrose table shipped in `luts/penrose.lut`, decoded once.
///
/// # Example
/// ```
/// assert_eq!(tessera::lut::penrose_lut().version, tessera::lut::PENROSE_LUT_VERSION);
/// ```
pub fn penrose_lut() -> Arc<PenroseLut> {
    static LUT: OnceLock<Arc<PenroseLut>> = OnceLock::new();
    LUT.get_or_init(|| {
        Arc::new(
            PenroseLut::from_bytes(PENROSE_BYTES)
                .expect("the embedded luts/penrose.lut is checked by the test suite"),
        )
    })
    .clone()
}

/// The tile systems a [`Table`] can be for.
///
/// # Example
/// ```
/// use tessera::lut::{PlaneSystem, TableSystem};
/// assert_eq!(TableSystem::Plane(PlaneSystem::Ghexomino).name(), "ghexomino");
/// ```
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum TableSystem {
    /// [`SphereLut`].
    Sphere,
    /// [`PlaneLut`] of a polyomino.
    Plane(PlaneSystem),
    /// [`PenroseLut`].
    Penrose,
}

impl TableSystem {
    /// The system's name (its file stem in `luts/`).
    ///
    /// # Example
    /// ```
    /// assert_eq!(tessera::lut::TableSystem::Penrose.name(), "penrose");
    /// ```
    pub fn name(self) -> &'static str {
        match self {
            TableSystem::Sphere => "sphere",
            TableSystem::Plane(system) => system.name(),
            TableSystem::Penrose => "penrose",
        }
    }
}

/// A table read from a file at run time, to sample with instead of the one
/// embedded at build time (`--table FILE`): `tessera lut build` writes
/// them, so a rebuilt table is used without recompiling.
///
/// # Example
/// ```
/// use tessera::lut::{sphere_lut, Table, TableSystem};
/// let path = std::env::temp_dir().join(format!("tessera-doc-table-{}.lut", std::process::id()));
/// std::fs::write(&path, sphere_lut().to_bytes()).unwrap();
/// let table = Table::open(&path, TableSystem::Sphere).unwrap();
/// assert_eq!(table, Table::Sphere(sphere_lut()));
/// let e = Table::open(&path, TableSystem::Penrose).unwrap_err().to_string();
/// assert!(e.contains("not a penrose table"), "{e}");
/// std::fs::remove_file(&path).unwrap();
/// ```
#[derive(Clone, Debug, PartialEq)]
pub enum Table {
    /// A sphere table.
    Sphere(Arc<SphereLut>),
    /// A polyomino table.
    Plane(Arc<PlaneLut>),
    /// A Penrose table.
    Penrose(Arc<PenroseLut>),
}

impl Table {
    /// Reads the table of `system` from `path`, refusing (naming the file)
    /// one that does not decode, or a polyomino table of another rep-tile.
    ///
    /// # Errors
    /// [`Error::Io`] when the file cannot be read, [`Error::File`] when it
    /// is not a table of `system`.
    ///
    /// # Example
    /// ```
    /// use tessera::lut::{Table, TableSystem};
    /// let e = Table::open("no-such.lut".as_ref(), TableSystem::Sphere).unwrap_err();
    /// assert!(e.to_string().contains("no-such.lut"));
    /// ```
    pub fn open(path: &std::path::Path, system: TableSystem) -> Result<Table, Error> {
        let bytes = std::fs::read(path).map_err(|source| Error::Io {
            path: path.into(),
            source,
        })?;
        let refuse = |why: String| Error::File {
            path: path.into(),
            reason: format!("not a {} table: {why}", system.name()),
        };
        let decoded = |e: Error| match e {
            Error::Table(why) => refuse(why),
            e => refuse(e.to_string()),
        };
        Ok(match system {
            TableSystem::Sphere => {
                Table::Sphere(Arc::new(SphereLut::from_bytes(&bytes).map_err(decoded)?))
            }
            TableSystem::Penrose => {
                Table::Penrose(Arc::new(PenroseLut::from_bytes(&bytes).map_err(decoded)?))
            }
            TableSystem::Plane(plane) => {
                let lut = PlaneLut::from_bytes(&bytes).map_err(decoded)?;
                // the table carries its own rep-tile: it must be this one
                let shipped = plane_lut(plane);
                if lut.shape != shipped.shape || lut.arity() != shipped.arity() {
                    return Err(refuse(format!(
                        "its rep-tile is another ({}-rep)",
                        lut.arity()
                    )));
                }
                Table::Plane(Arc::new(lut))
            }
        })
    }
}

//! Where the points beside a request's holes go ([`DropMoves`]).
//!
//! Between two importance bins a request keeps the codes below its count
//! of the upper bin's relaxed set, and every code it drops leaves a hole
//! about one spacing wide. The builder drops the bin's codes one at a time
//! from the top, as ever smaller requests drop them, and each drop moves
//! the kept points beside the hole (Lloyd among the others held fixed):
//! a move records the point's shift from its bin offset, keyed by the
//! dropped code. A
//! request then reads, for each point, the move of the lowest code it
//! drops, so its set is the builder's state after dropping exactly its
//! codes: the holes close as a relaxed set of its own count would have
//! them closed, where moving the dropped point's siblings alone (the
//! sibling fills) left holes of 3.6-4.6 / sqrt(N).

use super::{decompress, Error, SPHERE_LUT_ZSTD_LEVEL};
use serde::{Deserialize, Serialize};
use std::sync::{Arc, OnceLock};

/// Most moves one row of one bin may hold (its count is a byte).
pub const MOST_MOVES_A_ROW: usize = u8::MAX as usize;

/// One level's moves in one importance bin, per offset row: each a key,
/// the dropped code less the lower bin's count (`codes below the key's
/// code` kept, from it up dropped), the shift the row's point then takes
/// from the bin's offset (in the offset tables' units, added wrapping as
/// `i8`s do), and where rows are shared by a ring's
/// four faces, which face of the ring (turning from the point's) the
/// dropped code lies on; keys increase along a row. Kept in its zstd frame
/// until first read, as [`super::Offsets`] are.
///
/// At the ring-shared levels a move is keyed by the dropped ring orbit
/// (codes equal but for the last two bits, one on each face), counted
/// from the orbit of the lower bin's count: a request that splits the
/// orbit drops its twin on some faces only, and [`DropMoves::shift`]
/// reads the move where the twin beside the point is dropped.
///
/// # Example
/// ```
/// use tessera::lut::DropMoves;
/// let moves = DropMoves::from_rows(vec![vec![(3, [1, 2], 0), (9, [4, 5], 0)], vec![]]);
/// // a request keeping the keys below 2 (so dropping 3 and 9) reads the move of key 3
/// assert_eq!(moves.shift(0, 2, None), Some([1, 2]));
/// assert_eq!(moves.shift(0, 4, None), Some([4, 5]));
/// assert_eq!(moves.shift(0, 10, None), None);
/// assert_eq!(moves.shift(1, 0, None), None);
/// // shared by a ring: key 9 is the orbit of codes 36..40; a request
/// // keeping the codes below 38 drops the twins that are members 2 and 3
/// // (faces 1 and 3 of the ring, the point's own face here)
/// assert_eq!(moves.shift(0, 38, Some(2)), Some([4, 5]));
/// assert_eq!(moves.shift(0, 38, Some(1)), None);
/// ```
pub struct DropMoves {
    decoded: OnceLock<MoveRows>,
    /// The zstd frame of the raw moves, until decoded.
    frame: Option<Arc<[u8]>>,
}

/// Decoded moves: row `r`'s are `keys[starts[r]..starts[r + 1]]`.
#[derive(Clone, Debug, Default, PartialEq)]
struct MoveRows {
    starts: Vec<u32>,
    keys: Vec<u16>,
    /// Each move's shift from its row's bin offset.
    shifts: Vec<[i8; 2]>,
    /// The dropped code's face in the ring less the point's, mod 4.
    turns: Vec<u8>,
}

/// A ring orbit's member on each face of its ring (`face % 4`): the
/// roots' ranks put opposite twins first (`optimize::sphere`), and the
/// member is a code's last two bits. Its own inverse.
const MEMBER_OF_FACE: [u8; 4] = [0, 2, 1, 3];

impl DropMoves {
    /// Moves from each row's list of `(key, shift, turn)`, keys
    /// increasing; `turn` is the dropped code's face in its ring less the
    /// point's, mod 4 (0 where rows are per tile). A row holds at most
    /// [`MOST_MOVES_A_ROW`]: the builder keeps a row's highest keys, which
    /// the most requests read.
    pub fn from_rows(rows: Vec<Vec<(u16, [i8; 2], u8)>>) -> Self {
        let mut decoded = MoveRows {
            starts: vec![0],
            ..MoveRows::default()
        };
        for row in rows {
            let kept = &row[row.len().saturating_sub(MOST_MOVES_A_ROW)..];
            decoded.keys.extend(kept.iter().map(|m| m.0));
            decoded.shifts.extend(kept.iter().map(|m| m.1));
            decoded.turns.extend(kept.iter().map(|m| m.2 & 3));
            decoded.starts.push(decoded.keys.len() as u32);
        }
        DropMoves {
            decoded: OnceLock::from(decoded),
            frame: None,
        }
    }

    /// Rows the moves are kept for.
    pub fn rows(&self) -> usize {
        self.get().starts.len().saturating_sub(1)
    }

    /// Moves in all.
    pub fn len(&self) -> usize {
        self.get().keys.len()
    }

    /// Whether there are none.
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// The shift of row `row` from its bin offset for a request that drops
    /// the keys from `dropped_from` up: the move of its lowest such key,
    /// `None` if the request drops none of the row's. Where rows are shared by a ring,
    /// `member` is the point's code's last two bits, a key is a ring orbit
    /// (its codes `4 * key .. 4 * key + 4`, counted from the lower bin's
    /// count rounded down to a whole orbit, which keeps level 6's bins
    /// within 16 bits), `dropped_from` counts codes from there, and a move
    /// counts where the request drops the orbit's twin beside the point.
    #[inline]
    pub fn shift(&self, row: usize, dropped_from: u32, member: Option<u8>) -> Option<[i8; 2]> {
        let moves = self.get();
        let (start, end) = (moves.starts[row] as usize, moves.starts[row + 1] as usize);
        // a few moves a row: a scan beats a binary search
        let found = match member {
            None => (start..end).find(|&k| u32::from(moves.keys[k]) >= dropped_from),
            Some(member) => {
                // the twin's code is the orbit's first plus its member
                let face = MEMBER_OF_FACE[(member & 3) as usize];
                let twin = |k: usize| MEMBER_OF_FACE[((face + moves.turns[k]) & 3) as usize];
                (start..end)
                    .find(|&k| 4 * u32::from(moves.keys[k]) + u32::from(twin(k)) >= dropped_from)
            }
        };
        found.map(|k| moves.shifts[k])
    }

    /// Every move, row by row: `(row, key, shift)`.
    pub fn iter(&self) -> impl Iterator<Item = (usize, u16, [i8; 2])> + '_ {
        let moves = self.get();
        (moves.starts.windows(2).enumerate()).flat_map(move |(row, w)| {
            (w[0] as usize..w[1] as usize).map(move |k| (row, moves.keys[k], moves.shifts[k]))
        })
    }

    /// Moves still in their zstd frame, decoded when first read.
    pub(super) fn packed(frame: &[u8]) -> Self {
        DropMoves {
            decoded: OnceLock::new(),
            frame: Some(frame.into()),
        }
    }

    /// Decodes the frame now (a file from outside is checked in full).
    pub(super) fn unpack(&mut self) -> Result<(), Error> {
        if let Some(frame) = self.frame.take() {
            self.decoded = OnceLock::from(MoveRows::from_raw(&decompress(&frame)?)?);
        }
        Ok(())
    }

    /// The moves' zstd frame.
    pub(super) fn compress(&self) -> Vec<u8> {
        zstd::bulk::compress(&self.get().to_raw(), SPHERE_LUT_ZSTD_LEVEL)
            .expect("compressing in memory cannot fail")
    }

    fn get(&self) -> &MoveRows {
        self.decoded.get_or_init(|| {
            let raw = decompress(self.frame.as_deref().unwrap_or_default());
            raw.and_then(|raw| MoveRows::from_raw(&raw))
                .expect("the embedded luts/sphere.lut is checked by the test suite")
        })
    }
}

impl MoveRows {
    /// The raw layout: the row count (`u32`, little-endian), a count a
    /// row (`u8`), the keys (`u16`: the high bytes of all, then the low
    /// bytes, which zstd packs 3.5 % smaller than the keys' own bytes in
    /// turn on levels 0-6 together), the shifts (`i8` pairs: 3.3 % smaller
    /// than the offsets the points take, format 11's), then the turns
    /// (`u8`).
    fn to_raw(&self) -> Vec<u8> {
        let rows = self.starts.len().saturating_sub(1);
        let mut raw = (rows as u32).to_le_bytes().to_vec();
        raw.extend(self.starts.windows(2).map(|w| (w[1] - w[0]) as u8));
        raw.extend(self.keys.iter().map(|k| (k >> 8) as u8));
        raw.extend(self.keys.iter().map(|&k| k as u8));
        raw.extend(self.shifts.iter().flat_map(|o| o.map(|v| v as u8)));
        raw.extend(&self.turns);
        raw
    }

    fn from_raw(raw: &[u8]) -> Result<Self, Error> {
        let bad =
            || Error::Table("sphere table: a drop-move table is cut short or too long".into());
        let (rows, rest) = raw.split_first_chunk::<4>().ok_or_else(bad)?;
        let rows = u32::from_le_bytes(*rows) as usize;
        let counts = rest.get(..rows).ok_or_else(bad)?;
        let mut starts = Vec::with_capacity(rows + 1);
        starts.push(0u32);
        for &count in counts {
            starts.push(starts[starts.len() - 1] + u32::from(count));
        }
        let moves = starts[rows] as usize;
        let rest = &rest[rows..];
        if rest.len() != 5 * moves {
            return Err(bad());
        }
        let (high, rest) = rest.split_at(moves);
        let (low, rest) = rest.split_at(moves);
        let (shifts, turns) = rest.split_at(2 * moves);
        let decoded = MoveRows {
            keys: (high.iter().zip(low))
                .map(|(&h, &l)| u16::from_be_bytes([h, l]))
                .collect(),
            shifts: shifts
                .chunks_exact(2)
                .map(|o| [o[0] as i8, o[1] as i8])
                .collect(),
            turns: turns.iter().map(|t| t & 3).collect(),
            starts,
        };
        let increasing = |w: &[u32]| {
            decoded.keys[w[0] as usize..w[1] as usize]
                .windows(2)
                .all(|k| k[0] < k[1])
        };
        if !decoded.starts.windows(2).all(increasing) {
            return Err(Error::Table(
                "sphere table: a drop-move row's keys do not increase".into(),
            ));
        }
        Ok(decoded)
    }
}

impl Default for DropMoves {
    /// No rows.
    fn default() -> Self {
        DropMoves {
            decoded: OnceLock::from(MoveRows::default()),
            frame: None,
        }
    }
}

impl Clone for DropMoves {
    fn clone(&self) -> Self {
        DropMoves {
            decoded: self.decoded.clone(),
            frame: self.frame.clone(),
        }
    }
}

impl std::fmt::Debug for DropMoves {
    fn fmt(&self, f: &mut std::fmt::Formatter) -> std::fmt::Result {
        write!(f, "DropMoves({} rows, {} moves)", self.rows(), self.len())
    }
}

impl PartialEq for DropMoves {
    fn eq(&self, other: &Self) -> bool {
        self.get() == other.get()
    }
}

impl Serialize for DropMoves {
    fn serialize<S: serde::Serializer>(&self, serializer: S) -> Result<S::Ok, S::Error> {
        self.get().to_raw().serialize(serializer)
    }
}

impl<'de> Deserialize<'de> for DropMoves {
    fn deserialize<D: serde::Deserializer<'de>>(deserializer: D) -> Result<Self, D::Error> {
        let raw = Vec::<u8>::deserialize(deserializer)?;
        let decoded = match raw.is_empty() {
            true => MoveRows::default(),
            false => MoveRows::from_raw(&raw).map_err(serde::de::Error::custom)?,
        };
        Ok(DropMoves {
            decoded: OnceLock::from(decoded),
            frame: None,
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    proptest! {
        /// Moves survive their frame, and a row reads the move of the
        /// lowest key a request drops.
        #[test]
        fn moves_round_trip_and_read_the_lowest_dropped_key(
            rows in prop::collection::vec(prop::collection::btree_map(0u16..500, (any::<i8>(), any::<i8>(), 0u8..4), 0..6), 1..20),
            from in 0u32..2100,
            member in 0u8..4,
        ) {
            let lists: Vec<Vec<(u16, [i8; 2], u8)>> = (rows.iter())
                .map(|row| row.iter().map(|(&k, &(x, y, t))| (k, [x, y], t)).collect())
                .collect();
            let moves = DropMoves::from_rows(lists.clone());
            let mut packed = DropMoves::packed(&moves.compress());
            packed.unpack().unwrap();
            prop_assert_eq!(&packed, &moves);
            for (row, list) in lists.iter().enumerate() {
                let expected = list.iter().find(|m| u32::from(m.0) >= from).map(|m| m.1);
                prop_assert_eq!(packed.shift(row, from, None), expected);
                // on a ring: the twin on the face `turn` quarter turns on
                let face = |m: u8| [0u8, 2, 1, 3][m as usize];
                let dropped = |m: &(u16, [i8; 2], u8)| {
                    4 * u32::from(m.0) + u32::from(face((face(member) + m.2) % 4)) >= from
                };
                let on_ring = list.iter().find(|m| dropped(m)).map(|m| m.1);
                prop_assert_eq!(packed.shift(row, from, Some(member)), on_ring);
            }
        }
    }

    #[test]
    fn a_cut_or_disordered_table_is_refused() {
        let raw = DropMoves::from_rows(vec![vec![(1, [0, 0], 0), (2, [1, 1], 0)]])
            .get()
            .to_raw();
        assert!(MoveRows::from_raw(&raw[..raw.len() - 1]).is_err());
        // rows, a count, the keys' high bytes, then their low bytes
        assert_eq!(raw[..9], [1, 0, 0, 0, 2, 0, 0, 1, 2]);
        let mut swapped = raw.clone();
        // the keys 1 and 2 swapped
        swapped.swap(7, 8);
        let e = MoveRows::from_raw(&swapped).unwrap_err().to_string();
        assert!(e.contains("do not increase"), "{e}");
    }
}

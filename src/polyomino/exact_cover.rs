//! Exact-cover search (Knuth's Algorithm X, fewest-options column first).
//!
//! Used offline to find polyomino dissections: the two 4-rep rules of the
//! P-pentomino, the 20-tile patch of a 10x10 face, the 81-rep G-hexomino rule.

use super::{Lattice, Orientation, Placement, Shape};
use std::collections::HashSet;

/// Every placement of `shape` (any of the 8 orientations, any translation)
/// whose cells all lie in `region`, deduplicated by the set of cells covered.
///
/// # Example
/// ```
/// use tessera::polyomino::exact_cover::placements_in;
/// use tessera::polyomino::Shape;
/// let domino = Shape::new(vec![(0, 0), (1, 0)]);
/// let square: Vec<(i64, i64)> = vec![(0, 0), (1, 0), (0, 1), (1, 1)];
/// // two horizontal and two vertical dominoes fit in a 2x2 square
/// assert_eq!(placements_in(&domino, &square).len(), 4);
/// ```
pub fn placements_in(shape: &Shape, region: &[(Lattice, Lattice)]) -> Vec<Placement> {
    let cells: HashSet<(Lattice, Lattice)> = region.iter().copied().collect();
    let mut seen = HashSet::new();
    let mut out = Vec::new();
    for orientation in Orientation::ALL {
        let at_origin = Placement::new((0, 0), orientation);
        let base: Vec<(Lattice, Lattice)> = at_origin.cells(shape).collect();
        // translate so that the first shape cell lands on every region cell
        for &anchor in region {
            let (dx, dy) = (anchor.0 - base[0].0, anchor.1 - base[0].1);
            if !base.iter().all(|c| cells.contains(&(c.0 + dx, c.1 + dy))) {
                continue;
            }
            let mut key: Vec<(Lattice, Lattice)> =
                base.iter().map(|c| (c.0 + dx, c.1 + dy)).collect();
            key.sort_unstable();
            if seen.insert(key) {
                out.push(Placement::new((dx, dy), orientation));
            }
        }
    }
    out
}

/// Finds exact covers of `region` by copies of `shape`.
///
/// Candidates are tried in the order given by `order_seed` (0 keeps the
/// natural order, other values shuffle deterministically), so different seeds
/// reach different tilings first. The search stops after `limit` solutions.
///
/// # Example
/// ```
/// use tessera::polyomino::exact_cover::tilings;
/// use tessera::polyomino::Shape;
/// let domino = Shape::new(vec![(0, 0), (1, 0)]);
/// let square: Vec<(i64, i64)> = vec![(0, 0), (1, 0), (0, 1), (1, 1)];
/// assert_eq!(tilings(&domino, &square, usize::MAX, 0).len(), 2);
/// ```
pub fn tilings(
    shape: &Shape,
    region: &[(Lattice, Lattice)],
    limit: usize,
    order_seed: u64,
) -> Vec<Vec<Placement>> {
    let mut options = placements_in(shape, region);
    if order_seed != 0 {
        shuffle(&mut options, order_seed);
    }
    let index: std::collections::HashMap<(Lattice, Lattice), usize> =
        region.iter().enumerate().map(|(i, &c)| (c, i)).collect();
    let option_cells: Vec<Vec<usize>> = options
        .iter()
        .map(|p| p.cells(shape).map(|c| index[&c]).collect())
        .collect();
    let mut by_cell: Vec<Vec<usize>> = vec![Vec::new(); region.len()];
    for (o, cells) in option_cells.iter().enumerate() {
        for &c in cells {
            by_cell[c].push(o);
        }
    }
    let mut search = Search {
        option_cells: &option_cells,
        by_cell: &by_cell,
        covered: vec![false; region.len()],
        chosen: Vec::new(),
        solutions: Vec::new(),
        limit,
    };
    search.run();
    search
        .solutions
        .into_iter()
        .map(|s| s.into_iter().map(|o| options[o]).collect())
        .collect()
}

struct Search<'a> {
    option_cells: &'a [Vec<usize>],
    by_cell: &'a [Vec<usize>],
    covered: Vec<bool>,
    chosen: Vec<usize>,
    solutions: Vec<Vec<usize>>,
    limit: usize,
}

impl Search<'_> {
    fn fits(&self, option: usize) -> bool {
        self.option_cells[option].iter().all(|&c| !self.covered[c])
    }

    fn run(&mut self) {
        if self.solutions.len() >= self.limit {
            return;
        }
        // the uncovered cell with the fewest fitting options
        let mut best: Option<(usize, usize)> = None;
        for cell in 0..self.covered.len() {
            if self.covered[cell] {
                continue;
            }
            let count = self.by_cell[cell].iter().filter(|&&o| self.fits(o)).count();
            if best.is_none_or(|(_, n)| count < n) {
                best = Some((cell, count));
                if count <= 1 {
                    break;
                }
            }
        }
        let Some((cell, count)) = best else {
            self.solutions.push(self.chosen.clone());
            return;
        };
        if count == 0 {
            return;
        }
        for &option in &self.by_cell[cell] {
            if !self.fits(option) {
                continue;
            }
            for &c in &self.option_cells[option] {
                self.covered[c] = true;
            }
            self.chosen.push(option);
            self.run();
            self.chosen.pop();
            for &c in &self.option_cells[option] {
                self.covered[c] = false;
            }
            if self.solutions.len() >= self.limit {
                return;
            }
        }
    }
}

/// Deterministic Fisher-Yates shuffle.
fn shuffle<T>(items: &mut [T], seed: u64) {
    let mut rng = crate::random::SplitMix64::new(seed);
    for i in (1..items.len()).rev() {
        items.swap(i, (rng.next_u64() % (i as u64 + 1)) as usize);
    }
}

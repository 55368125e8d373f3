//! Uniform samples in code order, from one shallow level's tiles.
//!
//! A constant density accepts the codes `0..N` of one level `L`. With `m`
//! the tile count of a shallower level `k`, code `c + h * m` (`c < m`) is
//! the descendant of the level-`k` tile of code `c` along the digits of
//! `h` (base-A, the level `k + 1` digit least significant). So the codes
//! in order are runs over the level-`k` tiles in code order, one run per
//! `h`, every tile of a run descending along the same digits. What that
//! descent does to a tile depends only on its rule and orientation (its
//! origin is scaled and shifted) and, for its class, on its rule and class:
//! a `Descent` tabulates both once per run. A sample then costs a few
//! table reads and the system's placing of its point, whatever the depth,
//! and the memory is the level-`k` list (at most [`LIST_TILES`] tiles),
//! built once; consecutive code ranges (a stream's blocks) reuse it.

use crate::polyomino::{Lattice, Orientation, Placement};
use crate::sample::Sample;
use crate::tiling::digit_blocks;
use rayon::prelude::*;
use std::ops::Range;

/// The longest level list kept: a level with at most this many tiles
/// serves every deeper one. Larger lists cost more memory and first
/// touches; smaller ones more runs, each tabulating a `Descent`.
pub const LIST_TILES: usize = 1 << 18;

/// Uniform samples of one level over consecutive code ranges (see
/// [`crate::tiling::TileSystem::code_order`]).
///
/// # Example
/// ```
/// use tessera::tiling::{sphere::SphereTiling, TileSystem};
/// let sphere = SphereTiling::default();
/// let mut source = sphere.code_order(1, 0..500, 500.0 / 960.0, 500.0).unwrap();
/// let (mut head, mut tail) = (Vec::new(), Vec::new());
/// source.fill(0..400, &mut head);
/// source.fill(400..500, &mut tail);
/// assert_eq!(head.len() + tail.len(), 500);
/// assert_eq!(tail[0].rank, 400.0 / 500.0);
/// ```
pub trait CodeOrder<P>: Send + Sync {
    /// Replaces the contents of `out` with the samples of the codes
    /// `codes`, in code order, ranked `code / d` (`codes` within the range
    /// the source was made for).
    fn fill(&mut self, codes: Range<usize>, out: &mut Vec<Sample<P>>);
}

/// How a polyomino system's tiles subdivide: what a `Descent` follows.
pub(crate) trait Subdivision: Sync {
    /// Children a tile.
    fn arity(&self) -> usize;
    /// Linear refinement a level.
    fn scale(&self) -> Lattice;
    /// Number of rules.
    fn rules(&self) -> usize;
    /// Number of classes the automaton maps.
    fn classes(&self) -> usize;
    /// The child (rule order) carrying code digit `digit` in a tile of
    /// rule `rule`.
    fn child_of_digit(&self, rule: usize, digit: usize) -> usize;
    /// The rule of child `child` of a tile of rule `rule`.
    fn child_rule(&self, rule: usize, child: usize) -> usize;
    /// Child `child`'s placement in its parent's refined frame.
    fn child_step(&self, rule: usize, child: usize) -> Placement;
    /// The class of child `child` of a tile of class `class`.
    fn child_class(&self, class: usize, child: usize) -> usize;
}

/// A tile of the listed level, compactly: what a descent needs.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Node {
    /// Lattice origin (listed levels are small: their lattices fit `i32`).
    pub x: i32,
    /// See `x`.
    pub y: i32,
    /// Structural index.
    pub class: u32,
    /// Orientation of the placement.
    pub orientation: Orientation,
    /// The rule the tile's children follow.
    pub rule: u8,
    /// Base face (sphere) or 0.
    pub face: u8,
}

impl Node {
    /// A node of a tile so placed.
    pub fn new(placement: &Placement, rule: u8, class: u32, face: u8) -> Node {
        let fit = |v: Lattice| i32::try_from(v).expect("listed levels have small lattices");
        Node {
            x: fit(placement.origin.0),
            y: fit(placement.origin.1),
            class,
            orientation: placement.orientation,
            rule,
            face,
        }
    }
}

/// A descendant, as a `Descent` gives it.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Placed {
    /// Its placement on its level's lattice.
    pub placement: Placement,
    /// Its structural index.
    pub class: u32,
    /// Its base face (sphere) or 0.
    pub face: u8,
}

/// What a listed tile's structural index says of its descendants'.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum Indexing {
    /// A neighbourhood class: the descendant's follows the automaton
    /// ([`Subdivision::child_class`]).
    Classes,
    /// A position in the subdivision tree: child `c` of index `i` has
    /// index `i * arity + c`.
    Tree,
}

/// How a descent maps the listed tile's index to its descendant's.
enum Indices {
    /// No digits: the index stays.
    Same,
    /// `table[rule * classes + class]`: the descendant's class.
    Classes(Vec<u32>),
    /// `index * factor + suffix[rule]`: the descendant's tree index.
    Tree { factor: u32, suffix: Vec<u32> },
}

/// The descent along fixed digits, tabulated.
struct Descent {
    /// `scale^depth`: an origin's factor.
    factor: Lattice,
    /// `steps[rule * 8 + orientation]`: the descendant of a tile of that
    /// rule at the origin so oriented.
    steps: Vec<Placement>,
    /// The descendant's structural index.
    indices: Indices,
}

impl Descent {
    /// The descent along `digits` (shallowest first).
    fn new(sub: &impl Subdivision, digits: &[usize], indexing: Indexing) -> Descent {
        let walk = |mut rule: usize, at: &mut dyn FnMut(usize, usize)| {
            for &digit in digits {
                let child = sub.child_of_digit(rule, digit);
                at(rule, child);
                rule = sub.child_rule(rule, child);
            }
        };
        let steps = (0..sub.rules() * 8)
            .map(|k| {
                let mut p = Placement::new((0, 0), Orientation::from_index(k % 8));
                walk(k / 8, &mut |rule, child| {
                    p = p.child(&sub.child_step(rule, child), sub.scale());
                });
                p
            })
            .collect();
        let indices = match (digits.is_empty(), indexing) {
            (true, _) => Indices::Same,
            (false, Indexing::Classes) => Indices::Classes(
                (0..sub.rules() * sub.classes())
                    .map(|k| {
                        let mut class = k % sub.classes();
                        walk(k / sub.classes(), &mut |_, child| {
                            class = sub.child_class(class, child)
                        });
                        class as u32
                    })
                    .collect(),
            ),
            (false, Indexing::Tree) => Indices::Tree {
                factor: (sub.arity() as u32).pow(digits.len() as u32),
                suffix: (0..sub.rules())
                    .map(|rule| {
                        let mut suffix = 0;
                        walk(rule, &mut |_, child| {
                            suffix = suffix * sub.arity() as u32 + child as u32
                        });
                        suffix
                    })
                    .collect(),
            },
        };
        Descent {
            factor: sub.scale().pow(digits.len() as u32),
            steps,
            indices,
        }
    }

    /// The descendant of `node`.
    #[inline(always)]
    fn apply(&self, node: &Node, classes: usize) -> Placed {
        let rule = node.rule as usize;
        let step = &self.steps[rule * 8 + node.orientation.index()];
        let class = match &self.indices {
            Indices::Same => node.class,
            Indices::Classes(table) => table[rule * classes + node.class as usize],
            Indices::Tree { factor, suffix } => node.class * factor + suffix[rule],
        };
        Placed {
            placement: Placement {
                origin: (
                    self.factor * node.x as Lattice + step.origin.0,
                    self.factor * node.y as Lattice + step.origin.1,
                ),
                orientation: step.orientation,
            },
            class,
            face: node.face,
        }
    }
}

/// The level `k` a code-order source of level `level` lists: the deepest
/// with at most [`LIST_TILES`] tiles, but no shallower than `first` (where
/// the system's class automaton starts) and no deeper than `level`.
pub(crate) fn list_level(level: u32, first: u32, capacity: impl Fn(u32) -> f64) -> u32 {
    let small = (0..=level)
        .take_while(|&l| capacity(l) <= LIST_TILES as f64)
        .last()
        .unwrap_or(0);
    small.max(first).min(level)
}

/// The level-`k` codes a source serving `codes` of a deeper level needs,
/// `m` tiles to level `k`: the residues of `codes`, or all of them when
/// the range wraps.
pub(crate) fn listed_codes(codes: &Range<usize>, m: usize) -> Range<usize> {
    if codes.is_empty() {
        0..0
    } else if codes.len() < m && codes.start / m == (codes.end - 1) / m {
        codes.start % m..(codes.end - 1) % m + 1
    } else {
        0..m
    }
}

/// A [`CodeOrder`] over a listed level: `place(descendant, code)` makes
/// each sample.
pub(crate) struct Listed<'a, S, F> {
    sub: &'a S,
    /// The listed level's tiles of codes `first..`, in code order.
    list: Vec<Node>,
    first: usize,
    /// Tiles of the listed level.
    m: usize,
    /// Levels from the listed one to the sampled one.
    depth: u32,
    /// What the listed tiles' indices are.
    indexing: Indexing,
    /// The last run's `h` and descent.
    run: Option<(usize, Descent)>,
    place: F,
}

impl<'a, S: Subdivision, F> Listed<'a, S, F> {
    /// A source of the level `depth` below the listed one, whose `m` tiles
    /// of codes `first..first + list.len()` are `list`, their indices
    /// of kind `indexing`.
    pub fn new(
        sub: &'a S,
        list: Vec<Node>,
        first: usize,
        m: usize,
        depth: u32,
        indexing: Indexing,
        place: F,
    ) -> Self {
        Listed {
            sub,
            list,
            first,
            m,
            depth,
            indexing,
            run: None,
            place,
        }
    }
}

impl<S, F, P> CodeOrder<P> for Listed<'_, S, F>
where
    S: Subdivision,
    F: Fn(&Placed, usize) -> Sample<P> + Send + Sync,
    P: Send,
{
    fn fill(&mut self, codes: Range<usize>, out: &mut Vec<Sample<P>>) {
        out.clear();
        out.reserve(codes.len());
        let (sub, a, classes) = (self.sub, self.sub.arity(), self.sub.classes());
        for (h, within) in digit_blocks(&codes, self.m) {
            if self.run.as_ref().is_none_or(|run| run.0 != h) {
                let digits: Vec<usize> = (0..self.depth)
                    .scan(h, |rest, _| {
                        let digit = *rest % a;
                        *rest /= a;
                        Some(digit)
                    })
                    .collect();
                self.run = Some((h, Descent::new(sub, &digits, self.indexing)));
            }
            let descent = &self.run.as_ref().expect("set above").1;
            let start = h * self.m + within.start;
            let nodes = &self.list[within.start - self.first..within.end - self.first];
            let place = &self.place;
            out.par_extend(
                nodes
                    .par_iter()
                    .enumerate()
                    .with_min_len(4096)
                    .map(|(i, node)| place(&descent.apply(node, classes), start + i)),
            );
        }
    }
}

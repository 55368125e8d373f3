//! Offline optimiser of the planar polyomino tables (`luts/ghexomino.lut`,
//! `luts/ppentomino.lut`).
//!
//! Steps, all on the torus (the root patch tiles the plane periodically):
//! 1. the root patch: an exact cover of the `side x side` square (the
//!    G-hexomino's from 12x9 rectangles of 18 tiles, chosen per rectangle
//!    among several covers);
//! 2. which rule each child subdivides with (several rules only), by the
//!    spread of the tile centroids three levels down;
//! 3. sibling ranks (code digits), void-and-cluster style: digit `k` goes, in
//!    every rule at once, to the children whose tiles lie farthest from the
//!    tiles of digits `0..k` (maximin over all instances), so every threshold
//!    keeps a well-spread subset; roots are ranked farthest-point first;
//! 4. structural indices: the automaton whose state is the tile's depth
//!    below the roots (up to `depth`), the rule of its ancestor `memory`
//!    levels up and the child numbers since (the tile's position inside
//!    that ancestor, which fixes its neighbourhood except at the ancestor's
//!    border); the report gives how often tiles of one state share one
//!    neighbourhood;
//! 5. offsets per (structural index, importance bin): Lloyd relaxation of the
//!    tiles a bin's density fraction accepts, every state sharing one offset,
//!    each depth on its own level (the deepest on the deepest level up to
//!    `lloyd_level` that holds at most `max_sites` of the bin's sites; where
//!    none does, its states take the offsets of their twins one depth up);
//!    then a few separation steps push apart the rare close pairs that shared
//!    offsets leave where a state meets an unusual neighbourhood. Depths
//!    matter where the neighbourhoods differ: the G-hexomino's children of
//!    roots sit in the root patch's arrangement, deeper tiles in the rule's.

use crate::lut::{PlaneLut, PlaneSystem, PLANE_LUT_VERSION};
use crate::optimize::lloyd::{cell_moments, torus_d2, wrap_half, TorusGrid};
use crate::optimize::ranking::farthest_point_ranks;
use crate::polyomino::exact_cover::tilings;
use crate::polyomino::{Lattice, Placement, Rule, Shape};
use crate::random::SplitMix64;
use crate::tiling::plane::{PlaneTile, PlaneTiling};
use crate::tiling::TileSystem;
use crate::Error;
use rayon::prelude::*;
use serde::Serialize;
use std::collections::HashMap;
use std::sync::Arc;
use std::time::Instant;

/// Options of [`build`].
///
/// # Example
/// ```
/// use tessera::{lut::PlaneSystem, optimize::plane::BuildOptions};
/// let o = BuildOptions::for_system(PlaneSystem::Ghexomino);
/// assert_eq!(o.bins, 81);
/// ```
#[derive(Clone, Debug, Serialize)]
pub struct BuildOptions {
    /// Seed of every random choice.
    pub seed: u64,
    /// Lloyd iterations per importance bin and level.
    pub iterations: usize,
    /// Importance bins, linear in the density fraction from `1/A` to 1.
    pub bins: u16,
    /// Structural indices tell tiles apart by their depth below the roots
    /// up to this depth (a child of a root sits in a different
    /// neighbourhood than a child of an inner tile).
    pub depth: u32,
    /// Child numbers a structural index remembers (at most `depth`): the
    /// tile's position inside its ancestor this many levels up.
    pub memory: u32,
    /// Level on which the deepest structural indices are relaxed.
    pub lloyd_level: u32,
    /// Largest number of sites relaxed at once; a bin with more sites at
    /// `lloyd_level` is relaxed on the deepest level that fits (at least
    /// `depth`; where even that holds more, the deepest states take their
    /// twins' offsets one depth up, or are relaxed there anyway if some
    /// have no twin).
    pub max_sites: usize,
    /// Quadrature points per site in Lloyd relaxation.
    pub quadrature: usize,
    /// Over-relaxation factor of the Lloyd steps (1 = plain Lloyd).
    pub relaxation: f64,
    /// Separation steps after Lloyd (see the module notes).
    pub separation_steps: usize,
}

impl BuildOptions {
    /// The defaults used for the shipped table of `system`.
    ///
    /// # Example
    /// ```
    /// use tessera::{lut::PlaneSystem, optimize::plane::BuildOptions};
    /// assert_eq!(BuildOptions::for_system(PlaneSystem::Ppentomino).depth, 3);
    /// ```
    pub fn for_system(system: PlaneSystem) -> Self {
        match system {
            PlaneSystem::Ghexomino => BuildOptions {
                seed: 1,
                iterations: 24,
                bins: 81,
                depth: 2,
                memory: 1,
                lloyd_level: 2,
                max_sites: 80_000,
                quadrature: 24,
                relaxation: 1.5,
                separation_steps: 24,
            },
            PlaneSystem::Ppentomino => BuildOptions {
                seed: 1,
                iterations: 24,
                bins: 25,
                depth: 3,
                memory: 3,
                lloyd_level: 4,
                max_sites: 80_000,
                quadrature: 40,
                relaxation: 1.5,
                separation_steps: 24,
            },
        }
    }
}

/// What the build measured, for the provenance file.
///
/// # Example
/// ```
/// use tessera::{lut::PlaneSystem, optimize::plane::BuildReport};
/// fn classes(r: &BuildReport) -> usize { r.classes }
/// ```
#[derive(Clone, Debug, Serialize)]
pub struct BuildReport {
    /// Roots in the patch.
    pub roots: usize,
    /// Structural indices (automaton states).
    pub classes: usize,
    /// Share of the tiles at the Lloyd level whose neighbourhood (the
    /// placements of the tiles touching them, in their own frame) is the
    /// most common one of their structural index.
    pub neighbourhood_agreement: f64,
    /// `child_rule` search: centroid spread (min + mean NN distance, cells
    /// at three levels down) of the chosen assignment.
    pub rule_score: f64,
    /// Mean site move (cells) in the last Lloyd iteration, per bin (of the
    /// deepest states, or of their twins where those lend their offsets).
    pub lloyd_residual: Vec<f64>,
    /// Seconds spent in Lloyd relaxation.
    pub lloyd_seconds: f64,
}

/// The rep-tile and rules stored by `tessera lut tiling`.
fn stored_rules(system: PlaneSystem) -> Result<(Shape, Vec<Rule>), Error> {
    let text = match system {
        PlaneSystem::Ghexomino => include_str!("../../luts/ghexomino.rules.json"),
        PlaneSystem::Ppentomino => include_str!("../../luts/ppentomino.rules.json"),
    };
    let bad = |e: serde_json::Error| Error::Table(format!("{}.rules.json: {e}", system.name()));
    let value: serde_json::Value = serde_json::from_str(text).map_err(bad)?;
    let shape: Shape = serde_json::from_value(value["shape"].clone()).map_err(bad)?;
    let rules: Vec<Rule> = serde_json::from_value(value["rules"].clone()).map_err(bad)?;
    Ok((shape, rules))
}

/// Builds the table of `system`; `progress(stage, done, total)` is called
/// along the way.
///
/// # Example
/// ```no_run
/// use tessera::{lut::PlaneSystem, optimize::plane::{build, BuildOptions}};
/// let options = BuildOptions::for_system(PlaneSystem::Ppentomino);
/// let (lut, report) = build(PlaneSystem::Ppentomino, &options, &|_, _, _| {}).unwrap();
/// assert_eq!(report.roots, lut.roots.len());
/// ```
pub fn build(
    system: PlaneSystem,
    options: &BuildOptions,
    progress: &(dyn Fn(&str, u64, u64) + Sync),
) -> Result<(PlaneLut, BuildReport), Error> {
    let (shape, rules) = stored_rules(system)?;
    let arity = rules[0].children.len();
    if options.bins < 2
        || options.depth == 0
        || options.lloyd_level < options.depth
        || !(1..=options.depth).contains(&options.memory)
    {
        return Err(Error::Request(
            "need at least 2 bins, 1 <= depth <= lloyd_level and 1 <= memory <= depth".into(),
        ));
    }
    let mut rng = SplitMix64::new(options.seed);
    progress("patch", 0, 1);
    let (side, roots) = root_patch(system, &shape, &mut rng)?;
    let mut lut = PlaneLut {
        version: PLANE_LUT_VERSION,
        seed: options.seed,
        shape: shape.clone(),
        child_rule: vec![vec![0; arity]; rules.len()],
        child_digit: vec![(0..arity as u8).collect(); rules.len()],
        rules,
        side,
        root_rule: vec![0; roots.len()],
        root_rank: (0..roots.len() as u32).collect(),
        root_class: vec![0; roots.len()],
        roots,
        transitions: vec![0; arity],
        bins: 2,
        offsets: vec![PlaneLut::quantise(shape.centroid()); 2],
    };
    progress("rules", 0, 1);
    let rule_score = choose_rules(&mut lut);
    progress("ranks", 0, 1);
    choose_digits(&mut lut);
    lut.root_rank = root_ranks(&lut);
    let (depths, shallower) = build_automaton(&mut lut, options.depth, options.memory);
    lut.bins = options.bins;
    let centroid = PlaneLut::quantise(shape.centroid());
    lut.offsets = vec![centroid; lut.classes() * options.bins as usize];
    let tiling = PlaneTiling::new(Arc::new(lut.clone()));
    let agreement_level = (0..=options.lloyd_level)
        .rev()
        .find(|&l| tiling.capacity(l) <= 200_000.0)
        .unwrap_or(0);
    let agreement = neighbourhood_agreement(&lut, agreement_level);
    let started = Instant::now();
    let mut residuals = Vec::new();
    let deepest = options.depth;
    // the deepest states can take their shallower twins' offsets where a
    // bin has too many sites to relax at their depth
    let twinned = depths
        .iter()
        .zip(&shallower)
        .all(|(&d, twin)| d < deepest || twin.is_some());
    for bin in 0..options.bins as usize {
        progress("lloyd", bin as u64, options.bins as u64);
        let mut shallower_residual = 0.0;
        for depth in 0..deepest {
            shallower_residual = relax(&mut lut, &depths, depth, depth, bin, options);
        }
        let sites = |l: u32| lut.bin_fraction(bin) * tiling.capacity(l);
        let level = (deepest..=options.lloyd_level)
            .rev()
            .find(|&l| sites(l) <= options.max_sites as f64);
        let residual = match level {
            None if twinned => {
                let bins = options.bins as usize;
                for (state, twin) in shallower.iter().enumerate() {
                    if let Some(twin) = *twin {
                        lut.offsets[state * bins + bin] = lut.offsets[twin as usize * bins + bin];
                    }
                }
                shallower_residual
            }
            _ => relax(
                &mut lut,
                &depths,
                deepest,
                level.unwrap_or(deepest),
                bin,
                options,
            ),
        };
        residuals.push(residual);
    }
    progress("lloyd", options.bins as u64, options.bins as u64);
    let report = BuildReport {
        roots: lut.roots.len(),
        classes: lut.classes(),
        neighbourhood_agreement: agreement,
        rule_score,
        lloyd_residual: residuals,
        lloyd_seconds: started.elapsed().as_secs_f64(),
    };
    // the run-time checks, before anything is written
    let lut = PlaneLut::from_bytes(&lut.to_bytes())?;
    Ok((lut, report))
}

/// The root patch: side and placements covering `[0, side)^2` exactly.
fn root_patch(
    system: PlaneSystem,
    shape: &Shape,
    rng: &mut SplitMix64,
) -> Result<(Lattice, Vec<Placement>), Error> {
    let rect = |w: Lattice, h: Lattice| -> Vec<(Lattice, Lattice)> {
        (0..h).flat_map(|y| (0..w).map(move |x| (x, y))).collect()
    };
    let none = || Error::Request(format!("no root patch found for the {}", system.name()));
    match system {
        PlaneSystem::Ppentomino => {
            let found = tilings(shape, &rect(10, 10), 1, rng.next_u64() | 1);
            Ok((10, found.into_iter().next().ok_or_else(none)?))
        }
        PlaneSystem::Ghexomino => {
            // 12x9 rectangles of 18 tiles, 3 across and 4 down, each its
            // own randomly ordered search, so borders differ
            let mut roots = Vec::new();
            for j in 0..4 {
                for i in 0..3 {
                    let covers = tilings(shape, &rect(12, 9), 1, rng.next_u64() | 1);
                    let cover = covers.first().ok_or_else(none)?;
                    roots.extend(cover.iter().map(|p| {
                        Placement::new((p.origin.0 + 12 * i, p.origin.1 + 9 * j), p.orientation)
                    }));
                }
            }
            Ok((36, roots))
        }
    }
}

/// Tile centroids (lattice cells of the tile's level) on the torus.
fn centroids(tiling: &PlaneTiling, tiles: &[PlaneTile]) -> Vec<[f64; 2]> {
    let c = tiling.shape().centroid();
    tiles.iter().map(|t| t.placement.to_lattice(c)).collect()
}

fn period(lut: &PlaneLut, level: u32) -> f64 {
    lut.side as f64 * (lut.rules[0].scale as f64).powi(level as i32)
}

/// Min plus mean nearest-neighbour distance of the tile centroids three
/// levels down (torus, cells).
fn spread(lut: &PlaneLut) -> f64 {
    let tiling = PlaneTiling::new(Arc::new(lut.clone()));
    let level = 3.min(tiling.max_level());
    let points = centroids(&tiling, &tiling.tiles(level));
    let grid = TorusGrid::new(&points, period(lut, level));
    let nn: Vec<f64> = (0..points.len())
        .map(|i| grid.nearest(points[i], Some(i)).1.sqrt())
        .collect();
    let min = nn.iter().copied().fold(f64::INFINITY, f64::min);
    min + nn.iter().sum::<f64>() / nn.len() as f64
}

/// Picks the rule of every child (and root) for the best centroid spread:
/// every assignment of child rules, then one pass of root flips.
fn choose_rules(lut: &mut PlaneLut) -> f64 {
    let (rules, arity) = (lut.rules.len(), lut.arity());
    if rules == 1 {
        return spread(lut);
    }
    let slots = rules * arity;
    let choices = (rules as u64).checked_pow(slots as u32).unwrap_or(u64::MAX);
    let assign = |code: u64| -> Vec<Vec<u8>> {
        let mut c = code;
        (0..rules)
            .map(|_| {
                (0..arity)
                    .map(|_| {
                        let r = (c % rules as u64) as u8;
                        c /= rules as u64;
                        r
                    })
                    .collect()
            })
            .collect()
    };
    let scored: Vec<(f64, u64)> = (0..choices.min(1 << 12))
        .into_par_iter()
        .map(|code| {
            let mut trial = lut.clone();
            trial.child_rule = assign(code);
            (spread(&trial), code)
        })
        .collect();
    let best = scored.iter().fold(
        (f64::NEG_INFINITY, 0),
        |b, &s| if s.0 > b.0 { s } else { b },
    );
    lut.child_rule = assign(best.1);
    let mut score = best.0;
    for r in 0..lut.roots.len() {
        let mut trial = lut.clone();
        trial.root_rule[r] = ((trial.root_rule[r] as usize + 1) % rules) as u8;
        let s = spread(&trial);
        if s > score {
            *lut = trial;
            score = s;
        }
    }
    score
}

/// Sibling ranks, void-and-cluster style (see the module notes), chosen on
/// the first level with at least 1000 tiles.
fn choose_digits(lut: &mut PlaneLut) {
    let tiling = PlaneTiling::new(Arc::new(lut.clone()));
    let level = (1..=tiling.max_level())
        .find(|&l| tiling.capacity(l) >= 1000.0)
        .unwrap_or(1);
    let tiles = tiling.tiles(level);
    let points = centroids(&tiling, &tiles);
    let p = period(lut, level);
    // which child of which rule each tile is (its parent's rule, its slot)
    let arity = lut.arity();
    let parents = tiling.tiles(level - 1);
    let slot: Vec<(usize, usize)> = (0..tiles.len())
        .map(|i| (parents[i / arity].rule as usize, i % arity))
        .collect();
    let rules = lut.rules.len();
    let mut left: Vec<Vec<usize>> = vec![(0..arity).collect(); rules];
    let mut nearest = vec![f64::INFINITY; tiles.len()];
    for digit in 0..arity {
        // every combination of one remaining child per rule
        let combos: usize = left.iter().map(Vec::len).product();
        let pick = |k: usize| -> Vec<usize> {
            let mut k = k;
            left.iter()
                .map(|l| {
                    let c = l[k % l.len()];
                    k /= l.len();
                    c
                })
                .collect()
        };
        let score = |choice: &[usize]| -> (f64, f64) {
            let (mut worst, mut sum) = (f64::INFINITY, 0.0);
            for (i, &(r, c)) in slot.iter().enumerate() {
                if choice[r] == c {
                    worst = worst.min(nearest[i]);
                    sum += nearest[i].min(1e9);
                }
            }
            (worst, sum)
        };
        let best = (0..combos)
            .map(|k| (score(&pick(k)), k))
            .fold(None, |b: Option<((f64, f64), usize)>, s| match b {
                Some(b) if (b.0 .0, b.0 .1) >= (s.0 .0, s.0 .1) => Some(b),
                _ => Some(s),
            })
            .map(|b| pick(b.1))
            .unwrap_or_default();
        let new: Vec<[f64; 2]> = (0..tiles.len())
            .filter(|&i| best[slot[i].0] == slot[i].1)
            .map(|i| points[i])
            .collect();
        let grid = TorusGrid::new(&new, p);
        nearest
            .par_iter_mut()
            .zip(&points)
            .for_each(|(n, &q)| *n = n.min(grid.nearest(q, None).1));
        for (r, &c) in best.iter().enumerate() {
            lut.child_digit[r][c] = digit as u8;
            left[r].retain(|&x| x != c);
        }
    }
}

/// Farthest-point ranks of the roots' centroids on the torus.
fn root_ranks(lut: &PlaneLut) -> Vec<u32> {
    let c = lut.shape.centroid();
    let points: Vec<[f64; 2]> = lut.roots.iter().map(|p| p.to_lattice(c)).collect();
    let p = lut.side as f64;
    farthest_point_ranks(points.len(), |a, b| {
        torus_d2(points[a], points[b], p).sqrt()
    })
}

/// The structural-index automaton: a state is (depth below the roots, capped
/// at `depth`; the rule of the ancestor up to `memory` levels up; the child
/// numbers since). Returns each state's depth and, for states of depth
/// `depth`, the state one depth up with the same rule and child numbers
/// (when there is one).
fn build_automaton(lut: &mut PlaneLut, depth: u32, memory: u32) -> (Vec<u32>, Vec<Option<u32>>) {
    type State = (u32, u8, Vec<u8>);
    let arity = lut.arity();
    let mut ids: HashMap<State, u32> = HashMap::new();
    let mut states: Vec<State> = Vec::new();
    let mut intern = |s: State, states: &mut Vec<State>| -> u32 {
        *ids.entry(s.clone()).or_insert_with(|| {
            states.push(s);
            states.len() as u32 - 1
        })
    };
    lut.root_class = lut
        .root_rule
        .iter()
        .map(|&r| intern((0, r, Vec::new()), &mut states))
        .collect();
    let mut transitions = Vec::new();
    let mut next = 0;
    while next < states.len() {
        let (d, rule, path) = states[next].clone();
        for child in 0..arity as u8 {
            let mut p = path.clone();
            p.push(child);
            let d = (d + 1).min(depth);
            let s = if p.len() as u32 <= memory {
                (d, rule, p)
            } else {
                let ancestor = lut.child_rule[rule as usize][p[0] as usize];
                (d, ancestor, p[1..].to_vec())
            };
            transitions.push(intern(s, &mut states));
        }
        next += 1;
    }
    lut.transitions = transitions;
    let shallower = states
        .iter()
        .map(|(d, rule, path)| match *d {
            d if d == depth && d > 0 => ids.get(&(d - 1, *rule, path.clone())).copied(),
            _ => None,
        })
        .collect();
    (states.iter().map(|s| s.0).collect(), shallower)
}

/// Share of the tiles of `level` whose neighbourhood is the most common one
/// of their structural index.
fn neighbourhood_agreement(lut: &PlaneLut, level: u32) -> f64 {
    let tiling = PlaneTiling::new(Arc::new(lut.clone()));
    let tiles = tiling.tiles(level);
    let size = period(lut, level) as i64;
    let mut owner: HashMap<(i64, i64), usize> = HashMap::new();
    for (i, t) in tiles.iter().enumerate() {
        for (x, y) in t.placement.cells(&lut.shape) {
            owner.insert((x, y), i);
        }
    }
    // (class, the neighbours' origins and orientations in the tile's frame)
    type Neighbourhood = (u32, Vec<(Lattice, Lattice, usize)>);
    let mut counts: HashMap<Neighbourhood, usize> = HashMap::new();
    for (i, t) in tiles.iter().enumerate() {
        let inverse = t.placement.orientation.inverse();
        let mut signature: Vec<(Lattice, Lattice, usize)> = Vec::new();
        for (x, y) in t.placement.cells(&lut.shape) {
            for (dx, dy) in [
                (1, 0),
                (-1, 0),
                (0, 1),
                (0, -1),
                (1, 1),
                (1, -1),
                (-1, 1),
                (-1, -1),
            ] {
                let cell = ((x + dx).rem_euclid(size), (y + dy).rem_euclid(size));
                let j = owner[&cell];
                if j == i {
                    continue;
                }
                // the neighbour's origin and orientation in this tile's frame
                let o = tiles[j].placement;
                let mut rel = (
                    o.origin.0 - t.placement.origin.0,
                    o.origin.1 - t.placement.origin.1,
                );
                rel.0 = (rel.0 + size / 2).rem_euclid(size) - size / 2;
                rel.1 = (rel.1 + size / 2).rem_euclid(size) - size / 2;
                let local = inverse.apply(rel);
                let orient = o.orientation.then(inverse).index();
                signature.push((local.0, local.1, orient));
            }
        }
        signature.sort_unstable();
        signature.dedup();
        *counts.entry((t.class, signature)).or_default() += 1;
    }
    let mut best: HashMap<u32, usize> = HashMap::new();
    for ((class, _), n) in counts {
        let b = best.entry(class).or_default();
        *b = (*b).max(n);
    }
    best.values().sum::<usize>() as f64 / tiles.len() as f64
}

/// Lloyd relaxation, at `level`, of the tiles of structural depth `depth`
/// that importance bin `bin` accepts; updates their classes' offsets and
/// returns the mean site move (cells) of the last iteration.
fn relax(
    lut: &mut PlaneLut,
    depths: &[u32],
    depth: u32,
    level: u32,
    bin: usize,
    options: &BuildOptions,
) -> f64 {
    let tiling = PlaneTiling::new(Arc::new(lut.clone()));
    let fraction = lut.bin_fraction(bin);
    let d = fraction * tiling.capacity(level);
    let tiles: Vec<PlaneTile> = tiling
        .tiles(level)
        .into_iter()
        .filter(|t| (t.code as f64) + 0.5 < d)
        .collect();
    if tiles.len() < 2 || tiles.iter().any(|t| depths[t.class as usize] != depth) {
        return 0.0;
    }
    let p = period(lut, level);
    // a square grid of about `quadrature` points per site
    let n = ((options.quadrature.max(1) * tiles.len()) as f64)
        .sqrt()
        .ceil() as usize;
    let h = p / n as f64;
    let bins = lut.bins as usize;
    let mut offsets: Vec<[f64; 2]> = (0..lut.classes()).map(|c| lut.offset(c, bin)).collect();
    let mut residual = 0.0;
    for _ in 0..options.iterations {
        let sites = sites_of(&tiles, &offsets, p);
        let grid = TorusGrid::new(&sites, p);
        let (sum, count) = cell_moments(&grid, n, h, [0.0, 0.0]);
        // each class moves by the mean of its sites' moves, in tile frames
        let mut class_sum = vec![[0.0f64; 2]; offsets.len()];
        let mut class_n = vec![0usize; offsets.len()];
        residual = 0.0;
        for (k, t) in tiles.iter().enumerate() {
            if count[k] == 0 {
                continue;
            }
            let shift = [sum[k][0] / count[k] as f64, sum[k][1] / count[k] as f64];
            residual += (shift[0] * shift[0] + shift[1] * shift[1]).sqrt();
            let local = t.placement.orientation.inverse().apply_f64(shift);
            let c = t.class as usize;
            class_sum[c][0] += local[0];
            class_sum[c][1] += local[1];
            class_n[c] += 1;
        }
        residual /= tiles.len() as f64;
        for c in 0..offsets.len() {
            if class_n[c] > 0 {
                for a in 0..2 {
                    offsets[c][a] += options.relaxation * class_sum[c][a] / class_n[c] as f64;
                }
            }
        }
    }
    separate(&tiles, &mut offsets, p, options.separation_steps);
    for (c, o) in offsets.iter().enumerate() {
        if depths[c] == depth {
            lut.offsets[c * bins + bin] = PlaneLut::quantise(*o);
        }
    }
    residual
}

/// Sites of the tiles on the torus of period `p`.
fn sites_of(tiles: &[PlaneTile], offsets: &[[f64; 2]], p: f64) -> Vec<[f64; 2]> {
    tiles
        .iter()
        .map(|t| {
            let [x, y] = t.placement.to_lattice(offsets[t.class as usize]);
            [x.rem_euclid(p), y.rem_euclid(p)]
        })
        .collect()
}

/// After Lloyd: shared offsets leave a few close pairs where one class
/// meets an unusual neighbourhood. Each step pushes the sites closer than
/// 0.8 hexagonal spacings apart, moves every class by the mean push of its
/// pushed instances (in tile frames), and the offsets with the largest
/// minimum distance seen are kept.
fn separate(tiles: &[PlaneTile], offsets: &mut [[f64; 2]], p: f64, steps: usize) {
    let spacing = (2.0 * p * p / (3f64.sqrt() * tiles.len() as f64)).sqrt();
    let target = 0.8 * spacing;
    let min_distance = |offsets: &[[f64; 2]]| {
        let sites = sites_of(tiles, offsets, p);
        let grid = TorusGrid::new(&sites, p);
        (0..sites.len())
            .map(|k| grid.nearest(sites[k], Some(k)))
            .map(|(j, d2)| (j, d2.sqrt()))
            .collect::<Vec<_>>()
    };
    let mut best = offsets.to_vec();
    let mut best_min = f64::NEG_INFINITY;
    for _ in 0..=steps {
        let sites = sites_of(tiles, offsets, p);
        let nearest = min_distance(offsets);
        let min = nearest.iter().map(|n| n.1).fold(f64::INFINITY, f64::min);
        if min > best_min {
            best_min = min;
            best.copy_from_slice(offsets);
        }
        let mut push = vec![[0.0f64; 2]; offsets.len()];
        let mut pushed = vec![0usize; offsets.len()];
        for (k, t) in tiles.iter().enumerate() {
            let (j, d) = nearest[k];
            if d >= target || d == 0.0 {
                continue;
            }
            let v = [
                wrap_half(sites[k][0] - sites[j][0], p) / d,
                wrap_half(sites[k][1] - sites[j][1], p) / d,
            ];
            let step = 0.5 * (target - d);
            let local = t
                .placement
                .orientation
                .inverse()
                .apply_f64([v[0] * step, v[1] * step]);
            let c = t.class as usize;
            push[c][0] += local[0];
            push[c][1] += local[1];
            pushed[c] += 1;
        }
        for c in 0..offsets.len() {
            if pushed[c] > 0 {
                offsets[c][0] += push[c][0] / pushed[c] as f64;
                offsets[c][1] += push[c][1] / pushed[c] as f64;
            }
        }
    }
    offsets.copy_from_slice(&best);
}

//! What drop moves give between the sphere's bins, simulated in sphere
//! coordinates: the measurement behind `lut::DropMoves`, and the way to
//! weigh them on the levels that do not have them yet (5 and 6, which keep
//! sibling fills: their moves would pass the 4 MB table budget).
//!
//! Between two bins a request keeps the codes below `N` of the upper
//! bin's relaxed set, and each dropped point leaves a hole. Here the
//! upper bin's codes are dropped one at a time, highest first, as ever
//! smaller requests drop them, and each drop relaxes (uniform Lloyd,
//! among the other points held fixed) the kept points within `--reach`
//! spacings of the dropped point or of any point dropped before it within
//! `--hole` spacings. A point that moves records an event: its new place,
//! keyed by the code whose drop moved it. A request of `N` would read, for
//! each point, the event of the lowest code at or above `N`, so its set
//! is exactly the simulation's state after dropping the codes from `N`
//! up. The table builder does the same in the tiles' frames, with a room
//! and a guard (`optimize::sphere::drop_moves`).
//!
//! For each bin interval of a level it prints separation, covering and
//! mesh ratio (times √N) and the normalised energy (issue 18's floors:
//! 2.4, 3.4, 2.8 and -1.085) at `--evaluate` counts spread over the interval,
//! the shipped table (drop moves on levels 0-5, sibling fills on 6)
//! against the simulation, then the level's worst, its events a tile and
//! what they would take in a table (per tile, uncompressed and zstd: a
//! count a tile, a 16- or 24-bit code and an `i8` pair a move, in 1/40
//! cell, per interval). Levels 4-6 share rows by ring on the shipped
//! table, which divides their tables by about 4.
//!
//!     cargo run --release --example neighbour_events -- LEVEL [BIN ...]
//!         [--reach 1.5] [--hole 2] [--iterations 5] [--prune 0.05] [--evaluate 3]

use glam::DVec3;
use kiddo::{ImmutableKdTree, SquaredEuclidean};
use std::f64::consts::PI;
use tessera::metrics::sphere::{covering_radius, riesz1_normalized, separation};
use tessera::relax::relax_among_fixed;
use tessera::tiling::{sphere::SphereTiling, TileSystem};
use tessera::Sampler;

const USAGE: &str = "usage: neighbour_events LEVEL [BIN ...] [--reach R] [--hole H] \
                     [--iterations K] [--prune P] [--evaluate E]";

/// How the simulated builder moves points.
struct Settings {
    /// Kept points this many spacings from a hole move.
    reach: f64,
    /// Points dropped this many spacings from the new one share its hole.
    hole: f64,
    /// Lloyd iterations a drop.
    iterations: usize,
    /// Moves shorter than this many spacings are not recorded (the point
    /// stays).
    prune: f64,
    /// Counts measured an interval.
    evaluate: usize,
}

/// Separation, covering radius and mesh ratio, times √N, and the
/// normalised Riesz s = 1 energy `(E - N²) / N^1.5`.
#[derive(Clone, Copy)]
struct Quality([f64; 4]);

impl Quality {
    fn of(points: &[DVec3]) -> Self {
        let (s, c) = (separation(points), covering_radius(points));
        Quality([s, c, 2.0 * c / s, riesz1_normalized(points)])
    }

    fn worst(self, other: Self) -> Self {
        let [s, c, m, e] = self.0;
        let [t, d, n, f] = other.0;
        Quality([s.min(t), c.max(d), m.max(n), e.max(f)])
    }
}

impl std::fmt::Display for Quality {
    fn fmt(&self, f: &mut std::fmt::Formatter) -> std::fmt::Result {
        let [s, c, m, e] = self.0;
        write!(f, "{s:.2} / {c:.2} / {m:.2} / {e:.4}")
    }
}

fn main() {
    let mut args: Vec<String> = std::env::args().skip(1).collect();
    let mut flag = |name: &str, default: f64| -> f64 {
        match args.iter().position(|a| a == name) {
            Some(k) => {
                let value = args.get(k + 1).and_then(|v| v.parse().ok()).expect(USAGE);
                args.drain(k..k + 2);
                value
            }
            None => default,
        }
    };
    let settings = Settings {
        reach: flag("--reach", 1.5),
        hole: flag("--hole", 2.0),
        iterations: flag("--iterations", 5.0) as usize,
        prune: flag("--prune", 0.05),
        evaluate: flag("--evaluate", 3.0) as usize,
    };
    let numbers: Vec<usize> = args.iter().map(|a| a.parse().expect(USAGE)).collect();
    let (&level, bins) = numbers.split_first().expect(USAGE);
    let sphere = SphereTiling::default();
    let bins = match bins.is_empty() {
        true => (0..sphere.lut().bins()).collect(),
        false => bins.to_vec(),
    };
    let capacity = sphere.capacity(level as u32);
    let (mut shipped, mut simulated) = (
        Quality([f64::INFINITY, 0.0, 0.0, f64::NEG_INFINITY]),
        None::<Quality>,
    );
    let (mut events, mut table) = (0, Vec::new());
    for bin in bins {
        let interval = Interval::new(&sphere, capacity, bin);
        let moves = interval.simulate(&settings, |n, points| {
            let main = Quality::of(&request(n));
            let ours = Quality::of(points);
            shipped = shipped.worst(main);
            simulated = Some(simulated.map_or(ours, |w| w.worst(ours)));
            println!("bin {bin:2} N {n:7}: shipped {main}, events {ours}");
        });
        events += moves.iter().map(Vec::len).sum::<usize>();
        table.extend(interval.encode(&moves));
    }
    let packed = zstd::bulk::compress(&table, 19).expect("zstd compresses");
    println!(
        "level {level}: {events} events ({:.2} a tile), table {} bytes, {} with zstd",
        events as f64 / capacity,
        table.len(),
        packed.len()
    );
    if let Some(simulated) = simulated {
        println!(
            "worst (separation / covering / mesh ratio / energy): shipped {shipped}, events {simulated}"
        );
    }
}

/// The uniform request of `n` points on the shipped table.
fn request(n: usize) -> Vec<DVec3> {
    (Sampler::sphere().count(n).generate().expect("uniform"))
        .into_iter()
        .map(|s| s.position)
        .collect()
}

/// The counts one bin serves between its lower neighbour and itself.
struct Interval {
    /// Codes below `lower` are the lower bin's (or the level above's).
    lower: usize,
    /// The bin's own set: codes below `upper`, at their places.
    set: Vec<DVec3>,
}

impl Interval {
    fn new(sphere: &SphereTiling, capacity: f64, bin: usize) -> Self {
        let lut = sphere.lut();
        let upper = lut.bin_codes(bin, capacity) as usize;
        let lower = match bin {
            0 => (capacity / 4.0) as usize,
            _ => lut.bin_codes(bin - 1, capacity) as usize,
        };
        // a uniform request lists its samples by code
        Interval {
            lower,
            set: request(upper),
        }
    }

    /// Drops the codes from the top, moving their neighbours; calls
    /// `measure(n, points)` at `settings.evaluate` counts. Returns each
    /// point's moves: the code that moved it and its displacement from
    /// the bin's place in 1/40 of a cell.
    fn simulate(
        &self,
        settings: &Settings,
        mut measure: impl FnMut(usize, &[DVec3]),
    ) -> Vec<Vec<(usize, [i8; 2])>> {
        let upper = self.set.len();
        let at: Vec<[f64; 3]> = self.set.iter().map(|p| p.to_array()).collect();
        let tree: ImmutableKdTree<f64, 3> = ImmutableKdTree::new_from_slice(&at);
        let within = |code: usize, radius: f64| {
            (tree
                .within_unsorted::<SquaredEuclidean>(&at[code], radius * radius)
                .into_iter())
            .map(|near| near.item as usize)
        };
        let evaluated: Vec<usize> = (1..=settings.evaluate)
            .map(|k| upper - (upper - self.lower) * k / (settings.evaluate + 1))
            .collect();
        let mut points = self.set.clone();
        let mut moves = vec![Vec::new(); upper];
        for dropped in (self.lower + 1..upper).rev() {
            // the points below `dropped` stay, `dropped` and above are gone
            let spacing = (4.0 * PI / dropped as f64).sqrt();
            let hole: Vec<DVec3> = (within(dropped, settings.hole * spacing))
                .filter(|&c| c >= dropped)
                .map(|c| points[c])
                .collect();
            let around: Vec<usize> = within(dropped, 6.0 * spacing)
                .filter(|&c| c < dropped)
                .collect();
            let mut local: Vec<DVec3> = around.iter().map(|&c| points[c]).collect();
            let movable: Vec<usize> = (0..around.len())
                .filter(|&k| {
                    hole.iter()
                        .any(|h| local[k].distance(*h) < settings.reach * spacing)
                })
                .collect();
            relax_among_fixed(&mut local, &movable, settings.iterations).expect("unit vectors");
            for k in movable {
                let code = around[k];
                if local[k].distance(points[code]) < settings.prune * spacing {
                    continue;
                }
                points[code] = local[k];
                let cell = spacing / 5f64.sqrt();
                moves[code].push((dropped, tangent(self.set[code], local[k], cell / 40.0)));
            }
            if evaluated.contains(&dropped) {
                measure(dropped, &points[..dropped]);
            }
        }
        moves
    }

    /// The interval's part of a table: a move count a point (`u8`), then
    /// the codes (from the interval's start, 16 bits where they fit, else
    /// 24), then the displacements.
    fn encode(&self, moves: &[Vec<(usize, [i8; 2])>]) -> Vec<u8> {
        let width = if self.set.len() - self.lower < 1 << 16 {
            2
        } else {
            3
        };
        let counts = moves.iter().map(|m| m.len().min(255) as u8);
        let codes = (moves.iter().flatten()).flat_map(|&(code, _)| {
            ((code - self.lower) as u32)
                .to_le_bytes()
                .into_iter()
                .take(width)
        });
        let steps = moves
            .iter()
            .flatten()
            .flat_map(|&(_, [x, y])| [x as u8, y as u8]);
        counts.chain(codes).chain(steps).collect()
    }
}

/// The displacement from `from` to `to` in a tangent basis at `from`, in
/// units of `unit`, rounded to `i8`.
fn tangent(from: DVec3, to: DVec3, unit: f64) -> [i8; 2] {
    let east = from.cross(DVec3::Z).try_normalize().unwrap_or(DVec3::X);
    let north = from.cross(east);
    let d = to - from;
    [d.dot(east), d.dot(north)].map(|v| (v / unit).round().clamp(-127.0, 127.0) as i8)
}

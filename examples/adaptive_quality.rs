//! Issue 18's adaptive-quality measure: whether sets following a density
//! keep the uniform set's spacing away from the density's edges. For caps
//! of contrast 16 and 100, a lon/lat polygon of contrast 16, a smooth bump
//! of contrast 64 and generated environment maps, at each count, it takes
//! every density level and, of the level's points lying more than two local spacings from any
//! edge, the nearest-neighbour angle (to any point) times
//! `√(4π N pdf(x))`; its 1st percentile is compared with the same measure
//! on the uniform tessera set of the same count (floor: 0.85 times it).
//!
//!     cargo run --release --example adaptive_quality [-- --out docs/SPHERE_ADAPTIVE.md]
//!
//! Options: `--out PATH` (default `docs/SPHERE_ADAPTIVE.md`), `--counts
//! N,N,...` (default 3072,20000,50000,200000), `--maps NAME,...` (generated
//! skies by `tessera::synth::Sky::name`; default `smooth,clear-sky`),
//! `--relax K` (measure each adaptive set after K density-weighted Lloyd
//! iterations, `tessera::relax::relax`, against the unrelaxed uniform
//! set: whether the floor is within a sampler's reach).
//! About 20 s at the defaults.

mod args;

use glam::DVec3;
use kiddo::{ImmutableKdTree, SquaredEuclidean};
use std::collections::BTreeMap;
use std::f64::consts::PI;
use std::fmt::Write as _;
use std::time::Instant;
use tessera::baselines::spherical_fibonacci;
use tessera::density::envmap::{EnvMap, Up};
use tessera::density::region::Regions;
use tessera::density::sphere::SphereFn;
use tessera::density::Density;
use tessera::healpix::lonlat_to_vec;
use tessera::metrics::sphere::{geodesic_distance, nearest_angles};
use tessera::synth::Sky;
use tessera::tiling::sphere::SphereRegion;
use tessera::Sampler;

/// Issue 18's floor on a level's 1st percentile over the uniform set's.
const FLOOR: f64 = 0.85;

/// How many local spacings from an edge a point must lie to be measured.
const MARGIN: f64 = 2.0;

/// Boundary samples per local spacing of the denser side of an edge.
const SAMPLES_PER_SPACING: f64 = 8.0;

/// The cap of the two cap cases: centre (lon, lat) and radius, degrees.
const CAP: [f64; 3] = [20.0, 40.0, 25.0];

/// The smooth bump's width (degrees): its density is `1 + (C - 1)
/// exp(-(θ / BUMP_WIDTH)²)`, `θ` the angle from the cap's centre.
const BUMP_WIDTH: f64 = 15.0;

/// The polygon case's vertices (lon, lat in degrees; edges straight in the
/// lon/lat plane, as `Regions` reads them).
const POLYGON: [[f64; 2]; 5] = [
    [-10.0, 35.0],
    [40.0, 30.0],
    [55.0, 55.0],
    [20.0, 72.0],
    [-15.0, 62.0],
];

/// The map case's size and seed.
const MAP: (usize, usize, u64) = (512, 256, 1);

/// Where a density changes level, with the larger relative density
/// (`pdf · 4π`) of its two sides.
enum Edge {
    /// The rim of a cap: centre and radius (rad).
    Circle(DVec3, f64, f64),
    /// A segment straight in the lon/lat plane, ends in degrees.
    Segment([f64; 2], [f64; 2], f64),
}

/// A density to measure.
struct Case {
    /// Short name for the tables.
    name: String,
    /// The density, sampled in the world frame.
    density: Box<dyn Density<SphereRegion>>,
    /// Every edge between levels.
    edges: Vec<Edge>,
    /// Levels are octaves of the relative density (a map), not contrasts
    /// (regions).
    octaves: bool,
}

impl Case {
    /// The level of a direction: a region's contrast, or the octave
    /// `floor(log2(pdf · 4π))` of a map; `None` where the density is 0.
    fn level(&self, p: DVec3) -> Option<i32> {
        let v = self.density.value(p);
        match (v > 0.0, self.octaves) {
            (false, _) => None,
            (true, true) => Some((v / self.density.mean()).log2().floor() as i32),
            (true, false) => Some(v.round() as i32),
        }
    }

    /// A level's name in the tables.
    fn label(&self, level: i32) -> String {
        match self.octaves {
            true => format!("pdf·4π in [2^{level}, 2^{})", level + 1),
            false => format!("density {level}"),
        }
    }

    /// Points along every edge, at most 1/[`SAMPLES_PER_SPACING`] of the
    /// local spacing of its denser side apart for `n` points.
    fn boundary(&self, n: usize) -> Vec<DVec3> {
        let step = |relative: f64| spacing(n, relative) / SAMPLES_PER_SPACING;
        let mut out = Vec::new();
        for edge in &self.edges {
            match *edge {
                Edge::Circle(centre, radius, relative) => {
                    let u = centre.any_orthonormal_vector();
                    let v = centre.cross(u);
                    let k = (2.0 * PI * radius.sin() / step(relative)).ceil() as usize;
                    out.extend((0..k).map(|i| {
                        let t = 2.0 * PI * i as f64 / k as f64;
                        centre * radius.cos() + (u * t.cos() + v * t.sin()) * radius.sin()
                    }));
                }
                Edge::Segment(a, b, relative) => {
                    // the lon/lat length bounds the angle travelled
                    let length = (b[0] - a[0]).hypot(b[1] - a[1]).to_radians();
                    let k = (length / step(relative)).ceil().max(1.0) as usize;
                    out.extend((0..=k).map(|i| {
                        let t = i as f64 / k as f64;
                        lonlat_to_vec(a[0] + t * (b[0] - a[0]), a[1] + t * (b[1] - a[1]))
                    }));
                }
            }
        }
        out
    }
}

/// The local spacing `1 / √(N pdf)` (rad) at relative density `pdf · 4π`.
fn spacing(n: usize, relative: f64) -> f64 {
    (4.0 * PI / (n as f64 * relative)).sqrt()
}

/// A case of one `Regions` specification; `edges` gets the density's mean.
fn region_case(name: String, spec: String, edges: impl Fn(f64) -> Vec<Edge>) -> Case {
    let regions = Regions::parse(&[spec]).expect("a valid region");
    let mean = Density::<SphereRegion>::mean(&regions);
    Case {
        name,
        density: Box::new(regions),
        edges: edges(mean),
        octaves: false,
    }
}

/// A cap of [`CAP`] `contrast` times denser than the rest of the sphere.
fn cap_case(contrast: f64) -> Case {
    let [lon, lat, radius] = CAP;
    region_case(
        format!("cap contrast {contrast}"),
        format!("cap:{lon},{lat},{radius},{contrast}"),
        |mean| {
            vec![Edge::Circle(
                lonlat_to_vec(lon, lat),
                radius.to_radians(),
                contrast / mean,
            )]
        },
    )
}

/// [`POLYGON`], `contrast` times denser than the rest of the sphere.
fn polygon_case(contrast: f64) -> Case {
    let list: Vec<String> = POLYGON.iter().map(|[x, y]| format!("{x} {y}")).collect();
    let k = POLYGON.len();
    region_case(
        format!("polygon contrast {contrast}"),
        format!("polygon:{};{contrast}", list.join(",")),
        |mean| {
            (0..k)
                .map(|i| Edge::Segment(POLYGON[i], POLYGON[(i + 1) % k], contrast / mean))
                .collect()
        },
    )
}

/// A smooth bump of `contrast` about the cap's centre, as a geophysicist's
/// regional refinement: its levels are octaves and it has no edges, so
/// every point is measured, the bins changing from tile to tile. With
/// `relative`, its `SphereFn` also has a relative Lipschitz constant.
fn bump_case(contrast: f64, relative: bool) -> Case {
    let [lon, lat, _] = CAP;
    let centre = lonlat_to_vec(lon, lat);
    let width = BUMP_WIDTH.to_radians();
    let profile = move |theta: f64| 1.0 + (contrast - 1.0) * (-(theta / width).powi(2)).exp();
    let bump = move |v: DVec3| profile(geodesic_distance(centre, v));
    // |d/dθ| of (C - 1) exp(-(θ/w)²) peaks at θ = w / √2: (C - 1) √2 e^(-1/2) / w
    let lipschitz = (contrast - 1.0) * 2f64.sqrt() * (-0.5f64).exp() / width;
    let mut density = SphereFn::new(bump, lipschitz).expect("a positive density");
    let mut name = format!("bump contrast {contrast}");
    if relative {
        // |d ln f / dθ| = (2θ/w²) (f - 1) / f, its largest value on a fine
        // grid of θ (a smooth profile), with a margin
        let k = (1..=100_000)
            .map(|i| {
                let theta = 5.0 * width * i as f64 / 100_000.0;
                let f = profile(theta);
                2.0 * theta / width.powi(2) * (f - 1.0) / f
            })
            .fold(0.0, f64::max)
            * 1.001;
        density = density.with_relative_lipschitz(k).expect("k >= 0");
        name = format!("{name}, relative {k:.1}");
    }
    Case {
        name,
        density: Box::new(density),
        edges: Vec::new(),
        octaves: true,
    }
}

/// A generated sky, Z up; its edges are the pixel sides between pixels of
/// different octaves (a zero pixel is an octave of its own).
fn map_case(sky: Sky) -> Case {
    let (width, height, seed) = MAP;
    let map = EnvMap::new(sky.generate(width, height, seed).raster(), Up::Z).expect("a lit map");
    let mean = Density::<SphereRegion>::mean(&map);
    let relative: Vec<f64> = map.values().iter().map(|v| v / mean).collect();
    let octave = |r: f64| (r > 0.0).then(|| r.log2().floor() as i32);
    // column i starts at longitude 360 i / W, row j at latitude 90 - 180 j / H
    let lon = |i: usize| 360.0 * i as f64 / width as f64;
    let lat = |j: usize| 90.0 - 180.0 * j as f64 / height as f64;
    let mut edges = Vec::new();
    for j in 0..height {
        for i in 0..width {
            let here = relative[j * width + i];
            let right = relative[j * width + (i + 1) % width];
            if octave(here) != octave(right) {
                let (a, b) = ([lon(i + 1), lat(j)], [lon(i + 1), lat(j + 1)]);
                edges.push(Edge::Segment(a, b, here.max(right)));
            }
            if j + 1 < height {
                let below = relative[(j + 1) * width + i];
                if octave(here) != octave(below) {
                    let (a, b) = ([lon(i), lat(j + 1)], [lon(i + 1), lat(j + 1)]);
                    edges.push(Edge::Segment(a, b, here.max(below)));
                }
            }
        }
    }
    Case {
        name: format!("map {} {width}x{height}", sky.name()),
        density: Box::new(map),
        edges,
        octaves: true,
    }
}

/// A k-d tree over the points' coordinates.
fn tree(points: &[DVec3]) -> ImmutableKdTree<f64, 3> {
    let coords: Vec<[f64; 3]> = points.iter().map(|p| p.to_array()).collect();
    ImmutableKdTree::new_from_slice(&coords)
}

/// A sample's size, 1st percentile and median (nearest rank; NaN when
/// empty).
struct Stats {
    count: usize,
    p1: f64,
    median: f64,
}

/// The [`Stats`] of `values`.
fn stats(mut values: Vec<f64>) -> Stats {
    values.sort_by(f64::total_cmp);
    let rank = |q: f64| {
        let r = (q * values.len() as f64).ceil() as usize;
        values.get(r.max(1) - 1).copied().unwrap_or(f64::NAN)
    };
    Stats {
        count: values.len(),
        p1: rank(0.01),
        median: rank(0.5),
    }
}

/// Whether a direction lies in HEALPix's polar caps (`|z| > 2/3`), where
/// cells are sheared, rather than in its equatorial belt.
fn polar(p: DVec3) -> bool {
    p.z.abs() > 2.0 / 3.0
}

/// Normalised nearest-neighbour angles over a set and over the points of
/// its equatorial belt and of its polar caps.
struct Zoned {
    all: Stats,
    equatorial: Stats,
    polar: Stats,
}

/// [`Zoned`] statistics of `values` at `points`.
fn zoned(points: &[DVec3], values: &[f64]) -> Zoned {
    let pick = |want: bool| {
        let v = points
            .iter()
            .zip(values)
            .filter(|(p, _)| polar(**p) == want);
        stats(v.map(|(_, v)| *v).collect())
    };
    Zoned {
        all: stats(values.to_vec()),
        equatorial: pick(false),
        polar: pick(true),
    }
}

/// The normalised nearest-neighbour angles `√N · d` of a uniform set.
fn uniform_reference(points: &[DVec3]) -> Zoned {
    let root = (points.len() as f64).sqrt();
    let values: Vec<f64> = nearest_angles(points).iter().map(|d| d * root).collect();
    zoned(points, &values)
}

/// One level's measures.
struct Level {
    label: String,
    /// Every point of the level.
    all: Stats,
    /// The points more than [`MARGIN`] local spacings from every edge.
    inner: Zoned,
}

/// Samples `case` with `n` points and measures each level, densest first,
/// with the count of points where the density is 0.
fn measure(case: &Case, n: usize, relax: usize) -> (Vec<Level>, usize) {
    let sampler = Sampler::sphere().density(&*case.density).count(n);
    let mut points: Vec<DVec3> = sampler
        .generate()
        .expect("a valid request")
        .iter()
        .map(|s| s.position)
        .collect();
    tessera::relax::relax(&mut points, &*case.density, relax).expect("unit vectors");
    let angles = nearest_angles(&points);
    let boundary = case.boundary(n);
    // (a smooth density has no edges)
    let edge_tree = (!boundary.is_empty()).then(|| tree(&boundary));
    // per level: every value, and the inner points with their values
    type Bins = (Vec<f64>, Vec<DVec3>, Vec<f64>);
    let mut by_level: BTreeMap<i32, Bins> = BTreeMap::new();
    let mut unsupported = 0;
    for (p, angle) in points.iter().zip(&angles) {
        let Some(level) = case.level(*p) else {
            unsupported += 1;
            continue;
        };
        let relative = sampler.pdf(*p) * 4.0 * PI;
        let value = angle * (n as f64 * relative).sqrt();
        let to_edge = edge_tree.as_ref().map_or(f64::INFINITY, |edges| {
            let nearest = edges.nearest_one::<SquaredEuclidean>(&p.to_array());
            geodesic_distance(*p, boundary[nearest.item as usize])
        });
        let (all, inner, values) = by_level.entry(level).or_default();
        all.push(value);
        if to_edge > MARGIN * spacing(n, relative) {
            inner.push(*p);
            values.push(value);
        }
    }
    let levels = by_level
        .into_iter()
        .rev()
        .map(|(level, (all, inner, values))| Level {
            label: case.label(level),
            all: stats(all),
            inner: zoned(&inner, &values),
        })
        .collect();
    (levels, unsupported)
}

fn main() {
    let mut out = String::from("docs/SPHERE_ADAPTIVE.md");
    let mut counts = vec![3072usize, 20_000, 50_000, 200_000];
    let mut skies = vec![Sky::Smooth, Sky::ClearSky];
    let mut relax = 0;
    let (command, list) = args::command_line("adaptive_quality");
    let mut it = list.into_iter();
    while let Some(a) = it.next() {
        let mut value = || it.next().unwrap_or_else(|| panic!("{a} needs a value"));
        match a.as_str() {
            "--out" => out = value(),
            "--counts" => {
                counts = value()
                    .split(',')
                    .map(|c| c.parse().expect("--counts N,N,..."))
                    .collect()
            }
            "--maps" => {
                skies = value()
                    .split(',')
                    .map(|m| Sky::from_name(m).expect("--maps: synth::Sky names"))
                    .collect()
            }
            "--relax" => relax = value().parse().expect("--relax K"),
            other => panic!("unknown option {other}"),
        }
    }
    let start = Instant::now();
    let mut cases = vec![cap_case(16.0), cap_case(100.0), polygon_case(16.0)];
    cases.extend([bump_case(64.0, false), bump_case(64.0, true)]);
    cases.extend(skies.iter().map(|&sky| map_case(sky)));
    let mut runs = Vec::new();
    for &n in &counts {
        let uniform: Vec<DVec3> = Sampler::sphere()
            .count(n)
            .generate()
            .expect("a uniform set")
            .iter()
            .map(|s| s.position)
            .collect();
        runs.push(Run {
            n,
            reference: uniform_reference(&uniform),
            fibonacci: uniform_reference(&spherical_fibonacci(n)),
            cases: cases.iter().map(|case| measure(case, n, relax)).collect(),
        });
        eprintln!("N = {n} done at {:.1} s", start.elapsed().as_secs_f64());
    }
    let wall = start.elapsed().as_secs_f64();
    let page = report(&cases, &skies, &runs, (&command, relax), wall);
    std::fs::write(&out, &page).expect("write the report");
    println!("{}", summary(&cases, &runs));
    eprintln!("wrote {out} ({wall:.1} s)");
}

/// One count's results.
struct Run {
    n: usize,
    /// tessera's uniform set of `n` points.
    reference: Zoned,
    /// The spherical Fibonacci lattice of `n` points.
    fibonacci: Zoned,
    /// Each case's levels, and its points where the density is 0.
    cases: Vec<(Vec<Level>, usize)>,
}

/// A 1st percentile over a reference's, in bold under the floor (`-` for
/// no points, `~` appended under 100 points, where the 1st percentile is
/// the smallest value or nearly).
fn ratio(stats: &Stats, reference: &Stats) -> String {
    let r = stats.p1 / reference.p1;
    let few = if stats.count < 100 { "~" } else { "" };
    match r >= FLOOR {
        _ if stats.count == 0 => "-".into(),
        true => format!("{r:.3}{few}"),
        false => format!("**{r:.3}**{few}"),
    }
}

/// A value to three decimals, `-` for NaN (no points).
fn value(x: f64) -> String {
    match x.is_nan() {
        true => "-".into(),
        false => format!("{x:.3}"),
    }
}

/// The table of ratios: a row per case and level, a column per count.
fn summary(cases: &[Case], runs: &[Run]) -> String {
    let mut s = String::from("| case | level |");
    for run in runs {
        let _ = write!(s, " N = {} |", run.n);
    }
    let _ = writeln!(s, "\n|---|---|{}", "---|".repeat(runs.len()));
    for (c, case) in cases.iter().enumerate() {
        let mut labels: Vec<&str> = Vec::new();
        for run in runs {
            for level in &run.cases[c].0 {
                if !labels.contains(&level.label.as_str()) {
                    labels.push(&level.label);
                }
            }
        }
        for label in labels {
            let _ = write!(s, "| {} | {label} |", case.name);
            for run in runs {
                let cell = run.cases[c].0.iter().find(|l| l.label == label);
                let _ = match cell {
                    Some(l) => write!(s, " {} |", ratio(&l.inner.all, &run.reference.all)),
                    None => write!(s, " - |"),
                };
            }
            let _ = writeln!(s);
        }
    }
    s
}

/// The generated page.
fn report(
    cases: &[Case],
    skies: &[Sky],
    runs: &[Run],
    (command, relax): (&str, usize),
    wall: f64,
) -> String {
    let mut s = String::new();
    let _ = writeln!(s, "# Adaptive sphere sets away from density edges\n");
    let _ = writeln!(
        s,
        "Generated by `{command}` ({wall:.1} s wall, {} threads). Do not edit by hand.\n",
        rayon::current_num_threads()
    );
    let [lon, lat, radius] = CAP;
    let (width, height, seed) = MAP;
    let polygon: Vec<String> = POLYGON.iter().map(|[x, y]| format!("{x} {y}")).collect();
    let skies: Vec<String> = skies.iter().map(|s| format!("`{}`", s.name())).collect();
    let _ = writeln!(
        s,
        "Issue 18 asks that adaptive sets keep the uniform set's quality away from density \
         edges: in each density level, the points more than {MARGIN} local spacings from an \
         edge have a normalised nearest-neighbour distance whose 1st percentile is at least \
         {FLOOR} times the uniform set's.\n\n\
         - **Sets**: `Sampler::sphere().density(D).count(N)`, in the world frame (no seed). \
         **cap contrast C**: `cap:{lon},{lat},{radius},C` (`Regions`), C times denser inside. \
         **polygon contrast 16**: `polygon:{};16`, edges straight in the lon/lat plane. \
         **bump contrast 64**: `1 + 63 exp(-(θ/{BUMP_WIDTH}°)²)`, `θ` the angle from the cap's \
         centre, a smooth regional refinement, as a `SphereFn` with its Lipschitz constant \
         (tile bounds `f + L d`, `f` the largest value at the tile's cell centres and `d` \
         `SphereRegion::cell_reach`) and with a relative one too (`|∇f| / f <= k`, \
         `SphereFn::with_relative_lipschitz`: also `f e^(k d)`). \
         **map**: the generated skies {} (`synth::Sky`; `--maps`) at {width}x{height}, seed \
         {seed}, as luminance (`SynthMap::raster`, `EnvMap::new`, Z up).{}\n\
         - **pdf**: the density the samples follow, per steradian, integrating to 1 over the \
         sphere (`Sampler::pdf`); a uniform set has `pdf = 1/(4π)`. The local spacing is \
         `1/√(N pdf(x))` radians, the normalisation of `metrics::sphere::local_spacing`.\n\
         - **Levels**: a region density's contrast (1 outside, C inside); for a map and the \
         bump, the octave of `pdf · 4π` (the pixels or points with `2^k <= pdf · 4π < 2^(k+1)` \
         form a level), zero pixels being a level without points.\n\
         - **Edges**: the rim of the cap, the polygon's sides, and for a map every pixel side \
         between pixels of different levels (steps of less than an octave inside a level are \
         not edges); the bump has none, every point of it is measured. The distance from a \
         point to the edges is its angle to the nearest of points placed along every edge at \
         most 1/{SAMPLES_PER_SPACING} of the local spacing of the edge's denser side apart, so \
         it reads at most 1/{} of a spacing long. A point is measured when that distance \
         exceeds {MARGIN} of its own local spacings.\n\
         - **Measure**: each point's geodesic angle to its nearest other point (of the whole \
         set, any level), times `√(4π N pdf(x))` (`√N` for a uniform set); 1st percentile \
         and median by nearest rank. **Reference**: the same over tessera's uniform set of the \
         same N (`Sampler::sphere().count(N)`); **ratio**: a level's 1st percentile over the \
         reference's, in bold below {FLOOR}; `~` marks fewer than 100 points measured, `-` \
         none. The spherical Fibonacci lattice is shown for context. **Zones**: HEALPix's \
         equatorial belt `|z| <= 2/3` and polar caps `|z| > 2/3`, where the cells are \
         sheared; a zone's ratio is over the uniform set's 1st percentile in the same zone.\n",
        polygon.join(","),
        skies.join(" and "),
        match relax {
            0 => String::new(),
            k => format!(
                " **Relaxed**: each adaptive set after {k} density-weighted Lloyd iterations \
                 (`tessera::relax::relax`, `--relax`); the reference stays unrelaxed."
            ),
        },
        2.0 * SAMPLES_PER_SPACING,
    );
    let _ = writeln!(s, "## Ratios\n\n{}", summary(cases, runs));
    let _ = writeln!(s, "## References\n");
    let _ = writeln!(
        s,
        "Normalised nearest-neighbour distance of uniform sets: 1st percentile (equatorial / \
         polar) and median.\n"
    );
    let _ = writeln!(s, "| N | tessera 1st percentile | equatorial / polar | median | Fibonacci 1st percentile | median |");
    let _ = writeln!(s, "|---|---|---|---|---|---|");
    for run in runs {
        let (t, f) = (&run.reference, &run.fibonacci);
        let _ = writeln!(
            s,
            "| {} | {:.3} | {:.3} / {:.3} | {:.3} | {:.3} | {:.3} |",
            run.n, t.all.p1, t.equatorial.p1, t.polar.p1, t.all.median, f.all.p1, f.all.median
        );
    }
    for run in runs {
        let _ = writeln!(s, "\n## N = {}\n", run.n);
        let _ = writeln!(
            s,
            "\"points\": in the level; \"measured\": beyond {MARGIN} spacings from an edge; \
             \"all\": over every point of the level, edges included.\n"
        );
        let _ = writeln!(s, "| case | level | points | measured | 1st percentile | median | ratio | equatorial: measured, ratio | polar: measured, ratio | all: 1st percentile |");
        let _ = writeln!(s, "|---|---|---|---|---|---|---|---|---|---|");
        for (case, (levels, unsupported)) in cases.iter().zip(&run.cases) {
            for l in levels {
                let z = &l.inner;
                let _ = writeln!(
                    s,
                    "| {} | {} | {} | {} | {} | {} | {} | {}, {} | {}, {} | {} |",
                    case.name,
                    l.label,
                    l.all.count,
                    z.all.count,
                    value(z.all.p1),
                    value(z.all.median),
                    ratio(&z.all, &run.reference.all),
                    z.equatorial.count,
                    ratio(&z.equatorial, &run.reference.equatorial),
                    z.polar.count,
                    ratio(&z.polar, &run.reference.polar),
                    value(l.all.p1)
                );
            }
            if *unsupported > 0 {
                let _ = writeln!(
                    s,
                    "| {} | zero density | {unsupported} | - | - | - | - | - | - | - |",
                    case.name
                );
            }
        }
    }
    s
}

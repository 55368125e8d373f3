//! The spherical Voronoi cells of a set of generators, integrated over a
//! lat-long map constant per pixel.
//!
//! Work is in the map's Z-up frame, with each pixel the rectangle
//! `[phi0, phi1] x [z0, z1]` (`z = cos theta`): equal steps in `phi` and `z`
//! cut it into equal-area pieces. Pixels are visited in blocks; a block's
//! candidate generators are those within `d1 + 2 rho` (chord) of its centre,
//! `d1` the nearest generator's chord distance and `rho` the largest chord
//! from the centre to the block (attained at a corner), so every point of
//! the block has its nearest generator among them. A pixel whose nearest
//! and second-nearest candidates differ in distance by more than `2 rho`
//! lies in one cell (triangle inequality) and is given to it whole, with
//! its exact first moment. Other pixels are split into 2 x 2 equal-area
//! pieces, recursively, while a piece is ambiguous and holds more than the
//! tolerance (of mass or of area) or contains a generator; an ambiguous
//! piece left unsplit goes to the generator nearest its centre and is
//! counted as unresolved. Every piece goes to exactly one cell, so the
//! cells' masses always sum to the map's integral.

use glam::DVec3;
use kiddo::{ImmutableKdTree, SquaredEuclidean};
use rayon::prelude::*;
use std::f64::consts::{PI, TAU};

/// Deepest split of a pixel (pieces of 4^-24 of it).
const MAX_DEPTH: usize = 24;

/// Largest candidate list of a block before it is split into four.
const MAX_CANDIDATES: usize = 24;

/// Per-pixel geometry of a `W x H` lat-long map and its values.
pub(super) struct Grid<'a> {
    pub width: usize,
    pub height: usize,
    /// Importance per pixel (row-major).
    pub values: &'a [f64],
    /// Colour per pixel, or the importance in every channel.
    pub rgb: Option<&'a [[f32; 3]]>,
    /// `cos(j pi / H)`, `j = 0..=H` (decreasing).
    z_edge: Vec<f64>,
    /// Solid angle of a pixel of each row (as the map's integral uses it).
    row_area: Vec<f64>,
    /// Equal-area centre of each row: `z` and `sqrt(1 - z^2)`.
    row_z: Vec<f64>,
    row_s: Vec<f64>,
    /// Largest chord from a pixel's centre to its corners, per row.
    row_rho: Vec<f64>,
    /// Row parts of a pixel's exact first moment `integral of w dw`:
    /// `integral of sqrt(1 - z^2) dz` and `integral of z dz` over the row.
    row_ms: Vec<f64>,
    row_mz: Vec<f64>,
    /// Centre azimuth of each column: cos and sin.
    col_cos: Vec<f64>,
    col_sin: Vec<f64>,
    /// Column parts of the first moment: `sin phi1 - sin phi0` and
    /// `cos phi0 - cos phi1`.
    col_mc: Vec<f64>,
    col_ms: Vec<f64>,
    /// `1 - cos(h)` for the half-width `h` in azimuth of a piece at each depth.
    versine: Vec<f64>,
    /// cos and sin of half the half-width in azimuth of a piece at each
    /// depth (the offset of its children's centres).
    quarter: Vec<[f64; 2]>,
}

/// `(z sqrt(1 - z^2) + asin z) / 2`, an antiderivative of `sqrt(1 - z^2)`.
fn half_disc(z: f64) -> f64 {
    let z = z.clamp(-1.0, 1.0);
    (z * ((1.0 - z) * (1.0 + z)).sqrt() + z.asin()) / 2.0
}

fn sin_of(z: f64) -> f64 {
    ((1.0 - z) * (1.0 + z)).max(0.0).sqrt()
}

/// Largest chord from the centre of `[phi0, phi1] x [z0, z1]` to its
/// corners (the largest to any of its points), given `1 - cos` of the
/// half-width in azimuth.
fn corner_chord(z0: f64, z1: f64, versine: f64) -> f64 {
    let zc = (z0 + z1) / 2.0;
    let sc = sin_of(zc);
    let hz = (z1 - z0) / 2.0;
    let d2 = |z: f64| {
        let s = sin_of(z);
        hz * hz + (s - sc) * (s - sc) + 2.0 * s * sc * versine
    };
    d2(z0).max(d2(z1)).sqrt()
}

impl<'a> Grid<'a> {
    /// The grid of a map: `values` row-major `width x height`, `row_area`
    /// the solid angle of one pixel of each row.
    pub fn new(
        width: usize,
        height: usize,
        values: &'a [f64],
        rgb: Option<&'a [[f32; 3]]>,
        row_area: Vec<f64>,
    ) -> Self {
        let z_edge: Vec<f64> = (0..=height)
            .map(|j| {
                if j == 0 {
                    1.0
                } else if j == height {
                    -1.0
                } else {
                    (j as f64 * PI / height as f64).cos()
                }
            })
            .collect();
        let dphi = TAU / width as f64;
        let versine: Vec<f64> = (0..=MAX_DEPTH + 1)
            .map(|d| {
                let h = dphi / 2f64.powi(d as i32 + 1);
                2.0 * (h / 2.0).sin().powi(2)
            })
            .collect();
        let quarter: Vec<[f64; 2]> = (0..=MAX_DEPTH + 1)
            .map(|d| {
                let (s, c) = (dphi / 2f64.powi(d as i32 + 2)).sin_cos();
                [c, s]
            })
            .collect();
        let (mut row_z, mut row_s, mut row_rho, mut row_ms, mut row_mz) =
            (vec![], vec![], vec![], vec![], vec![]);
        for j in 0..height {
            let (top, bottom) = (z_edge[j], z_edge[j + 1]);
            let zc = (top + bottom) / 2.0;
            row_z.push(zc);
            row_s.push(sin_of(zc));
            row_rho.push(corner_chord(bottom, top, versine[0]));
            row_ms.push(half_disc(top) - half_disc(bottom));
            row_mz.push((top - bottom) * (top + bottom) / 2.0);
        }
        let (mut col_cos, mut col_sin, mut col_mc, mut col_ms) = (vec![], vec![], vec![], vec![]);
        for i in 0..width {
            let (s, c) = ((i as f64 + 0.5) * dphi).sin_cos();
            col_cos.push(c);
            col_sin.push(s);
            let (s0, c0) = (i as f64 * dphi).sin_cos();
            let (s1, c1) = ((i + 1) as f64 * dphi).sin_cos();
            col_mc.push(s1 - s0);
            col_ms.push(c0 - c1);
        }
        Grid {
            width,
            height,
            values,
            rgb,
            z_edge,
            row_area,
            row_z,
            row_s,
            row_rho,
            row_ms,
            row_mz,
            col_cos,
            col_sin,
            col_mc,
            col_ms,
            versine,
            quarter,
        }
    }

    /// `[phi0, phi1] x [z0, z1]` of the block of columns `i0..i1`, rows `j0..j1`.
    fn rect(&self, i0: usize, i1: usize, j0: usize, j1: usize) -> [f64; 4] {
        let dphi = TAU / self.width as f64;
        [
            i0 as f64 * dphi,
            i1 as f64 * dphi,
            self.z_edge[j1],
            self.z_edge[j0],
        ]
    }
}

/// What one cell collects: mass (importance x sr), solid angle, the three
/// channels' powers and the importance-weighted first moment.
pub(super) type Acc = [f64; 8];

/// The cells of one set of generators.
pub(super) struct Cells {
    /// Per generator, see [`Acc`].
    pub acc: Vec<Acc>,
    /// Mass of the ambiguous pieces given whole to the generator nearest
    /// their centre (an upper bound of the mass that may be in the wrong cell).
    pub unresolved_mass: f64,
    /// Their solid angle.
    pub unresolved_area: f64,
    /// Pixels that had to be split.
    pub split_pixels: usize,
    /// Pieces assigned (whole pixels included).
    pub pieces: usize,
}

/// Generators in the map frame, with their `(phi, z)`.
pub(super) struct Generators {
    pub points: Vec<DVec3>,
    phi: Vec<f64>,
    z: Vec<f64>,
    tree: ImmutableKdTree<f64, 3>,
}

impl Generators {
    /// Unit vectors in the map frame (at least one).
    pub fn new(points: Vec<DVec3>) -> Self {
        let coords: Vec<[f64; 3]> = points.iter().map(|p| p.to_array()).collect();
        let tree = ImmutableKdTree::new_from_slice(&coords);
        let phi = points
            .iter()
            .map(|p| {
                let a = p.y.atan2(p.x);
                if a < 0.0 {
                    a + TAU
                } else {
                    a
                }
            })
            .collect();
        let z = points.iter().map(|p| p.z).collect();
        Generators {
            points,
            phi,
            z,
            tree,
        }
    }
}

/// Per-thread scratch: a dense accumulator with the list of what it touched.
struct Scratch {
    acc: Vec<Acc>,
    touched: Vec<u32>,
    seen: Vec<bool>,
    arena: Vec<u32>,
    stack: Vec<Node>,
    candidates: Vec<u32>,
    shares: Vec<(u32, f64, DVec3)>,
    polygons: [Vec<[f64; 2]>; 2],
    lin: Vec<[f64; 3]>,
}

/// A piece of a pixel: `[phi0, phi1] x [z0, z1]` at `depth`, with its
/// candidates `arena[start..start + len]`.
#[derive(Clone, Copy)]
struct Node {
    rect: [f64; 4],
    /// Its polar angles: `acos(z1)` and `acos(z0)`.
    theta: [f64; 2],
    /// cos and sin of the centre's azimuth.
    cs: [f64; 2],
    depth: usize,
    start: usize,
    len: usize,
}

/// One band's contribution: touched generators in increasing order.
struct Band {
    sums: Vec<(u32, Acc)>,
    unresolved_mass: f64,
    unresolved_area: f64,
    split_pixels: usize,
    pieces: usize,
}

struct Ctx<'g, 'a> {
    grid: &'g Grid<'a>,
    gens: &'g Generators,
    tol_mass: f64,
    tol_area: f64,
}

/// Nearest and second-nearest (chord) of `c` among `list`: (index, d1, d2),
/// `d2` infinite for a single candidate. Ties go to the lower index.
#[inline]
fn nearest_two(points: &[DVec3], list: &[u32], c: DVec3) -> (u32, f64, f64) {
    let (mut best, mut d1, mut d2) = (u32::MAX, f64::INFINITY, f64::INFINITY);
    for &k in list {
        let d = (points[k as usize] - c).length_squared();
        if d < d1 || (d == d1 && k < best) {
            d2 = d1;
            d1 = d;
            best = k;
        } else if d < d2 {
            d2 = d;
        }
    }
    (best, d1.sqrt(), d2.sqrt())
}

/// Whether the gap between the two nearest proves one cell holds the piece.
#[inline]
fn decided(d1: f64, d2: f64, rho: f64) -> bool {
    d2 - d1 > 2.0 * rho * (1.0 + 1e-9) + 1e-14
}

impl Scratch {
    fn add(&mut self, k: u32, a: &Acc) {
        let ku = k as usize;
        if !self.seen[ku] {
            self.seen[ku] = true;
            self.touched.push(k);
        }
        for (s, v) in self.acc[ku].iter_mut().zip(a) {
            *s += v;
        }
    }

    fn take(&mut self) -> Vec<(u32, Acc)> {
        self.touched.sort_unstable();
        let out = self
            .touched
            .iter()
            .map(|&k| {
                let ku = k as usize;
                self.seen[ku] = false;
                (k, std::mem::take(&mut self.acc[ku]))
            })
            .collect();
        self.touched.clear();
        out
    }
}

impl Ctx<'_, '_> {
    fn colour(&self, p: usize) -> [f64; 3] {
        match self.grid.rgb {
            Some(rgb) => rgb[p].map(|c| c as f64),
            None => [self.grid.values[p]; 3],
        }
    }

    /// Candidates of the block `i0..i1 x j0..j1` into `out` (sorted).
    fn block_candidates(&self, i0: usize, i1: usize, j0: usize, j1: usize, out: &mut Vec<u32>) {
        let [p0, p1, z0, z1] = self.grid.rect(i0, i1, j0, j1);
        let h = (p1 - p0) / 2.0;
        let rho = corner_chord(z0, z1, 2.0 * (h / 2.0).sin().powi(2));
        let zc = (z0 + z1) / 2.0;
        let (s, c) = ((p0 + p1) / 2.0).sin_cos();
        let sc = sin_of(zc);
        let q = [sc * c, sc * s, zc];
        let nearest = self.gens.tree.nearest_one::<SquaredEuclidean>(&q);
        let r = nearest.distance.sqrt() + 2.0 * rho;
        let r = r * (1.0 + 1e-9) + 1e-12;
        out.clear();
        out.extend(
            self.gens
                .tree
                .within_unsorted::<SquaredEuclidean>(&q, r * r)
                .iter()
                .map(|n| n.item as u32),
        );
        out.sort_unstable();
    }

    fn block(&self, s: &mut Scratch, band: &mut Band, i0: usize, i1: usize, j0: usize, j1: usize) {
        let mut list = std::mem::take(&mut s.candidates);
        self.block_candidates(i0, i1, j0, j1, &mut list);
        if list.len() > MAX_CANDIDATES && (i1 - i0 > 1 || j1 - j0 > 1) {
            s.candidates = list;
            let im = if i1 - i0 > 1 { (i0 + i1) / 2 } else { i1 };
            let jm = if j1 - j0 > 1 { (j0 + j1) / 2 } else { j1 };
            for (a0, a1) in [(i0, im), (im, i1)] {
                for (b0, b1) in [(j0, jm), (jm, j1)] {
                    if a0 < a1 && b0 < b1 {
                        self.block(s, band, a0, a1, b0, b1);
                    }
                }
            }
            return;
        }
        let g = self.grid;
        let points = &self.gens.points;
        for j in j0..j1 {
            let (z, sj, rho) = (g.row_z[j], g.row_s[j], g.row_rho[j]);
            let area = g.row_area[j];
            for i in i0..i1 {
                let c = DVec3::new(sj * g.col_cos[i], sj * g.col_sin[i], z);
                let (k, d1, d2) = nearest_two(points, &list, c);
                let p = j * g.width + i;
                let v = g.values[p];
                if decided(d1, d2, rho) {
                    let rgb = self.colour(p);
                    let ms = g.row_ms[j];
                    s.add(
                        k,
                        &[
                            v * area,
                            area,
                            rgb[0] * area,
                            rgb[1] * area,
                            rgb[2] * area,
                            v * ms * g.col_mc[i],
                            v * ms * g.col_ms[i],
                            v * TAU / g.width as f64 * g.row_mz[j],
                        ],
                    );
                    band.pieces += 1;
                } else {
                    band.split_pixels += 1;
                    self.split(s, band, i, j, &list, c, d1, rho);
                }
            }
        }
        s.candidates = list;
    }

    /// Assigns pixel `(i, j)` piece by piece; `c`, `d1`, `rho` are its
    /// centre, nearest distance and corner chord.
    #[allow(clippy::too_many_arguments)]
    fn split(
        &self,
        s: &mut Scratch,
        band: &mut Band,
        i: usize,
        j: usize,
        list: &[u32],
        c: DVec3,
        d1: f64,
        rho: f64,
    ) {
        let g = self.grid;
        let points = &self.gens.points;
        let p = j * g.width + i;
        let v = g.values[p];
        let rgb = self.colour(p);
        let area0 = g.row_area[j];
        s.arena.clear();
        s.stack.clear();
        let reach = d1 + 2.0 * rho;
        let reach = reach * (1.0 + 1e-9) + 1e-12;
        s.arena.extend(
            list.iter()
                .copied()
                .filter(|&k| (points[k as usize] - c).length() <= reach),
        );
        let len = s.arena.len();
        s.stack.push(Node {
            rect: g.rect(i, i + 1, j, j + 1),
            theta: [
                j as f64 * PI / g.height as f64,
                (j + 1) as f64 * PI / g.height as f64,
            ],
            cs: [g.col_cos[i], g.col_sin[i]],
            depth: 0,
            start: 0,
            len,
        });
        while let Some(node) = s.stack.pop() {
            s.arena.truncate(node.start + node.len);
            let [p0, p1, z0, z1] = node.rect;
            let zc = (z0 + z1) / 2.0;
            let sc = sin_of(zc);
            let [cs, sn] = node.cs;
            let c = DVec3::new(sc * cs, sc * sn, zc);
            let rho = corner_chord(z0, z1, g.versine[node.depth]);
            let cands = &s.arena[node.start..node.start + node.len];
            let (k, d1, d2) = nearest_two(points, cands, c);
            let scale = 0.25f64.powi(node.depth as i32);
            let (mass, area) = (v * area0 * scale, area0 * scale);
            if !decided(d1, d2, rho) {
                let contains = || {
                    cands.iter().any(|&k| {
                        let (phi, z) = (self.gens.phi[k as usize], self.gens.z[k as usize]);
                        phi >= p0 && phi < p1 && z >= z0 && z <= z1
                    })
                };
                let wanted = mass > self.tol_mass || area > self.tol_area || contains();
                if wanted && node.depth < MAX_DEPTH {
                    let reach = (d1 + 2.0 * rho) * (1.0 + 1e-9) + 1e-12;
                    let start = s.arena.len();
                    for a in node.start..node.start + node.len {
                        let k = s.arena[a];
                        if (points[k as usize] - c).length() <= reach {
                            s.arena.push(k);
                        }
                    }
                    let len = s.arena.len() - start;
                    let (pm, zm) = ((p0 + p1) / 2.0, zc);
                    // the children's centre azimuths by rotation
                    let [cd, sd] = g.quarter[node.depth];
                    let right = [cs * cd - sn * sd, sn * cd + cs * sd];
                    let left = [cs * cd + sn * sd, sn * cd - cs * sd];
                    let [t0, t1] = node.theta;
                    let tm = zm.clamp(-1.0, 1.0).acos();
                    for (rect, theta, cs) in [
                        ([pm, p1, zm, z1], [t0, tm], right),
                        ([p0, pm, zm, z1], [t0, tm], left),
                        ([pm, p1, z0, zm], [tm, t1], right),
                        ([p0, pm, z0, zm], [tm, t1], left),
                    ] {
                        s.stack.push(Node {
                            rect,
                            theta,
                            cs,
                            depth: node.depth + 1,
                            start,
                            len,
                        });
                    }
                    continue;
                }
                band.unresolved_mass += mass;
                band.unresolved_area += area;
                band.pieces += 1;
                let (start, len) = (node.start, node.len);
                let mut shares = std::mem::take(&mut s.shares);
                clip_shares(
                    points,
                    &s.arena[start..start + len],
                    &node,
                    &mut shares,
                    &mut s.polygons,
                    &mut s.lin,
                );
                if !shares.is_empty() {
                    for &(k, f, d) in &shares {
                        let (m, a) = (mass * f, area * f);
                        s.add(
                            k,
                            &[
                                m,
                                a,
                                rgb[0] * a,
                                rgb[1] * a,
                                rgb[2] * a,
                                m * d.x,
                                m * d.y,
                                m * d.z,
                            ],
                        );
                    }
                    s.shares = shares;
                    continue;
                }
                s.shares = shares;
            } else {
                band.pieces += 1;
            }
            // midpoint rule for the moment of a piece
            s.add(
                k,
                &[
                    mass,
                    area,
                    rgb[0] * area,
                    rgb[1] * area,
                    rgb[2] * area,
                    mass * c.x,
                    mass * c.y,
                    mass * c.z,
                ],
            );
        }
    }
}

/// Splits the piece `[phi0, phi1] x [z0, z1]` among `cands` along their
/// bisectors linearised at its centre in `(phi, theta)` (whose second
/// derivatives stay bounded at the poles, unlike `z`'s): each candidate's
/// polygon is the rectangle clipped by its half-planes against the others,
/// and its area is weighted by `sin theta` taken linear across the piece
/// (exact through the polygon's centroid). The linearised regions partition
/// the rectangle (the differences of linear functions are consistent), so
/// the shares are normalised to sum to 1. Writes `(candidate, share of the
/// area, direction of the polygon's centroid)`; nothing when every share
/// vanishes in rounding.
fn clip_shares(
    points: &[DVec3],
    cands: &[u32],
    node: &Node,
    out: &mut Vec<(u32, f64, DVec3)>,
    polygons: &mut [Vec<[f64; 2]>; 2],
    lin: &mut Vec<[f64; 3]>,
) {
    out.clear();
    let [p0, p1, _, _] = node.rect;
    let [t0, t1] = node.theta;
    let [cs, sn] = node.cs;
    let tc = (t0 + t1) / 2.0;
    let (hp, ht) = ((p1 - p0) / 2.0, (t1 - t0) / 2.0);
    let (st, ct) = tc.sin_cos();
    let c = DVec3::new(st * cs, st * sn, ct);
    // d omega / d u and d omega / d v for u = (phi - pc) / hp, v = (theta - tc) / ht
    let du = DVec3::new(-st * sn, st * cs, 0.0) * hp;
    let dv = DVec3::new(ct * cs, ct * sn, -st) * ht;
    // k . omega ~ k.c + (k.du) u + (k.dv) v: larger is nearer
    lin.clear();
    lin.extend(cands.iter().map(|&k| {
        let p = points[k as usize];
        [p.dot(c), p.dot(du), p.dot(dv)]
    }));
    let mut total = 0.0;
    for (a, la) in lin.iter().enumerate() {
        let [poly, next] = polygons;
        poly.clear();
        poly.extend([[-1.0, -1.0], [1.0, -1.0], [1.0, 1.0], [-1.0, 1.0]]);
        for (b, lb) in lin.iter().enumerate() {
            if a == b || poly.is_empty() {
                continue;
            }
            // a wins where (la - lb) . (1, u, v) >= 0; ties to the lower index
            let g = [la[0] - lb[0], la[1] - lb[1], la[2] - lb[2]];
            let value = |q: &[f64; 2]| g[0] + g[1] * q[0] + g[2] * q[1];
            let keep = |x: f64| if a < b { x >= 0.0 } else { x > 0.0 };
            next.clear();
            for i in 0..poly.len() {
                let (q, r) = (poly[i], poly[(i + 1) % poly.len()]);
                let (fq, fr) = (value(&q), value(&r));
                if keep(fq) {
                    next.push(q);
                }
                if keep(fq) != keep(fr) {
                    let t = fq / (fq - fr);
                    next.push([q[0] + t * (r[0] - q[0]), q[1] + t * (r[1] - q[1])]);
                }
            }
            std::mem::swap(poly, next);
        }
        // shoelace area and centroid
        let (mut area2, mut cu, mut cv) = (0.0, 0.0, 0.0);
        for i in 0..poly.len() {
            let (q, r) = (poly[i], poly[(i + 1) % poly.len()]);
            let cross = q[0] * r[1] - r[0] * q[1];
            area2 += cross;
            cu += (q[0] + r[0]) * cross;
            cv += (q[1] + r[1]) * cross;
        }
        if area2 > 0.0 {
            let (u, v) = (cu / (3.0 * area2), cv / (3.0 * area2));
            let weight = area2 * (st + ct * ht * v).max(0.0);
            // the centroid's direction, to second order in the piece's size
            let d = (c + du * u + dv * v).normalize();
            out.push((cands[a], weight, d));
            total += weight;
        }
    }
    if total > 0.0 {
        for share in out.iter_mut() {
            share.1 /= total;
        }
    } else {
        out.clear();
    }
}

/// The cells of `gens` over the grid: pieces are refined while they hold
/// more than `tol_mass` of mass or `tol_area` of solid angle.
pub(super) fn cells(grid: &Grid, gens: &Generators, tol_mass: f64, tol_area: f64) -> Cells {
    let n = gens.points.len();
    let (w, h) = (grid.width, grid.height);
    // blocks of about the generators' spacing: each costs two k-d tree
    // queries, which dominated the Lloyd steps' passes at half the spacing
    // (N = 4096 on 1024 x 512, one thread: about 85 against 50 ms a step,
    // `cargo bench --bench lights`)
    let side = ((w * h) as f64 / n as f64).sqrt();
    let side = (side as usize).clamp(1, 32);
    let ctx = Ctx {
        grid,
        gens,
        tol_mass,
        tol_area,
    };
    let bands: Vec<Band> = (0..h.div_ceil(side))
        .into_par_iter()
        .map_init(
            || Scratch {
                acc: vec![[0.0; 8]; n],
                touched: Vec::new(),
                seen: vec![false; n],
                arena: Vec::new(),
                stack: Vec::new(),
                candidates: Vec::new(),
                shares: Vec::new(),
                polygons: [Vec::new(), Vec::new()],
                lin: Vec::new(),
            },
            |s, b| {
                let (j0, j1) = (b * side, ((b + 1) * side).min(h));
                let mut band = Band {
                    sums: Vec::new(),
                    unresolved_mass: 0.0,
                    unresolved_area: 0.0,
                    split_pixels: 0,
                    pieces: 0,
                };
                let mut i0 = 0;
                while i0 < w {
                    let i1 = (i0 + side).min(w);
                    ctx.block(s, &mut band, i0, i1, j0, j1);
                    i0 = i1;
                }
                band.sums = s.take();
                band
            },
        )
        .collect();
    let mut out = Cells {
        acc: vec![[0.0; 8]; n],
        unresolved_mass: 0.0,
        unresolved_area: 0.0,
        split_pixels: 0,
        pieces: 0,
    };
    // in band order: the result does not depend on the thread count
    for band in bands {
        for (k, a) in band.sums {
            for (s, v) in out.acc[k as usize].iter_mut().zip(&a) {
                *s += v;
            }
        }
        out.unresolved_mass += band.unresolved_mass;
        out.unresolved_area += band.unresolved_area;
        out.split_pixels += band.split_pixels;
        out.pieces += band.pieces;
    }
    out
}

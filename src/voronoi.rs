//! Spherical Voronoi cells, each clipped in a gnomonic chart centred on its
//! site from its k nearest neighbours (k-d tree), k doubled until a
//! radius-of-security test certifies the cell. Shared by the covering
//! radius ([`crate::metrics::sphere::covering_radius`]) and Lloyd
//! relaxation ([`crate::relax`]).

use glam::DVec3;
use kiddo::{ImmutableKdTree, SquaredEuclidean};
use rayon::prelude::*;
use std::f64::consts::PI;
use std::num::NonZero;

/// A k-d tree over the 3-D coordinates of unit vectors.
pub(crate) type Tree3 = ImmutableKdTree<f64, 3>;

/// The k-d tree of `points`.
pub(crate) fn build_tree(points: &[DVec3]) -> Tree3 {
    let coords: Vec<[f64; 3]> = points.iter().map(|p| p.to_array()).collect();
    ImmutableKdTree::new_from_slice(&coords)
}

/// Polygon vertices in a gnomonic chart (coordinates `(a, b)`).
pub(crate) type Poly = Vec<[f64; 2]>;

/// Clips the convex polygon `poly` by the half-plane `c0 + c1 a + c2 b ≥ 0`
/// (Sutherland–Hodgman), writing the result to `out`.
pub(crate) fn clip(poly: &Poly, c: [f64; 3], out: &mut Poly) {
    out.clear();
    let f = |u: &[f64; 2]| c[0] + c[1] * u[0] + c[2] * u[1];
    let Some(mut prev) = poly.last() else {
        return;
    };
    let mut fp = f(prev);
    for cur in poly {
        let fc = f(cur);
        if (fc >= 0.0) != (fp >= 0.0) {
            let t = fp / (fp - fc);
            out.push([
                prev[0] + t * (cur[0] - prev[0]),
                prev[1] + t * (cur[1] - prev[1]),
            ]);
        }
        if fc >= 0.0 {
            out.push(*cur);
        }
        prev = cur;
        fp = fc;
    }
}

/// Clips the square `[-half, half]²` of the gnomonic chart
/// `u ↦ e + a ea + b eb` by the hemispheres `x · n ≥ 0`.
pub(crate) fn clip_chart(e: DVec3, ea: DVec3, eb: DVec3, half: f64, normals: &[DVec3]) -> Poly {
    let mut poly: Poly = vec![[-half, -half], [half, -half], [half, half], [-half, half]];
    let mut tmp = Poly::with_capacity(16);
    for n in normals {
        clip(&poly, [n.dot(e), n.dot(ea), n.dot(eb)], &mut tmp);
        std::mem::swap(&mut poly, &mut tmp);
        if poly.is_empty() {
            break;
        }
    }
    poly
}

/// Unit tangent basis `(ea, eb)` at `p`, right-handed with `p`.
pub(crate) fn tangent_basis(p: DVec3) -> (DVec3, DVec3) {
    let helper = if p.x.abs() <= p.y.abs() && p.x.abs() <= p.z.abs() {
        DVec3::X
    } else if p.y.abs() <= p.z.abs() {
        DVec3::Y
    } else {
        DVec3::Z
    };
    let ea = helper.cross(p).normalize();
    (ea, p.cross(ea))
}

/// Half-width of the chart square centred on the sample (`tan` of about
/// 76°); cells reaching beyond it use the cube-face fallback.
pub(crate) const CHART_HALF: f64 = 4.0;

/// Largest geodesic distance from `p` to the points of the spherical convex
/// region `{x : x · n ≥ 0 for all n in normals}` (the Voronoi cell of `p` when
/// `normals` are `p − q` for its competitors), a point of the region that
/// far from `p`, and the region in the gnomonic chart at `p` (basis
/// [`tangent_basis`]; empty when it reaches past the chart). Exact up to
/// rounding.
fn cell_radius(p: DVec3, normals: &[DVec3]) -> (f64, DVec3, Poly) {
    // Fast path: a gnomonic chart centred on p. If the clipped polygon stays
    // strictly inside the chart square, it is the whole cell, which then lies
    // in the open hemisphere around p; there the distance to p is maximal at
    // a vertex, and the distance of the chart point u is atan(|u|).
    let (ea, eb) = tangent_basis(p);
    let poly = clip_chart(p, ea, eb, CHART_HALF, normals);
    let limit = CHART_HALF * (1.0 - 1e-9);
    if !poly.is_empty()
        && poly
            .iter()
            .all(|u| u[0].abs() < limit && u[1].abs() < limit)
    {
        let (r2, u) = poly
            .iter()
            .map(|u| (u[0] * u[0] + u[1] * u[1], u))
            .fold((0.0, &[0.0, 0.0]), |a, b| if b.0 > a.0 { b } else { a });
        let farthest = (p + u[0] * ea + u[1] * eb).normalize();
        return (r2.sqrt().atan(), farthest, poly);
    }
    let (radius, farthest) = cell_radius_cube(p, normals);
    (radius, farthest, Poly::new())
}

/// General (wide cells) version of [`cell_radius`]: the cell is cut by the six
/// faces of the cube map, each piece clipped in its face's gnomonic chart;
/// the maximum distance is taken over the vertices, over the interior points
/// of the edges nearest to the antipode of `p`, and over the antipode itself.
fn cell_radius_cube(p: DVec3, normals: &[DVec3]) -> (f64, DVec3) {
    let anti = -p;
    if normals.iter().all(|n| anti.dot(*n) >= 0.0) {
        return (PI, anti);
    }
    let axes = [DVec3::X, DVec3::Y, DVec3::Z];
    let mut best = (0.0, p);
    let mut consider = |q: DVec3| {
        let d = geodesic(p, q);
        if d > best.0 {
            best = (d, q);
        }
    };
    for k in 0..3 {
        for sign in [1.0, -1.0] {
            let e = axes[k] * sign;
            let ea = axes[(k + 1) % 3];
            let eb = axes[(k + 2) % 3] * sign;
            let poly = clip_chart(e, ea, eb, 1.0, normals);
            let verts: Vec<DVec3> = poly
                .iter()
                .map(|u| (e + u[0] * ea + u[1] * eb).normalize())
                .collect();
            for (idx, &v) in verts.iter().enumerate() {
                consider(v);
                let w = verts[(idx + 1) % verts.len()];
                // Point of the great-circle arc v → w nearest to the antipode.
                let m = v.cross(w);
                if m.length_squared() < 1e-300 {
                    continue;
                }
                let m = m.normalize();
                let proj = anti - anti.dot(m) * m;
                if proj.length_squared() < 1e-300 {
                    continue;
                }
                let q = proj.normalize();
                if v.cross(q).dot(m) >= 0.0 && q.cross(w).dot(m) >= 0.0 {
                    consider(q);
                }
            }
        }
    }
    best
}

/// What [`cell_of`] finds of a Voronoi cell.
pub(crate) struct Cell {
    /// The largest geodesic distance from the site to its cell.
    pub(crate) radius: f64,
    /// A point of the cell that far from the site (a Voronoi vertex, unless
    /// the cell is wider than a hemisphere).
    pub(crate) farthest: DVec3,
    /// The index of the site's nearest other point (chordal; `None` for a
    /// single point).
    pub(crate) nearest: Option<usize>,
    /// The cell in the gnomonic chart at the site (basis [`tangent_basis`]),
    /// empty when it reaches past the chart (wider than about 76°).
    pub(crate) chart: Poly,
}

impl Cell {
    /// The chordal radius within which every point that can clip this
    /// cell lies (twice the chord of its radius): a bound for the next
    /// search of a site that moves little.
    pub(crate) fn reach(&self) -> f64 {
        4.0 * (0.5 * self.radius).sin()
    }
}

/// The Voronoi cell of `points[i]` as the half-spaces `x · n ≥ 0` that
/// bound it, into `normals` (`p − q` for its competitors `q`): the nearest
/// neighbours from the tree, certified by the radius-of-security test, or
/// all points when `tree` is `None`. `reach` (chordal, or infinity) bounds
/// the first search: the radius the cell is expected to need (see
/// [`Cell::reach`]), which spares the tree and the clipping the neighbours
/// beyond it. Returns what it found of the cell.
pub(crate) fn cell_of(
    points: &[DVec3],
    tree: Option<&Tree3>,
    i: usize,
    normals: &mut Vec<DVec3>,
    reach: f64,
) -> Cell {
    let p = points[i];
    let n = points.len();
    let others = |normals: &mut Vec<DVec3>, j: usize| {
        let d = p - points[j];
        if j != i && d != DVec3::ZERO {
            normals.push(d);
        }
    };
    let cell = |normals: &[DVec3], nearest| {
        let (radius, farthest, chart) = cell_radius(p, normals);
        Cell {
            radius,
            farthest,
            nearest,
            chart,
        }
    };
    let everyone = |normals: &mut Vec<DVec3>| {
        normals.clear();
        (0..n).for_each(|j| others(normals, j));
        let nearest = (0..n).filter(|&j| j != i).min_by(|&a, &b| {
            p.distance_squared(points[a])
                .total_cmp(&p.distance_squared(points[b]))
        });
        cell(normals, nearest)
    };
    let Some(tree) = tree else {
        return everyone(normals);
    };
    // 12 neighbours certify most cells of a well-spread set (a hexagonal
    // one needs about 6)
    let (mut k, mut reach) = (12usize, reach);
    loop {
        if k + 1 >= n {
            return everyone(normals);
        }
        normals.clear();
        // a heap, then a sort of the few results: kiddo's sorted
        // collection shifts its array on every insertion
        let mut found = tree.nearest_n_within::<SquaredEuclidean>(
            &p.to_array(),
            reach * reach,
            NonZero::new(k + 1).unwrap(),
            false,
        );
        found.sort_unstable_by(|a, b| a.distance.total_cmp(&b.distance).then(a.item.cmp(&b.item)));
        for nn in &found {
            others(normals, nn.item as usize);
        }
        let (radius, farthest, chart) = cell_radius(p, normals);
        // Every point not fetched is at least this far (chordal) from p:
        // the k-th neighbour's distance, or all within `reach` were fetched.
        let fetched = if found.len() > k {
            found.last().map_or(0.0, |nn| nn.distance.sqrt())
        } else {
            reach
        };
        // Points x of the clipped cell satisfy |x − p| ≤ r (chordal); a point
        // q with |q − p| ≥ 2r has |x − q| ≥ r ≥ |x − p| and cannot clip it.
        let chord = 2.0 * (0.5 * radius).sin();
        if fetched >= 2.0 * chord {
            // found is sorted by distance, p itself (or a twin) first
            return Cell {
                radius,
                farthest,
                nearest: found.iter().map(|nn| nn.item as usize).find(|&j| j != i),
                chart,
            };
        }
        k *= 2;
        reach = f64::INFINITY;
    }
}

/// The indices of `points` along a Morton (Z-order) curve of their 3-D
/// coordinates: points near on the sphere are mostly near in this order,
/// so visiting them in it keeps a k-d tree's nodes in cache (at 10⁷
/// points, visiting them in a progressive file's order misses the cache
/// on nearly every query).
pub(crate) fn spatial_order(points: &[DVec3]) -> Vec<usize> {
    // 21 bits per axis over [-1, 1], interleaved into 63 bits
    fn spread(v: f64) -> u64 {
        let q = (((v.clamp(-1.0, 1.0) + 1.0) * 0.5) * ((1u64 << 21) - 1) as f64) as u64;
        let mut x = q & 0x1f_ffff;
        x = (x | x << 32) & 0x1f_0000_0000_ffff;
        x = (x | x << 16) & 0x1f_0000_ff00_00ff;
        x = (x | x << 8) & 0x100f_00f0_0f00_f00f;
        x = (x | x << 4) & 0x10c3_0c30_c30c_30c3;
        (x | x << 2) & 0x1249_2492_4924_9249
    }
    let mut keyed: Vec<(u64, usize)> = points
        .par_iter()
        .enumerate()
        .map(|(i, p)| (spread(p.x) | spread(p.y) << 1 | spread(p.z) << 2, i))
        .collect();
    keyed.par_sort_unstable();
    keyed.into_iter().map(|(_, i)| i).collect()
}

/// Geodesic angle between two unit vectors, `atan2(|a × b|, a · b)`: accurate
/// for all angles, including nearly coincident and nearly antipodal points.
pub(crate) fn geodesic(a: DVec3, b: DVec3) -> f64 {
    a.cross(b).length().atan2(a.dot(b))
}

//! SVG drawings of tilings and their samples.

use crate::healpix::lonlat_deg;
use crate::tiling::sphere::{SphereTile, SphereTiling};
use crate::tiling::TileSystem;
use std::fmt::Write;

const WIDTH: f64 = 1440.0;
const HEIGHT: f64 = 720.0;

/// Draws every tile of a sphere level in equirectangular projection
/// (longitude -180..180 left to right, latitude 90 at the top), filled by
/// code rank (dark = small code: kept first), outlined, and the given points
/// as dots.
///
/// # Example
/// ```
/// use tessera::tiling::sphere::SphereTiling;
/// let svg = tessera::plot::svg::sphere_tiles(&SphereTiling::default(), 0, &[glam::DVec3::X]);
/// assert!(svg.starts_with("<svg") && svg.matches("<polygon").count() >= 240);
/// ```
pub fn sphere_tiles(tiling: &SphereTiling, level: u32, points: &[glam::DVec3]) -> String {
    let tiles: Vec<SphereTile> = tiling.tiles(level);
    let capacity = tiling.capacity(level);
    let outline = tiling.shape().outline();
    let mut svg = open_svg(WIDTH, HEIGHT);
    let stroke = (0.8 / (1 << level) as f64).max(0.1);
    for tile in &tiles {
        let mut lonlats = Vec::new();
        for k in 0..outline.len() {
            let (a, b) = (outline[k], outline[(k + 1) % outline.len()]);
            for s in 0..4 {
                let t = s as f64 / 4.0;
                let local = [
                    a.0 as f64 + t * (b.0 - a.0) as f64,
                    a.1 as f64 + t * (b.1 - a.1) as f64,
                ];
                lonlats.push(lonlat_deg(tiling.face_point(tile, local).to_vec()));
            }
        }
        unwrap_longitudes(&mut lonlats);
        let grey = 40.0 + 200.0 * tile.code as f64 / capacity;
        // a polygon crossing the antimeridian is drawn on both edges
        let west = lonlats.iter().map(|l| l.0).fold(f64::INFINITY, f64::min);
        let east = lonlats
            .iter()
            .map(|l| l.0)
            .fold(f64::NEG_INFINITY, f64::max);
        let shifts = [(true, 0.0), (west < -180.0, 360.0), (east > 180.0, -360.0)];
        for (_, shift) in shifts.iter().filter(|s| s.0) {
            let mut path = String::new();
            for (lon, lat) in &lonlats {
                let _ = write!(path, "{:.2},{:.2} ", x_of(lon + shift), y_of(*lat));
            }
            let _ = writeln!(
                svg,
                r#"<polygon points="{path}" fill="rgb({g},{g},255)" stroke="black" stroke-width="{stroke}"/>"#,
                g = grey as u8
            );
        }
    }
    let radius = (3.0 / (1 << level) as f64).max(0.6);
    for &p in points {
        let (lon, lat) = lonlat_deg(p);
        let _ = writeln!(
            svg,
            r#"<circle cx="{:.2}" cy="{:.2}" r="{radius}" fill="red"/>"#,
            x_of(lon),
            y_of(lat)
        );
    }
    svg.push_str("</svg>\n");
    svg
}

fn x_of(lon: f64) -> f64 {
    (lon + 180.0) / 360.0 * WIDTH
}

fn y_of(lat: f64) -> f64 {
    (90.0 - lat) / 180.0 * HEIGHT
}

/// Makes consecutive longitudes continuous so polygons crossing the
/// antimeridian are drawn whole (they overhang the picture's edge).
fn unwrap_longitudes(lonlats: &mut [(f64, f64)]) {
    for k in 1..lonlats.len() {
        let previous = lonlats[k - 1].0;
        while lonlats[k].0 - previous > 180.0 {
            lonlats[k].0 -= 360.0;
        }
        while lonlats[k].0 - previous < -180.0 {
            lonlats[k].0 += 360.0;
        }
    }
}

/// Draws every tile of a planar polyomino level on the unit square (x to
/// the right, y down as in images), filled by code rank (dark = kept
/// first), labelled with its code when the level has at most 400 tiles,
/// and the given points as dots.
///
/// # Example
/// ```
/// use tessera::tiling::plane::PlaneTiling;
/// let svg = tessera::plot::svg::plane_tiles(&PlaneTiling::ppentomino(), 0, &[glam::DVec2::splat(0.5)]);
/// assert_eq!(svg.matches("<polygon").count(), 20);
/// assert_eq!(svg.matches("<text").count(), 20);
/// ```
pub fn plane_tiles(
    tiling: &crate::tiling::plane::PlaneTiling,
    level: u32,
    points: &[glam::DVec2],
) -> String {
    let side = HEIGHT;
    let tiles = tiling.tiles(level);
    let capacity = tiling.capacity(level);
    let outline = tiling.shape().outline();
    let mut svg = open_svg(side, side);
    let stroke = (side / tiling.cells_per_unit(level) / 8.0).clamp(0.1, 1.0);
    let label = tiles.len() <= 400;
    let font = side / tiling.cells_per_unit(level) * 0.8;
    for tile in &tiles {
        let mut path = String::new();
        for &(x, y) in &outline {
            let p = tiling.to_unit(tile, [x as f64, y as f64]) * side;
            let _ = write!(path, "{:.2},{:.2} ", p.x, p.y);
        }
        let grey = (40.0 + 200.0 * tile.code as f64 / capacity) as u8;
        let _ = writeln!(
            svg,
            r#"<polygon points="{path}" fill="rgb({grey},{grey},255)" stroke="black" stroke-width="{stroke:.2}"/>"#
        );
        if label {
            let c = tiling.to_unit(tile, tiling.shape().centroid()) * side;
            let _ = writeln!(
                svg,
                r#"<text x="{:.2}" y="{:.2}" font-size="{font:.2}" text-anchor="middle" dominant-baseline="middle">{}</text>"#,
                c.x, c.y, tile.code
            );
        }
    }
    let radius = (side / tiling.cells_per_unit(level) / 4.0).max(0.6);
    unit_square_points(&mut svg, points, side, radius);
    svg.push_str("</svg>\n");
    svg
}

/// Draws the Penrose tiles of a level that reach the unit square (x to the
/// right, y down), triangles filled by code rank (dark = kept first) and
/// clipped to the square, each point tile's code beside its vertex when
/// there are at most 400 of them and a legible font (4 px or more) fits
/// between the closest vertices (a short diagonal, 0.38 edges apart, holds
/// the widest code at 0.6 font sizes a digit; level 8's labels overlapped
/// when the font was 0.3 edges), and the given points as dots.
///
/// # Example
/// ```
/// use tessera::tiling::penrose::PenroseTiling;
/// let svg = tessera::plot::svg::penrose_tiles(&PenroseTiling::default(), 4, &[glam::DVec2::splat(0.5)]);
/// assert!(svg.matches("<polygon").count() > 10);
/// assert!(svg.contains("<text") && svg.contains("<circle"));
/// ```
pub fn penrose_tiles(
    tiling: &crate::tiling::penrose::PenroseTiling,
    level: u32,
    points: &[glam::DVec2],
) -> String {
    let side = HEIGHT;
    let tiles = tiling.tiles(level);
    let capacity = tiling.capacity(level);
    let edge = tiling.edge(level) * side;
    let mut svg = open_svg(side, side);
    let _ = writeln!(
        svg,
        r#"<defs><clipPath id="square"><rect width="{side}" height="{side}"/></clipPath></defs><g clip-path="url(#square)">"#
    );
    let stroke = (edge / 20.0).clamp(0.1, 1.0);
    for tile in tiles.iter().filter(|t| !t.kind.is_point()) {
        let mut path = String::new();
        for p in tile.v {
            let _ = write!(path, "{:.2},{:.2} ", p.x * side, p.y * side);
        }
        let grey = (40.0 + 200.0 * tile.code as f64 / capacity) as u8;
        let _ = writeln!(
            svg,
            r#"<polygon points="{path}" fill="rgb({grey},{grey},255)" stroke="black" stroke-width="{stroke:.2}"/>"#
        );
    }
    let vertices: Vec<_> = tiles.iter().filter(|t| t.kind.is_point()).collect();
    let digits = (capacity.max(10.0)).log10().ceil();
    let font = 0.38 * edge / (0.6 * digits);
    if vertices.len() <= 400 && font >= 4.0 {
        for t in vertices {
            let _ = writeln!(
                svg,
                r#"<text x="{:.2}" y="{:.2}" font-size="{font:.2}">{}</text>"#,
                t.v[0].x * side + font * 0.3,
                t.v[0].y * side - font * 0.3,
                t.code
            );
        }
    }
    unit_square_points(&mut svg, points, side, (edge / 8.0).max(0.6));
    svg.push_str("</g></svg>\n");
    svg
}

/// Red dots for unit-square points on a `side`-pixel drawing.
fn unit_square_points(svg: &mut String, points: &[glam::DVec2], side: f64, radius: f64) {
    for p in points {
        let _ = writeln!(
            svg,
            r#"<circle cx="{:.2}" cy="{:.2}" r="{radius:.2}" fill="red"/>"#,
            p.x * side,
            p.y * side
        );
    }
}

/// An SVG document opened at `width x height` pixels on a white background.
fn open_svg(width: f64, height: f64) -> String {
    let mut svg = String::new();
    let _ = writeln!(
        svg,
        r#"<svg xmlns="http://www.w3.org/2000/svg" width="{width}" height="{height}" viewBox="0 0 {width} {height}">"#
    );
    let _ = writeln!(
        svg,
        r#"<rect width="{width}" height="{height}" fill="white"/>"#
    );
    svg
}

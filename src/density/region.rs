//! Regional refinement for geophysical point sets: caps and lon/lat
//! polygons, each with a contrast, combined so that the finest request
//! wins: the density at a point is the largest contrast of the regions
//! containing it, and 1 where none does.
//!
//! Polygons follow GeoJSON (RFC 7946): vertices are `lon lat` in degrees
//! and edges are straight in the lon/lat plane; a polygon crossing the
//! antimeridian is written with longitudes beyond 180 (e.g. 170 to 190).
//!
//! ```
//! use tessera::density::{region::Regions, Density};
//! use tessera::tiling::sphere::SphereRegion;
//! let r = Regions::parse(&["cap:0,90,10,4", "polygon:0 0,20 0,20 20,0 20;9"]).unwrap();
//! let v = tessera::density::sphere::lonlat_to_vec(10.0, 10.0);
//! assert_eq!(Density::<SphereRegion>::value(&r, v), 9.0);
//! assert_eq!(Density::<SphereRegion>::value(&r, glam::DVec3::Z), 4.0);
//! assert_eq!(Density::<SphereRegion>::value(&r, -glam::DVec3::Z), 1.0);
//! ```

use super::sphere::{angle_between, lonlat_to_vec};
use super::Density;
use crate::healpix::lonlat_deg;
use crate::tiling::sphere::SphereRegion;
use crate::Error;
use glam::DVec3;

/// Where a tile lies relative to a shape.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Side {
    Inside,
    Outside,
    Unknown,
}

/// A refinement shape.
#[derive(Clone, Debug, PartialEq)]
enum Shape {
    /// Centre and angular radius (rad).
    Cap(DVec3, f64),
    /// Vertices `[lon, lat]` in degrees (closed implicitly) and their
    /// bounding box `[lon_min, lat_min, lon_max, lat_max]`.
    Polygon(Vec<[f64; 2]>, [f64; 4]),
}

/// The lon/lat box (degrees) of a cap, `None` when it holds a pole (or
/// spans every longitude).
fn cap_box(center: DVec3, radius: f64) -> Option<[f64; 4]> {
    let (lon, lat) = lonlat_deg(center);
    let r = radius.to_degrees();
    if lat + r >= 90.0 || lat - r <= -90.0 {
        return None;
    }
    let s = radius.sin() / lat.to_radians().cos();
    if s >= 1.0 {
        return None;
    }
    let half = s.asin().to_degrees() + 1e-9;
    Some([lon - half, lat - r - 1e-9, lon + half, lat + r + 1e-9])
}

/// Whether segment `a`-`b` meets the closed box (Liang-Barsky clipping).
fn segment_meets_box(a: [f64; 2], b: [f64; 2], bx: [f64; 4]) -> bool {
    let (mut t0, mut t1) = (0.0f64, 1.0f64);
    let d = [b[0] - a[0], b[1] - a[1]];
    for axis in 0..2 {
        let (lo, hi) = (bx[axis], bx[axis + 2]);
        if d[axis] == 0.0 {
            if a[axis] < lo || a[axis] > hi {
                return false;
            }
            continue;
        }
        let (mut u, mut v) = ((lo - a[axis]) / d[axis], (hi - a[axis]) / d[axis]);
        if u > v {
            std::mem::swap(&mut u, &mut v);
        }
        t0 = t0.max(u);
        t1 = t1.min(v);
        if t0 > t1 {
            return false;
        }
    }
    true
}

impl Shape {
    fn polygon(vertices: Vec<[f64; 2]>) -> Shape {
        let mut bx = [f64::INFINITY, f64::INFINITY, -f64::INFINITY, -f64::INFINITY];
        for &[lon, lat] in &vertices {
            bx = [
                bx[0].min(lon),
                bx[1].min(lat),
                bx[2].max(lon),
                bx[3].max(lat),
            ];
        }
        Shape::Polygon(vertices, bx)
    }

    /// Crossing-number test in the lon/lat plane, trying the point's
    /// longitude and its copies 360 degrees either side.
    fn contains(&self, v: DVec3) -> bool {
        match self {
            Shape::Cap(c, r) => angle_between(*c, v) <= *r,
            Shape::Polygon(vertices, _) => {
                let (lon, lat) = lonlat_deg(v);
                [lon, lon + 360.0, lon - 360.0]
                    .iter()
                    .any(|&x| crossing_inside(vertices, x, lat))
            }
        }
    }

    fn side(&self, region: &SphereRegion) -> Side {
        self.side_of(region.center(), region.radius)
    }

    /// Where the cap of `radius` about `center` lies.
    fn side_of(&self, center: DVec3, radius: f64) -> Side {
        match self {
            Shape::Cap(c, r) => {
                let d = angle_between(*c, center);
                if d + radius <= *r {
                    Side::Inside
                } else if d - radius > *r {
                    Side::Outside
                } else {
                    Side::Unknown
                }
            }
            Shape::Polygon(vertices, pbox) => {
                let Some(tile) = cap_box(center, radius) else {
                    return Side::Unknown;
                };
                let shifted = |k: f64| [tile[0] + k, tile[1], tile[2] + k, tile[3]];
                let boxes = [shifted(0.0), shifted(360.0), shifted(-360.0)];
                let overlaps = |b: &[f64; 4]| {
                    b[0] <= pbox[2] && b[2] >= pbox[0] && b[1] <= pbox[3] && b[3] >= pbox[1]
                };
                if !boxes.iter().any(overlaps) {
                    return Side::Outside;
                }
                let n = vertices.len();
                let crossed = boxes.iter().filter(|b| overlaps(b)).any(|b| {
                    (0..n).any(|k| segment_meets_box(vertices[k], vertices[(k + 1) % n], *b))
                });
                match (crossed, self.contains(center)) {
                    (true, _) => Side::Unknown,
                    (false, true) => Side::Inside,
                    (false, false) => Side::Outside,
                }
            }
        }
    }
}

/// Even-odd rule for the point (`x`, `y`) against a closed polygon.
fn crossing_inside(vertices: &[[f64; 2]], x: f64, y: f64) -> bool {
    let n = vertices.len();
    let mut inside = false;
    for k in 0..n {
        let ([x0, y0], [x1, y1]) = (vertices[k], vertices[(k + 1) % n]);
        if (y0 > y) != (y1 > y) && x < x0 + (y - y0) / (y1 - y0) * (x1 - x0) {
            inside = !inside;
        }
    }
    inside
}

/// Caps and polygons with contrasts; the finest request wins (see the
/// [module docs](self)).
///
/// # Example
/// ```
/// use tessera::density::region::Regions;
/// use tessera::Sampler;
/// let r = Regions::parse(&["polygon:-10 30,40 30,40 70,-10 70;16"]).unwrap();
/// assert_eq!(Sampler::sphere().density(r).count(1000).generate().unwrap().len(), 1000);
/// ```
#[derive(Clone, Debug, PartialEq)]
pub struct Regions {
    shapes: Vec<(Shape, f64)>,
    mean: f64,
}

impl Regions {
    /// Parses specifications `cap:LON,LAT,RADIUS_DEG,CONTRAST` and
    /// `polygon:LON LAT,LON LAT,...;CONTRAST` (at least 3 vertices).
    ///
    /// # Example
    /// ```
    /// use tessera::density::region::Regions;
    /// let e = Regions::parse(&["polygon:0 0,1 1;5"]).unwrap_err().to_string();
    /// assert!(e.contains("polygon:0 0,1 1;5") && e.contains("3 vertices"));
    /// ```
    pub fn parse<S: AsRef<str>>(specs: &[S]) -> Result<Regions, Error> {
        let mut shapes = Vec::new();
        for spec in specs {
            let spec = spec.as_ref();
            let fail = |why: &str| Error::Density(spec.to_string(), why.to_string());
            let finite = |v: &[f64]| v.iter().all(|x| x.is_finite());
            if let Some(args) = spec.strip_prefix("cap:") {
                let [lon, lat, radius, contrast] = super::sphere::cap_numbers(spec, args)?;
                // the same checks as a single cap
                super::sphere::Cap::new(lon, lat, radius, contrast.max(f64::MIN_POSITIVE))
                    .map_err(|e| match e {
                        Error::Density(_, why) => fail(&why),
                        other => other,
                    })?;
                check_contrast(contrast).map_err(|why| fail(&why))?;
                shapes.push((
                    Shape::Cap(lonlat_to_vec(lon, lat), radius.to_radians()),
                    contrast,
                ));
            } else if let Some(args) = spec.strip_prefix("polygon:") {
                let (points, contrast) = args
                    .rsplit_once(';')
                    .ok_or_else(|| fail("expected polygon:LON LAT,LON LAT,...;CONTRAST"))?;
                let contrast: f64 = contrast
                    .trim()
                    .parse()
                    .map_err(|_| fail("the contrast after ';' is not a number"))?;
                check_contrast(contrast).map_err(|why| fail(&why))?;
                let mut vertices = Vec::new();
                for pair in points.split(',') {
                    let v: Vec<f64> = pair
                        .split_whitespace()
                        .map(str::parse)
                        .collect::<Result<_, _>>()
                        .map_err(|_| fail("each vertex is 'LON LAT' in degrees"))?;
                    let [lon, lat] = v[..] else {
                        return Err(fail("each vertex is 'LON LAT' in degrees"));
                    };
                    if !finite(&v) || !(-90.0..=90.0).contains(&lat) || lon.abs() > 540.0 {
                        return Err(fail(
                            "vertices need finite lon in [-540, 540] and lat in [-90, 90]",
                        ));
                    }
                    vertices.push([lon, lat]);
                }
                if vertices.len() < 3 {
                    return Err(fail("a polygon needs at least 3 vertices"));
                }
                shapes.push((Shape::polygon(vertices), contrast));
            } else {
                return Err(fail(
                    "expected 'cap:LON,LAT,RADIUS_DEG,CONTRAST' or 'polygon:LON LAT,LON LAT,...;CONTRAST'",
                ));
            }
        }
        let mut regions = Regions { shapes, mean: 1.0 };
        regions.mean = regions.quadrature_mean();
        if !(regions.mean.is_finite() && regions.mean > 0.0) {
            return Err(Error::Density(
                specs
                    .iter()
                    .map(|s| s.as_ref())
                    .collect::<Vec<_>>()
                    .join(" "),
                "the density is zero (almost) everywhere".into(),
            ));
        }
        Ok(regions)
    }

    /// The density's mean over the sphere by the equal-area quadrature of
    /// HEALPix cell centres at Nside 128.
    fn quadrature_mean(&self) -> f64 {
        super::sphere::cell_centre_mean(128, |v| self.at(v))
    }

    /// The bound over the cap of `radius` about `center`.
    fn bound_about(&self, center: DVec3, radius: f64) -> f64 {
        let mut bound: f64 = 0.0;
        let mut covered = false;
        for (shape, contrast) in &self.shapes {
            match shape.side_of(center, radius) {
                Side::Inside => {
                    covered = true;
                    bound = bound.max(*contrast);
                }
                Side::Unknown => bound = bound.max(*contrast),
                Side::Outside => {}
            }
        }
        if covered {
            bound
        } else {
            bound.max(1.0)
        }
    }

    fn at(&self, v: DVec3) -> f64 {
        self.shapes
            .iter()
            .filter(|(s, _)| s.contains(v))
            .map(|&(_, c)| c)
            .reduce(f64::max)
            .unwrap_or(1.0)
    }
}

fn check_contrast(contrast: f64) -> Result<(), String> {
    if contrast.is_finite() && contrast >= 0.0 {
        Ok(())
    } else {
        Err(format!("contrast {contrast} must be finite and >= 0"))
    }
}

impl Density<SphereRegion> for Regions {
    fn bound(&self, region: &SphereRegion) -> f64 {
        self.bound_about(region.center(), region.radius)
    }

    fn bounds(&self, region: &SphereRegion, inner: &SphereRegion) -> (f64, f64) {
        if region.centroid != inner.centroid {
            return (self.bound(region), self.bound(inner));
        }
        // one centre, two radii
        let center = region.center();
        let of = |radius| self.bound_about(center, radius);
        (of(region.radius), of(inner.radius))
    }

    fn average(&self, region: &SphereRegion) -> f64 {
        let mut decided: Option<f64> = None;
        for (shape, contrast) in &self.shapes {
            match shape.side(region) {
                Side::Inside => decided = Some(decided.map_or(*contrast, |d| d.max(*contrast))),
                Side::Outside => {}
                Side::Unknown => {
                    let probes = region.probes();
                    return probes.iter().map(|&p| self.at(p)).sum::<f64>() / 5.0;
                }
            }
        }
        decided.unwrap_or(1.0)
    }

    fn value(&self, point: DVec3) -> f64 {
        self.at(point)
    }

    fn mean(&self) -> f64 {
        self.mean
    }
}

/// Parses the command line's `--density` values: one `uniform` or `cap:`
/// as [`super::sphere::parse`] does, otherwise (polygons, several
/// regions) a [`Regions`] combination.
///
/// # Example
/// ```
/// use tessera::density::region::parse_all;
/// assert!(parse_all(&["uniform"]).unwrap().constant().is_some());
/// assert!(parse_all(&["cap:0,0,5,3", "cap:90,0,5,3"]).is_ok());
/// assert!(parse_all(&["uniform", "cap:0,0,5,3"]).is_err());
/// ```
pub fn parse_all<S: AsRef<str>>(
    specs: &[S],
) -> Result<Box<dyn Density<SphereRegion> + Send>, Error> {
    match specs {
        [] => Ok(Box::new(super::Uniform)),
        [one] if !one.as_ref().starts_with("polygon:") => super::sphere::parse(one.as_ref()),
        _ => Ok(Box::new(Regions::parse(specs)?)),
    }
}

//! Importance functions ("densities") and their bounds over tiles.
//!
//! The engine asks a density two things: a conservative upper bound over a
//! tile (to decide how deep to subdivide: a small bright region must never
//! be skipped) and its value where the tile's sample lands (to threshold
//! the tile's code). Averages serve size hints and callers. Values are
//! relative: only ratios matter, and the engine scales by the requested count.

pub mod envmap;
pub mod healpix;
pub mod plane;
pub mod rectangle;
pub mod region;
pub mod sphere;

/// The geometry a density sees of a tile.
///
/// # Example
/// ```
/// use tessera::density::Region;
/// fn point_type<R: Region>() -> &'static str { std::any::type_name::<R::Point>() }
/// assert!(point_type::<tessera::tiling::sphere::SphereRegion>().contains("DVec3"));
/// ```
pub trait Region {
    /// Points of the domain.
    type Point: Copy;
}

impl Region for crate::tiling::sphere::SphereRegion {
    type Point = glam::DVec3;
}

/// A non-negative importance function over a domain.
///
/// # Example
/// ```
/// use tessera::density::{Density, Uniform};
/// use tessera::tiling::sphere::SphereRegion;
/// let d: &dyn Density<SphereRegion> = &Uniform;
/// assert_eq!(d.mean(), 1.0);
/// ```
pub trait Density<R: Region>: Sync {
    /// An upper bound of the density over the region (never below the
    /// truth: a request fails with an error where a sample lands on a
    /// density above its tile's bound, as its samples would be biased).
    fn bound(&self, region: &R) -> f64;
    /// [`Density::bound`] over `region` and over `inner`, a region inside it
    /// (a tile's placing region,
    /// [`crate::tiling::TileSystem::placing_region`]), in one call: the
    /// engine asks for both where it knows it needs both, and a density
    /// whose bound starts from the region's centre or probes computes
    /// them once.
    ///
    /// # Example
    /// ```
    /// use tessera::density::{sphere::SphereFn, Density};
    /// use tessera::tiling::{sphere::SphereTiling, TileSystem};
    /// let sphere = SphereTiling::default();
    /// let tile = sphere.child(&sphere.roots()[4], 0);
    /// let region = sphere.region(&tile);
    /// let inner = sphere.placing_region(&tile, &region).unwrap();
    /// let d = SphereFn::new(|v: glam::DVec3| 2.0 + v.z, 1.0).unwrap();
    /// assert_eq!(d.bounds(&region, &inner), (d.bound(&region), d.bound(&inner)));
    /// ```
    fn bounds(&self, region: &R, inner: &R) -> (f64, f64) {
        (self.bound(region), self.bound(inner))
    }
    /// The density's average over the region (may be approximate).
    fn average(&self, region: &R) -> f64;
    /// The density at a point: where a tile's sample lands it keeps or
    /// drops the sample, and it gives pdfs.
    fn value(&self, point: R::Point) -> f64;
    /// The average over the whole domain (its integral over the domain's
    /// measure), used to turn a sample count into a magnitude.
    fn mean(&self) -> f64;
    /// `Some(c)` when the density is the constant `c` (lets the engine skip
    /// every bound and average).
    fn constant(&self) -> Option<f64> {
        None
    }
    /// The seed of a randomised density (a random rotation or shift):
    /// the engine draws its per-tile dithers from it, so that expectations
    /// over seeds are exact. `None` for a fixed density.
    fn seed(&self) -> Option<u64> {
        None
    }
}

/// The constant density 1.
///
/// # Example
/// ```
/// use tessera::density::{Density, Uniform};
/// use tessera::tiling::sphere::SphereRegion;
/// assert_eq!(Density::<SphereRegion>::constant(&Uniform), Some(1.0));
/// ```
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Uniform;

impl<R: Region> Density<R> for Uniform {
    fn bound(&self, _: &R) -> f64 {
        1.0
    }
    fn average(&self, _: &R) -> f64 {
        1.0
    }
    fn value(&self, _: R::Point) -> f64 {
        1.0
    }
    fn mean(&self) -> f64 {
        1.0
    }
    fn constant(&self) -> Option<f64> {
        Some(1.0)
    }
}

impl<R: Region, D: Density<R> + ?Sized> Density<R> for &D {
    fn bound(&self, region: &R) -> f64 {
        (**self).bound(region)
    }
    fn bounds(&self, region: &R, inner: &R) -> (f64, f64) {
        (**self).bounds(region, inner)
    }
    fn average(&self, region: &R) -> f64 {
        (**self).average(region)
    }
    fn value(&self, point: R::Point) -> f64 {
        (**self).value(point)
    }
    fn mean(&self) -> f64 {
        (**self).mean()
    }
    fn constant(&self) -> Option<f64> {
        (**self).constant()
    }
    fn seed(&self) -> Option<u64> {
        (**self).seed()
    }
}

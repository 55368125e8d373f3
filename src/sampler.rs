//! The builder most users start from.

use crate::density::envmap::EnvMap;
use crate::density::{Density, Region, Uniform};
use crate::engine::{self, Order, Sample};
use crate::tiling::sphere::SphereTiling;
use crate::tiling::TileSystem;
use crate::Error;
use glam::DVec3;

/// A configured sampling request: a tile system, a density and a count.
///
/// # Example
/// ```
/// use tessera::Sampler;
/// let points = Sampler::sphere().count(3072).generate().unwrap();
/// assert_eq!(points.len(), 3072);
/// ```
#[derive(Clone)]
pub struct Sampler<S, D> {
    system: S,
    density: D,
    count: usize,
    exact: bool,
    order: Order,
}

impl Sampler<SphereTiling, Uniform> {
    /// Uniform sampling of the unit sphere with the shipped tables.
    ///
    /// # Example
    /// ```
    /// let s = tessera::Sampler::sphere().count(10).generate().unwrap();
    /// assert!(s.iter().all(|p| (p.position.length() - 1.0).abs() < 1e-12));
    /// ```
    pub fn sphere() -> Self {
        Sampler::new(SphereTiling::default())
    }
}

impl<S: TileSystem> Sampler<S, Uniform> {
    /// Uniform sampling over any tile system.
    ///
    /// # Example
    /// ```
    /// use tessera::{tiling::sphere::SphereTiling, Sampler};
    /// let s = Sampler::new(SphereTiling::default()).count(5).generate().unwrap();
    /// assert_eq!(s.len(), 5);
    /// ```
    pub fn new(system: S) -> Self {
        Sampler {
            system,
            density: Uniform,
            count: 0,
            exact: true,
            order: Order::Progressive,
        }
    }
}

impl<S, D> Sampler<S, D>
where
    S: TileSystem,
    S::Region: Region<Point = S::Point>,
    D: Density<S::Region>,
{
    /// Replaces the density.
    ///
    /// # Example
    /// ```
    /// use tessera::{density::sphere::Cap, Sampler};
    /// let cap = Cap::new(0.0, 0.0, 10.0, 5.0).unwrap();
    /// assert_eq!(Sampler::sphere().density(cap).count(7).generate().unwrap().len(), 7);
    /// ```
    pub fn density<E: Density<S::Region>>(self, density: E) -> Sampler<S, E> {
        Sampler {
            system: self.system,
            density,
            count: self.count,
            exact: self.exact,
            order: self.order,
        }
    }

    /// Sets the number of samples.
    ///
    /// # Example
    /// ```
    /// assert!(tessera::Sampler::sphere().count(0).generate().unwrap().is_empty());
    /// ```
    pub fn count(mut self, count: usize) -> Self {
        self.count = count;
        self
    }

    /// Skips the exactness pass: returns the natural count, near the requested one.
    ///
    /// # Example
    /// ```
    /// use tessera::{density::sphere::Cap, Sampler};
    /// let cap = Cap::new(0.0, 0.0, 10.0, 5.0).unwrap();
    /// let n = Sampler::sphere().density(cap).count(1000).expected().generate().unwrap().len();
    /// assert!((900..1100).contains(&n));
    /// ```
    pub fn expected(mut self) -> Self {
        self.exact = false;
        self
    }

    /// Sets the order of the output (progressive by default; see
    /// [`Order`]).
    ///
    /// # Example
    /// ```
    /// use tessera::{engine::Order, Sampler};
    /// let s = Sampler::sphere().count(100).order(Order::Unsorted).generate().unwrap();
    /// assert_eq!(s.len(), 100);
    /// ```
    pub fn order(mut self, order: Order) -> Self {
        self.order = order;
        self
    }

    /// Runs the recursion; samples come in the sampler's order
    /// (progressive unless [`Sampler::order`] says otherwise).
    ///
    /// # Example
    /// ```
    /// let s = tessera::Sampler::sphere().count(100).generate().unwrap();
    /// assert!(s.windows(2).all(|w| w[0].rank <= w[1].rank));
    /// ```
    pub fn generate(&self) -> Result<Vec<Sample<S::Point>>, Error> {
        let (count, exact, order) = (self.count, self.exact, self.order);
        engine::generate_ordered(&self.system, &self.density, count, exact, order)
    }

    /// [`Sampler::generate`] into memory kept between requests (see
    /// [`engine::Buffers`]): for a new set every frame.
    ///
    /// # Example
    /// ```
    /// let sampler = tessera::Sampler::sphere().count(100);
    /// let mut buffers = tessera::engine::Buffers::default();
    /// let samples = sampler.generate_into(&mut buffers).unwrap();
    /// assert_eq!(samples, &sampler.generate().unwrap()[..]);
    /// ```
    pub fn generate_into<'b>(
        &self,
        buffers: &'b mut engine::Buffers<S::Point>,
    ) -> Result<&'b [Sample<S::Point>], Error> {
        engine::generate_into(
            &self.system,
            &self.density,
            self.count,
            self.exact,
            self.order,
            buffers,
        )
    }

    /// The pdf (per unit measure) the samples follow at `point`.
    ///
    /// # Example
    /// ```
    /// let p = tessera::Sampler::sphere().pdf(glam::DVec3::X);
    /// assert!((p * 4.0 * std::f64::consts::PI - 1.0).abs() < 1e-12);
    /// ```
    pub fn pdf(&self, point: S::Point) -> f64 {
        engine::pdf(&self.system, &self.density, point)
    }

    /// The pdfs of generated samples, computed only when asked for.
    ///
    /// # Example
    /// ```
    /// let sampler = tessera::Sampler::sphere().count(4);
    /// let pdfs = sampler.pdfs(&sampler.generate().unwrap());
    /// assert!(pdfs.iter().all(|p| (p * 4.0 * std::f64::consts::PI - 1.0).abs() < 1e-12));
    /// ```
    pub fn pdfs(&self, samples: &[Sample<S::Point>]) -> Vec<f64> {
        samples.iter().map(|s| self.pdf(s.position)).collect()
    }

    /// The tile system.
    ///
    /// # Example
    /// ```
    /// use tessera::tiling::TileSystem;
    /// assert_eq!(tessera::Sampler::sphere().system().roots().len(), 240);
    /// ```
    pub fn system(&self) -> &S {
        &self.system
    }
}

impl<S, D> Sampler<S, D>
where
    S: TileSystem<Point = glam::DVec2, Region = crate::tiling::plane::PlaneRegion>,
    D: Density<crate::tiling::plane::PlaneRegion>,
{
    /// Runs a planar system on an axis-aligned rectangle instead of the
    /// unit square: the density (given on the unit square) is stretched
    /// over `rect`, and samples come back in the rectangle's coordinates.
    ///
    /// # Example
    /// ```
    /// use tessera::{density::rectangle::Rectangle, tiling::penrose::PenroseTiling, Sampler};
    /// let rect = Rectangle::new(-1.0, 0.0, 1.0, 1.0).unwrap();
    /// let s = Sampler::new(PenroseTiling::default()).count(300).generate_on(&rect).unwrap();
    /// assert_eq!(s.len(), 300);
    /// assert!(s.iter().all(|p| rect.contains(p.position)));
    /// ```
    pub fn generate_on(
        &self,
        rect: &crate::density::rectangle::Rectangle,
    ) -> Result<Vec<Sample<glam::DVec2>>, Error> {
        let density = rect.restrict(&self.density);
        let (count, exact, order) = (self.count, self.exact, self.order);
        let mut samples = engine::generate_ordered(&self.system, &density, count, exact, order)?;
        for s in &mut samples {
            s.position = rect.to_world(s.position);
        }
        Ok(samples)
    }
}

/// Sampling an environment map directly (it lives here, beside the other
/// entry points, so that densities do not depend on the engine).
impl EnvMap {
    /// Exactly `count` samples of the map in progressive order, in world
    /// directions (the sphere tiling with the shipped tables).
    ///
    /// # Example
    /// ```
    /// # use tessera::{density::envmap::{EnvMap, Up}, io::image::Raster};
    /// let map = EnvMap::new(Raster { width: 2, height: 1, values: vec![1.0, 3.0], bad_pixels: 0 }, Up::Z).unwrap();
    /// assert_eq!(map.generate(100).unwrap().len(), 100);
    /// ```
    pub fn generate(&self, count: usize) -> Result<Vec<Sample<DVec3>>, Error> {
        self.generate_with(&SphereTiling::default(), count)
    }

    /// [`EnvMap::generate`] with the sphere tiling `tiling` (for instance
    /// one driven by a table read at run time, [`crate::lut::Table::open`]).
    ///
    /// # Example
    /// ```
    /// # use tessera::{density::envmap::{EnvMap, Up}, io::image::Raster, tiling::sphere::SphereTiling};
    /// let map = EnvMap::new(Raster { width: 2, height: 1, values: vec![1.0, 3.0], bad_pixels: 0 }, Up::Z).unwrap();
    /// let tiling = SphereTiling::new(tessera::lut::sphere_lut());
    /// assert_eq!(map.generate_with(&tiling, 100).unwrap(), map.generate(100).unwrap());
    /// ```
    pub fn generate_with(
        &self,
        tiling: &SphereTiling,
        count: usize,
    ) -> Result<Vec<Sample<DVec3>>, Error> {
        let mut samples = engine::generate(tiling, self, count, true)?;
        if self.seed().is_some() {
            for s in &mut samples {
                s.position = self.to_world(s.position);
            }
        }
        Ok(samples)
    }
}

//! Planar sampling on any axis-aligned rectangle.
//!
//! A rectangle `[x0, x1) x [y0, y1)` is covered by the square of side
//! `max(w, h)` anchored at `(x0, y0)`: the planar tile systems sample that
//! square as their unit square, the density is stretched over the rectangle
//! (its unit square mapped onto it, so an image fills the rectangle) and is
//! zero beyond it, so the engine skips the tiles outside, and points are
//! mapped back. Exact counts hold as on the square.

use super::Density;
use crate::tiling::plane::PlaneRegion;
use crate::Error;
use glam::DVec2;

/// An axis-aligned rectangle `[lo.x, hi.x) x [lo.y, hi.y)` to sample.
///
/// # Example
/// ```
/// use tessera::density::rectangle::Rectangle;
/// let r = Rectangle::new(1.0, 2.0, 5.0, 4.0).unwrap();
/// assert_eq!(r.side(), 4.0);
/// assert_eq!(r.to_world(glam::DVec2::new(0.5, 0.25)), glam::DVec2::new(3.0, 3.0));
/// assert!(Rectangle::new(0.0, 0.0, 0.0, 1.0).is_err());
/// ```
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Rectangle {
    /// Lower corner `(x0, y0)`.
    pub lo: DVec2,
    /// Upper corner `(x1, y1)`.
    pub hi: DVec2,
}

impl Rectangle {
    /// The unit square.
    pub const UNIT: Rectangle = Rectangle {
        lo: DVec2::ZERO,
        hi: DVec2::ONE,
    };

    /// The rectangle `[x0, x1) x [y0, y1)`: corners finite, `x1 > x0`,
    /// `y1 > y0`, and a side that stays representable.
    ///
    /// # Example
    /// ```
    /// use tessera::density::rectangle::Rectangle;
    /// assert!(Rectangle::new(0.0, 0.0, 2.0, 1.0).is_ok());
    /// let e = Rectangle::new(0.0, 1.0, 2.0, f64::NAN).unwrap_err().to_string();
    /// assert!(e.contains("finite"), "{e}");
    /// ```
    pub fn new(x0: f64, y0: f64, x1: f64, y1: f64) -> Result<Self, Error> {
        let fail = |why: String| {
            Err(Error::Request(format!(
                "domain {x0:?},{y0:?},{x1:?},{y1:?}: {why}"
            )))
        };
        if ![x0, y0, x1, y1].iter().all(|v| v.is_finite()) {
            return fail("every corner coordinate must be finite".into());
        }
        if !(x1 > x0 && y1 > y0) {
            return fail("expected x1 > x0 and y1 > y0".into());
        }
        let (w, h) = (x1 - x0, y1 - y0);
        if !(w.is_finite() && h.is_finite()) || w.min(h) < w.max(h) * 1e-12 {
            return fail("the sides must be finite and within a factor 1e12 of each other".into());
        }
        Ok(Rectangle {
            lo: DVec2::new(x0, y0),
            hi: DVec2::new(x1, y1),
        })
    }

    /// Parses `x0,y0,x1,y1`.
    ///
    /// # Example
    /// ```
    /// use tessera::density::rectangle::Rectangle;
    /// assert_eq!(Rectangle::parse("0,0,2,1").unwrap().hi, glam::DVec2::new(2.0, 1.0));
    /// assert!(Rectangle::parse("0,0,2").is_err_and(|e| e.to_string().contains("0,0,2")));
    /// assert!(Rectangle::parse("0,0,1,-1").is_err());
    /// ```
    pub fn parse(spec: &str) -> Result<Self, Error> {
        let values: Result<Vec<f64>, _> = spec.split(',').map(|v| v.trim().parse()).collect();
        match values.as_deref() {
            Ok(&[x0, y0, x1, y1]) => Rectangle::new(x0, y0, x1, y1),
            _ => Err(Error::Request(format!(
                "domain '{spec}': expected four numbers x0,y0,x1,y1"
            ))),
        }
    }

    /// Whether `p` lies in the closed rectangle `[x0, x1] x [y0, y1]` (a
    /// NaN coordinate does not): the bounds that pictures and measures of
    /// a point file accept.
    ///
    /// # Example
    /// ```
    /// use glam::DVec2;
    /// use tessera::density::rectangle::Rectangle;
    /// assert!(Rectangle::UNIT.holds(DVec2::ONE));
    /// assert!(!Rectangle::UNIT.holds(DVec2::new(0.5, f64::NAN)));
    /// ```
    pub fn holds(&self, p: DVec2) -> bool {
        p.cmpge(self.lo).all() && p.cmple(self.hi).all()
    }

    /// Side of the covering square, `max(w, h)`.
    ///
    /// # Example
    /// ```
    /// assert_eq!(tessera::density::rectangle::Rectangle::UNIT.side(), 1.0);
    /// ```
    pub fn side(&self) -> f64 {
        let size = self.hi - self.lo;
        size.x.max(size.y)
    }

    /// The rectangle's point for a point `u` of the tiling's unit square.
    ///
    /// # Example
    /// ```
    /// let r = tessera::density::rectangle::Rectangle::UNIT;
    /// assert_eq!(r.to_world(glam::DVec2::splat(0.3)), glam::DVec2::splat(0.3));
    /// ```
    pub fn to_world(&self, u: DVec2) -> DVec2 {
        let p = self.lo + u * self.side();
        // rounding may land a point on the far edge: keep the half-open box
        p.min(self.hi - self.hi.abs().max(DVec2::ONE) * f64::EPSILON)
    }

    /// Whether a point lies in the rectangle.
    ///
    /// # Example
    /// ```
    /// let r = tessera::density::rectangle::Rectangle::new(0.0, 0.0, 2.0, 1.0).unwrap();
    /// assert!(r.contains(glam::DVec2::new(1.9, 0.5)) && !r.contains(glam::DVec2::new(1.0, 1.0)));
    /// ```
    pub fn contains(&self, p: DVec2) -> bool {
        p.cmpge(self.lo).all() && p.cmplt(self.hi).all()
    }

    /// `density` (given on the unit square) stretched over the rectangle,
    /// as a density on the tiling's unit square.
    ///
    /// # Example
    /// ```
    /// use tessera::density::{rectangle::Rectangle, Density, Uniform};
    /// use tessera::tiling::plane::PlaneRegion;
    /// let d = Rectangle::new(0.0, 0.0, 2.0, 1.0).unwrap().restrict(Uniform);
    /// assert_eq!(Density::<PlaneRegion>::mean(&d), 0.5);
    /// assert_eq!(Density::<PlaneRegion>::value(&d, glam::DVec2::new(0.5, 0.75)), 0.0);
    /// ```
    pub fn restrict<D: Density<PlaneRegion>>(&self, density: D) -> OnRectangle<D> {
        let size = self.hi - self.lo;
        OnRectangle {
            density,
            stretch: DVec2::splat(self.side()) / size,
        }
    }
}

/// A unit-square density stretched over a [`Rectangle`] and zero beyond it,
/// seen from the tiling's unit square (see [`Rectangle::restrict`]).
///
/// # Example
/// ```
/// use tessera::{density::{plane::Ramp, rectangle::Rectangle}, engine, tiling::plane::PlaneTiling};
/// let rect = Rectangle::new(0.0, 0.0, 1.0, 0.5).unwrap();
/// let s = engine::generate(&PlaneTiling::ppentomino(), &rect.restrict(Ramp), 500, true).unwrap();
/// assert!(s.iter().all(|p| rect.contains(rect.to_world(p.position))));
/// ```
#[derive(Clone, Debug)]
pub struct OnRectangle<D> {
    density: D,
    /// Unit-square coordinates to rectangle coordinates (`side / size`,
    /// at least 1 on each axis).
    stretch: DVec2,
}

impl<D> OnRectangle<D> {
    fn is_square(&self) -> bool {
        self.stretch == DVec2::ONE
    }
}

impl<D: Density<PlaneRegion>> Density<PlaneRegion> for OnRectangle<D> {
    fn bound(&self, region: &PlaneRegion) -> f64 {
        let (lo, hi) = (region.lo * self.stretch, region.hi * self.stretch);
        if lo.x >= 1.0 || lo.y >= 1.0 || hi.x <= 0.0 || hi.y <= 0.0 {
            return 0.0; // wholly outside: the engine skips the tile
        }
        let clipped = PlaneRegion {
            lo: lo.max(DVec2::ZERO),
            hi: hi.min(DVec2::ONE),
            ..*region
        };
        self.density.bound(&clipped)
    }

    fn average(&self, region: &PlaneRegion) -> f64 {
        // the cells whose centres lie in the rectangle, stretched with it;
        // the others count as zero
        let mut inside = PlaneRegion {
            lo: (region.lo * self.stretch).max(DVec2::ZERO),
            hi: (region.hi * self.stretch).min(DVec2::ONE),
            cell: region.cell * (self.stretch.x * self.stretch.y).sqrt(),
            count: 0,
            ..*region
        };
        for &c in region.centres() {
            let r = c * self.stretch;
            if r.cmplt(DVec2::ONE).all() && r.cmpge(DVec2::ZERO).all() {
                inside.cells[inside.count as usize] = r;
                inside.count += 1;
            }
        }
        if inside.count == 0 {
            return 0.0;
        }
        inside.centroid = inside.centres().iter().sum::<DVec2>() / inside.count as f64;
        self.density.average(&inside) * inside.count as f64 / region.count as f64
    }

    fn value(&self, point: DVec2) -> f64 {
        let r = point * self.stretch;
        if r.cmplt(DVec2::ONE).all() && r.cmpge(DVec2::ZERO).all() {
            self.density.value(r)
        } else {
            0.0
        }
    }

    fn mean(&self) -> f64 {
        self.density.mean() / (self.stretch.x * self.stretch.y)
    }

    fn constant(&self) -> Option<f64> {
        if self.is_square() {
            self.density.constant()
        } else {
            None
        }
    }
}

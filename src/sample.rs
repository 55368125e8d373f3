//! What every sampler returns: a position and a progressive rank.

/// A generated sample.
///
/// # Example
/// ```
/// use tessera::{density::Uniform, engine, tiling::sphere::SphereTiling};
/// let samples = engine::generate(&SphereTiling::default(), &Uniform, 10, true).unwrap();
/// assert_eq!(samples.len(), 10);
/// assert!(samples.windows(2).all(|w| w[0].rank <= w[1].rank));
/// ```
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Sample<P> {
    /// Where the sample is.
    pub position: P,
    /// Progressive rank in `[0, 1)`: smaller ranks survive smaller requests.
    pub rank: f64,
}

/// A sample position as Cartesian coordinates, for orders and metrics that
/// only need distances: a unit vector on the sphere (chord distance, which
/// orders pairs as the angle does), `(x, y, 0)` on the plane.
///
/// # Example
/// ```
/// use glam::{DVec2, DVec3};
/// use tessera::Position;
/// assert_eq!(DVec2::new(0.5, 0.25).coordinates(), [0.5, 0.25, 0.0]);
/// assert_eq!(DVec3::Z.coordinates(), [0.0, 0.0, 1.0]);
/// ```
pub trait Position: Copy {
    /// The point in three-dimensional Cartesian coordinates.
    fn coordinates(&self) -> [f64; 3];
}

impl Position for glam::DVec2 {
    fn coordinates(&self) -> [f64; 3] {
        [self.x, self.y, 0.0]
    }
}

impl Position for glam::DVec3 {
    fn coordinates(&self) -> [f64; 3] {
        self.to_array()
    }
}

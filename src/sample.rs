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

//! tessera: fast hierarchical importance sampling with blue-noise properties,
//! built on self-similar tilings.
//!
//! Tiles subdivide by production rules until the local density is reached, a
//! per-tile code thresholds each candidate, and a precomputed offset table
//! places each point. One adaptive engine ([`engine`]) serves every tile
//! system ([`tiling`]); densities ([`density`]) bound themselves over tiles.
//!
//! ```
//! use tessera::{density::sphere::Cap, Sampler};
//! let cap = Cap::new(0.0, 90.0, 30.0, 10.0).unwrap();
//! let points = Sampler::sphere().density(cap).count(500).generate().unwrap();
//! assert_eq!(points.len(), 500);
//! ```

pub mod accuracy;
pub mod baselines;
pub mod density;
pub mod engine;
mod error;
pub mod healpix;
pub mod io;
pub mod lights;
pub mod lut;
mod memory;
pub mod metrics;
pub mod optimize;
pub mod plot;
pub mod polyomino;
pub mod random;
pub mod relax;
pub mod request;
mod sample;
mod sampler;
pub mod synth;
pub mod tiling;
mod voronoi;

pub use error::Error;
pub use sample::Sample;
pub use sampler::Sampler;

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
//!
//! # Features
//!
//! All on by default. With `default-features = false` the library keeps the
//! samplers (sphere, plane, Penrose, polyominoes), densities (caps, polygons,
//! environment maps and HEALPix maps from arrays in memory, HEALPix FITS
//! files), relaxation, lights, metrics, tables and point files, and builds
//! none of these:
//!
//! - `cli`: the `tessera` command line (clap, indicatif); turns on the rest.
//! - `exr`: OpenEXR maps in [`io::image`] and `synth::SynthMap::write_exr`.
//! - `image`: PNG and Radiance `.hdr` maps in [`io::image`], and the PNG
//!   pictures of `plot`.
//! - `baselines`: the samplers tessera is compared with (`baselines`), and
//!   with `image` the accuracy study (`accuracy`).
//!
//! A file whose format needs a feature left out is refused with an error
//! naming the file and the feature.

#[cfg(all(feature = "baselines", feature = "image"))]
pub mod accuracy;
#[cfg(feature = "baselines")]
pub mod baselines;
pub mod blocks;
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
#[cfg(feature = "image")]
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
pub use sample::{Position, Sample};
pub use sampler::Sampler;

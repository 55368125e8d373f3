//! tessera: fast hierarchical importance sampling with blue-noise properties.
pub mod healpix;
pub mod metrics;

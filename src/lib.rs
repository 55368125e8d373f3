//! tessera: fast hierarchical importance sampling with blue-noise properties.
pub mod baselines;
pub mod healpix;
pub mod metrics;

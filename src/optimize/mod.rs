//! Offline optimisation: tiling searches, rankings and Lloyd relaxation that
//! produce the tables in `luts/`. Nothing here runs when sampling.

mod lloyd;
pub mod penrose;
pub mod plane;
pub mod ranking;
pub mod sphere;

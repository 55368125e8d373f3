//! Files: point-set formats (UTK-style text and binary, CSV, GeoJSON) and
//! raster readers. Pictures are [`crate::plot`]'s.

pub mod image;
pub mod points;

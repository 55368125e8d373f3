//! Files: point-set formats (UTK-style text and binary, CSV, GeoJSON) and
//! raster readers, and HEALPix maps in FITS files. Pictures are
//! `crate::plot`'s (the `image` feature).

pub mod fits;
pub mod image;
pub mod points;

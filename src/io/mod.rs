//! Point-set formats (UTK-style text and binary), drawings and raster readers.

pub mod image;
pub mod points;
pub mod svg;

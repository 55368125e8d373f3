//! Point-set formats (UTK-style text and binary), drawings, PNG pictures and
//! raster readers.

pub mod image;
pub mod plot;
pub mod points;
pub mod svg;

//! Point-set formats (UTK-style text and binary) and drawings.

pub mod points;
pub mod svg;

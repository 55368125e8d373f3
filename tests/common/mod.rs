pub mod plane;
pub mod sky;

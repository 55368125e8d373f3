pub mod sky;

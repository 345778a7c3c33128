//! The generated paths (see `paths.rs`).

pub mod paths;

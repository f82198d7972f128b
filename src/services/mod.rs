//! What the shells run, on top of `arlpcg_core`: each service is pure and seeded but for the
//! files it is told to read or write.

pub mod campaign;
pub mod certificate;
pub mod chart;
pub mod difficulty;
pub mod eval;
pub mod fsio;
pub mod generation;
pub mod level_files;
pub mod making;
pub mod onnx;
pub mod panel;
pub mod policies;
pub mod profile;
pub mod train;
pub mod verify;
pub mod view;
pub mod wish;

//! The integration tests, in one binary: the dependencies (rapier3d, candle, ratatui) are linked
//! once rather than once per file. Each module is one area; `common` holds what they share.
#![allow(clippy::unwrap_used)] // a measurement or a test may unwrap (Cargo.toml, [lints])

mod common;

mod architecture;
mod cli;
mod designer;
mod determinism;
mod faults;
mod gltf_export;
mod hostile_input;
mod level_format;
mod onnx_export;
mod pacing;
mod panel;
mod platform_game;
mod ppo_learns;
mod racing_game;
mod report;
mod shipped;
mod train;
mod view;
mod wish;

//! arlpcg: Adversarial Reinforcement Learning for Procedural Content Generation, as a tool.
//!
//! Layers, dependencies pointing down:
//! - shells: [`cli`] and [`commands`] (parse, run, report, write files atomically via [`fsio`]);
//! - [`eval`]: the paper's tables, measured on our game;
//! - [`verify`]: play a level many times and aggregate the Solver's statistics;
//! - [`generation`]: levels from a trained Generator; [`train`] and [`rl`]: PPO and the
//!   training runs that make the policies;
//! - [`game`]: the games as deterministic rapier3d simulations, and rule-based generation;
//! - [`level`]: levels as pure data, their YAML file format and glTF export.
//!
//! Nothing below the shells prints, reads the clock or uses a global RNG: the same inputs give
//! the same bytes.

pub mod bootstrap;
pub mod chart;
pub mod cli;
pub mod commands;
pub mod design;
pub mod difficulty;
pub mod eval;
pub mod fsio;
pub mod game;
pub mod generation;
pub mod level;
pub mod level_files;
pub mod onnx;
pub mod panel;
pub mod policies;
pub mod rating;
pub mod rl;
pub mod seeds;
pub mod shell;
pub mod train;
pub mod verify;

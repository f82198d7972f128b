//! arlpcg's pure, seeded core, the bottom layer of the tool (docs/architecture.md):
//! - [`level`]: levels as data, their YAML file format and glTF export;
//! - [`rl`]: the actor-critic, PPO and its fused update, policy and checkpoint files;
//! - [`game`]: the two games as deterministic rapier3d simulations, their Solver and Generator
//!   environments, scripted players and rule levels;
//! - [`statistics`]: estimates over training seeds and the judges' difficulty rating;
//! - [`seed_ranges`]: which seeds each part of the tool draws from.
//!
//! `game` and `rl` sit side by side on `level`: neither imports the other. Nothing here reads
//! the clock, prints or uses a global RNG (the one file it reads is a level, `level::yaml::load`): the same inputs give the same bytes.
//! This crate depends on no other crate of the workspace, so the compiler refuses an import
//! from the layers above.

pub mod game;
pub mod level;
pub mod rl;
pub mod seed_ranges;
pub mod statistics;

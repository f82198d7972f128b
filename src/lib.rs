//! arlpcg: Adversarial Reinforcement Learning for Procedural Content Generation, as a tool.
//!
//! Three layers, imports pointing down (docs/architecture.md; `tests/suite/architecture.rs`
//! checks the rules the compiler cannot):
//! - [`shells`]: the command line, its subcommands and the terminal designer; they own the
//!   clock, signals, the terminal, progress and the choice of files;
//! - [`services`]: what the shells run: verification, generation, evaluation, training, the
//!   ONNX export, policy and level files;
//! - the crate `arlpcg_core`: levels, the games, PPO; pure and seeded, and a crate of its own,
//!   so it cannot import the layers above.

pub mod services;
pub mod shells;

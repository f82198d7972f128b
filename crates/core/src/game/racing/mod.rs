//! The racing game: a car on a banked road. [`car`] is the rapier3d ray-cast vehicle and its
//! calibrated constants, [`env`] the Solver's environment, [`scripted`] a pure-pursuit driver
//! (test instrument and stand-in Solver), and [`rules`] rule-based tracks.

pub mod car;
pub mod env;
pub mod feasibility;
pub mod generator;
pub mod rules;
pub mod scripted;

pub use car::CarAction;
pub use env::{OBSERVATION_SIZE, RacingEnv, RacingRewards};
pub use scripted::ScriptedDriver;

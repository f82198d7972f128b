//! The platform game: blocks to jump across. [`world`] holds the blocks in rapier3d,
//! [`character`] moves the capsule, [`env`] is the Solver's environment, [`generator`] the Generator's side and a match of both, [`scripted`] a
//! non-learning controller, and [`reach`] the calibrated jumping range.

pub mod character;
pub mod env;
pub mod generator;
pub mod reach;
pub mod rules;
pub mod scripted;
pub mod world;

pub use character::PlatformAction;
pub use env::{OBSERVATION_SIZE, PlatformEnv, PlatformRewards};
pub use scripted::ScriptedController;

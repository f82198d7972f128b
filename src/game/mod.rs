//! The games as deterministic simulations over rapier3d: the same level, seed and actions give
//! the same trajectory, bit for bit. Nothing here prints, reads the clock or uses a global RNG.

pub mod platform;
pub mod racing;
pub mod rules;

use crate::level::stats::Outcome;

/// What one decision led to.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Step {
    pub reward: f32,
    /// The run ended by reaching the goal or failing (no value to bootstrap after it).
    pub terminated: bool,
    /// The run was cut by its time limit.
    pub truncated: bool,
    /// How the run ended, on its last step.
    pub outcome: Option<Outcome>,
}

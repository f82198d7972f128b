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

/// What verification and the designer need from a game's Solver environment. Code written
/// once over `E: SolverEnv` is compiled per game: nothing is dispatched per step.
pub trait SolverEnv: Send + Sync + Sized {
    /// One decision.
    type Action: Copy + Send + Sync;
    /// The game's scripted (non-learning) player.
    type Scripted: Scripted<Self>;
    /// Length of the observation vector.
    const OBSERVATION_SIZE: usize;

    /// Starts a new run, seeded.
    fn reset(&mut self, seed: u64);
    /// Advances one decision.
    fn step(&mut self, action: Self::Action) -> Step;
    /// Writes the observation into `out` (`OBSERVATION_SIZE` values).
    fn observe(&self, out: &mut [f32]);
    /// The action a policy's output row stands for.
    fn action_from_policy_row(row: &[f32]) -> Self::Action;
    /// A uniformly random action (the random baseline).
    fn random_action(rng: &mut rand_chacha::ChaCha8Rng) -> Self::Action;
    /// The scripted player of run `seed`, as verification uses it.
    fn scripted(seed: u64) -> Self::Scripted;
    /// The finished run as verification records it.
    fn trial_result(&self, outcome: Outcome) -> crate::level::stats::TrialResult;
    /// Where the player is (a recorded run's path).
    fn marker(&self) -> [f32; 3];
}

/// A scripted player of environment `E`.
pub trait Scripted<E: SolverEnv> {
    fn act(&mut self, env: &E) -> E::Action;
}

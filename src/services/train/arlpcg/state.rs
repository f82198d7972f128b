//! Where an adversarial run stands (its phase and counters, saved in checkpoints) and the
//! statistics of its matches since they were last taken.

use serde::{Deserialize, Serialize};

/// Which agent is learning.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Phase {
    /// The Solver is learning.
    Solver,
    /// The Generator is learning.
    Generator,
}

/// Progress of the match source and the phase schedule, saved in checkpoints.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct AdversarialState {
    /// Matches started so far (each gets its own seed).
    pub episodes_started: u64,
    /// Which agent is learning.
    pub phase: Phase,
    /// Steps the learning agent has learned from in the current phase.
    pub phase_steps: u64,
    /// Generator decisions learned from, over the run.
    pub generator_steps: u64,
    /// The finish: the Solver's successes and finished hard matches (λ < 0) in the block being
    /// counted (`Finish::generator_until_hard_success`, `Finish::until_hard_success`)...
    #[serde(default, alias = "catch_up_block")]
    pub hard_block: [u32; 2],
    /// ...and the Solver steps where the catch-up ended the finish (none: it has not).
    #[serde(default)]
    pub finish_ended_at: Option<u64>,
    /// The finish's own checks (`Finish::own_check_every`): the largest slack any of them
    /// left ([`OwnControl::slack`](crate::services::train::own_check::OwnControl::slack)),
    /// whose Generator the run keeps as `generator-best-check.safetensors` (none: no check yet).
    #[serde(default)]
    pub best_check: Option<f64>,
    /// Before the finish: the Solver succeeded in too few of the last Generator phase's hard
    /// matches (`GeneratorConfig::hard_success_floor`), so this phase leaves the hard side
    /// unpaid.
    #[serde(default)]
    pub hard_side_unpaid: bool,
}

impl Default for AdversarialState {
    fn default() -> Self {
        Self {
            episodes_started: 0,
            phase: Phase::Solver,
            phase_steps: 0,
            generator_steps: 0,
            hard_block: [0, 0],
            finish_ended_at: None,
            best_check: None,
            hard_side_unpaid: false,
        }
    }
}

/// Episode statistics since they were last taken, split by the sign of λ.
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
pub struct MatchStats {
    /// Matches ended.
    pub episodes: u32,
    /// Matches ended without a valid level.
    pub invalid: u32,
    /// Sum of the Generator's returns over the ended matches.
    pub generator_return_sum: f64,
    /// [easy (λ > 0), hard (λ < 0)]: finished (valid) matches, Solver successes, pieces placed,
    /// the sums of the pieces' two features (`GeneratorGame::PIECE_FEATURES`), and the Solver's
    /// steps in the air.
    pub judged: [u32; 2],
    /// [easy, hard]: Solver successes.
    pub successes: [u32; 2],
    /// [easy, hard]: pieces placed.
    pub pieces: [u32; 2],
    /// [easy, hard]: the sums of the pieces' two features.
    pub feature_sums: [[f64; 2]; 2],
    /// [easy, hard]: the Solver's steps in the air.
    pub air_steps: [u64; 2],
    /// [easy, hard]: the matches the scripted opponent finished, and its successes (counted
    /// apart: the finish's stops count the Solver's).
    #[serde(default)]
    pub scripted_judged: [u32; 2],
    /// [easy, hard]: the scripted opponent's successes.
    #[serde(default)]
    pub scripted_successes: [u32; 2],
}

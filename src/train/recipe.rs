//! The recipe: what `train` does by default for each game (the budget, the racing Solver's
//! discount and phases, each game's finish), so that `arlpcg train --game G --mode M --seed S
//! --out D` alone makes what ships. docs/training.md ("The recipe") says how each value was
//! found.

use super::config::{Finish, TrainConfig};
use crate::game::RacingGame;
use crate::game::generator::GeneratorGame;
use crate::level::Game;

/// The recipe's budget of each game in Solver steps learned from ([`TrainConfig::steps`]).
pub const PLATFORM_STEPS: u64 = 8_000_000;
pub const RACING_STEPS: u64 = 5_000_000;
/// Racing Generator phases are short: each segment costs the Solver (and its snapshots) about
/// 40 steps of driving without learning, and these phases were 73% of a 10M run's time at 10k.
pub const RACING_GENERATOR_PHASE_STEPS: u64 = 4_096;

/// The racing Solver's discount (docs/spec.md §3: γ 0.998; its runs are hundreds of steps
/// longer than a platform run).
pub const RACING_SOLVER_GAMMA: f32 = 0.998;

/// The platform recipe's finish: after its 8M steps the Solver is frozen and the Generator
/// trains on against it alone (no snapshots) in 100k-block phases, four of them between
/// one-iteration Solver phases over 32,768 more Solver steps. Against the population alone
/// the Generator finds nothing its own Solver cannot do (λ = -1 levels succeed 0.93-0.97 of
/// the time); this brings that to about 0.67 while the players it never met keep part of their
/// drop (docs/training.md, "The recipe").
pub const PLATFORM_FINISH: Finish = Finish {
    solver_steps: 32_768,
    generator_phase_steps: 100_000,
    solver_learning_rate: 0.0,
    solver_phase_steps: 1,
    generator_until_hard_success: None,
    until_hard_success: None,
};

/// The racing recipe's finish, in two parts, each ended by the Solver's success on hard
/// matches: a Generator phase against the final Solver (which only plays in it) until that
/// success has fallen to 30% (at most 400k track segments), then the Solver catches up at a
/// constant 1e-4 against that Generator, frozen, until it succeeds on 70% of its hard matches
/// again (at most 1M Solver steps past the budget; its phase is longer than that). Without the
/// catch-up the Generator's λ = -1 tracks were completed by under half of its Solver's runs;
/// with 1M steps of it the Solver drove them all and λ steered nothing; a fixed 140k-segment
/// Generator phase left the Solver at 30% in one run and 60% in another (docs/results.md,
/// "A finish with a catch-up").
pub const RACING_FINISH: Finish = Finish {
    solver_steps: 1_000_000,
    generator_phase_steps: 400_000,
    solver_learning_rate: 1e-4,
    solver_phase_steps: 1_000_000_000,
    generator_until_hard_success: Some(0.3),
    until_hard_success: Some(0.7),
};

impl TrainConfig {
    /// The defaults for training `game`: the paper's values; the racing game differs in the
    /// budget, the Solver's γ, the Generator's rewards and the obstacles of its scenes.
    pub fn for_game(game: Game) -> TrainConfig {
        let mut config = TrainConfig::default();
        if game == Game::Racing {
            config.steps = RACING_STEPS;
            config.solver.gamma = RACING_SOLVER_GAMMA;
            config.generator.rewards = RacingGame::default_rewards();
            config.generator.max_pieces = RacingGame::DEFAULT_MAX_PIECES;
            config.generator.obstacles = crate::game::racing::generator::MATCH_OBSTACLES;
            // What trained the shipped racing Generator: with 30° the road stays near the
            // goal's bearing and cannot make the sustained bends that are hard to drive.
            config.generator.curve_offset = 90.0;
            config.generator.generator_phase_steps = RACING_GENERATOR_PHASE_STEPS;
            config.generator.finish = RACING_FINISH;
        }
        config
    }
}

//! The recipe: what `train` does by default for each game, so that `arlpcg train --game G
//! --mode M --seed S --out D` alone makes what ships. The platform's is the configuration's
//! default (config/mod.rs: its budget and finish); racing's differs in its budget, the Solver's
//! discount and constant learning rate, the Generator's phases, rewards and curve offset, its
//! paced matches and its finish.
//! docs/decisions.md says why each value is what it is.

use super::config::{Finish, SOLO_SOLVER_UPDATE_EPOCHS, ScriptedOpponent, TrainConfig};
use arlpcg_core::game::RacingGame;
use arlpcg_core::game::generator::GeneratorGame;
use arlpcg_core::level::Game;
use arlpcg_core::level::stats::Skill;
use arlpcg_core::rl::checkpoint::TrainMode;

/// The racing recipe's budget in Solver steps learned from ([`TrainConfig::steps`]).
/// Why: docs/decisions.md#d11.
pub const RACING_STEPS: u64 = 5_000_000;
/// Racing Generator phases, in segments. Why: docs/decisions.md#d11.
pub const RACING_GENERATOR_PHASE_STEPS: u64 = 4_096;

/// The share of racing matches whose λ changes along the track
/// ([`GeneratorConfig::paced_share`](super::GeneratorConfig::paced_share)). Why:
/// docs/decisions.md#d12.
pub const RACING_PACED_SHARE: f64 = 0.5;

/// The racing Solver's discount (docs/spec.md §3: γ 0.998; its runs are hundreds of steps
/// longer than a platform run).
pub const RACING_SOLVER_GAMMA: f32 = 0.998;

/// Whether the racing Solver's learning rate anneals to 0 over the budget: it stays at 3e-4.
/// Why: docs/decisions.md#d10.
pub const RACING_SOLVER_ANNEAL_LR: bool = false;

/// The racing recipe's finish: one Generator phase, entropy bonus 0.01, against the final
/// Solver, frozen, and the median scripted driver, each driving half the matches, until the
/// Solver succeeds on half its hard matches (blocks of 32; at most 800k segments), then one
/// frozen Solver iteration. Why: docs/decisions.md#d6 to #d9.
pub const RACING_FINISH: Finish = Finish {
    // Two frozen Solver iterations: the one that opens the finish, then one after the
    // Generator's phase.
    solver_steps: 16_384,
    generator_phase_steps: 800_000,
    generator_until_hard_success: Some(0.5),
    generator_entropy: Some(0.01),
    scripted_opponent: Some(ScriptedOpponent {
        skill: Skill::Median,
        share: 0.5,
    }),
    ..Finish::NONE
};

impl TrainConfig {
    /// The defaults for training `game`: the paper's values; the racing game differs in the
    /// budget, the Solver's γ, the Generator's rewards and the obstacles of its scenes.
    pub fn for_game(game: Game) -> TrainConfig {
        let mut config = TrainConfig::default();
        if game == Game::Racing {
            config.steps = RACING_STEPS;
            config.solver.gamma = RACING_SOLVER_GAMMA;
            config.solver.anneal_lr = RACING_SOLVER_ANNEAL_LR;
            config.generator.rewards = RacingGame::default_rewards();
            config.generator.max_pieces = RacingGame::DEFAULT_MAX_PIECES;
            config.generator.obstacles = arlpcg_core::game::racing::generator::MATCH_OBSTACLES;
            // What trained the shipped racing Generator: with 30° the road stays near the
            // goal's bearing and cannot make the sustained bends that are hard to drive.
            config.generator.curve_offset = 90.0;
            config.generator.generator_phase_steps = RACING_GENERATOR_PHASE_STEPS;
            config.generator.finish = RACING_FINISH;
            config.generator.paced_share = RACING_PACED_SHARE;
        }
        config
    }

    /// The defaults for training `game` in `mode`: the game's, without the finish in
    /// `fixed-aux` (docs/decisions.md#d14), with four update passes for a Solver trained alone
    /// (docs/decisions.md#d15).
    pub fn for_run(game: Game, mode: TrainMode) -> TrainConfig {
        let mut config = Self::for_game(game);
        match mode {
            TrainMode::FixedAux => config.generator.finish = Finish::NONE,
            TrainMode::RulePcg | TrainMode::FixedTrack => {
                config.solver.update_epochs = SOLO_SOLVER_UPDATE_EPOCHS;
            }
            TrainMode::Arlpcg => {}
        }
        config
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::services::train::config::SOLVER_UPDATE_EPOCHS;

    #[test]
    fn the_racing_recipe_has_short_generator_phases_and_a_frozen_finish() {
        let racing = TrainConfig::for_game(Game::Racing);
        assert_eq!(racing.steps, RACING_STEPS);
        assert_eq!(racing.solver.gamma, RACING_SOLVER_GAMMA);
        assert!(!racing.solver.anneal_lr && TrainConfig::for_game(Game::Platform).solver.anneal_lr);
        assert_eq!(racing.generator.curve_offset, 90.0);
        assert_eq!(racing.generator.generator_phase_steps, 4_096);
        assert_eq!(racing.generator.finish, RACING_FINISH);
        assert_eq!(racing.generator.paced_share, 0.5);
        assert_eq!(
            TrainConfig::for_game(Game::Platform).generator.paced_share,
            0.0
        );
        assert_eq!(racing.adversarial_budget(), 5_016_384);
        // The finish: the Generator's phase against the Solver frozen.
        let finish = racing.schedule_at(5_000_000);
        assert_eq!(
            (finish.solver_learning_rate, finish.generator_phase_steps),
            (Some(0.0), 800_000)
        );
        assert_eq!(racing.schedule_at(4_999_999).solver_learning_rate, None);
    }

    #[test]
    fn fixed_aux_drops_the_finish_and_solvers_alone_update_in_four_passes() {
        for game in [Game::Platform, Game::Racing] {
            let fixed_aux = TrainConfig::for_run(game, TrainMode::FixedAux);
            assert_eq!(fixed_aux.generator.finish, Finish::NONE);
            assert_eq!(fixed_aux.adversarial_budget(), fixed_aux.steps);
            assert!(!fixed_aux.in_finish(fixed_aux.steps));
            assert_eq!(
                TrainConfig::for_run(game, TrainMode::Arlpcg),
                TrainConfig::for_game(game)
            );
            for mode in [TrainMode::RulePcg, TrainMode::FixedTrack] {
                let mut solo = TrainConfig::for_run(game, mode);
                assert_eq!(solo.solver.update_epochs, SOLO_SOLVER_UPDATE_EPOCHS);
                solo.solver.update_epochs = SOLVER_UPDATE_EPOCHS;
                assert_eq!(solo, TrainConfig::for_game(game));
            }
        }
    }
}

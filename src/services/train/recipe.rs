//! The recipe: what `train` does by default for each game, so that `arlpcg train --game G
//! --mode M --seed S --out D` alone makes what ships. Every game lays its own recipe over the
//! configuration's defaults (config/mod.rs), a configuration file in its folder
//! ([`GeneratorGame::RECIPE`]: platform's sets the budget, the networks' width, the characters'
//! ranges, rule levels and the finish; racing's the budget, the Solver's discount and constant
//! learning rate, the Generator's phases, curve offset, paced matches and finish), and sets
//! the Generator's rewards, piece budget and obstacles from its own. docs/decisions.md says
//! why each value is what it is.

use super::config::{Finish, SOLO_SOLVER_UPDATE_EPOCHS, TrainConfig, overlay};
use arlpcg_core::game::generator::GeneratorGame;
use arlpcg_core::level::Game;
use arlpcg_core::rl::checkpoint::TrainMode;

impl TrainConfig {
    /// The defaults for training `game`: the configuration's defaults with the game's rewards,
    /// piece budget and scene obstacles, and its recipe laid over them.
    pub fn for_game(game: Game) -> TrainConfig {
        arlpcg_core::for_game!(game, G => Self::recipe::<G>())
    }

    fn recipe<G: GeneratorGame>() -> TrainConfig {
        let mut config = TrainConfig::default();
        config.generator.rewards = G::default_rewards();
        config.generator.max_pieces = G::DEFAULT_MAX_PIECES;
        config.generator.obstacles = G::FACTS.scene_obstacles;
        let defaults = serde_yaml::to_value(&config)
            .expect("a configuration is plain data (a test writes it)");
        let recipe: serde_yaml::Value =
            serde_yaml::from_str(G::RECIPE).expect("every game's recipe reads (a test reads each)");
        serde_yaml::from_value(overlay(defaults, recipe))
            .expect("every game's recipe is a configuration (a test reads each)")
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
    use crate::services::train::config::{SOLVER_UPDATE_EPOCHS, ScriptedOpponent};
    use arlpcg_core::level::stats::Skill;

    #[test]
    fn every_games_recipe_is_a_configuration_its_checks_accept() {
        for game in Game::ALL {
            let config = TrainConfig::for_game(game);
            let text = serde_yaml::to_string(&config).unwrap();
            assert_eq!(TrainConfig::parse_for(&text, game), Ok(config), "{game}");
        }
    }

    #[test]
    fn the_racing_recipe_has_short_generator_phases_and_a_frozen_finish() {
        let racing = TrainConfig::for_game(Game::Racing);
        let platform = TrainConfig::for_game(Game::Platform);
        assert_eq!(racing.steps, 5_000_000);
        assert_eq!(racing.solver.gamma, 0.998);
        assert!(!racing.solver.anneal_lr && platform.solver.anneal_lr);
        assert_eq!(racing.generator.curve_offset, 90.0);
        assert_eq!(racing.generator.generator_phase_steps, 4_096);
        assert_eq!(racing.generator.obstacles, 3);
        assert_eq!(
            racing.generator.finish,
            Finish {
                solver_steps: 16_384,
                generator_phase_steps: 800_000,
                generator_until_hard_success: Some(0.5),
                generator_entropy: Some(0.01),
                scripted_opponent: Some(ScriptedOpponent {
                    skill: Skill::Median,
                    share: 0.5,
                    easy_only: false,
                }),
                ..Finish::NONE
            }
        );
        assert_eq!(racing.generator.paced_share, 0.5);
        assert_eq!(platform.generator.paced_share, 0.0);
        assert!(racing.ability_ranges.is_empty() && racing.generator.rule_level_share == 0.0);
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
    fn the_platform_recipe_trains_narrow_networks_over_the_designers_characters() {
        let platform = TrainConfig::for_game(Game::Platform);
        assert_eq!(platform.hidden, vec![256, 256]);
        let ranges: Vec<(&str, [f64; 2])> = platform
            .ability_ranges
            .iter()
            .map(|(name, range)| (name.as_str(), *range))
            .collect();
        assert_eq!(
            ranges,
            [
                ("character.gravity", [9.0, 25.0]),
                ("character.jump_speed", [4.0, 11.0]),
                ("character.run_speed", [4.0, 9.0]),
            ]
        );
        let generator = &platform.generator;
        assert_eq!(generator.generator_phase_steps, 5_000);
        assert_eq!(generator.hard_success_floor, Some(0.25));
        assert_eq!(generator.rule_level_share, 0.25);
        assert_eq!(generator.rewards.knobs, [0.25, 0.25]);
        let finish = &generator.finish;
        assert_eq!(
            (finish.solver_steps, finish.generator_phase_steps),
            (40_000, 300_000)
        );
        assert_eq!(finish.generator_until_hard_success, Some(0.4));
        assert_eq!(finish.reach_runs, Some(4));
        assert!(finish.knobs_only);
        assert_eq!(finish.paced_share, Some(0.5));
        assert!(
            finish
                .scripted_opponent
                .as_ref()
                .is_some_and(|o| !o.easy_only && o.share == 0.5)
        );
    }

    #[test]
    fn fixed_aux_drops_the_finish_and_solvers_alone_update_in_four_passes() {
        for game in Game::ALL {
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

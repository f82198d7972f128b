//! The platform game: blocks to jump across. [`world`] holds the blocks in rapier3d,
//! [`character`] moves the capsule, [`env`] is the Solver's environment, [`generator`] the Generator's side and a match of both, [`scripted`] a
//! non-learning controller, and [`reach`] the calibrated jumping range.

pub mod character;
pub mod course;
pub mod env;
pub mod generator;
pub mod reach;
pub mod rules;
pub mod scripted;
pub mod world;

pub use character::PlatformAction;
pub use env::{OBSERVATION_SIZE, PlatformEnv, PlatformRewards};
pub use scripted::ScriptedController;

use super::facts::{GameFacts, ObservationFacts};
use super::{GameSpec, NoRuleLevel, Player, RuleAsk};
use crate::level::profile::{Abilities, Profile};
use crate::level::stats::Skill;
use crate::level::{Game, Level, PlatformRulesConfig};

/// The platform game: blocks to jump across.
pub struct PlatformGame;

impl GameSpec for PlatformGame {
    const GAME: Game = Game::Platform;
    const FACTS: &'static GameFacts = &FACTS;
    type Env = PlatformEnv;
    type Scripted = ScriptedController;
    const OBSERVATION_LAYOUT: &'static [(&'static str, usize)] = &env::OBSERVATION_LAYOUT;
    const CONTINUOUS_ACTIONS: &'static [&'static str] = &["forward", "turn"];
    const BINARY_ACTIONS: &'static [&'static str] = &["jump"];

    fn solver_env_with(level: &Level, abilities: Option<Abilities>) -> Option<PlatformEnv> {
        let track = level.platform()?;
        let env = PlatformEnv::new(track, level.goal, PlatformRewards::default());
        Some(match abilities {
            Some(Abilities::Character(character)) => env.with_body(character.into()),
            _ => env,
        })
    }

    fn rule_level_draw(ask: RuleAsk, player: &Player) -> Result<Level, NoRuleLevel> {
        let config = PlatformRulesConfig::default();
        rules::platform_level_draw(ask.seed, ask.aux, ask.goal, &config, player, ask.draw)
            .map_err(|e| NoRuleLevel(e.to_string()))
    }

    fn scripted(seed: u64, skill: Skill) -> ScriptedController {
        ScriptedController::with_skill(seed, scripted::ControllerSkill::of(skill))
    }

    /// Each block's distance and size.
    fn piece_values(level: &Level) -> Vec<Vec<f64>> {
        level.platform().map_or_else(Vec::new, |track| {
            track
                .block_params()
                .iter()
                .map(|b| vec![b.distance, b.size])
                .collect()
        })
    }

    /// The jump's apex, time in the air and length at full speed, and the reach table.
    fn ability_figures(profile: &Profile) -> Vec<String> {
        let Abilities::Character(c) = profile.abilities else {
            return Vec::new();
        };
        let apex = c.jump_speed * c.jump_speed / (2.0 * c.gravity);
        let flight = 2.0 * c.jump_speed / c.gravity;
        let table = reach::measure_reach(character::Body::from(c));
        let reach: Vec<String> = reach::REACH_HEIGHTS
            .iter()
            .zip(table)
            .map(|(h, gap)| match gap < 1.0 {
                true => format!("{h:+} m: none (under 1 m)"),
                false => format!("{h:+} m: {gap} m"),
            })
            .collect();
        vec![
            format!(
                "jump apex {apex:.2} m, {flight:.2} s in the air on the flat, {:.1} m at full speed",
                c.run_speed * flight
            ),
            format!(
                "reach table (largest edge gap the scripted expert clears, by height change): {}",
                reach.join(", ")
            ),
        ]
    }
}

/// The platform game's facts.
pub const FACTS: GameFacts = GameFacts {
    game: Game::Platform,
    piece: "block",
    pieces: "blocks",
    failed_at: "on the way to",
    player_kind: "character",
    endings: &[("fell", "fell"), ("timed_out", "out of time")],
    max_obstacles: 0,
    curve_offset: false,
    reach_runs: Some(reach::REACH_TRIALS),
    scene_obstacles: 0,
    piece_columns: &[("avg_block_distance", " m"), ("avg_block_size", " m")],
    air_time_step: None,
    goal_distance: rules::GOAL_DISTANCE,
    goal_height: rules::GOAL_HEIGHT,
    goal_distance_step: 5.0,
    paper_controllability: [
        "0.97, 6.73 m, 5.95 m", "0.92, 6.98 m, 5.77 m", "0.88, 7.15 m, 5.42 m",
        "0.74, 7.11 m, 4.52 m", "0.69, 7.46 m, 4.01 m",
    ],
    controllability_header: "| λ | success ratio | completed by any | avg block distance | avg block size | blocks | failures on the last block | on the worst block | levels | paper: success, distance, size |\n|---|---|---|---|---|---|---|---|---|---|\n",
    paper_generalization: [
        ("fixed-track", "0.081 ± 0.205, 0.20 (54 steps)"),
        ("rule-pcg", "0.233 ± 0.200, 0.95 (451 steps)"),
        ("fixed-aux", "0.173 ± 0.195, 0.90 (442 steps)"),
        ("arlpcg", "0.457 ± 0.211, 1.00 (467 steps)"),
    ],
    solver_observation: ObservationFacts {
        layout: &env::OBSERVATION_LAYOUT,
        meanings: &env::OBSERVATION_MEANINGS,
    },
    generator_observation: ObservationFacts {
        layout: &generator::GENERATOR_OBSERVATION_LAYOUT,
        meanings: &generator::GENERATOR_OBSERVATION_MEANINGS,
    },
};

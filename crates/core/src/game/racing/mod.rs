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

use super::facts::{GameFacts, ObservationFacts};
use super::{GameSpec, NoRuleLevel, Player, RuleAsk};
use crate::level::profile::{Abilities, Profile};
use crate::level::racing::RacingRulesConfig;
use crate::level::stats::Skill;
use crate::level::{Game, Level};

/// The racing game: a car on a banked road.
pub struct RacingGame;

impl GameSpec for RacingGame {
    const GAME: Game = Game::Racing;
    const FACTS: &'static GameFacts = &FACTS;
    type Env = RacingEnv;
    type Scripted = ScriptedDriver;
    const OBSERVATION_LAYOUT: &'static [(&'static str, usize)] = &env::OBSERVATION_LAYOUT;
    const CONTINUOUS_ACTIONS: &'static [&'static str] = &["throttle", "steer"];
    const BINARY_ACTIONS: &'static [&'static str] = &[];

    fn solver_env_with(level: &Level, abilities: Option<Abilities>) -> Option<RacingEnv> {
        let track = level.racing()?;
        let env = RacingEnv::new(track, level.goal, RacingRewards::default());
        Some(match abilities {
            Some(Abilities::Car(car)) => env.with_car(car.into()),
            _ => env,
        })
    }

    /// The racing rules keep within what any car of the profile ranges drives (the scripted
    /// driver brakes for what it cannot take at speed), so they read only the player's segment
    /// ranges, not its car.
    fn rule_level_draw(ask: RuleAsk, player: &Player) -> Result<Level, NoRuleLevel> {
        let config = RacingRulesConfig {
            obstacles: ask.obstacles,
            ..RacingRulesConfig::default()
        };
        rules::racing_level_draw(ask.seed, ask.aux, ask.goal, &config, player, ask.draw)
            .map_err(|e| NoRuleLevel(e.to_string()))
    }

    fn scripted(seed: u64, skill: Skill) -> ScriptedDriver {
        ScriptedDriver::with_skill(seed, scripted::DriverSkill::of(skill))
    }

    /// Each segment's curve, length and height change (the curve's and the height change's
    /// size, whatever their sign).
    fn piece_values(level: &Level) -> Vec<Vec<f64>> {
        level.racing().map_or_else(Vec::new, |track| {
            track
                .segments
                .iter()
                .map(|s| vec![s.curve.abs(), s.length, s.height.abs()])
                .collect()
        })
    }

    /// The car's top speed and acceleration, the speed it holds through the tightest curves,
    /// and its flight over a crest.
    fn ability_figures(profile: &Profile) -> Vec<String> {
        let Abilities::Car(c) = profile.abilities else {
            return Vec::new();
        };
        let car = car::Car::from(c);
        let top = feasibility::top_speed(car);
        let road = profile.pieces.segments().road();
        let held = |curves: usize| match feasibility::cornering_speed(car, curves, 2, road) {
            v if v >= top => "at full speed".to_string(),
            v => format!("at {v} m/s"),
        };
        let crest_speed = top.min(25.0).floor();
        let crest = feasibility::crest(car, 3.0, crest_speed);
        vec![
            format!(
                "top speed {top:.1} m/s ({:.0} km/h), {:.1} m/s² from rest",
                3.6 * top,
                c.engine_force / c.mass
            ),
            format!(
                "the tightest curve (30° over 20 m) taken {} alone, {} four in a row",
                held(1),
                held(4)
            ),
            format!(
                "a 3 m crest at {crest_speed} m/s: {:.2} s in the air, {:?}",
                crest.air_s, crest.outcome
            ),
        ]
    }
}

/// The racing game's facts.
pub const FACTS: GameFacts = GameFacts {
    game: Game::Racing,
    piece: "segment",
    pieces: "segments",
    failed_at: "on",
    player_kind: "car",
    endings: &[
        ("off_road", "off the road"),
        ("flipped", "flipped"),
        ("timed_out", "out of time"),
    ],
    max_obstacles: crate::level::racing::MAX_OBSTACLES,
    curve_offset: true,
    reach_runs: None,
    scene_obstacles: generator::MATCH_OBSTACLES,
    piece_columns: &[
        ("avg_segment_curve", "°"),
        ("avg_segment_length", " m"),
        ("avg_segment_height", " m"),
    ],
    air_time_step: Some(car::DECISION_DT as f64),
    goal_distance: rules::GOAL_DISTANCE,
    goal_height: rules::GOAL_HEIGHT,
    goal_distance_step: 20.0,
    paper_controllability: [
        "0.99, 14.4°, 28.4 m, 1.5 m", "0.89, 14.7°, 27.1 m, 2.0 m", "0.77, 15.1°, 25.1 m, 2.5 m",
        "0.64, 15.3°, 23.0 m, 3.1 m", "0.61, 16.8°, 21.8 m, 3.9 m",
    ],
    controllability_header: "| λ | success ratio | completed by any | air time per run | avg segment curve | avg segment length | avg segment height change | segments | failures on the last segment | on the worst segment | tracks | paper: success, angle, length, height |\n|---|---|---|---|---|---|---|---|---|---|---|---|\n",
    paper_generalization: [
        ("fixed-track", "0.219 ± 0.280, 0.7 (431 m)"),
        ("rule-pcg", "0.174 ± 0.160, 0.9 (355 m)"),
        ("fixed-aux", "0.163 ± 0.138, 0.8 (382 m)"),
        ("arlpcg", "0.331 ± 0.225, 1.0 (507 m)"),
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

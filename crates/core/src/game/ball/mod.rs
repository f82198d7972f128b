//! The ball game, built only with the `test-game` feature: a ball pushed across blocks to the
//! goal block. It lives in the tests (tests/ball_game) to prove that a game plugs in through
//! [`GameSpec`] and [`GeneratorGame`], its own folder, its track variant and the dispatch: its
//! levels are the platform game's blocks (the platform's rules and Generator build them), its
//! player a ball that rapier's controller rolls over them ([`env`]).

pub mod env;

use rand_chacha::ChaCha8Rng;

use self::env::{BallEnv, BallPusher};
use super::facts::{GameFacts, ObservationFacts};
use super::generator::{BuildLimits, GeneratorGame, GeneratorRewards, Knob, Placement, TrackBuild};
use super::platform::PlatformGame;
use super::platform::generator::PlatformBuild;
use super::{GameSpec, NoRuleLevel, Player, PortState, RuleAsk};
use crate::level::profile::{Abilities, CharacterProfile, Profile};
use crate::level::stats::Skill;
use crate::level::{Game, Level, Track};

/// The ball game.
pub struct BallGame;

/// The ball's abilities: a character's speeds, gravity, pushes and radius (a ball's player is
/// of the platform's kind, and its pieces too: the platform's rules and Generator build for it).
fn ball_of(abilities: Option<Abilities>) -> CharacterProfile {
    match abilities {
        Some(Abilities::Character(ball)) => ball,
        _ => CharacterProfile::default(),
    }
}

impl GameSpec for BallGame {
    const GAME: Game = Game::Ball;
    const FACTS: &'static GameFacts = &FACTS;
    type Env = BallEnv;
    type Scripted = BallPusher;
    const OBSERVATION_LAYOUT: &'static [(&'static str, usize)] = &env::OBSERVATION_LAYOUT;
    const CONTINUOUS_ACTIONS: &'static [&'static str] = &["push_x", "push_z"];
    const BINARY_ACTIONS: &'static [&'static str] = &["hop"];

    fn solver_env_with(level: &Level, abilities: Option<Abilities>) -> Option<BallEnv> {
        let Track::Ball(track) = &level.track else {
            return None;
        };
        Some(BallEnv::new(track, level.goal, ball_of(abilities)))
    }

    fn rule_level_draw(ask: RuleAsk, player: &Player) -> Result<Level, NoRuleLevel> {
        let level = PlatformGame::rule_level_draw(ask, player)?;
        let Track::Platform(blocks) = level.track else {
            return Err(NoRuleLevel("the platform rules built no blocks".into()));
        };
        Ok(Level {
            track: Track::Ball(blocks),
            ..level
        })
    }

    fn scripted(seed: u64, skill: Skill) -> BallPusher {
        BallPusher::new(seed, skill)
    }

    fn piece_values(level: &Level) -> Vec<Vec<f64>> {
        let Track::Ball(track) = &level.track else {
            return Vec::new();
        };
        track
            .block_params()
            .iter()
            .map(|b| vec![b.distance, b.size])
            .collect()
    }

    fn ability_figures(profile: &Profile) -> Vec<String> {
        let ball = ball_of(Some(profile.abilities));
        vec![format!(
            "hop apex {:.2} m, top speed {} m/s",
            ball.jump_speed * ball.jump_speed / (2.0 * ball.gravity),
            ball.run_speed
        )]
    }
}

/// A track of blocks the platform's Generator builds, played by the ball.
#[derive(Debug, Clone)]
pub struct BallBuild(PlatformBuild);

impl TrackBuild for BallBuild {
    fn goal(&self) -> [f64; 3] {
        self.0.goal()
    }
    fn piece_count(&self) -> usize {
        self.0.piece_count()
    }
    fn player(&self) -> &Player {
        self.0.player()
    }
    fn observe(&self, aux: &[f32], out: &mut [f32]) {
        self.0.observe(aux, out);
    }
    fn place(&mut self, row: &[f32]) -> Placement {
        self.0.place(row)
    }
    fn distance_to_goal(&self, k: usize) -> f64 {
        self.0.distance_to_goal(k)
    }
    fn piece_style(&self, piece: usize, out: &mut [f32]) {
        self.0.piece_style(piece, out);
    }
    fn piece_features(&self) -> Vec<[f64; 2]> {
        self.0.piece_features()
    }
    fn into_track(self) -> Track {
        Track::Ball(self.0.track)
    }
    fn port_state(&self) -> PortState {
        self.0.port_state()
    }
}

impl GeneratorGame for BallGame {
    type Build = BallBuild;
    const GENERATOR_OBSERVATION_LAYOUT: &'static [(&'static str, usize)] =
        PlatformGame::GENERATOR_OBSERVATION_LAYOUT;
    const GENERATOR_ACTIONS: &'static [&'static str] = PlatformGame::GENERATOR_ACTIONS;
    const DEFAULT_MAX_PIECES: usize = PlatformGame::DEFAULT_MAX_PIECES;
    const MAX_PIECES: usize = PlatformGame::MAX_PIECES;
    const KNOBS: &'static [Knob] = PlatformGame::KNOBS;
    const PIECE_FEATURES: [&'static str; 2] = PlatformGame::PIECE_FEATURES;
    const RECIPE: &'static str = "{}";

    fn default_rewards() -> GeneratorRewards {
        PlatformGame::default_rewards()
    }

    fn new_build(
        seed: u64,
        goal: Option<[f64; 3]>,
        limits: BuildLimits,
        obstacles: u32,
    ) -> (BallBuild, ChaCha8Rng) {
        let (build, rng) = PlatformGame::new_build(seed, goal, limits, obstacles);
        (BallBuild(build), rng)
    }

    fn kept_build(
        track: &Track,
        goal: [f64; 3],
        pieces: usize,
        limits: BuildLimits,
    ) -> Result<BallBuild, String> {
        let Track::Ball(blocks) = track else {
            return Err("it is not a ball level".into());
        };
        let blocks = Track::Platform(blocks.clone());
        PlatformGame::kept_build(&blocks, goal, pieces, limits).map(BallBuild)
    }

    fn open_env(build: &BallBuild, complete: bool) -> BallEnv {
        let start = crate::level::PlatformTrack::new(*build.0.track.start());
        let mut env = BallEnv::open(&start, build.0.goal, ball_of(build.0.player.abilities));
        env.push_platform(build.0.track.last(), complete);
        env
    }

    fn extend_env(env: &mut BallEnv, build: &BallBuild, complete: bool) {
        env.push_platform(build.0.track.last(), complete);
    }

    fn wants_piece(env: &BallEnv) -> bool {
        env.awaits_platform()
    }

    fn furthest_piece(env: &BallEnv) -> usize {
        env.furthest()
    }

    fn air_steps(_: &BallEnv) -> u32 {
        0
    }

    fn respawn(env: &mut BallEnv, piece: usize, seed: u64) {
        env.reset_on(piece, seed);
    }
}

/// The ball game's facts (its paper figures: none, it is not in the paper).
pub const FACTS: GameFacts = GameFacts {
    game: Game::Ball,
    piece: "block",
    pieces: "blocks",
    failed_at: "on the way to",
    player_kind: "ball",
    endings: &[("fell", "fell"), ("timed_out", "out of time")],
    max_obstacles: 0,
    curve_offset: false,
    reach_runs: None,
    scene_obstacles: 0,
    piece_columns: &[("avg_block_distance", " m"), ("avg_block_size", " m")],
    air_time_step: None,
    goal_distance: super::platform::FACTS.goal_distance,
    goal_height: super::platform::FACTS.goal_height,
    goal_distance_step: 5.0,
    paper_controllability: ["", "", "", "", ""],
    controllability_header: "| λ | success ratio | completed by any | avg block distance | avg block size | blocks | failures on the last block | on the worst block | levels | paper |\n|---|---|---|---|---|---|---|---|---|---|\n",
    paper_generalization: [
        ("fixed-track", ""),
        ("rule-pcg", ""),
        ("fixed-aux", ""),
        ("arlpcg", ""),
    ],
    solver_observation: ObservationFacts {
        layout: &env::OBSERVATION_LAYOUT,
        meanings: &env::OBSERVATION_MEANINGS,
    },
    generator_observation: super::platform::FACTS.generator_observation,
};

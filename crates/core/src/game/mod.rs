//! The games as deterministic simulations over rapier3d: the same level, seed and actions give
//! the same trajectory, bit for bit. Nothing here prints, reads the clock or uses a global RNG.

pub mod facts;
pub mod generator;
pub mod platform;
pub mod racing;

use crate::level::profile::{Abilities, BlockRanges, Pieces, SegmentRanges};
use crate::level::stats::Outcome;
pub use crate::level::stats::Skill;

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

impl Step {
    /// The step that ends a run with `outcome`: a time-out truncates it (a value to bootstrap
    /// remains), every other ending terminates it.
    pub fn finished(outcome: Outcome, reward: f32) -> Self {
        Self {
            reward,
            terminated: outcome != Outcome::TimedOut,
            truncated: outcome == Outcome::TimedOut,
            outcome: Some(outcome),
        }
    }

    /// The step of a decision that earned `reward`: where it ends the run with `outcome`, the
    /// ending's reward (`success`, or `failure` for every other ending) is added.
    pub fn after(outcome: Option<Outcome>, reward: f32, success: f32, failure: f32) -> Self {
        match outcome {
            Some(Outcome::Success) => Self::finished(Outcome::Success, reward + success),
            Some(outcome) => Self::finished(outcome, reward + failure),
            None => Self {
                reward,
                terminated: false,
                truncated: false,
                outcome: None,
            },
        }
    }
}

/// What verification and the designer need from a game's Solver environment. Code written
/// once over `E: SolverEnv` is compiled per game: nothing is dispatched per step.
pub trait SolverEnv: Send + Sync + Sized {
    /// One decision.
    type Action: Copy + Send + Sync;
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
    /// The finished run as verification records it.
    fn trial_result(&self, outcome: Outcome) -> crate::level::stats::TrialResult;
    /// Where the player is (a recorded run's path).
    fn marker(&self) -> [f32; 3];
    /// The game state the observation is computed from, by name, in world coordinates (the
    /// golden episodes an engine's port of the observation is checked against; docs/engines.md):
    /// what the port cannot compute itself (positions, rotations, the distance each ray travels
    /// before it hits) and nothing it can.
    fn port_state(&self) -> PortState;
}

/// Named groups of numbers: a Solver's state as a port of its observation starts from.
pub type PortState = Vec<(&'static str, Vec<f64>)>;

/// A vector's three coordinates as f64.
fn coords(v: rapier3d::math::Vector) -> Vec<f64> {
    v.to_array().map(f64::from).to_vec()
}

/// Who plays a game's levels: a profile's abilities (none: the built-in ones), what the rules
/// derive from them, measured once (the platform character's reach), and the ranges the
/// profile draws pieces from (none: the built-in ones). Rule levels, the Generator's tracks and
/// the Solver's environments are made for one player.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct Player {
    pub abilities: Option<Abilities>,
    /// The platform character's reach (the built-in table in racing, which has none).
    pub reach: platform::reach::Reach,
    pub pieces: Option<Pieces>,
}

impl Player {
    /// The player of `abilities` (none, or the built-in ones: the built-in player, measuring
    /// nothing).
    pub fn of(abilities: Option<Abilities>) -> Self {
        let reach = match abilities {
            Some(Abilities::Platform(character)) => {
                platform::reach::Reach::of(platform::character::Body::from(character))
            }
            _ => platform::reach::Reach::default(),
        };
        Self {
            abilities,
            reach,
            pieces: None,
        }
    }

    /// This player drawing pieces from `pieces` (none: the built-in ranges).
    pub fn with_pieces(self, pieces: Option<Pieces>) -> Self {
        Self { pieces, ..self }
    }

    /// The ranges platform blocks are drawn from.
    pub fn blocks(&self) -> BlockRanges {
        self.pieces
            .map_or_else(BlockRanges::default, |p| p.blocks())
    }

    /// The ranges racing segments are drawn from.
    pub fn segments(&self) -> SegmentRanges {
        self.pieces
            .map_or_else(SegmentRanges::default, |p| p.segments())
    }

    /// The player of one training episode or match of game `game`: its main abilities drawn
    /// within `spread` of its own from `seed` (itself when `spread` is 0), its reach kept.
    pub fn varied(self, game: crate::level::Game, spread: f64, seed: u64) -> Self {
        if spread <= 0.0 {
            return self;
        }
        let own = self.abilities.unwrap_or(Abilities::default_of(game));
        Self {
            abilities: Some(own.varied(spread, seed)),
            ..self
        }
    }
}

/// Writes a Solver's observation of `env` into `out`: the game's observation, then, for an
/// ability-aware Solver (`out` [`MAIN_ABILITIES`](crate::level::profile::MAIN_ABILITIES)
/// longer), the main abilities the run is played with relative to ours (none: ours, all 0).
pub fn observe_solver<G: GameSpec>(env: &G::Env, abilities: Option<&Abilities>, out: &mut [f32]) {
    let base = G::Env::OBSERVATION_SIZE;
    env.observe(&mut out[..base]);
    if out.len() > base {
        let played = abilities.copied().unwrap_or(Abilities::default_of(G::GAME));
        out[base..].copy_from_slice(&played.relative_main());
    }
}

/// A scripted player of environment `E`.
pub trait Scripted<E: SolverEnv> {
    fn act(&mut self, env: &E) -> E::Action;
}

/// One game as the layers above `game` see it: its Solver environment, the Solver's inputs and
/// outputs as a policy card names them, and its rule-based levels. `train`, `verify` and the
/// commands are written once over `G: GameSpec`; the command layer picks [`PlatformGame`] or
/// [`RacingGame`] from a level's or an argument's [`Game`](crate::level::Game), once.
pub trait GameSpec: Send + Sync + 'static {
    const GAME: crate::level::Game;
    type Env: SolverEnv;
    /// The game's scripted (non-learning) player.
    type Scripted: Scripted<Self::Env> + Send + Sync;
    /// The Solver's observation, named parts in order.
    const OBSERVATION_LAYOUT: &'static [(&'static str, usize)];
    /// The Solver's continuous actions, in the policy's order...
    const CONTINUOUS_ACTIONS: &'static [&'static str];
    /// ...and its binary ones, after them.
    const BINARY_ACTIONS: &'static [&'static str];

    /// The Solver's environment on `level` with `abilities` (none: the built-in ones), or `None`
    /// for a level of another game.
    fn solver_env_with(
        level: &crate::level::Level,
        abilities: Option<Abilities>,
    ) -> Option<Self::Env>;
    /// The Solver's environment on `level` with the abilities of the profile it records.
    fn solver_env(level: &crate::level::Level) -> Option<Self::Env> {
        Self::solver_env_with(level, level.profile.as_ref().map(|p| p.abilities))
    }
    /// The rule-based level of `seed` (its goal drawn from the seed) for `player`, if the rules
    /// find one. The level records no profile: its caller names it.
    fn rule_level(seed: u64, player: &Player) -> Option<crate::level::Level>;
    /// The scripted player of run `seed` at `skill`, as verification uses it.
    fn scripted(seed: u64, skill: Skill) -> Self::Scripted;
}

/// The platform game: blocks to jump across.
pub struct PlatformGame;

/// The racing game: a car on a banked road.
pub struct RacingGame;

impl GameSpec for PlatformGame {
    const GAME: crate::level::Game = crate::level::Game::Platform;
    type Env = platform::PlatformEnv;
    type Scripted = platform::ScriptedController;
    const OBSERVATION_LAYOUT: &'static [(&'static str, usize)] = &platform::env::OBSERVATION_LAYOUT;
    const CONTINUOUS_ACTIONS: &'static [&'static str] = &["forward", "turn"];
    const BINARY_ACTIONS: &'static [&'static str] = &["jump"];

    fn solver_env_with(
        level: &crate::level::Level,
        abilities: Option<Abilities>,
    ) -> Option<platform::PlatformEnv> {
        let track = level.platform()?;
        let env =
            platform::PlatformEnv::new(track, level.goal, platform::PlatformRewards::default());
        Some(match abilities {
            Some(Abilities::Platform(character)) => env.with_body(character.into()),
            _ => env,
        })
    }

    fn rule_level(seed: u64, player: &Player) -> Option<crate::level::Level> {
        platform::rules::platform_level(seed, None, None, &Default::default(), player).ok()
    }

    fn scripted(seed: u64, skill: Skill) -> platform::ScriptedController {
        let skill = platform::scripted::ControllerSkill::of(skill);
        platform::ScriptedController::with_skill(seed, skill)
    }
}

impl GameSpec for RacingGame {
    const GAME: crate::level::Game = crate::level::Game::Racing;
    type Env = racing::RacingEnv;
    type Scripted = racing::ScriptedDriver;
    const OBSERVATION_LAYOUT: &'static [(&'static str, usize)] = &racing::env::OBSERVATION_LAYOUT;
    const CONTINUOUS_ACTIONS: &'static [&'static str] = &["throttle", "steer"];
    const BINARY_ACTIONS: &'static [&'static str] = &[];

    fn solver_env_with(
        level: &crate::level::Level,
        abilities: Option<Abilities>,
    ) -> Option<racing::RacingEnv> {
        let crate::level::Track::Racing(track) = &level.track else {
            return None;
        };
        let env = racing::RacingEnv::new(track, level.goal, racing::RacingRewards::default());
        Some(match abilities {
            Some(Abilities::Racing(car)) => env.with_car(car.into()),
            _ => env,
        })
    }

    /// The racing rules keep within what any car of the profile ranges drives (the scripted
    /// driver brakes for what it cannot take at speed), so they read only the player's segment
    /// ranges, not its car.
    fn rule_level(seed: u64, player: &Player) -> Option<crate::level::Level> {
        racing::rules::racing_level(seed, None, None, &Default::default(), player).ok()
    }

    fn scripted(seed: u64, skill: Skill) -> racing::ScriptedDriver {
        racing::ScriptedDriver::with_skill(seed, racing::scripted::DriverSkill::of(skill))
    }
}

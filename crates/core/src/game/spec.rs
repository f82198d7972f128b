//! What a game is to the layers above it: [`GameSpec`] (its Solver environment, inputs and
//! outputs, rule levels, scripted player and facts), [`SolverEnv`] and one decision's [`Step`],
//! the [`Player`] a level is made for. Each game implements them in its own folder.

use crate::level::profile::{Abilities, AbilityRanges, BlockRanges, Pieces, SegmentRanges};
use crate::level::stats::Outcome;
use crate::level::stats::Skill;

/// What one decision led to. A run that ends, however it ends, ends its episode: nothing is
/// bootstrapped after it, a time-out included, since a level's time limit is a rule of its game
/// that costs the failure reward (docs/decisions.md#d18).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Step {
    /// The step's reward.
    pub reward: f32,
    /// How the run ended, on its last step.
    pub outcome: Option<Outcome>,
}

impl Step {
    /// The step that ends a run with `outcome`.
    pub fn finished(outcome: Outcome, reward: f32) -> Self {
        Self {
            reward,
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
pub(crate) fn coords(v: rapier3d::math::Vector) -> Vec<f64> {
    v.to_array().map(f64::from).to_vec()
}

/// Who plays a game's levels: a profile's abilities (none: the built-in ones) and the ranges
/// the profile draws pieces from (none: the built-in ones). Rule levels, the Generator's tracks
/// and the Solver's environments are made for one player; what a game derives from the
/// abilities (the platform character's reach) it measures itself, once per process.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct Player {
    /// The player's abilities (none: the built-in ones).
    pub abilities: Option<Abilities>,
    /// The ranges pieces are drawn from (none: the built-in ones).
    pub pieces: Option<Pieces>,
}

impl Player {
    /// The player of `abilities` (none: the built-in player).
    pub fn of(abilities: Option<Abilities>) -> Self {
        Self {
            abilities,
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
    /// within `ranges` from `seed` (itself when there are none).
    pub fn drawn(
        self,
        game: crate::level::Game,
        ranges: Option<&AbilityRanges>,
        seed: u64,
    ) -> Self {
        let Some(ranges) = ranges else {
            return self;
        };
        let own = self.abilities.unwrap_or(Abilities::default_of(game));
        Self {
            abilities: Some(ranges.draw(&own, seed)),
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
    /// The player's action in the environment's current state.
    fn act(&mut self, env: &E) -> E::Action;
}

/// Why the rules built no level, in the game's own words.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[error("{0}")]
pub struct NoRuleLevel(pub String);

/// Which rule-based level to draw: the level of `seed` (its goal drawn from the seed unless
/// given), the `draw`-th valid one of the seed's stream, with `obstacles` where the game has
/// them; `aux` is recorded, not used (the rules know no λ).
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct RuleAsk {
    /// The level's seed.
    pub seed: u64,
    /// The λ recorded in the level (the rules do not use it).
    pub aux: Option<f64>,
    /// The goal, m (none: drawn from the seed).
    pub goal: Option<[f64; 3]>,
    /// How many obstacles, where the game has them.
    pub obstacles: u32,
    /// Which valid level of the seed's stream, from 0.
    pub draw: u32,
}

/// One game as the layers above `game` see it: its Solver environment, the Solver's inputs and
/// outputs as a policy card names them, its rule-based levels, its scripted player and its
/// facts. `train`, `verify` and the commands are written once over `G: GameSpec` (with
/// [`GeneratorGame`](super::generator::GeneratorGame), its Generator's side); a runtime
/// [`Game`](crate::level::Game) becomes its type once per entry point, through
/// [`for_game!`](crate::for_game). Each game implements it in its own folder.
pub trait GameSpec: Send + Sync + 'static {
    /// The game, as a runtime value.
    const GAME: crate::level::Game;
    /// What the layers above know of the game as plain data.
    const FACTS: &'static super::facts::GameFacts;
    /// The Solver's environment.
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
    /// The rule-based level `ask` names, for `player`, with the rules' default settings. The
    /// level records no profile: its caller names it.
    fn rule_level_draw(ask: RuleAsk, player: &Player) -> Result<crate::level::Level, NoRuleLevel>;
    /// The rule-based level of `seed` (its goal drawn from the seed) for `player`, if the rules
    /// find one.
    fn rule_level(seed: u64, player: &Player) -> Option<crate::level::Level> {
        let ask = RuleAsk {
            seed,
            ..RuleAsk::default()
        };
        Self::rule_level_draw(ask, player).ok()
    }
    /// The scripted player of run `seed` at `skill`, as verification uses it.
    fn scripted(seed: u64, skill: Skill) -> Self::Scripted;
    /// Each piece's parameters of `level`, as [`GameFacts::piece_columns`] names them
    /// (none for a level of another game).
    ///
    /// [`GameFacts::piece_columns`]: super::facts::GameFacts::piece_columns
    fn piece_values(level: &crate::level::Level) -> Vec<Vec<f64>>;
    /// What `profile`'s abilities allow, one line per figure, measured in the game's own
    /// physics (`arlpcg profile check`).
    fn ability_figures(profile: &crate::level::profile::Profile) -> Vec<String>;
}

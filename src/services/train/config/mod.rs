//! The configuration of a training run (`--config FILE`, `--print-config`): the training mode,
//! the Solver's and the Generator's hyper-parameters with the paper's defaults, and the checks
//! serde cannot make.

use std::collections::BTreeMap;
use std::path::Path;

use anyhow::Result;
use serde::{Deserialize, Serialize};

use super::solver_envs::SolverMode;
use arlpcg_core::game::Player;
use arlpcg_core::game::generator::{GeneratorGame, GeneratorRewards};
use arlpcg_core::level::Game;
use arlpcg_core::level::profile::{Abilities, AbilityRanges, ProfileRecord};
use arlpcg_core::rl::checkpoint::TrainMode;
use arlpcg_core::rl::ppo::PpoConfig;

mod checks;
mod finish;
pub(super) use checks::{check_config, check_resumable_change};
pub use finish::{Finish, PLATFORM_FINISH, ScriptedOpponent};

/// The level source of a Solver-only mode; `None` for the adversarial ones.
pub(super) fn solver_only(mode: TrainMode) -> Option<SolverMode> {
    match mode {
        TrainMode::RulePcg => Some(SolverMode::RulePcg),
        TrainMode::FixedTrack => Some(SolverMode::FixedTrack),
        TrainMode::FixedAux | TrainMode::Arlpcg => None,
    }
}

/// Everything a training run is configured by (`--config FILE`, YAML; every field has the
/// default `arlpcg train --print-config` shows, the paper's values where it gives them).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct TrainConfig {
    /// Seeds network initialization and action sampling.
    pub seed: u64,
    /// The run's budget: Solver environment steps in all, over every `--resume` (`--steps`
    /// sets it). Annealed learning rates fall to 0 over it. The default is the recipe's
    /// (platform 8M, racing 5M): every mode of a game learns for the same budget.
    pub steps: u64,
    /// Hidden layer sizes of the actors and critics of both agents (the paper: 2 × 512).
    pub hidden: Vec<usize>,
    /// Minutes between checkpoints.
    pub checkpoint_minutes: f64,
    /// The Solver's PPO (the paper: learning rate 3e-4, γ 0.99 on the platform game);
    /// `num_envs` is also the number of matches in the adversarial modes.
    #[serde(alias = "ppo")]
    pub solver: PpoConfig,
    /// The Generator (adversarial modes only).
    pub generator: GeneratorConfig,
    /// The game profile the run trains for (`train --profile FILE`): the Solver plays with its
    /// abilities, on levels made for them. None: the built-in game.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub profile: Option<ProfileRecord>,
    /// Above 0, the Solver is ability-aware: each episode (each match) is played with the
    /// game's main abilities drawn within this share of the profile's (0.2: ±20%), and the
    /// Solver observes them, so that it plays a profile within the range without retraining.
    /// In [0, 0.5]; 0 (the default): one character or car.
    #[serde(default, skip_serializing_if = "is_zero")]
    pub ability_spread: f64,
    /// Ability-aware agents over ranges of their own, in place of `ability_spread`: each main
    /// ability by name, `[least, most]` (`character.jump_speed: [4, 11]`), drawn per episode and
    /// match among evenly spaced values (`AbilityRanges::draw`). Empty (the default, or
    /// `null` over a recipe that sets ranges): `ability_spread` decides.
    #[serde(
        default,
        deserialize_with = "null_is_empty",
        skip_serializing_if = "BTreeMap::is_empty"
    )]
    pub ability_ranges: BTreeMap<String, [f64; 2]>,
}

fn is_zero(x: &f64) -> bool {
    *x == 0.0
}

/// A map that `null` leaves empty, so a `--config` file can turn off the recipe's.
fn null_is_empty<'de, D, V>(deserializer: D) -> Result<BTreeMap<String, V>, D::Error>
where
    D: serde::Deserializer<'de>,
    V: serde::Deserialize<'de>,
{
    let given: Option<BTreeMap<String, V>> = serde::Deserialize::deserialize(deserializer)?;
    Ok(given.unwrap_or_default())
}

/// The values each style knob of a match is drawn from by default (`knob_values`).
pub const DEFAULT_KNOB_VALUES: [f32; 5] = [-1.0, -0.5, 0.0, 0.5, 1.0];

/// The Generator's side of an adversarial run.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct GeneratorConfig {
    /// The Generator's PPO (the paper: learning rate 2e-4, γ 0.99). One Generator step is one
    /// block; a batch is `num_envs × num_steps` completed decisions.
    pub ppo: PpoConfig,
    /// Reward terms and the weights of each aux input (paper eq. 1; docs/spec.md §2).
    pub rewards: GeneratorRewards,
    /// λ of each match is drawn uniformly from these (`fixed-aux` holds λ = 1).
    pub aux_values: Vec<f32>,
    /// With knobs (`rewards.knobs`), each knob of each match is drawn uniformly from these
    /// (none: [`DEFAULT_KNOB_VALUES`]; 0 is no preference).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub knob_values: Option<Vec<f32>>,
    /// A track that has not reached its goal in this many pieces (blocks, segments) ends as
    /// invalid.
    #[serde(alias = "max_blocks")]
    pub max_pieces: usize,
    /// Racing: obstacles drawn into each match's scene (some draws fall too near the start or
    /// the goal and are dropped); the platform game has none.
    pub obstacles: u32,
    /// Racing: how far, in degrees, the Generator's curve action may ask to turn from the goal's
    /// bearing, in [0, 180] (the segment's curve stays within ±30°). 30 keeps the road within
    /// about 30° of the bearing; 90 (the racing default) lets it bend away from the goal and
    /// back. The platform game has no curve: there it stays 30.
    pub curve_offset: f64,
    /// Log standard deviation of the new Generator's actions (in [-1, 1] units). At 0 (std 1)
    /// its turns span ±180° and almost no track reaches its goal; -1.6 (std 0.2) starts it at
    /// ±36°, ±0.5 m of distance, ±0.4 m of height, and lets PPO widen what pays.
    pub initial_log_std: f32,
    /// The first Solver phase lasts at least this many steps, against the untrained Generator
    /// (random blocks). Without it the Generator learns against a Solver that cannot jump yet:
    /// every match fails whatever it builds, so it learns only to avoid overlaps (long jumps
    /// at every λ), which in turn keeps the Solver from learning (seen in a first run: no
    /// success after 300k steps, where rule-pcg had 0.5).
    pub solver_warmup_steps: u64,
    /// Solver steps learned from in each Solver phase...
    pub solver_phase_steps: u64,
    /// ...and Generator decisions in each Generator phase. The Solver acts about 25 times per
    /// block, so its phase switches about a tenth as often as the Generator's in its own steps.
    pub generator_phase_steps: u64,
    /// Before the finish: a Generator phase whose hard matches (λ < 0) the Solver succeeds in
    /// less often than this leaves the next phase with the hard side unpaid (failures, the
    /// piece cost and air time at λ < 0 pay as at λ = 0, nothing), so the Generator eases its
    /// hard levels back to where the Solver learns from them before it is paid for beating it
    /// again (none: always paid, as in the paper). It was made for a Generator that at once
    /// builds hard levels its young Solver never completes (the 2026-12-04 candidate's seed 4:
    /// hard success 0.03 for 8M steps, validation 0.23); there it held the hard side at the
    /// floor, but the Solver still learned only its Generator's levels, which
    /// `rule_level_share` fixes (docs/trials.md). The finish is always paid.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub hard_success_floor: Option<f64>,
    /// The share of the Solver's environments (`solver.num_envs`, rounded) that play rule
    /// levels, as `rule-pcg` does, instead of the Generator's matches; they play while the
    /// Solver learns and wait while the Generator does (0: every environment is a match, as
    /// in the paper). A Solver that learns only its own Generator's levels may learn them and
    /// nothing else (the 2026-12-04 floor trial's seed 4: its own levels 0.93, rule levels
    /// 0.03; docs/trials.md); rule levels keep it playing levels of every kind.
    #[serde(skip_serializing_if = "is_zero")]
    pub rule_level_share: f64,
    /// While the Generator learns, each match is played by the current Solver or by one of up
    /// to this many earlier snapshots of it, drawn uniformly per match, so that no single
    /// network's blind spot pays (0: the current Solver alone, as in the paper). The snapshots
    /// are part of the Generator's checkpoint.
    pub population: usize,
    /// Solver steps between snapshots (one is taken when a Solver phase ends this long after
    /// the last; the oldest leaves when there are more than `population`).
    pub population_every_steps: u64,
    /// The share of a Generator phase's matches that a snapshot plays (the rest: the current
    /// Solver); none: the current Solver and each snapshot equally often.
    pub snapshot_share: Option<f64>,
    /// The share of matches whose λ changes once along the track (λ before and after drawn
    /// from `aux_values` apart, switching at a fraction of the way to the goal drawn within
    /// [0.25, 0.75]), so that the Generator learns to put difficulty where λ asks for it, as
    /// `generate --aux-curve` uses it (0: one λ per match, as in the paper). Paced matches
    /// are left out of the hard-match success counts.
    pub paced_share: f64,
    /// Later stretches of the run with their own schedule, each from a number of Solver steps
    /// on (the last one reached applies): e.g. a last stage where the Solver is frozen and the
    /// Generator goes on against it and the population.
    pub stages: Vec<Stage>,
    /// After the Solver's budget, the Generator's finish against the Solver frozen and alone.
    #[serde(default)]
    pub finish: Finish,
    /// The check a finished run makes of its own knob ([`OwnCheck`]).
    #[serde(default)]
    pub own_check: OwnCheck,
}

/// What a finished adversarial run plays to say whether its knob works: `levels` of its
/// Generator's levels at λ = +1 and at λ = -1, each played `trials` times by its own Solver
/// (`services/train/own_check.rs`); 0 of either: no check. A file may give one field only.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct OwnCheck {
    /// Levels at each end of λ.
    pub levels: u32,
    /// Runs per level.
    pub trials: u32,
}

impl OwnCheck {
    /// Whether the check plays anything (0 levels or 0 runs: no check).
    pub fn plays(&self) -> bool {
        self.levels > 0 && self.trials > 0
    }
}

impl Default for OwnCheck {
    /// 20 levels × 20 runs at each end: a few seconds to a minute on two cores.
    fn default() -> Self {
        Self {
            levels: 20,
            trials: 20,
        }
    }
}

/// A stretch of an adversarial run with its own schedule.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Stage {
    /// It applies from this many Solver steps on.
    pub from_steps: u64,
    /// The Solver's learning rate in it, in place of `solver.learning_rate` and its annealing
    /// (0: frozen; its phases only play, and its observation normalizer still follows them).
    pub solver_learning_rate: f64,
    pub solver_phase_steps: u64,
    pub generator_phase_steps: u64,
    /// The share of the stage's matches that a snapshot plays (0: the current Solver alone);
    /// none: the run's `snapshot_share`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub snapshot_share: Option<f64>,
}

impl Default for TrainConfig {
    fn default() -> Self {
        Self {
            seed: 0,
            steps: PLATFORM_STEPS,
            hidden: vec![512, 512],
            checkpoint_minutes: 5.0,
            solver: PpoConfig {
                learning_rate: 3e-4,
                gamma: 0.99,
                num_envs: 64,
                num_steps: 128,
                ent_coef: 0.005,
                update_epochs: SOLVER_UPDATE_EPOCHS,
                ..PpoConfig::default()
            },
            generator: GeneratorConfig::default(),
            profile: None,
            ability_spread: 0.0,
            ability_ranges: BTreeMap::new(),
        }
    }
}

impl GeneratorConfig {
    /// The schedule at `solver_steps`: the last stage reached, else the run's own phases.
    pub fn schedule_at(&self, solver_steps: u64) -> Schedule {
        match self
            .stages
            .iter()
            .rev()
            .find(|s| solver_steps >= s.from_steps)
        {
            Some(stage) => Schedule {
                solver_learning_rate: Some(stage.solver_learning_rate),
                solver_phase_steps: stage.solver_phase_steps,
                generator_phase_steps: stage.generator_phase_steps,
                snapshot_share: stage.snapshot_share.or(self.snapshot_share),
                generator_entropy: None,
                generator_learning_rate: None,
                scripted_opponent: None,
                reach_runs: None,
                draw_knobs: !self.finish.knobs_only,
                paced_share: None,
            },
            None => Schedule {
                solver_learning_rate: None,
                solver_phase_steps: self.solver_phase_steps,
                generator_phase_steps: self.generator_phase_steps,
                snapshot_share: self.snapshot_share,
                generator_entropy: None,
                generator_learning_rate: None,
                scripted_opponent: None,
                reach_runs: None,
                draw_knobs: !self.finish.knobs_only,
                paced_share: None,
            },
        }
    }
}

/// The phases in force at a point of a run.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Schedule {
    /// The stage's Solver learning rate (`None`: the configured one, annealed or not).
    pub solver_learning_rate: Option<f64>,
    pub solver_phase_steps: u64,
    pub generator_phase_steps: u64,
    /// The share of matches a snapshot plays (`GeneratorConfig::snapshot_share`).
    pub snapshot_share: Option<f64>,
    /// The Generator's entropy bonus (`None`: `generator.ppo.ent_coef`).
    pub generator_entropy: Option<f32>,
    /// The Generator's learning rate (`None`: `generator.ppo.learning_rate`, annealed or not).
    pub generator_learning_rate: Option<f64>,
    /// The scripted player's share of the matches (`Finish::scripted_opponent`).
    pub scripted_opponent: Option<ScriptedOpponent>,
    /// The runs the Generator's reach counts (`Finish::reach_runs`; none: all of them).
    pub reach_runs: Option<u64>,
    /// Whether the Generator's knobs are drawn (`Finish::knobs_only`), else all 0.
    pub draw_knobs: bool,
    /// The finish's share of paced matches (`Finish::paced_share`; none: the Generator's own).
    pub paced_share: Option<f64>,
}

impl Default for GeneratorConfig {
    fn default() -> Self {
        Self {
            // What trained the shipped Generators: a constant 3e-4 and a little entropy. The
            // paper's 2e-4, annealed, without an entropy bonus, gave Generators that λ did not
            // steer (docs/decisions.md#d3).
            ppo: PpoConfig {
                learning_rate: 3e-4,
                anneal_lr: false,
                gamma: 0.99,
                num_envs: 64,
                num_steps: 16,
                ent_coef: 0.001,
                ..PpoConfig::default()
            },
            rewards: arlpcg_core::for_game!(Game::default(), G => G::default_rewards()),
            aux_values: vec![-1.0, -1.0, -0.5, 0.5, 1.0, 1.0],
            knob_values: None,
            max_pieces: arlpcg_core::for_game!(Game::default(), G => G::DEFAULT_MAX_PIECES),
            obstacles: 0,
            curve_offset: arlpcg_core::game::generator::DEFAULT_CURVE_OFFSET,
            initial_log_std: -1.6,
            solver_warmup_steps: 500_000,
            solver_phase_steps: 100_000,
            generator_phase_steps: 10_000,
            hard_success_floor: None,
            rule_level_share: 0.0,
            population: 4,
            population_every_steps: 500_000,
            snapshot_share: None,
            paced_share: 0.0,
            stages: Vec::new(),
            finish: PLATFORM_FINISH,
            own_check: OwnCheck::default(),
        }
    }
}

/// Configuration files larger than this are refused unread (a full one is 2 kB).
const MAX_CONFIG_BYTES: u64 = 1 << 20;

/// The platform recipe's budget in Solver steps learned from ([`TrainConfig::steps`]).
pub const PLATFORM_STEPS: u64 = 8_000_000;

/// Passes of the Solver's update over each batch where a Generator trains beside it (`arlpcg`,
/// `fixed-aux`). Why: docs/decisions.md#d15.
pub const SOLVER_UPDATE_EPOCHS: usize = 2;

/// Passes of a Solver trained alone (`rule-pcg`, `fixed-track`: the baselines). Why:
/// docs/decisions.md#d15.
pub const SOLO_SOLVER_UPDATE_EPOCHS: usize = 4;

/// The configuration file at `path` laid over the defaults of `game` in `mode`
/// ([`TrainConfig::for_run`]: a baseline's Solver keeps its four update passes unless the file
/// says otherwise).
pub fn load_config(path: &Path, game: Game, mode: TrainMode) -> Result<TrainConfig> {
    let bytes =
        crate::services::fsio::read_limited(path, MAX_CONFIG_BYTES, "training configuration")?;
    let text = String::from_utf8(bytes).map_err(|e| {
        anyhow::anyhow!(
            "{}: not a text file (invalid UTF-8 at byte {})",
            path.display(),
            e.utf8_error().valid_up_to()
        )
    })?;
    TrainConfig::parse_over(&text, TrainConfig::for_run(game, mode), game)
        .map_err(|problem| anyhow::anyhow!("{}: {problem}", path.display()))
}

impl TrainConfig {
    /// The ranges its ability-aware agents train over (`ability_ranges`, or `ability_spread`
    /// around the profile's abilities), none for one character or car; `Err` names the field.
    pub fn trained_over(&self, game: Game) -> Result<Option<AbilityRanges>, String> {
        let named = (!self.ability_ranges.is_empty()).then_some(&self.ability_ranges);
        let spread = (self.ability_spread > 0.0).then_some(self.ability_spread);
        if named.is_some() && spread.is_some() {
            return Err("give ability_ranges or ability_spread, not both".into());
        }
        let base = self
            .player(game)
            .abilities
            .unwrap_or(Abilities::default_of(game));
        AbilityRanges::given(named, spread, &base)
    }

    /// Whether its agents are ability-aware (they observe the abilities they play with).
    pub fn ability_aware(&self) -> bool {
        self.ability_spread > 0.0 || !self.ability_ranges.is_empty()
    }

    /// The player the run trains for: its profile's (checked when the configuration was read),
    /// else the built-in one.
    pub fn player(&self, game: Game) -> Player {
        let profile = self
            .profile
            .as_ref()
            .and_then(|record| record.profile(game).ok());
        crate::services::generation::player_for(profile.as_ref())
    }

    /// How many of the Solver's environments play rule levels in an adversarial run
    /// ([`GeneratorConfig::rule_level_share`]); the rest are the Generator's matches.
    pub fn rule_level_envs(&self) -> usize {
        (self.solver.num_envs as f64 * self.generator.rule_level_share).round() as usize
    }

    /// An adversarial run's budget in Solver steps: `steps`, then the finish's.
    pub fn adversarial_budget(&self) -> u64 {
        self.steps
            .saturating_add(self.generator.finish.solver_steps)
    }

    /// Whether `solver_steps` fall in an adversarial run's finish (past `steps`, if it has one).
    pub fn in_finish(&self, solver_steps: u64) -> bool {
        self.generator.finish.solver_steps > 0 && solver_steps >= self.steps
    }

    /// An adversarial run's schedule at `solver_steps`: the finish past `steps`, else the last
    /// stage reached, else the run's own phases.
    pub fn schedule_at(&self, solver_steps: u64) -> Schedule {
        let finish = self.generator.finish;
        if self.in_finish(solver_steps) {
            return Schedule {
                solver_learning_rate: Some(finish.solver_learning_rate),
                solver_phase_steps: finish.solver_phase_steps,
                generator_phase_steps: finish.generator_phase_steps,
                snapshot_share: Some(0.0),
                generator_entropy: finish.generator_entropy,
                generator_learning_rate: finish.generator_learning_rate,
                scripted_opponent: finish.scripted_opponent,
                reach_runs: finish.reach_runs,
                draw_knobs: true,
                paced_share: finish.paced_share,
            };
        }
        self.generator.schedule_at(solver_steps)
    }

    /// What annealing leaves of the configured learning rates at `solver_steps`: 1 at the
    /// start, 0 from `steps` on.
    pub fn lr_scale(&self, solver_steps: u64) -> f64 {
        (1.0 - solver_steps as f64 / self.steps as f64).max(0.0)
    }

    /// Parses and checks the text of a configuration file for `game`: fields the text leaves
    /// out take that game's defaults ([`TrainConfig::for_game`]); `Err` names the field (and,
    /// for syntax and type errors, the line).
    pub fn parse_for(text: &str, game: Game) -> Result<TrainConfig, String> {
        Self::parse_over(text, Self::for_game(game), game)
    }

    /// `text` laid over `defaults` (a game's, or a mode's), checked for `game`.
    fn parse_over(text: &str, defaults: TrainConfig, game: Game) -> Result<TrainConfig, String> {
        arlpcg_core::level::yaml_limits::check(text)?;
        // Parsed once as written, for errors with their line...
        let _: TrainConfig = serde_yaml::from_str(text).map_err(|e| e.to_string())?;
        // ...then laid over the game's defaults.
        let given: serde_yaml::Value = serde_yaml::from_str(text).map_err(|e| e.to_string())?;
        let mut given = match given {
            serde_yaml::Value::Null => serde_yaml::Value::Mapping(Default::default()),
            other => other,
        };
        rename_aliases(&mut given);
        let defaults = serde_yaml::to_value(defaults).map_err(|e| e.to_string())?;
        let config: TrainConfig =
            serde_yaml::from_value(overlay(defaults, given)).map_err(|e| e.to_string())?;
        check_config(&config, game)?;
        Ok(config)
    }
}

impl TrainConfig {
    /// [`TrainConfig::parse_for`] the platform game.
    pub fn parse(text: &str) -> Result<TrainConfig, String> {
        Self::parse_for(text, Game::default())
    }
}

/// The old names a configuration may use (`ppo` for `solver`, `generator.max_blocks` for
/// `generator.max_pieces`), renamed to the current ones.
fn rename_aliases(given: &mut serde_yaml::Value) {
    fn rename(map: &mut serde_yaml::Mapping, old: &str, new: &str) {
        if let Some(value) = map.remove(old) {
            map.insert(new.into(), value);
        }
    }
    if let serde_yaml::Value::Mapping(top) = given {
        rename(top, "ppo", "solver");
        if let Some(serde_yaml::Value::Mapping(generator)) = top.get_mut("generator") {
            rename(generator, "max_blocks", "max_pieces");
        }
    }
}

/// `given` laid over `defaults`: mappings merge key by key (recursively), anything else given
/// replaces the default.
pub(super) fn overlay(defaults: serde_yaml::Value, given: serde_yaml::Value) -> serde_yaml::Value {
    use serde_yaml::Value;
    match (defaults, given) {
        (Value::Mapping(mut base), Value::Mapping(top)) => {
            for (key, value) in top {
                let merged = match base.remove(&key) {
                    Some(old) => overlay(old, value),
                    None => value,
                };
                base.insert(key, merged);
            }
            Value::Mapping(base)
        }
        (_, given) => given,
    }
}

#[cfg(test)]
mod tests;

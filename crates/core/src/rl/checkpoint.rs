//! Policies and training checkpoints as bytes: safetensors for the tensors, with everything
//! else (card, normalizer, counters, RNG) as JSON in the safetensors metadata, so that one file
//! is one atomic unit. The shell writes the bytes atomically.

use std::collections::HashMap;

use candle_core::{Device, Tensor};
use serde::{Deserialize, Serialize};

use super::normalizer::RunningNorm;
use super::policy::{ActorCritic, PolicyShape};
use super::ppo::Ppo;
use super::timing::TimeSplit;
use crate::level::Game;

/// The `format` of every policy card.
pub const POLICY_FORMAT: &str = "arlpcg-policy";
/// The `version` of every policy card this build writes and reads.
pub const POLICY_VERSION: u32 = 1;
/// The largest policy or checkpoint file read (the paper's 2 × 512 network is 2.3 MB, its
/// checkpoint with optimizer moments 7 MB).
pub const MAX_POLICY_BYTES: u64 = 256 * 1024 * 1024;
/// The most hidden layers a policy card may claim.
const MAX_HIDDEN_LAYERS: usize = 64;
const CARD_KEY: &str = "card";
const TRAINING_KEY: &str = "training_state";

/// Which side of the game a policy plays.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Role {
    /// Plays the levels.
    Solver,
    /// Builds the levels.
    Generator,
}

impl std::fmt::Display for Role {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(match self {
            Role::Solver => "solver",
            Role::Generator => "generator",
        })
    }
}

/// How the Solver is trained (the paper's baselines and its method, docs/spec.md §3).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum TrainMode {
    /// On a fresh rule-based level every episode (the Rule-PCG baseline).
    RulePcg,
    /// On a small fixed set of rule-based levels (the Fixed-Track baseline).
    FixedTrack,
    /// Against a Generator that always has λ = 1 (the ablation).
    FixedAux,
    /// Against a Generator with λ drawn per match (the full method).
    Arlpcg,
}

impl TrainMode {
    /// Every mode, in the order tables list them.
    pub const ALL: [TrainMode; 4] = [
        TrainMode::RulePcg,
        TrainMode::FixedTrack,
        TrainMode::FixedAux,
        TrainMode::Arlpcg,
    ];

    /// The mode whose [`name`](Self::name) is `name` (as a card records it).
    pub fn from_name(name: &str) -> Option<TrainMode> {
        Self::ALL.into_iter().find(|mode| mode.name() == name)
    }

    /// The mode's name on the command line and in files (`rule-pcg`, `fixed-track`, ...).
    pub fn name(self) -> &'static str {
        match self {
            TrainMode::RulePcg => "rule-pcg",
            TrainMode::FixedTrack => "fixed-track",
            TrainMode::FixedAux => "fixed-aux",
            TrainMode::Arlpcg => "arlpcg",
        }
    }
}

impl std::fmt::Display for TrainMode {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.name())
    }
}

/// What a policy is and how it came to be: saved beside its weights (and inside them).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct PolicyCard {
    /// Always [`POLICY_FORMAT`].
    pub format: String,
    /// The card's format version ([`POLICY_VERSION`]).
    pub version: u32,
    /// The game the policy plays.
    pub game: Game,
    /// Which side of the game it plays.
    pub role: Role,
    /// Named parts of the observation vector and their sizes, in order.
    pub observation: Vec<(String, usize)>,
    /// The names of its continuous actions, in order.
    pub continuous_actions: Vec<String>,
    /// The names of its binary actions, in order.
    pub binary_actions: Vec<String>,
    /// The network's sizes.
    pub network: PolicyShape,
    /// The observation normalizer's statistics, frozen.
    pub normalizer: RunningNorm,
    /// How it was trained.
    pub training: TrainingRecord,
    /// Measured results, filled in by evaluation.
    #[serde(default)]
    pub results: HashMap<String, f64>,
    /// Generators only: the piece budget its `blocks_left` / `segments_left` observation counts
    /// down from (absent: the default of `train`; platform cards before racing call it
    /// `max_blocks`).
    #[serde(default, alias = "max_blocks", skip_serializing_if = "Option::is_none")]
    pub max_pieces: Option<usize>,
    /// Racing Generators only: how far its curve action may turn from the goal's bearing,
    /// degrees (absent: 30, as every racing Generator before it was trained).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub curve_offset: Option<f64>,
    /// Platform Generators only: its jumps are cut to the gaps the reach measurement clears
    /// in at least this many of its 8 runs (absent: all 8, the reach table, as every Generator
    /// before it; `generator.finish.reach_runs`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub reach_runs: Option<u64>,
    /// The game profile the policy was trained for (`train --profile`; absent: the built-in
    /// game).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub profile: Option<crate::level::profile::ProfileRecord>,
    /// Ability-aware policies given as a share: each main ability was drawn within this share
    /// (0.2: ±20%) of the profile's (or ours) in training; a Solver refuses a profile beyond it.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub ability_spread: Option<f64>,
    /// Ability-aware policies: the range each main ability was drawn from in training, by
    /// field name (written by every ability-aware card since ranges; older cards give only
    /// `ability_spread`); a Solver refuses a profile beyond them.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub ability_ranges: Option<std::collections::BTreeMap<String, [f64; 2]>>,
}

/// How a policy was trained.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct TrainingRecord {
    /// How the Solver was trained.
    pub mode: TrainMode,
    /// Environment steps trained.
    pub steps: u64,
    /// Wall-clock seconds trained, over all sessions.
    pub wall_time_s: f64,
    /// The run's seed.
    pub seed: u64,
    /// The commit that trained it, `-dirty` when the tree held uncommitted changes.
    pub commit: String,
    /// The command that started the run.
    pub command: String,
    /// The commands of the sessions that resumed it, in order (a run from one command has
    /// only that command plus `--resume` here).
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub resumed_with: Vec<String>,
    /// A Generator trained against a population: the Solver steps at which each earlier
    /// Solver it played was taken, oldest first (the current Solver played too).
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub population: Vec<u64>,
    /// Where the run's time went, over every session (both agents' iterations).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub time_split: Option<TimeSplit>,
    /// The update's FLOPs per second over the matrix-product peak of the last session's
    /// machine ([`crate::rl::fused::matmul_peak_flops`]).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub update_mfu: Option<f64>,
}

/// Everything needed to continue a training run where it stopped.
#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct TrainingState {
    /// Environment steps collected so far.
    pub global_step: u64,
    /// PPO iterations done so far.
    pub iteration: u64,
    /// Adam's step count, for its bias correction.
    pub adam_step: u64,
    /// Wall-clock seconds trained so far, over all sessions.
    pub wall_time_s: f64,
    /// The run's configuration (game-specific), as it started.
    pub config: serde_json::Value,
    /// The run's RNG, where it stopped.
    pub rng: rand_chacha::ChaCha8Rng,
    /// Game-specific progress (e.g. the next level seed), opaque here.
    pub source: serde_json::Value,
    /// Each environment's return so far in its episode under way (none: start afresh).
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub episode_returns: Vec<f32>,
    /// Where the run's time went so far, over every session.
    #[serde(default)]
    pub time_split: TimeSplit,
}

impl TrainingState {
    /// The numbers a resume carries on are checked like user input: seconds finite and not
    /// negative, episode returns finite. `Err` names the field.
    pub fn check(&self) -> Result<(), String> {
        let split = &self.time_split;
        let numbers = std::iter::once(("wall_time_s".to_string(), self.wall_time_s))
            .chain(
                split
                    .buckets()
                    .map(|(name, value)| (format!("time_split.{name}_s"), value)),
            )
            .chain([("time_split.update_flops".into(), split.update_flops)])
            .chain(
                split
                    .stretches
                    .named()
                    .map(|(name, value)| (format!("time_split.stretches ({name})"), value)),
            );
        for (name, value) in numbers {
            if !(value.is_finite() && value >= 0.0) {
                return Err(format!("{name} is {value}, not a finite number >= 0"));
            }
        }
        if self.episode_returns.iter().any(|r| !r.is_finite()) {
            return Err("episode_returns holds a value that is not a finite number".into());
        }
        Ok(())
    }
}

/// Why a policy or checkpoint could not be read.
#[derive(Debug, thiserror::Error)]
pub enum PolicyError {
    /// The bytes are not a safetensors file (the reader's words).
    #[error("not a safetensors file: {0}")]
    NotSafetensors(String),
    /// The file has no policy card in its metadata.
    #[error("no policy card inside: not an arlpcg policy")]
    NoCard,
    /// The card is unreadable or disagrees with the file or the game.
    #[error("policy card: {0}")]
    Card(String),
    /// The policy is for another game or role.
    #[error("this is a {found} policy, expected a {expected} one")]
    WrongKind {
        /// The file's game and role.
        found: String,
        /// The game and role asked for.
        expected: String,
    },
    /// A tensor is missing or has the wrong type or shape.
    #[error("tensor `{name}`: {problem}")]
    Tensor {
        /// The tensor's name.
        name: String,
        /// What is wrong with it.
        problem: String,
    },
    /// The file holds no training state: it is not a checkpoint.
    #[error("no training state inside: not a checkpoint")]
    NoTrainingState,
}

/// Serializes a policy (weights + card) to safetensors bytes.
pub fn policy_bytes(policy: &ActorCritic, card: &PolicyCard) -> Vec<u8> {
    let tensors: Vec<(String, Tensor)> = policy
        .named_vars()
        .into_iter()
        .map(|(n, v)| (n, v.as_tensor().clone()))
        .collect();
    let metadata = HashMap::from([(
        CARD_KEY.to_string(),
        serde_json::to_string(card).expect("cards serialize"),
    )]);
    safetensors::serialize(tensors, Some(metadata)).expect("policy tensors serialize")
}

/// Serializes a training checkpoint: policy, optimizer moments, card and training state, and
/// `extra` tensors the run keeps beside them (named apart from the policy's).
pub fn checkpoint_bytes(
    ppo: &Ppo,
    card: &PolicyCard,
    state: &TrainingState,
    extra: Vec<(String, Tensor)>,
) -> Vec<u8> {
    let vars = ppo.policy.named_vars();
    let mut tensors: Vec<(String, Tensor)> = vars
        .iter()
        .map(|(n, v)| (n.clone(), v.as_tensor().clone()))
        .collect();
    tensors.extend(ppo.adam.named_state(&vars));
    tensors.extend(extra);
    let metadata = HashMap::from([
        (
            CARD_KEY.to_string(),
            serde_json::to_string(card).expect("cards serialize"),
        ),
        (
            TRAINING_KEY.to_string(),
            serde_json::to_string(state).expect("training state serializes"),
        ),
    ]);
    safetensors::serialize(tensors, Some(metadata)).expect("checkpoint tensors serialize")
}

/// A policy read back, checked against the game and role it must play.
pub struct LoadedPolicy {
    /// The network, with the file's weights.
    pub policy: ActorCritic,
    /// The policy's card.
    pub card: PolicyCard,
    /// Every tensor in the file, by name.
    pub tensors: HashMap<String, Tensor>,
    training: Option<String>,
}

impl LoadedPolicy {
    /// The training state, for checkpoints.
    pub fn training_state(&self) -> Result<TrainingState, PolicyError> {
        let text = self.training.as_ref().ok_or(PolicyError::NoTrainingState)?;
        let state: TrainingState = serde_json::from_str(text)
            .map_err(|e| PolicyError::Card(format!("training state: {e}")))?;
        state
            .check()
            .map_err(|problem| PolicyError::Card(format!("training state: {problem}")))?;
        Ok(state)
    }
}

/// A normalizer must hold finite means, finite positive variances and a positive count.
fn check_normalizer(norm: &RunningNorm) -> Result<(), PolicyError> {
    let problem = if norm.mean.iter().any(|m| !m.is_finite()) {
        "normalizer: a mean is not a finite number"
    } else if norm.var.iter().any(|v| !(v.is_finite() && *v > 0.0)) {
        "normalizer: a variance is not a finite number > 0"
    } else if !(norm.count.is_finite() && norm.count > 0.0) {
        "normalizer: count is not a finite number > 0"
    } else {
        return Ok(());
    };
    Err(PolicyError::Card(problem.into()))
}

/// The card's own lists must agree with its network: as many named observation values, and
/// continuous and binary actions, as the network has inputs and outputs of each kind.
fn check_card_agrees(card: &PolicyCard) -> Result<(), PolicyError> {
    let network = &card.network;
    let observed: usize = card.observation.iter().map(|(_, n)| n).sum();
    let problem = if observed != network.observation {
        format!(
            "card field observation names {observed} values, its network observes {}",
            network.observation
        )
    } else if card.continuous_actions.len() != network.continuous {
        format!(
            "card field continuous_actions names {} actions, its network has {}",
            card.continuous_actions.len(),
            network.continuous
        )
    } else if card.binary_actions.len() != network.binary {
        format!(
            "card field binary_actions names {} actions, its network has {}",
            card.binary_actions.len(),
            network.binary
        )
    } else {
        return Ok(());
    };
    Err(PolicyError::Card(problem))
}

/// Sets `var` to the tensor `name` of `tensors`, checked for the variable's shape and for finite
/// values.
pub fn restore_var(
    tensors: &HashMap<String, Tensor>,
    name: &str,
    var: &candle_core::Var,
) -> Result<(), PolicyError> {
    let problem = |problem: String| PolicyError::Tensor {
        name: name.to_string(),
        problem,
    };
    let saved = tensors.get(name).ok_or_else(|| problem("missing".into()))?;
    if saved.dims() != var.as_tensor().dims() {
        return Err(problem(format!(
            "shape {:?}, the network needs {:?}",
            saved.dims(),
            var.as_tensor().dims()
        )));
    }
    let values = saved
        .flatten_all()
        .and_then(|t| t.to_vec1::<f32>())
        .map_err(|e| problem(e.to_string()))?;
    if values.iter().any(|v| !v.is_finite()) {
        return Err(problem("holds NaN or infinite values".into()));
    }
    var.set(saved).map_err(|e| problem(e.to_string()))
}

/// The card of a policy or checkpoint, whatever its game and role (nothing else is checked).
pub fn read_card(bytes: &[u8]) -> Result<PolicyCard, PolicyError> {
    Ok(read_header(bytes)?.1)
}

fn read_header(bytes: &[u8]) -> Result<(safetensors::tensor::Metadata, PolicyCard), PolicyError> {
    let (_, header) = safetensors::SafeTensors::read_metadata(bytes)
        .map_err(|e| PolicyError::NotSafetensors(e.to_string()))?;
    let metadata = header.metadata().clone().unwrap_or_default();
    let card_text = metadata.get(CARD_KEY).ok_or(PolicyError::NoCard)?;
    let card: PolicyCard =
        serde_json::from_str(card_text).map_err(|e| PolicyError::Card(e.to_string()))?;
    if card.format != POLICY_FORMAT || card.version != POLICY_VERSION {
        return Err(PolicyError::Card(format!(
            "format {} version {} is not {POLICY_FORMAT} version {POLICY_VERSION}",
            card.format, card.version
        )));
    }
    Ok((header, card))
}

/// The size of the ability part a card's observation ends with (0: none): the game's main
/// abilities.
fn ability_part(card: &PolicyCard) -> Result<usize, PolicyError> {
    match card.observation.last() {
        Some((name, size)) if name == crate::level::profile::ABILITIES_PART => {
            if *size == crate::level::profile::MAIN_ABILITIES {
                Ok(*size)
            } else {
                Err(PolicyError::Card(format!(
                    "card field observation ends with {size} abilities, not the game's {}",
                    crate::level::profile::MAIN_ABILITIES
                )))
            }
        }
        _ => Ok(0),
    }
}

/// The size of the knobs' part of a card's observation (0: none): a Generator's style knobs,
/// after the game's observation (their number is the caller's to check against its game).
pub fn knob_part(card: &PolicyCard) -> usize {
    card.observation
        .iter()
        .find(|(name, _)| name == crate::level::KNOBS_PART)
        .map_or(0, |(_, size)| *size)
}

/// Reads a policy or checkpoint, requiring `game` and `role` and the observation size the game
/// produces now (with the knobs and abilities its card names after it).
pub fn load_policy(
    bytes: &[u8],
    game: Game,
    role: Role,
    observation_size: usize,
) -> Result<LoadedPolicy, PolicyError> {
    let (header, card) = read_header(bytes)?;
    let metadata = header.metadata().clone().unwrap_or_default();
    if card.game != game || card.role != role {
        return Err(PolicyError::WrongKind {
            found: format!("{} {}", card.game, card.role),
            expected: format!("{game} {role}"),
        });
    }
    // The card must agree with its own network before either is held against the game.
    check_card_agrees(&card)?;
    // An ability-aware Solver observes the game's main abilities after the game's observation.
    let observation_size = observation_size + knob_part(&card) + ability_part(&card)?;
    if card.network.observation != observation_size {
        return Err(PolicyError::Card(format!(
            "its network observes {} values but the {game} {role} observes {observation_size}",
            card.network.observation
        )));
    }
    if card.normalizer.mean.len() != observation_size
        || card.normalizer.var.len() != observation_size
    {
        return Err(PolicyError::Card(format!(
            "its normalizer has {} means and {} variances but the {game} {role} observes {observation_size} values",
            card.normalizer.mean.len(),
            card.normalizer.var.len()
        )));
    }
    check_normalizer(&card.normalizer)?;
    if card.network.hidden.len() > MAX_HIDDEN_LAYERS {
        return Err(PolicyError::Card(format!(
            "its network has {} hidden layers, more than {MAX_HIDDEN_LAYERS}",
            card.network.hidden.len()
        )));
    }
    // The card's network against the file's own tensor table, before anything is allocated:
    // a card may claim any size, the tensors are bounded by the file.
    let table = header.tensors();
    for (name, dims) in card.network.named_dims() {
        let problem = match table.get(&name) {
            None => "missing".to_string(),
            Some(info) if info.dtype != safetensors::Dtype::F32 => {
                format!("holds {:?} values, not F32", info.dtype)
            }
            Some(info) if info.shape != dims => {
                format!("shape {:?}, the card's network needs {dims:?}", info.shape)
            }
            Some(_) => continue,
        };
        return Err(PolicyError::Tensor { name, problem });
    }
    let tensors = candle_core::safetensors::load_buffer(bytes, &Device::Cpu)
        .map_err(|e| PolicyError::NotSafetensors(e.to_string()))?;
    let policy =
        ActorCritic::new(card.network.clone(), 0).map_err(|e| PolicyError::Card(e.to_string()))?;
    for (name, var) in policy.named_vars() {
        restore_var(&tensors, &name, &var)?;
    }
    Ok(LoadedPolicy {
        policy,
        card,
        tensors,
        training: metadata.get(TRAINING_KEY).cloned(),
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn card(shape: &PolicyShape) -> PolicyCard {
        PolicyCard {
            format: POLICY_FORMAT.into(),
            version: POLICY_VERSION,
            game: Game::Platform,
            role: Role::Solver,
            observation: vec![("x".into(), shape.observation)],
            continuous_actions: vec!["forward".into(), "turn".into()],
            binary_actions: vec!["jump".into()],
            network: shape.clone(),
            normalizer: RunningNorm::new(shape.observation),
            training: TrainingRecord {
                mode: TrainMode::RulePcg,
                steps: 0,
                wall_time_s: 0.0,
                seed: 0,
                commit: "none".into(),
                command: String::new(),
                resumed_with: Vec::new(),
                population: Vec::new(),
                time_split: None,
                update_mfu: None,
            },
            results: HashMap::new(),
            max_pieces: None,
            curve_offset: None,
            reach_runs: None,
            profile: None,
            ability_spread: None,
            ability_ranges: None,
        }
    }

    fn small_shape() -> PolicyShape {
        PolicyShape {
            observation: 5,
            hidden: vec![8],
            continuous: 2,
            binary: 1,
        }
    }

    #[test]
    fn a_policy_round_trips_and_wrong_kinds_are_refused() {
        let shape = small_shape();
        let policy = ActorCritic::new(shape.clone(), 4).unwrap();
        let bytes = policy_bytes(&policy, &card(&shape));
        let loaded = load_policy(&bytes, Game::Platform, Role::Solver, 5).unwrap();
        assert_eq!(loaded.policy.first_weights(), policy.first_weights());
        let err = load_policy(&bytes, Game::Platform, Role::Generator, 5)
            .err()
            .unwrap();
        assert_eq!(
            err.to_string(),
            "this is a platform solver policy, expected a platform generator one"
        );
        let err = load_policy(&bytes, Game::Platform, Role::Solver, 40)
            .err()
            .unwrap();
        assert!(err.to_string().contains("observes 5 values"), "{err}");
        assert!(matches!(
            load_policy(b"garbage", Game::Platform, Role::Solver, 5),
            Err(PolicyError::NotSafetensors(_))
        ));
        assert!(matches!(
            loaded.training_state(),
            Err(PolicyError::NoTrainingState)
        ));
    }

    /// A card that claims a huge network, or a normalizer that is not a distribution, is refused
    /// before any tensor is allocated (a card claiming 2^30 hidden units made the loader
    /// allocate 172 GB and abort).
    #[test]
    fn cards_that_disagree_with_the_tensors_or_hold_bad_normalizers_are_refused() {
        let shape = small_shape();
        let policy = ActorCritic::new(shape.clone(), 4).unwrap();
        let refused = |card: PolicyCard| {
            load_policy(
                &policy_bytes(&policy, &card),
                Game::Platform,
                Role::Solver,
                5,
            )
            .err()
            .map(|e| e.to_string())
            .unwrap_or_default()
        };
        let mut huge = card(&shape);
        huge.network.hidden = vec![1 << 30, 1 << 30];
        let err = refused(huge);
        assert!(
            err.contains("actor.0.weight") && err.contains("[5, 1073741824]"),
            "{err}"
        );
        let mut deep = card(&shape);
        deep.network.hidden = vec![8; 100];
        assert!(refused(deep).contains("100 hidden layers"));
        for (k, bad) in [0.0, -1.0].into_iter().enumerate() {
            let mut card = card(&shape);
            card.normalizer.var[k] = bad;
            let err = refused(card);
            assert!(
                err.contains("variance is not a finite number > 0"),
                "{bad}: {err}"
            );
        }
        // JSON has no NaN or infinity: they arrive as null and are refused as not a number.
        for bad in [f64::NAN, f64::INFINITY] {
            let mut card = card(&shape);
            card.normalizer.var[0] = bad;
            let err = refused(card);
            assert!(err.contains("policy card: invalid type: null"), "{err}");
        }
        let mut short = card(&shape);
        short.normalizer.var.pop();
        let err = refused(short);
        assert!(err.contains("5 means and 4 variances"), "{err}");
    }
}

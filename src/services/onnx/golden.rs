//! Golden episodes: a real run of a Solver policy on a rule level of its game, each decision's
//! game state ([`SolverEnv::port_state`]), the raw observation the game computed from it and the
//! deterministic action the policy (and so its ONNX graph) chose. An engine's port of the
//! observation recomputes each frame's observation from its state and runs the graph on it;
//! `.ci/port-check.py` is such a port, written from docs/engines.md alone.

use std::collections::BTreeMap;

use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;
use serde::{Deserialize, Serialize};

use arlpcg_core::game::{GameSpec, SolverEnv};
use arlpcg_core::level::PolicyRef;
use arlpcg_core::rl::checkpoint::PolicyCard;
use arlpcg_core::rl::policy::{ActMode, ActorCritic};

/// The rule level a golden episode plays: the first seed from here whose rules find a level.
const GOLDEN_LEVEL_SEED: u64 = 1;
/// The run's reset seed (the start's jitter).
const GOLDEN_RUN_SEED: u64 = 0;

/// A Solver's run, decision by decision.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct GoldenEpisode {
    pub format: String,
    pub version: u32,
    pub game: String,
    pub role: String,
    pub policy: PolicyRef,
    /// The level played, as its YAML file.
    pub level: String,
    /// The run's reset seed.
    pub run_seed: u64,
    /// How the run ended.
    pub outcome: String,
    pub frames: Vec<GoldenFrame>,
}

/// One decision.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct GoldenFrame {
    /// The game state by name ([`SolverEnv::port_state`]).
    pub state: BTreeMap<String, Vec<f64>>,
    /// The raw observation (before the normalizer the graph holds).
    pub observation: Vec<f32>,
    /// The deterministic action: continuous actions clipped to [-1, 1], binary ones 0 or 1.
    pub action: Vec<f32>,
}

/// The golden episode of Solver `policy` (with its `card`) of game `G`.
pub fn golden_episode<G: GameSpec>(
    policy: &ActorCritic,
    card: &PolicyCard,
    reference: PolicyRef,
) -> candle_core::Result<GoldenEpisode> {
    let level = (GOLDEN_LEVEL_SEED..)
        .find_map(G::rule_level)
        .expect("the rules find a level within a few seeds");
    let mut env = G::solver_env(&level).expect("a rule level of the game itself");
    env.reset(GOLDEN_RUN_SEED);
    let continuous = policy.shape().continuous;
    // Deterministic play draws nothing; the stream is only what `choose` asks for.
    let mut rng = ChaCha8Rng::seed_from_u64(0);
    let mut frames = Vec::new();
    let outcome = loop {
        let mut observation = vec![0.0; G::Env::OBSERVATION_SIZE];
        env.observe(&mut observation);
        let mut normalized = observation.clone();
        card.normalizer.normalize(&mut normalized);
        let mut action = policy.choose(&normalized, ActMode::Deterministic, &mut rng)?;
        for value in &mut action[..continuous] {
            *value = value.clamp(-1.0, 1.0);
        }
        frames.push(GoldenFrame {
            state: env
                .port_state()
                .into_iter()
                .map(|(name, values)| (name.to_string(), values))
                .collect(),
            observation,
            action: action.clone(),
        });
        if let Some(outcome) = env.step(G::Env::action_from_policy_row(&action)).outcome {
            break outcome;
        }
    };
    Ok(GoldenEpisode {
        format: "arlpcg-golden-episode".into(),
        version: 1,
        game: card.game.to_string(),
        role: card.role.to_string(),
        policy: reference,
        level: arlpcg_core::level::yaml::to_string(&level),
        run_seed: GOLDEN_RUN_SEED,
        outcome: format!("{outcome:?}"),
        frames,
    })
}

/// Where the golden episode of the graph at `onnx` goes: the same name with `.golden.json`.
pub fn golden_path(onnx: &std::path::Path) -> std::path::PathBuf {
    let mut name = onnx.as_os_str().to_owned();
    name.push(".golden.json");
    name.into()
}

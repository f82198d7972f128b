//! Golden episodes: a real run of a policy, each decision's state ([`SolverEnv::port_state`],
//! [`TrackBuild::port_state`]), the raw observation computed from it and the deterministic
//! action the policy (and so its ONNX graph) chose. A Solver plays a rule level of its game; a
//! Generator builds a level at λ = [`GOLDEN_AUX`] toward the goal of a seed. An engine's port
//! of the observation recomputes each frame's observation from its state and runs the graph on
//! it; `.ci/port-check.py` is such a port, written from docs/engines.md alone.

use std::collections::BTreeMap;

use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;
use serde::{Deserialize, Serialize};

use arlpcg_core::game::generator::{
    BuildLimits, GeneratorGame, Placement, TrackBuild, observe_build,
};
use arlpcg_core::game::{GameSpec, PortState, SolverEnv, observe_solver};
use arlpcg_core::level::PolicyRef;
use arlpcg_core::rl::checkpoint::PolicyCard;
use arlpcg_core::rl::policy::{ActMode, ActorCritic};

/// The rule level a golden episode plays: the first seed from here whose rules find a level.
const GOLDEN_LEVEL_SEED: u64 = 1;
/// The run's reset seed (the start's jitter); a Generator's scene (goal, start, obstacles).
const GOLDEN_RUN_SEED: u64 = 0;
/// λ of a Generator's golden episode.
const GOLDEN_AUX: f32 = -1.0;

/// A Solver's run, decision by decision.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct GoldenEpisode {
    /// Always `arlpcg-golden-episode`.
    pub format: String,
    /// The file's format version.
    pub version: u32,
    /// The game the policy plays.
    pub game: String,
    /// The policy's role (`solver`, `generator`).
    pub role: String,
    /// The policy file that played.
    pub policy: PolicyRef,
    /// The level played (a Generator's: the level it built), as its YAML file.
    pub level: String,
    /// λ a Generator built at (none: a Solver's episode).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub aux: Option<f32>,
    /// The run's reset seed.
    pub run_seed: u64,
    /// How the run ended.
    pub outcome: String,
    /// Each decision, in order.
    pub frames: Vec<GoldenFrame>,
}

impl GoldenEpisode {
    fn new(
        card: &PolicyCard,
        policy: PolicyRef,
        level: &arlpcg_core::level::Level,
        aux: Option<f32>,
        outcome: String,
        frames: Vec<GoldenFrame>,
    ) -> Self {
        Self {
            format: "arlpcg-golden-episode".into(),
            version: 1,
            game: card.game.to_string(),
            role: card.role.to_string(),
            policy,
            level: arlpcg_core::level::yaml::to_string(level),
            aux,
            run_seed: GOLDEN_RUN_SEED,
            outcome,
            frames,
        }
    }
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
        .find_map(|seed| G::rule_level(seed, &Default::default()))
        .expect("the rules find a level within a few seeds");
    let mut env = G::solver_env(&level).expect("a rule level of the game itself");
    env.reset(GOLDEN_RUN_SEED);
    let mut frames = Vec::new();
    let outcome = loop {
        // An ability-aware Solver also observes the abilities: ours, all 0.
        let mut observation = vec![0.0; card.network.observation];
        observe_solver::<G>(&env, None, &mut observation);
        let frame = frame(policy, card, env.port_state(), observation)?;
        let action = G::Env::action_from_policy_row(&frame.action);
        frames.push(frame);
        if let Some(outcome) = env.step(action).outcome {
            break outcome;
        }
    };
    Ok(GoldenEpisode::new(
        card,
        reference,
        &level,
        None,
        format!("{outcome:?}"),
        frames,
    ))
}

/// The golden episode of Generator `policy` (with its `card` and `limits`) of game `G`: each
/// piece it places, until the track reaches its goal or ends.
pub fn generator_golden_episode<G: GeneratorGame>(
    policy: &ActorCritic,
    card: &PolicyCard,
    reference: PolicyRef,
    limits: BuildLimits,
) -> candle_core::Result<GoldenEpisode> {
    let obstacles = arlpcg_core::game::facts::facts(G::GAME).scene_obstacles;
    let (mut build, _) = G::new_build(GOLDEN_RUN_SEED, None, limits, obstacles);
    let mut frames = Vec::new();
    let outcome = loop {
        // A Generator with knobs observes them, all at 0 (no preference); an ability-aware one
        // the abilities: ours, all 0.
        let mut observation = vec![0.0; card.network.observation];
        let knobs = vec![0.0; arlpcg_core::rl::checkpoint::knob_part(card)];
        observe_build::<G>(&build, &[GOLDEN_AUX], &knobs, &mut observation);
        let frame = frame(policy, card, build.port_state(), observation)?;
        let placement = build.place(&frame.action);
        frames.push(frame);
        if placement != Placement::Placed {
            break placement;
        }
    };
    let level = arlpcg_core::level::Level {
        seed: Some(GOLDEN_RUN_SEED),
        aux: Some(f64::from(GOLDEN_AUX)),
        goal: build.goal(),
        track: build.into_track(),
        source: arlpcg_core::level::Source::Policy {
            generator: reference.clone(),
        },
        stats: None,
        pacing: None,
        profile: None,
        knobs: Default::default(),
    };
    let outcome = format!("{outcome:?}");
    Ok(GoldenEpisode::new(
        card,
        reference,
        &level,
        Some(GOLDEN_AUX),
        outcome,
        frames,
    ))
}

/// One decision: the policy's deterministic action on `observation` (normalized by the card's
/// normalizer), continuous actions clipped to [-1, 1] as the games clip them.
fn frame(
    policy: &ActorCritic,
    card: &PolicyCard,
    state: PortState,
    observation: Vec<f32>,
) -> candle_core::Result<GoldenFrame> {
    let mut normalized = observation.clone();
    card.normalizer.normalize(&mut normalized);
    // Deterministic play draws nothing from the stream.
    let mut unused = ChaCha8Rng::seed_from_u64(0);
    let mut action = policy.choose(&normalized, ActMode::Deterministic, &mut unused)?;
    for value in &mut action[..policy.shape().continuous] {
        *value = value.clamp(-1.0, 1.0);
    }
    Ok(GoldenFrame {
        state: state
            .into_iter()
            .map(|(name, values)| (name.to_string(), values))
            .collect(),
        observation,
        action,
    })
}

/// Where the golden episode of the graph at `onnx` goes: the same name with `.golden.json`.
pub fn golden_path(onnx: &std::path::Path) -> std::path::PathBuf {
    let mut name = onnx.as_os_str().to_owned();
    name.push(".golden.json");
    name.into()
}

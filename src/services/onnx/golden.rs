//! Golden episodes: a real run of a policy, each decision's state ([`SolverEnv::port_state`],
//! [`TrackBuild::port_state`]), the raw observation computed from it and the deterministic
//! action the policy (and so its ONNX graph) chose. A Solver plays a rule level of its game; a
//! Generator builds a level at λ = [`GOLDEN_AUX`] toward the goal of a seed, and each of its
//! frames also holds the piece its action stood for, with what the action → piece mapping
//! reads besides the state in the episode's `piece_rules` ([`TrackBuild::port_piece`]). An
//! ability-aware agent's state holds the abilities it played with. An engine's port recomputes
//! each frame's observation from its state, runs the graph on it, and rebuilds each piece from
//! the action; `.ci/port-check.py` is such a port, written from docs/engines.md alone.

use std::collections::BTreeMap;

use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;
use serde::{Deserialize, Serialize};

use super::GeneratorRules;
use arlpcg_core::game::generator::{
    BuildLimits, GeneratorGame, Placement, TrackBuild, observe_build,
};
use arlpcg_core::game::{GameSpec, PortState, SolverEnv, observe_solver};
use arlpcg_core::level::profile::{ABILITIES_PART, Abilities, main_abilities};
use arlpcg_core::level::{Game, PolicyRef};
use arlpcg_core::rl::checkpoint::PolicyCard;
use arlpcg_core::rl::policy::{ActMode, ActorCritic};

/// The rule level a golden episode plays: the first seed from here whose rules find a level.
const GOLDEN_LEVEL_SEED: u64 = 1;
/// The run's reset seed (the start's jitter); a Generator's scene (goal, start, obstacles).
const GOLDEN_RUN_SEED: u64 = 0;
/// λ of a Generator's golden episode.
const GOLDEN_AUX: f32 = -1.0;

/// The golden episodes' format version: 2 added each Generator frame's `piece`, the episode's
/// `piece_rules`, and an ability-aware agent's `abilities` and `abilities_built_in` state.
const GOLDEN_VERSION: u32 = 2;

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
    /// A Generator's: what its action → piece mapping reads besides each frame's state (the
    /// player's piece ranges; platform: the reach table; racing: the curve offset), by name.
    #[serde(default, skip_serializing_if = "BTreeMap::is_empty")]
    pub piece_rules: BTreeMap<String, Vec<f64>>,
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
        piece_rules: BTreeMap<String, Vec<f64>>,
        outcome: String,
        frames: Vec<GoldenFrame>,
    ) -> Self {
        Self {
            format: "arlpcg-golden-episode".into(),
            version: GOLDEN_VERSION,
            game: card.game.to_string(),
            role: card.role.to_string(),
            policy,
            level: arlpcg_core::level::yaml::to_string(level),
            aux,
            run_seed: GOLDEN_RUN_SEED,
            piece_rules,
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
    /// A Generator's: the piece the action stood for, by parameter name as the level file
    /// names them, as placing it computed it (also when the placement was then refused as
    /// invalid); none when the track had no piece left to place.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub piece: Option<BTreeMap<String, f64>>,
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
        let mut frame = frame(policy, card, env.port_state(), observation)?;
        record_abilities::<G>(card, None, &mut frame);
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
        BTreeMap::new(),
        format!("{outcome:?}"),
        frames,
    ))
}

/// What `generate` reads besides a Generator's graph (the sidecar's `generator`): its piece
/// budget, the attempts and the built-in player's piece rules, for a Generator of `game`.
pub fn generator_rules(game: Game, limits: BuildLimits) -> GeneratorRules {
    let piece_rules = arlpcg_core::for_game!(game, G => {
        let obstacles = arlpcg_core::game::facts::facts(G::GAME).scene_obstacles;
        G::new_build(GOLDEN_RUN_SEED, None, limits, obstacles).0.port_piece_rules()
    });
    GeneratorRules {
        max_pieces: limits.max_pieces,
        attempts: crate::services::generation::ATTEMPTS,
        piece_rules,
    }
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
    let piece_rules = build.port_piece_rules();
    let mut frames = Vec::new();
    let outcome = loop {
        // A Generator with knobs observes them, all at 0 (no preference); an ability-aware one
        // the abilities: ours, all 0.
        let mut observation = vec![0.0; card.network.observation];
        let knobs = vec![0.0; arlpcg_core::rl::checkpoint::knob_part(card)];
        observe_build::<G>(&build, &[GOLDEN_AUX], &knobs, &mut observation);
        let mut frame = frame(policy, card, build.port_state(), observation)?;
        if !knobs.is_empty() {
            frame.state.insert("knobs".into(), vec![0.0; knobs.len()]);
        }
        record_abilities::<G>(card, build.player().abilities, &mut frame);
        let piece = build.port_piece(&frame.action);
        let placement = build.place(&frame.action);
        frame.piece = piece.filter(|_| placement != Placement::OutOfPieces);
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
        want: None,
    };
    let outcome = format!("{outcome:?}");
    Ok(GoldenEpisode::new(
        card,
        reference,
        &level,
        Some(GOLDEN_AUX),
        piece_rules,
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
        piece: None,
    })
}

/// An ability-aware agent's (its card's observation ends with [`ABILITIES_PART`]) state gains
/// the main abilities it played with (`played`; none: ours), in [`main_abilities`]' order, and
/// ours (`abilities_built_in`): its `abilities` columns are each value / ours - 1.
fn record_abilities<G: GameSpec>(
    card: &PolicyCard,
    played: Option<Abilities>,
    frame: &mut GoldenFrame,
) {
    if card.observation.last().map(|(name, _)| name.as_str()) != Some(ABILITIES_PART) {
        return;
    }
    let ours = Abilities::default_of(G::GAME);
    let values = |abilities: &Abilities| -> Vec<f64> {
        main_abilities(G::GAME)
            .iter()
            .map(|field| {
                abilities
                    .value(field)
                    .expect("a main ability of the game")
                    .0
            })
            .collect()
    };
    let state = &mut frame.state;
    state.insert("abilities".into(), values(&played.unwrap_or(ours)));
    state.insert("abilities_built_in".into(), values(&ours));
}

/// Where the golden episode of the graph at `onnx` goes: the same name with `.golden.json`.
pub fn golden_path(onnx: &std::path::Path) -> std::path::PathBuf {
    let mut name = onnx.as_os_str().to_owned();
    name.push(".golden.json");
    name.into()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::services::policies::{generator_limits, load_any};
    use arlpcg_core::game::{PlatformGame, RacingGame};

    fn shipped(name: &str) -> std::path::PathBuf {
        std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join(format!("policies/{name}"))
    }

    /// Each frame of a shipped Generator's golden episode holds the piece it placed, the very
    /// piece of the level it built, and the episode what the mapping read.
    #[test]
    fn a_generators_golden_frames_hold_the_pieces_of_its_level() {
        for game in ["platform", "racing"] {
            let path = shipped(&format!("{game}/generator.safetensors"));
            let (policy, card, reference) = load_any(&path).unwrap();
            let limits = generator_limits(&path, &card).unwrap();
            let episode = arlpcg_core::for_game!(card.game, G => {
                generator_golden_episode::<G>(&policy, &card, reference, limits)
            })
            .unwrap();
            assert_eq!(episode.version, GOLDEN_VERSION);
            let level = arlpcg_core::level::yaml::parse(&episode.level).unwrap();
            let pieces: Vec<Vec<f64>> = match (level.platform(), level.racing()) {
                (Some(track), _) => track
                    .block_params()
                    .iter()
                    .map(|b| vec![b.angle, b.distance, b.height, b.size])
                    .collect(),
                (_, Some(track)) => track
                    .segments
                    .iter()
                    .map(|s| vec![s.curve, s.height, s.length])
                    .collect(),
                _ => unreachable!("a level of the Generator's game"),
            };
            let recorded: Vec<Vec<f64>> = episode
                .frames
                .iter()
                .map(|f| f.piece.clone().unwrap().into_values().collect())
                .collect();
            assert_eq!(recorded, pieces, "{game}");
            let rules = match game {
                "platform" => {
                    "headroom max_distance max_height max_size max_turn min_distance min_height min_size reach_table"
                }
                _ => "curve_offset max_curve max_height max_length min_length",
            };
            let names: Vec<&str> = episode.piece_rules.keys().map(String::as_str).collect();
            assert_eq!(names.join(" "), rules);
        }
    }

    /// An ability-aware Solver's golden state holds the abilities it played with (ours) and
    /// ours; a Solver that is not aware has neither.
    #[test]
    fn an_ability_aware_solvers_golden_state_holds_its_abilities() {
        let path = shipped("platform/solver.safetensors");
        let (policy, card, reference) = load_any(&path).unwrap();
        let episode = golden_episode::<PlatformGame>(&policy, &card, reference).unwrap();
        let state = &episode.frames[0].state;
        assert_eq!(state["abilities"], [9.25, 8.0, 20.0]);
        assert_eq!(state["abilities"], state["abilities_built_in"]);
        let path = shipped("racing/solver.safetensors");
        let (policy, card, reference) = load_any(&path).unwrap();
        let episode = golden_episode::<RacingGame>(&policy, &card, reference).unwrap();
        assert!(!episode.frames[0].state.contains_key("abilities"));
    }
}

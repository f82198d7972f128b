//! A trained policy's actor as an ONNX graph, for engines that run policies themselves (Unity
//! through ML-Agents' Sentis/Inference Engine, Godot RL Agents, onnxruntime anywhere).
//!
//! The graph takes raw observations, as the game produces them: the observation normalizer is
//! folded in as `Sub`, `Mul` and `Clip`, then the actor's layers are `Gemm` and `Relu`. It gives
//! the deterministic actions the tool plays with (`verify` and the certificates): each
//! continuous action is the Gaussian's mean clipped to [-1, 1], as the games clip it, and each
//! binary action is on when its probability is at least one half. Opset 9 (the oldest the
//! engines above read, and ML-Agents' own), IR version 4.
//!
//! Two contracts ([`Contract`]): `plain` names things after this tool (`observation`,
//! `continuous_actions`, `binary_probabilities`, `binary_actions`); `mlagents` follows
//! ML-Agents' model contract (version 3: `obs_0`, `action_masks`, `version_number`,
//! `memory_size`, `continuous_actions`, `deterministic_continuous_actions`,
//! `continuous_action_output_shape`, `discrete_actions`, `deterministic_discrete_actions`,
//! `discrete_action_output_shape`), each binary action a discrete branch of two (0 off, 1 on).
//! ML-Agents' `continuous_actions` and `discrete_actions` are samples in its own exports; here
//! both are the deterministic actions.
//!
//! Beside the graph goes a [`Sidecar`] (JSON): the observation layout and the meaning of each
//! action from the policy's card, and example rows with the outputs this tool computes for them,
//! so an integration can check itself.

mod builder;
mod examples;
pub mod golden;
pub mod proto;
mod sidecar;
pub mod web;

use arlpcg_core::level::profile::{ABILITIES_PART, main_abilities};
use prost::Message;
use serde::{Deserialize, Serialize};

use arlpcg_core::level::PolicyRef;
use arlpcg_core::rl::checkpoint::PolicyCard;
use arlpcg_core::rl::normalizer::{CLIP, RunningNorm};
use arlpcg_core::rl::policy::ActorCritic;
use builder::{GraphBuilder, attribute_int, entry, typed_value_info, value_info};
use examples::examples;
pub use examples::{example_observations, reference_outputs};
use proto::*;
pub use sidecar::{
    Columns, Examples, GeneratorRules, Port, Sampling, Sidecar, SidecarTraining, sidecar_path,
};
use sidecar::{columns, sampling};

/// The ONNX operator set the graphs use.
pub const OPSET: i64 = 9;
/// The IR version that goes with [`OPSET`].
const IR_VERSION: i64 = 4;
/// ML-Agents' model API version its contract's `version_number` carries.
const MLAGENTS_API_VERSION: f32 = 3.0;
/// How many example rows the sidecar carries.
const EXAMPLE_ROWS: usize = 4;

/// Whose names and outputs the graph follows.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Contract {
    /// Names of this tool.
    Plain,
    /// ML-Agents' model contract, for Unity.
    Mlagents,
}

impl Contract {
    /// The contract's name on the command line and in sidecars (`plain`, `mlagents`).
    pub fn name(self) -> &'static str {
        match self {
            Contract::Plain => "plain",
            Contract::Mlagents => "mlagents",
        }
    }

    /// The name of the observation input.
    pub fn observation_input(self) -> &'static str {
        match self {
            Contract::Plain => "observation",
            Contract::Mlagents => "obs_0",
        }
    }
}

/// The graph's bytes and its sidecar.
pub struct Exported {
    /// The ONNX model's bytes.
    pub onnx: Vec<u8>,
    /// Its sidecar.
    pub sidecar: Sidecar,
}

/// An output of the graph: its dimensions (`None` the batch) and what the sidecar says of it.
#[derive(Clone)]
struct Output {
    dims: Vec<Option<usize>>,
    meaning: &'static str,
    columns: Vec<Columns>,
    /// 64-bit integers rather than floats.
    int64: bool,
}

/// The outputs `name` and `deterministic_<name>` (ML-Agents reads both): `actions`, renamed,
/// and a copy of it, each with `output`'s shape and meaning.
fn both_names(
    graph: &mut GraphBuilder,
    actions: &str,
    name: &str,
    output: Output,
) -> [(String, Output); 2] {
    let copy = graph.node("Identity", &[actions], vec![]);
    graph.rename(actions, name);
    let deterministic = format!("deterministic_{name}");
    graph.rename(&copy, &deterministic);
    [(name.into(), output.clone()), (deterministic, output)]
}

const CONTINUOUS_MEANING: &str =
    "the deterministic continuous actions (the Gaussian's mean clipped to [-1, 1])";

/// The observation's columns, each part with what it holds (the game's own words, by name; an
/// ability-aware Solver's abilities last).
fn observation_columns(card: &PolicyCard) -> Vec<Columns> {
    let facts = arlpcg_core::game::facts::facts(card.game);
    let observation = match card.role {
        arlpcg_core::rl::checkpoint::Role::Solver => &facts.solver_observation,
        arlpcg_core::rl::checkpoint::Role::Generator => &facts.generator_observation,
    };
    let mut columns = columns(card.observation.clone());
    for column in &mut columns {
        column.meaning = observation
            .layout
            .iter()
            .zip(observation.meanings)
            .find(|((name, width), _)| *name == column.name && *width == column.width)
            .map(|(_, meaning)| meaning.to_string());
        if column.name == arlpcg_core::game::generator::KNOBS_PART {
            use arlpcg_core::game::generator::GeneratorGame;
            let knobs = arlpcg_core::for_game!(card.game, G => G::KNOBS);
            column.meaning = Some(format!(
                "the style knobs {}, each in [-1, 1] (0: no preference)",
                knobs
                    .iter()
                    .map(|k| format!("{} ({})", k.name, k.meaning))
                    .collect::<Vec<_>>()
                    .join("; ")
            ));
        }
        if column.name == ABILITIES_PART {
            column.meaning = Some(format!(
                "the profile's {} relative to the built-in ones (value / ours - 1; 0 for ours)",
                main_abilities(card.game).join(", ")
            ));
        }
    }
    columns
}

/// One column per action name.
fn action_columns(names: &[String]) -> Vec<Columns> {
    columns(names.iter().map(|n| (n.clone(), 1)))
}

/// Exports the actor of `policy` (with its card's normalizer) in `contract`. Pure: the same
/// policy gives the same bytes.
pub fn export(
    policy: &ActorCritic,
    card: &PolicyCard,
    reference: PolicyRef,
    contract: Contract,
) -> candle_core::Result<Exported> {
    let shape = policy.shape();
    let (observation, continuous, binary) = (shape.observation, shape.continuous, shape.binary);
    let mut graph = GraphBuilder::default();
    let input = contract.observation_input();
    graph
        .inputs
        .push(value_info(input, &[None, Some(observation)]));
    let head = actor_head(&mut graph, policy, &card.normalizer, input)?;
    let mean = (continuous > 0).then(|| graph.columns(&head, 0, continuous));
    let logits = (binary > 0).then(|| graph.columns(&head, continuous, continuous + binary));
    let actions = ActionNodes {
        continuous: mean.map(|m| graph.clip(&m, -1.0, 1.0)),
        logits,
    };
    let outputs = match contract {
        Contract::Plain => plain_outputs(&mut graph, card, actions),
        Contract::Mlagents => mlagents_outputs(&mut graph, card, actions),
    };
    for (name, output) in &outputs {
        let element = if output.int64 { INT64 } else { FLOAT };
        graph
            .outputs
            .push(typed_value_info(name, &output.dims, element));
    }
    let model = ModelProto {
        ir_version: IR_VERSION,
        producer_name: "arlpcg".into(),
        producer_version: env!("CARGO_PKG_VERSION").into(),
        doc_string: format!(
            "The actor of the {} {} trained in mode {} ({} steps, seed {}), from {} (SHA-256 {}).",
            card.game,
            card.role,
            card.training.mode,
            card.training.steps,
            card.training.seed,
            reference.path,
            reference.sha256
        ),
        graph: Some(GraphProto {
            node: graph.nodes,
            name: format!("{}-{}", card.game, card.role),
            initializer: graph.initializers,
            doc_string: String::new(),
            input: graph.inputs,
            output: graph.outputs,
        }),
        opset_import: vec![OperatorSetIdProto {
            domain: String::new(),
            version: OPSET,
        }],
        metadata_props: vec![
            entry("arlpcg.game", &card.game.to_string()),
            entry("arlpcg.role", &card.role.to_string()),
            entry("arlpcg.profile", contract.name()),
            entry("arlpcg.policy_sha256", &reference.sha256),
        ],
    };
    let mut inputs = vec![Port {
        name: input.into(),
        shape: dims_json(&[None, Some(observation)]),
        meaning: "raw observations, as the game produces them (normalized inside the graph)".into(),
        element_type: None,
        columns: observation_columns(card),
    }];
    if contract == Contract::Mlagents && binary > 0 {
        inputs.push(Port {
            name: "action_masks".into(),
            shape: dims_json(&[None, Some(2 * binary)]),
            meaning: "1 where a branch's option is allowed, 0 where masked; all ones to leave \
                the policy free"
                .into(),
            element_type: None,
            columns: columns(
                card.binary_actions
                    .iter()
                    .flat_map(|n| [(format!("{n}=off"), 1), (format!("{n}=on"), 1)]),
            ),
        });
    }
    let examples = examples(policy, card, contract)?;
    Ok(Exported {
        onnx: model.encode_to_vec(),
        sidecar: Sidecar {
            format: "arlpcg-onnx".into(),
            version: 1,
            profile: contract,
            opset: OPSET,
            game: card.game.to_string(),
            role: card.role.to_string(),
            policy: reference,
            training: SidecarTraining {
                mode: card.training.mode.to_string(),
                steps: card.training.steps,
                seed: card.training.seed,
                command: card.training.command.clone(),
            },
            inputs,
            outputs: outputs
                .into_iter()
                .map(|(name, output)| Port {
                    name,
                    shape: dims_json(&output.dims),
                    meaning: output.meaning.into(),
                    element_type: output.int64.then(|| "int64".into()),
                    columns: output.columns,
                })
                .collect(),
            examples,
            sampling: sampling(policy)?,
            generator: None,
        },
    })
}

/// The graph's nodes a contract's outputs are made from: the continuous actions (the mean,
/// clipped) and the binary actions' logits, where the policy has them.
struct ActionNodes {
    continuous: Option<String>,
    logits: Option<String>,
}

/// This tool's names: the continuous actions, and each binary action's probability and choice.
fn plain_outputs(
    graph: &mut GraphBuilder,
    card: &PolicyCard,
    nodes: ActionNodes,
) -> Vec<(String, Output)> {
    let mut outputs = Vec::new();
    if let Some(actions) = nodes.continuous {
        graph.rename(&actions, "continuous_actions");
        outputs.push((
            "continuous_actions".into(),
            Output {
                dims: vec![None, Some(card.continuous_actions.len())],
                meaning: CONTINUOUS_MEANING,
                columns: action_columns(&card.continuous_actions),
                int64: false,
            },
        ));
    }
    if let Some(logits) = nodes.logits {
        let binary = card.binary_actions.len();
        let probability = graph.node("Sigmoid", &[&logits], vec![]);
        graph.rename(&probability, "binary_probabilities");
        let zero = graph.constant_f32(&[1], &[0.0]);
        let below = graph.node("Less", &[&logits, &zero], vec![]);
        let on = graph.node("Not", &[&below], vec![]);
        let actions = graph.node("Cast", &[&on], vec![attribute_int("to", FLOAT as i64)]);
        graph.rename(&actions, "binary_actions");
        outputs.push((
            "binary_probabilities".into(),
            Output {
                dims: vec![None, Some(binary)],
                meaning: "each binary action's probability of being on",
                columns: action_columns(&card.binary_actions),
                int64: false,
            },
        ));
        outputs.push((
            "binary_actions".into(),
            Output {
                dims: vec![None, Some(binary)],
                meaning: "the deterministic binary actions: 1 when the probability is at least \
                    0.5, else 0",
                columns: action_columns(&card.binary_actions),
                int64: false,
            },
        ));
    }
    outputs
}

/// ML-Agents' model contract (version 3): constants, then the continuous actions and each
/// binary action as a discrete branch of two, masked by `action_masks`.
fn mlagents_outputs(
    graph: &mut GraphBuilder,
    card: &PolicyCard,
    nodes: ActionNodes,
) -> Vec<(String, Output)> {
    let mut outputs = Vec::new();
    let constant = |graph: &mut GraphBuilder, name: &str, values: &[f32], meaning| {
        let value = graph.constant_node(&[values.len()], values);
        graph.rename(&value, name);
        let output = Output {
            dims: vec![Some(values.len())],
            meaning,
            columns: vec![],
            int64: false,
        };
        (name.to_string(), output)
    };
    // Actions under both of ML-Agents' names, then their shape.
    let actions_and_shape = |graph: &mut GraphBuilder,
                             (actions, name, output): (&str, &str, Output),
                             (shape_name, shape): (&str, &[f32]),
                             meaning| {
        let [named, deterministic] = both_names(graph, actions, name, output);
        [
            named,
            deterministic,
            constant(graph, shape_name, shape, meaning),
        ]
    };
    outputs.push(constant(
        graph,
        "version_number",
        &[MLAGENTS_API_VERSION],
        "ML-Agents' model API version",
    ));
    outputs.push(constant(
        graph,
        "memory_size",
        &[0.0],
        "no recurrent memory",
    ));
    if let Some(actions) = nodes.continuous {
        let continuous = card.continuous_actions.len();
        let output = Output {
            dims: vec![None, Some(continuous)],
            meaning: CONTINUOUS_MEANING,
            columns: action_columns(&card.continuous_actions),
            int64: false,
        };
        outputs.extend(actions_and_shape(
            graph,
            (&actions, "continuous_actions", output),
            ("continuous_action_output_shape", &[continuous as f32]),
            "how many continuous actions",
        ));
    }
    if let Some(logits) = nodes.logits {
        let binary = card.binary_actions.len();
        graph
            .inputs
            .push(value_info("action_masks", &[None, Some(2 * binary)]));
        let on_columns: Vec<i64> = (0..binary as i64).map(|k| 2 * k + 1).collect();
        let off_columns: Vec<i64> = (0..binary as i64).map(|k| 2 * k).collect();
        let allowed_on = graph.gather_columns("action_masks", &on_columns);
        let allowed_off = graph.gather_columns("action_masks", &off_columns);
        let on = graph.node("Sigmoid", &[&logits], vec![]);
        let one = graph.constant_f32(&[1], &[1.0]);
        let off = graph.node("Sub", &[&one, &on], vec![]);
        let on = graph.node("Mul", &[&on, &allowed_on], vec![]);
        let off = graph.node("Mul", &[&off, &allowed_off], vec![]);
        let below = graph.node("Less", &[&on, &off], vec![]);
        let chosen = graph.node("Not", &[&below], vec![]);
        // Integers, as ML-Agents' own exporter writes them and its runtime reads them.
        let actions = graph.node("Cast", &[&chosen], vec![attribute_int("to", INT64 as i64)]);
        let output = Output {
            dims: vec![None, Some(binary)],
            meaning: "one branch per binary action: 1 (on) when its probability, masked, \
                is at least that of 0 (off)",
            columns: action_columns(&card.binary_actions),
            int64: true,
        };
        outputs.extend(actions_and_shape(
            graph,
            (&actions, "discrete_actions", output),
            ("discrete_action_output_shape", &vec![2.0; binary]),
            "each branch's size (2)",
        ));
    }
    outputs
}

/// The normalizer and the actor's layers: the head's output (means, then logits).
fn actor_head(
    graph: &mut GraphBuilder,
    policy: &ActorCritic,
    normalizer: &RunningNorm,
    input: &str,
) -> candle_core::Result<String> {
    let size = normalizer.size();
    let mean: Vec<f32> = normalizer.mean.iter().map(|&m| m as f32).collect();
    let scale: Vec<f32> = normalizer
        .var
        .iter()
        .map(|v| (1.0 / (v + 1e-8).sqrt()) as f32)
        .collect();
    let mean = graph.constant_f32(&[size], &mean);
    let scale = graph.constant_f32(&[size], &scale);
    let centred = graph.node("Sub", &[input, &mean], vec![]);
    let scaled = graph.node("Mul", &[&centred, &scale], vec![]);
    let mut h = graph.clip(&scaled, -CLIP, CLIP);
    let actor: Vec<_> = policy
        .named_vars()
        .into_iter()
        .filter(|(name, _)| name.starts_with("actor."))
        .collect();
    let layers = actor.len() / 2;
    for (k, pair) in actor.chunks(2).enumerate() {
        let weight = pair[0].1.as_tensor();
        let (fan_in, fan_out) = weight.dims2()?;
        let weights = weight.flatten_all()?.to_vec1::<f32>()?;
        let bias = pair[1].1.as_tensor().flatten_all()?.to_vec1::<f32>()?;
        let weight = graph.constant_f32(&[fan_in, fan_out], &weights);
        let bias = graph.constant_f32(&[fan_out], &bias);
        h = graph.node("Gemm", &[&h, &weight, &bias], vec![]);
        if k + 1 < layers {
            h = graph.node("Relu", &[&h], vec![]);
        }
    }
    Ok(h)
}

fn dims_json(dims: &[Option<usize>]) -> Vec<serde_json::Value> {
    dims.iter()
        .map(|d| match d {
            Some(size) => serde_json::json!(size),
            None => serde_json::json!("batch"),
        })
        .collect()
}

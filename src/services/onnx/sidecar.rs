//! The [`Sidecar`] beside an exported graph (JSON): the observation layout and the meaning of each
//! action from the policy's card, how the tool samples, what a Generator's builds read, and
//! example rows with the outputs this tool computes for them.

use serde::{Deserialize, Serialize};

use super::Contract;
use arlpcg_core::level::PolicyRef;
use arlpcg_core::rl::policy::ActorCritic;

/// What the sidecar says about the graph: enough to wire it into a game without this tool.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Sidecar {
    /// Always `arlpcg-onnx`.
    pub format: String,
    /// The sidecar's format version.
    pub version: u32,
    /// The contract (the field's name predates the word; files keep it).
    pub profile: Contract,
    /// The ONNX operator set the graph uses ([`OPSET`](super::OPSET)).
    pub opset: i64,
    /// The game the policy plays.
    pub game: String,
    /// The policy's role (`solver`, `generator`).
    pub role: String,
    /// The policy file the graph was made from.
    pub policy: PolicyRef,
    /// How the policy was trained.
    pub training: SidecarTraining,
    /// The graph's inputs.
    pub inputs: Vec<Port>,
    /// The graph's outputs.
    pub outputs: Vec<Port>,
    /// Observation rows (raw, as the game produces them) and what this tool computes for them,
    /// output by output.
    pub examples: Examples,
    /// How this tool samples the continuous actions where it does not act deterministically
    /// (a Generator building a level); none for a policy without continuous actions.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub sampling: Option<Sampling>,
    /// What a Generator's builds read besides the graph (none for a Solver): the piece budget,
    /// the attempts and the built-in player's piece rules.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub generator: Option<GeneratorRules>,
}

/// The Gaussian each continuous action is sampled from: its mean is the actor's output before
/// the graph's clip to [-1, 1]; its standard deviation is a trained constant per action.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Sampling {
    /// How a sample is drawn, in words.
    pub meaning: String,
    /// The log standard deviation of each continuous action, in order.
    pub log_std: Vec<f32>,
    /// `exp(log_std)` as this tool computes it (float32), in order.
    pub std: Vec<f32>,
}

/// A Generator's build rules, as `generate` reads them (`build_level` in
/// `src/services/generation.rs`).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct GeneratorRules {
    /// The piece budget of a level (the card's `max_pieces`).
    pub max_pieces: usize,
    /// Attempts at a level before `generate` gives up.
    pub attempts: usize,
    /// The built-in player's piece rules, as a golden episode's `piece_rules`.
    pub piece_rules: std::collections::BTreeMap<String, Vec<f64>>,
}

/// The sampling of `policy`'s continuous actions; none when it has none.
pub(super) fn sampling(policy: &ActorCritic) -> candle_core::Result<Option<Sampling>> {
    if policy.shape().continuous == 0 {
        return Ok(None);
    }
    let log_std = policy
        .named_vars()
        .into_iter()
        .find(|(name, _)| name == "log_std")
        .map(|(_, var)| var.as_tensor().flatten_all()?.to_vec1::<f32>())
        .transpose()?
        .unwrap_or_default();
    let std = log_std.iter().map(|l| l.exp()).collect();
    Ok(Some(Sampling {
        meaning: "action k = mean_k + std_k * n_k (float32), mean_k the actor's output before \
            the clip that gives continuous_actions, n_k a standard normal draw, the columns in \
            order; the game then clips each to [-1, 1]"
            .into(),
        log_std,
        std,
    }))
}

/// How the policy was trained, from its card.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct SidecarTraining {
    /// The training mode (`rule-pcg`, `arlpcg`, ...).
    pub mode: String,
    /// Environment steps trained.
    pub steps: u64,
    /// The run's seed.
    pub seed: u64,
    /// The command that started the run.
    pub command: String,
}

/// One input or output of the graph.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Port {
    /// The name in the graph.
    pub name: String,
    /// `"batch"` for the rows, else a size.
    pub shape: Vec<serde_json::Value>,
    /// What it holds, in words.
    pub meaning: String,
    /// The elements' type where they are not 32-bit floats (`int64`: ML-Agents' discrete
    /// actions).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub element_type: Option<String>,
    /// What the columns of the last dimension hold, in order.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub columns: Vec<Columns>,
}

/// A named run of columns: `width` of them from `offset`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Columns {
    /// The part's name.
    pub name: String,
    /// Its first column.
    pub offset: usize,
    /// How many columns.
    pub width: usize,
    /// How an observation part is computed (frame, scale, sign, order), for a port of it.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub meaning: Option<String>,
}

/// Named runs of columns laid end to end.
pub(super) fn columns(named: impl IntoIterator<Item = (String, usize)>) -> Vec<Columns> {
    let mut offset = 0;
    named
        .into_iter()
        .map(|(name, width)| {
            offset += width;
            Columns {
                name,
                offset: offset - width,
                width,
                meaning: None,
            }
        })
        .collect()
}

/// Example rows and this tool's outputs for them, to check a runtime against.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Examples {
    /// Observation rows, raw.
    pub observations: Vec<Vec<f32>>,
    /// Each output's rows for them, by output name.
    pub outputs: std::collections::BTreeMap<String, Vec<Vec<f32>>>,
}

/// Where the sidecar of the graph at `onnx` goes: the same name with `.json` added.
pub fn sidecar_path(onnx: &std::path::Path) -> std::path::PathBuf {
    let mut name = onnx.as_os_str().to_owned();
    name.push(".json");
    name.into()
}

//! A Generator for a web page that has no onnxruntime (`arlpcg view`'s λ slider, through
//! `web/network.mjs`): the sidecar its plain ONNX export would carry (observation, sampling,
//! build rules) and, instead of the graph, its actor's weights and its observation normalizer
//! as JSON numbers. The same numbers the graph holds: a page that evaluates them as
//! `web/network.mjs` does builds the levels `generate` builds (docs/engines.md).

use anyhow::{Context, Result};
use serde::Serialize;
use serde_json::{Value, json};

use super::golden::generator_rules;
use super::{Contract, Sidecar, export};
use crate::services::generation::{GeneratorPolicy, player_for};
use arlpcg_core::game::generator::{
    BuildLimits, GeneratorGame, TrackBuild, observation_size, observe_build,
};
use arlpcg_core::level::PolicyRef;
use arlpcg_core::level::profile::Profile;
use arlpcg_core::rl::checkpoint::PolicyCard;
use arlpcg_core::rl::normalizer::CLIP;
use arlpcg_core::rl::policy::ActorCritic;

/// Generator `policy` (with its `card`, file and build `limits`) as a page builds levels with
/// it, as JSON: `sidecar` (the plain export's, with its `generator` build rules) and `network`
/// (`normalizer`: mean, var and clip; `layers`: each layer's `inputs`, `outputs`, `weight`
/// row-major inputs × outputs and `bias`, ReLU between), each float32 written in its shortest
/// decimal that reads back to it.
pub fn web_generator(
    policy: &ActorCritic,
    card: &PolicyCard,
    reference: PolicyRef,
    limits: BuildLimits,
) -> Result<String> {
    let mut exported =
        export(policy, card, reference, Contract::Plain).context("reading the actor")?;
    exported.sidecar.generator = Some(generator_rules(card.game, limits));
    let actor: Vec<_> = policy
        .named_vars()
        .into_iter()
        .filter(|(name, _)| name.starts_with("actor."))
        .collect();
    let mut layers = Vec::new();
    for pair in actor.chunks(2) {
        let weight = pair[0].1.as_tensor();
        let (inputs, outputs) = weight.dims2()?;
        layers.push(Layer {
            inputs,
            outputs,
            weight: weight.flatten_all()?.to_vec1::<f32>()?,
            bias: pair[1].1.as_tensor().flatten_all()?.to_vec1::<f32>()?,
        });
    }
    let numbers = WebGenerator {
        sidecar: exported.sidecar,
        network: Network {
            normalizer: Normalizer {
                mean: &card.normalizer.mean,
                var: &card.normalizer.var,
                clip: CLIP,
            },
            layers,
        },
    };
    Ok(serde_json::to_string(&numbers)?)
}

#[derive(Serialize)]
struct WebGenerator<'a> {
    sidecar: Sidecar,
    network: Network<'a>,
}

#[derive(Serialize)]
struct Network<'a> {
    normalizer: Normalizer<'a>,
    layers: Vec<Layer>,
}

#[derive(Serialize)]
struct Normalizer<'a> {
    mean: &'a [f64],
    var: &'a [f64],
    clip: f32,
}

#[derive(Serialize)]
struct Layer {
    inputs: usize,
    outputs: usize,
    weight: Vec<f32>,
    bias: Vec<f32>,
}

/// What a page's `build` takes to make `generator`'s levels for `profile`, as JSON: `rules`, its
/// piece rules with the reach table measured for its player (as a golden episode's
/// `piece_rules`), and `abilities`, the columns an ability-aware Generator observes (empty for
/// one that observes none).
pub fn profile_build(generator: &GeneratorPolicy, profile: &Profile) -> Value {
    let limits = BuildLimits {
        player: player_for(Some(profile)),
        ..generator.limits
    };
    let observation = generator.policy.shape().observation;
    arlpcg_core::for_game!(generator.game, G => {
        let (build, _) = G::new_build(0, None, limits, 0);
        let mut row = vec![0.0; observation];
        observe_build::<G>(&build, &[0.0], &vec![0.0; generator.knobs], &mut row);
        let own = observation_size::<G>() + generator.knobs;
        json!({"rules": build.port_piece_rules(), "abilities": row[own.min(observation)..]})
    })
}

//! The sidecar's example rows: observations near those the policy trained on, and what this
//! tool's own playing path outputs for them (an integration checks its graph against them).

use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;
use rand_distr::{Distribution, StandardNormal};

use super::{Contract, EXAMPLE_ROWS, Examples};
use arlpcg_core::rl::checkpoint::PolicyCard;
use arlpcg_core::rl::normalizer::RunningNorm;
use arlpcg_core::rl::policy::{ActMode, ActorCritic};

/// Example rows near the observations the policy was trained on (the normalizer's mean plus
/// two standard deviations of seeded noise), and this tool's outputs for them, computed the way
/// the tool plays: normalize, run the actor, choose deterministically.
pub(super) fn examples(
    policy: &ActorCritic,
    card: &PolicyCard,
    contract: Contract,
) -> candle_core::Result<Examples> {
    let observations = example_observations(&card.normalizer, EXAMPLE_ROWS, 0);
    let outputs = reference_outputs(policy, card, contract, &observations)?;
    Ok(Examples {
        observations: observations
            .chunks(card.normalizer.size())
            .map(<[f32]>::to_vec)
            .collect(),
        outputs,
    })
}

/// `rows` observations drawn around the normalizer's statistics, from `seed`.
pub fn example_observations(normalizer: &RunningNorm, rows: usize, seed: u64) -> Vec<f32> {
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let mut out = Vec::with_capacity(rows * normalizer.size());
    for _ in 0..rows {
        for (m, v) in normalizer.mean.iter().zip(&normalizer.var) {
            let noise: f64 = StandardNormal.sample(&mut rng);
            out.push((m + 2.0 * v.sqrt() * noise) as f32);
        }
    }
    out
}

/// What each output of the graph should hold for `observations` (rows of raw observations),
/// computed by this tool's own playing path; masks all allowed. Constant outputs are left out.
pub fn reference_outputs(
    policy: &ActorCritic,
    card: &PolicyCard,
    contract: Contract,
    observations: &[f32],
) -> candle_core::Result<std::collections::BTreeMap<String, Vec<Vec<f32>>>> {
    let shape = policy.shape();
    let (c, b) = (shape.continuous, shape.binary);
    let mut normalized = observations.to_vec();
    card.normalizer.normalize(&mut normalized);
    let mut rng = ChaCha8Rng::seed_from_u64(0);
    let actions = policy.choose(&normalized, ActMode::Deterministic, &mut rng)?;
    let head = policy.actor_head(&normalized)?;
    let rows = |values: &[f32], width: usize, from: usize, to: usize, f: &dyn Fn(f32) -> f32| {
        values
            .chunks(width)
            .map(|row| row[from..to].iter().map(|&v| f(v)).collect::<Vec<f32>>())
            .collect::<Vec<_>>()
    };
    let continuous = rows(&actions, c + b, 0, c, &|v| v.clamp(-1.0, 1.0));
    let binary = rows(&actions, c + b, c, c + b, &|v| v);
    let probabilities = rows(&head, c + b, c, c + b, &|v| 1.0 / (1.0 + (-v).exp()));
    let mut outputs = std::collections::BTreeMap::new();
    let named: Vec<(&str, &Vec<Vec<f32>>, bool)> = match contract {
        Contract::Plain => vec![
            ("continuous_actions", &continuous, c > 0),
            ("binary_probabilities", &probabilities, b > 0),
            ("binary_actions", &binary, b > 0),
        ],
        Contract::Mlagents => vec![
            ("continuous_actions", &continuous, c > 0),
            ("deterministic_continuous_actions", &continuous, c > 0),
            ("discrete_actions", &binary, b > 0),
            ("deterministic_discrete_actions", &binary, b > 0),
        ],
    };
    for (name, values, present) in named {
        if present {
            outputs.insert(name.to_string(), values.clone());
        }
    }
    Ok(outputs)
}

use candle_core::{Device, Tensor};
use rand::{RngExt, SeedableRng};
use rand_chacha::ChaCha8Rng;

use super::*;
use crate::rl::policy::ActorCritic;
use crate::rl::ppo::readable_loss;

fn flat_parameters(policy: &ActorCritic) -> Vec<f32> {
    policy
        .named_vars()
        .iter()
        .flat_map(|(_, v)| {
            v.as_tensor()
                .flatten_all()
                .unwrap()
                .to_vec1::<f32>()
                .unwrap()
        })
        .collect()
}

/// The fused gradients against candle's autograd of [`readable_loss`], on random inputs, for
/// shapes with and without each kind of action.
#[test]
fn gradients_match_candle_autograd() {
    for (continuous, binary, rows) in [(2, 1, 150), (3, 0, 64), (0, 2, 70)] {
        let shape = PolicyShape {
            observation: 7,
            hidden: vec![32, 24],
            continuous,
            binary,
        };
        let policy = ActorCritic::new(shape.clone(), 5).unwrap();
        policy.set_log_std(-0.3).unwrap();
        let mut rng = ChaCha8Rng::seed_from_u64(11);
        let mut random = |n: usize, scale: f32| -> Vec<f32> {
            (0..n)
                .map(|_| scale * rng.random_range(-1.0f32..1.0))
                .collect()
        };
        let width = continuous + binary;
        let observations = random(rows * 7, 2.0);
        let actions: Vec<f32> = random(rows * width, 1.5)
            .chunks(width)
            .flat_map(|a| {
                let mut a = a.to_vec();
                for v in &mut a[continuous..] {
                    *v = if *v > 0.0 { 1.0 } else { 0.0 };
                }
                a
            })
            .collect();
        // Old log-probabilities near the new ones, so that some ratios fall inside the
        // clipping band and some outside.
        let obs_t = Tensor::from_slice(&observations, (rows, 7), &Device::Cpu).unwrap();
        let act_t = Tensor::from_slice(&actions, (rows, width), &Device::Cpu).unwrap();
        let (reference_log_prob, _, _) = policy.evaluate(&obs_t, &act_t).unwrap();
        let old_log_probs: Vec<f32> = reference_log_prob
            .to_vec1::<f32>()
            .unwrap()
            .iter()
            .zip(random(rows, 0.4))
            .map(|(l, noise)| l + noise)
            .collect();
        let advantages = random(rows, 1.0);
        let returns = random(rows, 1.0);
        let weights = LossWeights {
            clip_coef: 0.2,
            ent_coef: 0.01,
            vf_coef: 0.5,
        };

        let layout = ParamLayout::new(&shape);
        let mut workspace = Workspace::new(layout, rows + 10);
        let params = flat_parameters(&policy);
        let minibatch = Minibatch {
            observations: &observations,
            actions: &actions,
            old_log_probs: &old_log_probs,
            advantages: &advantages,
            returns: &returns,
        };
        let terms = workspace.loss_and_gradients(&params, &minibatch, weights);
        let loss = readable_loss(&policy, &minibatch, weights).unwrap();
        let reference_loss = loss.to_scalar::<f32>().unwrap();
        assert!(
            (terms.total(weights) - reference_loss).abs() < 1e-5 * reference_loss.abs().max(1.0),
            "loss {} vs autograd {reference_loss}",
            terms.total(weights)
        );
        let grads = loss.backward().unwrap();
        let mut offset = 0;
        for (name, var) in policy.named_vars() {
            let len = var.as_tensor().elem_count();
            let ours = &workspace.gradients[offset..offset + len];
            offset += len;
            let Some(reference) = grads.get(var.as_tensor()) else {
                assert!(
                    ours.iter().all(|&g| g == 0.0),
                    "{name}: {ours:?} where autograd has none"
                );
                continue;
            };
            let reference = reference.flatten_all().unwrap().to_vec1::<f32>().unwrap();
            let norm = reference.iter().map(|g| g * g).sum::<f32>().sqrt();
            let error = ours
                .iter()
                .zip(&reference)
                .map(|(a, b)| (a - b) * (a - b))
                .sum::<f32>()
                .sqrt();
            assert!(
                norm > 0.0 && error <= 1e-4 * norm,
                "{name} ({continuous}+{binary} actions): relative error {} (norm {norm})",
                error / norm
            );
        }
        assert_eq!(offset, workspace.gradients.len());
    }
}

#[test]
fn sums_do_not_depend_on_the_thread_count() {
    let values: Vec<f32> = (0..100_000)
        .map(|i| ((i * 7919) % 1000) as f32 * 1e-3)
        .collect();
    let in_pool = |threads: usize| {
        rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .unwrap()
            .install(|| {
                let chunks = values.len().div_ceil(ROW_CHUNK * 10);
                let mut partial = vec![0.0; chunks * 10];
                let mut out = vec![0.0; 10];
                partial_column_sums(&mut values.clone(), None, 10, &mut partial);
                add_partials(&partial, chunks, &mut out);
                (global_norm(&values), out)
            })
    };
    assert_eq!(in_pool(1), in_pool(3));
}

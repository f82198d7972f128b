//! Proximal Policy Optimization, shaped like CleanRL's `ppo.py`: one documented config, `gae`,
//! the clipped surrogate loss, and `update` over shuffled minibatches with Adam, advantage
//! normalization, an entropy bonus and gradient-norm clipping.
//!
//! One iteration, and the file each line lives in (`rl/` unless named):
//!
//! ```text
//! for tick in 0..num_steps:                                     vec_env.rs  Trainer::collect
//!     norm.update(obs); x = norm(obs)                           normalizer.rs
//!     action, log_prob, value = policy.act(x)  (sampled)        policy.rs   ActorCritic::act
//!     reward, ended = envs.step(action)  (a game, or a match)   vec_env.rs  VecEnv; game/
//! advantages, returns = gae(rewards, values, ended, γ, λ)       ppo.rs      gae (no bootstrap past an ending)
//! for epoch in 0..update_epochs: for minibatch in shuffle(batch):   ppo.rs  Ppo::update
//!     normalize(advantages)
//!     loss = clipped surrogate - ent_coef·entropy + vf_coef·½(v - R)²   ppo.rs readable_loss
//!     gradients = ∂loss, fused on gemm (checked against readable_loss)  fused/mod.rs
//!     clip the global norm to max_grad_norm; Adam step               adam.rs
//! ```
//!
//! [`readable_loss`] is the loss written plainly in candle; the update computes the same loss
//! and its gradients by hand in [`super::fused`] (several times faster), and the fused tests
//! check both against candle's autograd of [`readable_loss`].

use rand::seq::SliceRandom;
use rand_chacha::ChaCha8Rng;
use serde::{Deserialize, Serialize};

use super::adam::Adam;
pub use super::fused::{LossWeights, Minibatch};
use super::fused::{ParamLayout, Workspace, global_norm};
use super::policy::ActorCritic;

/// Every PPO hyper-parameter, with CleanRL's meanings.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct PpoConfig {
    /// Adam step size; 0 keeps the policy as it is (it plays but does not learn: a Generator
    /// trained on against a finished Solver).
    pub learning_rate: f64,
    /// Decay the learning rate linearly to 0 over the run.
    pub anneal_lr: bool,
    /// Discount factor γ.
    pub gamma: f32,
    /// λ of generalized advantage estimation.
    pub gae_lambda: f32,
    /// Environments stepped together.
    pub num_envs: usize,
    /// Steps per environment per rollout (batch = num_envs × num_steps).
    pub num_steps: usize,
    /// Passes over each batch.
    pub update_epochs: usize,
    /// Minibatches per pass.
    pub num_minibatches: usize,
    /// Surrogate clipping ε.
    pub clip_coef: f32,
    /// Entropy bonus weight.
    pub ent_coef: f32,
    /// Value loss weight.
    pub vf_coef: f32,
    /// Gradients are scaled down to at most this global norm.
    pub max_grad_norm: f32,
    /// Normalize advantages within each minibatch.
    pub norm_adv: bool,
    /// Stop an update's remaining epochs once the approximate KL exceeds this (none: never).
    pub target_kl: Option<f32>,
}

impl Default for PpoConfig {
    fn default() -> Self {
        Self {
            learning_rate: 3e-4,
            anneal_lr: true,
            gamma: 0.99,
            gae_lambda: 0.95,
            num_envs: 32,
            num_steps: 128,
            update_epochs: 4,
            num_minibatches: 4,
            clip_coef: 0.2,
            ent_coef: 0.0,
            vf_coef: 0.5,
            max_grad_norm: 0.5,
            norm_adv: true,
            target_kl: None,
        }
    }
}

/// The most environments, steps per rollout and rows per batch a configuration may ask for: a
/// batch of 2^20 rows of 100 observations is already 400 MB.
pub const MAX_ENVS: usize = 4096;
/// The most steps per rollout.
pub const MAX_STEPS: usize = 65_536;
/// The most rows per batch.
pub const MAX_BATCH: usize = 1 << 20;

impl PpoConfig {
    /// Checks every field's range (and that it is a number): `Err("field: what it must be")`.
    pub fn check(&self) -> Result<(), String> {
        let unit = |x: f32| (0.0..=1.0).contains(&x);
        let checks = [
            (
                "learning_rate",
                self.learning_rate.is_finite()
                    && self.learning_rate >= 0.0
                    && self.learning_rate <= 1.0,
                "a number in [0, 1]".to_string(),
            ),
            ("gamma", unit(self.gamma), "a number in [0, 1]".into()),
            (
                "gae_lambda",
                unit(self.gae_lambda),
                "a number in [0, 1]".into(),
            ),
            (
                "num_envs",
                (1..=MAX_ENVS).contains(&self.num_envs),
                format!("within [1, {MAX_ENVS}]"),
            ),
            (
                "num_steps",
                (1..=MAX_STEPS).contains(&self.num_steps),
                format!("within [1, {MAX_STEPS}]"),
            ),
            (
                "num_envs × num_steps",
                self.num_envs.saturating_mul(self.num_steps) <= MAX_BATCH,
                format!("at most {MAX_BATCH} rows per batch"),
            ),
            (
                "update_epochs",
                (1..=1000).contains(&self.update_epochs),
                "within [1, 1000]".into(),
            ),
            (
                "num_minibatches",
                self.num_minibatches >= 1
                    && self.num_minibatches <= self.num_envs.saturating_mul(self.num_steps),
                format!(
                    "within [1, num_envs × num_steps = {}]",
                    self.num_envs.saturating_mul(self.num_steps)
                ),
            ),
            (
                "clip_coef",
                self.clip_coef > 0.0 && self.clip_coef <= 1.0,
                "a number in (0, 1]".into(),
            ),
            ("ent_coef", unit(self.ent_coef), "a number in [0, 1]".into()),
            (
                "vf_coef",
                self.vf_coef.is_finite() && (0.0..=100.0).contains(&self.vf_coef),
                "a number in [0, 100]".into(),
            ),
            (
                "max_grad_norm",
                self.max_grad_norm.is_finite() && self.max_grad_norm > 0.0,
                "a finite number > 0".into(),
            ),
            (
                "target_kl",
                self.target_kl.is_none_or(|kl| kl.is_finite() && kl > 0.0),
                "a finite number > 0, or null".into(),
            ),
        ];
        match checks.into_iter().find(|(_, ok, _)| !ok) {
            Some((field, _, must)) => Err(format!("{field} must be {must}")),
            None => Ok(()),
        }
    }

    /// Rows per rollout: environments × steps.
    pub fn batch_size(&self) -> usize {
        self.num_envs * self.num_steps
    }

    /// Rows per minibatch.
    pub fn minibatch_size(&self) -> usize {
        self.batch_size() / self.num_minibatches.max(1)
    }
}

/// Generalized advantage estimation over a time-major rollout (index `t * num_envs + e`).
/// `ended[i]`: the episode ended with transition `i`, so nothing is bootstrapped past it.
/// `last_values`: value estimates of the observations after the last step. Returns
/// (advantages, returns).
pub fn gae(
    rewards: &[f32],
    values: &[f32],
    ended: &[bool],
    last_values: &[f32],
    gamma: f32,
    gae_lambda: f32,
) -> (Vec<f32>, Vec<f32>) {
    let num_envs = last_values.len();
    let steps = rewards.len() / num_envs;
    let mut advantages = vec![0.0; rewards.len()];
    for (e, &last_value) in last_values.iter().enumerate() {
        let mut next_advantage = 0.0;
        for t in (0..steps).rev() {
            let i = t * num_envs + e;
            let next_value = if t + 1 < steps {
                values[i + num_envs]
            } else {
                last_value
            };
            let carry = if ended[i] { 0.0 } else { 1.0 };
            let delta = rewards[i] + gamma * next_value * carry - values[i];
            next_advantage = delta + gamma * gae_lambda * carry * next_advantage;
            advantages[i] = next_advantage;
        }
    }
    let returns = advantages.iter().zip(values).map(|(a, v)| a + v).collect();
    (advantages, returns)
}

/// One rollout, flattened, ready to learn from.
pub struct Batch {
    /// Normalized observations, rows of `observation` values.
    pub observations: Vec<f32>,
    /// Actions taken, rows of the policy's action size.
    pub actions: Vec<f32>,
    /// Each row's log-probability of its action when taken.
    pub log_probs: Vec<f32>,
    /// Each row's advantage (GAE).
    pub advantages: Vec<f32>,
    /// Each row's return: advantage plus value.
    pub returns: Vec<f32>,
    /// Each row's value estimate when taken.
    pub values: Vec<f32>,
}

/// What an update did, CleanRL's diagnostics.
#[derive(Debug, Clone, Copy, PartialEq, Default, Serialize)]
pub struct UpdateStats {
    /// The clipped surrogate loss.
    pub policy_loss: f32,
    /// The value loss.
    pub value_loss: f32,
    /// The policy's entropy.
    pub entropy: f32,
    /// Approximate KL divergence from the policy that collected the rollout.
    pub approx_kl: f32,
    /// Fraction of rows whose probability ratio was clipped.
    pub clip_fraction: f32,
    /// How much of the returns' variance the value estimates explain.
    pub explained_variance: f32,
    /// Minibatch gradient steps taken.
    pub gradient_steps: u32,
}

/// A policy and its optimizer.
pub struct Ppo {
    /// The hyperparameters.
    pub config: PpoConfig,
    /// The policy being trained.
    pub policy: ActorCritic,
    /// Its optimizer.
    pub adam: Adam,
    /// The fused update's buffers, made at the first update for the minibatch size.
    workspace: Option<Workspace>,
}

impl Ppo {
    /// PPO on `policy` under `config`, with a fresh optimizer.
    pub fn new(config: PpoConfig, policy: ActorCritic) -> candle_core::Result<Self> {
        let adam = Adam::new(&policy.named_vars());
        Ok(Self {
            config,
            policy,
            adam,
            workspace: None,
        })
    }

    /// The FLOPs of the matrix products of an update that made `update`'s gradient steps
    /// (for its MFU, [`super::timing::TimeSplit::update_mfu`]).
    pub fn update_flops(&self, update: &UpdateStats) -> f64 {
        f64::from(update.gradient_steps)
            * self.config.minibatch_size() as f64
            * super::timing::update_flops_per_sample(self.policy.shape())
    }

    /// Learns from one batch at `learning_rate`: `update_epochs` passes of shuffled minibatches,
    /// each one fused forward/backward pass ([`super::fused`]) and one Adam step. The policy's
    /// parameters are read before the first minibatch and written back after the last.
    pub fn update(
        &mut self,
        batch: &Batch,
        learning_rate: f64,
        rng: &mut ChaCha8Rng,
    ) -> candle_core::Result<UpdateStats> {
        let shape = self.policy.shape().clone();
        let (obs_width, action_width) = (shape.observation, shape.action_size());
        let n = batch.log_probs.len();
        let minibatch = self.config.minibatch_size().clamp(1, n);
        let workspace = match &mut self.workspace {
            Some(workspace) if workspace.capacity() >= minibatch => workspace,
            slot => slot.insert(Workspace::new(ParamLayout::new(&shape), minibatch)),
        };
        let weights = LossWeights {
            clip_coef: self.config.clip_coef,
            ent_coef: self.config.ent_coef,
            vf_coef: self.config.vf_coef,
        };
        let mut params = self.policy.flat_parameters()?;
        // A loss that turns out not to be a number rolls the optimizer back with the policy.
        let adam_before = self.adam.clone();
        let mut rows = Rows::with_capacity(minibatch, obs_width, action_width);
        let mut order: Vec<usize> = (0..n).collect();
        let mut stats = UpdateStats::default();
        let mut sums = [0.0f32; 5];
        let mut count = 0.0f32;
        'epochs: for epoch in 1..=self.config.update_epochs {
            order.shuffle(rng);
            for ids in order.chunks(minibatch) {
                rows.gather(batch, ids, obs_width, action_width);
                if self.config.norm_adv && ids.len() > 1 {
                    normalize(&mut rows.advantages);
                }
                let terms = workspace.loss_and_gradients(&params, &rows.minibatch(), weights);
                let norm = global_norm(&workspace.gradients);
                if !norm.is_finite() || !terms.total(weights).is_finite() {
                    // The policy keeps the parameters it had before this update.
                    self.adam = adam_before;
                    return Err(candle_core::Error::Msg(format!(
                        "the PPO loss or its gradient is not a number (loss {}, gradient norm {norm}) \
                         in update epoch {epoch}: the policy and its optimizer are left as they were before this update",
                        terms.total(weights)
                    )));
                }
                let scale = if norm > self.config.max_grad_norm as f64 {
                    self.config.max_grad_norm as f64 / (norm + 1e-6)
                } else {
                    1.0
                };
                self.adam
                    .apply(&mut params, &workspace.gradients, learning_rate, scale);
                for (sum, value) in sums.iter_mut().zip([
                    terms.policy_loss, terms.value_loss, terms.entropy, terms.approx_kl,
                    terms.clip_fraction,
                ]) {
                    *sum += value;
                }
                count += 1.0;
                stats.gradient_steps += 1;
                if self
                    .config
                    .target_kl
                    .is_some_and(|limit| terms.approx_kl > limit)
                {
                    break 'epochs;
                }
            }
        }
        self.policy.set_flat_parameters(&params)?;
        let [policy_loss, value_loss, entropy, approx_kl, clip_fraction] =
            sums.map(|s| s / count.max(1.0));
        stats.policy_loss = policy_loss;
        stats.value_loss = value_loss;
        stats.entropy = entropy;
        stats.approx_kl = approx_kl;
        stats.clip_fraction = clip_fraction;
        stats.explained_variance = explained_variance(&batch.values, &batch.returns);
        Ok(stats)
    }
}

/// One minibatch's rows, gathered from a [`Batch`] into buffers reused across minibatches.
struct Rows {
    observations: Vec<f32>,
    actions: Vec<f32>,
    old_log_probs: Vec<f32>,
    advantages: Vec<f32>,
    returns: Vec<f32>,
}

impl Rows {
    fn with_capacity(rows: usize, obs_width: usize, action_width: usize) -> Self {
        Self {
            observations: Vec::with_capacity(rows * obs_width),
            actions: Vec::with_capacity(rows * action_width),
            old_log_probs: Vec::with_capacity(rows),
            advantages: Vec::with_capacity(rows),
            returns: Vec::with_capacity(rows),
        }
    }

    fn gather(&mut self, batch: &Batch, ids: &[usize], obs_width: usize, action_width: usize) {
        self.observations.clear();
        self.actions.clear();
        self.old_log_probs.clear();
        self.advantages.clear();
        self.returns.clear();
        for &i in ids {
            self.observations
                .extend_from_slice(&batch.observations[i * obs_width..(i + 1) * obs_width]);
            self.actions
                .extend_from_slice(&batch.actions[i * action_width..(i + 1) * action_width]);
            self.old_log_probs.push(batch.log_probs[i]);
            self.advantages.push(batch.advantages[i]);
            self.returns.push(batch.returns[i]);
        }
    }

    fn minibatch(&self) -> Minibatch<'_> {
        Minibatch {
            observations: &self.observations,
            actions: &self.actions,
            old_log_probs: &self.old_log_probs,
            advantages: &self.advantages,
            returns: &self.returns,
        }
    }
}

/// Centres `values` and scales them to unit (population) standard deviation.
fn normalize(values: &mut [f32]) {
    let n = values.len() as f64;
    let mean = values.iter().map(|&v| v as f64).sum::<f64>() / n;
    let variance = values
        .iter()
        .map(|&v| (v as f64 - mean).powi(2))
        .sum::<f64>()
        / n;
    let std = variance.sqrt() as f32;
    for v in values {
        *v = (*v - mean as f32) / (std + 1e-8);
    }
}

/// 1 - Var(returns - values) / Var(returns): how much of the return the critic explains.
pub fn explained_variance(values: &[f32], returns: &[f32]) -> f32 {
    let variance = |xs: &mut dyn Iterator<Item = f32>| {
        let v: Vec<f32> = xs.collect();
        let mean = v.iter().sum::<f32>() / v.len().max(1) as f32;
        v.iter().map(|x| (x - mean).powi(2)).sum::<f32>() / v.len().max(1) as f32
    };
    let var_returns = variance(&mut returns.iter().copied());
    if var_returns == 0.0 {
        return f32::NAN;
    }
    1.0 - variance(&mut returns.iter().zip(values).map(|(r, v)| r - v)) / var_returns
}

/// PPO's loss on a minibatch, written plainly in candle (to minimize): the clipped surrogate
/// ([`clipped_policy_loss`]), minus `ent_coef` times the mean entropy, plus `vf_coef` times half
/// the mean squared value error. [`Ppo::update`] computes the same loss and its gradients with
/// the fused pass ([`super::fused`]); its tests check them against candle's autograd of this.
pub fn readable_loss(
    policy: &ActorCritic,
    minibatch: &Minibatch,
    weights: LossWeights,
) -> candle_core::Result<candle_core::Tensor> {
    use candle_core::{Device, Tensor};
    let rows = minibatch.old_log_probs.len();
    let shape = policy.shape();
    let observations = Tensor::from_slice(
        minibatch.observations,
        (rows, shape.observation),
        &Device::Cpu,
    )?;
    let actions = Tensor::from_slice(minibatch.actions, (rows, shape.action_size()), &Device::Cpu)?;
    let column = |v: &[f32]| Tensor::from_slice(v, rows, &Device::Cpu);
    let (new_log_prob, entropy, values) = policy.evaluate(&observations, &actions)?;
    let policy_loss = clipped_policy_loss(
        &new_log_prob,
        &column(minibatch.old_log_probs)?,
        &column(minibatch.advantages)?,
        weights.clip_coef,
    )?;
    let value_loss = ((values - column(minibatch.returns)?)?.sqr()?.mean_all()? * 0.5)?;
    let entropy = entropy.mean_all()?;
    (policy_loss - (entropy * weights.ent_coef as f64)?)? + (value_loss * weights.vf_coef as f64)?
}

/// PPO's clipped surrogate objective in candle (to minimize), the mean over the batch of
/// `max(-A·r, -A·clip(r, 1-ε, 1+ε))` with `r = exp(new_log_prob - old_log_prob)`.
pub fn clipped_policy_loss(
    new_log_prob: &candle_core::Tensor,
    old_log_prob: &candle_core::Tensor,
    advantages: &candle_core::Tensor,
    clip: f32,
) -> candle_core::Result<candle_core::Tensor> {
    let ratio = (new_log_prob - old_log_prob)?.exp()?;
    let unclipped = (advantages.neg()? * &ratio)?;
    let clipped = (advantages.neg()? * ratio.clamp(1.0 - clip, 1.0 + clip)?)?;
    unclipped.maximum(&clipped)?.mean_all()
}

#[cfg(test)]
mod tests {
    use super::*;
    use candle_core::{Device, Tensor};

    #[test]
    fn gae_matches_hand_computed_values() {
        // One env, three steps, γ = 0.5, λ = 0.5, the episode ends after step 1.
        let rewards = [1.0, 2.0, 3.0];
        let values = [0.5, 1.0, 2.0];
        let ended = [false, true, false];
        let (adv, ret) = gae(&rewards, &values, &ended, &[4.0], 0.5, 0.5);
        // t=2: δ = 3 + 0.5·4 - 2 = 3;                      A = 3
        // t=1: δ = 2 + 0 - 1 = 1 (ended: no bootstrap);    A = 1
        // t=0: δ = 1 + 0.5·1 - 0.5 = 1;                    A = 1 + 0.25·1 = 1.25
        assert_eq!(adv, vec![1.25, 1.0, 3.0]);
        assert_eq!(ret, vec![1.75, 2.0, 5.0]);
    }

    #[test]
    fn gae_keeps_environments_apart() {
        // Two envs interleaved time-major; env 1 has zero reward throughout.
        let rewards = [1.0, 0.0, 1.0, 0.0];
        let values = [0.0; 4];
        let (adv, _) = gae(&rewards, &values, &[false; 4], &[0.0, 0.0], 1.0, 1.0);
        assert_eq!(adv, vec![2.0, 0.0, 1.0, 0.0]);
    }

    #[test]
    fn clipped_loss_matches_hand_computed_values() {
        let t = |v: &[f32]| Tensor::from_slice(v, v.len(), &Device::Cpu).unwrap();
        // ratios e^0.5 = 1.6487 (clipped to 1.2) and e^-0.5 = 0.6065 (clipped to 0.8)
        let new = t(&[0.5, -0.5, 0.5]);
        let old = t(&[0.0, 0.0, 0.0]);
        let adv = t(&[1.0, 1.0, -1.0]);
        let loss = clipped_policy_loss(&new, &old, &adv, 0.2)
            .unwrap()
            .to_scalar::<f32>()
            .unwrap();
        // rows: max(-1.6487, -1.2) = -1.2; max(-0.6065, -0.8) = -0.6065; max(1.6487, 1.2) = 1.6487
        let expected = (-1.2 - 0.606_530_6 + 1.648_721_3) / 3.0;
        assert!((loss - expected).abs() < 1e-5, "{loss} vs {expected}");
    }

    fn small_shape() -> crate::rl::policy::PolicyShape {
        crate::rl::policy::PolicyShape {
            observation: 9,
            hidden: vec![512, 512],
            continuous: 2,
            binary: 1,
        }
    }

    /// The parameters after two updates at `learning_rate` of a 2 × 512 policy on a random
    /// batch of 600 rows.
    fn parameters_after_updates(threads: usize, learning_rate: f64) -> Vec<f32> {
        use rand::{RngExt, SeedableRng};
        let shape = small_shape();
        let mut rng = ChaCha8Rng::seed_from_u64(4);
        let mut random =
            |n: usize| -> Vec<f32> { (0..n).map(|_| rng.random_range(-1.0f32..1.0)).collect() };
        let n = 600;
        let batch = Batch {
            observations: random(n * 9),
            actions: random(n * 3)
                .chunks(3)
                .flat_map(|a| [a[0], a[1], (a[2] > 0.0) as u8 as f32])
                .collect(),
            log_probs: random(n).iter().map(|x| x - 3.0).collect(),
            advantages: random(n),
            returns: random(n),
            values: random(n),
        };
        let config = PpoConfig {
            num_envs: 10,
            num_steps: 60,
            num_minibatches: 3,
            ent_coef: 0.01,
            ..PpoConfig::default()
        };
        let mut ppo = Ppo::new(config, ActorCritic::new(shape, 1).unwrap()).unwrap();
        rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .unwrap()
            .install(|| {
                let mut rng = ChaCha8Rng::seed_from_u64(2);
                for _ in 0..2 {
                    ppo.update(&batch, learning_rate, &mut rng).unwrap();
                }
            });
        ppo.policy.flat_parameters().unwrap()
    }

    #[test]
    fn updates_are_deterministic_and_do_not_depend_on_the_thread_count() {
        let one = parameters_after_updates(1, 1e-3);
        let initial = ActorCritic::new(small_shape(), 1).unwrap();
        assert_ne!(one, initial.flat_parameters().unwrap());
        assert_eq!(one, parameters_after_updates(1, 1e-3));
        assert_eq!(one, parameters_after_updates(3, 1e-3));
    }

    #[test]
    fn a_zero_learning_rate_keeps_every_parameter() {
        let initial = ActorCritic::new(small_shape(), 1).unwrap();
        assert_eq!(
            parameters_after_updates(2, 0.0),
            initial.flat_parameters().unwrap()
        );
    }

    #[test]
    fn a_loss_that_is_not_a_number_stops_the_update_and_keeps_the_policy() {
        let shape = crate::rl::policy::PolicyShape {
            observation: 2,
            hidden: vec![8],
            continuous: 1,
            binary: 0,
        };
        let mut ppo = Ppo::new(
            PpoConfig {
                num_envs: 2,
                num_steps: 4,
                ..PpoConfig::default()
            },
            ActorCritic::new(shape, 0).unwrap(),
        )
        .unwrap();
        let before = ppo.policy.flat_parameters().unwrap();
        let batch = Batch {
            observations: vec![0.5; 16],
            actions: vec![0.1; 8],
            log_probs: vec![-1.0; 8],
            advantages: vec![1.0, f32::NAN, 0.0, 1.0, 1.0, 0.0, 2.0, 1.0],
            returns: vec![1.0; 8],
            values: vec![0.0; 8],
        };
        let error = ppo
            .update(&batch, 1e-3, &mut rand::SeedableRng::seed_from_u64(0))
            .unwrap_err();
        assert!(error.to_string().contains("not a number"), "{error}");
        assert_eq!(ppo.policy.flat_parameters().unwrap(), before);
        assert_eq!(ppo.adam.step, 0);
    }

    #[test]
    fn explained_variance_is_one_for_a_perfect_critic() {
        assert_eq!(explained_variance(&[1.0, 2.0, 3.0], &[1.0, 2.0, 3.0]), 1.0);
        assert_eq!(explained_variance(&[2.0, 2.0, 2.0], &[1.0, 2.0, 3.0]), 0.0);
    }
}

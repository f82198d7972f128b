//! The actor-critic: two ReLU MLPs on candle (actor and critic, CleanRL's layout), weights stored
//! [in, out] so a batch is `x · W + b`. The actor's head gives Gaussian means for the continuous
//! actions (with a learned, state-independent log std) and logits for the binary ones.
//!
//! Actions travel as rows `[continuous..., binary...]`, binaries as 0.0 or 1.0. Continuous
//! samples are unbounded; environments clip them to [-1, 1] (CleanRL's `ClipAction`).

use candle_core::{DType, Device, Tensor, Var};
use rand::RngExt;
use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;
use rand_distr::{Distribution, StandardNormal};
use rayon::prelude::*;
use serde::{Deserialize, Serialize};

/// ln(2π) / 2
pub(super) const HALF_LN_TAU: f32 = 0.918_938_5;

/// Where a batch's random numbers come from.
enum Draws<'a> {
    /// One stream for the whole batch, row after row.
    Shared(&'a mut ChaCha8Rng),
    /// One stream per row.
    PerRow(&'a mut [ChaCha8Rng]),
}

impl Draws<'_> {
    fn row(&mut self, i: usize) -> &mut ChaCha8Rng {
        match self {
            Draws::Shared(rng) => rng,
            Draws::PerRow(rngs) => &mut rngs[i],
        }
    }
}

/// The actor's output for some rows, from [`ActorCritic::heads`], to draw actions from.
pub struct Head(Vec<Vec<f32>>);

/// The rows (of `width` values) where `keep` is true, in order.
pub fn rows_where(rows: &[f32], width: usize, keep: &[bool]) -> Vec<f32> {
    rows.chunks(width)
        .zip(keep)
        .filter(|&(_, &k)| k)
        .flat_map(|(row, _)| row.iter().copied())
        .collect()
}

/// The sizes of a policy.
#[derive(Debug, Clone, PartialEq, Eq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct PolicyShape {
    /// Observation values.
    pub observation: usize,
    /// Each hidden layer's width, in order (the actor and the critic alike).
    pub hidden: Vec<usize>,
    /// Continuous actions (Gaussian).
    pub continuous: usize,
    /// Binary actions (Bernoulli).
    pub binary: usize,
}

impl PolicyShape {
    /// Values in one action row: the continuous actions, then the binary ones.
    pub fn action_size(&self) -> usize {
        self.continuous + self.binary
    }

    /// The width of each layer of a network from the observation to `out` outputs.
    pub fn layer_sizes(&self, out: usize) -> Vec<usize> {
        let mut sizes = vec![self.observation];
        sizes.extend(&self.hidden);
        sizes.push(out);
        sizes
    }

    /// The name and dimensions of every parameter tensor, in [`ActorCritic::named_vars`] order:
    /// what a policy file of this shape must hold (checked before anything is allocated).
    pub fn named_dims(&self) -> Vec<(String, Vec<usize>)> {
        let mut dims = Vec::new();
        for (prefix, out) in [("actor", self.action_size()), ("critic", 1)] {
            for (k, pair) in self.layer_sizes(out).windows(2).enumerate() {
                dims.push((format!("{prefix}.{k}.weight"), vec![pair[0], pair[1]]));
                dims.push((format!("{prefix}.{k}.bias"), vec![1, pair[1]]));
            }
        }
        dims.push(("log_std".to_string(), vec![1, self.continuous.max(1)]));
        dims
    }
}

/// Whether to sample actions or take the most likely ones.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ActMode {
    /// Draw from the policy's distributions.
    Sample,
    /// Take the most likely actions.
    Deterministic,
}

/// A batch of actions chosen by the policy, with what PPO needs to learn from them.
#[derive(Debug, Clone, PartialEq)]
pub struct Acted {
    /// Rows of `action_size` values.
    pub actions: Vec<f32>,
    /// Each row's log-probability of its action.
    pub log_probs: Vec<f32>,
    /// Each row's value estimate, from the critic.
    pub values: Vec<f32>,
}

struct Layer {
    weight: Var,
    bias: Var,
}

/// A ReLU multi-layer perceptron.
struct Mlp {
    layers: Vec<Layer>,
}

impl Mlp {
    /// He-initialized hidden layers; the output layer's scale is `output_gain`. Seeded.
    fn new(sizes: &[usize], output_gain: f32, rng: &mut ChaCha8Rng) -> candle_core::Result<Self> {
        let mut layers = Vec::new();
        for (k, pair) in sizes.windows(2).enumerate() {
            let (fan_in, fan_out) = (pair[0], pair[1]);
            let last = k == sizes.len() - 2;
            let std = if last { output_gain } else { 2f32.sqrt() } / (fan_in as f32).sqrt();
            let weights: Vec<f32> = (0..fan_in * fan_out)
                .map(|_| std * Distribution::<f32>::sample(&StandardNormal, rng))
                .collect();
            layers.push(Layer {
                weight: Var::from_tensor(&Tensor::from_vec(
                    weights,
                    (fan_in, fan_out),
                    &Device::Cpu,
                )?)?,
                bias: Var::zeros((1, fan_out), DType::F32, &Device::Cpu)?,
            });
        }
        Ok(Self { layers })
    }

    /// The network's output for a batch of rows. `track`: gradients may flow to the weights
    /// (only the autograd reference of the tests asks for them; learning uses [`super::fused`]).
    fn forward(&self, x: &Tensor, track: bool) -> candle_core::Result<Tensor> {
        let mut h = x.clone();
        for (k, layer) in self.layers.iter().enumerate() {
            let (weight, bias) = (layer.weight.as_tensor(), layer.bias.as_tensor());
            h = match track {
                true => h.matmul(weight)?.broadcast_add(bias)?,
                false => h.matmul(&weight.detach())?.broadcast_add(&bias.detach())?,
            };
            if k + 1 < self.layers.len() {
                h = h.relu()?;
            }
        }
        Ok(h)
    }

    fn named_vars(&self, prefix: &str, out: &mut Vec<(String, Var)>) {
        for (k, layer) in self.layers.iter().enumerate() {
            out.push((format!("{prefix}.{k}.weight"), layer.weight.clone()));
            out.push((format!("{prefix}.{k}.bias"), layer.bias.clone()));
        }
    }
}

/// The actor-critic policy.
pub struct ActorCritic {
    shape: PolicyShape,
    actor: Mlp,
    critic: Mlp,
    log_std: Var,
}

impl ActorCritic {
    /// A freshly initialized policy, reproducible from `seed`.
    pub fn new(shape: PolicyShape, seed: u64) -> candle_core::Result<Self> {
        let mut rng = ChaCha8Rng::seed_from_u64(seed);
        let actor = Mlp::new(&shape.layer_sizes(shape.action_size()), 0.01, &mut rng)?;
        let critic = Mlp::new(&shape.layer_sizes(1), 1.0, &mut rng)?;
        let log_std = Var::zeros((1, shape.continuous.max(1)), DType::F32, &Device::Cpu)?;
        Ok(Self {
            shape,
            actor,
            critic,
            log_std,
        })
    }

    /// The network's sizes.
    pub fn shape(&self) -> &PolicyShape {
        &self.shape
    }

    /// The first trainable tensor's values (tests compare networks by it).
    #[cfg(test)]
    pub(crate) fn first_weights(&self) -> Vec<f32> {
        self.named_vars()[0]
            .1
            .as_tensor()
            .flatten_all()
            .and_then(|t| t.to_vec1::<f32>())
            .expect("a tensor of f32")
    }

    /// Every trainable tensor with a stable name (for saving, loading and the optimizer).
    pub fn named_vars(&self) -> Vec<(String, Var)> {
        let mut vars = Vec::new();
        self.actor.named_vars("actor", &mut vars);
        self.critic.named_vars("critic", &mut vars);
        vars.push(("log_std".to_string(), self.log_std.clone()));
        vars
    }

    /// Sets the log standard deviation of every continuous action (a new policy starts at 0).
    pub fn set_log_std(&self, value: f32) -> candle_core::Result<()> {
        let n = self.shape.continuous.max(1);
        self.log_std
            .set(&Tensor::full(value, (1, n), &Device::Cpu)?)
    }

    /// Chooses actions for a batch of (normalized) observations, with their log-probabilities
    /// and the critic's value estimates (what PPO learns from).
    pub fn act(
        &self,
        observations: &[f32],
        mode: ActMode,
        rng: &mut ChaCha8Rng,
    ) -> candle_core::Result<Acted> {
        let obs = self.observation_tensor(observations)?;
        // The two networks side by side: a rollout's batch is too small for one product to use
        // every thread well.
        let (head, values) = rayon::join(|| self.head(&obs), || self.critic_values(&obs));
        let (actions, log_probs) = self.draw(&head?, mode, Draws::Shared(rng))?;
        Ok(Acted {
            actions,
            log_probs,
            values: values?,
        })
    }

    /// The critic's value estimates alone (the actor is not run).
    pub fn values(&self, observations: &[f32]) -> candle_core::Result<Vec<f32>> {
        self.critic_values(&self.observation_tensor(observations)?)
    }

    fn critic_values(&self, obs: &Tensor) -> candle_core::Result<Vec<f32>> {
        self.critic
            .forward(obs, false)?
            .flatten_all()?
            .to_vec1::<f32>()
    }

    /// The actions alone (rows of `action_size`), for playing rather than learning: the critic
    /// is not run. Draws the same random numbers as [`Self::act`], so both choose alike.
    pub fn choose(
        &self,
        observations: &[f32],
        mode: ActMode,
        rng: &mut ChaCha8Rng,
    ) -> candle_core::Result<Vec<f32>> {
        let obs = self.observation_tensor(observations)?;
        Ok(self.draw(&self.head(&obs)?, mode, Draws::Shared(rng))?.0)
    }

    /// The actors' outputs for each policy's own observations, run side by side: a playing
    /// tick's batches are small, and one product alone leaves threads idle.
    pub fn heads(players: &[(&ActorCritic, &[f32])]) -> candle_core::Result<Vec<Head>> {
        players
            .par_iter()
            .map(|(policy, observations)| match observations.is_empty() {
                true => Ok(Head(Vec::new())),
                false => Ok(Head(
                    policy.head(&policy.observation_tensor(observations)?)?,
                )),
            })
            .collect()
    }

    /// The actions [`Self::choose`] draws, from `head` (the actor's output for the rows where
    /// `played` is true, in order); the other rows get zeros, but their random numbers are drawn
    /// all the same (the draws do not depend on the actor's output).
    pub fn draw_rows(
        &self,
        head: Head,
        played: &[bool],
        mode: ActMode,
        rng: &mut ChaCha8Rng,
    ) -> candle_core::Result<Vec<f32>> {
        let width = self.shape.action_size();
        let mut heads = head.0.into_iter();
        let rows: Vec<Vec<f32>> = played
            .iter()
            .map(|&p| match p {
                true => heads.next().expect("one head row per row played"),
                false => vec![0.0; width],
            })
            .collect();
        let (mut actions, _) = self.draw(&rows, mode, Draws::Shared(rng))?;
        for (row, _) in actions.chunks_mut(width).zip(played).filter(|&(_, &p)| !p) {
            row.fill(0.0);
        }
        Ok(actions)
    }

    /// [`Self::choose`] with one random stream per row: row `k` draws from `rngs[k]` only, so
    /// each row's actions do not depend on which other rows share its batch.
    pub fn choose_per_row(
        &self,
        observations: &[f32],
        mode: ActMode,
        rngs: &mut [ChaCha8Rng],
    ) -> candle_core::Result<Vec<f32>> {
        let obs = self.observation_tensor(observations)?;
        Ok(self.draw(&self.head(&obs)?, mode, Draws::PerRow(rngs))?.0)
    }

    /// The actor's raw output for a batch of (normalized) observations: rows of the continuous
    /// actions' means, then the binary actions' logits (what the ONNX export writes).
    pub fn actor_head(&self, observations: &[f32]) -> candle_core::Result<Vec<f32>> {
        let obs = self.observation_tensor(observations)?;
        self.actor
            .forward(&obs, false)?
            .flatten_all()?
            .to_vec1::<f32>()
    }

    fn observation_tensor(&self, observations: &[f32]) -> candle_core::Result<Tensor> {
        let n = observations.len() / self.shape.observation;
        Tensor::from_slice(observations, (n, self.shape.observation), &Device::Cpu)
    }

    /// The actor's output, a row per observation.
    fn head(&self, obs: &Tensor) -> candle_core::Result<Vec<Vec<f32>>> {
        self.actor.forward(obs, false)?.to_vec2::<f32>()
    }

    /// Draws each row's action from the actor's output: continuous values first, then binaries.
    fn draw(
        &self,
        head: &[Vec<f32>],
        mode: ActMode,
        mut draws: Draws<'_>,
    ) -> candle_core::Result<(Vec<f32>, Vec<f32>)> {
        let log_std = self.log_std.as_tensor().flatten_all()?.to_vec1::<f32>()?;
        let (c, b) = (self.shape.continuous, self.shape.binary);
        let mut actions = Vec::with_capacity(head.len() * (c + b));
        let mut log_probs = Vec::with_capacity(head.len());
        for (i, row) in head.iter().enumerate() {
            let rng = draws.row(i);
            let mut log_prob = 0.0;
            for k in 0..c {
                let (mean, std) = (row[k], log_std[k].exp());
                let noise: f32 = match mode {
                    ActMode::Sample => StandardNormal.sample(rng),
                    ActMode::Deterministic => 0.0,
                };
                actions.push(mean + std * noise);
                log_prob += -0.5 * noise * noise - log_std[k] - HALF_LN_TAU;
            }
            for &logit in &row[c..c + b] {
                let p = sigmoid(logit);
                let on = match mode {
                    ActMode::Sample => rng.random::<f32>() < p,
                    ActMode::Deterministic => p >= 0.5,
                };
                actions.push(if on { 1.0 } else { 0.0 });
                log_prob += if on {
                    -softplus(-logit)
                } else {
                    -softplus(logit)
                };
            }
            log_probs.push(log_prob);
        }
        Ok((actions, log_probs))
    }

    /// Every parameter in one flat vector, in [`Self::named_vars`] order (the layout of
    /// [`super::fused::ParamLayout`]).
    pub fn flat_parameters(&self) -> candle_core::Result<Vec<f32>> {
        let mut flat = Vec::new();
        for (_, var) in self.named_vars() {
            flat.extend(var.as_tensor().flatten_all()?.to_vec1::<f32>()?);
        }
        Ok(flat)
    }

    /// Sets every parameter from a flat vector in [`Self::named_vars`] order.
    pub fn set_flat_parameters(&self, flat: &[f32]) -> candle_core::Result<()> {
        let mut offset = 0;
        for (_, var) in self.named_vars() {
            let len = var.as_tensor().elem_count();
            let values = flat.get(offset..offset + len).ok_or_else(|| {
                candle_core::Error::Msg(format!("{} parameters for a larger policy", flat.len()))
            })?;
            var.set(&Tensor::from_slice(
                values,
                var.as_tensor().dims(),
                &Device::Cpu,
            )?)?;
            offset += len;
        }
        Ok(())
    }

    /// Log-probabilities of `actions`, the entropy of each row's distribution and the value
    /// estimates, as tensors that gradients flow through: the autograd definition of what
    /// [`super::fused`] differentiates by hand ([`super::ppo::readable_loss`] is built on it).
    pub fn evaluate(
        &self,
        observations: &Tensor,
        actions: &Tensor,
    ) -> candle_core::Result<(Tensor, Tensor, Tensor)> {
        let n = observations.dim(0)?;
        let (c, b) = (self.shape.continuous, self.shape.binary);
        let head = self.actor.forward(observations, true)?;
        let values = self
            .critic
            .forward(observations, true)?
            .squeeze(candle_core::D::Minus1)?;
        let mut log_prob = Tensor::zeros(n, DType::F32, &Device::Cpu)?;
        let mut entropy = Tensor::zeros(n, DType::F32, &Device::Cpu)?;
        if c > 0 {
            let mean = head.narrow(1, 0, c)?;
            let log_std = self.log_std.as_tensor();
            let z = actions
                .narrow(1, 0, c)?
                .sub(&mean)?
                .broadcast_div(&log_std.exp()?)?;
            let per_dim = z
                .sqr()?
                .affine(-0.5, -(HALF_LN_TAU as f64))?
                .broadcast_sub(log_std)?;
            log_prob = log_prob.add(&per_dim.sum(1)?)?;
            let gaussian_entropy = log_std.affine(1.0, 0.5 + HALF_LN_TAU as f64)?.sum_all()?;
            entropy = entropy.broadcast_add(&gaussian_entropy)?;
        }
        if b > 0 {
            let logits = head.narrow(1, c, b)?;
            let taken = actions.narrow(1, c, b)?;
            // log p(a) = a·l - softplus(l);  H = softplus(l) - l·sigmoid(l)
            let softplus_l = softplus_tensor(&logits)?;
            log_prob = log_prob.add(&taken.mul(&logits)?.sub(&softplus_l)?.sum(1)?)?;
            let sigmoid_l = candle_nn::ops::sigmoid(&logits)?;
            entropy = entropy.add(&softplus_l.sub(&logits.mul(&sigmoid_l)?)?.sum(1)?)?;
        }
        Ok((log_prob, entropy, values))
    }
}

pub(super) fn sigmoid(x: f32) -> f32 {
    1.0 / (1.0 + (-x).exp())
}

pub(super) fn softplus(x: f32) -> f32 {
    x.max(0.0) + (-x.abs()).exp().ln_1p()
}

/// softplus(x) = max(x, 0) + ln(1 + e^-|x|), stable for large |x|.
fn softplus_tensor(x: &Tensor) -> candle_core::Result<Tensor> {
    x.relu()?
        .add(&x.abs()?.neg()?.exp()?.affine(1.0, 1.0)?.log()?)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn shape() -> PolicyShape {
        PolicyShape {
            observation: 3,
            hidden: vec![16, 16],
            continuous: 2,
            binary: 1,
        }
    }

    #[test]
    fn choose_and_values_give_what_act_gives() {
        let policy = ActorCritic::new(shape(), 2).unwrap();
        policy.set_log_std(-0.5).unwrap();
        let obs: Vec<f32> = (0..15).map(|i| (i as f32 * 1.3).cos()).collect();
        for mode in [ActMode::Sample, ActMode::Deterministic] {
            let acted = policy
                .act(&obs, mode, &mut ChaCha8Rng::seed_from_u64(9))
                .unwrap();
            let chosen = policy
                .choose(&obs, mode, &mut ChaCha8Rng::seed_from_u64(9))
                .unwrap();
            assert_eq!(chosen, acted.actions, "{mode:?}");
            assert_eq!(policy.values(&obs).unwrap(), acted.values);
        }
    }

    #[test]
    fn choosing_some_rows_or_policy_by_policy_draws_what_choosing_all_in_turn_does() {
        let policies: Vec<ActorCritic> = (0..3)
            .map(|seed| ActorCritic::new(shape(), seed).unwrap())
            .collect();
        let obs: Vec<f32> = (0..30).map(|i| (i as f32 * 0.7).sin()).collect();
        let played = [
            true, false, false, true, true, false, true, false, false, true,
        ];
        let (mut all, mut some) = (ChaCha8Rng::seed_from_u64(4), ChaCha8Rng::seed_from_u64(4));
        let every = policies[0].choose(&obs, ActMode::Sample, &mut all).unwrap();
        let kept = rows_where(&obs, 3, &played);
        let head = ActorCritic::heads(&[(&policies[0], &kept)])
            .unwrap()
            .remove(0);
        let rows = policies[0]
            .draw_rows(head, &played, ActMode::Sample, &mut some)
            .unwrap();
        for (k, (a, b)) in every.chunks(3).zip(rows.chunks(3)).enumerate() {
            assert_eq!(b, if played[k] { a } else { &[0.0; 3][..] }, "row {k}");
        }
        assert_eq!(all, some, "the same draws");
        // A policy that plays no row still draws for every row.
        let head = ActorCritic::heads(&[(&policies[1], &[][..])])
            .unwrap()
            .remove(0);
        let none = policies[1]
            .draw_rows(head, &[false; 10], ActMode::Sample, &mut some)
            .unwrap();
        assert_eq!(none, vec![0.0; 30]);
        policies[1].choose(&obs, ActMode::Sample, &mut all).unwrap();
        assert_eq!(all, some);

        let parts = [&obs[..9], &obs[9..12], &obs[12..]];
        let players: Vec<(&ActorCritic, &[f32])> = policies.iter().zip(parts).collect();
        let heads = ActorCritic::heads(&players).unwrap();
        for ((policy, part), head) in players.iter().zip(heads) {
            let every_row = vec![true; part.len() / 3];
            let drawn = policy
                .draw_rows(head, &every_row, ActMode::Sample, &mut some)
                .unwrap();
            assert_eq!(
                drawn,
                policy.choose(part, ActMode::Sample, &mut all).unwrap()
            );
        }
        assert_eq!(all, some);
    }

    #[test]
    fn act_and_evaluate_agree_on_log_probabilities() {
        let policy = ActorCritic::new(shape(), 1).unwrap();
        let obs: Vec<f32> = (0..12).map(|i| (i as f32 * 0.7).sin()).collect();
        let mut rng = ChaCha8Rng::seed_from_u64(3);
        let acted = policy.act(&obs, ActMode::Sample, &mut rng).unwrap();
        assert_eq!(acted.actions.len(), 4 * 3);
        assert!(acted.actions.chunks(3).all(|a| a[2] == 0.0 || a[2] == 1.0));
        let obs_t = Tensor::from_slice(&obs, (4, 3), &Device::Cpu).unwrap();
        let act_t = Tensor::from_slice(&acted.actions, (4, 3), &Device::Cpu).unwrap();
        let (log_prob, entropy, values) = policy.evaluate(&obs_t, &act_t).unwrap();
        let log_prob = log_prob.to_vec1::<f32>().unwrap();
        for (a, b) in log_prob.iter().zip(&acted.log_probs) {
            assert!(
                (a - b).abs() < 1e-4,
                "{log_prob:?} vs {:?}",
                acted.log_probs
            );
        }
        assert_eq!(values.to_vec1::<f32>().unwrap(), acted.values);
        // At initialization: std 1 per Gaussian dim (entropy 1.419 each), logits near 0 (ln 2).
        let h = entropy.to_vec1::<f32>().unwrap()[0];
        assert!(
            (h - (2.0 * 1.418_938_5 + std::f32::consts::LN_2)).abs() < 1e-2,
            "{h}"
        );
    }

    #[test]
    fn named_dims_are_the_dims_of_named_vars() {
        let shape = shape();
        let policy = ActorCritic::new(shape.clone(), 0).unwrap();
        let vars: Vec<(String, Vec<usize>)> = policy
            .named_vars()
            .into_iter()
            .map(|(name, var)| (name, var.as_tensor().dims().to_vec()))
            .collect();
        assert_eq!(shape.named_dims(), vars);
    }

    #[test]
    fn initialization_is_seeded() {
        let a = ActorCritic::new(shape(), 9).unwrap();
        let b = ActorCritic::new(shape(), 9).unwrap();
        let c = ActorCritic::new(shape(), 10).unwrap();
        assert_eq!(a.first_weights(), b.first_weights());
        assert_ne!(a.first_weights(), c.first_weights());
    }
}

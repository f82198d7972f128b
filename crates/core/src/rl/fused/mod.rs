//! The PPO minibatch step without autograd: the actor-critic's forward and backward pass written
//! out on gemm's matrix products (the kernels candle itself calls) into buffers allocated once,
//! with the element-wise work fused into few passes and split across rows with rayon.
//!
//! The network is a stack of dense layers with ReLU between them (actor and critic alike), so its
//! gradients are two matrix products per layer plus element-wise work: for a layer `z = a·W + b`,
//! `∂W = aᵀ·∂z`, `∂b = Σ_rows ∂z` and `∂a = ∂z·Wᵀ`, masked by `a > 0` below a ReLU. The loss is
//! PPO's (CleanRL's `ppo.py`): the clipped surrogate, minus `ent_coef` times the entropy, plus
//! `vf_coef` times half the squared value error, each a mean over the minibatch.
//!
//! Every parameter lives in one flat vector in [`ActorCritic::named_vars`] order, weights `[in,
//! out]` row-major, so the optimizer and the gradient norm are single passes. Sums over rows are
//! taken over fixed chunks of [`ROW_CHUNK`] rows and then added in chunk order: results do not
//! depend on how rayon schedules the chunks. `tests` compares every gradient with candle's
//! autograd on the same loss.

use gemm::{Parallelism, gemm};
use rayon::prelude::*;

use super::policy::{HALF_LN_TAU, PolicyShape, sigmoid, softplus};

/// Rows per unit of parallel element-wise work (and per partial sum).
const ROW_CHUNK: usize = 64;
/// Parameters per unit of parallel work in whole-vector passes (norm, optimizer).
pub(super) const PARAM_CHUNK: usize = 16 * 1024;

/// Where one dense layer's weight `[fan_in, fan_out]` and bias `[fan_out]` lie in the flat vector.
#[derive(Debug, Clone, Copy)]
struct Dense {
    fan_in: usize,
    fan_out: usize,
    weight: usize,
    bias: usize,
}

/// The flat parameter vector's layout for one [`PolicyShape`].
#[derive(Debug, Clone)]
pub struct ParamLayout {
    actor: Vec<Dense>,
    critic: Vec<Dense>,
    /// Offset of the log standard deviations (`max(continuous, 1)` values).
    log_std: usize,
    len: usize,
    continuous: usize,
    binary: usize,
}

impl ParamLayout {
    /// The layout of a network of this shape.
    pub fn new(shape: &PolicyShape) -> Self {
        let mut offset = 0;
        let mut stack = |out: usize| {
            shape
                .layer_sizes(out)
                .windows(2)
                .map(|pair| {
                    let dense = Dense {
                        fan_in: pair[0],
                        fan_out: pair[1],
                        weight: offset,
                        bias: offset + pair[0] * pair[1],
                    };
                    offset += (pair[0] + 1) * pair[1];
                    dense
                })
                .collect::<Vec<_>>()
        };
        let actor = stack(shape.action_size());
        let critic = stack(1);
        Self {
            actor,
            critic,
            log_std: offset,
            len: offset + shape.continuous.max(1),
            continuous: shape.continuous,
            binary: shape.binary,
        }
    }

    /// Number of parameters.
    pub fn len(&self) -> usize {
        self.len
    }

    /// Whether the vector holds no parameters.
    pub fn is_empty(&self) -> bool {
        self.len == 0
    }
}

/// One minibatch, gathered: rows of observations and actions and one value per row of the rest
/// (advantages already normalized if they are to be).
pub struct Minibatch<'a> {
    /// Observation rows, normalized.
    pub observations: &'a [f32],
    /// Action rows, as taken.
    pub actions: &'a [f32],
    /// Each row's log-probability of its action under the policy that took it.
    pub old_log_probs: &'a [f32],
    /// Each row's advantage.
    pub advantages: &'a [f32],
    /// Each row's return, the value head's target.
    pub returns: &'a [f32],
}

/// The loss weights of one update.
#[derive(Debug, Clone, Copy)]
pub struct LossWeights {
    /// PPO's clip range ε on the probability ratio.
    pub clip_coef: f32,
    /// The entropy bonus's weight.
    pub ent_coef: f32,
    /// The value loss's weight.
    pub vf_coef: f32,
}

/// The minibatch's loss terms and CleanRL's diagnostics (means over its rows).
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct LossTerms {
    /// The clipped surrogate loss.
    pub policy_loss: f32,
    /// The value loss, half the squared error.
    pub value_loss: f32,
    /// The policy's entropy.
    pub entropy: f32,
    /// Approximate KL divergence from the old policy, `(ratio − 1) − log ratio`.
    pub approx_kl: f32,
    /// Fraction of rows whose ratio was clipped, `|ratio − 1| > clip_coef`.
    pub clip_fraction: f32,
}

impl LossTerms {
    /// The loss that the gradients are of.
    pub fn total(&self, weights: LossWeights) -> f32 {
        self.policy_loss - weights.ent_coef * self.entropy + weights.vf_coef * self.value_loss
    }
}

/// Buffers for one stack of dense layers: each layer's output (after its ReLU, for hidden layers)
/// and the loss's gradient with respect to its pre-activation.
struct StackBuffers {
    outputs: Vec<Vec<f32>>,
    deltas: Vec<Vec<f32>>,
    /// Per-chunk partial column sums, for bias gradients.
    partial: Vec<f32>,
}

impl StackBuffers {
    fn new(layers: &[Dense], rows: usize) -> Self {
        let widest = layers.iter().map(|l| l.fan_out).max().unwrap_or(0);
        Self {
            outputs: layers.iter().map(|l| vec![0.0; rows * l.fan_out]).collect(),
            deltas: layers.iter().map(|l| vec![0.0; rows * l.fan_out]).collect(),
            partial: vec![0.0; rows.div_ceil(ROW_CHUNK) * widest],
        }
    }
}

/// Everything a minibatch step writes, allocated once for a minibatch size.
pub struct Workspace {
    layout: ParamLayout,
    rows: usize,
    actor: StackBuffers,
    critic: StackBuffers,
    /// Per-chunk partial sums of the loss terms and the log std gradient.
    loss_partials: Vec<f32>,
    /// ∂loss/∂parameters, in the flat layout.
    pub gradients: Vec<f32>,
}

/// Loss partials per chunk: the five [`LossTerms`] then one per log std.
const TERMS: usize = 5;

impl Workspace {
    /// Buffers for minibatches of up to `rows` rows.
    pub fn new(layout: ParamLayout, rows: usize) -> Self {
        let actor = StackBuffers::new(&layout.actor, rows);
        let critic = StackBuffers::new(&layout.critic, rows);
        let width = TERMS + layout.continuous.max(1);
        Self {
            gradients: vec![0.0; layout.len],
            loss_partials: vec![0.0; rows.div_ceil(ROW_CHUNK) * width],
            layout,
            rows,
            actor,
            critic,
        }
    }

    /// The most rows a minibatch may have.
    pub fn capacity(&self) -> usize {
        self.rows
    }

    /// Computes the loss of `batch` under `params` and writes its gradient to `self.gradients`.
    pub fn loss_and_gradients(
        &mut self,
        params: &[f32],
        batch: &Minibatch,
        weights: LossWeights,
    ) -> LossTerms {
        let rows = batch.old_log_probs.len();
        assert!(rows > 0 && rows <= self.rows, "minibatch of {rows} rows");
        assert_eq!(params.len(), self.layout.len);
        let x = batch.observations;
        // The actor and the critic side by side: each pass's products get part of the threads,
        // which a minibatch's small products use better than all of them (docs/speed.md).
        let (layout, actor, critic) = (&self.layout, &mut self.actor, &mut self.critic);
        rayon::join(
            || forward(params, &layout.actor, x, rows, actor),
            || forward(params, &layout.critic, x, rows, critic),
        );
        let terms = self.loss_pass(params, batch, weights, rows);
        let (layout, actor, critic) = (&self.layout, &mut self.actor, &mut self.critic);
        let critic_start = layout.critic[0].weight;
        let (actor_gradients, critic_gradients) = self.gradients.split_at_mut(critic_start);
        rayon::join(
            || backward(params, (actor_gradients, 0), &layout.actor, x, rows, actor),
            || {
                let gradients = (critic_gradients, critic_start);
                backward(params, gradients, &layout.critic, x, rows, critic)
            },
        );
        terms
    }

    /// Reads the network's outputs, fills the output layers' deltas (actor and critic) and the
    /// log std gradient, and returns the loss terms.
    fn loss_pass(
        &mut self,
        params: &[f32],
        batch: &Minibatch,
        weights: LossWeights,
        rows: usize,
    ) -> LossTerms {
        let layout = &self.layout;
        let (c, b) = (layout.continuous, layout.binary);
        let width = c + b;
        let log_std = &params[layout.log_std..layout.log_std + c];
        let std: Vec<f32> = log_std.iter().map(|l| l.exp()).collect();
        let gaussian_entropy: f32 = log_std.iter().map(|l| l + 0.5 + HALF_LN_TAU).sum();
        let per_row = 1.0 / rows as f32;
        let (lo, hi) = (1.0 - weights.clip_coef, 1.0 + weights.clip_coef);
        let stride = TERMS + c.max(1);
        let actor_last = layout.actor.len() - 1;
        let critic_last = layout.critic.len() - 1;
        let head = &self.actor.outputs[actor_last][..rows * width];
        let values = &self.critic.outputs[critic_last][..rows];
        let actor_delta = &mut self.actor.deltas[actor_last][..rows * width];
        let critic_delta = &mut self.critic.deltas[critic_last][..rows];
        let partials = &mut self.loss_partials[..rows.div_ceil(ROW_CHUNK) * stride];
        actor_delta
            .par_chunks_mut(ROW_CHUNK * width)
            .zip(critic_delta.par_chunks_mut(ROW_CHUNK))
            .zip(partials.par_chunks_mut(stride))
            .enumerate()
            .for_each(|(chunk, ((delta, value_delta), partial))| {
                partial.fill(0.0);
                let first = chunk * ROW_CHUNK;
                for (r, value_delta) in value_delta.iter_mut().enumerate() {
                    let i = first + r;
                    let out = &head[i * width..(i + 1) * width];
                    let action = &batch.actions[i * width..(i + 1) * width];
                    let delta = &mut delta[r * width..(r + 1) * width];
                    let mut log_prob = 0.0;
                    let mut entropy = gaussian_entropy;
                    for k in 0..c {
                        let z = (action[k] - out[k]) / std[k];
                        log_prob += -0.5 * z * z - log_std[k] - HALF_LN_TAU;
                    }
                    for k in c..width {
                        let (logit, taken) = (out[k], action[k]);
                        let softplus_l = softplus(logit);
                        log_prob += taken * logit - softplus_l;
                        entropy += softplus_l - logit * sigmoid(logit);
                    }
                    let log_ratio = log_prob - batch.old_log_probs[i];
                    let ratio = log_ratio.exp();
                    let advantage = batch.advantages[i];
                    let unclipped = -advantage * ratio;
                    let clipped = -advantage * ratio.clamp(lo, hi);
                    // The surrogate's slope: the unclipped term's where it is the larger one.
                    let d_log_prob = if unclipped >= clipped {
                        unclipped * per_row
                    } else {
                        0.0
                    };
                    for k in 0..c {
                        let z = (action[k] - out[k]) / std[k];
                        delta[k] = d_log_prob * z / std[k];
                        partial[TERMS + k] += d_log_prob * (z * z - 1.0);
                    }
                    for k in c..width {
                        let (logit, taken) = (out[k], action[k]);
                        let p = sigmoid(logit);
                        // ∂H/∂l = -l·σ(l)·(1 - σ(l)); the entropy enters with -ent_coef.
                        delta[k] = d_log_prob * (taken - p)
                            + weights.ent_coef * per_row * logit * p * (1.0 - p);
                    }
                    let error = values[i] - batch.returns[i];
                    *value_delta = weights.vf_coef * error * per_row;
                    partial[0] += unclipped.max(clipped);
                    partial[1] += 0.5 * error * error;
                    partial[2] += entropy;
                    partial[3] += (ratio - 1.0) - log_ratio;
                    partial[4] += ((ratio - 1.0).abs() > weights.clip_coef) as u8 as f32;
                }
            });
        let mut totals = vec![0.0f64; stride];
        for partial in partials.chunks(stride) {
            for (total, value) in totals.iter_mut().zip(partial) {
                *total += *value as f64;
            }
        }
        let log_std_gradient = &mut self.gradients[layout.log_std..layout.log_std + c.max(1)];
        log_std_gradient.fill(0.0);
        for k in 0..c {
            // d(mean entropy)/d(log std) = 1 per dimension.
            log_std_gradient[k] = totals[TERMS + k] as f32 - weights.ent_coef;
        }
        let mean = |k: usize| (totals[k] / rows as f64) as f32;
        LossTerms {
            policy_loss: mean(0),
            value_loss: mean(1),
            entropy: mean(2),
            approx_kl: mean(3),
            clip_fraction: mean(4),
        }
    }
}

/// This machine's own matrix-product rate in FLOP/s: the best of `runs` products of two
/// `size × size` matrices on the kernels and threads the update uses, timed by `clock`. The
/// update's model-FLOPs utilisation is read against it ([`crate::rl::timing::TimeSplit::update_mfu`]).
pub fn matmul_peak_flops(size: usize, runs: usize, clock: crate::rl::timing::Clock) -> f64 {
    let lhs = vec![1.0f32; size * size];
    let rhs = vec![0.5f32; size * size];
    let mut dst = vec![0.0f32; size * size];
    let mut best = 0.0f64;
    for _ in 0..runs {
        let start = clock();
        matmul(
            &mut dst,
            (size, size, size),
            &lhs,
            (size, 1),
            &rhs,
            (size, 1),
            false,
        );
        let seconds = clock() - start;
        if seconds > 0.0 {
            best = best.max(2.0 * (size as f64).powi(3) / seconds);
        }
    }
    best
}

/// `dst[rows × n] = lhs · rhs` (`read_dst`: `+=`), with explicit strides: element (i, j) of a
/// matrix `m` lies at `m[i * row_stride + j * col_stride]`.
#[allow(clippy::too_many_arguments)]
fn matmul(
    dst: &mut [f32],
    (m, n, k): (usize, usize, usize),
    lhs: &[f32],
    (lhs_rs, lhs_cs): (usize, usize),
    rhs: &[f32],
    (rhs_rs, rhs_cs): (usize, usize),
    read_dst: bool,
) {
    assert!(dst.len() >= m * n);
    assert!(m == 0 || k == 0 || lhs.len() > (m - 1) * lhs_rs + (k - 1) * lhs_cs);
    assert!(k == 0 || n == 0 || rhs.len() > (k - 1) * rhs_rs + (n - 1) * rhs_cs);
    // SAFETY: the asserts above keep every element gemm reads or writes inside the slices; `dst`
    // is borrowed mutably, so it aliases neither input.
    unsafe {
        gemm(
            m,
            n,
            k,
            dst.as_mut_ptr(),
            1,
            n as isize,
            read_dst,
            lhs.as_ptr(),
            lhs_cs as isize,
            lhs_rs as isize,
            rhs.as_ptr(),
            rhs_cs as isize,
            rhs_rs as isize,
            1.0,
            1.0,
            false,
            false,
            false,
            Parallelism::Rayon(0),
        )
    }
}

/// Runs `input` (rows × the first layer's fan-in) through the layers, keeping every output.
fn forward(
    params: &[f32],
    layers: &[Dense],
    input: &[f32],
    rows: usize,
    buffers: &mut StackBuffers,
) {
    for (k, layer) in layers.iter().enumerate() {
        let (before, after) = buffers.outputs.split_at_mut(k);
        let x = if k == 0 { input } else { &before[k - 1][..] };
        let out = &mut after[0][..rows * layer.fan_out];
        let weight = &params[layer.weight..layer.bias];
        matmul(
            out,
            (rows, layer.fan_out, layer.fan_in),
            x,
            (layer.fan_in, 1),
            weight,
            (layer.fan_out, 1),
            false,
        );
        let bias = &params[layer.bias..layer.bias + layer.fan_out];
        let hidden = k + 1 < layers.len();
        out.par_chunks_mut(ROW_CHUNK * layer.fan_out)
            .for_each(|chunk| {
                for row in chunk.chunks_exact_mut(layer.fan_out) {
                    for (v, b) in row.iter_mut().zip(bias) {
                        *v += b;
                    }
                    if hidden {
                        for v in row.iter_mut() {
                            *v = v.max(0.0);
                        }
                    }
                }
            });
    }
}

/// From the last layer's delta (filled by the loss), the gradients of every layer's weights
/// and biases, written into `gradients`: the flat gradient vector from offset `start` on.
fn backward(
    params: &[f32],
    (gradients, start): (&mut [f32], usize),
    layers: &[Dense],
    input: &[f32],
    rows: usize,
    buffers: &mut StackBuffers,
) {
    let last = layers.len() - 1;
    let width = layers[last].fan_out;
    partial_column_sums(
        &mut buffers.deltas[last][..rows * width],
        None,
        width,
        &mut buffers.partial,
    );
    for (k, layer) in layers.iter().enumerate().rev() {
        let (fan_in, fan_out) = (layer.fan_in, layer.fan_out);
        let x = if k == 0 {
            input
        } else {
            &buffers.outputs[k - 1][..]
        };
        let delta = &buffers.deltas[k][..rows * fan_out];
        // ∂W = xᵀ · δ: lhs element (i, r) is x[r][i].
        let (weight_gradient, rest) =
            gradients[layer.weight - start..].split_at_mut(fan_in * fan_out);
        matmul(
            weight_gradient,
            (fan_in, fan_out, rows),
            x,
            (1, fan_in),
            delta,
            (fan_out, 1),
            false,
        );
        add_partials(
            &buffers.partial,
            rows.div_ceil(ROW_CHUNK),
            &mut rest[..fan_out],
        );
        if k == 0 {
            break;
        }
        // ∂x = δ · Wᵀ, then through the ReLU that made x (with the next bias's partial sums).
        let (below, from_k) = buffers.deltas.split_at_mut(k);
        let x_delta = &mut below[k - 1][..rows * fan_in];
        let weight = &params[layer.weight..layer.bias];
        matmul(
            x_delta,
            (rows, fan_in, fan_out),
            &from_k[0][..rows * fan_out],
            (fan_out, 1),
            weight,
            (1, fan_out),
            false,
        );
        let x = &buffers.outputs[k - 1][..rows * fan_in];
        partial_column_sums(x_delta, Some(x), fan_in, &mut buffers.partial);
    }
}

/// Sums the columns of `m` (rows of `width`) per chunk of [`ROW_CHUNK`] rows into `partial`
/// (one row of `width` per chunk). With `relu_output`, first zeroes every element of `m` whose
/// ReLU output is not positive (the ReLU's gradient).
fn partial_column_sums(
    m: &mut [f32],
    relu_output: Option<&[f32]>,
    width: usize,
    partial: &mut [f32],
) {
    let chunks = m.len().div_ceil(ROW_CHUNK * width);
    partial[..chunks * width]
        .par_chunks_mut(width)
        .zip(m.par_chunks_mut(ROW_CHUNK * width))
        .enumerate()
        .for_each(|(chunk, (sum, rows))| {
            if let Some(output) = relu_output {
                let output = &output[chunk * ROW_CHUNK * width..][..rows.len()];
                for (d, a) in rows.iter_mut().zip(output) {
                    *d = if *a > 0.0 { *d } else { 0.0 };
                }
            }
            sum.fill(0.0);
            for row in rows.chunks_exact(width) {
                for (s, v) in sum.iter_mut().zip(row) {
                    *s += v;
                }
            }
        });
}

/// `out = Σ` of the first `chunks` rows of `partial` (each `out.len()` wide), in order.
fn add_partials(partial: &[f32], chunks: usize, out: &mut [f32]) {
    let width = out.len();
    out.fill(0.0);
    for sum in partial[..chunks * width].chunks_exact(width) {
        for (o, s) in out.iter_mut().zip(sum) {
            *o += s;
        }
    }
}

/// The gradient's global L2 norm, summed per chunk in f64 and then in chunk order.
pub fn global_norm(gradients: &[f32]) -> f64 {
    let partials: Vec<f64> = gradients
        .par_chunks(PARAM_CHUNK)
        .map(|chunk| {
            // Sixteen lanes of f32 sums (vectorized), added in f64.
            let mut lanes = [0.0f32; 16];
            let tail = chunk.chunks_exact(16);
            let rest: f64 = tail.remainder().iter().map(|&g| (g * g) as f64).sum();
            for block in tail {
                for (lane, g) in lanes.iter_mut().zip(block) {
                    *lane += g * g;
                }
            }
            rest + lanes.iter().map(|&l| l as f64).sum::<f64>()
        })
        .collect();
    partials.iter().sum::<f64>().sqrt()
}

#[cfg(test)]
mod tests;

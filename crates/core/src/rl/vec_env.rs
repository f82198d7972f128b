//! Many environments stepped together, and the rollout loop that drives them: one batched forward
//! pass of the policy per tick for all environments (beside the other players' passes when some
//! play other policies), then PPO on the collected batch.

use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;

use super::normalizer::RunningNorm;
use super::policy::{ActMode, Acted, ActorCritic, rows_where};
use super::ppo::{Batch, Ppo, UpdateStats, gae};
use super::timing::{Clock, InnerTime, Stopwatch, TimeSplit};

/// What one environment's step led to. Finished episodes are reset by the environment.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct Transition {
    /// The step's reward.
    pub reward: f32,
    /// The episode ended with this step (success, failure or time limit): no bootstrapping.
    pub ended: bool,
    /// For an ended episode of a task with a goal: whether it was reached.
    pub success: Option<bool>,
}

/// A set of environments with automatic reset.
pub trait VecEnv {
    /// How many environments there are.
    fn num_envs(&self) -> usize;
    /// The length of one environment's observation.
    fn observation_size(&self) -> usize;
    /// Writes every environment's current observation, rows of `observation_size`.
    fn observe(&mut self, out: &mut [f32]);
    /// Steps environment `i` with action row `i` and records its transition in `out[i]`.
    fn step(&mut self, actions: &[f32], out: &mut [Transition]);
    /// [`VecEnv::step`], with the seconds by `clock` of the work inside it that is not the
    /// environments' own (a Generator's work); environments
    /// without such work have none to report.
    fn step_timed(&mut self, actions: &[f32], out: &mut [Transition], clock: Clock) -> InnerTime {
        let _ = clock;
        self.step(actions, out);
        InnerTime::default()
    }
    /// Who plays each environment on the next playing tick, when the trainer's policy does not
    /// play them all (earlier snapshots of it, scripted players). None: it plays every one.
    fn other_players(&mut self) -> Option<OtherPlayers<'_>> {
        None
    }
}

/// Who plays an environment on a playing tick.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Seat {
    /// The trainer's policy.
    Learner,
    /// Policy `k` of [`OtherPlayers::policies`].
    Other(usize),
    /// Something that is not a policy (a scripted player): the action row is not read.
    Scripted,
}

/// The players of a playing tick besides the trainer's policy: each environment's seat, the
/// other policies with their observation normalizers, and the stream their actions are drawn
/// from (policy after policy, each over its own environments in order).
pub struct OtherPlayers<'a> {
    /// Each environment's seat, in order.
    pub seats: Vec<Seat>,
    /// The other policies, each with its observation normalizer.
    pub policies: Vec<(&'a ActorCritic, &'a RunningNorm)>,
    /// The stream the other policies' actions are drawn from.
    pub rng: &'a mut ChaCha8Rng,
}

/// Episode statistics of one rollout.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct RolloutStats {
    /// Environment steps collected.
    pub steps: u64,
    /// Episodes that ended.
    pub episodes: u32,
    /// Mean undiscounted return of the episodes that ended (NaN when none did).
    pub mean_return: f32,
    /// Fraction of ended episodes that reached their goal (NaN when none reported).
    pub success_ratio: f32,
}

/// A PPO learner bound to its environments.
pub struct Trainer<E: VecEnv> {
    /// The learner.
    pub ppo: Ppo,
    /// The environments.
    pub env: E,
    /// The observation normalizer, updated as the rollout observes.
    pub norm: RunningNorm,
    /// The stream actions are drawn from.
    pub rng: ChaCha8Rng,
    /// Environment steps collected so far.
    pub global_step: u64,
    observations: Vec<f32>,
    /// Each environment's return so far in its episode under way (a checkpoint keeps them).
    pub episode_returns: Vec<f32>,
}

impl<E: VecEnv> Trainer<E> {
    /// A trainer of `ppo` on `env`, with a fresh normalizer and its RNG seeded by `seed`.
    pub fn new(ppo: Ppo, mut env: E, seed: u64) -> Self {
        let (n, d) = (env.num_envs(), env.observation_size());
        let mut observations = vec![0.0; n * d];
        env.observe(&mut observations);
        Self {
            ppo,
            env,
            norm: RunningNorm::new(d),
            rng: ChaCha8Rng::seed_from_u64(seed),
            global_step: 0,
            observations,
            episode_returns: vec![0.0; n],
        }
    }

    /// Plays `num_steps` ticks of every environment with the current policy; `clock` times
    /// the rollout's buckets (its `update_s` stays 0).
    pub fn collect(
        &mut self,
        clock: Clock,
    ) -> candle_core::Result<(Batch, RolloutStats, TimeSplit)> {
        let mut time = TimeSplit::default();
        let (n, d) = (self.env.num_envs(), self.env.observation_size());
        let steps = self.ppo.config.num_steps;
        let action_size = self.ppo.policy.shape().action_size();
        let mut batch = Batch {
            observations: Vec::with_capacity(steps * n * d),
            actions: Vec::with_capacity(steps * n * action_size),
            log_probs: Vec::with_capacity(steps * n),
            advantages: Vec::new(),
            returns: Vec::new(),
            values: Vec::with_capacity(steps * n),
        };
        let mut rewards = Vec::with_capacity(steps * n);
        let mut ended = Vec::with_capacity(steps * n);
        let mut transitions = vec![Transition::default(); n];
        let (mut episodes, mut return_sum, mut successes, mut judged) = (0u32, 0.0f64, 0u32, 0u32);
        let mut watch = Stopwatch::new(clock);
        for _ in 0..steps {
            self.norm.update(&self.observations);
            time.copies_s += watch.lap();
            let (normalized, acted) = self.act_sampled()?;
            time.forward_s += watch.lap();
            let inner = self.env.step_timed(&acted.actions, &mut transitions, clock);
            time.add_step(watch.lap(), inner);
            for (e, t) in transitions.iter().enumerate() {
                self.episode_returns[e] += t.reward;
                rewards.push(t.reward);
                ended.push(t.ended);
                if t.ended {
                    episodes += 1;
                    return_sum += self.episode_returns[e] as f64;
                    self.episode_returns[e] = 0.0;
                    if let Some(success) = t.success {
                        judged += 1;
                        successes += success as u32;
                    }
                }
            }
            batch.observations.extend_from_slice(&normalized);
            batch.actions.extend_from_slice(&acted.actions);
            batch.log_probs.extend_from_slice(&acted.log_probs);
            batch.values.extend_from_slice(&acted.values);
            time.copies_s += watch.lap();
            self.env.observe(&mut self.observations);
            time.env_s += watch.lap();
        }
        let last_values = self.ppo.policy.values(&self.normalized())?;
        time.forward_s += watch.lap();
        let (advantages, returns) = gae(
            &rewards, &batch.values, &ended, &last_values, self.ppo.config.gamma,
            self.ppo.config.gae_lambda,
        );
        batch.advantages = advantages;
        batch.returns = returns;
        time.gae_s += watch.lap();
        let collected = (steps * n) as u64;
        self.global_step += collected;
        let stats = RolloutStats {
            steps: collected,
            episodes,
            mean_return: if episodes > 0 {
                (return_sum / episodes as f64) as f32
            } else {
                f32::NAN
            },
            success_ratio: if judged > 0 {
                successes as f32 / judged as f32
            } else {
                f32::NAN
            },
        };
        Ok((batch, stats, time))
    }

    /// The current observations normalized (the normalizer itself stays as it is).
    fn normalized(&self) -> Vec<f32> {
        let mut normalized = self.observations.clone();
        self.norm.normalize(&mut normalized);
        normalized
    }

    /// The current observations normalized, and the actions sampled for them.
    fn act_sampled(&mut self) -> candle_core::Result<(Vec<f32>, Acted)> {
        let normalized = self.normalized();
        let acted = self
            .ppo
            .policy
            .act(&normalized, ActMode::Sample, &mut self.rng)?;
        Ok((normalized, acted))
    }

    /// Plays one tick of every environment with the current policy, learning nothing (the
    /// normalizer stays as it is too): the frozen side of an adversarial phase. Nothing is
    /// learned from these steps, so the critic is not run (in a racing finish the networks
    /// were about a quarter of the Generator phase's time); the actions are those a learning
    /// tick would choose, from the same random numbers.
    pub fn play_tick(&mut self, clock: Clock) -> candle_core::Result<TimeSplit> {
        let mut time = TimeSplit::default();
        let mut watch = Stopwatch::new(clock);
        let actions = match self.env.other_players() {
            Some(others) => play_beside(
                (&self.ppo.policy, &self.norm, &mut self.rng),
                &self.observations,
                others,
            )?,
            None => {
                let observations = self.normalized();
                let policy = &self.ppo.policy;
                policy.choose(&observations, ActMode::Sample, &mut self.rng)?
            }
        };
        time.forward_s += watch.lap();
        let mut transitions = vec![Transition::default(); self.env.num_envs()];
        let inner = self.env.step_timed(&actions, &mut transitions, clock);
        time.add_step(watch.lap(), inner);
        for (e, t) in transitions.iter().enumerate() {
            self.episode_returns[e] = if t.ended {
                0.0
            } else {
                self.episode_returns[e] + t.reward
            };
        }
        time.copies_s += watch.lap();
        self.env.observe(&mut self.observations);
        time.env_s += watch.lap();
        Ok(time)
    }

    /// One PPO update on `batch`.
    pub fn learn(&mut self, batch: &Batch, learning_rate: f64) -> candle_core::Result<UpdateStats> {
        self.ppo.update(batch, learning_rate, &mut self.rng)
    }
}

/// The actions of a playing tick where other policies play some environments: every policy's
/// actor run side by side on its own rows (each normalized by its own normalizer), then the
/// learner's draws over every row (as [`ActorCritic::choose`] of all would draw) and each other
/// policy's over its rows, in order.
fn play_beside(
    (policy, norm, rng): (&ActorCritic, &RunningNorm, &mut ChaCha8Rng),
    observations: &[f32],
    others: OtherPlayers<'_>,
) -> candle_core::Result<Vec<f32>> {
    let OtherPlayers {
        seats,
        policies,
        rng: others_rng,
    } = others;
    let d = observations.len() / seats.len();
    let seated = |seat: Seat, norm: &RunningNorm| {
        let mask: Vec<bool> = seats.iter().map(|&s| s == seat).collect();
        let mut rows = rows_where(observations, d, &mask);
        norm.normalize(&mut rows);
        (mask, rows)
    };
    let mut tables = vec![seated(Seat::Learner, norm)];
    tables.extend((0..policies.len()).map(|k| seated(Seat::Other(k), policies[k].1)));
    let players: Vec<(&ActorCritic, &[f32])> = std::iter::once(policy)
        .chain(policies.iter().map(|(p, _)| *p))
        .zip(&tables)
        .map(|(p, (_, rows))| (p, &rows[..]))
        .collect();
    let mut heads = ActorCritic::heads(&players)?.into_iter();
    let learner = heads.next().expect("the learner's head");
    let mut actions = policy.draw_rows(learner, &tables[0].0, ActMode::Sample, rng)?;
    let width = actions.len() / seats.len();
    for (((other, _), (mask, _)), head) in policies.iter().zip(&tables[1..]).zip(heads) {
        let played = mask.iter().filter(|&&m| m).count();
        // A policy that plays no environment draws nothing.
        if played == 0 {
            continue;
        }
        let drawn = other.draw_rows(head, &vec![true; played], ActMode::Sample, others_rng)?;
        let rows = mask.iter().enumerate().filter(|&(_, &m)| m).map(|(i, _)| i);
        for (i, row) in rows.zip(drawn.chunks(width)) {
            actions[i * width..(i + 1) * width].copy_from_slice(row);
        }
    }
    Ok(actions)
}

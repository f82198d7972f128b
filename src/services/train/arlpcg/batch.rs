//! What the Generator learns from: its recorded decisions, taken as a PPO batch once their
//! rewards are final, and the match statistics (with the finish's blocks of hard matches).

use super::{AdversarialEnvs, MatchStats};
use arlpcg_core::game::generator::GeneratorGame;
use arlpcg_core::rl::ppo::{Batch, gae};

impl<G: GeneratorGame> AdversarialEnvs<G> {
    /// Recorded Generator decisions that are complete (their reward is final).
    pub fn completed_decisions(&self) -> usize {
        self.recorded
            .iter()
            .map(|r| r.len() - usize::from(r.last().is_some_and(|d| !d.ended)))
            .sum()
    }

    /// Takes the completed decisions as a PPO batch (advantages by GAE along each match's
    /// sequence of decisions); a decision still waiting for its reward stays for the next batch.
    pub fn take_generator_batch(&mut self) -> Batch {
        let config = &self.generator.ppo.config;
        let mut batch = Batch {
            observations: Vec::new(),
            actions: Vec::new(),
            log_probs: Vec::new(),
            advantages: Vec::new(),
            returns: Vec::new(),
            values: Vec::new(),
        };
        for recorded in &mut self.recorded {
            let pending = recorded.last().filter(|d| !d.ended).cloned();
            if pending.is_some() {
                recorded.pop();
            }
            if !recorded.is_empty() {
                let rewards: Vec<f32> = recorded.iter().map(|d| d.reward).collect();
                let values: Vec<f32> = recorded.iter().map(|d| d.value).collect();
                let ended: Vec<bool> = recorded.iter().map(|d| d.ended).collect();
                let last_value = pending.as_ref().map_or(0.0, |d| d.value);
                let (advantages, returns) = gae(
                    &rewards,
                    &values,
                    &ended,
                    &[last_value],
                    config.gamma,
                    config.gae_lambda,
                );
                for d in recorded.iter() {
                    batch.observations.extend_from_slice(&d.observation);
                    batch.actions.extend_from_slice(&d.action);
                    batch.log_probs.push(d.log_prob);
                    batch.values.push(d.value);
                }
                batch.advantages.extend(advantages);
                batch.returns.extend(returns);
            }
            recorded.clear();
            recorded.extend(pending);
        }
        batch
    }

    /// The match statistics gathered since the last call.
    pub fn take_stats(&mut self) -> MatchStats {
        std::mem::take(&mut self.stats)
    }

    /// Adds the hard matches (λ < 0) of `stats` to the block being counted.
    pub fn add_to_hard_block(&mut self, stats: &MatchStats) {
        self.state.hard_block[0] += stats.successes[1];
        self.state.hard_block[1] += stats.judged[1];
    }

    /// The Solver's success over the block counted so far (none: it holds no hard match).
    pub fn hard_block_success(&self) -> Option<f64> {
        let [successes, judged] = self.state.hard_block;
        (judged > 0).then(|| f64::from(successes) / f64::from(judged))
    }

    /// Adds the hard matches (λ < 0) of `stats` to the block being counted; once the block
    /// holds `block_size` of them, returns the Solver's success ratio over it and begins a
    /// new one.
    pub fn count_hard_block(&mut self, stats: &MatchStats, block_size: u32) -> Option<f64> {
        self.add_to_hard_block(stats);
        let block = &mut self.state.hard_block;
        if block[1] < block_size {
            return None;
        }
        let ratio = f64::from(block[0]) / f64::from(block[1]);
        *block = [0, 0];
        Some(ratio)
    }
}

//! A Solver's training environments, for any game: many of the game's Solver environments
//! stepped in parallel on the rayon pool, each starting a new level when its episode ends.
//! Levels come from the rules (`rule-pcg`: a fresh level every episode) or from a small fixed
//! set (`fixed-track`).
//!
//! Training levels use seeds from [`TRAINING_SEED_BASE`] up, so that evaluation on seeds below it
//! always plays levels the Solver never trained on. New levels and reset seeds are handed out in
//! environment order after each parallel step, so results do not depend on thread timing.

use rayon::prelude::*;
use serde::{Deserialize, Serialize};

use crate::game::{GameSpec, SolverEnv};
use crate::level::Level;
use crate::level::stats::Outcome;
use crate::rl::vec_env::{Transition, VecEnv};

use crate::seeds::TRAINING_SEED_BASE;
/// How many levels `fixed-track` trains on.
pub const FIXED_TRACK_COUNT: u64 = 8;

/// Where the training levels come from.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum SolverMode {
    /// A fresh rule-based level every episode (the paper's Rule-PCG baseline).
    RulePcg,
    /// A small fixed set of rule-based levels (the paper's Fixed-Track baseline).
    FixedTrack,
}

impl SolverMode {
    pub fn name(self) -> &'static str {
        match self {
            SolverMode::RulePcg => "rule-pcg",
            SolverMode::FixedTrack => "fixed-track",
        }
    }
}

/// Progress of the level source, saved in checkpoints.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
pub struct SourceState {
    /// Levels handed out so far.
    pub levels_drawn: u64,
    /// Episodes started so far (each gets its own reset seed).
    pub episodes_started: u64,
}

/// Many environments of game `G` with automatic reset onto new levels.
pub struct SolverEnvs<G: GameSpec> {
    mode: SolverMode,
    envs: Vec<G::Env>,
    fixed: Vec<Level>,
    state: SourceState,
}

impl<G: GameSpec> SolverEnvs<G> {
    /// `num_envs` environments, continuing from `state` (a fresh run starts from the default).
    pub fn new(mode: SolverMode, num_envs: usize, state: SourceState) -> Self {
        let fixed = match mode {
            SolverMode::RulePcg => Vec::new(),
            SolverMode::FixedTrack => (0..FIXED_TRACK_COUNT)
                .map(|k| rule_level::<G>(TRAINING_SEED_BASE + k))
                .collect(),
        };
        let mut this = Self {
            mode,
            envs: Vec::with_capacity(num_envs),
            fixed,
            state,
        };
        let starts: Vec<(Level, u64)> = (0..num_envs).map(|_| this.next_episode()).collect();
        this.envs = starts
            .par_iter()
            .map(|(level, seed)| this.start(level, *seed))
            .collect();
        this
    }

    pub fn state(&self) -> SourceState {
        self.state
    }

    /// The level and reset seed of the next episode to start.
    fn next_episode(&mut self) -> (Level, u64) {
        let level = match self.mode {
            SolverMode::RulePcg => {
                let level = rule_level::<G>(
                    TRAINING_SEED_BASE + FIXED_TRACK_COUNT + self.state.levels_drawn,
                );
                self.state.levels_drawn += 1;
                level
            }
            SolverMode::FixedTrack => {
                let k = self.state.levels_drawn % FIXED_TRACK_COUNT;
                self.state.levels_drawn += 1;
                self.fixed[k as usize].clone()
            }
        };
        let seed = TRAINING_SEED_BASE + self.state.episodes_started;
        self.state.episodes_started += 1;
        (level, seed)
    }

    fn start(&self, level: &Level, seed: u64) -> G::Env {
        let mut env = G::solver_env(level).expect("training levels are of the run's game");
        env.reset(seed);
        env
    }
}

fn rule_level<G: GameSpec>(seed: u64) -> Level {
    // The rules find a level for every seed in practice; if one ever fails, the next seed serves.
    (seed..)
        .find_map(G::rule_level)
        .expect("the rules produce levels")
}

impl<G: GameSpec> VecEnv for SolverEnvs<G> {
    fn num_envs(&self) -> usize {
        self.envs.len()
    }

    fn observation_size(&self) -> usize {
        G::Env::OBSERVATION_SIZE
    }

    fn observe(&mut self, out: &mut [f32]) {
        self.envs
            .par_iter()
            .zip(out.par_chunks_mut(G::Env::OBSERVATION_SIZE))
            .for_each(|(env, row)| env.observe(row));
    }

    fn step(&mut self, actions: &[f32], out: &mut [Transition]) {
        let width = actions.len() / self.envs.len();
        self.envs
            .par_iter_mut()
            .zip(actions.par_chunks(width))
            .zip(out.par_iter_mut())
            .for_each(|((env, row), t)| {
                let step = env.step(G::Env::action_from_policy_row(row));
                *t = Transition {
                    reward: step.reward,
                    ended: step.outcome.is_some(),
                    success: step.outcome.map(|o| o == Outcome::Success),
                };
            });
        let restarts: Vec<(usize, Level, u64)> = (0..self.envs.len())
            .filter(|&i| out[i].ended)
            .map(|i| {
                let (level, seed) = self.next_episode();
                (i, level, seed)
            })
            .collect();
        let fresh: Vec<(usize, G::Env)> = restarts
            .par_iter()
            .map(|(i, level, seed)| (*i, self.start(level, *seed)))
            .collect();
        for (i, env) in fresh {
            self.envs[i] = env;
        }
    }
}

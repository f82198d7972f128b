//! A Solver's training environments, for any game: many of the game's Solver environments
//! stepped in parallel on the rayon pool, each starting a new level when its episode ends.
//! Levels come from the rules (`rule-pcg`: a fresh level every episode) or from a small fixed
//! set (`fixed-track`).
//!
//! Training levels use seeds from [`TRAINING_SEED_BASE`] up, so that evaluation on seeds below it
//! always plays levels the Solver never trained on. New levels and reset seeds are handed out in
//! environment order after each parallel step, so results do not depend on thread timing.
//!
//! Each environment keeps the log of its episode under way (its level's seed, its reset seed,
//! the action rows played since); a checkpoint stores the logs and a resume replays them, so a
//! resumed run goes on with the very episodes it stopped in.

use rayon::prelude::*;
use serde::{Deserialize, Serialize};

use arlpcg_core::game::{GameSpec, Player, SolverEnv, observe_solver};
use arlpcg_core::level::Level;
use arlpcg_core::level::profile::{Abilities, AbilityRanges, ability_columns};
use arlpcg_core::level::stats::Outcome;
use arlpcg_core::rl::vec_env::{Transition, VecEnv};

use arlpcg_core::seed_ranges::TRAINING_SEED_BASE;
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
    /// The mode's name on the command line and in files (`rule-pcg`, `fixed-track`).
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

/// What a checkpoint stores of the environments: the level source's progress and, per
/// environment, its episode under way (none, in checkpoints from before: episodes start afresh).
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
pub struct SourceRecord {
    /// The level source's progress.
    #[serde(flatten)]
    pub state: SourceState,
    /// Per environment, its episode under way.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub under_way: Vec<EpisodeLog>,
}

/// An episode under way: enough to play it again to where it is.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct EpisodeLog {
    /// The seed its rule level was made from.
    pub level_seed: u64,
    /// The seed of the episode's reset.
    pub reset_seed: u64,
    /// The policy's action rows, one per step so far.
    pub rows: Vec<Vec<f32>>,
}

/// Many environments of game `G` with automatic reset onto new levels.
pub struct SolverEnvs<G: GameSpec> {
    mode: SolverMode,
    /// Who the levels are made for and who plays them.
    player: Player,
    /// Some: each episode's main abilities are drawn within these ranges, and the Solver
    /// observes them.
    trained_over: Option<AbilityRanges>,
    /// The abilities each environment's episode is played with.
    played: Vec<Option<Abilities>>,
    envs: Vec<G::Env>,
    logs: Vec<EpisodeLog>,
    fixed: Vec<Level>,
    state: SourceState,
}

impl<G: GameSpec> SolverEnvs<G> {
    /// `num_envs` environments of `player` (its main abilities drawn within `trained_over`
    /// each episode, where given), continuing from `record` (a fresh run starts from the default): its
    /// episodes under way are replayed, rows of `action_size`. `Err` says why a record's
    /// episodes cannot be replayed.
    pub fn new(
        mode: SolverMode,
        num_envs: usize,
        record: SourceRecord,
        action_size: usize,
        (player, trained_over): (Player, Option<AbilityRanges>),
    ) -> Result<Self, String> {
        let fixed = match mode {
            SolverMode::RulePcg => Vec::new(),
            SolverMode::FixedTrack => (0..FIXED_TRACK_COUNT)
                .map(|k| rule_level::<G>(TRAINING_SEED_BASE + k, &player))
                .collect(),
        };
        let mut this = Self {
            mode,
            player,
            trained_over,
            played: Vec::new(),
            envs: Vec::with_capacity(num_envs),
            logs: record.under_way,
            fixed,
            state: record.state,
        };
        if this.logs.is_empty() {
            this.logs = (0..num_envs).map(|_| this.next_episode()).collect();
        } else if this.logs.len() != num_envs {
            return Err(format!(
                "{} episodes under way for {num_envs} environments",
                this.logs.len()
            ));
        }
        this.envs = this
            .logs
            .par_iter()
            .map(|log| this.replayed(log, action_size))
            .collect::<Result<_, String>>()?;
        this.played = this.logs.iter().map(|log| this.abilities(log)).collect();
        Ok(this)
    }

    /// The source's progress and the episodes under way, as a checkpoint stores them.
    pub fn record(&self) -> SourceRecord {
        SourceRecord {
            state: self.state,
            under_way: self.logs.clone(),
        }
    }

    /// The next episode to start: its level's seed and its reset seed.
    fn next_episode(&mut self) -> EpisodeLog {
        let level_seed = match self.mode {
            SolverMode::RulePcg => TRAINING_SEED_BASE + FIXED_TRACK_COUNT + self.state.levels_drawn,
            SolverMode::FixedTrack => {
                TRAINING_SEED_BASE + self.state.levels_drawn % FIXED_TRACK_COUNT
            }
        };
        self.state.levels_drawn += 1;
        let reset_seed = TRAINING_SEED_BASE + self.state.episodes_started;
        self.state.episodes_started += 1;
        EpisodeLog {
            level_seed,
            reset_seed,
            rows: Vec::new(),
        }
    }

    /// The abilities the episode of `log` is played with: the player's, varied from the
    /// episode's reset seed when the Solver is ability-aware.
    fn abilities(&self, log: &EpisodeLog) -> Option<Abilities> {
        let player = self
            .player
            .drawn(G::GAME, self.trained_over.as_ref(), log.reset_seed);
        player.abilities
    }

    /// The environment of a fresh episode: a fixed level when it is one of them, else the
    /// rule level of its seed.
    fn start(&self, log: &EpisodeLog) -> G::Env {
        let fixed = match self.mode {
            SolverMode::FixedTrack => log
                .level_seed
                .checked_sub(TRAINING_SEED_BASE)
                .and_then(|k| self.fixed.get(usize::try_from(k).ok()?)),
            SolverMode::RulePcg => None,
        };
        let level = match fixed {
            Some(level) => level,
            None => &rule_level::<G>(log.level_seed, &self.player),
        };
        let mut env = G::solver_env_with(level, self.abilities(log))
            .expect("training levels are of the run's game");
        env.reset(log.reset_seed);
        env
    }

    /// The episode of `log` played again to where it was: started, and every row stepped.
    fn replayed(&self, log: &EpisodeLog, action_size: usize) -> Result<G::Env, String> {
        let mut env = self.start(log);
        play_rows::<G::Env>(&mut env, &log.rows, action_size)?;
        Ok(env)
    }
}

/// Steps `env` with `rows` (each of `action_size` finite values), which must leave its
/// episode under way.
fn play_rows<E: SolverEnv>(
    env: &mut E,
    rows: &[Vec<f32>],
    action_size: usize,
) -> Result<(), String> {
    for row in rows {
        if row.len() != action_size || !row.iter().all(|a| a.is_finite()) {
            return Err(format!(
                "an action row of an episode under way is not {action_size} finite numbers"
            ));
        }
        if env.step(E::action_from_policy_row(row)).outcome.is_some() {
            return Err("an episode under way ends before its last action".into());
        }
    }
    Ok(())
}

fn rule_level<G: GameSpec>(seed: u64, player: &Player) -> Level {
    // The rules find a level for every seed in practice; if one ever fails, the next seed serves.
    (seed..)
        .find_map(|seed| G::rule_level(seed, player))
        .expect("the rules produce levels")
}

impl<G: GameSpec> VecEnv for SolverEnvs<G> {
    fn num_envs(&self) -> usize {
        self.envs.len()
    }

    fn observation_size(&self) -> usize {
        G::Env::OBSERVATION_SIZE + ability_columns(self.trained_over.is_some())
    }

    fn observe(&mut self, out: &mut [f32]) {
        let size = self.observation_size();
        self.envs
            .par_iter()
            .zip(&self.played)
            .zip(out.par_chunks_mut(size))
            .for_each(|((env, played), row)| observe_solver::<G>(env, played.as_ref(), row));
    }

    fn step(&mut self, actions: &[f32], out: &mut [Transition]) {
        let width = actions.len() / self.envs.len();
        self.envs
            .par_iter_mut()
            .zip(self.logs.par_iter_mut())
            .zip(actions.par_chunks(width))
            .zip(out.par_iter_mut())
            .for_each(|(((env, log), row), t)| {
                let step = env.step(G::Env::action_from_policy_row(row));
                log.rows.push(row.to_vec());
                *t = Transition {
                    reward: step.reward,
                    ended: step.outcome.is_some(),
                    success: step.outcome.map(|o| o == Outcome::Success),
                };
            });
        let restarts: Vec<(usize, EpisodeLog)> = (0..self.envs.len())
            .filter(|&i| out[i].ended)
            .map(|i| (i, self.next_episode()))
            .collect();
        let fresh: Vec<(usize, G::Env)> = restarts
            .par_iter()
            .map(|(i, log)| (*i, self.start(log)))
            .collect();
        for (i, env) in fresh {
            self.envs[i] = env;
        }
        for (i, log) in restarts {
            self.played[i] = self.abilities(&log);
            self.logs[i] = log;
        }
    }
}

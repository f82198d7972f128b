//! A Solver training run: its PPO learner over its environments, started or resumed from a
//! checkpoint, one iteration (rollout, update, metrics row) at a time.

use std::io::Write;
use std::path::{Path, PathBuf};

use super::arlpcg::AdversarialEnvs;
use super::cards::{
    card, read_checkpoint, record_commands, recorded_commands, save_policy_files, solver_shape,
};
use super::config::{TrainConfig, check_config, check_resumable_change};
use super::metrics::{
    check_metrics_header, open_append, time_columns, truncate_metrics, update_columns,
};
use super::solver_envs::SolverEnvs;
use super::{CHECKPOINT, ConfigChange, METRICS, METRICS_HEADER, Progress, Training, UNDER_WAY};
use crate::services::fsio;
use crate::services::fsio::Overwrite;
use anyhow::bail;
use anyhow::{Context, Result};
use arlpcg_core::game::GameSpec;
use arlpcg_core::game::generator::GeneratorGame;
use arlpcg_core::level::Game;
use arlpcg_core::rl::checkpoint;
use arlpcg_core::rl::checkpoint::{PolicyCard, Role, TrainMode, TrainingState};
use arlpcg_core::rl::policy::ActorCritic;
use arlpcg_core::rl::ppo::Ppo;
use arlpcg_core::rl::timing::{Stretch, TimeSplit};
use arlpcg_core::rl::vec_env::{RolloutStats, Trainer, VecEnv};

/// Environments whose progress is saved in checkpoints.
pub(super) trait Resumable: VecEnv {
    /// The game the environments play.
    const GAME: Game;
    fn source_state(&self) -> serde_json::Value;
}

impl<G: GameSpec> Resumable for SolverEnvs<G> {
    const GAME: Game = G::GAME;
    fn source_state(&self) -> serde_json::Value {
        serde_json::to_value(self.record()).expect("source states serialize")
    }
}

impl<G: GeneratorGame> Resumable for AdversarialEnvs<G> {
    const GAME: Game = G::GAME;
    fn source_state(&self) -> serde_json::Value {
        serde_json::to_value(self.record()).expect("source states serialize")
    }
}

/// A Solver training run in progress (the Solver-only modes, and the Solver of the adversarial
/// ones, whose environments hold the Generator).
pub(super) struct SolverRun<E: Resumable> {
    pub(super) out: PathBuf,
    pub(super) mode: TrainMode,
    pub(super) config: TrainConfig,
    pub(super) trainer: Trainer<E>,
    pub(super) iteration: u64,
    pub(super) wall_before: f64,
    pub(super) metrics: std::fs::File,
    /// Each session's command line, the first one's first (the shell names them).
    pub(super) commands: Vec<String>,
    /// The commit of this session's code ([`Training::add_session`]).
    pub(super) commit: String,
    /// Where the run's time went, over every session (both agents' iterations).
    pub(super) time: TimeSplit,
    /// This session's matrix-product peak in FLOP/s ([`Training::set_matmul_peak`]; 0: none).
    pub(super) matmul_peak: f64,
    /// What the finished run measured of itself, for its cards' `results`
    /// ([`Training::check_own_control`]).
    pub(super) results: std::collections::HashMap<String, f64>,
}

impl<E: Resumable> SolverRun<E> {
    pub(super) fn start(
        out: &Path,
        mode: TrainMode,
        config: TrainConfig,
        build: impl FnOnce(&TrainConfig, Option<serde_json::Value>, u64) -> Result<E>,
    ) -> Result<Self> {
        std::fs::create_dir_all(out).with_context(|| format!("cannot create {}", out.display()))?;
        fsio::write_atomic(
            &out.join("config.yaml"),
            serde_yaml::to_string(&config)?.as_bytes(),
            Overwrite::Allowed,
        )?;
        fsio::write_atomic(
            &out.join(METRICS),
            format!("{METRICS_HEADER}\n").as_bytes(),
            Overwrite::Allowed,
        )?;
        let policy = ActorCritic::new(solver_shape(&config, E::GAME), config.seed)?;
        let ppo = Ppo::new(config.solver.clone(), policy)?;
        let envs = build(&config, None, 0)?;
        let trainer = Trainer::new(ppo, envs, config.seed);
        Ok(Self {
            metrics: open_append(&out.join(METRICS))?,
            out: out.to_path_buf(),
            mode,
            config,
            trainer,
            iteration: 0,
            wall_before: 0.0,
            commands: Vec::new(),
            commit: String::new(),
            time: TimeSplit::default(),
            matmul_peak: 0.0,
            results: Default::default(),
        })
    }

    /// Resumes the run in `out`; `change` (from `--config`, `--steps`) replaces its
    /// configuration from here on, the old one kept as `config-until-step-N.yaml`.
    pub(super) fn resume(
        out: &Path,
        mode: TrainMode,
        change: ConfigChange,
        build: impl FnOnce(&TrainConfig, Option<serde_json::Value>, u64) -> Result<E>,
    ) -> Result<Self> {
        let path = out.join(CHECKPOINT);
        let (loaded, state) = read_checkpoint(&path, E::GAME, Role::Solver, mode)?;
        let stored: TrainConfig = serde_json::from_value(state.config.clone())
            .with_context(|| format!("{}: configuration", path.display()))?;
        // As strict as --config: a tampered checkpoint must not allocate or divide by its numbers.
        check_config(&stored, E::GAME).map_err(|problem| {
            anyhow::anyhow!("{}: stored configuration: {problem}", path.display())
        })?;
        check_folder_config(out, &stored, state.global_step, &path)?;
        check_metrics_header(&out.join(METRICS), METRICS_HEADER, &path)?;
        let config = change.apply(&stored);
        check_resumable_change(&stored, &config).map_err(|problem| {
            anyhow::anyhow!(
                "--resume with --config or --seed: {problem} (the run in {})",
                out.display()
            )
        })?;
        if config != stored {
            fsio::write_atomic(
                &out.join(format!("config-until-step-{}.yaml", state.global_step)),
                serde_yaml::to_string(&stored)?.as_bytes(),
                Overwrite::Never,
            )?;
            fsio::write_atomic(
                &out.join("config.yaml"),
                serde_yaml::to_string(&config)?.as_bytes(),
                Overwrite::Allowed,
            )?;
        }
        let vars = loaded.policy.named_vars();
        let mut ppo = Ppo::new(config.solver.clone(), loaded.policy)?;
        ppo.adam
            .restore(&vars, &loaded.tensors, state.adam_step)
            .map_err(|e| anyhow::anyhow!("{}: {e}", path.display()))?;
        // The episodes under way go on where they were, unless the configuration changes
        // (other rules, other rewards): then fresh ones start.
        let mut source = state.source.clone();
        let same_rules = TrainConfig {
            steps: stored.steps,
            ..config.clone()
        } == stored;
        if !same_rules && let Some(fields) = source.as_object_mut() {
            fields.remove(UNDER_WAY);
        }
        let replayed = source.get(UNDER_WAY).is_some();
        let envs = build(&config, Some(source), state.global_step)
            .with_context(|| format!("{}", path.display()))?;
        let mut trainer = Trainer::new(ppo, envs, config.seed);
        trainer.norm = loaded.card.normalizer.clone();
        trainer.rng = state.rng;
        trainer.global_step = state.global_step;
        if replayed {
            if state.episode_returns.len() != trainer.episode_returns.len() {
                bail!(
                    "{}: {} episode returns for {} episodes under way",
                    path.display(),
                    state.episode_returns.len(),
                    trainer.episode_returns.len()
                );
            }
            trainer.episode_returns = state.episode_returns.clone();
        }
        truncate_metrics(&out.join(METRICS), METRICS_HEADER, state.iteration)?;
        Ok(Self {
            metrics: open_append(&out.join(METRICS))?,
            out: out.to_path_buf(),
            mode,
            config,
            trainer,
            iteration: state.iteration,
            wall_before: state.wall_time_s,
            commands: recorded_commands(&loaded.card),
            commit: loaded.card.training.commit.clone(),
            time: state.time_split,
            matmul_peak: 0.0,
            results: Default::default(),
        })
    }

    pub(super) fn save_solver_checkpoint(&self, wall_time_s: f64) -> Result<()> {
        let bytes = self.solver_checkpoint_bytes(wall_time_s)?;
        fsio::write_atomic(&self.out.join(CHECKPOINT), &bytes, Overwrite::Allowed)
    }

    pub(super) fn solver_checkpoint_bytes(&self, wall_time_s: f64) -> Result<Vec<u8>> {
        let state = TrainingState {
            global_step: self.trainer.global_step,
            iteration: self.iteration,
            adam_step: self.trainer.ppo.adam.step,
            wall_time_s,
            rng: self.trainer.rng.clone(),
            source: self.trainer.env.source_state(),
            config: serde_json::to_value(&self.config)?,
            episode_returns: self.trainer.episode_returns.clone(),
            time_split: self.time,
        };
        let card = self.solver_card(wall_time_s);
        Ok(checkpoint::checkpoint_bytes(
            &self.trainer.ppo,
            &card,
            &state,
            Vec::new(),
        ))
    }

    pub(super) fn solver_card(&self, wall_time_s: f64) -> PolicyCard {
        let mut card = card(
            E::GAME,
            Role::Solver,
            self.mode,
            &self.config,
            &self.trainer.norm,
            self.trainer.global_step,
            wall_time_s,
        );
        record_commands(&mut card, &self.commands, &self.commit);
        self.record_time(&mut card);
        card.results = self.results.clone();
        card
    }

    /// The run's time split and the update's MFU, into `card`.
    pub(super) fn record_time(&self, card: &mut PolicyCard) {
        card.training.time_split = Some(self.time.rounded());
        card.training.update_mfu = (self.matmul_peak > 0.0)
            .then(|| (self.time.update_mfu(self.matmul_peak) * 1000.0).round() / 1000.0);
    }

    /// Collects a rollout, updates the Solver, logs a metrics row.
    pub(super) fn solver_iteration(
        &mut self,
        lr_scale: f64,
        stage_rate: Option<f64>,
        wall: &dyn Fn() -> f64,
    ) -> Result<RolloutStats> {
        let learning_rate = match stage_rate {
            Some(rate) => rate,
            None if self.config.solver.anneal_lr => self.config.solver.learning_rate * lr_scale,
            None => self.config.solver.learning_rate,
        };
        let t0 = wall();
        let (batch, rollout, mut time) = self.trainer.collect(wall)?;
        let t1 = wall();
        let update = self.trainer.learn(&batch, learning_rate)?;
        let t2 = wall();
        time.update_s = t2 - t1;
        time.update_flops = self.trainer.ppo.update_flops(&update);
        self.iteration += 1;
        let (rollout_s, update_s) = (t1 - t0, t2 - t1);
        time.copies_s += wall() - t2;
        let iteration_s = wall() - t0;
        self.time.add(&time);
        writeln!(
            self.metrics,
            "{},{},{:.2},{:.1},{:.6},{:.6},{:.3e},{},{:.4},{:.4},{},{},{iteration_s:.6},{:.3}",
            self.iteration,
            self.trainer.global_step,
            wall(),
            rollout.steps as f64 / (rollout_s + update_s),
            rollout_s,
            update_s,
            learning_rate,
            rollout.episodes,
            rollout.mean_return,
            rollout.success_ratio,
            update_columns(&update),
            time_columns(&time),
            time.update_mfu(self.matmul_peak),
        )?;
        Ok(rollout)
    }
}

impl<G: GameSpec> Training for SolverRun<SolverEnvs<G>> {
    fn solver_steps(&self) -> u64 {
        self.trainer.global_step
    }

    fn budget(&self) -> u64 {
        self.config.steps
    }

    fn wall_before(&self) -> f64 {
        self.wall_before
    }

    fn add_session(&mut self, command: String, commit: String) {
        self.commands.push(command);
        self.commit = commit;
    }

    fn set_matmul_peak(&mut self, flops: f64) {
        self.matmul_peak = flops;
    }

    fn time_split(&self) -> (TimeSplit, f64) {
        (self.time, self.time.update_mfu(self.matmul_peak))
    }

    fn iterate(&mut self, wall: &dyn Fn() -> f64) -> Result<Progress> {
        let t0 = wall();
        let lr_scale = self.config.lr_scale(self.trainer.global_step);
        let rollout = self.solver_iteration(lr_scale, None, wall)?;
        self.time.stretches.add(Stretch::SolverPhases, wall() - t0);
        Ok(Progress {
            message: format!(
                "return {:.2}, success {:.2}, {:.0} steps/s, {}",
                rollout.mean_return,
                rollout.success_ratio,
                rollout.steps as f64 / (wall() - t0),
                self.time.largest_two()
            ),
            notable: false,
        })
    }

    fn checkpoint_minutes(&self) -> f64 {
        self.config.checkpoint_minutes
    }

    fn save_checkpoint(&self, wall: f64) -> Result<()> {
        self.save_solver_checkpoint(wall)
    }

    fn save_policies(&self, wall: f64) -> Result<()> {
        save_policy_files(
            &self.out,
            "solver",
            &self.trainer.ppo.policy,
            &self.solver_card(wall),
        )
    }

    fn out(&self) -> &Path {
        &self.out
    }
}

/// Refuses a run folder whose `config.yaml` is not its checkpoint's configuration (the files of
/// two runs, say another game's config beside this checkpoint), before anything is written. A
/// session stopped between a `--config` change and its first checkpoint leaves the new file
/// beside `config-until-step-N.yaml` of the checkpoint's step, which holds the checkpoint's.
fn check_folder_config(
    out: &Path,
    stored: &TrainConfig,
    step: u64,
    checkpoint: &Path,
) -> Result<()> {
    let read = |name: &str| -> Option<std::result::Result<TrainConfig, String>> {
        let path = out.join(name);
        let text = std::fs::read_to_string(&path).ok()?;
        Some(serde_yaml::from_str(&text).map_err(|e| format!("{}: {e}", path.display())))
    };
    let config = out.join("config.yaml");
    match read("config.yaml") {
        None => Ok(()), // missing: the checkpoint's own is the run's configuration
        Some(Ok(own)) if own == *stored => Ok(()),
        Some(own) => {
            let before_change = read(&format!("config-until-step-{step}.yaml"));
            if matches!(before_change, Some(Ok(before)) if before == *stored) {
                return Ok(());
            }
            let why = match own {
                Err(e) => format!("it does not read as a configuration ({e})"),
                Ok(_) => format!(
                    "it is not the configuration stored in {}",
                    checkpoint.display()
                ),
            };
            bail!(
                "{}: {why}: the folder holds files of two different runs; resume a folder that \
                 one run wrote",
                config.display()
            )
        }
    }
}

//! `arlpcg train`: the training runs, in the paper's four modes: the Solver (of either game)
//! alone on rule levels (`rule-pcg`) or on a small fixed set (`fixed-track`), and the adversarial
//! loop with a Generator (`arlpcg`, λ drawn per match; `fixed-aux`, λ = 1).
//!
//! A run lives in its output folder: `config.yaml`, `checkpoint.safetensors` (the Solver;
//! written atomically every few minutes, on Ctrl-C and at the end), `metrics.csv` (one row per
//! Solver update), the final `solver.safetensors` with its card `solver.yaml`, and for the
//! adversarial modes `generator-checkpoint.safetensors`, `generator-metrics.csv` and
//! `generator.safetensors` + `generator.yaml`. `--resume` continues from the checkpoints.

mod adversarial_run;
pub mod arlpcg;
mod cards;
mod config;
mod metrics;
pub mod solver_envs;
mod solver_run;

pub use config::{GeneratorConfig, TrainConfig, TrainMode};

use std::path::{Path, PathBuf};
use std::sync::Arc;
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::Instant;

use anyhow::{Context, Result, bail};

use crate::fsio::{self, Overwrite};
use crate::game::generator::{BuildLimits, GeneratorGame, observation_size};
use crate::game::{GameSpec, PlatformGame, RacingGame};
use crate::level::Game;
use crate::rl::checkpoint::{self, PolicyCard, Role, TrainingRecord, TrainingState};
use crate::rl::normalizer::RunningNorm;
use crate::rl::policy::{ActorCritic, PolicyShape};
use crate::rl::ppo::{Ppo, UpdateStats};
use crate::rl::vec_env::{RolloutStats, Trainer, VecEnv};
use adversarial_run::AdversarialRun;
use arlpcg::{AdversarialEnvs, AdversarialState, Generator, MatchRules, MatchStats, Phase};
use cards::*;
use config::{check_resumable_change, load_config};
use metrics::*;
use solver_envs::{SolverEnvs, SourceState};
use solver_run::*;

pub(super) const CHECKPOINT: &str = "checkpoint.safetensors";
pub(super) const GENERATOR_CHECKPOINT: &str = "generator-checkpoint.safetensors";
pub(super) const METRICS: &str = "metrics.csv";
pub(super) const GENERATOR_METRICS: &str = "generator-metrics.csv";
pub(super) const METRICS_HEADER: &str = "iteration,global_step,wall_time_s,steps_per_s,rollout_s,update_s,learning_rate,episodes,mean_return,success_ratio,policy_loss,value_loss,entropy,approx_kl,clip_fraction,explained_variance";

/// What a training run is asked to do (the command line's `train`, resolved).
#[derive(Debug, Clone, PartialEq)]
pub struct TrainRequest {
    pub game: Game,
    pub mode: TrainMode,
    /// Stop at this many Solver steps in all (over every resume).
    pub steps: Option<u64>,
    /// Stop after this many minutes of this session.
    pub minutes: Option<f64>,
    /// A configuration file (with `resume`: the run's new hyper-parameters).
    pub config: Option<PathBuf>,
    /// The run's folder.
    pub out: Option<PathBuf>,
    pub resume: bool,
    /// Print the default configuration and stop.
    pub print_config: bool,
    /// Worker threads (default: one per core).
    pub threads: Option<u64>,
}

/// Runs `arlpcg train`.
pub fn run(args: &TrainRequest) -> Result<()> {
    if args.print_config {
        print!(
            "{}",
            serde_yaml::to_string(&TrainConfig::for_game(args.game))?
        );
        return Ok(());
    }
    let mode = args.mode;
    let usage = |message: &str| anyhow::Error::from(crate::shell::UsageError(message.into()));
    let out = args.out.as_ref().ok_or_else(|| {
        usage("--out DIR is required: where the run's checkpoint, metrics and policy go")
    })?;
    if args.steps.is_none() && args.minutes.is_none() {
        return Err(usage(
            "give a budget: --steps N (total Solver environment steps) or --minutes M (this session)",
        ));
    }
    let pool = crate::shell::thread_pool(args.threads)?;
    pool.install(|| {
        // A new run's configuration, or a resumed run's replacement (None: keep its own).
        let config = if args.resume {
            args.config
                .as_deref()
                .map(|path| load_config(path, args.game))
                .transpose()?
        } else {
            if out.join(CHECKPOINT).exists() {
                bail!(
                    "{} already holds a training run: add --resume to continue it, or choose another --out",
                    out.display()
                );
            }
            Some(match &args.config {
                Some(path) => load_config(path, args.game)?,
                None => TrainConfig::for_game(args.game),
            })
        };
        match (mode.solver_only(), args.game) {
            (Some(source), Game::Platform) => {
                solver_run::<PlatformGame>(out, mode, source, config, args)
            }
            (Some(source), Game::Racing) => {
                solver_run::<RacingGame>(out, mode, source, config, args)
            }
            (None, Game::Platform) => adversarial_run::<PlatformGame>(out, mode, config, args),
            (None, Game::Racing) => adversarial_run::<RacingGame>(out, mode, config, args),
        }
    })
}

/// Trains a Generator of game `G` against its Solver (the adversarial modes), starting or
/// resuming.
fn adversarial_run<G: GeneratorGame>(
    out: &Path,
    mode: TrainMode,
    config: Option<TrainConfig>,
    args: &TrainRequest,
) -> Result<()> {
    let mut run = if args.resume {
        AdversarialRun::<G>::resume(out, mode, config)?
    } else {
        let config = config.unwrap_or_else(|| TrainConfig::for_game(G::GAME));
        AdversarialRun::<G>::start(out, mode, config)?
    };
    train_loop(&mut run, args)
}

/// Trains a Solver of game `G` alone (the Solver-only modes), starting or resuming.
fn solver_run<G: GameSpec>(
    out: &Path,
    mode: TrainMode,
    source: solver_envs::SolverMode,
    config: Option<TrainConfig>,
    args: &TrainRequest,
) -> Result<()> {
    let build = |config: &TrainConfig, state: Option<serde_json::Value>| {
        let state: SourceState = match state {
            Some(json) => serde_json::from_value(json).context("level source")?,
            None => SourceState::default(),
        };
        Ok(SolverEnvs::<G>::new(source, config.solver.num_envs, state))
    };
    let mut run = if args.resume {
        Run::resume(out, mode, config, build)?
    } else {
        let config = config.unwrap_or_else(|| TrainConfig::for_game(G::GAME));
        Run::start(out, mode, config, build)?
    };
    train_loop(&mut run, args)
}

/// What the training loop drives: one iteration at a time, checkpoints, the final policies.
pub(super) trait Training {
    /// Solver environment steps learned from so far (the budget `--steps` counts).
    fn solver_steps(&self) -> u64;
    /// Wall-clock seconds of earlier sessions.
    fn wall_before(&self) -> f64;
    /// One PPO iteration (of whichever agent learns now) at `lr_scale` times the configured
    /// learning rates; returns the progress bar's message.
    fn iterate(&mut self, lr_scale: f64, wall: &dyn Fn() -> f64) -> Result<String>;
    fn checkpoint_minutes(&self) -> f64;
    fn save_checkpoint(&self, wall: f64) -> Result<()>;
    fn save_policies(&self, wall: f64) -> Result<()>;
    fn out(&self) -> &Path;
}

fn train_loop(run: &mut dyn Training, args: &TrainRequest) -> Result<()> {
    let stop = Arc::new(AtomicBool::new(false));
    {
        let stop = stop.clone();
        // A second handler cannot be installed (tests run several runs in one process).
        let _ = ctrlc::set_handler(move || stop.store(true, Ordering::SeqCst));
    }
    let session = Instant::now();
    let wall_before = run.wall_before();
    let wall = || wall_before + session.elapsed().as_secs_f64();
    let mut last_checkpoint = Instant::now();
    let total_steps = args.steps;
    let bar = match total_steps {
        Some(total) => crate::shell::progress_bar(total, "training"),
        None => crate::shell::progress_bar(
            args.minutes.map_or(0, |m| (m * 60.0) as u64),
            "training (s)",
        ),
    };
    bar.set_position(match total_steps {
        Some(_) => run.solver_steps(),
        None => 0,
    });
    loop {
        let done_by_steps = total_steps.is_some_and(|t| run.solver_steps() >= t);
        let done_by_time = args
            .minutes
            .is_some_and(|m| session.elapsed().as_secs_f64() >= m * 60.0);
        if done_by_steps || done_by_time || stop.load(Ordering::SeqCst) {
            break;
        }
        let lr_scale = match total_steps {
            Some(total) => (1.0 - run.solver_steps() as f64 / total as f64).max(0.0),
            None => 1.0,
        };
        let message = run.iterate(lr_scale, &wall).with_context(|| {
            format!(
                "training stopped at {} Solver steps; the last checkpoint in {} is kept \
                 (--resume, with --config for a smaller learning rate, continues from it)",
                run.solver_steps(),
                run.out().display()
            )
        })?;
        bar.set_message(message);
        match total_steps {
            Some(_) => bar.set_position(run.solver_steps()),
            None => bar.set_position(session.elapsed().as_secs()),
        }
        if last_checkpoint.elapsed().as_secs_f64() >= run.checkpoint_minutes() * 60.0 {
            run.save_checkpoint(wall())?;
            write_learning_curve(run.out())?;
            last_checkpoint = Instant::now();
        }
    }
    bar.finish_and_clear();
    let wall = wall();
    run.save_checkpoint(wall)?;
    run.save_policies(wall)?;
    write_learning_curve(run.out())?;
    let why = if stop.load(Ordering::SeqCst) {
        "stopped (Ctrl-C)"
    } else {
        "finished"
    };
    println!(
        "{why} at {} Solver steps after {:.1} min in all; checkpoints and policies in {}",
        run.solver_steps(),
        wall / 60.0,
        run.out().display()
    );
    Ok(())
}

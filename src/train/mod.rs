//! `arlpcg train`: the training runs of the platform game, in the paper's four modes: the Solver
//! alone on rule levels (`rule-pcg`) or on a small fixed set (`fixed-track`), and the adversarial
//! loop with a Generator (`arlpcg`, λ drawn per match; `fixed-aux`, λ = 1).
//!
//! A run lives in its output folder: `config.yaml`, `checkpoint.safetensors` (the Solver;
//! written atomically every few minutes, on Ctrl-C and at the end), `metrics.csv` (one row per
//! Solver update), the final `solver.safetensors` with its card `solver.yaml`, and for the
//! adversarial modes `generator-checkpoint.safetensors`, `generator-metrics.csv` and
//! `generator.safetensors` + `generator.yaml`. `--resume` continues from the checkpoints.

pub mod arlpcg;
mod config;
pub mod solver_envs;

pub use config::{GeneratorConfig, TrainConfig, TrainMode};

use std::io::Write;
use std::path::{Path, PathBuf};
use std::sync::Arc;
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::Instant;

use anyhow::{Context, Result, bail};
use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;

use crate::cli::TrainArgs;
use crate::fsio::{self, Overwrite};
use crate::game::platform::generator::{
    GENERATOR_ACTIONS, GENERATOR_OBSERVATION_LAYOUT, GENERATOR_OBSERVATION_SIZE,
};
use crate::game::{GameSpec, PlatformGame, RacingGame};
use crate::level::Game;
use crate::rl::checkpoint::{self, PolicyCard, Role, TrainingRecord, TrainingState};
use crate::rl::normalizer::RunningNorm;
use crate::rl::policy::{ActorCritic, PolicyShape};
use crate::rl::ppo::{Ppo, UpdateStats};
use crate::rl::vec_env::{RolloutStats, Trainer, VecEnv};
use arlpcg::{AdversarialEnvs, AdversarialState, Generator, MatchRules, MatchStats, Phase};
use config::{check_resumable_change, load_config};
use solver_envs::{SolverEnvs, SourceState};

const CHECKPOINT: &str = "checkpoint.safetensors";
const GENERATOR_CHECKPOINT: &str = "generator-checkpoint.safetensors";
const METRICS: &str = "metrics.csv";
const GENERATOR_METRICS: &str = "generator-metrics.csv";
const METRICS_HEADER: &str = "iteration,global_step,wall_time_s,steps_per_s,rollout_s,update_s,learning_rate,episodes,mean_return,success_ratio,policy_loss,value_loss,entropy,approx_kl,clip_fraction,explained_variance";
const GENERATOR_METRICS_HEADER: &str = "iteration,solver_step,generator_step,wall_time_s,rollout_s,update_s,learning_rate,episodes,mean_return,invalid_ratio,success_easy,success_hard,distance_easy,distance_hard,size_easy,size_hard,policy_loss,value_loss,entropy,approx_kl,clip_fraction,explained_variance";

/// Runs `arlpcg train`.
pub fn run(args: &TrainArgs) -> Result<()> {
    if args.print_config {
        print!(
            "{}",
            serde_yaml::to_string(&TrainConfig::for_game(args.game))?
        );
        return Ok(());
    }
    let mode = args.mode;
    let usage = |message: &str| anyhow::Error::from(crate::commands::UsageError(message.into()));
    if args.game == Game::Racing && mode.solver_only().is_none() {
        return Err(usage(
            "--game racing trains with --mode rule-pcg or fixed-track so far: the racing Generator (for arlpcg and fixed-aux) is not built yet",
        ));
    }
    let out = args.out.as_ref().ok_or_else(|| {
        usage("--out DIR is required: where the run's checkpoint, metrics and policy go")
    })?;
    if args.steps.is_none() && args.minutes.is_none() {
        return Err(usage(
            "give a budget: --steps N (total Solver environment steps) or --minutes M (this session)",
        ));
    }
    let pool = crate::commands::thread_pool(args.threads)?;
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
            (None, _) => {
                let mut run = if args.resume {
                    AdversarialRun::resume(out, mode, config)?
                } else {
                    AdversarialRun::start(out, mode, config.unwrap_or_default())?
                };
                train_loop(&mut run, args)
            }
        }
    })
}

/// Trains a Solver of game `G` alone (the Solver-only modes), starting or resuming.
fn solver_run<G: GameSpec>(
    out: &Path,
    mode: TrainMode,
    source: solver_envs::SolverMode,
    config: Option<TrainConfig>,
    args: &TrainArgs,
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
trait Training {
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

fn train_loop(run: &mut dyn Training, args: &TrainArgs) -> Result<()> {
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
        Some(total) => crate::commands::progress_bar(total, "training"),
        None => crate::commands::progress_bar(
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

/// Column `name` of a metrics CSV as (x column, value) pairs, smoothed over `window` rows.
fn metric_series(text: &str, x: &str, name: &str, window: usize) -> Vec<(f64, f64)> {
    let mut lines = text.lines();
    let header: Vec<&str> = lines.next().unwrap_or_default().split(',').collect();
    let (Some(xi), Some(yi)) = (
        header.iter().position(|h| *h == x),
        header.iter().position(|h| *h == name),
    ) else {
        return Vec::new();
    };
    let rows: Vec<(f64, f64)> = lines
        .filter_map(|line| {
            let fields: Vec<&str> = line.split(',').collect();
            Some((fields.get(xi)?.parse().ok()?, fields.get(yi)?.parse().ok()?))
        })
        .collect();
    (0..rows.len())
        .map(|i| {
            let recent: Vec<f64> = rows[i.saturating_sub(window - 1)..=i]
                .iter()
                .map(|r| r.1)
                .filter(|v: &f64| v.is_finite())
                .collect();
            // An empty window is NaN (0/0): the chart breaks the line there.
            (rows[i].0, recent.iter().sum::<f64>() / recent.len() as f64)
        })
        .collect()
}

/// `learning-curve.png`: the Solver's training success ratio against its steps (and, in the
/// adversarial modes, its success on easy and hard Generator levels), smoothed over 10 updates.
fn write_learning_curve(out: &Path) -> Result<()> {
    let read = |name: &str| std::fs::read_to_string(out.join(name)).unwrap_or_default();
    let solver = read(METRICS);
    let generator = read(GENERATOR_METRICS);
    let mut series = vec![crate::chart::Series {
        name: "Solver, training".into(),
        points: metric_series(&solver, "global_step", "success_ratio", 10),
    }];
    for (column, name) in [("success_easy", "λ > 0"), ("success_hard", "λ < 0")] {
        let points = metric_series(&generator, "solver_step", column, 10);
        if !points.is_empty() {
            series.push(crate::chart::Series {
                name: name.into(),
                points,
            });
        }
    }
    let chart = crate::chart::LineChart {
        title: format!("Solver success ratio ({})", out.display()),
        x_label: "Solver environment steps".into(),
        y_label: "success ratio".into(),
        series,
        y_range: Some((0.0, 1.0)),
    };
    fsio::write_atomic(
        &out.join("learning-curve.png"),
        &chart.to_png(),
        Overwrite::Allowed,
    )
}

/// Environments whose progress is saved in checkpoints.
trait Resumable: VecEnv {
    /// The game the environments play.
    const GAME: Game;
    fn source_state(&self) -> serde_json::Value;
}

impl<G: GameSpec> Resumable for SolverEnvs<G> {
    const GAME: Game = G::GAME;
    fn source_state(&self) -> serde_json::Value {
        serde_json::to_value(self.state()).expect("source states serialize")
    }
}

impl Resumable for AdversarialEnvs {
    const GAME: Game = Game::Platform;
    fn source_state(&self) -> serde_json::Value {
        serde_json::to_value(self.state).expect("source states serialize")
    }
}

/// What a game's Solver observes and does, as a policy card names it.
struct SolverIo {
    observation: &'static [(&'static str, usize)],
    continuous: &'static [&'static str],
    binary: &'static [&'static str],
}

impl SolverIo {
    fn of(game: Game) -> Self {
        fn io<G: GameSpec>() -> SolverIo {
            SolverIo {
                observation: G::OBSERVATION_LAYOUT,
                continuous: G::CONTINUOUS_ACTIONS,
                binary: G::BINARY_ACTIONS,
            }
        }
        match game {
            Game::Platform => io::<PlatformGame>(),
            Game::Racing => io::<RacingGame>(),
        }
    }

    fn observation_size(&self) -> usize {
        self.observation.iter().map(|(_, k)| k).sum()
    }
}

/// The Solver's policy shape.
fn solver_shape(config: &TrainConfig, game: Game) -> PolicyShape {
    let io = SolverIo::of(game);
    PolicyShape {
        observation: io.observation_size(),
        hidden: config.hidden.clone(),
        continuous: io.continuous.len(),
        binary: io.binary.len(),
    }
}

/// The Generator's policy shape.
fn generator_shape(config: &TrainConfig) -> PolicyShape {
    PolicyShape {
        observation: GENERATOR_OBSERVATION_SIZE,
        hidden: config.hidden.clone(),
        continuous: GENERATOR_ACTIONS.len(),
        binary: 0,
    }
}

/// A policy card for a policy trained by this run.
fn card(
    game: Game,
    role: Role,
    mode: TrainMode,
    config: &TrainConfig,
    normalizer: &RunningNorm,
    steps: u64,
    wall_time_s: f64,
) -> PolicyCard {
    let names = |list: &[&str]| list.iter().map(|s| s.to_string()).collect::<Vec<_>>();
    let layout = |list: &[(&str, usize)]| {
        list.iter()
            .map(|(n, k)| (n.to_string(), *k))
            .collect::<Vec<_>>()
    };
    let (observation, continuous_actions, binary_actions, network) = match role {
        Role::Solver => {
            let io = SolverIo::of(game);
            (
                layout(io.observation),
                names(io.continuous),
                names(io.binary),
                solver_shape(config, game),
            )
        }
        Role::Generator => (
            layout(&GENERATOR_OBSERVATION_LAYOUT),
            names(&GENERATOR_ACTIONS),
            Vec::new(),
            generator_shape(config),
        ),
    };
    PolicyCard {
        format: checkpoint::POLICY_FORMAT.into(),
        version: checkpoint::POLICY_VERSION,
        game,
        role,
        observation,
        continuous_actions,
        binary_actions,
        network,
        normalizer: normalizer.clone(),
        training: TrainingRecord {
            mode: mode.name().into(),
            steps,
            wall_time_s: (wall_time_s * 10.0).round() / 10.0,
            seed: config.seed,
            commit: git_commit(),
            command: std::iter::once("arlpcg".to_string())
                .chain(std::env::args().skip(1))
                .collect::<Vec<_>>()
                .join(" "),
        },
        results: Default::default(),
        max_blocks: (role == Role::Generator).then_some(config.generator.max_blocks),
    }
}

/// Writes a policy and its YAML card (`<name>.safetensors`, `<name>.yaml`) into `out`.
fn save_policy_files(
    out: &Path,
    name: &str,
    policy: &ActorCritic,
    card: &PolicyCard,
) -> Result<()> {
    fsio::write_atomic(
        &out.join(format!("{name}.safetensors")),
        &checkpoint::policy_bytes(policy, card),
        Overwrite::Allowed,
    )?;
    fsio::write_atomic(
        &out.join(format!("{name}.yaml")),
        serde_yaml::to_string(card)?.as_bytes(),
        Overwrite::Allowed,
    )
}

/// A Solver training run in progress (the Solver-only modes, and the Solver of the adversarial
/// ones, whose environments hold the Generator).
struct Run<E: Resumable> {
    out: PathBuf,
    mode: TrainMode,
    config: TrainConfig,
    trainer: Trainer<E>,
    iteration: u64,
    wall_before: f64,
    metrics: std::fs::File,
}

impl<E: Resumable> Run<E> {
    fn start(
        out: &Path,
        mode: TrainMode,
        config: TrainConfig,
        build: impl FnOnce(&TrainConfig, Option<serde_json::Value>) -> Result<E>,
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
        let envs = build(&config, None)?;
        let trainer = Trainer::new(ppo, envs, config.seed);
        Ok(Self {
            metrics: open_append(&out.join(METRICS))?,
            out: out.to_path_buf(),
            mode,
            config,
            trainer,
            iteration: 0,
            wall_before: 0.0,
        })
    }

    /// Resumes the run in `out`; `replacement` (from `--config`) replaces its configuration from
    /// here on, the old one kept as `config-until-step-N.yaml`.
    fn resume(
        out: &Path,
        mode: TrainMode,
        replacement: Option<TrainConfig>,
        build: impl FnOnce(&TrainConfig, Option<serde_json::Value>) -> Result<E>,
    ) -> Result<Self> {
        let path = out.join(CHECKPOINT);
        let (loaded, state) = read_checkpoint(&path, E::GAME, Role::Solver, mode)?;
        let stored: TrainConfig = serde_json::from_value(state.config.clone())
            .with_context(|| format!("{}: configuration", path.display()))?;
        let config = match replacement {
            None => stored,
            Some(new) => {
                check_resumable_change(&stored, &new).map_err(|problem| {
                    anyhow::anyhow!(
                        "--config with --resume: {problem} (the run in {})",
                        out.display()
                    )
                })?;
                if new != stored {
                    fsio::write_atomic(
                        &out.join(format!("config-until-step-{}.yaml", state.global_step)),
                        serde_yaml::to_string(&stored)?.as_bytes(),
                        Overwrite::Never,
                    )?;
                    fsio::write_atomic(
                        &out.join("config.yaml"),
                        serde_yaml::to_string(&new)?.as_bytes(),
                        Overwrite::Allowed,
                    )?;
                }
                new
            }
        };
        let vars = loaded.policy.named_vars();
        let mut ppo = Ppo::new(config.solver.clone(), loaded.policy)?;
        ppo.adam
            .restore(&vars, &loaded.tensors, state.adam_step)
            .map_err(|e| anyhow::anyhow!("{}: {e}", path.display()))?;
        let envs = build(&config, Some(state.source.clone()))
            .with_context(|| format!("{}", path.display()))?;
        let mut trainer = Trainer::new(ppo, envs, config.seed);
        trainer.norm = loaded.card.normalizer.clone();
        trainer.rng = state.rng;
        trainer.global_step = state.global_step;
        truncate_metrics(&out.join(METRICS), METRICS_HEADER, state.iteration)?;
        Ok(Self {
            metrics: open_append(&out.join(METRICS))?,
            out: out.to_path_buf(),
            mode,
            config,
            trainer,
            iteration: state.iteration,
            wall_before: state.wall_time_s,
        })
    }

    fn save_solver_checkpoint(&self, wall_time_s: f64) -> Result<()> {
        let state = TrainingState {
            global_step: self.trainer.global_step,
            iteration: self.iteration,
            adam_step: self.trainer.ppo.adam.step,
            wall_time_s,
            rng: self.trainer.rng.clone(),
            source: self.trainer.env.source_state(),
            config: serde_json::to_value(&self.config)?,
        };
        let card = self.solver_card(wall_time_s);
        let bytes = checkpoint::checkpoint_bytes(&self.trainer.ppo, &card, &state);
        fsio::write_atomic(&self.out.join(CHECKPOINT), &bytes, Overwrite::Allowed)
    }

    fn solver_card(&self, wall_time_s: f64) -> PolicyCard {
        card(
            E::GAME,
            Role::Solver,
            self.mode,
            &self.config,
            &self.trainer.norm,
            self.trainer.global_step,
            wall_time_s,
        )
    }

    /// Collects a rollout, updates the Solver, logs a metrics row.
    fn solver_iteration(&mut self, lr_scale: f64, wall: &dyn Fn() -> f64) -> Result<RolloutStats> {
        let learning_rate = if self.config.solver.anneal_lr {
            self.config.solver.learning_rate * lr_scale
        } else {
            self.config.solver.learning_rate
        };
        let t0 = Instant::now();
        let (batch, rollout) = self.trainer.collect()?;
        let t1 = Instant::now();
        let update = self.trainer.learn(&batch, learning_rate)?;
        let t2 = Instant::now();
        self.iteration += 1;
        let (rollout_s, update_s) = ((t1 - t0).as_secs_f64(), (t2 - t1).as_secs_f64());
        writeln!(
            self.metrics,
            "{},{},{:.2},{:.1},{:.3},{:.3},{:.3e},{},{:.4},{:.4},{}",
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
            update_columns(&update)
        )?;
        Ok(rollout)
    }
}

/// The loss columns of a metrics row.
fn update_columns(u: &UpdateStats) -> String {
    format!(
        "{:.5},{:.5},{:.4},{:.5},{:.4},{:.4}",
        u.policy_loss, u.value_loss, u.entropy, u.approx_kl, u.clip_fraction, u.explained_variance
    )
}

fn open_append(path: &Path) -> Result<std::fs::File> {
    std::fs::OpenOptions::new()
        .append(true)
        .open(path)
        .with_context(|| format!("cannot open {}", path.display()))
}

/// Reads a checkpoint of `role`, checking that it was trained in `mode`.
fn read_checkpoint(
    path: &Path,
    game: Game,
    role: Role,
    mode: TrainMode,
) -> Result<(checkpoint::LoadedPolicy, TrainingState)> {
    let bytes = crate::fsio::read_limited(path, checkpoint::MAX_POLICY_BYTES, "checkpoint")
        .context("cannot resume")?;
    let observation = match role {
        Role::Solver => SolverIo::of(game).observation_size(),
        Role::Generator => GENERATOR_OBSERVATION_SIZE,
    };
    let loaded = checkpoint::load_policy(&bytes, game, role, observation)
        .with_context(|| format!("{}", path.display()))?;
    let state = loaded
        .training_state()
        .with_context(|| format!("{}", path.display()))?;
    if loaded.card.training.mode != mode.name() {
        bail!(
            "{} was trained with --mode {}, not {}",
            path.display(),
            loaded.card.training.mode,
            mode.name()
        );
    }
    Ok((loaded, state))
}

impl<G: GameSpec> Training for Run<SolverEnvs<G>> {
    fn solver_steps(&self) -> u64 {
        self.trainer.global_step
    }

    fn wall_before(&self) -> f64 {
        self.wall_before
    }

    fn iterate(&mut self, lr_scale: f64, wall: &dyn Fn() -> f64) -> Result<String> {
        let t0 = Instant::now();
        let rollout = self.solver_iteration(lr_scale, wall)?;
        Ok(format!(
            "return {:.2}, success {:.2}, {:.0} steps/s",
            rollout.mean_return,
            rollout.success_ratio,
            rollout.steps as f64 / t0.elapsed().as_secs_f64()
        ))
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

/// An adversarial run: the Solver's run, whose environments hold the Generator, and the
/// Generator's own counters and metrics.
struct AdversarialRun {
    solver: Run<AdversarialEnvs>,
    generator_iteration: u64,
    generator_metrics: std::fs::File,
}

impl AdversarialRun {
    fn rules(mode: TrainMode, config: &TrainConfig) -> MatchRules {
        MatchRules {
            aux_values: match mode {
                TrainMode::FixedAux => vec![1.0],
                _ => config.generator.aux_values.clone(),
            },
            max_blocks: config.generator.max_blocks,
            rewards: config.generator.rewards.clone(),
        }
    }

    fn start(out: &Path, mode: TrainMode, config: TrainConfig) -> Result<Self> {
        let build = |config: &TrainConfig, _: Option<serde_json::Value>| {
            let policy = ActorCritic::new(generator_shape(config), config.seed.wrapping_add(1))?;
            policy.set_log_std(config.generator.initial_log_std)?;
            let generator = Generator {
                ppo: Ppo::new(config.generator.ppo.clone(), policy)?,
                norm: RunningNorm::new(GENERATOR_OBSERVATION_SIZE),
            };
            let rng = ChaCha8Rng::seed_from_u64(config.seed.wrapping_add(1));
            Ok(AdversarialEnvs::new(
                config.solver.num_envs,
                generator,
                rng,
                Self::rules(mode, config),
                AdversarialState::default(),
            )?)
        };
        let solver = Run::start(out, mode, config, build)?;
        fsio::write_atomic(
            &out.join(GENERATOR_METRICS),
            format!("{GENERATOR_METRICS_HEADER}\n").as_bytes(),
            Overwrite::Allowed,
        )?;
        Ok(Self {
            solver,
            generator_iteration: 0,
            generator_metrics: open_append(&out.join(GENERATOR_METRICS))?,
        })
    }

    fn resume(out: &Path, mode: TrainMode, replacement: Option<TrainConfig>) -> Result<Self> {
        let path = out.join(GENERATOR_CHECKPOINT);
        if !path.exists() && out.join(CHECKPOINT).exists() {
            // A Solver-only run: its checkpoint says which mode it was trained in.
            read_checkpoint(&out.join(CHECKPOINT), Game::Platform, Role::Solver, mode)?;
        }
        let (loaded, generator_state) =
            read_checkpoint(&path, Game::Platform, Role::Generator, mode)?;
        let generator_iteration = generator_state.iteration;
        let build = move |config: &TrainConfig, source: Option<serde_json::Value>| {
            let state: AdversarialState =
                serde_json::from_value(source.unwrap_or_default()).context("match source")?;
            let vars = loaded.policy.named_vars();
            let mut ppo = Ppo::new(config.generator.ppo.clone(), loaded.policy)?;
            ppo.adam
                .restore(&vars, &loaded.tensors, generator_state.adam_step)
                .map_err(|e| anyhow::anyhow!("{}: {e}", path.display()))?;
            let generator = Generator {
                ppo,
                norm: loaded.card.normalizer.clone(),
            };
            // Unfinished matches are gone: the run goes on with fresh ones, in the same phase.
            Ok(AdversarialEnvs::new(
                config.solver.num_envs,
                generator,
                generator_state.rng,
                Self::rules(mode, config),
                state,
            )?)
        };
        let solver = Run::resume(out, mode, replacement, build)?;
        truncate_metrics(
            &out.join(GENERATOR_METRICS),
            GENERATOR_METRICS_HEADER,
            generator_iteration,
        )?;
        Ok(Self {
            solver,
            generator_iteration,
            generator_metrics: open_append(&out.join(GENERATOR_METRICS))?,
        })
    }

    fn envs(&mut self) -> &mut AdversarialEnvs {
        &mut self.solver.trainer.env
    }

    fn generator_card(&self, wall_time_s: f64) -> PolicyCard {
        let envs = &self.solver.trainer.env;
        card(
            Game::Platform,
            Role::Generator,
            self.solver.mode,
            &self.solver.config,
            &envs.generator.norm,
            envs.state.generator_steps,
            wall_time_s,
        )
    }

    /// Plays until a batch of Generator decisions is complete, and learns from it.
    fn generator_iteration(&mut self, lr_scale: f64, wall: &dyn Fn() -> f64) -> Result<String> {
        let config = self.solver.config.generator.ppo.clone();
        let learning_rate = if config.anneal_lr {
            config.learning_rate * lr_scale
        } else {
            config.learning_rate
        };
        let t0 = Instant::now();
        self.envs().take_stats();
        while self.envs().completed_decisions() < config.batch_size() {
            self.solver.trainer.play_tick()?;
        }
        let batch = self.envs().take_generator_batch();
        let stats = self.envs().take_stats();
        let t1 = Instant::now();
        let envs = self.envs();
        let update = envs
            .generator
            .ppo
            .update(&batch, learning_rate, &mut envs.rng)?;
        let t2 = Instant::now();
        let decisions = batch.log_probs.len() as u64;
        envs.state.generator_steps += decisions;
        envs.state.phase_steps += decisions;
        self.generator_iteration += 1;
        let row = generator_row(&stats);
        writeln!(
            self.generator_metrics,
            "{},{},{},{:.2},{:.3},{:.3},{:.3e},{row},{}",
            self.generator_iteration,
            self.solver.trainer.global_step,
            self.solver.trainer.env.state.generator_steps,
            wall(),
            (t1 - t0).as_secs_f64(),
            (t2 - t1).as_secs_f64(),
            learning_rate,
            update_columns(&update)
        )?;
        let ratio = |a: u32, b: u32| a as f64 / b.max(1) as f64;
        Ok(format!(
            "generator: success easy {:.2} / hard {:.2}, invalid {:.2}",
            ratio(stats.successes[0], stats.judged[0]),
            ratio(stats.successes[1], stats.judged[1]),
            ratio(stats.invalid, stats.episodes)
        ))
    }
}

/// The match columns of a Generator metrics row.
fn generator_row(s: &MatchStats) -> String {
    let ratio = |a: f64, b: u32| if b == 0 { f64::NAN } else { a / b as f64 };
    format!(
        "{},{:.4},{:.4},{:.4},{:.4},{:.4},{:.4},{:.4},{:.4}",
        s.episodes,
        ratio(s.generator_return_sum, s.episodes),
        ratio(s.invalid as f64, s.episodes),
        ratio(s.successes[0] as f64, s.judged[0]),
        ratio(s.successes[1] as f64, s.judged[1]),
        ratio(s.distance_sum[0], s.blocks[0]),
        ratio(s.distance_sum[1], s.blocks[1]),
        ratio(s.size_sum[0], s.blocks[0]),
        ratio(s.size_sum[1], s.blocks[1]),
    )
}

impl Training for AdversarialRun {
    fn solver_steps(&self) -> u64 {
        self.solver.trainer.global_step
    }

    fn wall_before(&self) -> f64 {
        self.solver.wall_before
    }

    fn iterate(&mut self, lr_scale: f64, wall: &dyn Fn() -> f64) -> Result<String> {
        let phases = self.solver.config.generator.clone();
        match self.envs().state.phase {
            Phase::Solver => {
                let rollout = self.solver.solver_iteration(lr_scale, wall)?;
                let envs = self.envs();
                envs.state.phase_steps += rollout.steps;
                let warm = self.solver.trainer.global_step >= phases.solver_warmup_steps;
                let envs = self.envs();
                if warm && envs.state.phase_steps >= phases.solver_phase_steps {
                    envs.set_phase(Phase::Generator);
                }
                Ok(format!(
                    "solver: return {:.2}, success {:.2}",
                    rollout.mean_return, rollout.success_ratio
                ))
            }
            Phase::Generator => {
                let message = self.generator_iteration(lr_scale, wall)?;
                let envs = self.envs();
                if envs.state.phase_steps >= phases.generator_phase_steps {
                    envs.set_phase(Phase::Solver);
                }
                Ok(message)
            }
        }
    }

    fn checkpoint_minutes(&self) -> f64 {
        self.solver.config.checkpoint_minutes
    }

    fn save_checkpoint(&self, wall: f64) -> Result<()> {
        let envs = &self.solver.trainer.env;
        let state = TrainingState {
            global_step: envs.state.generator_steps,
            iteration: self.generator_iteration,
            adam_step: envs.generator.ppo.adam.step,
            wall_time_s: wall,
            rng: envs.rng.clone(),
            source: serde_json::Value::Null,
            config: serde_json::to_value(&self.solver.config)?,
        };
        let bytes =
            checkpoint::checkpoint_bytes(&envs.generator.ppo, &self.generator_card(wall), &state);
        let out = &self.solver.out;
        fsio::write_atomic(&out.join(GENERATOR_CHECKPOINT), &bytes, Overwrite::Allowed)?;
        self.solver.save_solver_checkpoint(wall)
    }

    fn save_policies(&self, wall: f64) -> Result<()> {
        let out = &self.solver.out;
        save_policy_files(
            out,
            "generator",
            &self.solver.trainer.env.generator.ppo.policy,
            &self.generator_card(wall),
        )?;
        save_policy_files(
            out,
            "solver",
            &self.solver.trainer.ppo.policy,
            &self.solver.solver_card(wall),
        )
    }

    fn out(&self) -> &Path {
        &self.solver.out
    }
}

/// Drops metric rows written after the checkpoint a run resumes from, so the curve continues
/// without a gap or a repeat.
fn truncate_metrics(path: &Path, header: &str, last_iteration: u64) -> Result<()> {
    let text = std::fs::read_to_string(path).unwrap_or_else(|_| format!("{header}\n"));
    let kept: Vec<&str> = text
        .lines()
        .enumerate()
        .filter(|(i, line)| {
            *i == 0
                || line
                    .split(',')
                    .next()
                    .and_then(|it| it.parse::<u64>().ok())
                    .is_some_and(|it| it <= last_iteration)
        })
        .map(|(_, line)| line)
        .collect();
    fsio::write_atomic(
        path,
        format!("{}\n", kept.join("\n")).as_bytes(),
        Overwrite::Allowed,
    )
}

/// The current commit, for policy cards, with `-dirty` when the working tree has changes that
/// are not committed (so the card cannot name the code that trained it); "unknown" outside a
/// git checkout.
fn git_commit() -> String {
    std::process::Command::new("git")
        .args(["describe", "--always", "--abbrev=7", "--dirty"])
        .output()
        .ok()
        .filter(|o| o.status.success())
        .map_or("unknown".into(), |o| {
            String::from_utf8_lossy(&o.stdout).trim().to_string()
        })
}

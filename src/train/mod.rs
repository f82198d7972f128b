//! `arlpcg train`: the training runs. For now the platform Solver alone on rule-pcg or
//! fixed-track levels; the adversarial loop joins later. A run lives in its output folder:
//! `config.yaml`, `checkpoint.safetensors` (written atomically every few minutes, on Ctrl-C and at
//! the end), `metrics.csv` (one row per PPO iteration), and the final `solver.safetensors` with
//! its card `solver.yaml`. `--resume` continues from the checkpoint.

pub mod platform;

use std::io::Write;
use std::path::{Path, PathBuf};
use std::sync::Arc;
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::Instant;

use anyhow::{Context, Result, bail};
use serde::{Deserialize, Serialize};

use crate::cli::TrainArgs;
use crate::fsio::{self, Overwrite};
use crate::level::Game;
use crate::rl::checkpoint::{self, PolicyCard, Role, TrainingRecord, TrainingState};
use crate::rl::policy::{ActorCritic, PolicyShape};
use crate::rl::ppo::{Ppo, PpoConfig, UpdateStats};
use crate::rl::vec_env::{RolloutStats, Trainer};
use platform::{PlatformSolverEnvs, SolverMode, SourceState};

/// Everything a Solver training run is configured by (`--config FILE`, YAML; every field has
/// the default `arlpcg train --print-config` shows).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct SolverTrainConfig {
    /// Seeds network initialization and action sampling.
    pub seed: u64,
    /// Hidden layer sizes of the actor and of the critic (the paper: 2 × 512).
    pub hidden: Vec<usize>,
    /// Minutes between checkpoints.
    pub checkpoint_minutes: f64,
    /// PPO (the paper's Solver: learning rate 3e-4, γ 0.99 on the platform game).
    pub ppo: PpoConfig,
}

impl Default for SolverTrainConfig {
    fn default() -> Self {
        Self {
            seed: 0,
            hidden: vec![512, 512],
            checkpoint_minutes: 5.0,
            ppo: PpoConfig {
                learning_rate: 3e-4,
                gamma: 0.99,
                num_envs: 64,
                num_steps: 128,
                ent_coef: 0.005,
                ..PpoConfig::default()
            },
        }
    }
}

const CHECKPOINT: &str = "checkpoint.safetensors";
const METRICS: &str = "metrics.csv";
const METRICS_HEADER: &str = "iteration,global_step,wall_time_s,steps_per_s,rollout_s,update_s,learning_rate,episodes,mean_return,success_ratio,policy_loss,value_loss,entropy,approx_kl,clip_fraction,explained_variance";

/// Runs `arlpcg train`.
pub fn run(args: &TrainArgs) -> Result<()> {
    if args.print_config {
        print!("{}", serde_yaml::to_string(&SolverTrainConfig::default())?);
        return Ok(());
    }
    if args.game != Game::Platform {
        bail!(
            "--game {}: only the platform game can be trained so far",
            args.game
        );
    }
    let mode = args.mode;
    let out = args
        .out
        .as_ref()
        .context("--out DIR is required: where the run's checkpoint, metrics and policy go")?;
    if args.steps.is_none() && args.minutes.is_none() {
        bail!("give a budget: --steps N (total environment steps) or --minutes M (this session)");
    }
    let checkpoint_path = out.join(CHECKPOINT);
    let threads = args.threads.map_or_else(
        || std::thread::available_parallelism().map_or(2, |n| n.get()),
        |t| t as usize,
    );
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()?;
    pool.install(|| {
        let mut run = if args.resume {
            if args.config.is_some() {
                bail!("--config cannot change a resumed run: its configuration is in {}", checkpoint_path.display());
            }
            Run::resume(out, mode)?
        } else {
            if checkpoint_path.exists() {
                bail!("{} already holds a training run: add --resume to continue it, or choose another --out", out.display());
            }
            let config = match &args.config {
                Some(path) => load_config(path)?,
                None => SolverTrainConfig::default(),
            };
            Run::start(out, mode, config)?
        };
        run.train(args)
    })
}

fn load_config(path: &Path) -> Result<SolverTrainConfig> {
    let text =
        std::fs::read_to_string(path).with_context(|| format!("cannot read {}", path.display()))?;
    let config: SolverTrainConfig =
        serde_yaml::from_str(&text).map_err(|e| anyhow::anyhow!("{}: {e}", path.display()))?;
    let p = &config.ppo;
    if config.hidden.is_empty()
        || config.hidden.contains(&0)
        || p.num_envs == 0
        || p.num_steps == 0
        || p.num_minibatches == 0
        || p.update_epochs == 0
    {
        bail!(
            "{}: hidden sizes, num_envs, num_steps, num_minibatches and update_epochs must be at least 1",
            path.display()
        );
    }
    let valid = p.learning_rate.is_finite()
        && p.learning_rate > 0.0
        && (0.0..=1.0).contains(&p.gamma)
        && (0.0..=1.0).contains(&p.gae_lambda);
    if !valid {
        bail!(
            "{}: learning_rate must be > 0, gamma and gae_lambda within [0, 1]",
            path.display()
        );
    }
    Ok(config)
}

/// A training run in progress.
struct Run {
    out: PathBuf,
    mode: SolverMode,
    config: SolverTrainConfig,
    trainer: Trainer<PlatformSolverEnvs>,
    iteration: u64,
    wall_before: f64,
}

impl Run {
    fn shape(config: &SolverTrainConfig) -> PolicyShape {
        PolicyShape {
            observation: crate::game::platform::OBSERVATION_SIZE,
            hidden: config.hidden.clone(),
            continuous: platform::CONTINUOUS_ACTIONS.len(),
            binary: platform::BINARY_ACTIONS.len(),
        }
    }

    fn start(out: &Path, mode: SolverMode, config: SolverTrainConfig) -> Result<Self> {
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
        let policy = ActorCritic::new(Self::shape(&config), config.seed)?;
        let ppo = Ppo::new(config.ppo.clone(), policy)?;
        let envs = PlatformSolverEnvs::new(
            mode,
            config.ppo.num_envs,
            SourceState {
                levels_drawn: 0,
                episodes_started: 0,
            },
        );
        let trainer = Trainer::new(ppo, envs, config.seed);
        Ok(Self {
            out: out.to_path_buf(),
            mode,
            config,
            trainer,
            iteration: 0,
            wall_before: 0.0,
        })
    }

    fn resume(out: &Path, mode: SolverMode) -> Result<Self> {
        let path = out.join(CHECKPOINT);
        let bytes = std::fs::read(&path)
            .with_context(|| format!("cannot resume: cannot read {}", path.display()))?;
        let loaded = checkpoint::load_policy(
            &bytes,
            Game::Platform,
            Role::Solver,
            crate::game::platform::OBSERVATION_SIZE,
        )
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
        let config: SolverTrainConfig = serde_json::from_value(state.config.clone())
            .with_context(|| format!("{}: configuration", path.display()))?;
        let source: SourceState = serde_json::from_value(state.source.clone())
            .with_context(|| format!("{}: level source", path.display()))?;
        let vars = loaded.policy.named_vars();
        let mut ppo = Ppo::new(config.ppo.clone(), loaded.policy)?;
        ppo.adam
            .restore(&vars, &loaded.tensors, state.adam_step)
            .map_err(|e| anyhow::anyhow!("{}: {e}", path.display()))?;
        let envs = PlatformSolverEnvs::new(mode, config.ppo.num_envs, source);
        let mut trainer = Trainer::new(ppo, envs, config.seed);
        trainer.norm = loaded.card.normalizer.clone();
        trainer.rng = state.rng;
        trainer.global_step = state.global_step;
        truncate_metrics(&out.join(METRICS), state.iteration)?;
        Ok(Self {
            out: out.to_path_buf(),
            mode,
            config,
            trainer,
            iteration: state.iteration,
            wall_before: state.wall_time_s,
        })
    }

    fn card(&self, wall_time_s: f64) -> PolicyCard {
        PolicyCard {
            format: checkpoint::POLICY_FORMAT.into(),
            version: checkpoint::POLICY_VERSION,
            game: Game::Platform,
            role: Role::Solver,
            observation: platform::observation_layout(),
            continuous_actions: platform::CONTINUOUS_ACTIONS.map(String::from).to_vec(),
            binary_actions: platform::BINARY_ACTIONS.map(String::from).to_vec(),
            network: Self::shape(&self.config),
            normalizer: self.trainer.norm.clone(),
            training: TrainingRecord {
                mode: self.mode.name().into(),
                steps: self.trainer.global_step,
                wall_time_s: (wall_time_s * 10.0).round() / 10.0,
                seed: self.config.seed,
                commit: git_commit(),
                command: std::iter::once("arlpcg".to_string())
                    .chain(std::env::args().skip(1))
                    .collect::<Vec<_>>()
                    .join(" "),
            },
            results: Default::default(),
        }
    }

    fn save_checkpoint(&self, wall_time_s: f64) -> Result<()> {
        let state = TrainingState {
            global_step: self.trainer.global_step,
            iteration: self.iteration,
            adam_step: self.trainer.ppo.adam.step,
            wall_time_s,
            rng: self.trainer.rng.clone(),
            source: serde_json::to_value(self.trainer.env.state())?,
            config: serde_json::to_value(&self.config)?,
        };
        let bytes =
            checkpoint::checkpoint_bytes(&self.trainer.ppo, &self.card(wall_time_s), &state);
        fsio::write_atomic(&self.out.join(CHECKPOINT), &bytes, Overwrite::Allowed)
    }

    fn save_policy(&self, wall_time_s: f64) -> Result<()> {
        let card = self.card(wall_time_s);
        fsio::write_atomic(
            &self.out.join("solver.safetensors"),
            &checkpoint::policy_bytes(&self.trainer.ppo.policy, &card),
            Overwrite::Allowed,
        )?;
        fsio::write_atomic(
            &self.out.join("solver.yaml"),
            serde_yaml::to_string(&card)?.as_bytes(),
            Overwrite::Allowed,
        )
    }

    fn train(&mut self, args: &TrainArgs) -> Result<()> {
        let stop = Arc::new(AtomicBool::new(false));
        {
            let stop = stop.clone();
            // A second handler cannot be installed (tests run several runs in one process).
            let _ = ctrlc::set_handler(move || stop.store(true, Ordering::SeqCst));
        }
        let session = Instant::now();
        let mut last_checkpoint = Instant::now();
        let config = self.config.ppo.clone();
        let total_steps = args.steps;
        let bar = match total_steps {
            Some(total) => crate::commands::progress_bar(total, "training"),
            None => crate::commands::progress_bar(
                args.minutes.map_or(0, |m| (m * 60.0) as u64),
                "training (s)",
            ),
        };
        bar.set_position(match total_steps {
            Some(_) => self.trainer.global_step,
            None => 0,
        });
        let mut metrics = std::fs::OpenOptions::new()
            .append(true)
            .open(self.out.join(METRICS))
            .context("cannot open metrics.csv")?;
        loop {
            let done_by_steps = total_steps.is_some_and(|t| self.trainer.global_step >= t);
            let done_by_time = args
                .minutes
                .is_some_and(|m| session.elapsed().as_secs_f64() >= m * 60.0);
            if done_by_steps || done_by_time || stop.load(Ordering::SeqCst) {
                break;
            }
            let learning_rate = match (config.anneal_lr, total_steps) {
                (true, Some(total)) => {
                    config.learning_rate
                        * (1.0 - self.trainer.global_step as f64 / total as f64).max(0.0)
                }
                _ => config.learning_rate,
            };
            let t0 = Instant::now();
            let (batch, rollout) = self.trainer.collect()?;
            let t1 = Instant::now();
            let update = self.trainer.learn(&batch, learning_rate)?;
            let t2 = Instant::now();
            self.iteration += 1;
            let wall = self.wall_before + session.elapsed().as_secs_f64();
            let timing = [(t1 - t0).as_secs_f64(), (t2 - t1).as_secs_f64()];
            writeln!(
                metrics,
                "{}",
                self.metrics_row(wall, timing, learning_rate, &rollout, &update)
            )?;
            bar.set_message(format!(
                "return {:.2}, success {:.2}, {:.0} steps/s",
                rollout.mean_return,
                rollout.success_ratio,
                rollout.steps as f64 / (timing[0] + timing[1])
            ));
            match total_steps {
                Some(_) => bar.set_position(self.trainer.global_step),
                None => bar.set_position(session.elapsed().as_secs()),
            }
            if last_checkpoint.elapsed().as_secs_f64() >= self.config.checkpoint_minutes * 60.0 {
                self.save_checkpoint(wall)?;
                last_checkpoint = Instant::now();
            }
        }
        bar.finish_and_clear();
        let wall = self.wall_before + session.elapsed().as_secs_f64();
        self.save_checkpoint(wall)?;
        self.save_policy(wall)?;
        let why = if stop.load(Ordering::SeqCst) {
            "stopped (Ctrl-C)"
        } else {
            "finished"
        };
        println!(
            "{why} at {} steps after {:.1} min in all; checkpoint and solver.safetensors in {}",
            self.trainer.global_step,
            wall / 60.0,
            self.out.display()
        );
        Ok(())
    }

    fn metrics_row(
        &self,
        wall: f64,
        [rollout_s, update_s]: [f64; 2],
        learning_rate: f64,
        r: &RolloutStats,
        u: &UpdateStats,
    ) -> String {
        format!(
            "{},{},{:.2},{:.1},{:.3},{:.3},{:.3e},{},{:.4},{:.4},{:.5},{:.5},{:.4},{:.5},{:.4},{:.4}",
            self.iteration,
            self.trainer.global_step,
            wall,
            r.steps as f64 / (rollout_s + update_s),
            rollout_s,
            update_s,
            learning_rate,
            r.episodes,
            r.mean_return,
            r.success_ratio,
            u.policy_loss,
            u.value_loss,
            u.entropy,
            u.approx_kl,
            u.clip_fraction,
            u.explained_variance
        )
    }
}

/// Drops metric rows written after the checkpoint a run resumes from, so the curve continues
/// without a gap or a repeat.
fn truncate_metrics(path: &Path, last_iteration: u64) -> Result<()> {
    let text = std::fs::read_to_string(path).unwrap_or_else(|_| format!("{METRICS_HEADER}\n"));
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

/// The current commit, for policy cards ("unknown" outside a git checkout).
fn git_commit() -> String {
    std::process::Command::new("git")
        .args(["rev-parse", "--short", "HEAD"])
        .output()
        .ok()
        .filter(|o| o.status.success())
        .map_or("unknown".into(), |o| {
            String::from_utf8_lossy(&o.stdout).trim().to_string()
        })
}

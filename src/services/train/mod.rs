//! The training runs, in the paper's four modes: the Solver (of either game)
//! alone on rule levels (`rule-pcg`) or on a small fixed set (`fixed-track`), and the adversarial
//! loop with a Generator (`arlpcg`, λ drawn per match; `fixed-aux`, λ = 1).
//!
//! A run lives in its output folder: `config.yaml`, `checkpoint.safetensors` (the Solver;
//! written atomically every few minutes, on Ctrl-C and at the end), `metrics.csv` (one row per
//! Solver update), the final `solver.safetensors` with its card `solver.yaml`, and for the
//! adversarial modes `generator-checkpoint.safetensors`, `generator-metrics.csv` and
//! `generator.safetensors` + `generator.yaml`. `--resume` continues from the checkpoints.
//!
//! This is the core that `arlpcg train` (`src/shells/commands/train.rs`) drives: [`open`] starts or
//! resumes a run, [`Training`] steps it one iteration at a time and saves it. The shell owns the
//! clock, signals, progress and printing; nothing here reads the clock or prints.

mod adversarial_run;
pub mod arlpcg;
mod cards;
mod config;
mod finish_checks;
mod metrics;
pub mod own_check;
pub mod population;
mod recipe;
pub mod solver_envs;
mod solver_run;

pub use config::{GeneratorConfig, SOLO_SOLVER_UPDATE_EPOCHS, TrainConfig};

use std::path::Path;

use anyhow::{Context, Result, bail};

use crate::services::fsio;
use adversarial_run::AdversarialRun;
use arlpcg_core::game::GameSpec;
use arlpcg_core::game::generator::GeneratorGame;
use arlpcg_core::level::Game;
use arlpcg_core::level::profile::{Profile, ProfileRecord};
use arlpcg_core::rl::checkpoint::TrainMode;
use cards::{check_folder_policies, checkpoint_identity, solver_shape};
pub use config::load_config;
pub use metrics::write_learning_curve;
use solver_envs::{SolverEnvs, SourceRecord};
use solver_run::SolverRun;

pub(super) const CHECKPOINT: &str = "checkpoint.safetensors";
/// The file a training session holds in its run folder while it runs (the shell's: see
/// `commands/train.rs`); it does not make a folder a run.
pub const LOCK_FILE: &str = "train.lock";
pub(super) const GENERATOR_CHECKPOINT: &str = "generator-checkpoint.safetensors";
/// The Generator of the finish's best own check (`generator.finish.own_check_every`), which a
/// finish that runs to its cap without passing ends with.
pub(super) const BEST_CHECK_GENERATOR: &str = "generator-best-check.safetensors";
/// The run's metrics file, a row per iteration.
pub const METRICS: &str = "metrics.csv";
/// The key under which a checkpoint's `source` holds the episodes or matches under way
/// ([`SourceRecord`], [`AdversarialRecord`]).
pub(super) const UNDER_WAY: &str = "under_way";
pub(super) const GENERATOR_METRICS: &str = "generator-metrics.csv";
pub(super) const METRICS_HEADER: &str = "iteration,global_step,wall_time_s,steps_per_s,rollout_s,update_s,learning_rate,episodes,mean_return,success_ratio,policy_loss,value_loss,entropy,approx_kl,clip_fraction,explained_variance,env_s,forward_s,generator_s,gae_s,copies_s,iteration_s,update_mfu";

/// What a session asks of its run besides its game and mode: a configuration file (the game's
/// defaults when `None`), a seed, a budget and a game profile, each replacing the
/// configuration's when given.
#[derive(Debug, Default, Clone, Copy)]
pub struct RunAsk<'a> {
    /// The configuration file (none: the game's defaults).
    pub config: Option<&'a Path>,
    /// The seed, replacing the configuration's.
    pub seed: Option<u64>,
    /// The step budget, replacing the configuration's.
    pub steps: Option<u64>,
    /// The game profile to train for, replacing the configuration's.
    pub profile: Option<&'a Profile>,
    /// The share each main ability varies by (`ability_spread`).
    pub ability_spread: Option<f64>,
}

/// The run in `out`: started afresh as `ask` asks, or with `resume` continued from its
/// checkpoints (`ask`'s configuration and steps, if given, replace its hyper-parameters and
/// budget from here on; its seed and profile cannot change). The caller installs the thread
/// pool the run's environments and updates use.
pub fn open(
    game: Option<Game>,
    mode: Option<TrainMode>,
    out: &Path,
    ask: RunAsk,
    resume: bool,
) -> Result<Box<dyn Training>> {
    let RunAsk {
        config,
        seed,
        steps,
        profile,
        ability_spread,
    } = ask;
    let (game, mode) = if resume {
        let identity = resumed_identity(out, game, mode)?;
        check_folder_policies(out, &out.join(CHECKPOINT), &out.join(GENERATOR_CHECKPOINT))?;
        identity
    } else {
        (game.unwrap_or_default(), mode.unwrap_or(TrainMode::RulePcg))
    };
    if let Some(profile) = profile.filter(|p| p.game() != game) {
        bail!(
            "--profile is a {} profile and the run is a {game} one (--game {game})",
            profile.game()
        );
    }
    let config = if resume {
        Start::Resume(ConfigChange {
            config: config
                .map(|path| load_config(path, game, mode))
                .transpose()?,
            seed,
            steps,
            profile: profile.map(|p| Box::new(p.record())),
            ability_spread,
        })
    } else {
        if out.join(CHECKPOINT).exists() {
            bail!(
                "{} already holds a training run: add --resume to continue it, or choose another --out",
                out.display()
            );
        }
        if out.exists() && !out.is_dir() {
            bail!("--out {} is not a folder", out.display());
        }
        if let Some(name) = fsio::first_entry(out, &[LOCK_FILE])? {
            bail!(
                "{} is not empty (it holds {name}): a new run starts in a new or empty folder, so that no policy or card is replaced; choose another --out",
                out.display()
            );
        }
        let mut config = match config {
            Some(path) => {
                let config = load_config(path, game, mode)?;
                // fixed-aux plays no hard match, so a finish that waits for them never ends.
                let finish = config.generator.finish;
                if mode == TrainMode::FixedAux
                    && finish.solver_steps > 0
                    && finish.generator_until_hard_success.is_some()
                {
                    bail!(
                        "{}: generator.finish.generator_until_hard_success: fixed-aux plays only \
                         λ = 1 matches, so its Solver fails no hard one and the finish's \
                         Generator phase would run to its cap; set it to null, or the finish's \
                         solver_steps to 0",
                        path.display()
                    );
                }
                config
            }
            None => TrainConfig::for_run(game, mode),
        };
        if let Some(seed) = seed {
            config.seed = seed;
        }
        if let Some(steps) = steps {
            config.steps = steps;
        }
        if let Some(profile) = profile {
            config.profile = Some(profile.record());
        }
        if let Some(spread) = ability_spread {
            config.ability_spread = spread;
            config.ability_ranges.clear();
        }
        Start::New(config)
    };
    arlpcg_core::for_game!(game, G => match config::solver_only(mode) {
        Some(source) => solver_run::<G>(out, mode, source, config),
        None => adversarial_run::<G>(out, mode, config),
    })
}

/// The game and mode a resumed run goes on with: its checkpoint's, which `--game` and `--mode`,
/// when given, must name.
fn resumed_identity(
    out: &Path,
    game: Option<Game>,
    mode: Option<TrainMode>,
) -> Result<(Game, TrainMode)> {
    let path = out.join(CHECKPOINT);
    if !path.exists() {
        bail!(
            "{} holds no checkpoint to resume: start the run without --resume",
            out.display()
        );
    }
    let (run_game, run_mode) = checkpoint_identity(&path)?;
    if game.is_some_and(|game| game != run_game) || mode.is_some_and(|mode| mode != run_mode) {
        bail!(
            "{} is a {run_game} {} run: resume it with --game {run_game} --mode {}, or leave both out",
            out.display(),
            run_mode.name(),
            run_mode.name()
        );
    }
    Ok((run_game, run_mode))
}

/// How a session opens its run: a new one with its configuration, or a resumed one with what
/// changes in its stored configuration.
enum Start {
    New(TrainConfig),
    Resume(ConfigChange),
}

/// What a resumed run changes in its configuration: `--config` replaces all of it, `--steps`
/// the budget. `--seed` may be given again (the run's first command plus `--resume`), but it
/// cannot change.
#[derive(Debug, Default)]
pub(super) struct ConfigChange {
    pub config: Option<TrainConfig>,
    pub seed: Option<u64>,
    pub steps: Option<u64>,
    pub profile: Option<Box<ProfileRecord>>,
    pub ability_spread: Option<f64>,
}

impl ConfigChange {
    /// The resumed run's configuration, from the one it stored.
    pub(super) fn apply(self, stored: &TrainConfig) -> TrainConfig {
        let mut new = self.config.unwrap_or_else(|| stored.clone());
        if let Some(seed) = self.seed {
            new.seed = seed;
        }
        if let Some(steps) = self.steps {
            new.steps = steps;
        }
        if let Some(profile) = self.profile {
            new.profile = Some(*profile);
        }
        if let Some(spread) = self.ability_spread {
            new.ability_spread = spread;
            new.ability_ranges.clear();
        }
        new
    }
}

/// Trains a Generator of game `G` against its Solver (the adversarial modes), starting or
/// resuming.
fn adversarial_run<G: GeneratorGame>(
    out: &Path,
    mode: TrainMode,
    start: Start,
) -> Result<Box<dyn Training>> {
    Ok(Box::new(match start {
        Start::New(config) => AdversarialRun::<G>::start(out, mode, config)?,
        Start::Resume(change) => AdversarialRun::<G>::resume(out, mode, change)?,
    }))
}

/// Trains a Solver of game `G` alone (the Solver-only modes), starting or resuming.
fn solver_run<G: GameSpec>(
    out: &Path,
    mode: TrainMode,
    source: solver_envs::SolverMode,
    start: Start,
) -> Result<Box<dyn Training>> {
    let build = |config: &TrainConfig, state: Option<serde_json::Value>, _: u64| {
        let record: SourceRecord = match state {
            Some(json) => serde_json::from_value(json).context("level source")?,
            None => SourceRecord::default(),
        };
        solver_envs::<G>(config, source, config.solver.num_envs, record)
    };
    Ok(Box::new(match start {
        Start::New(config) => SolverRun::start(out, mode, config, build)?,
        Start::Resume(change) => SolverRun::resume(out, mode, change, build)?,
    }))
}

/// `count` Solver environments of game `G` on levels from `source`, for the player and
/// ability ranges of `config`, continuing from `record` (its episodes under way replayed).
pub(super) fn solver_envs<G: GameSpec>(
    config: &TrainConfig,
    source: solver_envs::SolverMode,
    count: usize,
    record: SourceRecord,
) -> Result<SolverEnvs<G>> {
    let action_size = solver_shape(config, G::GAME).action_size();
    let trained_over = config
        .trained_over(G::GAME)
        .map_err(|problem| anyhow::anyhow!("configuration: {problem}"))?;
    let player = (config.player(G::GAME), trained_over);
    SolverEnvs::<G>::new(source, count, record, action_size, player)
        .map_err(|problem| anyhow::anyhow!("level source: {problem}"))
}

/// What one training iteration tells the shell.
pub struct Progress {
    /// The progress bar's message: the agent that learned and its figures.
    pub message: String,
    /// The iteration changed phase or played a finish check: a log without a progress bar
    /// keeps its line.
    pub notable: bool,
}

/// What the training loop drives: one iteration at a time, checkpoints, the final policies.
pub trait Training {
    /// Solver environment steps taken so far...
    fn solver_steps(&self) -> u64;
    /// ...and the run's budget of them ([`TrainConfig::steps`], plus an adversarial run's
    /// finish).
    fn budget(&self) -> u64;
    /// Wall-clock seconds of earlier sessions.
    fn wall_before(&self) -> f64;
    /// Records this session's command line and the commit of the code it runs (the last commit
    /// that changed it, `-dirty` for changes since) in the run's cards; the shell names both,
    /// the core reads no process arguments and runs no git.
    fn add_session(&mut self, command: String, commit: String);
    /// This session's matrix-product peak in FLOP/s, which the update's MFU is read against
    /// (the shell measures it: [`arlpcg_core::rl::fused::matmul_peak_flops`]).
    fn set_matmul_peak(&mut self, flops: f64);
    /// Where the run's time went so far, over every session, and the update's MFU.
    fn time_split(&self) -> (arlpcg_core::rl::timing::TimeSplit, f64);
    /// One PPO iteration (of whichever agent learns now); returns the progress bar's message.
    /// `wall` is the clock the shell lends: the run's wall-clock seconds over every session,
    /// for the metrics' time columns.
    fn iterate(&mut self, wall: &dyn Fn() -> f64) -> Result<Progress>;
    /// Minutes between checkpoints.
    fn checkpoint_minutes(&self) -> f64;
    /// Writes the checkpoint, with `wall` the run's wall-clock seconds so far.
    fn save_checkpoint(&self, wall: f64) -> Result<()>;
    /// Writes the policy files, with `wall` the run's wall-clock seconds so far.
    fn save_policies(&self, wall: f64) -> Result<()>;
    /// The run's folder.
    fn out(&self) -> &Path;
    /// For a finished run with a Generator: plays its own check ([`own_check`]; `starting`
    /// hears when it begins), writes the figures into its cards' `results` (the policies
    /// again, with the wall-clock seconds where it began as in [`Training::save_policies`];
    /// `wall` is the shell's clock, as in [`Training::iterate`]) and returns them in words;
    /// none for a run without a Generator or a check of 0 levels.
    fn check_own_control(
        &mut self,
        _wall: &dyn Fn() -> f64,
        _starting: &dyn Fn(),
    ) -> Result<Option<String>> {
        Ok(None)
    }
}
